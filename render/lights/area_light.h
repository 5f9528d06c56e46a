// Blender area light (Cycles 3.4 units): a one-sided rectangle or ellipse emitting towards the
// light's local -Z.
//
// Parameters (from gdpt::Light):
//   size_x, size_y [m]   extents along local X and Y; the object transform scales them (Cycles
//                        takes the axes from the object matrix columns, scale included)
//   shape                Square (size_x both ways), Rectangle, Disk (diameter size_x), Ellipse
//   power P [W], color c radiance L = c P / (4 A): Cycles 3.4 evaluates area lights with
//                        eval_fac = 0.25 / area and strength = colour * power, and no 1/pi
//                        anywhere, so a 1 W area light emits pi/4 W in total
// Area A: |u x v| for rectangles, pi/4 |u x v| for ellipses (u, v the scaled full extents).
// Rectangles (orthogonal axes) that subtend a large solid angle (kSphericalSolidAngle) are
// sampled uniformly in that solid angle, as Cycles does for every rectangle; ellipses, sheared
// rectangles and rectangles seen under a smaller angle are sampled uniformly by area with the pdf
// converted to solid angle (the spherical set-up costs more than it saves there). The choice
// depends only on the reference point, so sample() and intersect() agree on the density.
#pragma once

#include <cmath>
#include <optional>

#include "core/warp.h"
#include "render/lights/light_sample.h"
#include "render/lights/spherical_rectangle.h"
#include "scene/scene.h"

namespace gdpt::lights {

struct AreaLight {
  Vec3f center;
  Vec3f axis_u, axis_v;  // full extents (world)
  Vec3f normal;          // emission side (world, unit)
  float area = 0.0f;
  bool ellipse = false;
  Spectrum radiance;
  float select_pmf = 0.0f;      // filled by LightSampler
  bool camera_visible = false;  // filled by LightSampler
  bool cast_shadow = true;      // filled by LightSampler
  bool caustics = false;        // Light::caustics_light, filled by LightSampler
  // Dual basis of (axis_u, axis_v): local coordinates of a point in the plane are dot products.
  Vec3f dual_u, dual_v;
  bool orthogonal = false;  // rectangle with orthogonal axes: spherical sampling possible
  Vec3f corner, unit_u, unit_v;
  float len_u = 0.0f, len_v = 0.0f;
  float area_pdf = 0.0f;  // select_pmf / area, filled by LightSampler (LightSample::area_pdf)

  static constexpr float kMinSphericalSolidAngle = 1e-3f;
  // Spherical sampling only where the rectangle subtends at least this much, estimated as
  // area cos / d^2 from its centre: its set-up is a chain of square roots, divisions and two
  // atan2 on the sample's critical path, while below ~0.1 sr (an angular
  // radius of ~10 degrees) the cosines and 1 / d^2 barely vary over the light, so area sampling
  // is almost as good for much less time (docs/lights.md has the measurement).
  static constexpr float kSphericalSolidAngle = 0.1f;

  // Whether ref (to = ref - center, h = dot(to, normal) > 0 its height over the plane) samples the
  // spherical rectangle: area cos / d^2 >= threshold with cos = h / d, squared: no square root or
  // division in the test that most reference points fail.
  bool spherical_candidate(Vec3f to, float h) const {
    if (!orthogonal) return false;
    const float d2 = length_squared(to);
    const float a_cos_d = area * h;
    return a_cos_d > 0.0f &&
           !(a_cos_d * a_cos_d < kSphericalSolidAngle * kSphericalSolidAngle * d2 * d2 * d2);
  }

  // The spherical rectangle seen from ref when it is used for sampling (see the header).
  std::optional<SphericalRectangle> spherical(Vec3f ref) const {
    const Vec3f to = ref - center;
    if (!spherical_candidate(to, dot(to, normal))) return std::nullopt;
    const SphericalRectangle r(ref, corner, unit_u, unit_v, len_u, len_v);
    if (!(r.solid_angle() >= kMinSphericalSolidAngle)) return std::nullopt;
    return r;
  }

