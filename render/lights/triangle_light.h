// An emissive mesh triangle (world space), as Cycles' mesh lights: emits on both sides with the
// radiance the material's emission closure gives at the sampled point (Cycles: colour *
// strength, no conversion). Large triangles (longest edge over a tenth of the distance and over
// kMinSphericalSolidAngle) are sampled uniformly in the solid angle they subtend (spherical
// triangles, as Cycles for nearby emitters); the others uniformly by area with the pdf converted
// to solid angle. The choice depends only on the reference point, so pdf() agrees with sample().
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>

#include "core/warp.h"
#include "render/lights/light_sample.h"
#include "render/lights/spherical_triangle.h"
#include "scene/scene.h"
#include "shaders/material.h"

namespace gdpt::lights {

struct TriangleLight {
  Vec3f p0, e1, e2;  // p = p0 + b1 e1 + b2 e2
  Vec3f normal;      // geometric normal (unit), winding order
  float area = 0.0f;
  Vec2f uv0, uv1, uv2;
  Vec3f color0{0.0f}, color1{0.0f}, color2{0.0f};  // colour attribute at the corners
  float pointiness0 = 0.0f, pointiness1 = 0.0f, pointiness2 = 0.0f;  // Mesh::vertex_pointiness
  float island_random = 0.0f;                                        // Mesh::triangle_island_random
  uint32_t material = 0;                      // index into the materials span
  const ShadingInstance* instance = nullptr;  // its instance, for the material's nodes
  uint32_t primitive = 0;                     // its triangle in the instance's mesh
  float select_pmf = 0.0f;
  float max_edge2 = 0.0f;  // squared longest edge

  static constexpr float kMinSphericalSolidAngle = 1e-2f;

  void finish() {
    max_edge2 = std::max(length_squared(e1), std::max(length_squared(e2), length_squared(e2 - e1)));
  }

  // The spherical triangle seen from ref when it is used for sampling (see the header).
  std::optional<SphericalTriangle> spherical(Vec3f ref) const {
    const Vec3f centroid = p0 + (e1 + e2) * (1.0f / 3.0f);
    if (max_edge2 < 0.01f * length_squared(centroid - ref)) return std::nullopt;
    const SphericalTriangle st(ref, p0, p0 + e1, p0 + e2);
    if (!(st.solid_angle() >= kMinSphericalSolidAngle)) return std::nullopt;
    return st;
  }

  // Barycentrics (b1, b2) of a point in the triangle's plane.
  Vec2f barycentrics(Vec3f p) const {
    const Vec3f d = p - p0;
    const float d00 = dot(e1, e1), d01 = dot(e1, e2), d11 = dot(e2, e2);
    const float d20 = dot(d, e1), d21 = dot(d, e2);
    const float inv = 1.0f / (d00 * d11 - d01 * d01);
    float b1 = std::max(0.0f, (d11 * d20 - d01 * d21) * inv);
    float b2 = std::max(0.0f, (d00 * d21 - d01 * d20) * inv);
    const float sum = b1 + b2;
    if (sum > 1.0f) {
      b1 /= sum;
      b2 /= sum;
    }
    return {b1, b2};
  }

  Vec2f uv_at(float b1, float b2) const {
    const float b0 = 1.0f - b1 - b2;
    return uv0 * b0 + uv1 * b1 + uv2 * b2;
  }

  // Two-sided Lambertian emitter: 2 pi L A.
  float power(Spectrum average_emission) const {
    return 2.0f * kPi * luminance(average_emission) * area;
  }

  bool sample(Vec3f ref, Vec2f u, const Material& m, LightSample& s) const {
    const std::optional<SphericalTriangle> st = spherical(ref);
    Vec3f p, dir;
    Vec2f b;
    float d = 0.0f, pdf = 0.0f;
    if (st) {
      dir = st->sample(u);
      const float denom = dot(dir, normal);
      if (denom == 0.0f) return false;
      d = dot(p0 - ref, normal) / denom;
      if (!(d > 0.0f)) return false;
      p = ref + dir * d;
      b = barycentrics(p);
      pdf = 1.0f / st->solid_angle();
    } else {
      b = square_to_triangle(u);
      p = p0 + e1 * b.x + e2 * b.y;
      const Vec3f to = p - ref;
      const float d2 = length_squared(to);
      d = std::sqrt(d2);
      if (!(d > 0.0f)) return false;
      dir = to / d;
      const float cos_l = std::fabs(dot(dir, normal));
      if (!(cos_l > 0.0f)) return false;
      pdf = d2 / (area * cos_l);
    }
    ShadingContext ctx;
    ctx.uv = uv_at(b.x, b.y);
    const Vec3f color = color0 * (1.0f - b.x - b.y) + color1 * b.x + color2 * b.y;
    ctx.color = &color;
    SurfaceAttributes attributes;
    if (m.reads_surface_attributes()) {
      attributes.barycentric = b;
      attributes.pointiness =
          pointiness0 * (1.0f - b.x - b.y) + pointiness1 * b.x + pointiness2 * b.y;
      attributes.random_per_island = island_random;
      ctx.attributes = &attributes;
    }
    ctx.front_facing = dot(dir, normal) < 0.0f;  // the receiver is on the normal's side
    // As a hit on the triangle sees its instance (Vector Transform, Wireframe, coordinates).
    ctx.instance = instance;
    ctx.primitive = primitive;
    TexCoords coords;
    if (instance && m.reads_coordinates()) {
      coords = instance->coords_at(p);
      ctx.coords = &coords;
    }
    ShadingGeometry view;
    if (m.reads_view()) {
      // Seen from the receiver; the triangle keeps no corner normals: the flat one stands in.
      const Vec3f n = ctx.front_facing ? normal : -normal;
      view = {-dir, n, n, n};
      ctx.geometry = &view;
    }
    PathView light_sample;  // Cycles evaluates a light sample's emission outside any path
    light_sample.light_sample = true;
    light_sample.ray_length = d;
    if (m.reads_path()) ctx.path = &light_sample;
    s.radiance = m.emission(ctx);
    s.position = p;
    s.normal = normal;
    s.direction = dir;
    s.distance = d;
    s.pdf = pdf;
    s.is_delta = false;
    s.is_infinite = false;
    s.valid = std::isfinite(s.pdf) && s.pdf > 0.0f;
    return s.valid;
  }

  float pdf(Vec3f ref, Vec3f p) const {
    if (const std::optional<SphericalTriangle> st = spherical(ref)) return 1.0f / st->solid_angle();
    const Vec3f to = p - ref;
    const float d2 = length_squared(to);
    const float cos_l = std::fabs(dot(to, normal)) / std::sqrt(d2);
    if (!(cos_l > 0.0f)) return 0.0f;
    return d2 / (area * cos_l);
  }
};

}  // namespace gdpt::lights
