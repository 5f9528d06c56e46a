// Blender 3.4 Principled BSDF v1 (GGX distribution) turned into closures, following the
// CLOSURE_BSDF_PRINCIPLED_ID case of Cycles 3.4 (kernel/svm/closure.h) and the node's expansion
// (emission added, alpha mixed with Transparent):
//   diffuse      PrincipledDiffuse, weight base * (1 - metallic)(1 - transmission)
//   specular     GGXReflection with FresnelMode::PrincipledV1, weight (1 - transmission'),
//                ior_s = 2 / (1 - sqrt(0.08 specular)) - 1 (so F0 = 0.08 specular),
//                cspec0 = 0.08 specular tint (1 - metallic) + base metallic, where
//                tint = mix(1, base / lum_approx(base), specular_tint)
//   transmission GGXDielectric, weight transmission' = transmission (1 - metallic); the reflected
//                part blends mix(1, base, specular_tint) towards white, the refracted part is
//                tinted by base
//   sheen        PrincipledSheen, weight sheen mix(1, base / lum(base), sheen_tint)
//                (1 - metallic)(1 - transmission), lum the scene-linear Rec.709 luminance
//   clearcoat    Clearcoat (GTR1 of alpha clearcoat_roughness^2, the Fresnel of IOR 1.5),
//                weight 0.25 clearcoat; added on top, nothing below is attenuated
//   emission     emission * emission_strength
//   alpha        everything above times alpha, plus Transparent (white) times 1 - alpha
//   subsurface   s > 0 tints the diffuse with mix(base, subsurface_color, s): Cycles' BSSRDF at
//                radius 0 (bssrdf_setup) is its retro-reflection plus a Lambert part of that
//                colour, the whole PrincipledDiffuse; after a diffuse bounce (diffuse_ancestor)
//                Cycles uses that colour as the base of every lobe
// Multiscatter GGX: the specular lobe gets its multiple-scattering lobe, the transmission above
// roughness 0.05 is energy-compensated (Closure::multiscatter), as Cycles switches there.
// Subsurface transport (radius > 0) is not modelled.
// All weights are multiplied by `mix_weight` (the Mix/Add tree weight).
#pragma once

#include "shaders/bsdf.h"

namespace gdpt {

struct PrincipledParams {
  Spectrum base_color{0.8f};
  float metallic = 0.0f;
  float specular = 0.5f;
  float specular_tint = 0.0f;
  float roughness = 0.5f;
  float ior = 1.45f;
  float transmission = 0.0f;
  float sheen = 0.0f;
  float sheen_tint = 0.5f;
  float clearcoat = 0.0f;
  float clearcoat_roughness = 0.03f;
  float alpha = 1.0f;
  // Anisotropic: the specular lobe's widths r^2 / aspect along the tangent and r^2 aspect across,
  // aspect = sqrt(1 - 0.9 anisotropic); tangent (world) and rotation as Closure's.
  float anisotropic = 0.0f;
  Vec3f tangent{0.0f};
  Vec2f rotation{1.0f, 0.0f};
  Spectrum emission{0.0f};  // colour * strength
  float subsurface = 0.0f;
  Spectrum subsurface_color{0.8f};
  bool diffuse_ancestor = false;  // the path has bounced off a diffuse lobe (Cycles' flag)
  bool front_facing = true;  // false: the transmission closure gets 1 / ior (leaving the object)
  // Closure::interpolated_normal of the base lobes and of the clearcoat.
  bool interpolated_normal = false;
  bool clearcoat_interpolated_normal = false;
  // Blender's Multiscatter GGX: the specular lobe gets its multiple-scattering lobe, and above
  // roughness 0.05 the transmission is energy-compensated (Closure::multiscatter).
  bool multiscatter = false;
};

void add_principled_closures(const PrincipledParams& p, float mix_weight, ClosureSet& out);

}  // namespace gdpt