  static AreaLight from_light(const Light& l) {
    AreaLight a;
    const Transform& m = l.light_to_world;
    const bool square = l.shape == Light::Shape::Square || l.shape == Light::Shape::Disk;
    const float sx = std::max(0.0f, l.size_x);
    const float sy = square ? sx : std::max(0.0f, l.size_y);
    a.center = m.translation();
    a.axis_u = m.column(0) * sx;
    a.axis_v = m.column(1) * sy;
    a.ellipse = l.shape == Light::Shape::Disk || l.shape == Light::Shape::Ellipse;
    const Vec3f n = cross(a.axis_u, a.axis_v);
    const float parallelogram = length(n);
    a.area = a.ellipse ? 0.25f * kPi * parallelogram : parallelogram;
    if (!(a.area > 0.0f) || !std::isfinite(a.area)) {
      a.area = 0.0f;
      return a;
    }
    a.normal = n / parallelogram;
    if (dot(a.normal, m.column(2)) > 0.0f) a.normal = -a.normal;  // emits along local -Z
    a.radiance = l.color * (std::max(0.0f, l.power) * 0.25f / a.area);
    // Dual basis from the Gram matrix, so sheared axes work too.
    const float uu = dot(a.axis_u, a.axis_u), uv = dot(a.axis_u, a.axis_v);
    const float vv = dot(a.axis_v, a.axis_v);
    const float det = uu * vv - uv * uv;
    a.dual_u = (a.axis_u * vv - a.axis_v * uv) / det;
    a.dual_v = (a.axis_v * uu - a.axis_u * uv) / det;
    a.len_u = std::sqrt(uu);
    a.len_v = std::sqrt(vv);
    a.unit_u = a.axis_u / a.len_u;
    a.unit_v = a.axis_v / a.len_v;
    a.corner = a.center - (a.axis_u + a.axis_v) * 0.5f;
    a.orthogonal = !a.ellipse && std::fabs(uv) <= 1e-5f * a.len_u * a.len_v;
    return a;
  }

  // Emitted power (one-sided Lambertian emitter): pi L A.
  float power() const { return area > 0.0f ? kPi * luminance(radiance) * area : 0.0f; }

  // Fills s (valid: positive finite pdf) or returns false. The spherical branch is out of line:
  // most reference points sample by area, and that path stays small.
  bool sample(Vec3f ref, Vec2f u, LightSample& s) const {
    const Vec3f to = ref - center;
    const float h = dot(to, normal);  // height of ref over the emitting side
    if (h <= 0.0f) return false;      // behind: one-sided
    if (spherical_candidate(to, h)) return sample_spherical(ref, h, u, s);
    return sample_area(ref, h, u, s);
  }

  // cos_l d = h for every point of the plane, so the density d^2 / (A cos_l) is d^3 / (A h):
  // after the square root only multiplications (1 / (A h) is ready by then), no dot product
  // and one division for the direction.
  bool sample_area(Vec3f ref, float h, Vec2f u, LightSample& s) const {
    const float inv_ah = 1.0f / (area * h);
    Vec3f p = corner + axis_u * u.x + axis_v * u.y;
    if (ellipse) {
      const Vec2f q = square_to_disk_concentric(u) * 0.5f;
      p = center + axis_u * q.x + axis_v * q.y;
    }
    const Vec3f to = p - ref;
    const float d2 = length_squared(to);
    const float d = std::sqrt(d2);
    if (!(d > 0.0f)) return false;
    fill(p, to * (1.0f / d), d, d2 * d * inv_ah, s);
    return s.valid;
  }

  [[gnu::noinline]] bool sample_spherical(Vec3f ref, float h, Vec2f u, LightSample& s) const {
    const SphericalRectangle r(ref, corner, unit_u, unit_v, len_u, len_v);
    if (!(r.solid_angle() >= kMinSphericalSolidAngle)) return sample_area(ref, h, u, s);
    const Vec3f p = r.sample(u);
    const Vec3f to = p - ref;
    const float d = std::sqrt(length_squared(to));
    if (!(d > 0.0f)) return false;
    fill(p, to * (1.0f / d), d, 1.0f / r.solid_angle(), s);
    return s.valid;
  }

  void fill(Vec3f p, Vec3f dir, float d, float pdf, LightSample& s) const {
    s.radiance = radiance;
    s.position = p;
    s.normal = normal;
    s.direction = dir;
    s.distance = d;
    s.pdf = pdf;
    s.area_pdf = area_pdf;
    s.is_delta = false;
    s.is_infinite = false;
    s.valid = pdf > 0.0f && std::isfinite(pdf);
  }

  // LightSampler stores no zero-area lamp (zero power), so area > 0 here.
  float intersect_t(Vec3f o, Vec3f d, float t_max) const {
    const float denom = dot(d, normal);
    if (denom >= 0.0f) return -1.0f;  // one-sided: only rays travelling against the emission
    const float t = dot(center - o, normal) / denom;
    if (!(t > 0.0f && t < t_max)) return -1.0f;
    const Vec3f q = o + d * t - center;
    const float a = dot(q, dual_u), b = dot(q, dual_v);
    const bool inside =
        ellipse ? (4.0f * (a * a + b * b) <= 1.0f) : (std::fabs(a) <= 0.5f && std::fabs(b) <= 0.5f);
    return inside ? t : -1.0f;
  }

  void fill_hit(Vec3f o, Vec3f d, float t, LightHit& hit) const {
    hit.distance = t;
    hit.position = o + d * t;
    hit.normal = normal;
    hit.radiance = radiance;
    const std::optional<SphericalRectangle> sph = spherical(o);
    hit.pdf = sph ? 1.0f / sph->solid_angle() : t * t / (area * -dot(d, normal));
  }
};

}  // namespace gdpt::lights
