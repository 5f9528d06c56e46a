// valid_reflection_normal (core/valid_reflection.h): Cycles' ensure_valid_reflection.
// Oracle: a brute-force search for the smallest rotation of the shading normal towards the
// geometric normal, in their plane, that lifts the mirrored incoming direction to the threshold.
#include "core/valid_reflection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace gdpt {
namespace {

Vec3f reflect(Vec3f wi, Vec3f n) {
  return n * (2.0f * dot(n, wi)) - wi;
}

TEST(ValidReflection, RotatesOnlyAsFarAsTheThresholdNeeds) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  auto unit = [&] {
    Vec3f v;
    do v = Vec3f(u(rng), u(rng), u(rng));
    while (length(v) > 1.0f || length(v) < 0.1f);
    return normalize(v);
  };
  const Vec3f ng(0.0f, 0.0f, 1.0f);
  int kept = 0, rotated = 0, minimal = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3f wi = unit(), ns = unit();
    wi.z = std::fabs(wi.z);
    wi = normalize(wi);
    if (ns.z < 0.2f) continue;  // shading normals within ~80 degrees of the geometric one
    const float t = std::min(0.9f * wi.z, 0.01f);
    const Vec3f n = valid_reflection_normal(ns, ng, wi);
    if (reflect(wi, ns).z >= t) {
      EXPECT_EQ(n, ns);  // valid already: untouched
      ++kept;
      continue;
    }
    ++rotated;
    if (n == ng) continue;  // no rotation works: the geometric normal
    EXPECT_NEAR(length(n), 1.0f, 1e-5f);
    EXPECT_GT(reflect(wi, n).z, 0.0f) << "the reflection is above the surface";
    // In the plane of ns and ng, on ns's side, and tilted towards ng.
    const Vec3f side = normalize(Vec3f(ns.x, ns.y, 0.0f));
    EXPECT_NEAR(dot(cross(side, ng), n), 0.0f, 1e-5f);
    EXPECT_GE(dot(n, side), -1e-6f);
    EXPECT_GE(n.z, ns.z - 1e-6f);
    // The smallest rotation reaching the threshold, searched in steps of 1e-4 in n.z.
    float best = -1.0f;
    for (int k = 0; k <= 10000 && best < 0.0f; ++k) {
      const float z = std::max(ns.z, k / 10000.0f);
      const Vec3f c = side * std::sqrt(1.0f - z * z) + ng * z;
      if (reflect(wi, c).z >= t - 1e-6f) best = z;
    }
    minimal += best >= 0.0f && std::fabs(best - n.z) < 2e-3f;
  }
  EXPECT_GT(kept, 1000);
  EXPECT_GT(rotated, 1000);
  // Cycles' closed form (a quadratic in n.z^2, roots chosen by their reflections) is the
  // minimal rotation except in rare cases where its root choice overshoots: 99.5% here.
  EXPECT_GE(minimal, int(0.995 * rotated)) << minimal << " of " << rotated;
}

}  // namespace
}  // namespace gdpt
