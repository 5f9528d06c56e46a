// bench_reconstruct: cost of the reconstruction solvers at 1920x1080 RGB on 1 and 2 threads.
//
//   bench_reconstruct [--width W] [--height H] [--threads N] [--sweep] [--l2-only] [--feature-only]
//                     [--memory] [--admm] [--pcg] [--pcg-mg] [--warm]
//                     [--schedules K,F,L[,P[,S]] ... [--rounds N] [--l1d] [--outlier-data]]
//                     [--json PATH [--commit HASH]]
//
// Reports, per thread count:
//   - one bare FFTW forward + inverse 2-D DCT of the 3 planes (double, the same cached plans the
//     solver uses; float for context), and the L2 solve against it (target <= 1.5x); the double
//     pair and the L2 solve are timed alternately, 7 times each, medians;
//   - L1 (IRLS, Jacobi PCG from the L2 solution) time, inner iterations and objective, against the
//     reference "L1D" scheme implemented here: 20 reweightings x 50 plain CG steps from the
//     primal, w = 1 / (|e|_RGB + reg), reg = 0.05 halving (target >= 2.5x at equal or better
//     objective);
//   - Weighted time, iterations, exit residual and objective.
// --sweep also prints the L1 objective and time for a grid of (reweightings, CG steps);
// --l2-only stops after the DCT pair and the L2 solve (for quick runs while tuning L2).
//   - Feature (--norm feature): total time with the L1 guide (at its own reweightings and at the
//     L1 norm's) and with the L2 guide, split into the
//     guide solve, preparation, the cross-filtered candidates and the choice, on the synthetic
//     room of testing/feature_scene.h (half noise 0.2 with its variances, gradient noise 0.1),
//     relMSE against L1, CPU time (the time on idle cores on a loaded machine) of the whole and of
//     the filters and choice alone and its system part (first touches of fresh memory), a digest
//     of both outputs (to compare builds bit for bit), and what 1 GiB of fresh memory costs here;
//     --feature-only runs just this case.
// --admm compares an ADMM L1 probe (l1_admm_probe.h) with the library's IRLS (see bench_admm).
// --pcg counts PCG steps of the IRLS systems with DCT and multigrid preconditioners
// (l1_pcg_probe.h); --pcg-mg only Jacobi and multigrid, at more reweightings.
// --warm measures L1 warm-started from another alpha's output (ReconstructionInput::initial);
// --warm --sweep also a grid of warm schedules.
// --schedules K,F,L[,P[,S[,E[,U]]]] ...: cold L1 schedules against the Jacobi schedule 36 x 12 -> 3
// (the default before multigrid), alternated (time, objective); P the preconditioner (j Jacobi,
// a / v multigrid additive / V-cycle), S its coarse scale, E its edge scale, U the reweightings
// using it (none: all; the default is 30,3,1,v,1,1,16); --rounds N repeats each pair, --l1d adds
// the objective against the L1D scheme,
// --outlier-data uses test L1.BeatsL2OnSparseOutlierGradients' data (e.g. --width 96 --height 64).
// --json PATH also writes, per thread count run, L1's time and objective against L1D and the
// Feature reconstruction's time and split with the default guide (the benchmark report's table of
// the reconstruction's targets reads it), with --commit HASH's label as the commit measured.
// --memory only measures the peak resident memory (getrusage) after one solve of each norm, in the
// order L2, Weighted, L1: each figure is the process's peak so far, inputs included.
// Synthetic data: a smooth image with edges; primal noise sigma 0.2 (0.05 in the right half),
// gradient noise sigma 0.02 plus 1% outliers of +-2 (fireflies); variances match the noise.
#include <sys/resource.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <fftw3.h>
#include <tbb/task_arena.h>

#include "bench/reconstruct/l1_admm_probe.h"
#include "bench/reconstruct/l1_pcg_probe.h"
#include "core/huge_pages.h"
#include "reconstruct/dct_solver.h"
#include "reconstruct/feature_reconstruct.h"
#include "reconstruct/parallel.h"
#include "reconstruct/reconstruct.h"
#include "reconstruct/weighted_cg.h"
#include "testing/feature_scene.h"
#include "testing/l1d_reference.h"
#include "testing/test_images.h"

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// CPU time of the process so far (all threads), in seconds.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// System CPU time of the process so far (all threads): on Linux mostly the kernel backing first
// touches of fresh pages.
double system_seconds() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return double(ru.ru_stime.tv_sec) + 1e-6 * double(ru.ru_stime.tv_usec);
}

// Seconds to first-touch `bytes` of fresh huge-page memory (one write per 4 KB page).
double touch_fresh(size_t bytes) {
  char* p = static_cast<char*>(gdpt::allocate_huge(bytes));
  const auto t = Clock::now();
  for (size_t i = 0; i < bytes; i += 4096) p[i] = 1;
  const double seconds = seconds_since(t);
  gdpt::free_huge(p);
  return seconds;
}

// What fresh memory costs on this machine, which the Feature timings include: 1 GiB touched
// after 5 s in which the system had it free, then again right after it was freed. (On a virtual
// machine whose host reclaims the guest's free memory the first is several times the second.)
void print_fresh_memory_cost() {
  constexpr size_t kGiB = size_t(1) << 30;
  std::this_thread::sleep_for(std::chrono::seconds(5));
  const double first = touch_fresh(kGiB);
  const double again = touch_fresh(kGiB);
  std::printf("fresh memory: 1 GiB first touched in %.3f s, again right after freeing %.3f s\n",
              first, again);
}

// Minor page faults of the process so far (first touches of fresh memory).
long minor_faults() {
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  return ru.ru_minflt;
}

