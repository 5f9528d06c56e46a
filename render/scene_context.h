// Everything an integrator needs about a scene, built once per render session: the Embree BVH,
// the camera model, textures, compiled materials, the light sampler and the feature mask. PT and
// G-PT both receive a const SceneContext; nothing in it changes while rendering.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "render/camera.h"
#include "render/embree_scene.h"
#include "render/film.h"
#include "render/light_sampler.h"
#include "render/pixel_filter.h"
#include "scene/render_settings.h"
#include "scene/scene.h"
#include "shaders/material.h"
#include "shaders/texture.h"

namespace gdpt {

// Cycles' default transparent_max_bounces: transparent crossings a path or shadow ray may make.
constexpr int kMaxTransparentBounces = 8;

// The kind of a BSDF-sampled ray (RayKind) from the lobe it was sampled from, as Cycles labels
// it: transmission, else diffuse, else glossy (delta reflections included).
inline uint32_t ray_kind_of_lobe(uint32_t lobe) {
  if (lobe & kLobeTransmission) return kRayTransmission;
  return (lobe & kLobeDiffuse) ? kRayDiffuse : kRayGlossy;
}

// Throws std::invalid_argument with a clear message for an unusable scene; appends non-fatal
// problems to `warnings`.
void validate_scene(const Scene& scene, std::vector<std::string>& warnings);
// Whether the BVH of `a` serves `b`: equal meshes (their data), instances placing them alike
// (mesh, transform, slot materials, ray visibility, holdout) and the same material count.
bool same_geometry(const Scene& a, const Scene& b);

class SceneContext {
 public:
  // Validates and prepares `scene` (which must outlive the context). Throws std::invalid_argument
  // with a clear message for an unusable scene (zero resolution, out-of-range mesh indices, ...).
  SceneContext(const Scene& scene, const RenderSettings& settings);
  ~SceneContext();
  // Replaces the camera (the viewport's view moved), keeping the BVH, lights and materials.
  // Throws std::invalid_argument for an unusable camera. Not while an integrator renders.
  void set_camera(const Camera& camera);
  // Rebuilds textures, materials, lights and the feature mask from the scene (whose lights,
  // materials, images, world or camera the owner changed), keeping the BVH: the scene's meshes,
  // instance placements and slot tables and its material count must be those the BVH was built
  // from (same_geometry). Not while an integrator renders.
  void update_shading(const RenderSettings& settings);

  const Scene& scene() const { return scene_; }
  // The data passes of pixel (x, y) from the camera hit of its sample 0 (Film::set_first_hit):
  // view-axis depth, the instance's and the material's pass index (the default material has 0).
  void record_first_hit(Film& film, int x, int y, const SurfaceHit& hit) const {
    const float object =
        hit.instance < scene_.instances.size() ? scene_.instances[hit.instance].pass_index : 0.0f;
    const float material = hit.material >= 0 && size_t(hit.material) < scene_.materials.size()
                               ? scene_.materials[size_t(hit.material)].pass_index
                               : 0.0f;
    film.set_first_hit(x, y, camera_.view_depth(hit.position), object, material);
  }
  // Fraction of light passing along the shadow ray `ray`: 0 if an opaque surface blocks it, else
  // the product of the Transparent closure weights of the surfaces crossed (Cycles' transparent
  // shadows), at most kMaxTransparentBounces of them. `scratch` holds their closures; `rays`
  // counts the queries.
  Spectrum transmittance(Ray ray, ClosureSet& scratch, uint32_t& rays) const;
  // Holdout (Instance::holdout): whether the scene has any, and whether `hit` is on one.
  bool has_holdout() const { return has_holdout_; }
  // Cycles' Shadow Caustics (integrators/common/manifold_nee.h): some caster, receiver and lamp.
  bool shadow_caustics() const { return shadow_caustics_; }
  bool is_caustics_receiver(const SurfaceHit& hit) const {
    return scene_.instances[hit.instance].caustics_receiver;
  }
  bool is_caustics_caster(const SurfaceHit& hit) const {
    return scene_.instances[hit.instance].caustics_caster;
  }
  // A caster while shadow caustics run: Filter Glossy leaves its smooth glass sharp.
  bool is_sharp_caster(const SurfaceHit& hit) const {
    return shadow_caustics_ && is_caustics_caster(hit);
  }
  bool is_holdout(const SurfaceHit& hit) const {
    return hit.instance < scene_.instances.size() && scene_.instances[hit.instance].holdout;
  }
  const EmbreeScene& bvh() const { return *bvh_; }
  const CameraModel& camera() const { return camera_; }
  // RenderSettings::pixel_filter / filter_width: where each camera sample lies in its pixel.
  const PixelFilter& pixel_filter() const { return pixel_filter_; }
  const LightSampler& lights() const { return *lights_; }
  // Scene::materials followed by Blender's default grey material (index default_material()).
  const std::vector<Material>& materials() const { return materials_; }
  int32_t default_material() const { return int32_t(materials_.size()) - 1; }
  const std::vector<Texture>& textures() const { return textures_; }
  // Feature mask (features.h); with force_all_features every bit is set.
  uint32_t features() const { return features_; }
  uint32_t scene_features() const { return scene_features_; }  // what the scene really uses
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  void build_materials();                               // textures_ and materials_ from the scene
  void finish_shading(const RenderSettings& settings);  // lights, camera and features
  const Scene& scene_;
  std::vector<Texture> textures_;
  std::vector<Material> materials_;
  std::unique_ptr<EmbreeScene> bvh_;
  std::unique_ptr<LightSampler> lights_;
  bool has_holdout_ = false;
  bool shadow_caustics_ = false;
  CameraModel camera_;
  PixelFilter pixel_filter_;
  uint32_t features_ = 0, scene_features_ = 0;
  std::vector<std::string> warnings_;
};

}  // namespace gdpt
