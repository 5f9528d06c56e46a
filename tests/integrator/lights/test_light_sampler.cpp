// LightSampler as a whole: selection by power, intersect()/pdf_environment()/pdf_triangle()
// agreeing with sample() for the same direction, and degenerate lights.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <thread>
#include <vector>

#include "light_test_util.h"
#include "render/light_sampler.h"

namespace gdpt {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

Light point(Vec3f p, float power, float radius = 0.0f) {
  Light l;
  l.type = Light::Type::Point;
  l.light_to_world = test::light_frame(p, {0, 0, -1});
  l.power = power;
  l.radius = radius;
  return l;
}

TEST(LightSampler, SelectsByPower) {
  Scene scene = test::black_scene();
  scene.lights.push_back(point({0, 0, 5}, 10.0f));
  scene.lights.push_back(point({0, 0, 6}, 30.0f));
  Light green = point({0, 0, 7}, 60.0f);
  green.color = {0.0f, 1.0f, 0.0f};  // luminance 0.7152: power weight 60 * 0.7152
  scene.lights.push_back(green);
  const LightSampler lights(scene, {}, {});
  const double total = 10.0 + 30.0 + 60.0 * 0.7152;
  const int n = 100000;
  int counts[3] = {0, 0, 0};
  for (int i = 0; i < n; ++i) {
    const LightSample s = lights.sample({0, 0, 0}, (i + 0.5f) / n, {0.5f, 0.5f});
    ASSERT_TRUE(s.valid);
    const int k = int(std::lround(s.distance)) - 5;
    ASSERT_GE(k, 0);
    ASSERT_LE(k, 2);
    ++counts[k];
    const double expected_pmf = (k == 0 ? 10.0 : k == 1 ? 30.0 : 60.0 * 0.7152) / total;
    ASSERT_NEAR(s.pdf, expected_pmf, 1e-5);  // delta light: pdf is the discrete probability
  }
  EXPECT_NEAR(counts[0] / double(n), 10.0 / total, 1e-4);
  EXPECT_NEAR(counts[1] / double(n), 30.0 / total, 1e-4);
}

// A scene with one of each intersectable light, a delta light, a world and a triangle, so all
// selection probabilities are below 1.
struct MixedScene {
  Scene scene = test::black_scene();
  std::vector<Material> materials;
  MixedScene() {
    scene.lights.push_back(point({0, 0, 4}, 100.0f, 0.4f));  // disc above
    Light spot = point({3, 0, 3}, 500.0f, 0.2f);
    spot.type = Light::Type::Spot;
    spot.light_to_world = test::light_frame({3, 0, 3}, normalize(Vec3f(-1, 0, -1)));
    spot.spot_size = 1.2f;
    spot.spot_blend = 0.3f;
    scene.lights.push_back(spot);
    Light rect;
    rect.type = Light::Type::Area;
    rect.shape = Light::Shape::Rectangle;
    rect.size_x = 2.0f;
    rect.size_y = 1.0f;
    rect.power = 60.0f;
    rect.light_to_world = test::light_frame({-3, 0, 2}, normalize(Vec3f(1, 0, -1)), 1.5f, 1.0f);
    scene.lights.push_back(rect);
    Light disk = rect;
    disk.shape = Light::Shape::Ellipse;
    disk.light_to_world = test::light_frame({0, 3, 2}, normalize(Vec3f(0, -1, -0.5f)));
    scene.lights.push_back(disk);
    Light sun;
    sun.type = Light::Type::Sun;
    sun.power = 2.0f;
    sun.sun_angle = 0.3f;
    sun.light_to_world = test::light_frame({0, 0, 0}, normalize(Vec3f(0.2f, -0.3f, -1)));
    scene.lights.push_back(sun);
    scene.lights.push_back(point({9, 9, 9}, 10.0f));  // delta
    // An image world: only those are light-sampled (a constant one is not).
    ImageDesc sky;
    sky.width = 8;
    sky.height = 4;
    sky.rgba.assign(8 * 4 * 4, 1.0f);
    for (size_t i = 0; i < sky.rgba.size(); i += 4) {
      sky.rgba[i] = 0.1f + 0.01f * float(i % 7);
      sky.rgba[i + 1] = 0.2f;
      sky.rgba[i + 2] = 0.3f + 0.02f * float(i % 5);
    }
    scene.images.push_back(sky);
    scene.world.image = 0;
    scene.materials.push_back(test::emission_material({2, 1, 1}, 4.0f));
    Mesh mesh;
    mesh.positions = {{-1, -3, 1}, {1, -3, 1}, {0, -3, 2.5f}};
    mesh.indices = {0, 1, 2};
    scene.meshes.push_back(mesh);
    Instance inst;
    inst.slot_material = {0};
    scene.instances.push_back(inst);
    for (const MaterialDesc& d : scene.materials)
      materials.emplace_back(d, std::span<const Texture>{});
  }
};

TEST(LightSampler, IntersectAndPdfsAgreeWithSample) {
  MixedScene m;
  const LightSampler lights(m.scene, m.materials, {});
  const Vec3f ref(0.1f, -0.2f, 0.3f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  int by_kind[4] = {0, 0, 0, 0};  // analytic hit, sun, world, triangle
  int misses = 0, analytic = 0;
  for (int i = 0; i < 20000; ++i) {
    const LightSample s = lights.sample(ref, U(rng), {U(rng), U(rng)});
    if (!s.valid || s.is_delta) continue;
    LightHit hit;
    if (!s.is_infinite) {
      // Analytic light or triangle. Triangles are not intersected analytically.
      const bool hit_light = lights.intersect(ref, s.direction, kInf, hit);
      const float tri_pdf = lights.pdf_triangle(0, 0, ref, s.position, s.normal);
      if (tri_pdf > 0.0f && std::fabs(s.position.y + 3.0f) < 1e-4f) {
        EXPECT_NEAR(tri_pdf, s.pdf, 1e-3f * s.pdf);
        ++by_kind[3];
        continue;
      }
      ++analytic;
      if (!hit_light || std::fabs(hit.distance - s.distance) > 1e-3f * s.distance) {
        ++misses;  // rays grazing a disc's rim may miss in float
        continue;
      }
      EXPECT_NEAR(hit.pdf, s.pdf, 2e-3f * s.pdf);
      EXPECT_NEAR(hit.radiance.x, s.radiance.x, 1e-3f * s.radiance.x + 1e-9f);
      ++by_kind[0];
    } else if (lights.intersect(ref, s.direction, kInf, hit)) {
      // Inside the sun disc: either a sun sample or a world sample through the disc.
      if (std::fabs(hit.pdf - s.pdf) <= 1e-3f * s.pdf) {
        EXPECT_NEAR(hit.radiance.x, s.radiance.x, 1e-3f * s.radiance.x);
        ++by_kind[1];
      } else {
        EXPECT_NEAR(lights.pdf_environment(s.direction), s.pdf, 1e-4f * s.pdf);
      }
    } else {
      EXPECT_NEAR(lights.pdf_environment(s.direction), s.pdf, 1e-4f * s.pdf);
      EXPECT_NEAR(lights.environment(s.direction).z, s.radiance.z, 1e-6f);
      ++by_kind[2];
    }
  }
  for (int k = 0; k < 4; ++k) EXPECT_GT(by_kind[k], 100) << k;
  EXPECT_LT(misses, analytic / 1000 + 1);
}

TEST(LightSampler, IntersectRespectsTMaxAndOneSidedness) {
  MixedScene m;
  const LightSampler lights(m.scene, m.materials, {});
  LightHit hit;
  // Point light of radius 0.4 at (0,0,4): a disc facing the origin, hit at 4 straight up.
  ASSERT_TRUE(lights.intersect({0, 0, 0}, {0, 0, 1}, kInf, hit));
  EXPECT_NEAR(hit.distance, 4.0f, 1e-5f);
  EXPECT_FALSE(lights.intersect({0, 0, 0}, {0, 0, 1}, 3.9f, hit));
  EXPECT_FALSE(lights.intersect({0, 0, 0}, normalize(Vec3f(0.11f, 0, 1)), kInf, hit));
  // Sun disc only for escaping rays.
  const Vec3f to_sun = -normalize(Vec3f(0.2f, -0.3f, -1));
  ASSERT_TRUE(lights.intersect({0, 0, 0}, to_sun, kInf, hit));
  EXPECT_TRUE(lights.intersect({0, 0, 0}, to_sun, 1e30f, hit));  // Ray::t_max default
  EXPECT_FALSE(lights.intersect({0, 0, 0}, to_sun, 1e6f, hit));
  // The rectangle emits along (1,0,-1): seen from behind it is invisible.
  const Vec3f c(-3, 0, 2);
  EXPECT_TRUE(lights.intersect(c + normalize(Vec3f(1, 0, -1)) * 2.0f, -normalize(Vec3f(1, 0, -1)),
                               kInf, hit));
  EXPECT_FALSE(lights.intersect(c - normalize(Vec3f(1, 0, -1)) * 2.0f, normalize(Vec3f(1, 0, -1)),
                                kInf, hit));
}

TEST(LightSampler, ConcurrentSamplingIsDeterministic) {
  MixedScene m;
  const LightSampler lights(m.scene, m.materials, {});
  auto run = [&](std::vector<float>& out) {
    for (int i = 0; i < 5000; ++i) {
      const LightSample s = lights.sample({0, 0, 0.5f}, (i * 0.618034f) - std::floor(i * 0.618034f),
                                          {(i % 71 + 0.5f) / 71.0f, (i % 53 + 0.5f) / 53.0f});
      out.push_back(s.valid ? s.pdf + s.radiance.x : -1.0f);
    }
  };
  std::vector<float> a, b, c;
  std::thread t1([&] { run(a); });
  std::thread t2([&] { run(b); });
  t1.join();
  t2.join();
  run(c);
  EXPECT_EQ(a, c);
  EXPECT_EQ(b, c);
}

TEST(LightSampler, DegenerateLightsAreSkipped) {
  Scene scene = test::black_scene();
  scene.lights.push_back(point({0, 0, 2}, 0.0f, 0.5f));  // zero power
  Light area;
  area.type = Light::Type::Area;
  area.size_x = 0.0f;  // zero area
  area.power = 100.0f;
  area.light_to_world = test::light_frame({0, 0, 2}, {0, 0, -1});
  scene.lights.push_back(area);
  Light squashed = area;  // zero scale on one axis
  squashed.size_x = 1.0f;
  squashed.light_to_world = test::light_frame({0, 0, 2}, {0, 0, -1}, 1.0f, 0.0f);
  scene.lights.push_back(squashed);
  Light sun;
  sun.type = Light::Type::Sun;
  sun.power = 0.0f;
  scene.lights.push_back(sun);
  Light nan_light = point({0, 0, 2}, std::numeric_limits<float>::quiet_NaN());
  scene.lights.push_back(nan_light);
  // Degenerate emissive triangle (collinear vertices) and a zero-strength emitter.
  scene.materials.push_back(test::emission_material({1, 1, 1}, 5.0f));
  scene.materials.push_back(test::emission_material({1, 1, 1}, 0.0f));
  Mesh mesh;
  mesh.positions = {{0, 0, 1}, {1, 0, 1}, {2, 0, 1}, {0, 1, 1}};
  mesh.indices = {0, 1, 2, 0, 1, 3};
  mesh.material_slot = {0, 1};
  scene.meshes.push_back(mesh);
  Instance inst;
  inst.slot_material = {0, 1};
  scene.instances.push_back(inst);
  std::vector<Material> materials;
  for (const MaterialDesc& d : scene.materials)
    materials.emplace_back(d, std::span<const Texture>{});
  {
    const LightSampler lights(scene, materials, {});
    EXPECT_TRUE(lights.empty());
    EXPECT_FALSE(lights.has_environment());
    for (int i = 0; i < 100; ++i) {
      const LightSample s = lights.sample({0, 0, 0}, i / 100.0f, {0.3f, 0.6f});
      EXPECT_FALSE(s.valid);
      EXPECT_TRUE(std::isfinite(s.pdf));
    }
    LightHit hit;
    EXPECT_FALSE(lights.intersect({0, 0, 0}, {0, 0, 1}, kInf, hit));
    EXPECT_EQ(lights.pdf_triangle(0, 0, {0, 0, 0}, {1, 0, 1}, {0, 0, 1}), 0.0f);
    EXPECT_EQ(lights.pdf_environment({0, 0, 1}), 0.0f);
    EXPECT_TRUE(is_black(lights.environment({0, 0, 1})));
  }
  // Adding one valid light: every sample comes from it, with finite values.
  scene.lights.push_back(point({0, 0, 3}, 10.0f));
  const LightSampler lights(scene, materials, {});
  ASSERT_FALSE(lights.empty());
  for (int i = 0; i < 100; ++i) {
    const LightSample s = lights.sample({0, 0, 0}, (i + 0.5f) / 100.0f, {0.3f, 0.6f});
    ASSERT_TRUE(s.valid);
    EXPECT_FLOAT_EQ(s.pdf, 1.0f);
    EXPECT_NEAR(s.distance, 3.0f, 1e-6f);
    EXPECT_TRUE(is_finite(s.radiance));
  }
  // A reference point exactly at a point light's position: no NaN.
  const LightSample at = lights.sample({0, 0, 3}, 0.5f, {0.5f, 0.5f});
  EXPECT_FALSE(at.valid);
}

}  // namespace
}  // namespace gdpt
