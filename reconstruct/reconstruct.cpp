#include "reconstruct/reconstruct.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include "core/huge_pages.h"
#include "reconstruct/dct_solver.h"
#include "reconstruct/feature_reconstruct.h"
#include "reconstruct/irls_reweight.h"
#include "reconstruct/multigrid.h"
#include "reconstruct/parallel.h"
#include "reconstruct/weighted_cg.h"

namespace gdpt {

struct ReconstructionScratch {
  detail::CgWorkspace cg;
  std::vector<std::vector<float>> spare_planes;  // per-pixel planes no solve holds now
};

std::shared_ptr<ReconstructionScratch> make_reconstruction_scratch() {
  return std::make_shared<ReconstructionScratch>();
}

namespace {

using detail::parallel_rows;
using detail::parallel_rows_sum;

// Parameters of the reweighting and weighting schemes (docs/reconstruct.md).
// w = 1 / (|e| + reg); reg decays geometrically from 0.05 to the value the reference L1D scheme
// ends at after its 20 halvings, whatever the number of reweightings: the final reg, not the
// number of CG steps, decides how close IRLS gets to the L1 minimum (bench_reconstruct --sweep).
constexpr double kL1InitialRegulariser = 0.05;
constexpr double kL1FinalRegulariser = 0.05 / 524288.0;  // 0.05 / 2^19
constexpr double kVarianceFloor = 1e-3;                  // variances floored at 1e-3 x their mean

constexpr uint8_t kPrimal = detail::kPrimalTerm, kDx = detail::kDxTerm, kDy = detail::kDyTerm,
                  kAll = detail::kAllTerms;

// Inputs with non-finite values replaced by 0, and which terms of each pixel take part.
struct Prepared {
  int width = 0, height = 0;
  const float* primal = nullptr;
  const float* gradient_x = nullptr;
  const float* gradient_y = nullptr;
  std::vector<float> primal_copy, gx_copy, gy_copy;  // only when something is missing
  std::vector<uint8_t> terms;                        // per pixel TermBits; empty = all present
  int missing = 0;

  uint8_t terms_at(size_t i) const { return terms.empty() ? uint8_t(kAll) : terms[i]; }
};

bool finite3(const float* v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}

// The input as given, assumed finite (the L2 pass checks it; see reconstruct()).
Prepared unchecked(const ReconstructionInput& in) {
  Prepared p;
  p.width = in.width;
  p.height = in.height;
  p.primal = in.primal;
  p.gradient_x = in.gradient_x;
  p.gradient_y = in.gradient_y;
  return p;
}

Prepared prepare(const ReconstructionInput& in, bool need_gradients) {
  Prepared p = unchecked(in);
  const int W = in.width;
  const auto count = parallel_rows_sum<1>(in.height, [&](int y0, int y1, std::array<double, 1>& s) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      s[0] += !finite3(in.primal + 3 * i);
      if (need_gradients) s[0] += !finite3(in.gradient_x + 3 * i) + !finite3(in.gradient_y + 3 * i);
    }
  });
  p.missing = int(count[0]);
  if (p.missing == 0) return p;

  const size_t n = size_t(W) * in.height;
  p.terms.assign(n, kAll);
  auto sanitise = [&](const float* src, std::vector<float>& dst, uint8_t bit) {
    dst.resize(3 * n);
    parallel_rows(in.height, [&](int y0, int y1) {
      for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
        const bool ok = finite3(src + 3 * i);
        for (int c = 0; c < 3; ++c) dst[3 * i + c] = ok ? src[3 * i + c] : 0.f;
        if (!ok) p.terms[i] &= uint8_t(~bit);
      }
    });
  };
  sanitise(in.primal, p.primal_copy, kPrimal);
  p.primal = p.primal_copy.data();
  if (need_gradients) {
    sanitise(in.gradient_x, p.gx_copy, kDx);
    sanitise(in.gradient_y, p.gy_copy, kDy);
    p.gradient_x = p.gx_copy.data();
    p.gradient_y = p.gy_copy.data();
  }
  return p;
}