// FNV-1a over the bytes of an image: equal digests of two builds' runs mean bit-identical output.
uint64_t digest(const std::vector<float>& v) {
  uint64_t h = 1469598103934665603ull;
  const auto* p = reinterpret_cast<const unsigned char*>(v.data());
  for (size_t i = 0; i < v.size() * sizeof(float); ++i) h = (h ^ p[i]) * 1099511628211ull;
  return h;
}

// Median wall time of `runs` calls after one warm-up call.
template <class F>
double median_time(int runs, const F& f) {
  f();
  std::vector<double> t;
  for (int i = 0; i < runs; ++i) {
    const auto start = Clock::now();
    f();
    t.push_back(seconds_since(start));
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

// Median wall times of `runs` calls of f and of g, alternating f, g, f, g, ... after one warm-up
// call of each: on a shared machine the load drifts, and alternating exposes both to the same.
template <class F, class G>
std::pair<double, double> paired_median_times(int runs, const F& f, const G& g) {
  f();
  g();
  std::vector<double> tf, tg;
  for (int i = 0; i < runs; ++i) {
    auto start = Clock::now();
    f();
    tf.push_back(seconds_since(start));
    start = Clock::now();
    g();
    tg.push_back(seconds_since(start));
  }
  std::sort(tf.begin(), tf.end());
  std::sort(tg.begin(), tg.end());
  return {tf[tf.size() / 2], tg[tg.size() / 2]};
}

struct Data {
  int w, h;
  std::vector<float> truth, primal, gx, gy, variance;
};

Data make_data(int w, int h) {
  Data d{w, h, gdpt::test::make_image(w, h), {}, {}, {}, {}};
  const size_t px = size_t(w) * h;
  gdpt::test::exact_gradients(d.truth, w, h, d.gx, d.gy);
  std::mt19937 rng(1234);
  std::normal_distribution<float> normal(0.f, 1.f);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  d.primal = d.truth;
  d.variance.resize(px * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float sp = x < w / 2 ? 0.2f : 0.05f, sg = 0.02f;
      for (int c = 0; c < 3; ++c) {
        d.primal[3 * i + c] += sp * normal(rng);
        d.gx[3 * i + c] += sg * normal(rng);
        d.gy[3 * i + c] += sg * normal(rng);
      }
      const float ox = u(rng) < 0.01f ? (u(rng) < 0.5f ? 2.f : -2.f) : 0.f;
      const float oy = u(rng) < 0.01f ? (u(rng) < 0.5f ? 2.f : -2.f) : 0.f;
      for (int c = 0; c < 3; ++c) {
        d.gx[3 * i + c] += ox;
        d.gy[3 * i + c] += oy;
      }
      d.variance[3 * i] = sp * sp;
      d.variance[3 * i + 1] = sg * sg + (ox != 0.f ? 4.f : 0.f);
      d.variance[3 * i + 2] = sg * sg + (oy != 0.f ? 4.f : 0.f);
    }
  return d;
}

// Peak resident set size of the process so far, in MiB.
double peak_rss_mib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return double(u.ru_maxrss) / 1024.0;
}

// --memory: the inputs' size, then each solve's time and the peak RSS after it.
int measure_memory(const Data& d, int threads) {
  const double mpix = double(d.w) * d.h / 1e6;
  const double before = peak_rss_mib();
  std::printf(
      "memory: %dx%d (%.1f Mpx), inputs %.0f MiB, peak before solving %.0f MiB\n", d.w, d.h, mpix,
      double(d.truth.size() + d.primal.size() + d.gx.size() + d.gy.size() + d.variance.size()) * 4 /
          (1 << 20),
      before);
  gdpt::ReconstructionInput input{
      d.w, d.h, d.primal.data(), d.gx.data(), d.gy.data(), d.variance.data(), nullptr};
  for (const auto norm : {gdpt::ReconstructionNorm::L2, gdpt::ReconstructionNorm::Weighted,
                          gdpt::ReconstructionNorm::L1}) {
    gdpt::ReconstructionSettings s;
    s.threads = threads;
    s.norm = norm;
    const auto start = Clock::now();
    const std::vector<float> out = gdpt::reconstruct(input, s);
    const double t = seconds_since(start), peak = peak_rss_mib();
    std::printf("memory: %-8s %.1f s, peak %.0f MiB, %.0f MiB above the inputs (%.1f MiB/Mpx)\n",
                norm == gdpt::ReconstructionNorm::L2
                    ? "L2"
                    : (norm == gdpt::ReconstructionNorm::L1 ? "L1" : "Weighted"),
                t, peak, peak - before, (peak - before) / mpix);
  }
  return 0;
}

}  // namespace

// Parses a cold L1 schedule "K,F,L[,P[,S[,E[,U]]]]" into `s`: K reweightings, F -> L inner
// steps, P the preconditioner (j Jacobi, a additive multigrid, v multigrid V-cycle), S its coarse
// scale, E its coarse edge scale, U the reweightings that use it (Jacobi after).
bool parse_schedule(const std::string& spec, gdpt::ReconstructionSettings& s) {
  char p = 'j';
  float scale = 1.f, edges = s.l1_multigrid_edge_scale;
  s.l1_multigrid_reweightings = -1;  // no U: multigrid for every reweighting
  const int n =
      std::sscanf(spec.c_str(), "%d,%d,%d,%c,%f,%f,%d", &s.l1_reweightings, &s.l1_cg_steps_first,
                  &s.l1_cg_steps_last, &p, &scale, &edges, &s.l1_multigrid_reweightings);
  if (n < 3 || (p != 'j' && p != 'a' && p != 'v') || !(scale > 0.f && scale < 2.f) ||
      !(edges > 0.f && edges <= 1.f))
    return false;
  s.l1_multigrid_edge_scale = edges;
  s.l1_preconditioner = p == 'a'   ? gdpt::L1Preconditioner::MultigridAdditive
                        : p == 'v' ? gdpt::L1Preconditioner::MultigridVCycle
                                   : gdpt::L1Preconditioner::Jacobi;
  s.l1_multigrid_coarse_scale = scale;
  return true;
}

