// Oracles for the pure shift mathematics of integrators/gpt/shift_mapping.h:
//  - every Jacobian equals a finite-difference estimate of the shift's change of measure
//    (perturb the base direction or point, map it through the shift, measure the ratio of the
//    solid angles spanned numerically);
//  - the half-vector copy is an involution (shifting back recovers the base, J J_back = 1);
//  - the documented failure cases fail;
//  - the MIS weights of all four techniques of one path pair sum to one.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "integrators/gpt/shift_mapping.h"

namespace gdpt::shift {
namespace {

struct Rng {
  std::mt19937_64 gen;
  explicit Rng(uint64_t seed) : gen(seed) {}
  double uniform(double a = 0.0, double b = 1.0) {
    return std::uniform_real_distribution<double>(a, b)(gen);
  }
  Vec3d sphere() {
    const double z = uniform(-1.0, 1.0), phi = uniform(0.0, 2.0 * M_PI);
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
  Vec3d point(double extent) {
    return {uniform(-extent, extent), uniform(-extent, extent), uniform(-extent, extent)};
  }
};

// Two unit tangents orthogonal to the unit vector w.
void tangents(Vec3d w, Vec3d& u, Vec3d& v) {
  const Vec3d a = std::fabs(w.x) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
  u = normalize(cross(w, a));
  v = cross(w, u);
}

// Solid angle spanned on the unit sphere by central differences of a direction field
// d(a, b) around (0, 0): |d_a x d_b| (the area element of the map).
template <typename F>
double solid_angle_element(F&& dir, double eps) {
  const Vec3d da = (dir(eps, 0.0) - dir(-eps, 0.0)) / (2.0 * eps);
  const Vec3d db = (dir(0.0, eps) - dir(0.0, -eps)) / (2.0 * eps);
  return length(cross(da, db));
}

Vec3f to_f(Vec3d v) {
  return v.to_float();
}

// Intersection of the ray o + t d with the plane through p with normal n.
Vec3d hit_plane(Vec3d o, Vec3d d, Vec3d p, Vec3d n) {
  const double t = dot(p - o, n) / dot(d, n);
  return o + d * t;
}

// ----------------------------------------------------------------------------------------------
// Reconnection Jacobian: the base direction at x_i is perturbed, the perturbed ray hits the
// target's tangent plane, the offset y_i connects to that moved point; J = d omega' / d omega.
// ----------------------------------------------------------------------------------------------
TEST(ShiftMapping, ReconnectionJacobianMatchesFiniteDifferences) {
  Rng rng(1);
  int tested = 0;
  for (int trial = 0; trial < 400; ++trial) {
    // Positions exactly representable in float so that the float interface sees the same points.
    const Vec3d x = Vec3d(to_f(rng.point(1.0)));
    const Vec3d y = Vec3d(to_f(x + rng.point(0.3)));
    const Vec3d t = Vec3d(to_f(rng.point(1.0) + Vec3d(0, 0, 2.5)));
    const Vec3d n = Vec3d(to_f(rng.sphere()));
    const Vec3d w0 = normalize(t - x);
    const Vec3d w0_off = normalize(t - y);
    // Stay away from grazing targets, where the finite difference itself is ill-conditioned.
    if (std::fabs(dot(w0, n)) < 0.1 || std::fabs(dot(w0_off, n)) < 0.1) continue;

    const Reconnection r = reconnect(to_f(x), to_f(y), to_f(t), to_f(n));
    ASSERT_TRUE(r.valid);
    EXPECT_NEAR(length(r.direction - w0_off), 0.0, 1e-6);
    EXPECT_NEAR(r.distance, length(t - y), 1e-6 * length(t - y));

    Vec3d u, v;
    tangents(w0, u, v);
    auto base_dir = [&](double a, double b) { return normalize(w0 + u * a + v * b); };
    auto offset_dir = [&](double a, double b) {
      return normalize(hit_plane(x, base_dir(a, b), t, n) - y);
    };
    const double eps = 1e-5;
    const double fd = solid_angle_element(offset_dir, eps) / solid_angle_element(base_dir, eps);
    EXPECT_NEAR(r.jacobian / fd, 1.0, 1e-5) << "trial " << trial;

    // The reverse shift has the inverse Jacobian.
    const Reconnection back = reconnect(to_f(y), to_f(x), to_f(t), to_f(n));
    ASSERT_TRUE(back.valid);
    EXPECT_NEAR(r.jacobian * back.jacobian, 1.0, 1e-9);
    ++tested;
  }
  EXPECT_GT(tested, 150);
}

// ----------------------------------------------------------------------------------------------
// Light reconnection Jacobian, measured the other way round: the shared point on an area light
// moves on the light's plane, the solid angles it sweeps at x (base) and y (offset) are compared.
// ----------------------------------------------------------------------------------------------
TEST(ShiftMapping, LightReconnectionJacobianMatchesFiniteDifferences) {
  Rng rng(2);
  int tested = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Vec3d x = Vec3d(to_f(rng.point(1.0)));
    const Vec3d y = Vec3d(to_f(x + rng.point(0.4)));
    const Vec3d l = Vec3d(to_f(rng.point(0.5) + Vec3d(0, 0, 2.0)));
    const Vec3d n = Vec3d(to_f(rng.sphere()));
    if (std::fabs(dot(normalize(l - x), n)) < 0.1 || std::fabs(dot(normalize(l - y), n)) < 0.1)
      continue;
    const double J = light_reconnection_jacobian(to_f(x), to_f(y), to_f(l), to_f(n), false);
    Vec3d s, t;
    tangents(n, s, t);
    auto at = [&](Vec3d from) {
      return [&, from](double a, double b) { return normalize(l + s * a + t * b - from); };
    };
    const double eps = 1e-5;
    const double fd = solid_angle_element(at(y), eps) / solid_angle_element(at(x), eps);
    EXPECT_NEAR(J / fd, 1.0, 1e-5) << "trial " << trial;
    // Consistency with the light densities: J p'_L = p_L for one area density p_A.
    const double pA = 0.37;
    const double pL = pA * length_squared(l - x) / std::fabs(dot(normalize(x - l), n));
    const double pL_off = pA * length_squared(l - y) / std::fabs(dot(normalize(y - l), n));
    EXPECT_NEAR(J * pL_off / pL, 1.0, 1e-9);
    ++tested;
  }
  EXPECT_GT(tested, 150);
  // Point-like and infinite lights share the light vertex with a discrete density or a direction.
  EXPECT_EQ(light_reconnection_jacobian({0, 0, 0}, {1, 0, 0}, {0, 0, 3}, {0, 0, 0}, true), 1.0);
}

// Random direction in the upper (+z) or lower hemisphere.
Vec3d hemisphere(Rng& rng, bool upper, double min_cos = 0.05) {
  for (;;) {
    Vec3d w = rng.sphere();
    if (std::fabs(w.z) < min_cos) continue;
    if ((w.z > 0) != upper) w.z = -w.z;
    return w;
  }
}

// ----------------------------------------------------------------------------------------------
// Half-vector copy, reflection.
// ----------------------------------------------------------------------------------------------
TEST(ShiftMapping, HalfVectorReflectionJacobianAndInvolution) {
  Rng rng(3);
  int tested = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const bool upper = trial % 2 == 0;  // reflections inside a surface too
    const Vec3d wi = hemisphere(rng, upper), wo = hemisphere(rng, upper);
    const Vec3d wi_off = hemisphere(rng, upper);
    const HalfVectorShift s = half_vector_shift(wi, wo, wi_off, 1.5);
    if (!s.valid) continue;  // reflected below the surface: the offset dies, nothing to measure
    EXPECT_NEAR(length(s.wo), 1.0, 1e-12);
    // The half vector is shared.
    EXPECT_NEAR(length(normalize(wi_off + s.wo) - normalize(wi + wo)), 0.0, 1e-9);

    Vec3d u, v;
    tangents(wo, u, v);
    auto base_dir = [&](double a, double b) { return normalize(wo + u * a + v * b); };
    auto offset_dir = [&](double a, double b) {
      return half_vector_reflection(wi, base_dir(a, b), wi_off).wo;
    };
    const double eps = 1e-6;
    const double fd = solid_angle_element(offset_dir, eps) / solid_angle_element(base_dir, eps);
    EXPECT_NEAR(s.jacobian / fd, 1.0, 1e-5) << "trial " << trial;

    const HalfVectorShift back = half_vector_shift(wi_off, s.wo, wi, 1.5);
    ASSERT_TRUE(back.valid);
    EXPECT_NEAR(length(back.wo - wo), 0.0, 1e-9);
    EXPECT_NEAR(s.jacobian * back.jacobian, 1.0, 1e-9);
    ++tested;
  }
  EXPECT_GT(tested, 200);
}

// A base transmission: refract wi through a random microfacet normal m with the lobe's IOR.
bool sample_transmission(Rng& rng, double ior, Vec3d wi, Vec3d& wo) {
  Vec3d m = hemisphere(rng, true, 0.5);
  if (!refract(wi, m, relative_eta(ior, wi), wo)) return false;
  return wi.z * wo.z < 0.0 && std::fabs(wo.z) > 0.05;
}

// ----------------------------------------------------------------------------------------------
// Half-vector copy, refraction (both sides of the interface, IOR above and below 1).
// ----------------------------------------------------------------------------------------------
TEST(ShiftMapping, HalfVectorRefractionJacobianAndInvolution) {
  Rng rng(4);
  int tested = 0, opposite_sides = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const double ior = trial % 3 == 0 ? 0.75 : 1.5;
    const bool from_outside = trial % 2 == 0;
    const Vec3d wi = hemisphere(rng, from_outside);
    Vec3d wo;
    if (!sample_transmission(rng, ior, wi, wo)) continue;
    // Mostly from the same side, sometimes from the other side of the interface.
    const bool same_side = trial % 5 != 0;
    const Vec3d wi_off = hemisphere(rng, same_side ? from_outside : !from_outside);
    const HalfVectorShift s = half_vector_shift(wi, wo, wi_off, ior);
    if (!s.valid) continue;  // TIR / mismatch: tested separately
    EXPECT_LT(s.wo.z * wi_off.z, 0.0);
    EXPECT_NEAR(length(s.wo), 1.0, 1e-12);

    Vec3d u, v;
    tangents(wo, u, v);
    auto base_dir = [&](double a, double b) { return normalize(wo + u * a + v * b); };
    auto offset_dir = [&](double a, double b) {
      return half_vector_refraction(wi, base_dir(a, b), wi_off, ior).wo;
    };
    const double eps = 1e-6;
    const double fd = solid_angle_element(offset_dir, eps) / solid_angle_element(base_dir, eps);
    EXPECT_NEAR(s.jacobian / fd, 1.0, 1e-4) << "trial " << trial;

    const HalfVectorShift back = half_vector_shift(wi_off, s.wo, wi, ior);
    ASSERT_TRUE(back.valid) << "trial " << trial;
    EXPECT_NEAR(length(back.wo - wo), 0.0, 1e-8);
    EXPECT_NEAR(s.jacobian * back.jacobian, 1.0, 1e-8);
    ++tested;
    opposite_sides += same_side ? 0 : 1;
  }
  EXPECT_GT(tested, 300);
  EXPECT_GT(opposite_sides, 10);
}