// Calls body(i, terms, e0, ex, ey, sums) per pixel with the term residuals
//   e0 = I - primal,  ex = Dx I - dx,  ey = Dy I - dy   (RGB; ex / ey zero where absent),
// where `terms` has the Neumann boundary bits cleared; returns the deterministic sum.
template <class Body>
double for_each_term(const Prepared& pr, const float* x, const Body& body) {
  const int W = pr.width, H = pr.height;
  return parallel_rows_sum<1>(H, [&](int y0, int y1, std::array<double, 1>& s) {
    for (int y = y0; y < y1; ++y)
      for (int xx = 0; xx < W; ++xx) {
        const size_t i = size_t(y) * W + xx;
        uint8_t t = pr.terms_at(i);
        if (xx == W - 1) t &= uint8_t(~kDx);
        if (y == H - 1) t &= uint8_t(~kDy);
        float e0[3], ex[3] = {0, 0, 0}, ey[3] = {0, 0, 0};
        for (int c = 0; c < 3; ++c) {
          e0[c] = x[3 * i + c] - pr.primal[3 * i + c];
          if (t & kDx) ex[c] = x[3 * (i + 1) + c] - x[3 * i + c] - pr.gradient_x[3 * i + c];
          if (t & kDy) ey[c] = x[3 * (i + W) + c] - x[3 * i + c] - pr.gradient_y[3 * i + c];
        }
        s[0] += body(i, t, e0, ex, ey);
      }
  })[0];
}

double norm3(const float* e) {
  return std::sqrt(double(e[0]) * e[0] + double(e[1]) * e[1] + double(e[2]) * e[2]);
}
double squared3(const float* e) {
  return double(e[0]) * e[0] + double(e[1]) * e[1] + double(e[2]) * e[2];
}

// A per-pixel float plane (contents unspecified until written), taken from the scratch's spares
// when it has one and given back there when done; without a scratch, a fresh buffer.
class Plane {
 public:
  Plane(size_t n, ReconstructionScratch* scratch) : scratch_(scratch) {
    if (scratch_ && !scratch_->spare_planes.empty()) {
      v_ = std::move(scratch_->spare_planes.back());
      scratch_->spare_planes.pop_back();
      resize_huge(v_, n);
    } else {
      v_ = huge_vector<float>(n);
    }
  }
  Plane(Plane&& o) noexcept : v_(std::move(o.v_)), scratch_(std::exchange(o.scratch_, nullptr)) {}
  Plane& operator=(Plane&&) = delete;
  ~Plane() {
    if (scratch_) scratch_->spare_planes.push_back(std::move(v_));
  }
  float* data() { return v_.data(); }
  const float* data() const { return v_.data(); }
  float& operator[](size_t i) { return v_[i]; }

 private:
  std::vector<float> v_;
  ReconstructionScratch* scratch_;
};

// Per-pixel weights of a quadratic problem (alpha^2 folded into w0).
struct Weights {
  Plane w0, wx, wy;
  Weights(size_t n, ReconstructionScratch* scratch)
      : w0(n, scratch), wx(n, scratch), wy(n, scratch) {}
};

Weights uniform_weights(const Prepared& pr, double alpha, ReconstructionScratch* scratch) {
  const int W = pr.width, H = pr.height;
  Weights w(size_t(W) * H, scratch);
  const float a2 = float(alpha * alpha);
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        const uint8_t t = pr.terms_at(i);
        w.w0[i] = (t & kPrimal) ? a2 : 0.f;
        w.wx[i] = (t & kDx) && x < W - 1 ? 1.f : 0.f;
        w.wy[i] = (t & kDy) && y < H - 1 ? 1.f : 0.f;
      }
  });
  return w;
}

// Inverse-variance weights. Variances are floored at kVarianceFloor x their mean (a zero-variance
// pixel must not get an infinite weight) and every weight is multiplied by that mean, so the
// float weights stay O(1) whatever the image's scale (a common factor does not move the minimum).
struct VarianceScale {
  double mean = 1.0, floor = 1.0;
};