// --schedules K,F,L[,P[,S[,E[,U]]]] ...: each cold L1 schedule (parse_schedule) against the
// default, alternated default / schedule in one run, `rounds` times: wall and process CPU time,
// inner steps, objective relative to the default's and, with `l1d`, to the reference L1D scheme's.
int bench_schedules(const Data& d, int threads, const std::vector<std::string>& specs, int rounds,
                    bool l1d) {
  gdpt::ReconstructionInput in{d.w,         d.h,     d.primal.data(), d.gx.data(),
                               d.gy.data(), nullptr, nullptr};
  gdpt::ReconstructionSettings base;
  base.threads = threads;
  base.fft_measure = true;
  base.norm = gdpt::ReconstructionNorm::L1;
  gdpt::use_jacobi_l1_schedule(base);  // the reference: the earlier Jacobi default
  auto run = [&](const gdpt::ReconstructionSettings& s, double& wall, double& cpu, int& steps) {
    gdpt::ReconstructionReport r;
    const auto t0 = Clock::now();
    const double c0 = cpu_seconds();
    const auto x = gdpt::reconstruct(in, s, &r);
    wall = seconds_since(t0);
    cpu = cpu_seconds() - c0;
    steps = r.iterations;
    return gdpt::reconstruction_objective(in, gdpt::ReconstructionNorm::L1, s.alpha, x.data());
  };
  double w0, c0;
  int n0;
  run(base, w0, c0, n0);  // warm-up: plans, huge pages
  std::printf(
      "L1 schedules against the Jacobi schedule (%d x %d -> %d), %dx%d, %d threads, alternated\n",
      base.l1_reweightings, base.l1_cg_steps_first, base.l1_cg_steps_last, d.w, d.h, threads);
  double o_l1d = 0.0;
  if (l1d) {
    tbb::task_arena arena(threads);
    arena.execute([&] {
      const auto x = gdpt::test::l1d_reference(d.w, d.h, d.primal.data(), d.gx.data(), d.gy.data(),
                                               base.alpha);
      o_l1d =
          gdpt::reconstruction_objective(in, gdpt::ReconstructionNorm::L1, base.alpha, x.data());
    });
  }
  for (const std::string& spec : specs) {
    gdpt::ReconstructionSettings s = base;
    if (!parse_schedule(spec, s)) {
      std::fprintf(stderr, "bench_reconstruct: bad schedule '%s' (want K,F,L[,j|a|v[,S]])\n",
                   spec.c_str());
      return 2;
    }
    for (int round = 0; round < rounds; ++round) {
      double w1, c1;
      int n1;
      const double o0 = run(base, w0, c0, n0);
      const double o1 = run(s, w1, c1, n1);
      std::printf(
          "  %-12s %4d steps, wall %6.2f s (default %6.2f s), CPU %6.2f s (default "
          "%6.2f s): CPU ratio %.3f, objective %+.4f%% vs default",
          spec.c_str(), n1, w1, w0, c1, c0, c1 / c0, 100.0 * (o1 / o0 - 1.0));
      if (l1d)
        std::printf(", %+.4f%% vs L1D (default %+.4f%%)", 100.0 * (o1 / o_l1d - 1.0),
                    100.0 * (o0 / o_l1d - 1.0));
      std::printf("\n");
    }
  }
  return 0;
}

// The problem of test L1.BeatsL2OnSparseOutlierGradients (stronger outliers than make_data):
// gradient noise sigma 0.01 plus 2% outliers of +4 (x) / -4 (y), primal noise sigma 0.2.
Data make_outlier_data(int w, int h) {
  using namespace gdpt::test;
  Data d{w, h, make_image(w, h), {}, {}, {}, {}};
  const size_t px = size_t(w) * h;
  exact_gradients(d.truth, w, h, d.gx, d.gy);
  d.gx = add(d.gx, zero_mean_noise(px, 0.01f, 11));
  d.gy = add(d.gy, zero_mean_noise(px, 0.01f, 12));
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (size_t i = 0; i < px; ++i) {
    if (u(rng) < 0.02f)
      for (int c = 0; c < 3; ++c) d.gx[3 * i + c] += 4.f;
    if (u(rng) < 0.02f)
      for (int c = 0; c < 3; ++c) d.gy[3 * i + c] -= 4.f;
  }
  d.primal = add(d.truth, zero_mean_noise(px, 0.2f, 14));
  return d;
}

// What --json writes for one thread count (-1: not run).
struct Figures {
  int threads = 0;
  double l1_seconds = -1.0, l1_objective_vs_l1d = 0.0;  // objective / L1D's - 1
  // The Feature reconstruction with the default guide: wall time, its split, relMSE over L1's.
  double feature_seconds = -1.0, feature_solves = 0.0, feature_filters = 0.0;
  double feature_relmse_l1_over_feature = 0.0;
};

