#include "render/features.h"

namespace gdpt {

std::string features_to_string(uint32_t f) {
  static const struct {
    uint32_t bit;
    const char* name;
  } kNames[] = {
      {kFeatureTextures, "textures"},
      {kFeatureTransmission, "transmission"},
      {kFeatureGlossy, "glossy"},
      {kFeatureDelta, "delta-lobes"},
      {kFeatureEmission, "emission"},
      {kFeatureTransparent, "transparent"},
      {kSceneDoF, "dof"},
      {kSceneWorld, "world"},
      {kSceneWorldImage, "world-image"},
      {kSceneDeltaLights, "delta-lights"},
      {kSceneAnalyticLights, "analytic-lights"},
      {kSceneEmissiveTriangles, "emissive-triangles"},
      {kSceneOrthographic, "orthographic"},
      {kSceneInstances, "instances"},
  };
  std::string s;
  for (const auto& n : kNames)
    if (f & n.bit) {
      if (!s.empty()) s += ' ';
      s += n.name;
    }
  return s.empty() ? "none" : s;
}

}  // namespace gdpt
