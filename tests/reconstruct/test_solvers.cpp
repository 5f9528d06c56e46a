// Exactness and quality of the L2, L1 and variance-weighted solvers against known images.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>

#include "reconstruct/dct_solver.h"
#include "reconstruct/reconstruct.h"
#include "reconstruct/weighted_cg.h"
#include "testing/l1d_reference.h"
#include "testing/test_images.h"

namespace gdpt {
namespace {

using test::add;
using test::exact_gradients;
using test::make_image;
using test::relative_error;
using test::rms_error;
using test::zero_mean_noise;

std::vector<float> random_values(size_t n, unsigned seed, float lo, float hi) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (float& x : v) x = u(rng);
  return v;
}

// |(alpha^2 + Dx^T Dx + Dy^T Dy) x - b| / |b| in double, x in planes, inputs interleaved.
double normal_equation_residual(int w, int h, double alpha, const std::vector<float>& p,
                                const std::vector<float>& gx, const std::vector<float>& gy,
                                const double* planes) {
  const size_t plane = size_t(w) * h;
  double rr = 0, bb = 0;
  for (int c = 0; c < 3; ++c) {
    const double* x = planes + c * plane;
    for (int y = 0; y < h; ++y)
      for (int xx = 0; xx < w; ++xx) {
        const size_t i = size_t(y) * w + xx;
        double ax = alpha * alpha * x[i], b = alpha * alpha * p[3 * i + c];
        if (xx + 1 < w) ax += x[i] - x[i + 1], b -= gx[3 * i + c];
        if (xx > 0) ax += x[i] - x[i - 1], b += gx[3 * (i - 1) + c];
        if (y + 1 < h) ax += x[i] - x[i + w], b -= gy[3 * i + c];
        if (y > 0) ax += x[i] - x[i - w], b += gy[3 * (i - w) + c];
        rr += (ax - b) * (ax - b);
        bb += b * b;
      }
  }
  return std::sqrt(rr / bb);
}

class L2NormalEquations : public ::testing::TestWithParam<std::tuple<int, int, double>> {};

TEST_P(L2NormalEquations, RelativeResidualBelow1em6) {
  const auto [w, h, alpha] = GetParam();
  const size_t n = size_t(w) * h * 3;
  const auto p = random_values(n, 1, 0.f, 10.f);
  const auto gx = random_values(n, 2, -1.f, 1.f);
  const auto gy = random_values(n, 3, -1.f, 1.f);
  auto planes = detail::dct_alloc(n);
  ASSERT_TRUE(
      detail::solve_l2_dct(w, h, alpha, p.data(), gx.data(), gy.data(), planes.get(), false));
  EXPECT_LT(normal_equation_residual(w, h, alpha, p, gx, gy, planes.get()), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Sizes, L2NormalEquations,
                         ::testing::Values(std::make_tuple(64, 48, 0.2),
                                           std::make_tuple(37, 23, 0.2),
                                           std::make_tuple(1, 50, 0.2), std::make_tuple(50, 1, 0.5),
                                           std::make_tuple(1, 1, 0.3),
                                           std::make_tuple(101, 77, 1e-3)));

// Gradients of a known image, primal = image + zero-mean noise, alpha -> 1e-4: the solution is the
// image (only the DC comes from the primal, and the noise has none).
TEST(L2, ExactRecoveryFromTrueGradients) {
  const int w = 80, h = 61;
  const auto truth = make_image(w, h);
  std::vector<float> gx, gy;
  exact_gradients(truth, w, h, gx, gy);
  const auto primal = add(truth, zero_mean_noise(size_t(w) * h, 0.2f, 7));
  ReconstructionInput in{w, h, primal.data(), gx.data(), gy.data(), nullptr, nullptr};
  ReconstructionSettings s;
  s.norm = ReconstructionNorm::L2;
  s.alpha = 1e-4f;
  ReconstructionReport report;
  const auto out = reconstruct(in, s, &report);
  EXPECT_LT(relative_error(out, truth), 1e-4);
  EXPECT_GT(relative_error(primal, truth), 0.05);  // the primal alone is far off
  EXPECT_EQ(report.iterations, 0);                 // direct solve
  EXPECT_EQ(report.objective, 0.0);                // not requested
  s.compute_objective = true;
  const auto again = reconstruct(in, s, &report);
  EXPECT_EQ(again, out);
  EXPECT_NEAR(report.objective,
              reconstruction_objective(in, ReconstructionNorm::L2, s.alpha, out.data()),
              1e-9 * report.objective);
}

// The DCT solve and plain CG from zero on the same uniform system agree: two independent solvers
// of the same normal equations.
TEST(L2, DctAgreesWithConjugateGradients) {
  const int w = 48, h = 40;
  const size_t px = size_t(w) * h;
  const auto truth = make_image(w, h);
  std::vector<float> gx, gy;
  exact_gradients(truth, w, h, gx, gy);
  const auto primal = add(truth, zero_mean_noise(px, 0.3f, 9));
  const auto gx_noisy = add(gx, zero_mean_noise(px, 0.05f, 10));
  ReconstructionInput in{w, h, primal.data(), gx_noisy.data(), gy.data(), nullptr, nullptr};
  ReconstructionSettings s;
  s.norm = ReconstructionNorm::L2;
  const auto direct = reconstruct(in, s);

  const float a2 = s.alpha * s.alpha;
  std::vector<float> w0(px, a2), wx(px, 1.f), wy(px, 1.f);
  for (int y = 0; y < h; ++y) wx[size_t(y) * w + w - 1] = 0.f;
  for (int x = 0; x < w; ++x) wy[size_t(h - 1) * w + x] = 0.f;
  detail::WeightedProblem pb;
  pb.width = w;
  pb.height = h;
  pb.primal = primal.data();
  pb.gradient_x = gx_noisy.data();
  pb.gradient_y = gy.data();
  pb.w0 = w0.data();
  pb.wx = wx.data();
  pb.wy = wy.data();
  std::vector<float> x(px * 3, 0.f);
  detail::CgWorkspace ws;
  const auto cg = detail::solve_weighted_cg(pb, x.data(), 5000, 1e-5, ws);
  EXPECT_LE(cg.relative_residual, 1e-5);
  EXPECT_GT(cg.iterations, 20);
  EXPECT_LT(detail::weighted_relative_residual(pb, x.data()), 2e-5);
  EXPECT_LT(relative_error(x, direct), 1e-4);
  EXPECT_LT(detail::weighted_relative_residual(pb, direct.data()), 1e-5);
}

// Truth with sparse, large outliers in the gradients (fireflies): L1 ignores them, L2 smears them.
TEST(L1, BeatsL2OnSparseOutlierGradients) {
  const int w = 96, h = 64;
  const size_t px = size_t(w) * h;
  const auto truth = make_image(w, h);
  std::vector<float> gx, gy;
  exact_gradients(truth, w, h, gx, gy);
  gx = add(gx, zero_mean_noise(px, 0.01f, 11));
  gy = add(gy, zero_mean_noise(px, 0.01f, 12));
  std::mt19937 rng(13);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  for (size_t i = 0; i < px; ++i) {
    if (u(rng) < 0.02f)
      for (int c = 0; c < 3; ++c) gx[3 * i + c] += 4.f;
    if (u(rng) < 0.02f)
      for (int c = 0; c < 3; ++c) gy[3 * i + c] -= 4.f;
  }
  const auto primal = add(truth, zero_mean_noise(px, 0.2f, 14));
  ReconstructionInput in{w, h, primal.data(), gx.data(), gy.data(), nullptr, nullptr};

  ReconstructionSettings s2;
  s2.norm = ReconstructionNorm::L2;
  const auto l2 = reconstruct(in, s2);
  ReconstructionSettings s1;
  s1.norm = ReconstructionNorm::L1;
  s1.compute_objective = true;
  ReconstructionReport r1;
  const auto l1 = reconstruct(in, s1, &r1);

  const double e1 = rms_error(l1, truth), e2 = rms_error(l2, truth);
  EXPECT_LT(e1, 0.3 * e2) << "L1 rms " << e1 << ", L2 rms " << e2;
  // The reported objective is the L1 objective of the output, and IRLS lowered it from the start.
  const double objective_l2 =
      reconstruction_objective(in, ReconstructionNorm::L1, s1.alpha, l2.data());
  EXPECT_NEAR(r1.objective,
              reconstruction_objective(in, ReconstructionNorm::L1, s1.alpha, l1.data()),
              1e-9 * r1.objective);
  EXPECT_LT(r1.objective, objective_l2);
  int expected_iterations = 0;  // the documented linear schedule
  for (int k = 0; k < s1.l1_reweightings; ++k)
    expected_iterations +=
        int(std::lround(s1.l1_cg_steps_first + double(s1.l1_cg_steps_last - s1.l1_cg_steps_first) *
                                                   k / (s1.l1_reweightings - 1)));
  EXPECT_EQ(r1.iterations, expected_iterations);

  // The default schedule (+0.006%) and the earlier Jacobi-only one (-0.0001%) come within 0.01%
  // of the objective of the reference L1D scheme (20 x 50 CG).
  const auto l1d = test::l1d_reference(w, h, primal.data(), gx.data(), gy.data(), s1.alpha);
  const double objective_l1d =
      reconstruction_objective(in, ReconstructionNorm::L1, s1.alpha, l1d.data());
  EXPECT_LT(r1.objective, objective_l1d * 1.0001)
      << "default " << r1.objective << " L1D " << objective_l1d;
  ReconstructionSettings jacobi = s1;
  use_jacobi_l1_schedule(jacobi);
  ReconstructionReport rj;
  reconstruct(in, jacobi, &rj);
  EXPECT_EQ(rj.iterations, 270);
  EXPECT_LT(rj.objective, objective_l1d * 1.0001)
      << "Jacobi " << rj.objective << " L1D " << objective_l1d;
}

// Noisy primal, noisy gradients with sparse large outliers, and an emission buffer: the L1 case.
struct OutlierScene {
  int w = 128, h = 96;
  std::vector<float> truth, primal, gx, gy, emission;
  OutlierScene() : truth(make_image(w, h)) {
    const size_t px = size_t(w) * h;
    exact_gradients(truth, w, h, gx, gy);
    gx = add(gx, zero_mean_noise(px, 0.02f, 21));
    gy = add(gy, zero_mean_noise(px, 0.02f, 22));
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> u(0.f, 1.f);
    for (size_t i = 0; i < px; ++i)
      for (auto* g : {&gx, &gy})
        if (u(rng) < 0.01f)
          for (int c = 0; c < 3; ++c) (*g)[3 * i + c] += 3.f;
    primal = add(truth, zero_mean_noise(px, 0.2f, 24));
    emission.assign(3 * px, 0.f);
    for (int y = 10; y < 50; ++y)  // a lamp seen directly
      for (int x = 20; x < 60; ++x)
        for (int c = 0; c < 3; ++c) emission[3 * (size_t(y) * w + x) + c] = 2.f;
  }
  ReconstructionInput input() const {
    ReconstructionInput in{w, h, primal.data(), gx.data(), gy.data(), nullptr, emission.data()};
    return in;
  }
  // The output minus the emission (the solution the objective is about).
  std::vector<float> solution(std::vector<float> out) const {
    for (size_t i = 0; i < out.size(); ++i) out[i] -= emission[i];
    return out;
  }
};

// A warm start from the output at another alpha (the compositor node's tweak) reaches the cold
// default's objective, within 0.1% of a tightly converged solve, in fewer inner steps, and an
// image at least as close to the truth.
TEST(L1, WarmStartFromAnotherAlphaConvergesInFewerSteps) {
  const OutlierScene scene;
  const ReconstructionInput in = scene.input();
  ReconstructionSettings s;
  s.norm = ReconstructionNorm::L1;
  s.alpha = 0.2f;
  const auto previous = reconstruct(in, s);  // emission included, as the node keeps it

  s.alpha = 0.25f;
  ReconstructionSettings tight = s;
  tight.l1_reweightings = 72;
  tight.l1_cg_steps_first = 24;
  tight.l1_cg_steps_last = 6;
  tight.l1_preconditioner = L1Preconditioner::Jacobi;
  auto objective = [&](const std::vector<float>& out) {
    return reconstruction_objective(in, ReconstructionNorm::L1, s.alpha,
                                    scene.solution(out).data());
  };
  const double f_tight = objective(reconstruct(in, tight));
  ReconstructionReport cold_report, warm_report;
  const auto cold = reconstruct(in, s, &cold_report);
  ReconstructionInput warm_in = in;
  warm_in.initial = previous.data();
  const auto warm = reconstruct(warm_in, s, &warm_report);

  EXPECT_LT(objective(cold), 1.001 * f_tight);
  EXPECT_LT(objective(warm), 1.001 * f_tight) << "cold " << objective(cold) / f_tight;
  // The cold default's steps are a third multigrid-preconditioned (each costs a few Jacobi ones).
  EXPECT_LT(warm_report.iterations, cold_report.iterations / 3);
  const double e_cold = rms_error(scene.solution(cold), scene.truth);
  const double e_warm = rms_error(scene.solution(warm), scene.truth);
  EXPECT_LT(e_warm, 1.01 * e_cold) << "cold rms " << e_cold;
}

// Solves sharing a scratch (as the Feature norm's do) give the images of solves without one, bit
// for bit, whatever the scratch's buffers hold from earlier solves of other data and sizes.
TEST(Scratch, SharedBySolvesGivesTheSameImagesBitForBit) {
  const OutlierScene scene;
  const ReconstructionInput in = scene.input();
  std::vector<float> variance(scene.primal.size());
  for (size_t i = 0; i < variance.size(); ++i) variance[i] = 0.01f + 0.001f * float(i % 7);
  ReconstructionInput weighted_in = in;
  weighted_in.variance = variance.data();
  ReconstructionSettings l1, jacobi, weighted;
  l1.norm = ReconstructionNorm::L1;
  jacobi = l1;
  use_jacobi_l1_schedule(jacobi);
  jacobi.l1_reweightings = 5;
  weighted.norm = ReconstructionNorm::Weighted;
  const std::pair<const ReconstructionInput*, const ReconstructionSettings*> solves[] = {
      {&in, &l1}, {&weighted_in, &weighted}, {&in, &jacobi}};

  // Other data (scaled, shifted) at a smaller and at the same size leave the buffers dirty.
  const auto scale = [](std::vector<float> v) {
    for (float& x : v) x = 3.f * x + 1.f;
    return v;
  };
  const auto p3 = scale(scene.primal), gx3 = scale(scene.gx), gy3 = scale(scene.gy);
  const ReconstructionInput other{scene.w,    scene.h,         p3.data(), gx3.data(),
                                  gy3.data(), variance.data(), nullptr};
  const ReconstructionInput smaller{scene.w / 2, scene.h,         p3.data(), gx3.data(),
                                    gy3.data(),  variance.data(), nullptr};
  const auto scratch = make_reconstruction_scratch();
  for (const auto& [input, settings] : solves) {
    const auto plain = reconstruct(*input, *settings);
    ReconstructionSettings shared = *settings;
    shared.scratch = scratch;
    reconstruct(smaller, shared);
    reconstruct(other, shared);
    EXPECT_EQ(reconstruct(*input, shared), plain) << int(settings->norm);
  }
}

// Gradient noise 25x larger in the left half: inverse-variance weights beat uniform L2 at any
// alpha.
TEST(Weighted, BeatsUniformL2WithNonUniformGradientVariance) {
  const int w = 96, h = 64;
  const size_t px = size_t(w) * h;
  const auto truth = make_image(w, h);
  std::vector<float> gx, gy;
  exact_gradients(truth, w, h, gx, gy);
  const auto nx = zero_mean_noise(px, 1.f, 21), ny = zero_mean_noise(px, 1.f, 22);
  std::vector<float> variance(px * 3);
  const float sigma_p = 0.1f;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float sigma_g = x < w / 2 ? 0.5f : 0.02f;
      for (int c = 0; c < 3; ++c) {
        gx[3 * i + c] += sigma_g * nx[3 * i + c];
        gy[3 * i + c] += sigma_g * ny[3 * i + c];
      }
      variance[3 * i] = sigma_p * sigma_p;
      variance[3 * i + 1] = variance[3 * i + 2] = sigma_g * sigma_g;
    }
  const auto primal = add(truth, zero_mean_noise(px, sigma_p, 23));
  ReconstructionInput in{w, h, primal.data(), gx.data(), gy.data(), variance.data(), nullptr};

  ReconstructionSettings sw;
  sw.norm = ReconstructionNorm::Weighted;
  sw.alpha = 1.f;  // maximum likelihood
  ReconstructionReport rw;
  const auto weighted = reconstruct(in, sw, &rw);
  EXPECT_LE(rw.relative_residual, sw.weighted_tolerance);
  EXPECT_GT(rw.iterations, 0);
  const double ew = rms_error(weighted, truth);

  double best_l2 = 1e30;
  for (float alpha : {0.05f, 0.1f, 0.2f, 0.4f, 0.8f, 1.6f}) {
    ReconstructionSettings s2;
    s2.norm = ReconstructionNorm::L2;
    s2.alpha = alpha;
    best_l2 = std::min(best_l2, rms_error(reconstruct(in, s2), truth));
  }
  EXPECT_LT(ew, 0.8 * best_l2) << "weighted rms " << ew << ", best uniform L2 rms " << best_l2;

  // From `initial` (the Feature norm starts its Weighted halves there): no step returns the start
  // itself, and the solve to the tolerance reaches the same minimum as from L2.
  const auto start = add(truth, zero_mean_noise(px, 0.05f, 24));
  ReconstructionInput warm = in;
  warm.initial = start.data();
  ReconstructionSettings none = sw;
  none.max_cg_iterations = 0;
  EXPECT_EQ(reconstruct(warm, none), start);
  const auto from_start = reconstruct(warm, sw);
  EXPECT_LT(rms_error(from_start, weighted), 1e-3 * rms_error(start, weighted));
}

}  // namespace
}  // namespace gdpt