// --json PATH: the figures of every thread count run, for the benchmark report.
bool write_json(const char* path, const std::string& commit, int width, int height,
                const std::vector<Figures>& all) {
  FILE* f = std::fopen(path, "w");
  if (!f) return false;
  std::fprintf(f, "{\n \"commit\": \"%s\",\n \"width\": %d,\n \"height\": %d,\n \"runs\": [",
               commit.c_str(), width, height);
  for (size_t i = 0; i < all.size(); ++i) {
    const Figures& r = all[i];
    std::fprintf(f,
                 "%s\n  {\"threads\": %d, \"l1_seconds\": %.4f, \"l1_objective_vs_l1d\": %.3e, "
                 "\"feature_seconds\": %.4f, \"feature_solves_seconds\": %.4f, "
                 "\"feature_filters_seconds\": %.4f, \"feature_relmse_l1_over_feature\": %.4f}",
                 i ? "," : "", r.threads, r.l1_seconds, r.l1_objective_vs_l1d, r.feature_seconds,
                 r.feature_solves, r.feature_filters, r.feature_relmse_l1_over_feature);
  }
  std::fprintf(f, "\n ]\n}\n");
  return std::fclose(f) == 0;
}

// The Feature reconstruction on the synthetic room: total time per guide and its split; the
// default guide's figures go into `out`.
void bench_feature(int width, int height, int threads, Figures& out) {
  const float sigma_half = 0.2f;
  const gdpt::test::FeatureScene sc =
      gdpt::test::make_feature_scene(width, height, sigma_half, 0.1f, 7);
  // The halves' variances, as a render writes them (they enter the colour distances).
  const std::vector<float> half_variance(sc.a.size(), sigma_half * sigma_half);
  // The variances of the pixel means (primal, dx, dy), as a render writes them: the Weighted
  // candidate's solves run and are timed.
  std::vector<float> variance(sc.a.size(), 0.1f * 0.1f);
  for (size_t i = 0; i < variance.size(); i += 3) variance[i] = sigma_half * sigma_half / 2.f;
  gdpt::ReconstructionInput in = sc.input();
  in.variance_a = in.variance_b = half_variance.data();
  in.variance = variance.data();
  gdpt::ReconstructionSettings s;
  s.threads = threads;
  s.norm = gdpt::ReconstructionNorm::L1;
  const auto t0 = Clock::now();
  const double rel_l1 = gdpt::test::relative_mse(gdpt::reconstruct(in, s), sc.truth);
  const double t_l1 = seconds_since(t0);
  s.norm = gdpt::ReconstructionNorm::Feature;
  const int guide_k = s.feature_guide_l1_reweightings;
  // The L1 guide at its own reweightings, at the L1 norm's (a fully converged guide), and L2.
  for (auto [guide, k] : {std::pair{gdpt::ReconstructionNorm::L1, guide_k},
                          std::pair{gdpt::ReconstructionNorm::L1, s.l1_reweightings},
                          std::pair{gdpt::ReconstructionNorm::L2, guide_k}}) {
    s.feature_guide = guide;
    s.feature_guide_l1_reweightings = k;
    gdpt::ReconstructionReport r;
    const auto t1 = Clock::now();
    const double c1 = cpu_seconds(), sys1 = system_seconds();
    const long f1 = minor_faults();
    const auto img = gdpt::reconstruct(in, s, &r);
    const double total = seconds_since(t1), cpu_total = cpu_seconds() - c1;
    const double sys_total = system_seconds() - sys1;
    const long faults_total = minor_faults() - f1;
    // The filters and the choice alone, on the primal halves (the same work per candidate).
    gdpt::FeatureReconstruction fr;
    tbb::task_arena arena(threads);
    const auto t2 = Clock::now();
    const double c2 = cpu_seconds(), sys2 = system_seconds();
    const long f2 = minor_faults();
    arena.execute([&] {
      fr = gdpt::feature_filter(in, sc.a.data(), sc.b.data(), sc.primal.data(), in.variance_a,
                                in.variance_b);
    });
    const double filter_wall = seconds_since(t2), filter_cpu = cpu_seconds() - c2;
    const double filter_sys = system_seconds() - sys2;
    const long faults_filter = minor_faults() - f2;
    const double rel = gdpt::test::relative_mse(img, sc.truth);
    const double split =
        fr.prepare_seconds + fr.filter_seconds + fr.select_seconds + fr.blend_seconds;
    if (guide == gdpt::ReconstructionNorm::L1 && k == guide_k && out.feature_seconds < 0.0) {
      out.feature_seconds = total;
      out.feature_solves = r.guide_seconds;
      out.feature_filters = total - r.guide_seconds;
      out.feature_relmse_l1_over_feature = rel_l1 / rel;
    }
    std::printf(
        "Feature (guide %s, %d reweightings): %8.1f ms = solves %.1f ms + filters %.1f ms; "
        "relMSE %.5f vs L1 %.5f (%.1f ms): %.2fx lower\n",
        guide == gdpt::ReconstructionNorm::L1 ? "L1" : "L2", k, 1e3 * total, 1e3 * r.guide_seconds,
        1e3 * (total - r.guide_seconds), rel, rel_l1, 1e3 * t_l1, rel_l1 / rel);
    std::printf(
        "  filters alone %.1f ms = prepare %.1f (outlier limit, buffers) + %zu candidates "
        "%.1f + choice %.1f + blend %.1f + rest %.1f; CPU %.2f s (%.2f s per thread)\n",
        1e3 * filter_wall, 1e3 * fr.prepare_seconds,
        gdpt::detail::default_bilateral_candidates().size(), 1e3 * fr.filter_seconds,
        1e3 * fr.select_seconds, 1e3 * fr.blend_seconds, 1e3 * (filter_wall - split), filter_cpu,
        filter_cpu / threads);
    // Wall time depends on what else runs; CPU time (all threads) / threads is the time on
    // otherwise idle cores.
    std::printf(
        "  CPU time: total %.2f s (%.2f s per thread); system %.2f s, filters alone %.2f s\n",
        cpu_total, cpu_total / threads, sys_total, filter_sys);
    std::printf("  minor page faults: total %ld, filters alone %ld\n", faults_total, faults_filter);
    std::printf("  digest: whole %016llx, filters alone %016llx\n",
                static_cast<unsigned long long>(digest(img)),
                static_cast<unsigned long long>(digest(fr.image)));
  }
  print_fresh_memory_cost();
}

