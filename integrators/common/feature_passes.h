// The Feature reconstruction's guide passes, per camera sample (Blender's Denoising Albedo /
// Normal names; RenderSettings::feature_passes), by Cycles 3.4's rule for its denoising passes
// (kernel/film/denoising_passes.h):
//  - At each surface of the path, until written: the BSDF closures whose roughness exceeds
//    kFeatureRoughness (GGX alpha; diffuse-like lobes count as rough) are non-specular. When they
//    carry more than a quarter of the closures' weight (or the surface has no BSDF), the surface
//    is the feature hit: Albedo = the feature throughput x the non-specular closures' colour
//    weights (Principled specular lobes scaled by their Fresnel colour at the viewing angle, as
//    Cycles scales them: their weight alone is near 1 whatever they reflect), Normal = the
//    world-space shading normal turned towards the ray. Otherwise the
//    feature throughput is multiplied by the specular closures' weights and the path goes on
//    (through mirrors, glass and transparent surfaces to what they show).
//  - Depth: as Cycles' Denoising Depth, the length of the path up to the feature hit, each segment
//    weighted by the mean feature throughput it was travelled with (through a mirror: the
//    distance to the reflected surface, the depth of the mirror image).
// A path that leaves the scene before a feature hit keeps the albedo and normal 0 and the depth
// it had travelled (0 for a camera ray that meets nothing).
#pragma once

#include "render/embree_scene.h"
#include "scene/render_settings.h"
#include "shaders/bsdf.h"
#include "shaders/bsdf_ggx_reflection.h"

namespace gdpt {

// Cycles' threshold on the specular roughness (its square on roughness^2 = GGX alpha^2).
inline constexpr float kFeatureRoughness = 0.075f;

// One camera sample's values, filled along its path.
struct FeatureSample {
  Spectrum albedo{0.0f};
  Vec3f normal;
  float depth = 0.0f;
  Spectrum throughput{1.0f};  // product of the specular weights crossed so far
  bool done = false;
};

class FeaturePasses {
 public:
  explicit FeaturePasses(const RenderSettings& s) : on_(s.feature_passes) {}

  bool active() const { return on_; }

  // A surface of the path, its material's closures evaluated, reached by a segment of length
  // `segment`; `cos_wi`: |cosine| of the incoming ray with the shading normal.
  void at_surface(const SurfaceHit& hit, const ClosureSet& closures, float segment, float cos_wi,
                  FeatureSample& out) const {
    if (out.done) return;
    out.depth += (out.throughput.x + out.throughput.y + out.throughput.z) / 3.0f * segment;
    Spectrum rough(0.0f), specular(0.0f);
    float rough_weight = 0.0f, total_weight = 0.0f;
    for (int i = 0; i < closures.count(); ++i) {
      const Closure& c = closures[i];
      Spectrum albedo = c.weight;
      if (c.type == ClosureType::GGXReflection) albedo *= ggx_reflection::fresnel(c, cos_wi);
      const float w = (albedo.x + albedo.y + albedo.z) / 3.0f;
      total_weight += w;
      if (is_rough(c)) {
        rough += albedo;
        rough_weight += w;
      } else {
        specular += albedo;
      }
    }
    if (total_weight > 0.0f && 4.0f * rough_weight <= total_weight) {
      out.throughput *= specular;
      return;
    }
    out.albedo = out.throughput * rough;
    out.normal = hit.front_facing ? hit.shading_normal : -hit.shading_normal;
    out.done = true;
  }

 private:
  static bool is_rough(const Closure& c) {
    switch (c.type) {
      case ClosureType::GGXReflection:
      case ClosureType::GGXDielectric:
      case ClosureType::Clearcoat:
        return c.alpha > kFeatureRoughness;
      case ClosureType::Transparent:
        return false;
      default:  // diffuse-like lobes
        return true;
    }
  }

  bool on_;
};

}  // namespace gdpt
