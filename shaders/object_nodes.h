// Input nodes that read the hit's instance, its triangle or the camera: Vector Transform and
// Wireframe, as Cycles 3.4 computes them (kernel/svm/vector_transform.h, wireframe.h).
#pragma once

#include <cmath>

#include "core/transform.h"
#include "core/vec.h"
#include "scene/node_types.h"
#include "shaders/shading_context.h"

namespace gdpt {

namespace detail {

// v through the map m of inverse `inv`: a point, a direction, or a normal (the inverse transpose,
// renormalised as Cycles does; a zero normal stays zero).
inline Vec3f transform_as(const Transform& m, const Transform& inv, Vec3f v,
                          VectorTransformDesc::Type type) {
  using Type = VectorTransformDesc::Type;
  if (type == Type::Point) return m.point(v);
  if (type == Type::Vector) return m.vector(v);
  const Vec3f n(inv.m[0][0] * v.x + inv.m[1][0] * v.y + inv.m[2][0] * v.z,
                inv.m[0][1] * v.x + inv.m[1][1] * v.y + inv.m[2][1] * v.z,
                inv.m[0][2] * v.x + inv.m[1][2] * v.y + inv.m[2][2] * v.z);
  const float l = length(n);
  return l > 0.0f ? n / l : n;
}

}  // namespace detail

// Vector Transform: `v` from space `from` to space `to` through world space. Without an
// instance (null) object space is world space; the same space on both sides leaves v as it is.
inline Vec3f vector_transform(Vec3f v, const VectorTransformDesc& t,
                              const ShadingInstance* instance, const ShadingCamera& camera) {
  using Space = VectorTransformDesc::Space;
  if (t.from == t.to) return v;
  if (t.from == Space::Object && instance)
    v = detail::transform_as(instance->object_to_world, instance->world_to_object, v, t.type);
  else if (t.from == Space::Camera)
    v = detail::transform_as(camera.camera_to_world, camera.world_to_camera, v, t.type);
  if (t.to == Space::Object && instance)
    v = detail::transform_as(instance->world_to_object, instance->object_to_world, v, t.type);
  else if (t.to == Space::Camera)
    v = detail::transform_as(camera.world_to_camera, camera.camera_to_world, v, t.type);
  return v;
}

// Cycles' compact ray differential at a camera-ray hit at world point p: the ray's spread per
// pixel (the mean change of its unit direction over one pixel in x and in y) times the distance
// from the camera; orthographic: the pixel's size.
inline float pixel_footprint(const ShadingCamera& camera, Vec3f p) {
  if (camera.orthographic) return 0.5f * (camera.pixel_x + camera.pixel_y);
  const Vec3f c = camera.world_to_camera.point(p);
  // The pixel seeing p: its direction on the image plane at unit depth (the centre from behind).
  const Vec3f d = c.z > 0.0f ? Vec3f(c.x / c.z, c.y / c.z, 1.0f) : Vec3f(0.0f, 0.0f, 1.0f);
  const Vec3f n = normalize(d);
  const float spread_x = length(normalize(d + Vec3f(camera.pixel_x, 0.0f, 0.0f)) - n);
  const float spread_y = length(normalize(d + Vec3f(0.0f, camera.pixel_y, 0.0f)) - n);
  return length(c) * 0.5f * (spread_x + spread_y);
}

// Cycles' pixel width for Use Pixel Size: two orthogonal steps of length `footprint` in the plane
// normal to ng (Cycles 3.4's basis from (1, 1, 1) x ng), projected onto the plane normal to the
// incoming direction wi, their lengths averaged.
inline float wireframe_pixel_width(float footprint, Vec3f ng, Vec3f wi) {
  Vec3f a = ng.x != ng.y || ng.x != ng.z ? Vec3f(ng.z - ng.y, ng.x - ng.z, ng.y - ng.x)
                                         : Vec3f(ng.z - ng.y, ng.x + ng.z, -ng.y - ng.x);
  a = normalize(a);
  const Vec3f b = cross(ng, a);
  const float wa = length(a - wi * dot(a, wi)), wb = length(b - wi * dot(b, wi));
  return footprint * 0.5f * (wa + wb);
}

// Wireframe: 1 when p lies closer than width / 2 to the line of one of the triangle's edges
// (each neighbouring triangle draws the other half), else 0. Quads are two triangles, so their
// diagonal shows, as in Cycles.
inline float wireframe(const Vec3f corner[3], Vec3f p, float width) {
  const float half = 0.5f * width;
  const float half2 = half * half;
  for (int i = 0; i < 3; ++i) {
    const Vec3f edge = corner[i] - corner[i == 0 ? 2 : i - 1];
    const Vec3f c = cross(edge, p - corner[i]);
    // |c|^2 / |edge|^2 is the squared distance to the edge's line.
    if (dot(c, c) < dot(edge, edge) * half2) return 1.0f;
  }
  return 0.0f;
}

}  // namespace gdpt