VarianceScale variance_scale(const Prepared& pr, const float* variance) {
  const int W = pr.width;
  const auto s = parallel_rows_sum<2>(pr.height, [&](int y0, int y1, std::array<double, 2>& a) {
    for (size_t i = 3 * size_t(y0) * W; i < 3 * size_t(y1) * W; ++i)
      if (std::isfinite(variance[i]) && variance[i] > 0) {
        a[0] += variance[i];
        a[1] += 1;
      }
  });
  VarianceScale v;
  if (s[1] > 0 && s[0] > 0) v.mean = s[0] / s[1];
  v.floor = kVarianceFloor * v.mean;
  return v;
}

Weights variance_weights(const Prepared& pr, const float* variance, double alpha,
                         const VarianceScale& vs, ReconstructionScratch* scratch) {
  const int W = pr.width, H = pr.height;
  Weights w(size_t(W) * H, scratch);
  auto inverse = [&](float v) {
    return std::isfinite(v) ? float(vs.mean / std::max(double(v), vs.floor)) : 0.f;
  };
  parallel_rows(H, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        const uint8_t t = pr.terms_at(i);
        w.w0[i] = (t & kPrimal) ? float(alpha * alpha) * inverse(variance[3 * i]) : 0.f;
        w.wx[i] = (t & kDx) && x < W - 1 ? inverse(variance[3 * i + 1]) : 0.f;
        w.wy[i] = (t & kDy) && y < H - 1 ? inverse(variance[3 * i + 2]) : 0.f;
      }
  });
  return w;
}

detail::WeightedProblem make_problem(const Prepared& pr, const Weights& w) {
  detail::WeightedProblem pb;
  pb.width = pr.width;
  pb.height = pr.height;
  pb.primal = pr.primal;
  pb.gradient_x = pr.gradient_x;
  pb.gradient_y = pr.gradient_y;
  pb.w0 = w.w0.data();
  pb.wx = w.wx.data();
  pb.wy = w.wy.data();
  return pb;
}

double objective(const Prepared& pr, ReconstructionNorm norm, double alpha, const float* variance,
                 const float* x) {
  switch (norm) {
    case ReconstructionNorm::L1:
      return for_each_term(
          pr, x, [&](size_t, uint8_t t, const float* e0, const float* ex, const float* ey) {
            return ((t & kPrimal) ? alpha * norm3(e0) : 0.0) + norm3(ex) + norm3(ey);
          });
    case ReconstructionNorm::Weighted: {
      const VarianceScale vs = variance_scale(pr, variance);
      auto inverse = [&](float v) {
        return std::isfinite(v) ? 1.0 / std::max(double(v), vs.floor) : 0.0;
      };
      return for_each_term(
          pr, x, [&](size_t i, uint8_t t, const float* e0, const float* ex, const float* ey) {
            return ((t & kPrimal) ? alpha * alpha * inverse(variance[3 * i]) * squared3(e0) : 0.0) +
                   inverse(variance[3 * i + 1]) * squared3(ex) +
                   inverse(variance[3 * i + 2]) * squared3(ey);
          });
    }
    case ReconstructionNorm::L2:
    case ReconstructionNorm::None:
    case ReconstructionNorm::Feature:
      return for_each_term(
          pr, x, [&](size_t, uint8_t t, const float* e0, const float* ex, const float* ey) {
            return ((t & kPrimal) ? alpha * alpha * squared3(e0) : 0.0) + squared3(ex) +
                   squared3(ey);
          });
  }
  return 0.0;
}