// --admm: the ADMM probe (l1_admm_probe.h) against the library's IRLS L1, in one run: a tight
// IRLS reference (twice the default schedule), then the default IRLS and ADMM interleaved, ADMM's
// objective and time after every iteration, and a warm start (alpha 0.2 -> 0.25) against a cold
// one.
int bench_admm(const Data& d, int threads) {
  using gdpt::ReconstructionNorm;
  gdpt::ReconstructionInput in{d.w,         d.h,     d.primal.data(), d.gx.data(),
                               d.gy.data(), nullptr, nullptr};
  tbb::task_arena arena(threads);
  auto objective = [&](const std::vector<float>& x, float alpha) {
    return gdpt::reconstruction_objective(in, ReconstructionNorm::L1, alpha, x.data());
  };
  auto solve = [&](ReconstructionNorm norm, float alpha, int k = 36, int first = 12, int last = 3) {
    gdpt::ReconstructionSettings s;
    s.threads = threads;
    s.fft_measure = true;
    s.norm = norm;
    s.alpha = alpha;
    s.l1_reweightings = k;
    s.l1_cg_steps_first = first;
    s.l1_cg_steps_last = last;
    return gdpt::reconstruct(in, s);
  };
  // Constant threshold (1 x the start's mean gradient residual), or continuation: 3x shrinking
  // by 0.8 per iteration down to 0.3x (the best of a sweep at 480x270).
  auto admm = [&](std::vector<float>& x, float alpha, int iterations, double tolerance,
                  bool continuation) {
    gdpt::bench::AdmmOptions o;
    o.max_iterations = iterations;
    o.tolerance = tolerance;
    if (continuation) {
      o.threshold_per_residual = 3.0;
      o.threshold_decay = 0.8;
      o.final_threshold_per_residual = 0.3;
    }
    gdpt::bench::AdmmResult r;
    arena.execute([&] {
      r = gdpt::bench::solve_l1_admm({d.w, d.h, d.primal.data(), d.gx.data(), d.gy.data(), alpha},
                                     x.data(), o);
    });
    return r;
  };
  const float alpha = 0.2f;
  std::printf("bench_reconstruct --admm: %dx%d RGB, alpha %.2f, %d threads\n", d.w, d.h,
              double(alpha), threads);
  const auto tight = solve(ReconstructionNorm::L1, alpha, 72, 24, 6);
  const double f_tight = objective(tight, alpha);
  std::printf("tight IRLS reference (72 reweightings x 24->6 PCG steps): objective %.8g\n",
              f_tight);
  auto l2 = solve(ReconstructionNorm::L2, alpha);  // warm-up (plans), and the ADMM start
  for (int round = 0; round < 2; ++round) {
    auto t0 = Clock::now();
    const auto irls = solve(ReconstructionNorm::L1, alpha);
    const double t_irls = seconds_since(t0);
    t0 = Clock::now();
    std::vector<float> x = solve(ReconstructionNorm::L2, alpha);
    const double t_l2 = seconds_since(t0);
    std::vector<float> xc = x;
    const auto r = admm(x, alpha, 30, 0.0, false);
    const auto rc = admm(xc, alpha, 30, 0.0, true);
    std::printf("round %d: IRLS (default) %.2f s, objective / tight %.6f, rms to truth %.5f\n",
                round, t_irls, objective(irls, alpha) / f_tight,
                gdpt::test::rms_error(irls, d.truth));
    std::printf(
        "round %d: ADMM from L2 (L2 %.2f s), rms to truth after 30: constant threshold %.5f, "
        "continuation %.5f\n",
        round, t_l2, gdpt::test::rms_error(x, d.truth), gdpt::test::rms_error(xc, d.truth));
    for (size_t k = 0; k < r.objectives.size(); ++k)
      std::printf(
          "  ADMM iteration %2zu: constant %6.2f s (+ L2), objective / tight %.6f; continuation "
          "%6.2f s, %.6f\n",
          k, r.seconds[k], r.objectives[k] / f_tight, rc.seconds[k], rc.objectives[k] / f_tight);
  }
  // Warm start: from the L1 solution at alpha 0.2 to alpha 0.25, against a cold start from L2.
  const float alpha2 = 0.25f;
  std::vector<float> warm = solve(ReconstructionNorm::L1, alpha);
  std::vector<float> cold = solve(ReconstructionNorm::L2, alpha2);
  const auto rw = admm(warm, alpha2, 40, 1e-4, false);
  const auto rc = admm(cold, alpha2, 40, 1e-4, false);
  std::printf(
      "alpha 0.2 -> 0.25, constant threshold, stop rule tolerance 1e-4: warm start %d iterations "
      "(%.2f s, objective "
      "%.8g), cold start from L2 %d iterations (%.2f s, objective %.8g)\n",
      rw.iterations, rw.seconds.back(), rw.objectives.back(), rc.iterations, rc.seconds.back(),
      rc.objectives.back());
  return 0;
}

