#include "shaders/ggx_dielectric_albedo.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>

#include "shaders/bsdf_ggx_dielectric.h"

namespace gdpt {

namespace {

constexpr int kMu = 33;          // nodes along mu's coordinate (odd: the critical angle a node)
constexpr int kRoot = 32;        // nodes along sqrt(alpha)
constexpr int kEta = 17;         // nodes along eta (or 1 / eta) in [1, kMaxEta]
constexpr float kMaxEta = 3.0f;  // Blender's IORs beyond are rare; they clamp here
constexpr int kStrata = 32;      // quadrature points per axis of the visible-normal square
constexpr float kMinMu = 1e-4f;  // the mu = 0 node, where the lobe is undefined
// The eta = 1 node: just above the pass-through threshold, so it holds the microfacet lobe.
constexpr float kNearOne = 1.001f;

float node_eta(int k) {
  return k == 0 ? kNearOne : 1.0f + (kMaxEta - 1.0f) * float(k) / float(kEta - 1);
}

// The mu axis. Entering: t = mu. Leaving, with total internal reflection below the critical
// cosine mu_c: [0, mu_c] on t in [0, 1/2] linearly, and [mu_c, 1] on [1/2, 1] by the square root
// of the distance from mu_c, where the Fresnel term falls steeply from 1. Slices of two etas are
// read at the t of the eta looked up, so that their kinks at the critical angle line up.
float critical_cos(bool leaving, float outward_eta) {
  return leaving ? std::sqrt(std::max(0.0f, 1.0f - 1.0f / (outward_eta * outward_eta))) : 0.0f;
}
float mu_of(float t, float mu_c) {
  if (!(mu_c > 0.0f)) return t;
  if (t <= 0.5f) return 2.0f * t * mu_c;
  const float d = 2.0f * t - 1.0f;
  return mu_c + (1.0f - mu_c) * d * d;
}
float t_of(float mu, float mu_c) {
  mu = std::clamp(mu, 0.0f, 1.0f);
  if (!(mu_c > 0.0f)) return mu;
  if (mu <= mu_c) return 0.5f * mu / mu_c;
  return 0.5f + 0.5f * std::sqrt((mu - mu_c) / std::max(1.0f - mu_c, 1e-6f));
}

// The white multiscatter lobe's single-scattering albedo, by midpoint quadrature over its own
// visible-normal sampler: the lobe's formulas, so that the table matches what it renders.
float albedo(float mu, float alpha, float eta) {
  Closure c;
  c.type = ClosureType::GGXDielectric;
  c.fresnel = FresnelMode::Dielectric;
  c.alpha = alpha;
  c.ior = eta;
  c.multiscatter = true;
  const Vec3f wi(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
  double sum = 0.0;
  for (int i = 0; i < kStrata; ++i)
    for (int j = 0; j < kStrata; ++j) {
      const Vec2f u((i + 0.5f) / kStrata, (j + 0.5f) / kStrata);
      sum += ggx_dielectric::single_scattering_albedo_sample(c, wi, u);
    }
  return float(sum / (double(kStrata) * kStrata));
}

// E over (sqrt(alpha), mu) at one eta.
struct Slice {
  std::array<float, kRoot * kMu> e{};  // e[row (sqrt alpha) * kMu + column (mu)]
  std::once_flag ready;

  void fill(float eta, float mu_c) {
    for (int r = 0; r < kRoot; ++r) {
      const float root = float(r) / float(kRoot - 1);
      for (int m = 0; m < kMu; ++m) {
        const float mu = std::max(mu_of(float(m) / float(kMu - 1), mu_c), kMinMu);
        const float alpha = root * root;
        e[r * kMu + m] = is_delta_alpha(alpha) ? 1.0f : albedo(mu, alpha, eta);
      }
    }
  }
};

// Entering (eta >= 1) and leaving (eta < 1) slices; slice k of a side is eta_k or 1 / eta_k.
std::array<Slice, 2 * kEta>& slices() {
  static std::array<Slice, 2 * kEta> s;
  return s;
}

const Slice& slice(bool leaving, int k) {
  Slice& s = slices()[(leaving ? kEta : 0) + k];
  std::call_once(s.ready, [&] {
    const float eta = node_eta(k);
    s.fill(leaving ? 1.0f / eta : eta, critical_cos(leaving, eta));
  });
  return s;
}

// Position x in [0, 1] on an n-node axis: the lower node and the fraction towards the next.
void locate(float x, int n, int& i, float& f) {
  const float p = std::clamp(x, 0.0f, 1.0f) * float(n - 1);
  i = std::min(int(p), n - 2);
  f = p - float(i);
}

float bilinear(const Slice& s, int r, float fr, int m, float fm) {
  const float* a = &s.e[r * kMu + m];
  const float* b = a + kMu;
  const float lo = a[0] + (a[1] - a[0]) * fm, hi = b[0] + (b[1] - b[0]) * fm;
  return lo + (hi - lo) * fr;
}

}  // namespace

float ggx_dielectric_albedo(float mu, float alpha, float eta) {
  const bool leaving = eta < 1.0f;
  const float outward = leaving ? 1.0f / std::max(eta, 1e-6f) : eta;
  // The eta axis: node 0 at kNearOne, then uniform steps to kMaxEta.
  const float step = (kMaxEta - 1.0f) / float(kEta - 1);
  float x = outward <= 1.0f + step
                ? (outward - kNearOne) / (1.0f + step - kNearOne) / float(kEta - 1)
                : (outward - 1.0f) / (kMaxEta - 1.0f);
  int k, r, m;
  float fk, fr, fm;
  locate(x, kEta, k, fk);
  locate(std::sqrt(std::clamp(alpha, 0.0f, 1.0f)), kRoot, r, fr);
  locate(t_of(mu, critical_cos(leaving, std::min(outward, kMaxEta))), kMu, m, fm);
  const float lo = bilinear(slice(leaving, k), r, fr, m, fm);
  const float hi = bilinear(slice(leaving, k + 1), r, fr, m, fm);
  return lo + (hi - lo) * fk;
}

}  // namespace gdpt
