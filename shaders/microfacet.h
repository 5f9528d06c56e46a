// The microfacet distributions of the reflection and dielectric lobes: Microfacet, the one a
// Closure names (GGX or Beckmann, shaders/beckmann.h), AnisoMicrofacet, the same of an anisotropic
// reflection lobe, the isotropic GGX (Trowbridge-Reitz)
// distribution with the separable Smith masking term, and the anisotropic GGX (AnisoGGX, widths
// alpha_x along local x, the tangent, and alpha_y along local y), in the local frame
// (normal = +z), as Cycles 3.4's `microfacet_ggx`.
//
//  alpha: GGX width, Blender roughness^2, clamped to [0, 1] by the caller.
//  D(m):       normal distribution, integrates to 1 over projected microfacet area.
//  G1(w):      Smith masking for direction w (either hemisphere; uses |w.z|).
//  sample_visible(wi, u): microfacet normal from the distribution of normals visible from wi
//              (Heitz 2018, "Sampling the GGX Distribution of Visible Normals"), wi.z > 0;
//              density pdf_visible(wi, m) = G1(wi) max(0, wi.m) D(m) / wi.z.
//  Below kDeltaAlpha the lobe is treated as a perfect mirror / refractor, as Cycles does for
//  alpha_x * alpha_y <= 1e-7.
#pragma once

#include <cmath>

#include "core/vec.h"
#include "scene/node_types.h"
#include "shaders/beckmann.h"

namespace gdpt {

inline constexpr float kDeltaAlpha = 3.1623e-4f;  // sqrt(1e-7)

inline bool is_delta_alpha(float alpha) {
  return alpha < kDeltaAlpha;
}

// GGX's normals visible from wi (Heitz 2018): stretch wi by (ax, ay) to the isotropic hemisphere
// configuration, sample the projected hemisphere there, unstretch.
inline Vec3f sample_ggx_visible(Vec3f wi, float ax, float ay, Vec2f u) {
  const Vec3f vh = normalize(Vec3f(ax * wi.x, ay * wi.y, wi.z));
  // Orthonormal basis around vh (t1 horizontal).
  const float len2 = vh.x * vh.x + vh.y * vh.y;
  const Vec3f t1 =
      len2 > 0.0f ? Vec3f(-vh.y, vh.x, 0.0f) / std::sqrt(len2) : Vec3f(1.0f, 0.0f, 0.0f);
  const Vec3f t2 = cross(vh, t1);
  // Uniform point on the disk, then squash its lower half onto the projected hemisphere.
  const float r = std::sqrt(u.x);
  const float phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  const Vec3f nh = t1 * p1 + t2 * p2 + vh * std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2));
  return normalize(Vec3f(ax * nh.x, ay * nh.y, std::max(1e-7f, nh.z)));
}

struct GGX {
  float alpha;
  float alpha2;

  explicit GGX(float a) : alpha(a), alpha2(a * a) {}

  float D(Vec3f m) const {
    if (m.z <= 0.0f) return 0.0f;
    const float c2 = m.z * m.z;
    // alpha^2 cos^2 + sin^2 = 1 + (alpha^2 - 1) cos^2
    const float t = c2 * (alpha2 - 1.0f) + 1.0f;
    return alpha2 / (kPi * t * t);
  }

  // 2 / (1 + sqrt(1 + alpha^2 tan^2)), rewritten without the tangent so that z -> 0 gives 0.
  float G1(Vec3f w) const {
    const float z = std::fabs(w.z);
    if (z == 0.0f) return 0.0f;
    return 2.0f * z / (z + std::sqrt(alpha2 + (1.0f - alpha2) * z * z));
  }

  float pdf_visible(Vec3f wi, Vec3f m) const {
    const float cos_im = dot(wi, m);
    if (cos_im <= 0.0f || wi.z <= 0.0f) return 0.0f;
    return G1(wi) * cos_im * D(m) / wi.z;
  }

  Vec3f sample_visible(Vec3f wi, Vec2f u) const { return sample_ggx_visible(wi, alpha, alpha, u); }
};

// Anisotropic GGX, the same quantities as GGX with the slope widths alpha_x (x) and alpha_y (y);
// equal widths give GGX's distribution (GGX keeps its own code for the isotropic lobes).
struct AnisoGGX {
  float ax, ay;

  AnisoGGX(float alpha_x, float alpha_y) : ax(alpha_x), ay(alpha_y) {}

  // 1 / (pi ax ay (x^2/ax^2 + y^2/ay^2 + z^2)^2)
  float D(Vec3f m) const {
    if (m.z <= 0.0f) return 0.0f;
    const float sx = m.x / ax, sy = m.y / ay;
    const float t = sx * sx + sy * sy + m.z * m.z;
    return 1.0f / (kPi * ax * ay * t * t);
  }

  // 2 |z| / (|z| + sqrt(z^2 + ax^2 x^2 + ay^2 y^2)): the projected width along w's azimuth.
  float G1(Vec3f w) const {
    const float z = std::fabs(w.z);
    if (z == 0.0f) return 0.0f;
    const float px = ax * w.x, py = ay * w.y;
    return 2.0f * z / (z + std::sqrt(z * z + px * px + py * py));
  }

  float pdf_visible(Vec3f wi, Vec3f m) const {
    const float cos_im = dot(wi, m);
    if (cos_im <= 0.0f || wi.z <= 0.0f) return 0.0f;
    return G1(wi) * cos_im * D(m) / wi.z;
  }

  Vec3f sample_visible(Vec3f wi, Vec2f u) const { return sample_ggx_visible(wi, ax, ay, u); }
};

// A closure's distribution, GGX or Beckmann of one width (Microfacet) or two (AnisoMicrofacet:
// alpha_x along the lobe's tangent, alpha_y across it). The lobes' value is D(h) G1(wi) G1(wo)
// ..., their sampler draws h from the normals visible from wi, of density pdf_visible(wi, h) =
// G1_visible(wi) max(0, wi.h) D(h) / wi.z. G1_visible is G1 for GGX; for Beckmann it is the exact
// Smith term, where the value takes Cycles' rational fit.
template <class Ggx>
class MicrofacetOf {
 public:
  template <class... Widths>
  explicit MicrofacetOf(MicrofacetDistribution d, Widths... alpha)
      : beckmann_(d == MicrofacetDistribution::Beckmann), ggx_(alpha...), bk_(alpha...) {}

  float D(Vec3f m) const { return beckmann_ ? bk_.D(m) : ggx_.D(m); }
  float G1(Vec3f w) const { return beckmann_ ? bk_.G1(w) : ggx_.G1(w); }
  float G1_visible(Vec3f wi) const { return beckmann_ ? bk_.smith_G1(wi) : ggx_.G1(wi); }
  float pdf_visible(Vec3f wi, Vec3f m) const {
    return beckmann_ ? bk_.pdf_visible(wi, m) : ggx_.pdf_visible(wi, m);
  }
  Vec3f sample_visible(Vec3f wi, Vec2f u) const {
    return beckmann_ ? bk_.sample_visible(wi, u) : ggx_.sample_visible(wi, u);
  }

 private:
  bool beckmann_;
  Ggx ggx_;
  Beckmann bk_;
};
using Microfacet = MicrofacetOf<GGX>;
using AnisoMicrofacet = MicrofacetOf<AnisoGGX>;

}  // namespace gdpt
