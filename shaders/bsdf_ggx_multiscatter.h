// The multiple-scattering lobe that Blender's Multiscatter GGX adds to a GGX reflection lobe
// (Glossy BSDF, Principled specular): a deterministic energy compensation in the form of Kulla
// and Conty 2017 in place of Cycles 3.4's random walk (Heitz et al. 2016), since G-PT's shifts
// need a value, not an estimate. With E the white lobe's directional albedo (ggx_albedo.h),
//   f |cos_o| = weight (1 - E(cos_i)) (1 - E(cos_o)) / (pi (1 - E_avg)) |cos_o|,
// which reflects 1 - E(cos_i): what the white GGX lobe loses. The material folds the Fresnel
// colour into weight (multiscatter_fresnel). It depends on the two cosines only: a smooth,
// two-sided lobe, sampled cosine-weighted, picked in a set by its albedo 1 - E(cos_i).
#pragma once

#include <algorithm>
#include <cmath>

#include "shaders/closure.h"
#include "shaders/diffuse_sampling.h"
#include "shaders/ggx_albedo.h"
#include "shaders/lobe_util.h"

namespace gdpt::ggx_multiscatter {

// Kulla-Conty's colour of the scattered light: F_avg^2 E_avg / (1 - F_avg (1 - E_avg)), per
// channel; F_avg: the cosine-weighted average of the lobe's Fresnel colour.
inline Spectrum multiscatter_fresnel(Spectrum f_avg, float e_avg) {
  auto channel = [&](float f) {
    const float den = 1.0f - f * (1.0f - e_avg);
    return den > 1e-6f ? f * f * e_avg / den : 0.0f;
  };
  return {channel(f_avg.x), channel(f_avg.y), channel(f_avg.z)};
}

// The width whose albedo table compensates GGX reflection lobe `single`: an anisotropic lobe's
// is the root mean square of its widths, which loses about as much light as the lobe does
// averaged over azimuths (the area's sqrt(alpha_x alpha_y) compensates far too little of a
// narrow-and-wide lobe; white furnace: test_ggx_multiscatter).
inline float compensated_alpha(const Closure& single) {
  if (!is_anisotropic(single)) return single.alpha;
  return std::sqrt(0.5f * (single.alpha * single.alpha + single.alpha_y * single.alpha_y));
}

// The multiple-scattering lobe of GGX reflection lobe `single` whose Fresnel colour averages
// f_avg over the cosine-weighted hemisphere, scaled by `scale`.
inline Closure lobe_of(const Closure& single, Spectrum f_avg, Spectrum scale) {
  Closure m;
  m.type = ClosureType::GGXMultiscatter;
  m.alpha = compensated_alpha(single);
  m.weight = scale * multiscatter_fresnel(f_avg, ggx_average_albedo(m.alpha));
  m.interpolated_normal = single.interpolated_normal;
  return m;
}

inline Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo) {
  if (!(wi.z * wo.z > 0.0f)) return Spectrum(0.0f);
  const float lost = 1.0f - ggx_average_albedo(c.alpha);
  if (!(lost > 1e-6f)) return Spectrum(0.0f);
  const float mi = std::fabs(wi.z), mo = std::fabs(wo.z);
  const float ei = std::max(0.0f, 1.0f - ggx_albedo(mi, c.alpha));
  const float eo = std::max(0.0f, 1.0f - ggx_albedo(mo, c.alpha));
  return c.weight * (ei * eo * mo * kInvPi / lost);
}

inline float pdf(const Closure&, Vec3f wi, Vec3f wo) {
  return cosine_lobe_pdf(wi, wo);
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f u) {
  BsdfSample s = sample_cosine_lobe(wi, u, [&](Vec3f wo) { return eval(c, wi, wo); });
  s.lobe = kLobeReflection | kLobeGlossy;  // light of a glossy closure (Light Path, caustics)
  return s;
}

inline float albedo_hint(const Closure& c, Vec3f wi) {
  return std::max(0.0f, 1.0f - ggx_albedo(std::fabs(wi.z), c.alpha));
}

}  // namespace gdpt::ggx_multiscatter
