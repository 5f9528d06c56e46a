// Closures used by the shader tests, built the way the material code builds them.
#pragma once

#include <cmath>
#include <string>

#include "core/vec.h"
#include "shaders/bsdf.h"
#include "shaders/bsdf_ggx_multiscatter.h"
#include "shaders/material.h"
#include "testing/chi2.h"

namespace gdpt::test {

inline Closure lambert(Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::Lambert;
  k.weight = c;
  return k;
}
inline Closure oren_nayar(float sigma, Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::OrenNayar;
  k.weight = c;
  k.alpha = sigma;
  return k;
}
inline Closure principled_diffuse(float roughness, Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::PrincipledDiffuse;
  k.weight = c;
  k.alpha = roughness;
  return k;
}
inline Closure principled_sheen(Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::PrincipledSheen;
  k.weight = c;
  return k;
}
inline Closure ggx(float alpha, Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::GGXReflection;
  k.fresnel = FresnelMode::None;
  k.weight = c;
  k.alpha = alpha;
  return k;
}
// Anisotropic GGX: widths ax along the lobe's tangent, ay across it, the tangent at `angle`
// (radians) from the local x axis.
inline Closure aniso_ggx(float ax, float ay, float angle = 0.0f, Spectrum c = Spectrum(1.0f)) {
  Closure k = ggx(ax, c);
  k.alpha_y = ay;
  k.rotation = Vec2f(std::cos(angle), std::sin(angle));
  return k;
}
inline Closure ggx_principled(float alpha, float ior, Spectrum cspec0) {
  Closure k = ggx(alpha);
  k.fresnel = FresnelMode::PrincipledV1;
  k.ior = ior;
  k.f0 = cspec0;
  return k;
}
// Blender's Multiscatter GGX reflection: the GGX lobe `k` and its multiple-scattering lobe,
// whose colour is the Kulla-Conty factor of `f_avg` (the Glossy colour: no Fresnel).
inline Closure multiscatter_of(const Closure& k, Spectrum f_avg = Spectrum(1.0f)) {
  Closure m;
  m.type = ClosureType::GGXMultiscatter;
  m.alpha = k.alpha;
  m.weight = ggx_multiscatter::multiscatter_fresnel(f_avg, ggx_average_albedo(k.alpha));
  return m;
}
inline Closure clearcoat(float alpha, Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::Clearcoat;
  k.weight = c;
  k.alpha = alpha;
  return k;
}
inline Closure glass(float alpha, float ior, Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::GGXDielectric;
  k.fresnel = FresnelMode::Dielectric;
  k.weight = c;
  k.alpha = alpha;
  k.ior = ior;
  return k;
}
// A Glass lobe (glass) with Blender's Multiscatter GGX: energy-compensated, the added light
// tinted by `tint`.
inline Closure multiscatter_glass(Closure k, Spectrum tint = Spectrum(1.0f)) {
  k.multiscatter = true;
  k.multiscatter_tint = tint;
  return k;
}
// A Glossy or Anisotropic lobe (ggx, aniso_ggx) with Blender's Ashikhmin-Shirley distribution.
inline Closure ashikhmin_shirley(Closure k) {
  k.distribution = MicrofacetDistribution::AshikhminShirley;
  return k;
}
// A Glossy, Glass, Refraction or Anisotropic lobe with Blender's Beckmann distribution instead of
// GGX.
inline Closure beckmann(Closure k) {
  k.distribution = MicrofacetDistribution::Beckmann;
  return k;
}
inline Closure refraction(float alpha, float ior, Spectrum c = Spectrum(1.0f)) {
  Closure k = glass(alpha, ior, c);
  k.fresnel = FresnelMode::RefractionOnly;
  return k;
}
inline Closure transparent(Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::Transparent;
  k.weight = c;
  return k;
}
inline Closure translucent(Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::Translucent;
  k.weight = c;
  return k;
}
inline Closure velvet(float sigma, Spectrum c = Spectrum(1.0f)) {
  Closure k;
  k.type = ClosureType::Velvet;
  k.alpha = sigma;
  k.weight = c;
  return k;
}

// `c` as a lobe that keeps the interpolated normal under a bump (Closure::interpolated_normal).
inline Closure kept(Closure c) {
  c.interpolated_normal = true;
  return c;
}

// The set of `cs`; with `kept` lobes, evaluated about `interpolated` (shading-frame coordinates,
// normalised here) as shading_closures sets them up, the geometric normal +z.
inline ClosureSet set_of(std::initializer_list<Closure> cs,
                         Vec3f interpolated = Vec3f(0.0f, 0.0f, 1.0f)) {
  ClosureSet s;
  bool kept_lobes = false;
  for (const Closure& c : cs) {
    s.add(c);
    kept_lobes |= c.interpolated_normal;
  }
  if (kept_lobes) s.set_interpolated_normal(normalize(interpolated), Vec3f(0.0f, 0.0f, 1.0f));
  return s;
}

// Incident direction with the given cosine, slightly off the x-z plane.
inline Vec3f incident(float cos_theta) {
  const float sin_theta = std::sqrt(std::max(0.0f, 1.0f - cos_theta * cos_theta));
  return Vec3f(sin_theta * std::cos(0.3f), sin_theta * std::sin(0.3f), cos_theta);
}

// Directional albedo of `set` from wi in one channel: the mean sample weight (value / pdf) of
// `samples` draws from a generator seeded with `seed`.
inline double sampled_albedo(const ClosureSet& set, Vec3f wi, int samples, uint64_t seed,
                             int channel = 1) {
  Pcg32 rng(seed);
  double sum = 0.0;
  for (int i = 0; i < samples; ++i) {
    const float ul = rng.uniform();
    const Vec2f u(rng.uniform(), rng.uniform());
    const BsdfSample s = set.sample(wi, ul, u);
    if (s.valid) sum += s.weight()[channel];
  }
  return sum / samples;
}

// The closures of a material made of node n alone, at a fixed UV, seen from the front or back.
inline ClosureSet one_node_closures(const ShaderNode& n, bool front_facing = true) {
  MaterialDesc d;
  d.nodes = {n};
  d.root = 0;
  ClosureSet s;
  Material(d, {}).evaluate(ShadingContext{{0.25f, 0.25f}, front_facing}, s);
  return s;
}

}  // namespace gdpt::test
