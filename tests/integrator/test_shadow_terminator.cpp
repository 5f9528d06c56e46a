// The shadow terminator geometry offset (core/shadow_terminator.h) against values worked out by
// hand on a right triangle in the z = 0 plane with tilted corner normals.
#include <gtest/gtest.h>

#include <cmath>

#include "core/shadow_terminator.h"

using namespace gdpt;

namespace {

constexpr float kThird = 1.0f / 3.0f;
const Vec3f kCentroid(kThird, kThird, kThird);
const Vec3f kUp(0.0f, 0.0f, 1.0f);

// P0 = origin, P1 = x, P2 = y; N1, N2 lean out along their edges, N0 as given.
SmoothTriangle triangle(Vec3f n0) {
  return {{Vec3f(0.0f), Vec3f(1.0f, 0.0f, 0.0f), Vec3f(0.0f, 1.0f, 0.0f)},
          {n0, Vec3f(0.6f, 0.0f, 0.8f), Vec3f(0.0f, 0.6f, 0.8f)}};
}

void expect_vec(Vec3f got, Vec3f want) {
  EXPECT_NEAR(got.x, want.x, 1e-6f);
  EXPECT_NEAR(got.y, want.y, 1e-6f);
  EXPECT_NEAR(got.z, want.z, 1e-6f);
}

}  // namespace

// N0 = (-0.48, -0.36, 0.8): edge bends e02 = -0.96, e12 = -1.2, e01 = 1.08, so the quadratic patch
// at the centroid is (0.96 * 2 - 1.08 + 1.2 * 2) / 9 = 0.36; the tangent planes of the corners lie
// 0.28 (N0), 0.4 and 0.4 above it, so the envelope (0.28) bounds the lift, along the interpolated
// normal n = (0.04, 0.08, 0.8).
TEST(ShadowTerminator, LiftAtCentroidIsBoundedByTheCornerPlanes) {
  const SmoothTriangle t = triangle(Vec3f(-0.48f, -0.36f, 0.8f));
  expect_vec(smooth_surface_lift(t, kCentroid, kUp), Vec3f(0.04f, 0.08f, 0.8f) * 0.28f);
}

// From below (ng against n) the surface is pushed down: the corner planes seen from below give
// reach 0.48, 0.6, 0.6 and heights 0.48 - 0.28, 0.6 - 0.4, 0.6 - 0.4 = 0.2; the lift is -0.2 n
// (half the patch, 0.18, is larger than -0.2).
TEST(ShadowTerminator, LiftFromBelowPushesDown) {
  const SmoothTriangle t = triangle(Vec3f(-0.48f, -0.36f, 0.8f));
  expect_vec(smooth_surface_lift(t, kCentroid, -kUp), Vec3f(0.04f, 0.08f, 0.8f) * -0.2f);
}

// N0 = ng: corner 0's plane passes through the centroid (envelope 0), so half the patch wins:
// e02 = -0.6, e12 = -1.2, e01 = 0.6, patch (1.2 - 1.2 + 2.4) / 9 = 0.2667, lift 0.1333 n with
// n = (0.2, 0.2, 2.6 / 3).
TEST(ShadowTerminator, LiftIsHalfThePatchWhereTheEnvelopeIsZero) {
  const SmoothTriangle t = triangle(kUp);
  expect_vec(smooth_surface_lift(t, kCentroid, kUp),
             Vec3f(0.2f, 0.2f, 2.6f / 3.0f) * (0.5f * 2.4f / 9.0f));
}

// At a corner the point is on the surface: no lift.
TEST(ShadowTerminator, NoLiftAtACorner) {
  const SmoothTriangle t = triangle(Vec3f(-0.48f, -0.36f, 0.8f));
  expect_vec(smooth_surface_lift(t, Vec3f(1.0f, 0.0f, 0.0f), kUp), Vec3f(0.0f));
}

// A flat triangle (every corner normal = ng) is its own surface.
TEST(ShadowTerminator, NoLiftOnAFlatTriangle) {
  SmoothTriangle t = triangle(kUp);
  t.n[1] = t.n[2] = kUp;
  expect_vec(smooth_surface_lift(t, Vec3f(0.2f, 0.5f, 0.3f), kUp), Vec3f(0.0f));
}

