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
#include <emmintrin.h>

#include <cstdint>
#include <span>
#include <vector>

#include "core/huge_pages.h"
#include "core/shadow_terminator.h"
#include "core/transform.h"
#include "core/vec.h"
#include "render/camera.h"
#include "scene/scene.h"
#include "shaders/material.h"
#include "shaders/shading_context.h"

namespace gdpt {

struct SurfaceHit {
  float t = 0.0f;
  Vec3f position;          // world
  Vec3f geometric_normal;  // unit, world, as the triangle winding gives it (not flipped)
  Vec3f shading_normal;    // unit, world, interpolated corner normal (= geometric if flat)
  Vec2f uv;
  Vec3f color;       // colour attribute (Mesh::corner_colors), 0 when the mesh has none; only set
                     // on instances that have one or whose materials read one
  TexCoords coords;  // object-space coordinates; only set on instances whose materials read them
  SurfaceAttributes attributes;  // only set on instances whose materials read them
  // A normal map or bump replaced shading_normal; unperturbed_normal is the interpolated one
  // (for the bump shadowing of diffuse lobes, ClosureSet::set_bump_shadowing).
  bool perturbed = false;
  Vec3f unperturbed_normal;
  uint32_t instance = 0, primitive = 0;  // index in Scene::instances, triangle in its mesh
  Vec2f bary;  // Embree's (u, v): the weights of the triangle's second and third corners
  const ShadingInstance* shading_instance = nullptr;  // the instance as shading nodes see it
  int32_t material = -1;     // index into SceneContext::materials() (always valid after hit())
  bool front_facing = true;  // the ray came from the side geometric_normal points to
};

// What a material sees of a hit.
inline ShadingContext shading_context_of(const SurfaceHit& hit) {
  ShadingContext ctx{hit.uv, hit.front_facing, &hit.color, &hit.coords};
  ctx.instance = hit.shading_instance;
  ctx.primitive = hit.primitive;
  ctx.attributes = &hit.attributes;
  return ctx;
}

// The view of `hit` from `wi_world` (unit, from the hit back along the incoming ray), for
// materials that read it (Material::reads_view).
// `front_facing`: the side it is seen from (the hit's own by default).
inline ShadingGeometry shading_geometry(const SurfaceHit& hit, Vec3f wi_world, bool front_facing) {
  const float side = front_facing ? 1.0f : -1.0f;
  const Vec3f interpolated = hit.perturbed ? hit.unperturbed_normal : hit.shading_normal;
  return {wi_world, interpolated * side, hit.shading_normal * side, hit.geometric_normal * side};
}
inline ShadingGeometry shading_geometry(const SurfaceHit& hit, Vec3f wi_world) {
  return shading_geometry(hit, wi_world, hit.front_facing);
}

// Moves p off the surface along n (the side the new ray leaves to) by an amount proportional to
// the floating-point spacing at p, in the spirit of Wächter & Binder (Ray Tracing Gems, ch. 6):
// integer ULP steps away from the origin, a small absolute step near it. `scale`
// (EmbreeScene::offset_scale()) shrinks that absolute step and region with scenes smaller than a
// unit, so a scene modelled in tenths of a millimetre is not offset by a tenth of its size.
// The three components at once in SSE2 lanes (branch-free; the scalar form had
// a data-dependent branch per component); inline, since the call
// itself (Vec3f arguments split over registers, a stack round trip for the result) cost as much.
[[gnu::always_inline]] inline Vec3f offset_ray_origin(const Vec3f& p, const Vec3f& n, float scale) {
  // Integer-ULP offset scale and the absolute fallback near the origin (positions whose magnitude
  // is below kOriginRegion have too few ULPs to step by integers meaningfully).
  constexpr float kOriginRegion = 1.0f / 32.0f;
  constexpr float kFloatScale = 1.0f / 65536.0f;
  constexpr float kIntScale = 256.0f;
  const __m128 P = _mm_setr_ps(p.x, p.y, p.z, 0.0f), N = _mm_setr_ps(n.x, n.y, n.z, 0.0f);
  // Integer ULP steps, away from zero: add kIntScale * n ULPs to |p|'s bits, i.e. subtract for
  // negative p (sign = -1 there: (of ^ sign) - sign negates).
  const __m128i of = _mm_cvttps_epi32(_mm_mul_ps(N, _mm_set1_ps(kIntScale)));
  const __m128i bits = _mm_castps_si128(P);
  const __m128i sign = _mm_srai_epi32(bits, 31);
  const __m128 stepped =
      _mm_castsi128_ps(_mm_add_epi32(bits, _mm_sub_epi32(_mm_xor_si128(of, sign), sign)));
  // Near the origin an absolute step.
  const __m128 absolute = _mm_add_ps(P, _mm_mul_ps(N, _mm_set1_ps(kFloatScale * scale)));
  const __m128 abs_p = _mm_andnot_ps(_mm_set1_ps(-0.0f), P);
  const __m128 near = _mm_cmplt_ps(abs_p, _mm_set1_ps(kOriginRegion * scale));
  const __m128 r = _mm_or_ps(_mm_and_ps(near, absolute), _mm_andnot_ps(near, stepped));
  alignas(16) float out[4];
  _mm_store_ps(out, r);
  return {out[0], out[1], out[2]};
}

namespace detail {

// Embree's single-ray layout of `ray` (tnear > tfar marks an inactive ray of a stream).
inline void to_embree(const Ray& ray, bool active, RTCRay& r) {
  r.org_x = ray.origin.x;
  r.org_y = ray.origin.y;
  r.org_z = ray.origin.z;
  r.dir_x = ray.direction.x;
  r.dir_y = ray.direction.y;
  r.dir_z = ray.direction.z;
  r.tnear = active ? ray.t_min : 1.0f;
  r.tfar = active ? ray.t_max : 0.0f;
  r.time = 0.0f;
  r.mask = ray.kind;
  r.id = 0;
  r.flags = 0;
}

inline void to_embree(const Ray& ray, bool active, RTCRayHit& rh) {
  to_embree(ray, active, rh.ray);
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
}

}  // namespace detail

class EmbreeScene {
 public:
  // `default_material`: material index used for slot -1 / out-of-range slots.
  EmbreeScene(const Scene& scene, int32_t default_material);
  ~EmbreeScene();
  EmbreeScene(const EmbreeScene&) = delete;
  EmbreeScene& operator=(const EmbreeScene&) = delete;