void validate(const ReconstructionInput& in, ReconstructionNorm norm, float alpha) {
  if (in.width <= 0 || in.height <= 0)
    throw std::invalid_argument("reconstruct: image size must be positive, got " +
                                std::to_string(in.width) + "x" + std::to_string(in.height));
  if (size_t(in.width) * size_t(in.height) > size_t(std::numeric_limits<int>::max()) / 3)
    throw std::invalid_argument("reconstruct: image too large");
  if (!in.primal) throw std::invalid_argument("reconstruct: primal is required");
  if (norm == ReconstructionNorm::None) return;
  if (!in.gradient_x || !in.gradient_y)
    throw std::invalid_argument("reconstruct: gradient_x and gradient_y are required");
  if (!(alpha > 0.f) || !std::isfinite(alpha))
    throw std::invalid_argument("reconstruct: alpha must be > 0, got " + std::to_string(alpha));
  if (norm == ReconstructionNorm::Weighted && !in.variance)
    throw std::invalid_argument("reconstruct: the Weighted norm needs the variance buffer");
}

// The output rule: solution + emission where the emission is finite; non-finite values become 0.
inline float finish_value(float v, const float* emission, size_t i) {
  if (emission && std::isfinite(emission[i])) v += emission[i];
  return std::isfinite(v) ? v : 0.f;
}

// The exact uniform L2 solution of `pr`, as interleaved float; with `finish` the output rule is
// applied in the same pass (the result is then the final image). Returns an empty vector when
// some input value is not finite: `pr` must then be sanitised (prepare()) and solved again.
std::vector<float> l2_solution(const Prepared& pr, double alpha, bool measure,
                               const float* emission, bool finish) {
  const int W = pr.width, H = pr.height;
  const size_t plane = size_t(W) * H;
  const detail::CachedDctBuffer planes(3 * plane);
  auto x = huge_vector<float>(3 * plane);
  const bool ok = detail::solve_l2_dct_rows(
      W, H, alpha, pr.primal, pr.gradient_x, pr.gradient_y, planes.get(), measure,
      [&](int y, const double* const* rows) {
        const size_t row = size_t(y) * W;
        for (int c = 0; c < 3; ++c) {
          const double* src = rows[c];
          float* dst = x.data() + 3 * row + c;
          if (finish)
            for (int i = 0; i < W; ++i)
              dst[3 * i] = finish_value(float(src[i]), emission, 3 * (row + i) + c);
          else
            for (int i = 0; i < W; ++i) dst[3 * i] = float(src[i]);
        }
      });
  if (!ok) return {};
  return x;
}

// The start of a warm L1 or Weighted solve: input.initial minus the emission, the primal where
// that is not finite.
std::vector<float> warm_start(const Prepared& pr, const ReconstructionInput& in) {
  const int W = pr.width;
  auto x = huge_vector<float>(3 * size_t(W) * pr.height);
  parallel_rows(pr.height, [&](int y0, int y1) {
    for (size_t i = 3 * size_t(y0) * W; i < 3 * size_t(y1) * W; ++i) {
      float v = in.initial[i];
      if (in.emission && std::isfinite(in.emission[i])) v -= in.emission[i];
      x[i] = std::isfinite(v) ? v : pr.primal[i];
    }
  });
  return x;
}

// The reweighting schedule of an L1 solve: count, regulariser range and steps per reweighting.
struct L1Schedule {
  int reweightings = 1;
  double first_reg = kL1InitialRegulariser, last_reg = kL1FinalRegulariser;
  int first_steps = 1, last_steps = 1;

  L1Schedule(const ReconstructionSettings& s, bool warm) {
    if (warm) {
      reweightings = std::max(1, s.l1_warm_reweightings);
      first_reg = std::clamp(s.l1_warm_regulariser, kL1FinalRegulariser, kL1InitialRegulariser);
      first_steps = last_steps = s.l1_warm_cg_steps;
    } else {
      reweightings = std::max(1, s.l1_reweightings);
      first_steps = s.l1_cg_steps_first;
      last_steps = s.l1_cg_steps_last;
    }
    if (reweightings == 1) first_reg = last_reg;
  }
  double decay() const {
    return reweightings > 1 ? std::pow(last_reg / first_reg, 1.0 / (reweightings - 1)) : 1.0;
  }
  // Inner steps fall linearly from first to last: the early reweightings move the image far from
  // the L2 start, the late ones only refine it (bench_reconstruct --sweep).
  int steps(int k) const {
    const int K = reweightings;
    const int n =
        K > 1 ? int(std::lround(first_steps + double(last_steps - first_steps) * k / (K - 1)))
              : first_steps;
    return std::max(1, n);
  }
};

