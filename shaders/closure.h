// One BSDF lobe (Closure) and the result of sampling it (BsdfSample): the data every lobe
// implementation (bsdf_*.h) works on. ClosureSet, the weighted sum of lobes a material
// evaluates to, is in bsdf.h.
//
// Conventions (Mitsuba-style):
//  - wi points from the surface towards the previous path vertex, wo towards the next one.
//  - eval() returns f(wi, wo) * |cos theta_o| (the cosine-weighted BSDF value).
//  - pdf() is the solid-angle density of sample() producing wo, including lobe selection.
//  - Delta lobes (smooth glass, mirror, transparent) are never returned by eval()/pdf(); sample()
//    reports them with is_delta = true, value = weight of the discrete choice, pdf = its
//    probability.
//  - roughness() is what the gradient-domain shift uses to classify a vertex: the minimum GGX alpha
//    (or 1 for diffuse lobes) over the non-delta lobes; a sampled delta lobe counts as 0.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/frame.h"
#include "core/vec.h"
#include "scene/node_types.h"

namespace gdpt {

enum class ClosureType : uint8_t {
  Lambert,            // color / pi
  OrenNayar,          // Cycles' Oren-Nayar with sigma = roughness
  PrincipledDiffuse,  // Disney/Burley diffuse as in Cycles' Principled v1
  PrincipledSheen,    // Cycles' Principled v1 sheen (grazing retro-reflection)
  // Microfacet reflection (GGX or Closure::distribution) with the Fresnel mode below (Glossy:
  // none; Principled specular: Schlick mix)
  GGXReflection,
  // The light a GGX reflection lobe (of the same alpha) loses to multiple scattering, returned as
  // a smooth lobe (bsdf_ggx_multiscatter.h): Blender's Multiscatter GGX, reflection
  GGXMultiscatter,
  // Microfacet glass (GGX or Closure::distribution): reflection + refraction by dielectric
  // Fresnel; alpha 0 = smooth
  GGXDielectric,
  Clearcoat,    // Cycles' Principled v1 clearcoat: GTR1, fixed masking, Fresnel of IOR 1.5
  Transparent,  // straight through, delta
  Translucent,  // diffuse transmission: color / pi on the far side
  Velvet,       // Cycles' Ashikhmin velvet, alpha = Sigma
};

enum class FresnelMode : uint8_t {
  None,          // Glossy BSDF: colour only
  Dielectric,    // exact dielectric Fresnel with ior
  PrincipledV1,  // Cycles principled v1: mix(F0 tinted, base colour by metallic) via Schlick weight
  // GGXDielectric without its reflection and without Fresnel on the refraction (Blender's
  // Refraction BSDF, Cycles' refraction-only microfacet / sharp refraction closures).
  RefractionOnly,
};

struct Closure {
  ClosureType type = ClosureType::Lambert;
  FresnelMode fresnel = FresnelMode::None;
  // GGXReflection, GGXDielectric: the microfacet distribution (Blender's Glossy, Glass and
  // Refraction BSDFs offer Beckmann; Principled is GGX; GGXReflection alone may be
  // Ashikhmin-Shirley, isotropic or anisotropic).
  MicrofacetDistribution distribution = MicrofacetDistribution::GGX;
  Spectrum weight{1.0f, 1.0f, 1.0f};  // colour * mix weight
  float alpha = 0.0f;                 // microfacet alpha (= Blender roughness^2); diffuse roughness
  // Anisotropic (GGXReflection, any distribution): alpha is the width along
  // the lobe's tangent, alpha_y along its bitangent; alpha_y < 0: isotropic. The lobe's tangent is
  // local (rotation.x, rotation.y, 0): the shading frame's x axis follows `tangent` (world; the
  // material's Tangent input, neither projected nor rotated: shading_frame() in
  // integrators/common/surface_frame.h), and `rotation` is (cos, sin) of the Anisotropic Rotation
  // about the normal from there. The frame follows the set's first anisotropic lobe; the others
  // are turned to their own tangents per hit (ClosureSet::orient_own_tangents).
  float alpha_y = -1.0f;
  Vec2f rotation{1.0f, 0.0f};
  Vec3f tangent{0.0f, 0.0f, 0.0f};
  // Relative IOR: GGXDielectric: n(below the frame normal) / n(above), i.e. the IOR crossed by
  // a ray arriving with wi.z > 0 (Material sets 1/ior for back-face hits, since the integrators
  // orient the frame towards the ray); PrincipledV1 reflection: the IOR giving its F0.
  float ior = 1.45f;
  Spectrum f0{0.04f, 0.04f, 0.04f};  // PrincipledV1 specular colour at normal incidence
  // GGXDielectric: extra factor on the refracted part only (Principled transmission: base colour;
  // the reflected part is weight * Fresnel colour). Glass BSDF: 1 (its colour is in weight).
  Spectrum transmission_tint{1.0f, 1.0f, 1.0f};
  // The lobe keeps the interpolated normal where the material's normal map or bump tilts the
  // others (a BSDF whose Normal input is unlinked, Principled clearcoat with its Clearcoat Normal
  // unlinked: Cycles gives those sd->N). Material data; per hit, the set evaluates such lobes
  // about that normal (ClosureSet::set_interpolated_normal).
  bool interpolated_normal = false;
  // GGXDielectric: its reflected or its refracted part dropped, the other keeping its Fresnel
  // weight (Cycles' caustics toggles remove one of the glass BSDF's two closures).
  bool drop_reflection = false, drop_refraction = false;
  // GGXDielectric, GGX: Blender's Multiscatter GGX, the lobe divided by its white directional
  // albedo (shaders/ggx_dielectric_albedo.h); the light so added is tinted once more by
  // multiscatter_tint (Glass: its colour, which Cycles' random walk applies at every bounce).
  bool multiscatter = false;
  Spectrum multiscatter_tint{1.0f, 1.0f, 1.0f};
};

inline bool is_anisotropic(const Closure& c) {
  return c.alpha_y >= 0.0f;
}
// The narrower width: what roughness() reports of the lobe.
inline float min_alpha(const Closure& c) {
  return is_anisotropic(c) ? std::min(c.alpha, c.alpha_y) : c.alpha;
}
// The width tested for a perfect mirror: Cycles' alpha_x alpha_y <= 1e-7 (Ashikhmin-Shirley: the
// wider of the two, as Cycles tests max(alpha_x, alpha_y)).
inline float mirror_test_alpha(const Closure& c) {
  if (!is_anisotropic(c)) return c.alpha;
  if (c.distribution == MicrofacetDistribution::AshikhminShirley)
    return std::max(c.alpha, c.alpha_y);
  return std::sqrt(c.alpha * c.alpha_y);
}

enum LobeFlags : uint8_t {
  kLobeReflection = 1 << 0,
  kLobeTransmission = 1 << 1,
  kLobeDiffuse = 1 << 2,
  kLobeGlossy = 1 << 3,
  kLobeDelta = 1 << 4,
};

struct BsdfSample {
  Vec3f wo;                // local frame
  Spectrum value;          // eval(wi, wo) (or the delta weight * pdf for delta lobes)
  float pdf = 0.0f;        // solid angle (or discrete probability for delta lobes)
  float eta = 1.0f;        // relative IOR crossed (1 for reflection)
  float roughness = 1.0f;  // roughness of the sampled lobe (0 for delta)
  uint8_t lobe = 0;        // LobeFlags of the sampled lobe
  bool valid = false;
  bool is_delta() const { return (lobe & kLobeDelta) != 0; }
  // Straight through without refraction (a Transparent closure): Cycles' transparent bounce,
  // which is not a scattering event of the path.
  bool is_straight_crossing() const {
    return is_delta() && (lobe & kLobeTransmission) != 0 && eta == 1.0f;
  }
  Spectrum weight() const { return pdf > 0.0f ? value / pdf : Spectrum(0.0f); }
};

}  // namespace gdpt
