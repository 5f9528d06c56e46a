// A shading point of a G-PT path (base or offset): its hit, the frame facing the incoming ray and
// its closures, set up as the path tracer sets up its vertices.
#pragma once

#include <span>
#include <vector>

#include "core/frame.h"
#include "integrators/common/light_path_filters.h"
#include "integrators/common/path_state.h"
#include "integrators/common/shadow_ray.h"
#include "render/embree_scene.h"
#include "render/scene_context.h"
#include "shaders/bsdf.h"

namespace gdpt {

struct Vertex {
  SurfaceHit hit;
  Frame frame;
  Vec3f ng;  // geometric normal on the side of the incoming ray
  Vec3f wi;  // local incoming direction
  // The closures: a constant material's own set (no copy), else `own` filled by evaluate().
  // A Vertex is never copied or moved (it lives in PathScratch), so `closures` may point into it.
  const ClosureSet* closures = nullptr;
  ClosureSet own;
  float roughness = 1.0f;  // ClosureSet::roughness(), 1 for a vertex without BSDF
  // A single Lambert lobe: eval() and pdf() depend on wi only through the sign of wi.z * wo.z,
  // so an offset sharing this vertex with another wi reuses the base's values (same_side()).
  bool lambert = false;
  // offset_ray_origin() on the side of ng, computed on first use (ray_origin()): light samples,
  // the extension ray and reconnection rays of a vertex mostly leave on that side.
  mutable bool origin_set = false;
  mutable Vec3f origin;
  float offset_scale = 1.0f;  // EmbreeScene::offset_scale(), for offset_ray_origin()
};

// Origin of a ray leaving `v` on the side of ng (`front`) or the other side.
inline Vec3f ray_origin(const Vertex& v, bool front) {
  if (!front) return offset_ray_origin(v.hit.position, -v.ng, v.offset_scale);
  if (!v.origin_set) {
    v.origin = offset_ray_origin(v.hit.position, v.ng, v.offset_scale);
    v.origin_set = true;
  }
  return v.origin;
}

// Whether a single-Lambert vertex gives wi_a and wi_b the same eval() and pdf() for wo: the
// lobe's only use of wi is the test wi.z * wo.z > 0 (shaders/bsdf_lambert.h), so equal test
// outcomes mean bit-identical values.
inline bool same_side(const Vertex& v, Vec3f wi_a, Vec3f wi_b, Vec3f wo) {
  return v.lambert && (wi_a.z * wo.z > 0.0f) == (wi_b.z * wo.z > 0.0f);
}

// Local outgoing direction at `v` for world `dir`; false when the geometric and shading
// hemispheres disagree (the path tracer's leak test).
inline bool local_dir(const Vertex& v, Vec3f dir, Vec3f& wo) {
  wo = v.frame.to_local(dir);
  return v.closures->side_ok(wo, dot(dir, v.ng));
}

// The same for a light sample's direction: light_side_ok(), the path tracer's rule.
inline bool light_dir(const EmbreeScene& bvh, const Vertex& v, Vec3f dir, Vec3f& wo) {
  wo = v.frame.to_local(dir);
  return light_side_ok(bvh, v.hit, *v.closures, wo, dot(dir, v.ng));
}

// What a vertex needs of a material side whose closures do not vary over the surface
// (Material::closures returns its cached set): the set itself, its roughness and whether it is a
// single Lambert lobe, computed once per material and side. `set` is null for a material that
// is evaluated per hit (textures).
struct MaterialSide {
  const ClosureSet* set = nullptr;
  float roughness = 1.0f;
  bool lambert = false;
};

// Indexed by 2 * material + front_facing.
std::vector<MaterialSide> material_sides(const SceneContext& ctx);

// ClosureSet::roughness(), 1 for a set without BSDF.
float vertex_roughness(const ClosureSet& cs);

// The light-path rules (light_path_filters.h) for a vertex reached with a path state: base and
// offsets pass the base's state.
struct VertexRules {
  const LightPathFilters& filters;
  const PathState& state;
};

// The roughness of the material at `h` without setting up a vertex there.
float hit_roughness(const SceneContext& ctx, std::span<const MaterialSide> sides,
                    const VertexRules& rules, const SurfaceHit& h);

// Sets up `v` at its hit v.hit reached along `dir` (world, unit) by the path `path` (for
// materials that read it, Material::reads_path). (The base's next hit is traced into v.hit
// directly: no copy.)
void finish_vertex(const SceneContext& ctx, std::span<const MaterialSide> sides,
                   const VertexRules& rules, const Vec3f& dir, const PathView& path, Vertex& v);

// The same at a copy of `hit`.
inline void setup_vertex(const SceneContext& ctx, std::span<const MaterialSide> sides,
                         const VertexRules& rules, const SurfaceHit& hit, const Vec3f& dir,
                         const PathView& path, Vertex& v) {
  v.hit = hit;
  finish_vertex(ctx, sides, rules, dir, path, v);
}

// The closures of the base vertex `base` as an offset that reached it by reconnection sees them
// from `wi_world` (unit, towards the offset's previous vertex) at the end of `path` (its own ray
// length): the base's own, unless its material reads the view or the path
// (Material::reads_view, reads_path); then evaluated into `scratch`, in the base's frame.
const ClosureSet& shared_closures(const SceneContext& ctx, const VertexRules& rules,
                                  const Vertex& base, Vec3f wi_world, const PathView& path,
                                  ClosureSet& scratch);

// Emitted radiance of an emissive triangle at `hit` towards the point `from`, reached by `path`
// (for materials that read it; the ray length is the distance to `from`).
Spectrum triangle_emission(const SceneContext& ctx, const SurfaceHit& hit, Vec3f from,
                           const PathView& path);

}  // namespace gdpt