TEST(ShiftMapping, HalfVectorFailureCases) {
  // eta = 1: straight transmission has no generalised half vector.
  const Vec3d wi = normalize(Vec3d(0.3, 0.1, 1.0));
  EXPECT_FALSE(half_vector_shift(wi, -wi, normalize(Vec3d(0.1, 0.2, 1.0)), 1.0).valid);

  // Base leaves glass (inside -> outside) near the normal; the offset arrives inside at a grazing
  // angle where the same half vector gives total internal reflection.
  const double ior = 1.5;
  const Vec3d base_wi = normalize(Vec3d(0.05, 0.0, -1.0));
  Vec3d base_wo;
  ASSERT_TRUE(refract(base_wi, Vec3d(0, 0, 1), relative_eta(ior, base_wi), base_wo));
  ASSERT_GT(base_wo.z, 0.0);
  const Vec3d grazing = normalize(Vec3d(1.0, 0.0, -0.2));
  EXPECT_FALSE(half_vector_shift(base_wi, base_wo, grazing, ior).valid);
  EXPECT_TRUE(half_vector_shift(base_wi, base_wo, normalize(Vec3d(0.1, 0.0, -1.0)), ior).valid);

  // A reflection whose copy points below the surface is a reflection/transmission mismatch.
  const Vec3d r_wi = normalize(Vec3d(-0.2, 0.0, 1.0)), r_wo = normalize(Vec3d(0.9, 0.0, 0.2));
  EXPECT_FALSE(half_vector_shift(r_wi, r_wo, normalize(Vec3d(-1.0, 0.0, 0.05)), ior).valid);
}

