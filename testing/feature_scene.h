// A synthetic "room" with known truth for the Feature reconstruction: feature buffers (albedo,
// normal, depth), two independent noisy primal halves, and noisy gradients.
//
// Back wall, floor and a box with two visible faces (normals differ), a checker texture on the
// floor and a painted stripe on the wall (albedo edges), light falling off smoothly from a point
// a hard shadow of the box on the floor and a patch of light through a window on the wall:
// those edges are in no feature, only in the gradients. Rows are bottom-up like every image in
// reconstruct/.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "reconstruct/reconstruct.h"

namespace gdpt::test {

struct FeatureScene {
  int w = 0, h = 0;
  std::vector<float> truth, albedo, normal, depth;  // RGB / XYZ / 1 per pixel
  std::vector<float> a, b, primal, gx, gy;          // noisy halves, their mean, noisy gradients
  std::vector<float> gxa, gxb, gya, gyb;            // the gradients' halves (gx their mean)

  // The reconstruction's input over these buffers (the features left out when `features` is off).
  ReconstructionInput input(bool features = true) const {
    ReconstructionInput in;
    in.width = w;
    in.height = h;
    in.primal = primal.data();
    in.gradient_x = gx.data();
    in.gradient_y = gy.data();
    in.primal_a = a.data();
    in.primal_b = b.data();
    in.gradient_x_a = gxa.data();
    in.gradient_x_b = gxb.data();
    in.gradient_y_a = gya.data();
    in.gradient_y_b = gyb.data();
    if (features) {
      in.albedo = albedo.data();
      in.normal = normal.data();
      in.depth = depth.data();
    }
    return in;
  }
};

inline void add_noise(FeatureScene& s, float sigma_half, float sigma_gradient, unsigned seed);

inline FeatureScene make_feature_scene(int w, int h, float sigma_half, float sigma_gradient,
                                       unsigned seed, bool shadow = true) {
  FeatureScene s;
  s.w = w;
  s.h = h;
  const size_t n = size_t(w) * h;
  s.truth.resize(3 * n);
  s.albedo.resize(3 * n);
  s.normal.resize(3 * n);
  s.depth.resize(n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const size_t i = size_t(y) * w + x;
      const float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
      const bool floor = v < 0.35f;
      const bool box_front = u > 0.55f && u < 0.8f && v > 0.2f && v < 0.55f;
      const bool box_side = !box_front && u >= 0.8f && u < 0.88f && v > 0.23f && v < 0.58f;
      float alb[3], nrm[3], shade, dep;
      if (box_front || box_side) {
        alb[0] = 0.7f, alb[1] = 0.65f, alb[2] = 0.3f;
        nrm[0] = box_side ? 1.f : 0.f, nrm[1] = 0.f, nrm[2] = box_side ? 0.f : 1.f;
        shade = (box_side ? 0.45f : 0.9f) - 0.3f * v;
        dep = 3.f + (box_side ? 0.5f * (u - 0.8f) : 0.f);
      } else if (floor) {
        const bool check = (int(u * 10.f) + int(v * 10.f)) % 2 == 0;
        alb[0] = check ? 0.8f : 0.25f, alb[1] = check ? 0.75f : 0.2f, alb[2] = check ? 0.7f : 0.2f;
        nrm[0] = 0.f, nrm[1] = 1.f, nrm[2] = 0.f;
        const float d2 = (u - 0.3f) * (u - 0.3f) + (v - 0.3f) * (v - 0.3f);
        shade = 1.2f / (1.f + 6.f * d2);
        if (shadow && u > 0.45f && u < 0.75f && v > 0.08f && v < 0.22f) shade *= 0.3f;
        dep = 2.f + 4.f * v;
      } else {
        const bool stripe = v > 0.6f && v < 0.68f;
        alb[0] = stripe ? 0.2f : 0.6f, alb[1] = stripe ? 0.3f : 0.6f,
        alb[2] = stripe ? 0.8f : 0.55f;
        nrm[0] = 0.f, nrm[1] = 0.f, nrm[2] = 1.f;
        const float d2 = (u - 0.3f) * (u - 0.3f) + (v - 0.9f) * (v - 0.9f);
        shade = 0.3f + 0.9f / (1.f + 4.f * d2);
        // Light through a window: illumination detail that no feature has.
        const bool lit = u > 0.1f && u < 0.45f && v > 0.4f && v < 0.9f &&
                         int((u - 0.1f) * 20.f) % 2 == 0 && int((v - 0.4f) * 12.f) % 2 == 0;
        if (shadow && lit) shade += 0.6f;
        dep = 5.f;
      }
      for (int c = 0; c < 3; ++c) {
        s.albedo[3 * i + c] = alb[c];
        s.normal[3 * i + c] = nrm[c];
        s.truth[3 * i + c] = alb[c] * shade;
      }
      s.depth[i] = dep;
    }
  add_noise(s, sigma_half, sigma_gradient, seed);
  return s;
}

// Draws the noisy halves, their mean and the noisy gradients (and their halves) of s.truth.
inline void add_noise(FeatureScene& s, float sigma_half, float sigma_gradient, unsigned seed) {
  const int w = s.w, h = s.h;
  const size_t n = size_t(w) * h;
  std::mt19937 rng(seed);
  std::normal_distribution<float> half(0.f, sigma_half);
  s.a.resize(3 * n);
  s.b.resize(3 * n);
  s.primal.resize(3 * n);
  for (size_t i = 0; i < 3 * n; ++i) {
    s.a[i] = s.truth[i] + half(rng);
    s.b[i] = s.truth[i] + half(rng);
    s.primal[i] = 0.5f * (s.a[i] + s.b[i]);
  }
  // Each gradient half has twice the variance of their mean, as the halves of the primal.
  std::normal_distribution<float> grad_half(0.f, sigma_gradient * std::sqrt(2.f));
  for (auto* g : {&s.gx, &s.gy, &s.gxa, &s.gxb, &s.gya, &s.gyb}) g->assign(3 * n, 0.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = 3 * (size_t(y) * w + x) + c;
        if (x + 1 < w) {
          const float d = s.truth[i + 3] - s.truth[i];
          s.gxa[i] = d + grad_half(rng), s.gxb[i] = d + grad_half(rng);
          s.gx[i] = 0.5f * (s.gxa[i] + s.gxb[i]);
        }
        if (y + 1 < h) {
          const float d = s.truth[i + 3 * size_t(w)] - s.truth[i];
          s.gya[i] = d + grad_half(rng), s.gyb[i] = d + grad_half(rng);
          s.gy[i] = 0.5f * (s.gya[i] + s.gyb[i]);
        }
      }
}

// Mean over pixels and channels of (x - truth)^2 / (truth^2 + 0.01).
inline double relative_mse(const std::vector<float>& x, const std::vector<float>& truth) {
  double sum = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    const double d = double(x[i]) - truth[i];
    sum += d * d / (double(truth[i]) * truth[i] + 0.01);
  }
  return sum / double(x.size());
}

}  // namespace gdpt::test
