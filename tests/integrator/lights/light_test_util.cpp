#include "light_test_util.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/frame.h"

namespace gdpt::test {

Transform light_frame(Vec3f position, Vec3f emit_direction, float scale_x, float scale_y) {
  const Frame f(-normalize(emit_direction));  // local +Z = -emit
  const Vec3f x = f.s * scale_x, y = f.t * scale_y, z = f.n;
  const float rows[12] = {x.x, y.x,        z.x, position.x, x.y, y.y,
                          z.y, position.y, x.z, y.z,        z.z, position.z};
  return Transform::from_rows(rows);
}

Scene black_scene() {
  Scene s;
  s.world.color = Spectrum(0.0f);
  return s;
}

Estimate estimate(const LightSampler& lights, Vec3f ref, Vec3f normal, size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  // Stratify the 2-D light sample on a sqrt(n) x sqrt(n) grid; u_select stays random.
  const size_t side = size_t(std::sqrt(double(n)));
  Estimate e;
  double sum_omega = 0, sum_e = 0;
  for (size_t i = 0; i < side * side; ++i) {
    const Vec2f u((float(i % side) + U(rng)) / float(side),
                  (float(i / side) + U(rng)) / float(side));
    const LightSample s = lights.sample(ref, U(rng), u);
    if (!s.valid) continue;
    ++e.valid;
    EXPECT_TRUE(std::isfinite(s.pdf) && s.pdf > 0.0f);
    EXPECT_TRUE(is_finite(s.radiance));
    EXPECT_NEAR(length(s.direction), 1.0f, 1e-4f);
    sum_omega += 1.0 / double(s.pdf);
    sum_e += double(s.radiance.x) * std::max(0.0, double(dot(normal, s.direction))) / double(s.pdf);
  }
  e.solid_angle = sum_omega / double(side * side);
  e.irradiance = sum_e / double(side * side);
  return e;
}

}  // namespace gdpt::test
