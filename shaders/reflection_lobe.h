// What the two-sided microfacet reflection lobes (bsdf_ggx_reflection.h, bsdf_clearcoat.h)
// share around their own formulas: mirroring wi below the surface to the upper hemisphere
// (lobe_util.h), the half vector of a pair, the perfect mirror below kDeltaAlpha, and sampling
// by reflecting wi about a sampled microfacet normal. Each lobe supplies
//   upper(c, wi, wo, pdf) -> Spectrum   value and density for wi.z, wo.z > 0,
//   density(c, wi, wo, h) -> float      the density alone, given the half vector h,
//   mirror(c, cos_i) -> Spectrum        the perfect mirror's value,
//   normal(c, wi, u) -> Vec3f           a sampled microfacet normal (wi.z > 0).
#pragma once

#include <cmath>

#include "shaders/closure.h"
#include "shaders/fresnel.h"
#include "shaders/lobe_util.h"
#include "shaders/microfacet.h"

namespace gdpt::reflection_lobe {

// The half vector of wi and wo, both in the upper hemisphere; false where it is undefined.
inline bool upper_half_vector(Vec3f wi, Vec3f wo, Vec3f& h) {
  if (!(wi.z > 0.0f && wo.z > 0.0f)) return false;
  const Vec3f sum = wi + wo;
  const float len2 = length_squared(sum);
  if (!(len2 > 0.0f)) return false;
  h = sum / std::sqrt(len2);
  return true;
}

template <class Upper>
Spectrum eval(const Closure& c, Vec3f wi, Vec3f wo, Upper upper) {
  if (is_delta_alpha(mirror_test_alpha(c)) || !(wi.z * wo.z > 0.0f)) return Spectrum(0.0f);
  const MirroredPair p(wi, wo);
  float pdf;
  return upper(c, p.wi, p.wo, pdf);
}

template <class Density>
float pdf(const Closure& c, Vec3f wi, Vec3f wo, Density density) {
  if (is_delta_alpha(mirror_test_alpha(c)) || !(wi.z * wo.z > 0.0f)) return 0.0f;
  const MirroredPair p(wi, wo);
  Vec3f h;
  return upper_half_vector(p.wi, p.wo, h) ? density(c, p.wi, p.wo, h) : 0.0f;
}

template <class Mirror, class Normal, class Upper>
BsdfSample sample(const Closure& c, Vec3f wi_, Vec2f u, Mirror mirror, Normal normal, Upper upper) {
  BsdfSample s;
  if (wi_.z == 0.0f) return s;
  const float sign = wi_.z < 0.0f ? -1.0f : 1.0f;
  const Vec3f wi = flip_z(wi_, sign);
  s.eta = 1.0f;
  if (is_delta_alpha(mirror_test_alpha(c))) {
    s.wo = flip_z(Vec3f(-wi.x, -wi.y, wi.z), sign);
    s.value = mirror(c, wi.z);
    s.pdf = 1.0f;
    s.roughness = 0.0f;
    s.lobe = kLobeReflection | kLobeDelta;
    s.valid = true;
    return s;
  }
  const Vec3f wo = reflect(wi, normal(c, wi, u));
  if (wo.z <= 0.0f) return s;
  s.value = upper(c, wi, wo, s.pdf);
  if (!(s.pdf > 0.0f)) return s;
  s.wo = flip_z(wo, sign);
  s.roughness = min_alpha(c);
  s.lobe = kLobeReflection | kLobeGlossy;
  s.valid = true;
  return s;
}

}  // namespace gdpt::reflection_lobe
