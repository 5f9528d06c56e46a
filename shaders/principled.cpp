#include "shaders/principled.h"

#include <algorithm>
#include <cmath>

#include "shaders/bsdf_ggx_multiscatter.h"
#include "shaders/fresnel.h"

namespace gdpt {

namespace {
// Cycles drops closures lighter than this (CLOSURE_WEIGHT_CUTOFF).
constexpr float kWeightCutoff = 1e-5f;

// The specular lobe's multiple-scattering lobe, coloured by the cosine average of its Fresnel
// colour: cspec0 (1 - fh_avg) + fh_avg, fh_avg that of the normalised dielectric Fresnel.
Closure principled_multiscatter(const Closure& s) {
  constexpr int kSteps = 32;
  const PrincipledFresnel white(s.ior, Spectrum(0.0f));
  float fh = 0.0f;
  for (int i = 0; i < kSteps; ++i) {
    const float mu = (float(i) + 0.5f) / float(kSteps);
    fh += white(mu).x * mu;
  }
  fh *= 2.0f / float(kSteps);
  return ggx_multiscatter::lobe_of(s, s.f0 * (1.0f - fh) + Spectrum(fh), s.weight);
}

}  // namespace

void add_principled_closures(const PrincipledParams& p, float mix_weight, ClosureSet& out) {
  const float alpha = saturate(p.alpha);
  if (alpha < 1.0f) {
    Closure t;
    t.type = ClosureType::Transparent;
    t.weight = Spectrum(mix_weight * (1.0f - alpha));
    out.add(t);
  }
  const float w = mix_weight * alpha;
  if (w <= 0.0f) return;
  out.add_emission(p.emission * w);

  // Cycles mixes without clamping the weight (the socket's range keeps it in [0, 1]).
  const float subsurface = p.subsurface;
  const Spectrum mixed = p.base_color * (1.0f - subsurface) + p.subsurface_color * subsurface;
  const bool ancestor = p.diffuse_ancestor;
  const Spectrum base = ancestor ? mixed : p.base_color;
  const Spectrum diffuse_color = ancestor || subsurface > kWeightCutoff ? mixed : base;
  const float metallic = saturate(p.metallic);
  const float transmission = saturate(p.transmission);
  const float specular = std::max(0.0f, p.specular);
  const float specular_tint = p.specular_tint;
  const float roughness = saturate(p.roughness);
  const float ggx_alpha = roughness * roughness;
  const float diffuse_weight = (1.0f - metallic) * (1.0f - transmission);
  const float final_transmission = transmission * (1.0f - metallic);
  const float specular_weight = 1.0f - final_transmission;

  // --- Diffuse (Burley with retro-reflection; with subsurface, of the mixed colour).
  if (diffuse_weight > kWeightCutoff) {
    Closure d;
    d.type = ClosureType::PrincipledDiffuse;
    d.weight = diffuse_color * (w * diffuse_weight);
    d.alpha = roughness;
    d.interpolated_normal = p.interpolated_normal;
    out.add(d);
  }

  // --- Sheen, with the diffuse (Cycles tints it by the base colour's hue at scene-linear Rec.709
  // luminance, unlike the specular tint below).
  const float sheen = p.sheen;
  if (diffuse_weight > kWeightCutoff && sheen > kWeightCutoff) {
    const float lum = 0.2126729f * base.x + 0.7151522f * base.y + 0.0721750f * base.z;
    const Spectrum hue = lum > 0.0f ? base / lum : Spectrum(1.0f);
    Closure s;
    s.type = ClosureType::PrincipledSheen;
    s.weight = (Spectrum(1.0f - p.sheen_tint) + hue * p.sheen_tint) * (w * sheen * diffuse_weight);
    s.interpolated_normal = p.interpolated_normal;
    out.add(s);
  }

  // --- Specular reflection.
  if (specular_weight > kWeightCutoff && (specular > kWeightCutoff || metallic > kWeightCutoff)) {
    Closure s;
    s.type = ClosureType::GGXReflection;
    s.fresnel = FresnelMode::PrincipledV1;
    s.weight = Spectrum(w * specular_weight);
    s.alpha = ggx_alpha;
    if (p.anisotropic != 0.0f) {
      // Cycles' safe_sqrtf; a zero aspect saturates alpha_x to 1.
      const float aspect = std::sqrt(std::max(0.0f, 1.0f - 0.9f * p.anisotropic));
      s.alpha = saturate(ggx_alpha / aspect);
      s.alpha_y = saturate(ggx_alpha * aspect);
      if (s.alpha == s.alpha_y) s.alpha_y = -1.0f;
      s.tangent = p.tangent;
      s.rotation = p.rotation;
    }
    // F0 = 0.08 specular; keep the IOR finite for specular >= 12.5.
    const float sqrt_f0 = std::min(std::sqrt(0.08f * specular), 0.999f);
    s.ior = 2.0f / (1.0f - sqrt_f0) - 1.0f;
    // Cycles' rough luminance (0.3, 0.6, 0.1) isolates hue and saturation for the tint.
    const float lum = 0.3f * base.x + 0.6f * base.y + 0.1f * base.z;
    const Spectrum hue = lum > 0.0f ? base / lum : Spectrum(1.0f);
    const Spectrum tint = Spectrum(1.0f - specular_tint) + hue * specular_tint;
    s.f0 = saturate(tint * (specular * 0.08f * (1.0f - metallic)) + base * metallic);
    s.interpolated_normal = p.interpolated_normal;
    out.add(s);
    if (p.multiscatter) out.add(principled_multiscatter(s));
  }

  // --- Transmission (GGX glass; reflection part Fresnel-blended, refraction tinted by base).
  if (final_transmission > kWeightCutoff) {
    Closure g;
    g.type = ClosureType::GGXDielectric;
    g.fresnel = FresnelMode::PrincipledV1;
    g.weight = Spectrum(w * final_transmission);
    g.alpha = ggx_alpha;
    const float ior = std::max(p.ior, 1e-5f);
    g.ior = p.front_facing ? ior : 1.0f / ior;
    g.f0 = saturate(base * specular_tint + Spectrum(1.0f - specular_tint));
    g.transmission_tint = base;
    // Cycles keeps the single-scattering glass up to this roughness.
    g.multiscatter = p.multiscatter && roughness > 0.05f;
    g.interpolated_normal = p.interpolated_normal;
    out.add(g);
  }

  // --- Clearcoat (bsdf_clearcoat.h).
  if (p.clearcoat > kWeightCutoff) {
    Closure c;
    c.type = ClosureType::Clearcoat;
    c.weight = Spectrum(w * 0.25f * p.clearcoat);
    c.alpha = saturate(p.clearcoat_roughness * p.clearcoat_roughness);
    c.interpolated_normal = p.clearcoat_interpolated_normal;
    out.add(c);
  }
}

}  // namespace gdpt
