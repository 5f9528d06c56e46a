#include "integrators/gpt/path_vertex.h"

#include "integrators/common/bump_shadowing.h"
#include "integrators/common/surface_frame.h"
#include "shaders/shading_context.h"

namespace gdpt {

namespace {

bool single_lambert(const ClosureSet& cs) {
  return cs.count() == 1 && cs[0].type == ClosureType::Lambert;
}

}  // namespace

float vertex_roughness(const ClosureSet& cs) {
  return cs.has_bsdf() ? cs.roughness() : 1.0f;
}

std::vector<MaterialSide> material_sides(const SceneContext& ctx) {
  std::vector<MaterialSide> sides(2 * ctx.materials().size());
  ClosureSet scratch;
  for (size_t m = 0; m < ctx.materials().size(); ++m)
    for (int front = 0; front < 2; ++front) {
      const ClosureSet& cs = ctx.materials()[m].closures(ShadingContext{{}, front == 1}, scratch);
      if (&cs == &scratch) continue;  // evaluated per hit
      sides[2 * m + size_t(front)] = {&cs, vertex_roughness(cs), single_lambert(cs)};
    }
  return sides;
}

float hit_roughness(const SceneContext& ctx, std::span<const MaterialSide> sides,
                    const VertexRules& rules, const SurfaceHit& h) {
  const MaterialSide& side = sides[2 * size_t(h.material) + (h.front_facing ? 1 : 0)];
  const bool filtered = rules.filters.enabled() && rules.filters.active(rules.state);
  if (side.set && !filtered) return side.roughness;
  ClosureSet cs;
  if (side.set)
    cs.assign(*side.set);
  else
    ctx.materials()[size_t(h.material)].evaluate(shading_context_of(h), cs);
  if (filtered) rules.filters.apply(rules.state, cs, ctx.is_sharp_caster(h));
  return vertex_roughness(cs);
}

void finish_vertex(const SceneContext& ctx, std::span<const MaterialSide> sides,
                   const VertexRules& rules, const Vec3f& dir, const PathView& path, Vertex& v) {
  const SurfaceHit& hit = v.hit;
  const MaterialSide& side = sides[2 * size_t(hit.material) + (hit.front_facing ? 1 : 0)];
  const bool filtered = rules.filters.enabled() && rules.filters.active(rules.state);
  if (side.set && !filtered) {
    v.closures = side.set;
    v.roughness = side.roughness;
    v.lambert = side.lambert;
  } else {
    const Material& m = ctx.materials()[size_t(hit.material)];
    // The vertex's class (hit_roughness) must not depend on the direction or path it is
    // reached by: base and offsets arriving at a shared vertex classify it alike.
    const bool per_path = m.reads_view() || m.reads_path();
    if (side.set) {
      v.own.assign(*side.set);
    } else {
      ShadingContext sc = shading_context_of(hit);
      ShadingGeometry view;
      if (per_path) v.roughness = hit_roughness(ctx, sides, rules, hit);
      if (m.reads_view()) {
        view = shading_geometry(hit, -dir);
        sc.geometry = &view;
      }
      if (m.reads_path()) sc.path = &path;
      m.evaluate(sc, v.own);
    }
    if (filtered) rules.filters.apply(rules.state, v.own, ctx.is_sharp_caster(hit));
    v.closures = &v.own;
    if (!per_path) v.roughness = vertex_roughness(v.own);
    // Such a set is another set from another path (no same_side() sharing).
    v.lambert = !per_path && single_lambert(v.own);
  }
  const Vec3f wi_world = -dir;
  // The frame PT uses: a shading normal facing away from wi stays (the BSDFs see wi below it).
  const SurfaceFrame sf = facing_frame(hit, wi_world);
  v.ng = sf.ng;
  v.frame = shading_frame(sf.ns, *v.closures);
  v.wi = v.frame.to_local(wi_world);
  // With bump shadowing where the normal is not the interpolated one (bump_shadowing.h).
  v.closures = &shading_closures(*v.closures, v.own, hit, v.frame, v.ng, wi_world, sf.rotated);
  // A lobe about its own normal reads more of wi than the side (same_side()).
  if (v.closures->has_own_frames()) v.lambert = false;
  v.origin_set = false;
  v.offset_scale = ctx.bvh().offset_scale();
}

const ClosureSet& shared_closures(const SceneContext& ctx, const VertexRules& rules,
                                  const Vertex& base, Vec3f wi_world, const PathView& path,
                                  ClosureSet& scratch) {
  const Material& m = ctx.materials()[size_t(base.hit.material)];
  if (!m.reads_view() && !m.reads_path()) return *base.closures;
  ShadingContext sc = shading_context_of(base.hit);
  const ShadingGeometry view = shading_geometry(base.hit, wi_world);
  sc.geometry = &view;
  sc.path = &path;
  m.evaluate(sc, scratch);
  // The light-path rules as at the base, which shares its path state with the offset.
  if (rules.filters.enabled() && rules.filters.active(rules.state))
    rules.filters.apply(rules.state, scratch, ctx.is_sharp_caster(base.hit));
  // Bump shadowing as at the base (`rotated`: let shading_closures compare the normals).
  return shading_closures(scratch, scratch, base.hit, base.frame, base.ng, wi_world, true);
}

Spectrum triangle_emission(const SceneContext& ctx, const SurfaceHit& hit, Vec3f from,
                           const PathView& path) {
  const Material& m = ctx.materials()[size_t(hit.material)];
  if (!m.is_emissive()) return Spectrum(0.0f);
  ShadingContext sc = shading_context_of(hit);
  sc.front_facing = dot(from - hit.position, hit.geometric_normal) > 0.0f;
  ShadingGeometry view;
  if (m.reads_view()) {
    view = shading_geometry(hit, normalize(from - hit.position), sc.front_facing);
    sc.geometry = &view;
  }
  PathView own;
  if (m.reads_path()) {
    own = path;
    own.ray_length = length(from - hit.position);
    sc.path = &own;
  }
  return m.emission(sc);
}

}  // namespace gdpt
