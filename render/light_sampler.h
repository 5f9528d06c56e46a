// All light sources of a scene behind one interface: point (radius: disc), spot, sun, area lights,
// emissive triangles (sampled by power) and the world (constant, seen only by escaping rays, or an
// importance-sampled image).
// Units and looks as Cycles 3.4: area radiance = P / (4 A), point/spot intensity = P / (4 pi) per
// steradian, sun = irradiance in W/m^2 (docs/lights.md).
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/vec.h"
#include "render/lights/area_light.h"
#include "render/lights/light_sample.h"
#include "render/lights/point_light.h"
#include "scene/scene.h"
#include "shaders/material.h"
#include "shaders/texture.h"

namespace gdpt {

class LightSampler {
 public:
  LightSampler(const Scene& scene, std::span<const Material> materials,
               std::span<const Texture> textures);
  ~LightSampler();

  bool empty() const { return emitters_ == 0; }
  // Whether sample() reads u_select: a scene with one emitter (a Cornell box's lamp) needs no
  // selection number, and integrators skip drawing it.
  bool needs_selection() const { return emitters_ > 1; }
  // The scene whose only emitter is one area lamp (a Cornell box) goes straight to a small
  // function: no selection, no dispatch, no generic checks.
  LightSample sample(Vec3f ref_position, float u_select, Vec2f u) const {
    return only_area_ ? sample_only_area(ref_position, u) : sample_any(ref_position, u_select, u);
  }
  // Density of sample() choosing the point hit on emissive triangle (instance, primitive).
  float pdf_triangle(uint32_t instance, uint32_t primitive, Vec3f ref_position,
                     Vec3f light_position, Vec3f light_normal) const;
  // Closest analytic light (point/spot disc, area, sun disc) along the ray with t < t_max.
  // Sun discs are at infinity: reported only for unbounded rays (t_max >= 1e30, Ray's default,
  // or +inf), i.e. rays that escaped the geometry. Emissive triangles are geometry, not here.
  // It runs for every ray (a Blender lamp is not geometry) and almost always misses: the common
  // scene with one area lamp and nothing else is tested in line, without a call.
  [[gnu::always_inline]] bool intersect(Vec3f origin, Vec3f direction, float t_max,
                                        LightHit& hit) const {
    if (single_area_) {
      const float t = areas_[0].intersect_t(origin, direction, t_max);
      if (!(t > 0.0f)) return false;
      fill_hit(areas_[0], origin, direction, t, hit);
      return true;
    }
    return intersect_any(origin, direction, t_max, hit);
  }
  // Radiance of the world along an escaping ray (sun discs excluded: see intersect) and the
  // density sample() has for it (0 for a constant world, which is not light-sampled).
  Spectrum environment(Vec3f direction) const;
  float pdf_environment(Vec3f direction) const;
  bool has_environment() const;  // non-black world
  // The world as camera rays see it (World::camera_view, else the lighting world above).
  Spectrum camera_environment(Vec3f direction) const;
  bool has_camera_environment() const;
  // Some analytic lamp is visible to camera rays (Light::camera_visible).
  bool has_camera_visible_lights() const;  // world is non-black

 private:
  static void fill_hit(const lights::PointLight& l, Vec3f origin, Vec3f direction, float t,
                       LightHit& hit);
  static void fill_hit(const lights::AreaLight& l, Vec3f origin, Vec3f direction, float t,
                       LightHit& hit);
  // In line: one call less per vertex in the common one-lamp scene (the spherical branch stays
  // out of line, AreaLight::sample_spherical). Its pmf is 1 and its radiance finite (a
  // non-finite one has non-finite power: not stored). One named result, so that it is built in
  // the caller's slot: returning either it or a fresh LightSample{} made GCC build it on the
  // stack and copy it out with 16-byte loads of fields just stored as floats, a
  // store-forwarding stall on every light sample.
  [[gnu::always_inline]] LightSample sample_only_area(Vec3f ref, Vec2f u) const {
    LightSample s;
    if (areas_[0].sample(ref, u, s)) {
      s.cast_shadow = areas_[0].cast_shadow;
      s.caustics = areas_[0].caustics;
    } else {
      s = LightSample{};
    }
    return s;
  }
  LightSample sample_any(Vec3f ref_position, float u_select, Vec2f u) const;
  bool intersect_any(Vec3f origin, Vec3f direction, float t_max, LightHit& hit) const;

  // Analytic lamps with a surface, here rather than in Impl for the in-line intersect().
  std::vector<lights::PointLight> points_;
  std::vector<lights::AreaLight> areas_;
  bool single_area_ = false;  // one area lamp is the only analytic light (no point, spot, sun)
  bool only_area_ = false;    // ... and the only emitter (no emissive triangle, no world)
  size_t emitters_ = 0;       // entries of the selection CDF
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gdpt