  // Closest hit in (t_min, t_max). Fills `hit` when true. Inline (as occluded()): the wrappers
  // around Embree's calls are on every ray.
  [[gnu::always_inline]] bool intersect(const Ray& ray, SurfaceHit& hit) const {
    RTCRayHit rh;
    closest(ray, rh);
    return read_hit(rh, ray.direction, hit);
  }
  // Closest hit distance only, without the hit record: for rays whose hit can only end the path.
  bool intersect_distance(const Ray& ray, float& t) const {
    RTCRayHit rh;
    closest(ray, rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    t = rh.ray.tfar;
    return true;
  }
  // The scale of offset_ray_origin(): the largest coordinate magnitude of the scene's bounds,
  // at most 1 (larger scenes keep the unit step, which their integer ULP steps already exceed).
  float offset_scale() const { return offset_scale_; }
  // True when something blocks the segment (t_min, t_max).
  [[gnu::always_inline]] bool occluded(const Ray& ray) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    RTCRay r;
    detail::to_embree(ray, true, r);
    rtcOccluded1(top_, &ctx, &r);
    return r.tfar < 0.0f;  // Embree sets tfar = -inf on a hit
  }
  // A stream of n rays (Embree rtcIntersect1M, coherent context: Embree groups consecutive rays
  // into packets of its native width, on any ISA). Ray i is traced only when valid[i]; results as
  // intersect(). For G-PT's camera rays of a row of pixels (consecutive rays start at neighbouring
  // pixels).
  void intersect_stream(const Ray* rays, const bool* valid, int n, bool* found,
                        SurfaceHit* hits) const;

