// Two-level Embree 3 BVH: a Mesh placed by several Instances is built once (in its own RTCScene)
// and placed by one RTC_GEOMETRY_TYPE_INSTANCE per Instance, so memory does not grow with the
// instance count; a Mesh placed once is stored in world space directly in the top level (one BVH
// traversal instead of two). Hit records refer to the Scene's meshes: the Scene must outlive this.
//
// Hit records are rebuilt from the mesh data (barycentrics, instance transform), not from
// origin + t * direction, for precision; spawned rays are offset along the geometric normal by a
// few ULPs of the position (offset_ray), so self-intersection is avoided at any scene scale.
#pragma once

#include <embree3/rtcore.h>

#include <cstdint>
#include <vector>

#include "integrator/camera.h"
#include "integrator/math/transform.h"
#include "integrator/math/vec.h"
#include "integrator/scene.h"

namespace gdpt {

struct SurfaceHit {
  float t = 0.0f;
  Vec3f position;          // world
  Vec3f geometric_normal;  // unit, world, as the triangle winding gives it (not flipped)
  Vec3f shading_normal;    // unit, world, interpolated corner normal (= geometric if flat)
  Vec2f uv;
  uint32_t instance = 0, primitive = 0;  // index in Scene::instances, triangle in its mesh
  int32_t material = -1;     // index into SceneContext::materials() (always valid after hit())
  bool front_facing = true;  // the ray came from the side geometric_normal points to
};

// Moves p off the surface along n (the side the new ray leaves to) by an amount proportional to
// the floating-point spacing at p, in the spirit of Wächter & Binder (Ray Tracing Gems, ch. 6):
// integer ULP steps away from the origin, a small absolute step near it.
Vec3f offset_ray_origin(Vec3f p, Vec3f n);

class EmbreeScene {
 public:
  // `default_material`: material index used for slot -1 / out-of-range slots.
  EmbreeScene(const Scene& scene, int32_t default_material);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Closest hit in (t_min, t_max). Fills `hit` when true.
  bool intersect(const Ray& ray, SurfaceHit& hit) const;
  // True when something blocks the segment (t_min, t_max).
  bool occluded(const Ray& ray) const;
  // A stream of n rays (Embree rtcIntersect1M, coherent context: Embree groups consecutive rays
  // into packets of its native width, on any ISA). Ray i is traced only when valid[i]; results as
  // intersect(). For G-PT's camera rays of a row of pixels (consecutive rays start at neighbouring
  // pixels).
  void intersect_stream(const Ray* rays, const bool* valid, int n, bool* found,
                        SurfaceHit* hits) const;

  size_t triangle_count() const { return triangles_; }  // unique (per mesh)
  size_t instanced_triangle_count() const { return instanced_triangles_; }
  // Fills the rest of a hit from (top-level geometry id, primitive, barycentrics).
  void complete_hit(uint32_t top_id, uint32_t primitive, float u, float v, const Vec3f& dir,
                    SurfaceHit& hit) const;

 private:
  // Fills `hit` from Embree's result; false when nothing was hit.
  bool read_hit(const RTCRayHit& rh, const Vec3f& dir, SurfaceHit& hit) const;

  // Everything complete_hit() reads, resolved at build time (raw pointers into the Scene's
  // meshes, slot -> material table with the default applied): a hit costs no vector bounds or
  // emptiness checks and no chasing of Mesh / Instance pointers.
  struct InstanceData {
    uint32_t index = 0;  // in Scene::instances
    // Flattened (world-space) meshes: Embree's own vertex buffer, so hits need no transform;
    // instanced meshes: the Mesh's object-space positions.
    bool world_space = false;
    // -1 for mirroring transforms: a world-space cross product then points against the
    // transformed object-space normal, whose orientation front_facing is defined by (as Cycles).
    float winding = 1.0f;
    const Vec3f* positions = nullptr;
    const uint32_t* indices = nullptr;
    // Shading normals: corner normals for primitives < corner_normal_tris, else vertex normals
    // when present, else flat.
    const Vec3f* corner_normals = nullptr;
    uint32_t corner_normal_tris = 0;
    const Vec3f* vertex_normals = nullptr;
    const Vec2f* corner_uvs = nullptr;  // for primitives < corner_uv_tris; else uv = 0
    uint32_t corner_uv_tris = 0;
    // Material: `uniform_material` when every triangle resolves to one (the common case), else
    // slot_materials[material_slot[primitive]] (slot 0 past material_slot_count, default
    // material for slots outside the table).
    int32_t uniform_material = -1;
    const int32_t* material_slot = nullptr;
    uint32_t material_slot_count = 0;
    std::vector<int32_t> slot_materials;
    Transform to_world;
    float normal_matrix[3][3];  // inverse transpose of the linear part
  };
  RTCDevice device_ = nullptr;
  RTCScene top_ = nullptr;
  std::vector<RTCScene> mesh_scenes_;
  std::vector<InstanceData> instances_;  // indexed by top-level Embree geometry id
  int32_t default_material_ = -1;
  size_t triangles_ = 0, instanced_triangles_ = 0;
};

}  // namespace gdpt
