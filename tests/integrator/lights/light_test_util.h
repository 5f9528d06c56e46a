// Shared helpers for the light tests: scene construction, Monte Carlo estimators of the solid
// angle (mean of 1 / pdf) and irradiance (mean of L cos / pdf); chi-square statistics come from
// testing/statistics.h.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "render/light_sampler.h"
#include "scene/scene.h"
#include "shaders/material.h"
#include "testing/materials.h"
#include "testing/statistics.h"

namespace gdpt::test {

// Light frame at `position` whose local -Z (the emission axis of spot/sun/area lights) points
// along `emit_direction`; `scale_x`, `scale_y` scale the local X and Y axes.
Transform light_frame(Vec3f position, Vec3f emit_direction, float scale_x = 1.0f,
                      float scale_y = 1.0f);

// Empty scene with a black world (the default world is grey and would be a light).
Scene black_scene();

struct Estimate {
  double solid_angle = 0;  // mean of 1/pdf over all samples (invalid ones count 0)
  double irradiance = 0;   // mean of L.x max(0, n.w) / pdf (delta: L.x max(0, n.w) / pdf)
  size_t valid = 0;
};

// Stratified 3-D samples (u_select, u) from a fixed seed; pdfs include the selection pmf.
Estimate estimate(const LightSampler& lights, Vec3f ref, Vec3f normal, size_t n, uint32_t seed = 1);

}  // namespace gdpt::test
