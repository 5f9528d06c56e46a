// Error against time: PT against G-PT (primal alone, + L2, + L1 reconstruction) at equal render
// time, on the diffuse and the glossy Cornell box of the G-PT tests, against a converged PT
// reference. This is the comparison that decides whether gradient-domain rendering pays: G-PT
// costs about twice PT per sample (bench_gradient), so it must more than halve the error per
// sample to win.
//
// Usage: bench_equal_time [resolution [reference_spp [threads [budgets...]]]]
//        (default 96 8192 2, budgets 0.5 1 2 4 seconds)
// For each budget, PT renders for that wall time; G-PT renders for the budget minus the time its
// L1 reconstruction takes (measured once per scene beforehand), so both columns spend the same
// wall time in all. Error: relMSE = mean over pixels and channels of (I - ref)^2 / (ref^2 + 0.01),
// the per-pixel relative error of the G-PT papers. Run on a quiet machine: the budgets are wall
// time, so other processes shift samples between the two.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "reconstruct/reconstruct.h"
#include "testing/gradient_scenes.h"

using namespace gdpt;
using namespace gdpt::gradient_test;

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Timed {
  Passes passes;
  int spp = 0;
  double seconds = 0.0;
};

Timed render_for(const Scene& scene, RenderSettings::Mode mode, double budget, int threads,
                 uint32_t seed) {
  RenderSettings s = settings(mode, 1 << 20, seed, threads);
  s.samples_per_pass = 1;
  s.time_limit = budget;
  const double t0 = now();
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  Timed t;
  t.seconds = now() - t0;
  t.spp = session.film().min_samples();
  t.passes = read_film(session.film());
  return t;
}

std::vector<float> solve(const Passes& p, ReconstructionNorm norm, int threads, double* seconds) {
  ReconstructionInput in;
  in.width = p.w;
  in.height = p.h;
  in.primal = p.primal.data();
  in.gradient_x = p.dx.data();
  in.gradient_y = p.dy.data();
  ReconstructionSettings rs;
  rs.norm = norm;
  rs.alpha = 0.2f;
  rs.threads = threads;
  const double t0 = now();
  std::vector<float> img = reconstruct(in, rs);
  if (seconds) *seconds = now() - t0;
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  const int res = argc > 1 ? std::atoi(argv[1]) : 96;
  const int ref_spp = argc > 2 ? std::atoi(argv[2]) : 8192;
  const int threads = argc > 3 ? std::atoi(argv[3]) : 2;
  std::vector<double> budgets;
  for (int i = 4; i < argc; ++i) budgets.push_back(std::atof(argv[i]));
  if (budgets.empty()) budgets = {0.5, 1.0, 2.0, 4.0};
  std::printf("bench_equal_time: %dx%d, reference PT %d spp, %d threads, L2/L1 alpha 0.2\n", res,
              res, ref_spp, threads);

  struct Case {
    const char* name;
    Scene scene;
  };
  const Case cases[] = {{"cornell_diffuse", make_scene(SceneKind::CornellDiffuse, res)},
                        {"cornell_glossy_0.3", make_scene(SceneKind::CornellGlossy, res, 0.3f)}};
  for (const Case& c : cases) {
    const double t_ref = now();
    const Passes ref = render(c.scene, settings(RenderSettings::Mode::PT, ref_spp, 99, threads));
    std::printf("\n%s: reference %d spp in %.1f s\n", c.name, ref_spp, now() - t_ref);
    // L1 time at this size, taken from the G-PT budget below (L2 is cheaper: counted as L1).
    double l1_seconds = 0.0;
    solve(render_for(c.scene, RenderSettings::Mode::GPT, 0.2, threads, 7).passes,
          ReconstructionNorm::L1, threads, &l1_seconds);
    std::printf("  %-8s | %-22s | %-44s | %s\n", "budget", "PT: spp, relMSE",
                "G-PT: spp, relMSE primal / +L2 / +L1", "PT relMSE / G-PT+L1 relMSE");
    uint32_t seed = 1;
    for (double b : budgets) {
      const Timed pt = render_for(c.scene, RenderSettings::Mode::PT, b, threads, seed++);
      const Timed g = render_for(c.scene, RenderSettings::Mode::GPT, std::max(0.0, b - l1_seconds),
                                 threads, seed++);
      double t_l1 = 0.0;
      const double e_pt = rel_mse(pt.passes.primal, ref.primal);
      const double e_primal = rel_mse(g.passes.primal, ref.primal);
      const double e_l2 =
          rel_mse(solve(g.passes, ReconstructionNorm::L2, threads, nullptr), ref.primal);
      const double e_l1 =
          rel_mse(solve(g.passes, ReconstructionNorm::L1, threads, &t_l1), ref.primal);
      std::printf(
          "  %5.2f s  | %5d spp %9.3g (%.2fs) | %5d spp %9.3g / %9.3g / %9.3g (%.2fs+%.2fs) | "
          "%.2fx (L2: %.2fx)\n",
          b, pt.spp, e_pt, pt.seconds, g.spp, e_primal, e_l2, e_l1, g.seconds, t_l1, e_pt / e_l1,
          e_pt / e_l2);
      std::fflush(stdout);
    }
  }
  return 0;
}
