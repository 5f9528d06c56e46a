#include "render/scene_context.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "render/features.h"
#include "shaders/shading_context.h"

namespace gdpt {

namespace {

void validate_camera(const Camera& cam) {
  if (cam.width <= 0 || cam.height <= 0)
    throw std::invalid_argument("scene: camera resolution must be positive, got " +
                                std::to_string(cam.width) + "x" + std::to_string(cam.height));
  if (cam.projection == Camera::Projection::Perspective && !(cam.focal_length_mm > 0.0f))
    throw std::invalid_argument("scene: camera focal length must be positive");
  if (cam.projection == Camera::Projection::Orthographic && !(cam.ortho_scale > 0.0f))
    throw std::invalid_argument("scene: orthographic scale must be positive");
}

// The feature bits the camera decides (features.h).
uint32_t camera_features(const Camera& cam) {
  uint32_t f = 0;
  if (cam.aperture_radius > 0.0f) f |= kSceneDoF;
  if (cam.projection == Camera::Projection::Orthographic) f |= kSceneOrthographic;
  return f;
}

}  // namespace

void validate_scene(const Scene& scene, std::vector<std::string>& warnings) {
  validate_camera(scene.camera);
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    const std::string name = "scene: mesh " + std::to_string(m);
    if (mesh.indices.size() % 3 != 0)
      throw std::invalid_argument(name + ": index count is not a multiple of 3");
    const size_t tris = mesh.triangle_count();
    if (!mesh.corner_normals.empty() && mesh.corner_normals.size() != 3 * tris)
      throw std::invalid_argument(name + ": corner_normals must have 3 entries per triangle");
    if (!mesh.vertex_normals.empty() && mesh.vertex_normals.size() != mesh.positions.size())
      throw std::invalid_argument(name + ": vertex_normals must have 1 entry per vertex");
    if (!mesh.corner_uvs.empty() && mesh.corner_uvs.size() != 3 * tris)
      throw std::invalid_argument(name + ": corner_uvs must have 3 entries per triangle");
    if (!mesh.material_slot.empty() && mesh.material_slot.size() != tris)
      throw std::invalid_argument(name + ": material_slot must have 1 entry per triangle");
  }
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.mesh >= scene.meshes.size())
      throw std::invalid_argument("scene: instance " + std::to_string(i) + " refers to mesh " +
                                  std::to_string(inst.mesh) + " of " +
                                  std::to_string(scene.meshes.size()));
    for (int32_t mat : inst.slot_material)
      if (mat >= int32_t(scene.materials.size()))
        warnings.push_back("instance " + std::to_string(i) + ": material " + std::to_string(mat) +
                           " out of range, using the default material");
  }
  for (const ImageDesc& img : scene.images)
    if (img.rgba.size() != size_t(img.width) * size_t(img.height) * 4)
      throw std::invalid_argument("scene: image '" + img.name + "' has " +
                                  std::to_string(img.rgba.size()) + " floats, expected " +
                                  std::to_string(size_t(img.width) * img.height * 4));
  if (scene.world.image >= int32_t(scene.images.size()))
    throw std::invalid_argument("scene: world image index out of range");
  if (scene.world.camera_view && scene.world.camera_view->image >= int32_t(scene.images.size()))
    throw std::invalid_argument("scene: camera-view world image index out of range");
}

