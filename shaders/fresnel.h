// Fresnel terms shared by the specular lobes.
//
//  - fresnel_dielectric(cos_i, eta): unpolarised reflectance of a smooth dielectric interface,
//    eta = n_transmitted / n_incident (the IOR of the far side relative to the near side),
//    cos_i = cosine between the incident direction and the interface normal (sign ignored).
//    Returns 1 under total internal reflection.
//  - PrincipledFresnel: Cycles' Principled v1 "Fresnel colour": the dielectric Fresnel of an IOR
//    is renormalised to [0, 1] (0 at normal incidence, 1 at grazing) and used to blend the
//    specular colour at normal incidence (cspec0) towards white.
#pragma once

#include <cmath>

#include "core/vec.h"

namespace gdpt {

inline float fresnel_dielectric(float cos_i, float eta) {
  const float c = std::fabs(cos_i);
  // Snell: sin_t = sin_i / eta.
  const float sin2_t = (1.0f - c * c) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;  // total internal reflection
  const float cos_t = std::sqrt(1.0f - sin2_t);
  const float r_s = (c - eta * cos_t) / (c + eta * cos_t);
  const float r_p = (eta * c - cos_t) / (eta * c + cos_t);
  return 0.5f * (r_s * r_s + r_p * r_p);
}

// Reflectance at normal incidence, ((eta - 1) / (eta + 1))^2.
inline float fresnel_f0(float eta) {
  const float r = (eta - 1.0f) / (eta + 1.0f);
  return r * r;
}

// Refracts `wi` (pointing away from the surface, on the side m points to: dot(wi, m) > 0) through
// the microfacet normal m with eta = n_t / n_i. Returns false under total internal reflection.
inline bool refract(Vec3f wi, Vec3f m, float eta, Vec3f& wt) {
  const float cos_i = dot(wi, m);
  const float inv_eta = 1.0f / eta;
  const float sin2_t = inv_eta * inv_eta * std::max(0.0f, 1.0f - cos_i * cos_i);
  if (sin2_t >= 1.0f) return false;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  wt = -wi * inv_eta + m * (cos_i * inv_eta - cos_t);
  return true;
}

inline Vec3f reflect(Vec3f wi, Vec3f m) {
  return m * (2.0f * dot(wi, m)) - wi;
}

// Cycles' Principled v1 specular colour: cspec0 at normal incidence, white at grazing, blended by
// the normalised dielectric Fresnel of `ior`. Construct once per closure evaluation.
struct PrincipledFresnel {
  float ior = 1.5f;
  float f0 = 0.04f;        // fresnel_f0(ior), the normalisation offset
  float inv_range = 1.0f;  // 1 / (1 - f0)
  Spectrum cspec0{0.04f};

  PrincipledFresnel(float ior_, Spectrum cspec0_) : ior(ior_), cspec0(cspec0_) {
    f0 = fresnel_f0(ior_);
    inv_range = f0 < 1.0f ? 1.0f / (1.0f - f0) : 0.0f;
  }
  // cos_h: cosine between the outgoing direction and the (micro)facet normal.
  Spectrum operator()(float cos_h) const {
    const float fh = (fresnel_dielectric(cos_h, ior) - f0) * inv_range;
    return cspec0 * (1.0f - fh) + Spectrum(fh);
  }
};

}  // namespace gdpt
