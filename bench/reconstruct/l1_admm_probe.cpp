#include "bench/reconstruct/l1_admm_probe.h"

#include <array>
#include <chrono>
#include <cmath>

#include "core/huge_pages.h"
#include "reconstruct/dct_solver.h"
#include "reconstruct/parallel.h"

namespace gdpt::bench {

namespace {

// The state: targets t_k = b_k + z_k - u_k (the next L2 solve's data) and scaled duals u_k,
// interleaved RGB like the inputs; z_k = t_k - b_k + u_k is not stored.
struct State {
  std::vector<float> t0, tx, ty, u0, ux, uy;
  explicit State(size_t values)
      : t0(huge_vector<float>(values)),
        tx(huge_vector<float>(values)),
        ty(huge_vector<float>(values)),
        u0(huge_vector<float>(values)),
        ux(huge_vector<float>(values)),
        uy(huge_vector<float>(values)) {}
};

struct Term {
  float weight;     // s_k in the objective
  float threshold;  // 1 / (rho s_k)
};

inline float norm3f(const float* v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
}

enum class Mode { kStart, kIterate };

// One term of one pixel: e = A I - b of the current image; sums: objective, gradient residual
// sum, gradient term count, primal residual sum.
template <Mode kMode>
void update_term(const float* e, const float* b, float* t, float* u, const Term& term,
                 float relaxation, bool gradient, std::array<double, 4>& s) {
  const float ne = norm3f(e);
  s[0] += double(term.weight) * ne;
  if (gradient) {
    s[1] += ne;
    s[2] += 1.0;
  }
  if constexpr (kMode == Mode::kStart) {
    const float f = ne > 0.f ? term.threshold / ne : 0.f;
    for (int c = 0; c < 3; ++c) {
      u[c] = f * e[c];
      t[c] = b[c] + e[c] - u[c];
    }
    return;
  }
  float v[3], r[3];
  for (int c = 0; c < 3; ++c) {
    const float z_old = t[c] - b[c] + u[c];
    v[c] = relaxation * e[c] + (1.f - relaxation) * z_old + u[c];
  }
  const float nv = norm3f(v);
  const float shrink = nv > term.threshold ? 1.f - term.threshold / nv : 0.f;
  for (int c = 0; c < 3; ++c) {
    const float z = shrink * v[c];
    u[c] = v[c] - z;
    t[c] = b[c] + z - u[c];
    r[c] = e[c] - z;
  }
  s[3] += double(term.weight) * norm3f(r);
}

template <Mode kMode>
std::array<double, 4> update_pass(const AdmmProblem& p, const float* x, State& st,
                                  const Term (&terms)[3], float relaxation) {
  const int W = p.width, H = p.height;
  return detail::parallel_rows_sum<4>(H, [&](int y0, int y1, std::array<double, 4>& s) {
    for (int y = y0; y < y1; ++y)
      for (int xx = 0; xx < W; ++xx) {
        const size_t k = 3 * (size_t(y) * W + xx);
        const float* xi = x + k;
        float e[3];
        for (int c = 0; c < 3; ++c) e[c] = xi[c] - p.primal[k + c];
        update_term<kMode>(e, p.primal + k, &st.t0[k], &st.u0[k], terms[0], relaxation, false, s);
        if (xx < W - 1) {
          for (int c = 0; c < 3; ++c) e[c] = xi[3 + c] - xi[c] - p.gradient_x[k + c];
          update_term<kMode>(e, p.gradient_x + k, &st.tx[k], &st.ux[k], terms[1], relaxation, true,
                             s);
        } else {  // Neumann: not part of the problem (the L2 solve ignores it)
          for (int c = 0; c < 3; ++c) st.tx[k + c] = st.ux[k + c] = 0.f;
        }
        if (y < H - 1) {
          for (int c = 0; c < 3; ++c) e[c] = xi[3 * W + c] - xi[c] - p.gradient_y[k + c];
          update_term<kMode>(e, p.gradient_y + k, &st.ty[k], &st.uy[k], terms[2], relaxation, true,
                             s);
        } else {
          for (int c = 0; c < 3; ++c) st.ty[k + c] = st.uy[k + c] = 0.f;
        }
      }
  });
}

}  // namespace

AdmmResult solve_l1_admm(const AdmmProblem& p, float* x, const AdmmOptions& o) {
  const size_t values = 3 * size_t(p.width) * p.height;
  const float alpha = float(p.alpha), relax = float(o.relaxation);
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  State st(values);
  AdmmResult result;

  // The start's residuals set the scale of the shrinkage (a first pass with zero thresholds).
  Term terms[3] = {{alpha, 0.f}, {1.f, 0.f}, {1.f, 0.f}};
  auto s = update_pass<Mode::kStart>(p, x, st, terms, relax);
  result.objectives.push_back(s[0]);
  result.seconds.push_back(elapsed());
  const double mean_residual = s[2] > 0 ? s[1] / s[2] : 0.0;
  if (!(mean_residual > 0.0)) return result;  // exact already
  const double rho = 1.0 / (o.threshold_per_residual * mean_residual);
  terms[0].threshold = float(1.0 / (rho * alpha));
  terms[1].threshold = terms[2].threshold = float(1.0 / rho);
  update_pass<Mode::kStart>(p, x, st, terms, relax);

  const detail::CachedDctBuffer planes(values);
  const int W = p.width;
  for (int k = 0; k < o.max_iterations; ++k) {
    detail::solve_l2_dct_rows(W, p.height, p.alpha, st.t0.data(), st.tx.data(), st.ty.data(),
                              planes.get(), true, [&](int y, const double* const* rows) {
                                float* dst = x + 3 * size_t(y) * W;
                                for (int c = 0; c < 3; ++c)
                                  for (int i = 0; i < W; ++i) dst[3 * i + c] = float(rows[c][i]);
                              });
    ++result.iterations;
    s = update_pass<Mode::kIterate>(p, x, st, terms, relax);
    const double previous = result.objectives.back();
    result.objectives.push_back(s[0]);
    result.seconds.push_back(elapsed());
    if (o.tolerance > 0 && std::abs(previous - s[0]) <= o.tolerance * s[0] &&
        s[3] <= 10 * o.tolerance * s[0])
      break;
  }
  return result;
}

}  // namespace gdpt::bench
