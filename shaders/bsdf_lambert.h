// Lambertian diffuse reflection: f = weight / pi (Blender Diffuse BSDF, roughness 0).
// Cosine-weighted sampling makes sample().weight() exactly the colour.
#pragma once

#include "shaders/closure.h"
#include "shaders/diffuse_sampling.h"
#include "shaders/lobe_util.h"
#include "shaders/sampling.h"

namespace gdpt::lambert {

inline Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo) {
  if (!(wi.z * wo.z > 0.0f)) return Spectrum(0.0f);
  return c.weight * (std::fabs(wo.z) * kInvPi);
}

inline float pdf(const Closure&, Vec3f wi, Vec3f wo) {
  return cosine_lobe_pdf(wi, wo);
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f u) {
  return sample_cosine_lobe(wi, u, [&](Vec3f wo) { return eval(c, wi, wo); });
}

inline float albedo_hint(const Closure&, Vec3f) {
  return 1.0f;
}

}  // namespace gdpt::lambert