// IRLS: each reweighting solves  min sum w e^2  with w = s^2 / (s |e| + reg) from the current
// iterate (s = alpha for the primal term, 1 for gradients), which majorises the L1 objective.
// One pass forms the weights, the Jacobi diagonal and the CG's starting residual
// (irls_reweight.h); the buffers live across the reweightings. `x` holds the start (the L2
// solution, or a warm start) and receives the result.
template <class Progress>
void solve_l1(const Prepared& pr, const ReconstructionSettings& settings, bool warm,
              std::vector<float>& x, detail::CgWorkspace& ws, ReconstructionReport& rep,
              const Progress& progress) {
  const size_t n = size_t(pr.width) * pr.height;
  Weights w(n, settings.scratch.get());
  Plane inv_diag(n, settings.scratch.get());
  ws.resize(3 * n);
  const detail::IrlsData data{pr.width,      pr.height,
                              pr.primal,     pr.gradient_x,
                              pr.gradient_y, pr.terms.empty() ? nullptr : pr.terms.data(),
                              settings.alpha};
  const detail::IrlsWeights out{w.w0.data(), w.wx.data(), w.wy.data(), inv_diag.data()};
  auto pb = make_problem(pr, w);
  pb.inv_diagonal = inv_diag.data();
  detail::MultigridOptions mg_options;
  mg_options.form = settings.l1_preconditioner == L1Preconditioner::MultigridVCycle
                        ? detail::MultigridOptions::kVCycle
                        : detail::MultigridOptions::kAdditive;
  mg_options.coarse_scale = settings.l1_multigrid_coarse_scale;
  mg_options.edge_scale = settings.l1_multigrid_edge_scale;
  detail::WeightedMultigrid multigrid(mg_options);
  const bool mg = settings.l1_preconditioner != L1Preconditioner::Jacobi;
  const int mg_until = settings.l1_multigrid_reweightings < 0 ? std::numeric_limits<int>::max()
                                                              : settings.l1_multigrid_reweightings;
  const L1Schedule schedule(settings, warm);
  const int K = schedule.reweightings;
  const double decay = schedule.decay();
  double reg = schedule.first_reg;
  for (int k = 0; k < K; ++k, reg *= decay) {
    // |b| only for the last solve, whose exit residual is reported.
    const detail::CgStart start =
        detail::irls_reweight(data, float(reg), x.data(), out, ws.r.data(), k == K - 1);
    // Warm solves stay on Jacobi: their start's weights already spread over orders of magnitude,
    // where multigrid loses (bench_reconstruct --pcg-mg).
    pb.preconditioner = mg && !warm && k < mg_until ? &multigrid : nullptr;
    if (pb.preconditioner) multigrid.build(pb);
    const auto cg =
        detail::solve_weighted_cg_from_residual(pb, x.data(), start, schedule.steps(k), 0.0, ws);
    rep.iterations += cg.iterations;
    rep.relative_residual = cg.relative_residual;
    progress(float(k + 1) / float(K + 1));
  }
}

}  // namespace

double reconstruction_objective(const ReconstructionInput& input, ReconstructionNorm norm,
                                float alpha, const float* image) {
  if (norm == ReconstructionNorm::Feature)
    throw std::invalid_argument("reconstruct: the Feature norm has no objective");
  validate(input, norm == ReconstructionNorm::None ? ReconstructionNorm::L2 : norm, alpha);
  const Prepared pr = prepare(input, true);
  return objective(pr, norm, alpha, input.variance, image);
}

