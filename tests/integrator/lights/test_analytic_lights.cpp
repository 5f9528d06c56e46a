// Point, spot, sun and area lights: the sampled solid angle and the irradiance at a point match
// independent closed forms (Cycles 3.4 units, see docs/lights.md).
#include <gtest/gtest.h>

#include <cmath>

#include "light_test_util.h"
#include "render/light_sampler.h"

namespace gdpt {
namespace {

using test::black_scene;
using test::estimate;
using test::light_frame;

constexpr double kPiD = 3.14159265358979323846;

Light make_light(Light::Type type, Vec3f position, Vec3f emit, float power) {
  Light l;
  l.type = type;
  l.light_to_world = light_frame(position, emit);
  l.power = power;
  l.radius = 0.0f;
  return l;
}

TEST(PointLight, DeltaIrradianceIsInverseSquare) {
  Scene scene = black_scene();
  scene.lights.push_back(make_light(Light::Type::Point, {0, 0, 3}, {0, 0, -1}, 100.0f));
  const LightSampler lights(scene, {}, {});
  const LightSample s = lights.sample({0, 0, 0}, 0.5f, {0.5f, 0.5f});
  ASSERT_TRUE(s.valid);
  EXPECT_TRUE(s.is_delta);
  EXPECT_FLOAT_EQ(s.pdf, 1.0f);
  EXPECT_NEAR(s.distance, 3.0f, 1e-6f);
  // E = P / (4 pi d^2) at normal incidence.
  EXPECT_NEAR(s.radiance.x, 100.0 / (4.0 * kPiD * 9.0), 1e-6);
  // Inverse square at another distance and cosine at an angle.
  const test::Estimate e = estimate(lights, {0, 0, -2}, normalize(Vec3f(1, 0, 1)), 16);
  EXPECT_NEAR(e.irradiance, 100.0 / (4.0 * kPiD * 25.0) * std::sqrt(0.5), 1e-6);
}

TEST(PointLight, RadiusIsADiscFacingTheReceiver) {
  Scene scene = black_scene();
  Light l = make_light(Light::Type::Point, {0, 0, 2}, {0, 0, -1}, 50.0f);
  l.radius = 0.5f;
  scene.lights.push_back(l);
  const LightSampler lights(scene, {}, {});
  const test::Estimate e = estimate(lights, {0, 0, 0}, {0, 0, 1}, 250000);
  // Cycles 3.4: a disc of radius r facing the receiver, radiance I / (pi r^2).
  const double omega = 2.0 * kPiD * (1.0 - 2.0 / std::sqrt(4.0 + 0.25));
  EXPECT_NEAR(e.solid_angle, omega, 5e-3 * omega);
  const double expected = 50.0 / (4.0 * kPiD) / (4.0 + 0.25);  // I / (d^2 + r^2)
  EXPECT_NEAR(e.irradiance, expected, 3e-3 * expected);
}

TEST(PointLight, ReceiverAtTheCentreGivesNoLightAndNoNaN) {
  Scene scene = black_scene();
  Light l = make_light(Light::Type::Point, {0, 0, 0}, {0, 0, -1}, 50.0f);
  l.radius = 1.0f;
  scene.lights.push_back(l);
  const LightSampler lights(scene, {}, {});
  EXPECT_FALSE(lights.sample({0, 0, 0}, 0.3f, {0.2f, 0.7f}).valid);
  LightHit hit;
  EXPECT_FALSE(lights.intersect({0, 0, 0}, {1, 0, 0}, 1e30f, hit));
  // Very close to the centre: still finite.
  const LightSample s = lights.sample({1e-3f, 0, 0}, 0.3f, {0.2f, 0.7f});
  ASSERT_TRUE(s.valid);
  EXPECT_TRUE(std::isfinite(s.pdf) && is_finite(s.radiance));
}

// Cycles 3.4 spot attenuation, written out independently: cos * smoothstep over the blend band.
double cycles_spot(double cos_angle, double spot_size, double blend) {
  const double cos_half = std::cos(0.5 * spot_size);
  if (cos_angle <= cos_half) return 0.0;
  const double smooth = (1.0 - cos_half) * blend;
  const double t = cos_angle - cos_half;
  if (t < smooth) {
    const double x = t / smooth;
    return cos_angle * x * x * (3.0 - 2.0 * x);
  }
  return cos_angle;
}

TEST(SpotLight, OnAxisAndBlendBand) {
  Scene scene = black_scene();
  Light l = make_light(Light::Type::Spot, {0, 0, 4}, {0, 0, -1}, 200.0f);
  l.spot_size = 1.0f;  // radians, full angle
  l.spot_blend = 0.5f;
  scene.lights.push_back(l);
  const LightSampler lights(scene, {}, {});
  for (double angle : {0.0, 0.2, 0.35, 0.45, 0.49}) {
    const Vec3f ref(float(4.0 * std::tan(angle)), 0.0f, 0.0f);
    const double d2 = 16.0 + double(ref.x) * ref.x;
    const Vec3f n = normalize(Vec3f(0, 0, 4) - ref);
    const test::Estimate e = estimate(lights, ref, n, 4);
    const double expected = 200.0 / (4.0 * kPiD * d2) * cycles_spot(std::cos(angle), 1.0, 0.5);
    EXPECT_NEAR(e.irradiance, expected, 1e-5 * (1.0 + expected)) << "angle " << angle;
  }
  // Outside the cone: nothing.
  EXPECT_FALSE(lights.sample({4.0f, 0, 0}, 0.5f, {0.5f, 0.5f}).valid);
}

TEST(SpotLight, DiscSpotAgainstQuadrature) {
  Scene scene = black_scene();
  const Vec3f c(0.4f, 0, 1.5f);
  Light l = make_light(Light::Type::Spot, c, {0, 0, -1}, 80.0f);
  l.radius = 0.3f;
  l.spot_size = 0.8f;
  l.spot_blend = 0.6f;
  scene.lights.push_back(l);
  const LightSampler lights(scene, {}, {});
  // Quadrature over the disc facing the receiver at the origin; the attenuation uses the
  // direction from each disc point to the receiver. The disc straddles the cone's edge.
  const Vec3f dn = normalize(Vec3f(0, 0, 0) - c);
  const Frame f(dn);
  const double r = 0.3, L = 80.0 / (4.0 * kPiD) / (kPiD * r * r);
  double omega = 0, E = 0;
  const int nr = 400, np = 800;
  for (int i = 0; i < nr; ++i)
    for (int j = 0; j < np; ++j) {
      const double rho = r * (i + 0.5) / nr, phi = 2 * kPiD * (j + 0.5) / np;
      const double dA = rho * (r / nr) * (2 * kPiD / np);
      const Vec3f p = c + f.s * float(rho * std::cos(phi)) + f.t * float(rho * std::sin(phi));
      const double d2 = length_squared(p);
      const Vec3f w = normalize(p);  // receiver -> disc point
      const double cos_l = -dot(w, dn);
      const double atten = cycles_spot(w.z, 0.8, 0.6);  // axis (0,0,-1) . (-w)
      // Disc points outside the cone give no light sample: count only the lit part.
      if (atten > 0.0) omega += cos_l / d2 * dA;
      E += L * atten * std::max(0.0, double(w.z)) * cos_l / d2 * dA;
    }
  const test::Estimate e = estimate(lights, {0, 0, 0}, {0, 0, 1}, 250000);
  EXPECT_NEAR(e.solid_angle, omega, 5e-3 * omega);
  EXPECT_NEAR(e.irradiance, E, 3e-3 * E);
}

TEST(SunLight, IrradianceAsCycles) {
  for (float angle_deg : {0.0f, 0.526f, 10.0f, 40.0f}) {
    Scene scene = black_scene();
    Light l = make_light(Light::Type::Sun, {5, 5, 5}, normalize(Vec3f(0, 1, -2)), 3.0f);
    l.sun_angle = angle_deg * float(kPiD) / 180.0f;
    scene.lights.push_back(l);
    const LightSampler lights(scene, {}, {});
    const Vec3f to_sun = -normalize(Vec3f(0, 1, -2));
    // Receiver tilted 30 degrees away from the sun direction (the cone stays above it).
    const Vec3f n = Frame(to_sun).to_world({std::sin(0.5236f), 0.0f, std::cos(0.5236f)});
    const test::Estimate e = estimate(lights, {1, 2, 3}, n, 40000);
    // Cycles' disc of radius R = tan(a) at distance 1: E = P cos(theta) (2/R^2)(sqrt(1+R^2)-1),
    // the mean of 1/sqrt(1 + r^2) over the disc (1 for a delta sun).
    const double R = std::tan(0.5 * angle_deg * kPiD / 180.0);
    const double disc = R > 0 ? 2.0 / (R * R) * (std::sqrt(1.0 + R * R) - 1.0) : 1.0;
    EXPECT_NEAR(e.irradiance, 3.0 * std::cos(0.5236) * disc, 1e-4 * 3.0) << angle_deg;
    if (angle_deg > 0.0f) {
      const double omega = 2.0 * kPiD * (1.0 - std::cos(0.5 * angle_deg * kPiD / 180.0));
      EXPECT_NEAR(e.solid_angle, omega, 1e-3 * omega) << angle_deg;
    }
  }
}

// Irradiance on a plane parallel to a uniform rectangle from its corner region: the classic
// view-factor closed form for a point on the normal through one corner of an X by Y rectangle.
double corner_irradiance(double L, double a, double b, double d) {
  const double X = a / d, Y = b / d;
  const double sx = std::sqrt(1 + X * X), sy = std::sqrt(1 + Y * Y);
  return L / 2.0 * (X / sx * std::atan(Y / sx) + Y / sy * std::atan(X / sy));
}

TEST(AreaLight, SquareAndScaledRectangleOnAxis) {
  struct Case {
    Light::Shape shape;
    float size_x, size_y, scale_x, scale_y;
  };
  for (const Case c : {Case{Light::Shape::Square, 1.0f, 7.0f, 1.0f, 1.0f},
                       Case{Light::Shape::Rectangle, 1.0f, 0.5f, 2.0f, 1.0f},
                       Case{Light::Shape::Rectangle, 0.3f, 2.0f, 1.0f, 0.5f}}) {
    Scene scene = black_scene();
    Light l = make_light(Light::Type::Area, {0, 0, 2}, {0, 0, -1}, 40.0f);
    l.shape = c.shape;
    l.size_x = c.size_x;
    l.size_y = c.size_y;
    l.light_to_world = light_frame({0, 0, 2}, {0, 0, -1}, c.scale_x, c.scale_y);
    scene.lights.push_back(l);
    const LightSampler lights(scene, {}, {});
    const double a = double(c.size_x) * c.scale_x;
    const double b = double(c.shape == Light::Shape::Square ? c.size_x : c.size_y) * c.scale_y;
    const double d = 2.0;
    // Cycles 3.4: radiance = P / (4 A), A including the object scale.
    const double L = 40.0 / (4.0 * a * b);
    const double E = 4.0 * corner_irradiance(L, a / 2, b / 2, d);
    const double omega =
        4.0 * std::asin(a * b / std::sqrt((a * a + 4 * d * d) * (b * b + 4 * d * d)));
    const test::Estimate e = estimate(lights, {0, 0, 0}, {0, 0, 1}, 250000);
    EXPECT_NEAR(e.solid_angle, omega, 5e-3 * omega);
    EXPECT_NEAR(e.irradiance, E, 3e-3 * E);
    // One-sided: nothing behind the light.
    EXPECT_FALSE(lights.sample({0, 0, 3}, 0.5f, {0.5f, 0.5f}).valid);
  }
}

TEST(AreaLight, DiskOnAxis) {
  Scene scene = black_scene();
  Light l = make_light(Light::Type::Area, {0, 0, 1.5f}, {0, 0, -1}, 10.0f);
  l.shape = Light::Shape::Disk;
  l.size_x = 2.0f;  // diameter
  scene.lights.push_back(l);
  const LightSampler lights(scene, {}, {});
  const double R = 1.0, d = 1.5, A = kPiD * R * R, L = 10.0 / (4.0 * A);
  const double omega = 2.0 * kPiD * (1.0 - d / std::sqrt(d * d + R * R));
  const double E = L * kPiD * R * R / (d * d + R * R);
  const test::Estimate e = estimate(lights, {0, 0, 0}, {0, 0, 1}, 250000);
  EXPECT_NEAR(e.solid_angle, omega, 5e-3 * omega);
  EXPECT_NEAR(e.irradiance, E, 3e-3 * E);
}

TEST(AreaLight, TiltedEllipseOffAxisAgainstQuadrature) {
  Scene scene = black_scene();
  const Vec3f center(0.7f, -0.4f, 2.0f);
  const Vec3f emit = normalize(Vec3f(0.3f, 0.2f, -1.0f));
  Light l = make_light(Light::Type::Area, center, emit, 25.0f);
  l.shape = Light::Shape::Ellipse;
  l.size_x = 1.2f;
  l.size_y = 0.5f;
  scene.lights.push_back(l);
  const LightSampler lights(scene, {}, {});
  // Independent quadrature over the ellipse in polar coordinates.
  const Frame f(-emit);
  const double a = 0.6, b = 0.25, A = kPiD * a * b, L = 25.0 / (4.0 * A);
  const Vec3f n_recv(0, 0, 1);
  double omega = 0, E = 0;
  const int nr = 400, np = 800;
  for (int i = 0; i < nr; ++i)
    for (int j = 0; j < np; ++j) {
      const double rho = (i + 0.5) / nr, phi = 2 * kPiD * (j + 0.5) / np;
      const double dA = a * b * rho * (1.0 / nr) * (2 * kPiD / np);
      const Vec3f p =
          center + f.s * float(a * rho * std::cos(phi)) + f.t * float(b * rho * std::sin(phi));
      const Vec3f to = p;  // receiver at the origin
      const double d2 = length_squared(to);
      const Vec3f w = normalize(to);
      const double cos_l = -dot(w, emit);
      omega += cos_l / d2 * dA;
      E += L * std::max(0.0, double(dot(w, n_recv))) * cos_l / d2 * dA;
    }
  const test::Estimate e = estimate(lights, {0, 0, 0}, n_recv, 250000);
  EXPECT_NEAR(e.solid_angle, omega, 5e-3 * omega);
  EXPECT_NEAR(e.irradiance, E, 3e-3 * E);
}

// Rectangles: spherical-rectangle sampling near the light, area sampling far away (solid angle
// under 1e-3 sr); both against a midpoint quadrature over the rectangle.
TEST(AreaLight, TiltedRectangleNearAndFarAgainstQuadrature) {
  const Vec3f emit = normalize(Vec3f(-0.2f, 0.3f, -1.0f));
  for (const float dist : {1.5f, 60.0f}) {
    Scene scene = black_scene();
    const Vec3f center(0.5f, 0.3f, dist);
    Light l = make_light(Light::Type::Area, center, emit, 30.0f);
    l.shape = Light::Shape::Rectangle;
    l.size_x = 1.0f;
    l.size_y = 0.6f;
    l.light_to_world = light_frame(center, emit, 1.3f, 1.0f);
    scene.lights.push_back(l);
    const LightSampler lights(scene, {}, {});
    const Frame f(-emit);
    const double a = 1.3, b = 0.6, L = 30.0 / (4.0 * a * b);
    const Vec3f n_recv = normalize(Vec3f(0.1f, 0.0f, 1.0f));
    double omega = 0, E = 0;
    const int q = 600;
    for (int i = 0; i < q; ++i)
      for (int j = 0; j < q; ++j) {
        const double x = a * ((i + 0.5) / q - 0.5), y = b * ((j + 0.5) / q - 0.5);
        const Vec3f p = center + f.s * float(x) + f.t * float(y);
        const double d2 = length_squared(p);
        const Vec3f w = normalize(p);
        const double dA = a * b / (double(q) * q);
        const double g = -dot(w, emit) / d2 * dA;
        omega += g;
        E += L * std::max(0.0, double(dot(w, n_recv))) * g;
      }
    const test::Estimate e = estimate(lights, {0, 0, 0}, n_recv, 250000);
    EXPECT_NEAR(e.solid_angle, omega, 5e-3 * omega) << dist;
    EXPECT_NEAR(e.irradiance, E, 3e-3 * E) << dist;
  }
}

}  // namespace
}  // namespace gdpt
