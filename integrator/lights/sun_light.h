// Blender sun light: a distant light of irradiance c P [W/m^2] (Cycles: strength, no
// conversion) on a surface facing it, from a disc of directions of angular diameter sun_angle.
//
// Parameters (from gdpt::Light):
//   power P [W/m^2], color c   irradiance at normal incidence
//   sun_angle (full angle)     half angle a = sun_angle / 2; a = 0 is a delta light
// Radiance is uniform over the cone, L = c P / (pi sin^2 a), so that the cosine-weighted
// integral over the cone (the irradiance on a facing surface) is exactly c P. Cycles 3.4 instead
// samples a disc of radius tan(a) one unit away with radiance proportional to 1 / cos^3; both
// agree to 0.8% at a = 10 degrees and to 1e-5 at Blender's default 0.526 degree diameter.
// Emits along the light's local -Z, so the direction towards the sun is +Z.
#pragma once

#include <cmath>
#include <limits>

#include "integrator/light_sampler.h"
#include "integrator/lights/warp.h"
#include "integrator/math/frame.h"

namespace gdpt::lights {

struct SunLight {
  Vec3f to_sun{0.0f, 0.0f, 1.0f};  // unit, from the receiver towards the sun
  float one_minus_cos = 0.0f;      // of the half angle; 0 = delta
  Spectrum irradiance;             // W/m^2 at normal incidence
  Spectrum radiance;               // over the disc (finite angle only)
  float select_pmf = 0.0f;         // filled by LightSampler

  static SunLight from_light(const Light& l) {
    SunLight s;
    const Vec3f z = l.light_to_world.column(2);
    s.to_sun = length_squared(z) > 0.0f ? normalize(z) : Vec3f(0.0f, 0.0f, 1.0f);
    const float half = 0.5f * std::clamp(l.sun_angle, 0.0f, kPi);
    const float sin_half = std::sin(half);
    s.one_minus_cos = one_minus_cos_from_sin2(sin_half * sin_half);
    if (half > 0.5f * kPi) s.one_minus_cos = 1.0f - std::cos(half);
    s.irradiance = l.color * std::max(0.0f, l.power);
    if (s.one_minus_cos > 0.0f) {
      const float sin2 = s.one_minus_cos * (2.0f - s.one_minus_cos);
      s.radiance = s.irradiance / (kPi * sin2);
    }
    return s;
  }

  bool is_delta() const { return !(one_minus_cos > 0.0f); }

  // Power through a disc of radius scene_radius facing the sun.
  float power(float scene_radius) const {
    return luminance(irradiance) * kPi * scene_radius * scene_radius;
  }

  bool sample(Vec3f ref, Vec2f u, LightSample& s) const {
    const float inf = std::numeric_limits<float>::infinity();
    if (is_delta()) {
      s.direction = to_sun;
      s.radiance = irradiance;
      s.pdf = 1.0f;
      s.is_delta = true;
    } else {
      s.direction = Frame(to_sun).to_world(square_to_cone(u, one_minus_cos));
      s.radiance = radiance;
      s.pdf = cone_pdf(one_minus_cos);
      s.is_delta = false;
    }
    s.position = ref + s.direction;
    s.normal = -s.direction;
    s.distance = inf;
    s.is_infinite = true;
    s.valid = true;
    return true;
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
    h.radiance = radiance;
    h.pdf = cone_pdf(one_minus_cos);
  }
};

}  // namespace gdpt::lights
