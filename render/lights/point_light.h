// Blender point and spot lights, exactly as Cycles 3.4 (kernel/light/light.h, LIGHT_POINT and
// LIGHT_SPOT; scene/light.cpp for the constants).
//
// Parameters (from gdpt::Light):
//   power P [W], color c      radiant intensity I = c P / (4 pi) [W/sr] (Cycles: strength / 4 pi)
//   radius r [m]              r = 0: a delta light. r > 0: a disc of radius r through the light
//                             centre, always facing the receiver, of radiance L = I / (pi r^2)
//                             (Cycles 3.4's "sphere" light; 4.x made it a true sphere). A receiver
//                             at distance d gets I / (d^2 + r^2) at normal incidence.
//   spot_size (full angle)    spot only: cone half angle a = spot_size / 2
//   spot_blend b              spot only: the emission along a direction at angle t from the axis
//                             is scaled by cos t * smoothstep((cos t - cos a) / ((1 - cos a) b)),
//                             0 outside the cone (3.4 keeps the leading cos t). The direction is
//                             from the sampled disc point to the receiver, as Cycles.
// The disc is sampled uniformly by area and the pdf converted to solid angle; since its
// orientation depends only on the receiver (the ray origin), intersect() reports the same pdf.
#pragma once

#include <cmath>

#include "core/frame.h"
#include "core/warp.h"
#include "render/lights/light_sample.h"
#include "scene/scene.h"

namespace gdpt::lights {

struct PointLight {
  Vec3f center;
  float radius = 0.0f;
  Spectrum intensity;  // W/sr
  bool is_spot = false;
  Vec3f axis{0.0f, 0.0f, -1.0f};  // spot emission axis (world, unit)
  float cos_half_angle = -1.0f;
  float smooth = 0.0f;          // (1 - cos_half_angle) * blend
  float select_pmf = 0.0f;      // filled by LightSampler
  bool camera_visible = false;  // filled by LightSampler
  bool cast_shadow = true;      // filled by LightSampler

  static PointLight from_light(const Light& l) {
    PointLight s;
    s.center = l.light_to_world.translation();
    s.radius = std::isfinite(l.radius) ? std::max(0.0f, l.radius) : 0.0f;
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

  // Fills s without the selection probability.
  bool sample(Vec3f ref, Vec2f u, LightSample& s) const {
    const Vec3f from_center = ref - center;
    const float d2 = length_squared(from_center);
    if (!(d2 > 0.0f)) return false;
    const float d = std::sqrt(d2);
    if (radius == 0.0f) {
      const float atten = attenuation(from_center / d);
      if (!(atten > 0.0f)) return false;
      s.radiance = intensity * (atten / d2);
      s.position = center;
      s.normal = Vec3f(0.0f);
      s.direction = -from_center / d;
      s.distance = d;
      s.pdf = 1.0f;
      s.is_delta = true;
      s.is_infinite = false;
      s.valid = true;
      return true;
    }
    const Vec3f disc_normal = from_center / d;  // faces the receiver
    const Frame f(disc_normal);
    const Vec2f q = square_to_disk_concentric(u) * radius;
    const Vec3f p = center + f.s * q.x + f.t * q.y;
    const Vec3f to = p - ref;
    const float t2 = length_squared(to);
    const float t = std::sqrt(t2);
    const Vec3f dir = to / t;
    const float atten = attenuation(-dir);
    if (!(atten > 0.0f)) return false;
    const float cos_l = -dot(dir, disc_normal);  // = d / t > 0
    s.radiance = intensity * (atten / (kPi * radius * radius));
    s.position = p;
    s.normal = disc_normal;
    s.direction = dir;
    s.distance = t;
    s.pdf = t2 / (kPi * radius * radius * cos_l);
    s.is_delta = false;
    s.is_infinite = false;
    s.valid = s.pdf > 0.0f && std::isfinite(s.pdf);
    return s.valid;
  }

  // Hit of the disc facing the ray origin with 0 < t < t_max; returns t or a negative value.
  float intersect_t(Vec3f o, Vec3f d, float t_max) const {
    if (radius <= 0.0f) return -1.0f;
    const Vec3f from_center = o - center;
    const float dist2 = length_squared(from_center);
    if (!(dist2 > 0.0f)) return -1.0f;
    const float dist = std::sqrt(dist2);
    const float cos_l = -dot(d, from_center) / dist;
    if (!(cos_l > 0.0f)) return -1.0f;
    const float t = dist / cos_l;
    if (!(t < t_max)) return -1.0f;
    const Vec3f q = o + d * t - center;
    return length_squared(q) <= radius * radius ? t : -1.0f;
  }

  void fill_hit(Vec3f o, Vec3f d, float t, LightHit& hit) const {
    const Vec3f disc_normal = normalize(o - center);
    const float cos_l = -dot(d, disc_normal);
    hit.distance = t;
    hit.position = o + d * t;
    hit.normal = disc_normal;
    hit.radiance = intensity * (attenuation(-d) / (kPi * radius * radius));
    hit.pdf = t * t / (kPi * radius * radius * cos_l);
  }
};

}  // namespace gdpt::lights
