// A compiled material: evaluates a MaterialDesc node tree at a hit point into closures.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "scene/material_desc.h"
#include "shaders/bsdf.h"
#include "shaders/shading_context.h"
#include "shaders/texture.h"

namespace gdpt {

// What a material uses; the integrator ORs these over the scene to pick a specialised kernel.
enum MaterialFeature : uint32_t {
  kFeatureTextures = 1u << 0,  // inputs vary over the surface (image textures, colour attributes)
  kFeatureTransmission = 1u << 1,  // glass / principled transmission (refraction)
  kFeatureGlossy = 1u << 2,        // GGX lobes
  kFeatureDelta = 1u << 3,         // smooth glass / transparent
  kFeatureEmission = 1u << 4,
  kFeatureTransparent = 1u << 5,  // transparent BSDF or principled alpha < 1
};

class Material {
 public:
  Material(const MaterialDesc& desc, std::span<const Texture> textures);
  // Default grey diffuse (Blender's default material, colour 0.8).
  Material();

  void evaluate(const ShadingContext& ctx, ClosureSet& out) const;  // BSDF lobes + emission
  // The same closures without a copy: the cached set of a constant material, else `scratch`
  // filled by evaluate(). The reference lives as long as the material or `scratch`.
  const ClosureSet& closures(const ShadingContext& ctx, ClosureSet& scratch) const {
    if (constant_) return constant_closures_[ctx.front_facing ? 1 : 0];
    evaluate(ctx, scratch);
    return scratch;
  }
  Spectrum emission(const ShadingContext& ctx) const;  // emission only, cheaper
  bool is_emissive() const { return (features_ & kFeatureEmission) != 0; }
  // Emission averaged over textures (for sampling emissive triangles by power).
  Spectrum average_emission() const { return average_emission_; }
  uint32_t features() const { return features_; }
  // Normal Map node (NormalMapDesc): the tangent-space direction at a point, strength applied, not
  // normalised (x tangent, y bitangent, z normal).
  bool has_normal_map() const { return normal_map_.enabled; }
  Vec3f normal_map_direction(const ShadingContext& at) const;
  // Bump nodes (MaterialDesc::bumps, in their order): the height of one at a point (the caller
  // differentiates); a vector displacement's (BumpDesc::vector_space) is its vector dotted with
  // `along`, the normal taken into the vector's space.
  const std::vector<BumpDesc>& bumps() const { return bumps_; }
  float bump_height(size_t bump, const ShadingContext& at, Vec3f along = Vec3f(0.0f)) const;
  // Some input reads the mesh's colour attribute (ShadingContext::color).
  bool reads_color_attribute() const { return reads_color_attribute_; }
  // Some texture reads Generated or Object coordinates (ShadingContext::coords).
  bool reads_coordinates() const { return reads_coordinates_; }
  // Some input reads the view of the hit (ShadingContext::geometry: Fresnel, Layer Weight): its
  // closures depend on the incoming direction, so they are never cached per side, and a G-PT
  // offset evaluates them with its own direction.
  bool reads_view() const { return reads_view_; }
  // Some input reads the path (ShadingContext::path: Light Path): closures per hit, never cached.
  bool reads_path() const { return reads_path_; }
  // Some input reads the Geometry node's Pointiness, Parametric or Random Per Island
  // (ShadingContext::attributes).
  bool reads_surface_attributes() const { return reads_surface_attributes_; }
  // The camera Vector Transform's Camera space and Wireframe's pixel size read (set by the
  // scene's owner before rendering; default: at the origin, looking down world +z).
  void set_camera(const ShadingCamera& camera) { camera_ = camera; }
  // The camera it was given: Bump nodes' finite differences step one pixel footprint of it.
  const ShadingCamera& camera() const { return camera_; }

 private:
  void cache_if_constant();

  // Materials without textures or view nodes give the same closures at every hit of a side:
  // evaluated once at load, indexed by front_facing, and copied per hit instead of walking the
  // tree.
  bool constant_ = false;
  ClosureSet constant_closures_[2];
  std::vector<ShaderNode> nodes_;
  std::vector<InputNode> inputs_;  // colour / math nodes of the inputs (MaterialDesc::inputs)
  int32_t root_ = -1;
  std::span<const Texture> textures_;
  uint32_t features_ = 0;
  NormalMapDesc normal_map_;
  std::vector<BumpDesc> bumps_;
  bool reads_color_attribute_ = false;
  bool reads_coordinates_ = false;
  bool reads_view_ = false;
  bool reads_path_ = false;
  bool reads_surface_attributes_ = false;
  Spectrum average_emission_{0.0f, 0.0f, 0.0f};
  ShadingCamera camera_;
};

}  // namespace gdpt