namespace {

template <typename T>
bool same_data(const std::vector<T>& a, const std::vector<T>& b) {
  static_assert(std::is_trivially_copyable_v<T>);
  return a.size() == b.size() &&
         (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_mesh(const Mesh& a, const Mesh& b) {
  return same_data(a.positions, b.positions) && same_data(a.indices, b.indices) &&
         same_data(a.corner_normals, b.corner_normals) && same_data(a.corner_uvs, b.corner_uvs) &&
         same_data(a.corner_tangents, b.corner_tangents) &&
         same_data(a.corner_tangent_signs, b.corner_tangent_signs) &&
         same_data(a.corner_colors, b.corner_colors) &&
         same_data(a.vertex_pointiness, b.vertex_pointiness) &&
         same_data(a.triangle_island_random, b.triangle_island_random) &&
         same_data(a.material_slot, b.material_slot) &&
         same_data(a.vertex_normals, b.vertex_normals) &&
         std::memcmp(&a.texspace_location, &b.texspace_location, sizeof(Vec3f)) == 0 &&
         std::memcmp(&a.texspace_size, &b.texspace_size, sizeof(Vec3f)) == 0;
}

bool same_placement(const Instance& a, const Instance& b) {
  return a.mesh == b.mesh &&
         std::memcmp(&a.object_to_world, &b.object_to_world, sizeof(Transform)) == 0 &&
         a.slot_material == b.slot_material && a.visibility == b.visibility &&
         a.holdout == b.holdout &&
         // The BVH's instance data holds the shadow terminator offsets.
         a.terminator_geometry_offset == b.terminator_geometry_offset &&
         a.terminator_shading_offset == b.terminator_shading_offset;
}

}  // namespace

bool same_geometry(const Scene& a, const Scene& b) {
  if (a.meshes.size() != b.meshes.size() || a.instances.size() != b.instances.size() ||
      a.materials.size() != b.materials.size())
    return false;
  for (size_t i = 0; i < a.meshes.size(); ++i)
    if (!same_mesh(a.meshes[i], b.meshes[i])) return false;
  for (size_t i = 0; i < a.instances.size(); ++i)
    if (!same_placement(a.instances[i], b.instances[i])) return false;
  return true;
}

SceneContext::SceneContext(const Scene& scene, const RenderSettings& settings) : scene_(scene) {
  validate_scene(scene, warnings_);
  build_materials();
  bvh_ = std::make_unique<EmbreeScene>(scene, default_material());
  finish_shading(settings);
}

void SceneContext::update_shading(const RenderSettings& settings) {
  warnings_.clear();
  validate_scene(scene_, warnings_);
  lights_.reset();  // it refers to the materials and textures rebuilt next
  build_materials();
  finish_shading(settings);
}

void SceneContext::build_materials() {
  // Textures first: materials keep a span over them.
  materials_.clear();
  textures_.clear();
  textures_.reserve(scene_.images.size());
  for (const ImageDesc& img : scene_.images) textures_.emplace_back(img);
  materials_.reserve(scene_.materials.size() + 1);
  for (const MaterialDesc& desc : scene_.materials) materials_.emplace_back(desc, textures_);
  materials_.emplace_back();  // Blender's default grey diffuse
}

void SceneContext::finish_shading(const RenderSettings& settings) {
  const Scene& scene = scene_;
  bvh_->set_materials(materials_);
  has_holdout_ = false;
  for (const Instance& inst : scene.instances) has_holdout_ = has_holdout_ || inst.holdout;
  // Shadow caustics need a caster, a receiver and an area lamp that lights them.
  bool caster = false, receiver = false, lamp = false;
  for (const Instance& inst : scene.instances) {
    caster = caster || inst.caustics_caster;
    receiver = receiver || inst.caustics_receiver;
  }
  for (const Light& l : scene.lights)
    lamp = lamp || (l.caustics_light && l.type == Light::Type::Area);
  shadow_caustics_ = caster && receiver && lamp;
  lights_ = std::make_unique<LightSampler>(scene, materials_, textures_);
  camera_ = CameraModel(scene.camera);
  for (Material& m : materials_) m.set_camera(camera_.shading_camera());
  pixel_filter_ = PixelFilter(settings.pixel_filter, settings.filter_width);

  // --- Feature mask: what the instanced geometry, lights, world and camera really use ---
  uint32_t f = 0;
  std::vector<int> mesh_uses(scene.meshes.size(), 0);
  for (const Instance& inst : scene.instances) {
    ++mesh_uses[inst.mesh];
    bool uses_default = inst.slot_material.empty();
    for (int32_t mat : inst.slot_material) {
      if (mat >= 0 && mat < default_material())
        f |= materials_[size_t(mat)].features();
      else
        uses_default = true;
    }
    // Meshes may use slots beyond the map: they fall back to the default material.
    if (uses_default) f |= materials_.back().features();
  }
  for (int uses : mesh_uses)
    if (uses > 1) f |= kSceneInstances;
  if (f & kFeatureEmission) f |= kSceneEmissiveTriangles;
  f |= camera_features(scene.camera);
  if (lights_->has_environment() || lights_->has_camera_environment()) f |= kSceneWorld;
  if (scene.world.image >= 0) f |= kSceneWorldImage | kSceneWorld;
  for (const Light& l : scene.lights) {
    switch (l.type) {
      case Light::Type::Point:
      case Light::Type::Spot:
        f |= l.radius > 0.0f ? kSceneAnalyticLights : kSceneDeltaLights;
        break;
      case Light::Type::Sun:
        f |= l.sun_angle > 0.0f ? kSceneAnalyticLights : kSceneDeltaLights;
        break;
      case Light::Type::Area:
        f |= kSceneAnalyticLights;
        break;
    }
  }
  scene_features_ = f;
  features_ = settings.force_all_features ? kAllFeatures : f;
}

SceneContext::~SceneContext() = default;

void SceneContext::set_camera(const Camera& camera) {
  validate_camera(camera);
  camera_ = CameraModel(camera);
  for (Material& m : materials_) m.set_camera(camera_.shading_camera());
  scene_features_ = (scene_features_ & ~(kSceneDoF | kSceneOrthographic)) | camera_features(camera);
  if (features_ != kAllFeatures) features_ = scene_features_;  // else force_all_features
}

Spectrum SceneContext::transmittance(Ray ray, ClosureSet& scratch, uint32_t& rays) const {
  ++rays;
  Spectrum tr(1.0f);
  SurfaceHit h;
  for (int crossing = 0; crossing <= kMaxTransparentBounces; ++crossing) {
    if (!bvh_->intersect(ray, h)) return tr;
    scratch.clear();
    materials_[size_t(h.material)].evaluate(shading_context_of(h), scratch);
    tr *= scratch.transparency();
    if (is_black(tr)) return tr;
    const Vec3f n =
        dot(ray.direction, h.geometric_normal) > 0.0f ? h.geometric_normal : -h.geometric_normal;
    ray.origin = offset_ray_origin(h.position, n, bvh_->offset_scale());
    ray.t_max -= h.t;
    ++rays;
  }
  return Spectrum(0.0f);
}

}  // namespace gdpt
