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
  if (filtered) rules.filters.apply(rules.state, cs);
  return vertex_roughness(cs);
}

void finish_vertex(const SceneContext& ctx, std::span<const MaterialSide> sides,
                   const VertexRules& rules, const Vec3f& dir, Vertex& v) {
  const SurfaceHit& hit = v.hit;
  const MaterialSide& side = sides[2 * size_t(hit.material) + (hit.front_facing ? 1 : 0)];
  const bool filtered = rules.filters.enabled() && rules.filters.active(rules.state);
  if (side.set && !filtered) {
    v.closures = side.set;
    v.roughness = side.roughness;
    v.lambert = side.lambert;
  } else {
    if (side.set) {
      v.own.assign(*side.set);
    } else {
      v.own.clear();
      ctx.materials()[size_t(hit.material)].evaluate(shading_context_of(hit), v.own);
    }
    if (filtered) rules.filters.apply(rules.state, v.own);
    v.closures = &v.own;
    v.roughness = vertex_roughness(v.own);
    v.lambert = single_lambert(v.own);
  }
  const Vec3f wi_world = -dir;
  // The frame PT uses: a shading normal facing away from wi stays (the BSDFs see wi below it).
  const SurfaceFrame sf = facing_frame(hit, wi_world);
  v.ng = sf.ng;
  v.frame = Frame(sf.ns);
  v.wi = v.frame.to_local(wi_world);
  // With bump shadowing where the normal is not the interpolated one (bump_shadowing.h).
  v.closures = &shading_closures(*v.closures, v.own, hit, v.frame, v.ng, wi_world, sf.rotated);
  // A lobe about its own normal reads more of wi than the side (same_side()).
  if (v.closures->has_own_frames()) v.lambert = false;
  v.origin_set = false;
  v.offset_scale = ctx.bvh().offset_scale();
}

Spectrum triangle_emission(const SceneContext& ctx, const SurfaceHit& hit, Vec3f from) {
  const Material& m = ctx.materials()[size_t(hit.material)];
  if (!m.is_emissive()) return Spectrum(0.0f);
  ShadingContext sc = shading_context_of(hit);
  sc.front_facing = dot(from - hit.position, hit.geometric_normal) > 0.0f;
  return m.emission(sc);
}

}  // namespace gdpt
