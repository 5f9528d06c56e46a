// Visibility tests of a G-PT path's vertices: light samples (base and offsets) and reconnections.
// Every test towards a finite point is a segment to that point stopped at kShadowEnd of its
// length (common/shadow_ray.h), as the path tracer's: a base path and its offsets then test the
// same point alike, whatever the distance of the scene from the origin.
#pragma once

#include <cstdint>

#include "integrators/common/shadow_ray.h"
#include "integrators/gpt/gpt_context.h"
#include "integrators/gpt/path_vertex.h"
#include "render/light_sampler.h"

namespace gdpt {

// From vertex `v` to the point `target`, `dir` the unit direction towards it: the ray leaves the
// surface on the side of `dir`.
inline Ray shadow_ray_to(const Vertex& v, Vec3f dir, Vec3f target, uint32_t kind) {
  return shadow_ray_to_point(ray_origin(v, dot(dir, v.ng) > 0.0f), target, kind);
}

// From vertex `v` along the unit direction `dir` to infinity (the world, the sun).
inline Ray shadow_ray_along(const Vertex& v, Vec3f dir, uint32_t kind) {
  return shadow_ray_to_infinity(ray_origin(v, dot(dir, v.ng) > 0.0f), dir, kind);
}

// From vertex `v` towards a light sample in the unit direction `dir`, to the point `target`
// or, for `infinite`, to infinity: the path tracer's rule (light_ray_origin) at v's own hit.
inline Ray light_ray_from(const EmbreeScene& bvh, const Vertex& v, Vec3f dir, Vec3f target,
                          bool infinite) {
  const Vec3f origin =
      light_ray_origin(bvh, v.hit, v.ng, dir, ray_origin(v, dot(dir, v.ng) > 0.0f));
  return infinite ? shadow_ray_to_infinity(origin, dir, kRayShadow)
                  : shadow_ray_to_point(origin, target, kRayShadow);
}

// An occlusion query. `kind` of the ray: kRayShadow for light samples; a reconnected segment is
// the kind of the base's segment it replaces (RayKind, Instance::visibility).
inline bool occluded(const GptContext& g, const Ray& ray, uint32_t& rays) {
  ++rays;
  return g.ctx.bvh().occluded(ray);
}

// Whether the light sample `seen` from `v` (its direction, position, radiance) of the lamp of the
// base's sample `ls` (its cast_shadow and is_delta) is unblocked. Delta lamps see through
// Transparent surfaces as in Cycles' transparent shadows (`le` is multiplied by the
// transmittance), because no BSDF sample can reach them; the light of other lamps through such
// surfaces arrives by BSDF sampling (a crossing is a delta event of the path), so their shadow
// rays stay opaque and nothing is counted twice.
bool lamp_visible(const GptContext& g, const Vertex& v, const LightSample& ls,
                  const LightSample& seen, ClosureSet& scratch, Spectrum& le, uint32_t& rays);

}  // namespace gdpt