std::vector<float> reconstruct(const ReconstructionInput& input,
                               const ReconstructionSettings& settings,
                               ReconstructionReport* report) {
  if (settings.norm == ReconstructionNorm::Feature)
    return reconstruct_feature(input, settings, report);
  const auto start = std::chrono::steady_clock::now();
  validate(input, settings.norm, settings.alpha);
  const int threads = settings.threads > 0 ? settings.threads : tbb::info::default_concurrency();
  auto progress = [&](float f) {
    if (settings.progress) settings.progress(f);
  };

  const int W = input.width, H = input.height;
  const size_t n = size_t(W) * H;
  const double alpha = settings.alpha;
  ReconstructionReport rep;
  std::vector<float> x;

  tbb::task_arena arena(threads);
  arena.execute([&] {
    const bool gradients = settings.norm != ReconstructionNorm::None;
    progress(0.f);
    // L2 without missing data finishes the output in its last pass, unless the objective (of the
    // solution without emission) is still to be computed.
    const bool finish_in_l2 =
        settings.norm == ReconstructionNorm::L2 && !(settings.compute_objective && input.emission);
    bool finished = false;
    const bool warm = (settings.norm == ReconstructionNorm::L1 ||
                       settings.norm == ReconstructionNorm::Weighted) &&
                      input.initial;
    Prepared pr;
    if (!gradients) {
      pr = prepare(input, false);
      x.assign(input.primal, input.primal + 3 * n);  // non-finite values become 0 below
    } else {
      // Inputs are nearly always finite: the DCT's right-hand side pass checks that, and only
      // when it finds a non-finite value is the data sanitised (prepare) and solved again.
      if (warm) {
        pr = prepare(input, true);
        x = warm_start(pr, input);
      } else {
        pr = unchecked(input);
        x = l2_solution(pr, alpha, settings.fft_measure, input.emission, finish_in_l2);
        finished = finish_in_l2 && !x.empty();
      }
      if (x.empty()) {
        pr = prepare(input, true);
        x = l2_solution(pr, alpha, settings.fft_measure, nullptr, false);
      }
      ReconstructionScratch* const scratch = settings.scratch.get();
      detail::CgWorkspace own_ws;
      detail::CgWorkspace& ws = scratch ? scratch->cg : own_ws;
      if (settings.norm == ReconstructionNorm::L2 && pr.missing > 0) {
        // Missing terms break the DCT's constant coefficients: finish with CG on the masked
        // system from the DCT solution of the zero-filled data.
        const Weights w = uniform_weights(pr, alpha, scratch);
        auto pb = make_problem(pr, w);
        const auto inv_diag = detail::jacobi_inverse_diagonal(pb);
        pb.inv_diagonal = inv_diag.data();
        const auto cg = detail::solve_weighted_cg(pb, x.data(), settings.max_cg_iterations,
                                                  settings.weighted_tolerance, ws);
        rep.iterations = cg.iterations;
        rep.relative_residual = cg.relative_residual;
      } else if (settings.norm == ReconstructionNorm::L1) {
        solve_l1(pr, settings, warm, x, ws, rep, progress);
      } else if (settings.norm == ReconstructionNorm::Weighted) {
        const VarianceScale vs = variance_scale(pr, input.variance);
        const Weights w = variance_weights(pr, input.variance, alpha, vs, scratch);
        auto pb = make_problem(pr, w);
        const auto inv_diag = detail::jacobi_inverse_diagonal(pb);
        pb.inv_diagonal = inv_diag.data();
        const auto cg = detail::solve_weighted_cg(pb, x.data(), settings.max_cg_iterations,
                                                  settings.weighted_tolerance, ws);
        rep.iterations = cg.iterations;
        rep.relative_residual = cg.relative_residual;
      }
    }
    if (gradients && settings.compute_objective)
      rep.objective = objective(pr, settings.norm, alpha, input.variance, x.data());

    // Output = solution + very-direct emission; nothing non-finite leaves this function.
    if (!finished)
      parallel_rows(H, [&](int y0, int y1) {
        for (size_t i = 3 * size_t(y0) * W; i < 3 * size_t(y1) * W; ++i)
          x[i] = finish_value(x[i], input.emission, i);
      });
    rep.missing_values = pr.missing;
    progress(1.f);
  });

  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (report) *report = rep;
  return x;
}

}  // namespace gdpt