TEST(ShiftMapping, VertexClassificationByThreshold) {
  EXPECT_EQ(classify_vertex(0.0f), VertexType::Specular);  // delta lobe
  EXPECT_EQ(classify_vertex(0.00099f), VertexType::Specular);
  EXPECT_EQ(classify_vertex(0.001f), VertexType::Diffuse);
  EXPECT_EQ(classify_vertex(0.0011f), VertexType::Diffuse);
  EXPECT_EQ(classify_vertex(1.0f), VertexType::Diffuse);
  EXPECT_EQ(classify_vertex(0.004f, 0.005f), VertexType::Specular);
  EXPECT_EQ(classify_vertex(0.006f, 0.005f), VertexType::Diffuse);
}

// ----------------------------------------------------------------------------------------------
// MIS: for one path pair (x ending on an area light, y = T(x)), the four techniques (light / BSDF
// sample at the last vertex, from x's pixel as base or from y's pixel as base shifted back) have
// weights summing to one. The densities come from real geometry: the last segment of the pair is
// a reconnection to a point on the light, whose Jacobian enters both techniques of both sides.
// ----------------------------------------------------------------------------------------------
TEST(ShiftMapping, MisWeightsOfOnePathPairSumToOne) {
  Rng rng(5);
  for (int trial = 0; trial < 2000; ++trial) {
    const Vec3d x = Vec3d(to_f(rng.point(1.0))), y = Vec3d(to_f(x + rng.point(0.3)));
    const Vec3d l = Vec3d(to_f(rng.point(0.5) + Vec3d(0, 0, 2.0)));
    const Vec3d n = Vec3d(to_f(rng.sphere()));
    if (std::fabs(dot(normalize(l - x), n)) < 1e-3 || std::fabs(dot(normalize(l - y), n)) < 1e-3)
      continue;
    // Prefix densities and the prefix Jacobian (arbitrary positive, over many magnitudes).
    const double p = std::exp(rng.uniform(-20, 20)), p_off = std::exp(rng.uniform(-20, 20));
    const double J_prefix = std::exp(rng.uniform(-5, 5));
    const double pA = rng.uniform(0.01, 3.0);
    const double pL = pA * length_squared(l - x) / std::fabs(dot(normalize(x - l), n));
    const double pL_off = pA * length_squared(l - y) / std::fabs(dot(normalize(y - l), n));
    const double pB = trial % 7 == 0 ? 0.0 : rng.uniform(0.0, 5.0);
    const double pB_off = trial % 11 == 0 ? 0.0 : rng.uniform(0.0, 5.0);
    const double J_last = reconnect(to_f(x), to_f(y), to_f(l), to_f(n)).jacobian;
    const double J_last_back = reconnect(to_f(y), to_f(x), to_f(l), to_f(n)).jacobian;

    const PathDensities base{p, pL, pB};
    const PathDensities off = offset_densities(p_off * J_prefix, J_last, pL_off, pB_off);
    // Seen from y's pixel: y is the base, x its offset, all Jacobians inverted.
    const PathDensities base_y{p_off, pL_off, pB_off};
    const PathDensities off_x = offset_densities(p / J_prefix, J_last_back, pL, pB);

    const bool nee_shifted = trial % 3 != 0;
    double sum = 0.0;
    if (nee_shifted) {
      sum += mis_weight(base, off, base.light) + mis_weight(base, off, base.bsdf);
      sum += mis_weight(base_y, off_x, base_y.light) + mis_weight(base_y, off_x, base_y.bsdf);
    } else {
      // Next-event estimation dropped for the pair on both sides: only BSDF sampling remains.
      const PathDensities b{p, 0.0, pB},
          o = offset_densities(p_off * J_prefix, J_last, 0.0, pB_off);
      const PathDensities by{p_off, 0.0, pB_off},
          ox = offset_densities(p / J_prefix, J_last_back, 0.0, pB);
      if (pB == 0.0 && pB_off == 0.0) continue;
      sum += mis_weight(b, o, b.bsdf) + mis_weight(by, ox, by.bsdf);
    }
    EXPECT_NEAR(sum, 1.0, 1e-9) << "trial " << trial;
  }

  // A failed shift (offset density 0): the base keeps the plain two-technique weight.
  const PathDensities base{2.0, 3.0, 1.0}, dead{0.0, 0.0, 0.0};
  EXPECT_NEAR(mis_weight(base, dead, base.light) + mis_weight(base, dead, base.bsdf), 1.0, 1e-15);
  EXPECT_NEAR(mis_weight_over_pdf(base, dead, base.light), 3.0 / (2.0 * (9.0 + 1.0)), 1e-15);
}

}  // namespace
}  // namespace gdpt::shift
