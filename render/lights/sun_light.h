// Blender sun light (Cycles 3.4 units): a distant light of irradiance c P [W/m^2] on a surface
// facing it (Cycles: strength, no conversion), from a disc of directions of angular diameter
// sun_angle.
//
// Parameters (from gdpt::Light):
//   power P [W/m^2], color c   strength
//   sun_angle (full angle)     half angle a = sun_angle / 2; a = 0 is a delta light
// Exactly as Cycles 3.4 (kernel/light/light.h, distant light): the sun is a disc of radius
// R = tan(a) one unit away along the sun direction, sampled uniformly by area, and its radiance
// equals the resulting solid-angle density times c P: L(t) = c P / (pi R^2 cos^3 t) for
// directions at angle t from the sun direction. The estimate L / pdf is c P for every sample, and
// the irradiance on a facing surface is c P (2 / R^2)(sqrt(1 + R^2) - 1): 0.2% under c P for a
// 10 degree sun, 5e-6 under at Blender's default 0.526 degrees.
// Emits along the light's local -Z, so the direction towards the sun is +Z.
#pragma once

#include <cmath>
#include <limits>

#include "core/frame.h"
#include "core/warp.h"
#include "render/lights/light_sample.h"
#include "scene/scene.h"

namespace gdpt::lights {

struct SunLight {
  Vec3f to_sun{0.0f, 0.0f, 1.0f};  // unit, from the receiver towards the sun
  float disc_radius = 0.0f;        // tan(half angle); 0 = delta
  float one_minus_cos = 0.0f;      // of the half angle, as 2 sin^2(half / 2): exact for tiny suns
  float inv_disc_area = 0.0f;      // 1 / (pi R^2)
  Spectrum strength;               // c P, W/m^2
  float select_pmf = 0.0f;         // filled by LightSampler
  bool camera_visible = false;     // filled by LightSampler
  bool cast_shadow = true;         // filled by LightSampler

  static SunLight from_light(const Light& l) {
    SunLight s;
    const Vec3f z = l.light_to_world.column(2);
    s.to_sun = length_squared(z) > 0.0f ? normalize(z) : Vec3f(0.0f, 0.0f, 1.0f);
    // Cycles clamps nothing here; beyond 180 degrees tan() turns negative, so cap just below.
    const float half = 0.5f * std::clamp(l.sun_angle, 0.0f, 0.999f * kPi);
    s.disc_radius = std::tan(half);
    const float sin_quarter = std::sin(0.5f * half);
    s.one_minus_cos = 2.0f * sin_quarter * sin_quarter;
    if (s.disc_radius > 0.0f) s.inv_disc_area = 1.0f / (kPi * s.disc_radius * s.disc_radius);
    s.strength = l.color * std::max(0.0f, l.power);
    return s;
  }

  bool is_delta() const { return !(inv_disc_area > 0.0f) || !std::isfinite(inv_disc_area); }

  // Power through a disc of radius scene_radius facing the sun.
  float power(float scene_radius) const {
    return luminance(strength) * kPi * scene_radius * scene_radius;
  }

  // Solid-angle density of the disc construction for a direction with cosine c to the sun.
  float density(float c) const { return inv_disc_area / (c * c * c); }

  bool sample(Vec3f ref, Vec2f u, LightSample& s) const {
    const float inf = std::numeric_limits<float>::infinity();
    if (is_delta()) {
      s.direction = to_sun;
      s.radiance = strength;
      s.pdf = 1.0f;
      s.is_delta = true;
    } else {
      const Vec2f disc = square_to_disk_concentric(u) * disc_radius;
      s.direction = normalize(Frame(to_sun).to_world({disc.x, disc.y, 1.0f}));
      s.pdf = density(dot(s.direction, to_sun));
      s.radiance = strength * s.pdf;
      s.is_delta = false;
    }
    s.position = ref + s.direction;
    s.normal = -s.direction;
    s.distance = inf;
    s.is_infinite = true;
    s.valid = std::isfinite(s.pdf) && s.pdf > 0.0f;
    return s.valid;
  }

  bool hit(Vec3f d) const {
    if (is_delta()) return false;
    // 1 - cos = |d - to_sun|^2 / 2, accurate for the tiny cones of real suns.
    return 0.5f * length_squared(d - to_sun) <= one_minus_cos;
  }

  void fill_hit(Vec3f o, Vec3f d, LightHit& h) const {
    h.distance = std::numeric_limits<float>::infinity();
    h.position = o + d;
    h.normal = -d;
    h.pdf = density(dot(d, to_sun));
    h.radiance = strength * h.pdf;
  }
};

}  // namespace gdpt::lights