  // The scene's materials (indexed as SurfaceHit::material), for Normal Map and Bump nodes,
  // colour attributes and texture coordinates. Decides per instance whether its hits perturb
  // the shading normal (some material has a normal map or bump), carry a colour attribute (the
  // mesh has one, or some material reads one: black then) and carry object-space coordinates
  // (some material reads them); other hits skip all three. Unset: none.
  void set_materials(std::span<const Material> materials);

  // Where a shadow ray from `hit` towards the unit direction `l` starts, before
  // offset_ray_origin(): the hit's position, or on smooth-shaded triangles near the shadow
  // terminator that position lifted towards the curved surface the corner normals describe, by
  // the instance's Instance::terminator_geometry_offset (core/shadow_terminator.h).
  Vec3f shadow_ray_start(const SurfaceHit& hit, Vec3f l) const;
  // Whether shadow rays from `hit` may start lifted: a smooth-shaded triangle of an instance
  // with a Geometry Offset.
  bool lifts_shadow_rays(const SurfaceHit& hit) const;
  // The hit triangle's corners and unit shading normals in world space (a flat triangle: its
  // geometric normal at every corner), for the manifold walk (integrators/common/manifold_nee.h).
  void world_triangle(const SurfaceHit& hit, SmoothTriangle& t) const;

  size_t triangle_count() const { return triangles_; }  // unique (per mesh)
  size_t instanced_triangle_count() const { return instanced_triangles_; }
  // Fills the rest of a hit from (top-level geometry id, primitive, barycentrics).
  void complete_hit(uint32_t top_id, uint32_t primitive, float u, float v, const Vec3f& dir,
                    SurfaceHit& hit) const;

 private:
  // Embree's closest-hit query for one ray, shared by intersect() and intersect_distance().
  [[gnu::always_inline]] void closest(const Ray& ray, RTCRayHit& rh) const {
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    detail::to_embree(ray, true, rh);
    rtcIntersect1(top_, &ctx, &rh);
  }
  // Fills `hit` from Embree's result; false when nothing was hit.
  bool read_hit(const RTCRayHit& rh, const Vec3f& dir, SurfaceHit& hit) const {
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
    hit.t = rh.ray.tfar;
    // Instanced meshes report the top-level id in instID[0], flattened ones in geomID.
    const unsigned top_id =
        rh.hit.instID[0] != RTC_INVALID_GEOMETRY_ID ? rh.hit.instID[0] : rh.hit.geomID;
    complete_hit(top_id, rh.hit.primID, rh.hit.u, rh.hit.v, dir, hit);
    return true;
  }