// --pcg: the preconditioner probe (l1_pcg_probe.h) on the library's IRLS trajectory: per probed
// reweighting, the steps Jacobi, scalar-DCT, scaled-DCT and the two multigrid PCGs need to reach
// the residual of the library's fixed steps and a relative residual of 1e-3, and their wall time
// to the latter (the probe's own unfused passes). --pcg-mg skips the DCT preconditioners and
// probes more reweightings.
int bench_pcg(const Data& d, int threads, bool dct) {
  tbb::task_arena arena(threads);
  const float alpha = 0.2f;
  const double tolerance = 1e-3;
  std::vector<gdpt::bench::PcgProbeRow> rows;
  const std::vector<int> probe_at =
      dct ? std::vector<int>{0, 12, 35} : std::vector<int>{0, 12, 24, 35};
  arena.execute([&] {
    rows = gdpt::bench::probe_l1_pcg({d.w, d.h, d.primal.data(), d.gx.data(), d.gy.data(), alpha},
                                     probe_at, tolerance, 60, dct);
  });
  std::printf("bench_reconstruct --pcg: %dx%d RGB, alpha %.2f, %d threads, tolerance %.0e\n", d.w,
              d.h, double(alpha), threads, tolerance);
  std::printf(
      "reweighting  weight p99/p1  library steps  residual after them  | steps to that "
      "residual | steps to tolerance | seconds to tolerance; each in the order");
  for (const char* name : gdpt::bench::PcgProbeRow::kNames) std::printf(" %s", name);
  std::printf("\n");
  for (const auto& r : rows) {
    std::printf("%11d  %13.3g  %13d  %19.3e  |", r.reweighting, r.weight_spread, r.library_steps,
                r.jacobi_residual);
    for (const int n : r.steps_to_library) std::printf(" %4d", n);
    std::printf(" |");
    for (const int n : r.steps_to_tolerance) std::printf(" %4d", n);
    std::printf(" |");
    for (const double t : r.seconds_to_tolerance) std::printf(" %6.2f", t);
    std::printf("\n");
  }
  std::printf("(-1: not run, or not reached within 60 steps)\n");
  return 0;
}

// --warm: L1 warm-started from the L1 output at alpha 0.2 (ReconstructionInput::initial) at a
// new alpha, against the cold default at that alpha, interleaved in one process; objectives are
// divided by a tight cold solve (72 reweightings x 24->6 Jacobi-PCG steps) at the new alpha. With
// --sweep first a grid of warm schedules (reweightings, first regulariser, steps); then the
// defaults.
int bench_warm(const Data& d, int threads, bool sweep) {
  using gdpt::ReconstructionNorm;
  gdpt::ReconstructionInput in{d.w,         d.h,     d.primal.data(), d.gx.data(),
                               d.gy.data(), nullptr, nullptr};
  auto settings = [&](float alpha) {
    gdpt::ReconstructionSettings s;
    s.threads = threads;
    s.fft_measure = true;
    s.norm = ReconstructionNorm::L1;
    s.alpha = alpha;
    return s;
  };
  auto objective = [&](const std::vector<float>& x, float alpha) {
    return gdpt::reconstruction_objective(in, ReconstructionNorm::L1, alpha, x.data());
  };
  std::printf("bench_reconstruct --warm: %dx%d RGB, %d threads\n", d.w, d.h, threads);
  const auto from = gdpt::reconstruct(in, settings(0.2f));
  for (const float alpha : {0.25f, 0.3f, 0.4f, 0.8f, 0.15f, 0.1f, 0.05f}) {
    auto tight_s = settings(alpha);
    tight_s.l1_reweightings = 72;
    tight_s.l1_cg_steps_first = 24;
    tight_s.l1_cg_steps_last = 6;
    tight_s.l1_preconditioner = gdpt::L1Preconditioner::Jacobi;  // the reference as before
    const double f_tight = objective(gdpt::reconstruct(in, tight_s), alpha);
    auto warm_in = in;
    warm_in.initial = from.data();
    std::printf("alpha 0.2 -> %.2f: tight objective %.8g\n", double(alpha), f_tight);
    for (const int k : sweep ? std::vector<int>{4, 8, 12} : std::vector<int>{})
      for (const double reg : {0.05 / 512, 0.05 / 4096, 0.05 / 32768})
        for (const int steps : {3, 4, 6}) {
          auto s = settings(alpha);
          s.l1_warm_reweightings = k;
          s.l1_warm_regulariser = reg;
          s.l1_warm_cg_steps = steps;
          gdpt::ReconstructionReport r;
          const auto x = gdpt::reconstruct(warm_in, s, &r);
          std::printf(
              "  warm %2d reweightings, reg 0.05/%-5.0f, %d steps: %3d steps, %5.2f s, objective / "
              "tight %.6f, rms to truth %.5f\n",
              k, 0.05 / reg, steps, r.iterations, r.seconds, objective(x, alpha) / f_tight,
              gdpt::test::rms_error(x, d.truth));
        }
    for (int round = 0; round < 2; ++round) {
      gdpt::ReconstructionReport rc, rw;
      const auto cold = gdpt::reconstruct(in, settings(alpha), &rc);
      const auto warm = gdpt::reconstruct(warm_in, settings(alpha), &rw);
      std::printf(
          "  round %d: cold default %3d steps %5.2f s objective / tight %.6f rms %.5f | warm "
          "default %3d steps %5.2f s objective / tight %.6f rms %.5f | time ratio %.2f\n",
          round, rc.iterations, rc.seconds, objective(cold, alpha) / f_tight,
          gdpt::test::rms_error(cold, d.truth), rw.iterations, rw.seconds,
          objective(warm, alpha) / f_tight, gdpt::test::rms_error(warm, d.truth),
          rc.seconds / rw.seconds);
    }
  }
  return 0;
}

