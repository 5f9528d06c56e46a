// What a light sampler returns: a sampled light point (LightSample) and an analytic lamp found
// along a ray (LightHit). Separate from light_sampler.h so the light types (integrator/lights/)
// can fill them while LightSampler holds those types by value for its in-line hot paths.
#pragma once

#include "core/vec.h"

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
  bool cast_shadow = true;  // false: unoccluded, no shadow ray (Light::cast_shadow)
  bool caustics = false;    // an area lamp with Shadow Caustics (Light::caustics_light)
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
  bool caustics = false;        // LightSample::caustics
  float area_pdf = 0;           // area lights: selection pmf / area (LightSample::area_pdf)
};

}  // namespace gdpt
