// Ashikhmin-Shirley reflection (Ashikhmin and Shirley 2000, "An Anisotropic Phong BRDF Model"),
// the Glossy and Anisotropic BSDFs' Ashikhmin-Shirley option, as Cycles 3.4's
// bsdf_ashikhmin_shirley (without Fresnel), in the lobe's frame (normal +z, tangent +x).
//
//  Widths ax, ay: Blender roughness^2 (split by the anisotropy as for GGX), clamped to
//  [1e-4, 1]; exponents n = 2 / a^2 - 2 (a = 1: half vectors uniform over the hemisphere).
//  Half-vector density p_h(h) = sqrt((nx + 1)(ny + 1)) / (2 pi) cos_h^e, with
//  e = (nx hx^2 + ny hy^2) / (1 - cos_h^2) (e = n when isotropic).
//  f |cos_o| = p_h(h) / (4 |h.wi| max(cos_i, cos_o)) cos_o, pdf = p_h(h) / (4 |h.wi|).
//  So value / pdf = cos_o / max(cos_i, cos_o) <= 1, and f is symmetric in wi and wo.
//  Cycles' sampler reflects wi about -h when h.wi < 0 without normalising; here such samples are
//  reflected about h and fall below the surface (rejected), so the density is exactly pdf.
#pragma once

#include <algorithm>
#include <cmath>

#include "core/vec.h"

namespace gdpt {

struct AshikhminShirley {
  float nx, ny;

  AshikhminShirley(float ax, float ay) : nx(exponent(ax)), ny(exponent(ay)) {}

  static float exponent(float alpha) {
    const float a = std::clamp(alpha, 1e-4f, 1.0f);
    return 2.0f / (a * a) - 2.0f;
  }

  bool isotropic() const { return nx == ny; }

  // cos_h^e, the half vector's lobe without its normalisation. From sin^2 = hx^2 + hy^2 (h unit):
  // near the normal, float cos_h cannot resolve the 1 / e scale of narrow lobes.
  float lobe(Vec3f h) const {
    if (h.z < 1e-6f) return std::pow(1e-6f, exponent_at(h, 1.0f));
    const float sin2 = std::min(h.x * h.x + h.y * h.y, 1.0f - 1e-7f);
    if (!(sin2 > 0.0f)) return 1.0f;
    return std::exp(0.5f * exponent_at(h, sin2) * std::log1p(-sin2));
  }

  // e at h: nx along the tangent, ny across it, mixed by the azimuth.
  float exponent_at(Vec3f h, float sin2) const {
    return isotropic() ? nx : (nx * h.x * h.x + ny * h.y * h.y) / sin2;
  }

  // sqrt((nx + 1)(ny + 1)) / (8 pi): p_h / 4 without the lobe.
  float norm() const { return std::sqrt((nx + 1.0f) * (ny + 1.0f)) / (8.0f * kPi); }

  // f |cos_o| for wi.z, wo.z > 0 and h their half vector, all in the lobe's frame; writes the
  // density of sample().
  float eval_pdf(Vec3f wi, Vec3f wo, Vec3f h, float& pdf) const {
    const float cos_hi = std::max(std::fabs(dot(h, wi)), 1e-6f);
    const float cos_i = std::max(wi.z, 1e-6f), cos_o = std::max(wo.z, 1e-6f);
    const float common = norm() * lobe(h);
    pdf = common / cos_hi;
    return cos_o * common / std::max(1e-6f, cos_hi * std::max(cos_i, cos_o));
  }

  // A half vector of density p_h (upper hemisphere).
  Vec3f sample_normal(Vec2f u) const {
    float phi, e;
    if (isotropic()) {
      phi = 2.0f * kPi * u.x;
      e = nx;
    } else {
      // The first quadrant's azimuth by its CDF, mirrored to the quadrant u.x falls in.
      const int quadrant = std::min(int(u.x * 4.0f), 3);
      float v = u.x * 4.0f - float(quadrant);
      if (quadrant & 1) v = 1.0f - v;
      const float p = std::atan(std::sqrt((nx + 1.0f) / (ny + 1.0f)) * std::tan(0.5f * kPi * v));
      const float c = std::cos(p), s = std::sin(p);
      e = nx * c * c + ny * s * s;
      phi =
          (quadrant & 1) ? float(quadrant + 1) * 0.5f * kPi - p : float(quadrant) * 0.5f * kPi + p;
    }
    // cos_theta = u.y^(1 / (e + 1)), with 1 - cos_theta kept to full precision for narrow lobes.
    const float t = std::log(std::max(u.y, 1e-30f)) / (e + 1.0f);
    const float cos_theta = std::exp(t), one_minus = -std::expm1(t);
    const float sin_theta = std::sqrt(std::max(0.0f, one_minus * (2.0f - one_minus)));
    return Vec3f(sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta);
  }
};

}  // namespace gdpt
