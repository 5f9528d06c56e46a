// "Model only what a scene needs": the feature mask of a scene. At load time the SceneContext ORs
// the material features (shaders/material.h, bits 0-7) and the scene-level features below
// (bits 8+) together; the path tracer picks a kernel specialised for the bits that matter for
// speed.
#pragma once

#include <cstdint>
#include <string>

#include "shaders/material.h"

namespace gdpt {

enum SceneFeature : uint32_t {
  // Bits 0-7 are MaterialFeature (textures, transmission, glossy, delta, emission, transparent).
  kSceneDoF = 1u << 8,              // thin-lens camera (aperture_radius > 0)
  kSceneWorld = 1u << 9,            // non-black world (escaping rays must look it up)
  kSceneWorldImage = 1u << 10,      // equirectangular world image
  kSceneDeltaLights = 1u << 11,     // point / spot of radius 0, sun of angle 0
  kSceneAnalyticLights = 1u << 12,  // lights BSDF rays can hit: sphere, spot sphere, area, sun disc
  kSceneEmissiveTriangles = 1u << 13,  // meshes with emissive materials
  kSceneOrthographic = 1u << 14,
  kSceneInstances = 1u << 15,  // a mesh placed more than once
};

// Every bit, for RenderSettings::force_all_features.
inline constexpr uint32_t kAllFeatures = 0xffffffffu;

// "textures transmission glossy ..." in a fixed order; "none" for the empty mask.
std::string features_to_string(uint32_t features);

}  // namespace gdpt
