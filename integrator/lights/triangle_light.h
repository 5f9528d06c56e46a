// An emissive mesh triangle (world space), as Cycles' mesh lights: emits on both sides with the
// radiance the material's emission closure gives at the sampled point (Cycles: colour *
// strength, no conversion). Sampled uniformly by area; the pdf is converted to solid angle.
#pragma once

#include <cmath>
#include <cstdint>

#include "integrator/light_sampler.h"
#include "integrator/lights/warp.h"
#include "shaders/material.h"

namespace gdpt::lights {

struct TriangleLight {
  Vec3f p0, e1, e2;  // p = p0 + b1 e1 + b2 e2
  Vec3f normal;      // geometric normal (unit), winding order
  float area = 0.0f;
  Vec2f uv0, uv1, uv2;
  uint32_t material = 0;  // index into the materials span
  float select_pmf = 0.0f;

  Vec2f uv_at(float b1, float b2) const {
    const float b0 = 1.0f - b1 - b2;
    return uv0 * b0 + uv1 * b1 + uv2 * b2;
  }

  // Two-sided Lambertian emitter: 2 pi L A.
  float power(Spectrum average_emission) const {
    return 2.0f * kPi * luminance(average_emission) * area;
  }

  bool sample(Vec3f ref, Vec2f u, const Material& m, LightSample& s) const {
    const Vec2f b = square_to_triangle(u);
    const Vec3f p = p0 + e1 * b.x + e2 * b.y;
    const Vec3f to = p - ref;
    const float d2 = length_squared(to);
    const float d = std::sqrt(d2);
    if (!(d > 0.0f)) return false;
    const Vec3f dir = to / d;
    const float cos_l = std::fabs(dot(dir, normal));
    if (!(cos_l > 0.0f)) return false;
    ShadingContext ctx;
    ctx.uv = uv_at(b.x, b.y);
    ctx.front_facing = dot(dir, normal) < 0.0f;  // the receiver is on the normal's side
    s.radiance = m.emission(ctx);
    s.position = p;
    s.normal = normal;
    s.direction = dir;
    s.distance = d;
    s.pdf = d2 / (area * cos_l);
    s.is_delta = false;
    s.is_infinite = false;
    s.valid = std::isfinite(s.pdf);
    return s.valid;
  }

  float pdf(Vec3f ref, Vec3f p) const {
    const Vec3f to = p - ref;
    const float d2 = length_squared(to);
    const float cos_l = std::fabs(dot(to, normal)) / std::sqrt(d2);
    if (!(cos_l > 0.0f)) return 0.0f;
    return d2 / (area * cos_l);
  }
};

}  // namespace gdpt::lights
