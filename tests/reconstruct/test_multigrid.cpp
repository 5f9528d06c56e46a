// The multigrid preconditioner of the weighted systems (reconstruct/multigrid.h): its coarse
// operators, its symmetry and definiteness (which CG needs), and solves against Jacobi-PCG.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "reconstruct/multigrid.h"
#include "reconstruct/reconstruct.h"
#include "reconstruct/weighted_cg.h"
#include "testing/test_images.h"

namespace gdpt {
namespace {

// Per-pixel weights log-uniform over 10^[lo, hi], zero on the Neumann column / row.
struct Weights {
  int w, h;
  std::vector<float> w0, wx, wy;
  Weights(int w_, int h_, float lo, float hi, unsigned seed) : w(w_), h(h_) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(lo, hi);
    const size_t px = size_t(w) * h;
    w0.resize(px);
    wx.resize(px);
    wy.resize(px);
    for (size_t i = 0; i < px; ++i) {
      w0[i] = 0.04f * std::pow(10.f, u(rng));
      wx[i] = int(i % w) < w - 1 ? std::pow(10.f, u(rng)) : 0.f;
      wy[i] = int(i / w) < h - 1 ? std::pow(10.f, u(rng)) : 0.f;
    }
  }
  detail::WeightedProblem problem() const {
    detail::WeightedProblem pb;
    pb.width = w;
    pb.height = h;
    pb.w0 = w0.data();
    pb.wx = wx.data();
    pb.wy = wy.data();
    return pb;
  }
};

// A v for one channel, in double, written directly from the definition.
std::vector<double> apply(int W, int H, const float* w0, const float* wx, const float* wy,
                          const std::vector<double>& v) {
  std::vector<double> a(v.size());
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * W + x;
      double s = w0[i] * v[i];
      if (x + 1 < W) s += wx[i] * (v[i] - v[i + 1]);
      if (x > 0) s += wx[i - 1] * (v[i] - v[i - 1]);
      if (y + 1 < H) s += wy[i] * (v[i] - v[i + W]);
      if (y > 0) s += wy[i - W] * (v[i] - v[i - W]);
      a[i] = s;
    }
  return a;
}

std::vector<float> random_vector(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> g(0.f, 1.f);
  std::vector<float> v(n);
  for (float& x : v) x = g(rng);
  return v;
}

double dot(const std::vector<float>& a, const std::vector<float>& b) {
  double s = 0;
  for (size_t i = 0; i < a.size(); ++i) s += double(a[i]) * b[i];
  return s;
}

// With edge scale 1 the coarse operator is P^T A P (P: constant on 2x2 blocks), odd and even
// sizes; edge scale 0.5 halves exactly the coarse edges.
TEST(Multigrid, CoarseOperatorIsGalerkin) {
  for (auto [W, H] : {std::pair{13, 9}, std::pair{12, 8}, std::pair{1, 7}}) {
    const Weights f(W, H, -3.f, 3.f, 3);
    const int wc = (W + 1) / 2, hc = (H + 1) / 2;
    std::vector<float> c0(size_t(wc) * hc), cx(c0.size()), cy(c0.size());
    detail::coarsen_weights(W, H, f.w0.data(), f.wx.data(), f.wy.data(), 1.f, c0.data(), cx.data(),
                            cy.data());
    std::mt19937 rng(4);
    std::normal_distribution<double> g(0.0, 1.0);
    std::vector<double> vc(c0.size()), pv(size_t(W) * H);
    for (double& v : vc) v = g(rng);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) pv[size_t(y) * W + x] = vc[size_t(y / 2) * wc + x / 2];
    const auto apv = apply(W, H, f.w0.data(), f.wx.data(), f.wy.data(), pv);
    std::vector<double> galerkin(vc.size(), 0.0);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) galerkin[size_t(y / 2) * wc + x / 2] += apv[size_t(y) * W + x];
    const auto coarse = apply(wc, hc, c0.data(), cx.data(), cy.data(), vc);
    double err = 0, norm = 0;
    for (size_t i = 0; i < vc.size(); ++i) {
      err = std::max(err, std::abs(coarse[i] - galerkin[i]));
      norm = std::max(norm, std::abs(galerkin[i]));
    }
    EXPECT_LT(err, 1e-5 * norm) << W << "x" << H;

    std::vector<float> h0(c0.size()), hx(c0.size()), hy(c0.size());
    detail::coarsen_weights(W, H, f.w0.data(), f.wx.data(), f.wy.data(), 0.5f, h0.data(), hx.data(),
                            hy.data());
    for (size_t i = 0; i < c0.size(); ++i) {
      EXPECT_EQ(h0[i], c0[i]);
      EXPECT_EQ(hx[i], 0.5f * cx[i]);
      EXPECT_EQ(hy[i], 0.5f * cy[i]);
    }
  }
}