  // Everything complete_hit() reads, resolved at build time (raw pointers into the Scene's
  // meshes, slot -> material table with the default applied): a hit costs no vector bounds or
  // emptiness checks and no chasing of Mesh / Instance pointers.
  struct alignas(16) UnitNormal {
    UnitNormal() {}  // no zero fill: every one is written once at build time
    float v[4];      // x, y, z, 0
  };
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
    // World-space meshes: each triangle's unit geometric normal, winding applied, computed at
    // build time as complete_hit() would (all zero for a degenerate triangle): the hit's
    // square root and division are off its critical path.
    const UnitNormal* unit_normals = nullptr;
    // Shading normals: corner normals for primitives < corner_normal_tris, else vertex normals
    // when present, else flat.
    const Vec3f* corner_normals = nullptr;
    uint32_t corner_normal_tris = 0;
    const Vec3f* vertex_normals = nullptr;
    const Vec2f* corner_uvs = nullptr;  // for primitives < corner_uv_tris; else uv = 0
    uint32_t corner_uv_tris = 0;
    const Vec3f* corner_colors = nullptr;  // Color Attribute nodes, primitives < corner_color_tris
    uint32_t corner_color_tris = 0;
    bool writes_color = false;     // hits fill SurfaceHit::color (set_materials)
    bool perturbs_normal = false;  // some material has a normal map or a bump (set_materials)
    bool writes_coords = false;    // some material reads Generated / Object / Position coordinates
    bool writes_attributes = false;  // some material reads SurfaceAttributes (set_materials)
    const float* vertex_pointiness = nullptr;       // Mesh::vertex_pointiness, or null
    const float* triangle_island_random = nullptr;  // for primitives < island_random_tris
    uint32_t island_random_tris = 0;
    const Vec3f* object_positions = nullptr;  // the Mesh's own (object-space) positions
    // Generated coordinates = object position * generated_scale + generated_offset (lanes).
    alignas(16) float generated_scale[4] = {};
    alignas(16) float generated_offset[4] = {};
    const Vec3f* corner_tangents = nullptr;  // Normal Map nodes, primitives < corner_tangent_tris
    const float* corner_tangent_signs = nullptr;
    uint32_t corner_tangent_tris = 0;
    // Material: `uniform_material` when every triangle resolves to one (the common case), else
    // slot_materials[material_slot[primitive]] (slot 0 past material_slot_count, default
    // material for slots outside the table).
    int32_t uniform_material = -1;
    const int32_t* material_slot = nullptr;
    uint32_t material_slot_count = 0;
    std::vector<int32_t> slot_materials;
    // Columns of the object-to-world transform (the fourth: translation) and of the normal
    // matrix (inverse transpose of its linear part), as SSE lanes (w = 0).
    alignas(16) float to_world_cols[4][4] = {};
    alignas(16) float normal_cols[3][4] = {};
    const ShadingInstance* shading = nullptr;  // SurfaceHit::shading_instance
    float terminator_cutoff = 0.0f;            // Instance::terminator_geometry_offset
  };
  RTCDevice device_ = nullptr;
  RTCScene top_ = nullptr;
  float offset_scale_ = 1.0f;
  std::vector<RTCScene> mesh_scenes_;
  std::vector<HugePageVector<UnitNormal>> unit_normals_;  // InstanceData::unit_normals' storage
  std::vector<InstanceData> instances_;                   // indexed by top-level Embree geometry id
  std::vector<uint32_t> top_ids_;                         // Scene::instances index -> geometry id
  std::vector<ShadingInstance> shading_instances_;        // indexed as Scene::instances
  // Replaces hit.shading_normal by what the material's normal chain (displacement, normal map,
  // bumps: MaterialDesc::bumps) makes of it (out of line: rare).
  [[gnu::noinline]] void perturb_normal(const InstanceData& d, uint32_t primitive, float u, float v,
                                        SurfaceHit& hit) const;
  void normal_map_normal(const InstanceData& d, uint32_t primitive, float u, float v,
                         SurfaceHit& hit, const Material& material) const;
  void bump_normal(const InstanceData& d, uint32_t primitive, SurfaceHit& hit,
                   const Material& material, size_t bump) const;
  // What a vector displacement's vector is dotted with for its height (Material::bump_height).
  static Vec3f displacement_along(const InstanceData& d, uint32_t primitive, const SurfaceHit& hit,
                                  const BumpDesc& bump);
  // The shading context of a completed hit (its colour and coordinates where it has them).
  static ShadingContext shading_context(const InstanceData& d, const SurfaceHit& hit) {
    ShadingContext ctx{hit.uv, true, d.writes_color ? &hit.color : nullptr,
                       d.writes_coords ? &hit.coords : nullptr};
    ctx.instance = hit.shading_instance;
    ctx.primitive = hit.primitive;
    ctx.attributes = d.writes_attributes ? &hit.attributes : nullptr;
    return ctx;
  }
  static void set_generated_mapping(InstanceData& d, const Mesh& mesh);
  // A smooth triangle's corners and unit shading normals in world space (Cycles lifts objects
  // with their transform applied); false for a flat triangle.
  static bool world_smooth_triangle(const InstanceData& d, uint32_t prim, SmoothTriangle& t);
  static void world_corners(const InstanceData& d, uint32_t prim, SmoothTriangle& t);  // t.p only
  // The mesh attributes (SurfaceAttributes) at barycentrics (u, v) of triangle `primitive`.
  static SurfaceAttributes attributes_at(const InstanceData& d, uint32_t primitive,
                                         const uint32_t* idx, float u, float v);
  const Scene* scene_ = nullptr;

  std::span<const Material> materials_;
  int32_t default_material_ = -1;
  size_t triangles_ = 0, instanced_triangles_ = 0;
};

}  // namespace gdpt
