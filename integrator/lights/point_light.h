// Blender point and spot lights (Cycles 3.4 units).
//
// Parameters (from gdpt::Light):
//   power P [W], color c      radiant intensity I = c P / (4 pi) [W/sr] (Cycles: strength / 4 pi)
//   radius r [m]              r = 0: a delta light; r > 0: a sphere of uniform radiance
//                             L = I / (pi r^2), so that its far field is the same intensity I
//   spot_size (full angle)    spot only: cone half angle a = spot_size / 2
//   spot_blend b              spot only: Cycles 3.4 attenuation of the intensity along a direction
//                             at angle t from the axis: cos t * smoothstep((cos t - cos a) /
//                             ((1 - cos a) b)), 0 outside the cone (yes, 3.4 keeps the cos t)
// The spot attenuation is evaluated for the direction from the light centre to the receiver.
// Spheres are sampled uniformly in the solid angle of the cone they subtend (Cycles 4 does the
// same; Cycles 3.4 used a disc facing the receiver, which subtends slightly less solid angle).
// A receiver inside the sphere gets no light from it, and rays starting inside do not hit it.
#pragma once

#include <cmath>

#include "integrator/light_sampler.h"
#include "integrator/lights/warp.h"
#include "integrator/math/frame.h"

namespace gdpt::lights {

struct SphereLight {
  Vec3f center;
  float radius = 0.0f;
  Spectrum intensity;  // W/sr
  bool is_spot = false;
  Vec3f axis{0.0f, 0.0f, -1.0f};  // spot emission axis (world, unit)
  float cos_half_angle = -1.0f;
  float smooth = 0.0f;      // (1 - cos_half_angle) * blend
  float select_pmf = 0.0f;  // filled by LightSampler

  static SphereLight from_light(const Light& l) {
    SphereLight s;
    s.center = l.light_to_world.translation();
    s.radius = std::max(0.0f, l.radius);
    s.intensity = l.color * (std::max(0.0f, l.power) * kInv4Pi);
    if (l.type == Light::Type::Spot) {
      s.is_spot = true;
      const Vec3f z = l.light_to_world.column(2);
      s.axis = length_squared(z) > 0.0f ? -normalize(z) : Vec3f(0.0f, 0.0f, -1.0f);
      s.cos_half_angle = std::cos(0.5f * std::clamp(l.spot_size, 0.0f, kPi));
      s.smooth = (1.0f - s.cos_half_angle) * std::clamp(l.spot_blend, 0.0f, 1.0f);
    }
    return s;
  }

  // Importance for light selection: emitted power, the spot's restricted to its cone.
  float power() const {
    const float p = luminance(intensity) * 4.0f * kPi;
    return is_spot ? p * 0.5f * (1.0f - cos_half_angle) : p;
  }

  // Spot falloff for the unit direction from the light towards the receiver.
  float attenuation(Vec3f dir_out) const {
    if (!is_spot) return 1.0f;
    const float c = dot(axis, dir_out);
    if (c <= cos_half_angle) return 0.0f;
    const float t = c - cos_half_angle;
    if (smooth > 0.0f && t < smooth) {
      const float x = t / smooth;
      return c * x * x * (3.0f - 2.0f * x);
    }
    return c;
  }

  Spectrum sphere_radiance(Vec3f receiver) const {
    const Vec3f to = receiver - center;
    const float d2 = length_squared(to);
    return intensity * (attenuation(to / std::sqrt(d2)) / (kPi * radius * radius));
  }

  float cone_one_minus_cos(float d2) const { return one_minus_cos_from_sin2(radius * radius / d2); }

  // Fills s without the selection probability.
  bool sample(Vec3f ref, Vec2f u, LightSample& s) const {
    const Vec3f to_center = center - ref;
    const float d2 = length_squared(to_center);
    if (!(d2 > radius * radius)) return false;  // inside (or at) the light
    const float d = std::sqrt(d2);
    const Vec3f w = to_center / d;
    const float atten = attenuation(-w);
    if (atten <= 0.0f) return false;
    if (radius == 0.0f) {
      s.radiance = intensity * (atten / d2);
      s.position = center;
      s.normal = Vec3f(0.0f);
      s.direction = w;
      s.distance = d;
      s.pdf = 1.0f;
      s.is_delta = true;
      s.is_infinite = false;
      s.valid = true;
      return true;
    }
    const float omc = cone_one_minus_cos(d2);
    const Vec3f local = square_to_cone(u, omc);
    const Vec3f dir = Frame(w).to_world(local);
    // Distance to the near intersection with the sphere along dir (law of cosines).
    const float cos_t = local.z;
    const float sin2_t = std::max(0.0f, 1.0f - cos_t * cos_t);
    const float t = d * cos_t - std::sqrt(std::max(0.0f, radius * radius - d2 * sin2_t));
    const Vec3f p = ref + dir * t;
    s.radiance = intensity * (atten / (kPi * radius * radius));
    s.position = p;
    s.normal = normalize(p - center);
    s.direction = dir;
    s.distance = t;
    s.pdf = cone_pdf(omc);
    s.is_delta = false;
    s.is_infinite = false;
    s.valid = s.pdf > 0.0f && std::isfinite(s.pdf);
    return s.valid;
  }

  // Nearest hit with 0 < t < t_max; returns t or a negative value.
  float intersect_t(Vec3f o, Vec3f d, float t_max) const {
    if (radius <= 0.0f) return -1.0f;
    const Vec3f oc = o - center;
    const float c = length_squared(oc) - radius * radius;
    if (c <= 0.0f) return -1.0f;  // origin inside: see the header comment
    const float b = dot(oc, d);
    if (b >= 0.0f) return -1.0f;  // pointing away
    const float disc = b * b - c;
    if (disc < 0.0f) return -1.0f;
    // Stable near root: t = c / (-b + sqrt(disc)).
    const float t = c / (-b + std::sqrt(disc));
    return (t > 0.0f && t < t_max) ? t : -1.0f;
  }

  void fill_hit(Vec3f o, Vec3f d, float t, LightHit& hit) const {
    hit.distance = t;
    hit.position = o + d * t;
    hit.normal = normalize(hit.position - center);
    hit.radiance = sphere_radiance(o);
    hit.pdf = cone_pdf(cone_one_minus_cos(length_squared(center - o)));
  }
};

}  // namespace gdpt::lights