// The ramp with cutoff 0.1: 2 - (cos_g + cos_s) / cutoff below the cutoff, 1 - cos_g / cutoff
// above it, clamped to [0, 1].
TEST(ShadowTerminator, AmountRampsWithTheCutoff) {
  const Vec3f tilted(0.6f, 0.0f, 0.8f);
  Vec3f side;
  // Grazing in y at cos_g 0.06: 2 - 1.08 = 0.92.
  const Vec3f grazing(0.0f, std::sqrt(1.0f - 0.06f * 0.06f), 0.06f);
  // Shading normal (0, 0, 0.8) + (0.6, 0, 0) leans away in x: cos_s = 0.8 * 0.06.
  EXPECT_NEAR(terminator_lift_amount(0.1f, tilted, kUp, grazing, side),
              2.0f - (0.06f + 0.048f) / 0.1f, 1e-5f);
  expect_vec(side, kUp);
  // cos_s = 0.96 above the cutoff, cos_g = 0.6: 1 - 6, clamped to 0.
  EXPECT_EQ(terminator_lift_amount(0.1f, tilted, kUp, Vec3f(0.8f, 0.0f, 0.6f), side), 0.0f);
  // Shading normal towards the light (cos_s 0.63925), geometric grazing (cos_g 0.05): 0.5.
  const Vec3f low(std::sqrt(1.0f - 0.05f * 0.05f), 0.0f, 0.05f);
  EXPECT_NEAR(terminator_lift_amount(0.1f, tilted, kUp, low, side), 0.5f, 1e-5f);
  // The light below the triangle's plane but above the shading normal's: the full lift.
  const Vec3f below(std::sqrt(1.0f - 0.01f), 0.0f, -0.1f);
  EXPECT_EQ(terminator_lift_amount(0.1f, tilted, kUp, below, side), 1.0f);
  expect_vec(side, kUp);
  // Geometry Offset 0 turns it off at the terminator itself.
  EXPECT_EQ(terminator_lift_amount(0.0f, tilted, kUp, below, side), 0.0f);
}

// Light behind the shading normal (transmission): the geometric normal is taken on that side,
// and there the same ramp applies (cos_s = cos_g = 0.8 here: no lift).
TEST(ShadowTerminator, TransmissionTakesTheOtherSide) {
  Vec3f side;
  EXPECT_EQ(terminator_lift_amount(0.1f, kUp, kUp, Vec3f(0.0f, 0.6f, -0.8f), side), 0.0f);
  expect_vec(side, -kUp);
  // Grazing from below (cos 0.05 on both): 2 - 1 = 1.
  const Vec3f under(0.0f, std::sqrt(1.0f - 0.0025f), -0.05f);
  EXPECT_NEAR(terminator_lift_amount(0.1f, kUp, kUp, under, side), 1.0f, 1e-5f);
  expect_vec(side, -kUp);
}

// The shading offset's frequency multiplier, Cycles' 1 / (1 - offset / 2): 1 (off), 4/3, 2.
TEST(ShadowTerminator, ShadingOffsetFrequency) {
  EXPECT_FLOAT_EQ(terminator_frequency(0.0f), 1.0f);
  EXPECT_FLOAT_EQ(terminator_frequency(0.5f), 4.0f / 3.0f);
  EXPECT_FLOAT_EQ(terminator_frequency(1.0f), 2.0f);
}

// max(cos(k a), 0) / cos(a) by hand: k = 4/3 at a = 60 degrees gives cos(80) / cos(60) =
// 0.173648 / 0.5; k = 2 at 30 degrees cos(60) / cos(30) = 0.57735; at 70 degrees k = 4/3 turns
// past 90 (0); the normal itself keeps its value; below the horizon and with k = 1 nothing moves.
TEST(ShadowTerminator, ShadingFactorShiftsTheCosine) {
  const float k = 4.0f / 3.0f, deg = float(M_PI) / 180.0f;
  EXPECT_NEAR(terminator_shading_factor(0.5f, k), 0.3472964f, 1e-5f);
  EXPECT_NEAR(terminator_shading_factor(std::cos(30 * deg), 2.0f), 0.5773503f, 1e-5f);
  EXPECT_EQ(terminator_shading_factor(std::cos(70 * deg), k), 0.0f);
  EXPECT_NEAR(terminator_shading_factor(1.0f, k), 1.0f, 1e-6f);
  EXPECT_EQ(terminator_shading_factor(-0.5f, k), 1.0f);
  EXPECT_EQ(terminator_shading_factor(0.5f, 1.0f), 1.0f);
}