// <M x, y> = <x, M y> and <M x, x> > 0 on random vectors, for both forms and both coarse edge
// scales, with weights over six orders of magnitude (CG needs M symmetric positive definite);
// apply() returns <r_c, z_c>.
TEST(Multigrid, PreconditionerIsSymmetricPositiveDefinite) {
  const int W = 45, H = 31;
  const Weights f(W, H, -3.f, 3.f, 5);
  const auto pb = f.problem();
  const size_t n = size_t(W) * H * 3;
  for (auto form : {detail::MultigridOptions::kAdditive, detail::MultigridOptions::kVCycle})
    for (float edges : {0.5f, 1.f}) {
      detail::MultigridOptions o;
      o.form = form;
      o.edge_scale = edges;
      detail::WeightedMultigrid mg(o);
      mg.build(pb);
      EXPECT_EQ(mg.levels(), 4);  // 45x31, 23x16, 12x8, 6x4 (at most 64 pixels)
      for (unsigned seed = 0; seed < 4; ++seed) {
        const auto x = random_vector(n, 10 + seed), y = random_vector(n, 20 + seed);
        std::vector<float> mx(n), my(n);
        const auto rz = mg.apply(x.data(), mx.data());
        mg.apply(y.data(), my.data());
        const double a = dot(mx, y), b = dot(x, my);
        EXPECT_LT(std::abs(a - b), 1e-5 * std::sqrt(dot(mx, mx) * dot(y, y)))
            << "form " << form << " edges " << edges;
        EXPECT_GT(dot(mx, x), 0.0);
        double by_channel[3] = {};
        for (size_t i = 0; i < n; ++i) by_channel[i % 3] += double(x[i]) * mx[i];
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(rz[c], by_channel[c], 1e-9 * std::abs(rz[c]));
      }
    }
}

// IRLS-like weights (1 / (|e| + reg), |e| spread by sparse outliers): the system solved to a
// residual of 1e-5 with multigrid PCG matches the Jacobi-PCG solution, in fewer steps.
TEST(Multigrid, SolveMatchesJacobiInFewerSteps) {
  const int W = 160, H = 96;
  const size_t px = size_t(W) * H;
  const auto truth = test::make_image(W, H);
  std::vector<float> gx, gy;
  test::exact_gradients(truth, W, H, gx, gy);
  const auto primal = test::add(truth, test::zero_mean_noise(px, 0.2f, 7));
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<float> w0(px), wx(px), wy(px);
  for (size_t i = 0; i < px; ++i) {
    auto weight = [&](float scale) {
      const float e = u(rng) < 0.02f ? 4.f : 0.01f * u(rng);  // outlier or a small residual
      return scale / (e + 0.005f);
    };
    w0[i] = weight(0.04f);
    wx[i] = int(i % W) < W - 1 ? weight(1.f) : 0.f;
    wy[i] = int(i / W) < H - 1 ? weight(1.f) : 0.f;
  }
  detail::WeightedProblem pb;
  pb.width = W;
  pb.height = H;
  pb.primal = primal.data();
  pb.gradient_x = gx.data();
  pb.gradient_y = gy.data();
  pb.w0 = w0.data();
  pb.wx = wx.data();
  pb.wy = wy.data();
  const auto inv = detail::jacobi_inverse_diagonal(pb);
  pb.inv_diagonal = inv.data();
  detail::CgWorkspace ws;
  std::vector<float> jacobi(primal);
  const auto cj = detail::solve_weighted_cg(pb, jacobi.data(), 5000, 1e-5, ws);
  EXPECT_LE(cj.relative_residual, 1e-5);
  for (auto form : {detail::MultigridOptions::kAdditive, detail::MultigridOptions::kVCycle}) {
    detail::MultigridOptions o;
    o.form = form;
    detail::WeightedMultigrid mg(o);
    mg.build(pb);
    auto pm = pb;
    pm.preconditioner = &mg;
    std::vector<float> x(primal);
    const auto cm = detail::solve_weighted_cg(pm, x.data(), 5000, 1e-5, ws);
    EXPECT_LE(cm.relative_residual, 1e-5);
    EXPECT_LT(detail::weighted_relative_residual(pb, x.data()), 2e-5);
    EXPECT_LT(test::relative_error(x, jacobi), 1e-4) << "form " << form;
    EXPECT_LT(cm.iterations, cj.iterations / 2)
        << "form " << form << ": " << cm.iterations << " steps, Jacobi " << cj.iterations;
  }
}

// L1 with the multigrid preconditioner gives the same bits on one and two threads, also when it
// hands over to Jacobi after some reweightings; with multigrid for none, L1 is the Jacobi one.
TEST(Multigrid, L1SameResultOnOneAndTwoThreads) {
  const int w = 150, h = 70;
  const auto truth = test::make_image(w, h);
  std::vector<float> gx, gy;
  test::exact_gradients(truth, w, h, gx, gy);
  const auto primal = test::add(truth, test::zero_mean_noise(size_t(w) * h, 0.3f, 5));
  ReconstructionInput in{w, h, primal.data(), gx.data(), gy.data(), nullptr, nullptr};
  for (auto p : {L1Preconditioner::MultigridAdditive, L1Preconditioner::MultigridVCycle}) {
    ReconstructionSettings s;
    s.norm = ReconstructionNorm::L1;
    s.l1_preconditioner = p;
    s.threads = 1;
    const auto one = reconstruct(in, s);
    s.threads = 2;
    EXPECT_EQ(one, reconstruct(in, s));
    s.l1_multigrid_reweightings = 18;
    const auto part = reconstruct(in, s);
    EXPECT_NE(part, one);
    s.threads = 1;
    EXPECT_EQ(part, reconstruct(in, s));
    s.l1_multigrid_reweightings = 0;
    ReconstructionSettings jacobi;
    jacobi.norm = ReconstructionNorm::L1;
    jacobi.l1_preconditioner = L1Preconditioner::Jacobi;
    EXPECT_EQ(reconstruct(in, s), reconstruct(in, jacobi));
  }
}

}  // namespace
}  // namespace gdpt