int main(int argc, char** argv) {
  int width = 1920, height = 1080, only_threads = 0;
  bool sweep = false, l2_only = false, feature_only = false, memory = false, admm = false,
       pcg = false, pcg_mg = false, warm = false;
  bool outlier_data = false, l1d = false;
  int rounds = 1;
  std::vector<std::string> schedules;
  const char* json = nullptr;
  std::string commit = "unknown";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--width" && i + 1 < argc)
      width = std::atoi(argv[++i]);
    else if (a == "--height" && i + 1 < argc)
      height = std::atoi(argv[++i]);
    else if (a == "--threads" && i + 1 < argc)
      only_threads = std::atoi(argv[++i]);
    else if (a == "--feature-only")
      feature_only = true;
    else if (a == "--sweep")
      sweep = true;
    else if (a == "--l2-only")
      l2_only = true;
    else if (a == "--memory")
      memory = true;
    else if (a == "--admm")
      admm = true;
    else if (a == "--pcg")
      pcg = true;
    else if (a == "--pcg-mg")
      pcg = pcg_mg = true;
    else if (a == "--warm")
      warm = true;
    else if (a == "--outlier-data")
      outlier_data = true;
    else if (a == "--l1d")
      l1d = true;
    else if (a == "--rounds" && i + 1 < argc)
      rounds = std::max(1, std::atoi(argv[++i]));
    else if (a == "--json" && i + 1 < argc)
      json = argv[++i];
    else if (a == "--commit" && i + 1 < argc)
      commit = argv[++i];
    else if (a == "--schedules")
      while (i + 1 < argc && argv[i + 1][0] != '-') schedules.push_back(argv[++i]);
    else {
      std::fprintf(stderr,
                   "usage: bench_reconstruct [--width W] [--height H] [--threads N] [--sweep] "
                   "[--l2-only] [--feature-only] [--memory] [--admm] [--pcg] [--pcg-mg] [--warm] "
                   "[--schedules K,F,L[,P[,S]] ... [--rounds N] [--l1d] [--outlier-data]] "
                   "[--json PATH [--commit HASH]]\n");
      return 2;
    }
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress is visible when piped to a file
  const Data d = outlier_data ? make_outlier_data(width, height) : make_data(width, height);
  if (memory) return measure_memory(d, only_threads);
  if (admm) return bench_admm(d, only_threads > 0 ? only_threads : 2);
  if (pcg) return bench_pcg(d, only_threads > 0 ? only_threads : 2, !pcg_mg);
  if (warm) return bench_warm(d, only_threads > 0 ? only_threads : 2, sweep);
  if (!schedules.empty())
    return bench_schedules(d, only_threads > 0 ? only_threads : 2, schedules, rounds, l1d);
  const size_t px = size_t(width) * height;
  gdpt::ReconstructionInput input{
      width, height, d.primal.data(), d.gx.data(), d.gy.data(), d.variance.data(), nullptr};
  const float alpha = 0.2f;
  std::printf("bench_reconstruct: %dx%d RGB, alpha %.2f, FFTW wisdom %s\n", width, height,
              double(alpha), gdpt::detail::fftw_wisdom_path().c_str());

  std::vector<int> thread_counts = {1, 2};
  if (only_threads > 0) thread_counts = {only_threads};
  std::vector<Figures> figures;
  for (int threads : thread_counts) {
    tbb::task_arena arena(threads);
    std::printf("\n== %d thread%s\n", threads, threads > 1 ? "s" : "");
    figures.push_back(Figures{});
    Figures& fig = figures.back();
    fig.threads = threads;
    if (feature_only) {
      bench_feature(width, height, threads, fig);
      continue;
    }

    // --- A float DCT pair for context, then the bare double DCT pair (the solver's plans) and the
    // L2 solve, timed alternately.
    fftwf_init_threads();
    fftwf_plan_with_nthreads(threads);
    float* fplanes = fftwf_alloc_real(3 * px);
    const int n[2] = {height, width};
    const fftwf_r2r_kind k10[2] = {FFTW_REDFT10, FFTW_REDFT10},
                         k01[2] = {FFTW_REDFT01, FFTW_REDFT01};
    fftwf_plan pf = fftwf_plan_many_r2r(2, n, 3, fplanes, nullptr, 1, int(px), fplanes, nullptr, 1,
                                        int(px), k10, FFTW_MEASURE);
    fftwf_plan pi = fftwf_plan_many_r2r(2, n, 3, fplanes, nullptr, 1, int(px), fplanes, nullptr, 1,
                                        int(px), k01, FFTW_MEASURE);
    std::copy(d.primal.begin(), d.primal.end(), fplanes);
    const double t_fdct = median_time(5, [&] {
      fftwf_execute(pf);
      fftwf_execute(pi);
    });
    fftwf_destroy_plan(pf);
    fftwf_destroy_plan(pi);
    fftwf_free(fplanes);

    gdpt::ReconstructionSettings s;
    s.threads = threads;
    s.fft_measure = true;
    s.alpha = alpha;
    s.norm = gdpt::ReconstructionNorm::L2;
    gdpt::ReconstructionReport r2;
    std::vector<float> l2;
    auto planes = gdpt::detail::dct_alloc(3 * px);
    for (size_t i = 0; i < 3 * px; ++i) planes[i] = d.primal[i];
    const auto [t_dct, t_l2] = paired_median_times(
        7,
        [&] {
          arena.execute(
              [&] { gdpt::detail::dct_round_trip(width, height, planes.get(), threads, true); });
        },
        [&] { l2 = gdpt::reconstruct(input, s, &r2); });
    planes.reset();
    std::printf("DCT pair (3 planes, double, FFTW_MEASURE): %8.1f ms\n", 1e3 * t_dct);
    std::printf("DCT pair (3 planes, float,  FFTW_MEASURE): %8.1f ms (context only)\n",
                1e3 * t_fdct);
    std::printf(
        "L2 solve (reconstruct(), incl. I/O passes): %8.1f ms = %.2fx the double DCT pair, "
        "objective %.6g\n",
        1e3 * t_l2, t_l2 / t_dct,
        gdpt::reconstruction_objective(input, gdpt::ReconstructionNorm::L2, alpha, l2.data()));
    if (l2_only) continue;

    // --- L1: ours vs L1D.
    s.norm = gdpt::ReconstructionNorm::L1;
    gdpt::ReconstructionReport r1;
    std::vector<float> l1;
    // Process CPU time (all threads) as well as wall time: on an oversubscribed machine the wall
    // time of a long single run depends on how much of the run the process was descheduled.
    double cpu_l1 = 0, cpu_l1d = 0;
    const double t_l1 = median_time(1, [&] {
      const double c0 = cpu_seconds();
      l1 = gdpt::reconstruct(input, s, &r1);
      cpu_l1 = cpu_seconds() - c0;
    });
    std::vector<float> xd;
    double t_l1d = 0;
    arena.execute([&] {
      t_l1d = median_time(1, [&] {
        const double c0 = cpu_seconds();
        xd = gdpt::test::l1d_reference(d.w, d.h, d.primal.data(), d.gx.data(), d.gy.data(), alpha);
        cpu_l1d = cpu_seconds() - c0;
      });
    });
    const double obj_l1d =
        gdpt::reconstruction_objective(input, gdpt::ReconstructionNorm::L1, alpha, xd.data());
    // Objectives are evaluated outside the timed calls, for L1 as for L1D.
    const double obj_l1 =
        gdpt::reconstruction_objective(input, gdpt::ReconstructionNorm::L1, alpha, l1.data());
    const double obj_l2_as_l1 =
        gdpt::reconstruction_objective(input, gdpt::ReconstructionNorm::L1, alpha, l2.data());
    std::printf(
        "L1D reference (20 x 50 plain CG from primal): %8.1f ms, 1000 iterations, "
        "L1 objective %.8g\n",
        1e3 * t_l1d, obj_l1d);
    std::printf(
        "L1 (%d reweightings x %d->%d Jacobi-PCG steps from L2): %8.1f ms, %d iterations, "
        "L1 objective %.8g (%+.4f%% vs L1D; L2 start %+.3f%%)\n",
        s.l1_reweightings, s.l1_cg_steps_first, s.l1_cg_steps_last, 1e3 * t_l1, r1.iterations,
        obj_l1, 100.0 * (obj_l1 / obj_l1d - 1.0), 100.0 * (obj_l2_as_l1 / obj_l1d - 1.0));
    std::printf(
        "L1 speed-up over L1D: %.2fx (CPU time %.1f s vs %.1f s: %.2fx); rms error to truth: L1 "
        "%.5f, L1D %.5f, L2 %.5f, "
        "primal %.5f\n",
        t_l1d / t_l1, cpu_l1, cpu_l1d, cpu_l1d / cpu_l1, gdpt::test::rms_error(l1, d.truth),
        gdpt::test::rms_error(xd, d.truth), gdpt::test::rms_error(l2, d.truth),
        gdpt::test::rms_error(d.primal, d.truth));

    // --- Weighted.
    s.norm = gdpt::ReconstructionNorm::Weighted;
    gdpt::ReconstructionReport rw;
    std::vector<float> wt;
    const double t_w = median_time(1, [&] { wt = gdpt::reconstruct(input, s, &rw); });
    std::printf(
        "Weighted (Jacobi PCG from L2 to %.0e):      %8.1f ms, %d iterations, residual "
        "%.2e, objective %.6g, rms error %.5f\n",
        s.weighted_tolerance, 1e3 * t_w, rw.iterations, rw.relative_residual,
        gdpt::reconstruction_objective(input, gdpt::ReconstructionNorm::Weighted, alpha, wt.data()),
        gdpt::test::rms_error(wt, d.truth));

    fig.l1_seconds = t_l1;
    fig.l1_objective_vs_l1d = obj_l1 / obj_l1d - 1.0;
    bench_feature(width, height, threads, fig);

    if (sweep) {
      std::printf(
          "L1 schedule sweep (reweightings x PCG steps first -> last): ms, iterations, "
          "objective vs L1D\n");
      for (int k : {20, 30, 36, 40})
        for (auto [first, last] : {std::pair{10, 10}, {12, 3}, {14, 4}, {8, 2}}) {
          gdpt::ReconstructionSettings ss = s;
          ss.norm = gdpt::ReconstructionNorm::L1;
          ss.l1_reweightings = k;
          ss.l1_cg_steps_first = first;
          ss.l1_cg_steps_last = last;
          gdpt::ReconstructionReport rr;
          const auto t0 = Clock::now();
          const auto img = gdpt::reconstruct(input, ss, &rr);
          const double t = seconds_since(t0);
          const double obj = gdpt::reconstruction_objective(input, gdpt::ReconstructionNorm::L1,
                                                            alpha, img.data());
          std::printf("  %2d x %2d -> %2d: %8.1f ms %4d it  %+.4f%%\n", k, first, last, 1e3 * t,
                      rr.iterations, 100.0 * (obj / obj_l1d - 1.0));
        }
    }
  }
  if (json && !write_json(json, commit, width, height, figures)) {
    std::fprintf(stderr, "bench_reconstruct: cannot write %s\n", json);
    return 1;
  }
  return 0;
}
