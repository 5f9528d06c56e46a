// All light sources of a scene behind one interface: point (radius: disc), spot, sun, area lights,
// emissive triangles (sampled by power) and the world (constant or importance-sampled image).
// Units and looks as Cycles: area radiance = P / (pi A), point/spot intensity = P / (4 pi) per
// steradian, sun = irradiance in W/m^2.
#pragma once

#include <cstdint>
#include <memory>
#include <span>

#include "integrator/math/vec.h"
#include "integrator/scene.h"
#include "shaders/material.h"
#include "shaders/texture.h"

namespace gdpt {

struct LightSample {
  Spectrum radiance;   // emitted radiance arriving at the reference point (unoccluded), not / pdf
  Vec3f position;      // point on the light (finite lights); reference + direction for infinite
  Vec3f normal;        // light surface normal at position (zero for point-like lights)
  Vec3f direction;     // unit, from the reference point towards the light
  float distance = 0;  // to position; +inf for sun and world
  float pdf = 0;       // solid-angle density incl. light selection; discrete prob. if is_delta
  bool is_delta = false;     // cannot be hit by BSDF sampling (no MIS)
  bool is_infinite = false;  // sun or world
  bool valid = false;
  // Area lights only (0 for the others): selection pmf / area, the density per unit area of
  // uniform area sampling. G-PT weighs its techniques with the area-sampling density
  // area_pdf d^2 / cos of a light point, the same function from every reference point.
  float area_pdf = 0;
};

struct LightHit {
  Spectrum radiance;  // emitted towards the ray origin
  float distance = 0;
  float pdf = 0;  // density sample() would have produced this direction from the ray origin
  Vec3f position, normal;
  bool camera_visible = false;  // the lamp shows to camera rays (Light::camera_visible)
  float area_pdf = 0;           // area lights: selection pmf / area (LightSample::area_pdf)
};

class LightSampler {
 public:
  LightSampler(const Scene& scene, std::span<const Material> materials,
               std::span<const Texture> textures);
  ~LightSampler();

  bool empty() const;
  // Whether sample() reads u_select: a scene with one emitter (a Cornell box's lamp) needs no
  // selection number, and integrators skip drawing it.
  bool needs_selection() const;
  LightSample sample(Vec3f ref_position, float u_select, Vec2f u) const;
  // Density of sample() choosing the point hit on emissive triangle (instance, primitive).
  float pdf_triangle(uint32_t instance, uint32_t primitive, Vec3f ref_position,
                     Vec3f light_position, Vec3f light_normal) const;
  // Closest analytic light (point/spot disc, area, sun disc) along the ray with t < t_max.
  // Sun discs are at infinity: reported only for unbounded rays (t_max >= 1e30, Ray's default,
  // or +inf), i.e. rays that escaped the geometry. Emissive triangles are geometry, not here.
  bool intersect(Vec3f origin, Vec3f direction, float t_max, LightHit& hit) const;
  // Radiance of the world along an escaping ray (sun discs excluded: see intersect) and its pdf.
  Spectrum environment(Vec3f direction) const;
  float pdf_environment(Vec3f direction) const;
  bool has_environment() const;
  // Some analytic lamp is visible to camera rays (Light::camera_visible).
  bool has_camera_visible_lights() const;  // world is non-black

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gdpt
