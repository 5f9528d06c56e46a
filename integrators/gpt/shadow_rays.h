// Visibility tests of a G-PT path's vertices: light samples (base and offsets) and reconnections.
#pragma once

#include <cmath>
#include <cstdint>

#include "integrators/gpt/gpt_context.h"
#include "integrators/gpt/path_vertex.h"
#include "render/light_sampler.h"

namespace gdpt {

// The segment from vertex `v` along `dir` up to t_max, leaving the surface on the side of `dir`.
inline Ray shadow_ray(const Vertex& v, const Vec3f& dir, float t_max, uint32_t kind) {
  const Vec3f from = v.hit.position;
  Ray shadow;
  shadow.kind = kind;
  shadow.origin = ray_origin(v, dot(dir, v.ng) > 0.0f);
  shadow.direction = dir;
  shadow.t_min = 0.0f;
  shadow.t_max = t_max;
  if (std::isfinite(t_max)) {
    // Aim at the same end point from the offset origin: the offset shortens the path to a light
    // surface by up to offset / cos, which at grazing angles made an emitter occlude itself.
    // The segment itself is the direction, t in [0, 1]: an occlusion query needs no unit vector.
    const Vec3f to = from + dir * t_max - shadow.origin;
    if (length_squared(to) > 0.0f) {
      shadow.direction = to;
      shadow.t_max = 1.0f;
    }
  }
  return shadow;
}

// An occlusion query of that segment. `kind`: kRayShadow for light samples; a reconnected
// segment is the kind of the base's segment it replaces (RayKind, Instance::visibility).
bool occluded(const GptContext& g, const Vertex& v, const Vec3f& dir, float t_max, uint32_t kind,
              uint32_t& rays);

// Whether a light sample of lamp `ls` (its cast_shadow and is_delta) taken from `v` towards
// `dir`, `distance` away (infinite lamps: any distance), is unblocked. Delta lamps see through
// Transparent surfaces as in Cycles' transparent shadows (`le` is multiplied by the
// transmittance), because no BSDF sample can reach them; the light of other lamps through such
// surfaces arrives by BSDF sampling (a crossing is a delta event of the path), so their shadow
// rays stay opaque and nothing is counted twice.
bool lamp_visible(const GptContext& g, const Vertex& v, const LightSample& ls, const Vec3f& dir,
                  float distance, bool infinite, ClosureSet& scratch, Spectrum& le, uint32_t& rays);

}  // namespace gdpt
