// Cosine-weighted sampling shared by the diffuse lobes (Lambert, Oren-Nayar, Principled
// diffuse): they differ only in their value, so pdf() and sample() live here once. Two-sided as
// every reflection lobe: wo is drawn on wi's side of the surface.
#pragma once

#include <cmath>

#include "shaders/closure.h"
#include "shaders/lobe_util.h"
#include "shaders/sampling.h"

namespace gdpt {

inline float cosine_lobe_pdf(Vec3f wi, Vec3f wo) {
  if (!(wi.z * wo.z > 0.0f)) return 0.0f;
  return std::fabs(wo.z) * kInvPi;
}

// `eval(wo)` is the lobe's f(wi, wo) |cos theta_o| for the sampled direction.
template <typename Eval>
inline BsdfSample sample_cosine_lobe(Vec3f wi, Vec2f u, Eval&& eval) {
  BsdfSample s;
  if (wi.z == 0.0f) return s;
  const Vec3f w = square_to_cosine_hemisphere(u);
  if (w.z <= 0.0f) return s;
  s.wo = flip_z(w, wi.z < 0.0f ? -1.0f : 1.0f);
  s.pdf = w.z * kInvPi;
  s.value = eval(s.wo);
  s.lobe = kLobeReflection | kLobeDiffuse;
  s.roughness = 1.0f;
  s.valid = true;
  return s;
}

}  // namespace gdpt
