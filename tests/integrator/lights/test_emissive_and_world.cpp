// Emissive triangles and the constant world: sampled solid angle and irradiance against closed
// forms (Van Oosterom-Strackee solid angle, Lambert's polygon irradiance, E = pi L).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "light_test_util.h"
#include "render/light_sampler.h"
#include "shaders/object_nodes.h"

namespace gdpt {
namespace {

constexpr double kPiD = 3.14159265358979323846;

struct TriangleScene {
  Scene scene = test::black_scene();
  std::vector<Material> materials;
};

// One emissive triangle (v0, v1, v2) in world space, reached through an instance transform.
TriangleScene triangle_scene(Vec3f v0, Vec3f v1, Vec3f v2, float strength) {
  TriangleScene t;
  t.scene.materials.push_back(test::emission_material({1.0f, 1.0f, 1.0f}, strength));
  Mesh mesh;
  // Object space shifted by -1 in x; the instance moves it back.
  const Vec3f off(1, 0, 0);
  mesh.positions = {v0 - off, v1 - off, v2 - off};
  mesh.indices = {0, 1, 2};
  t.scene.meshes.push_back(mesh);
  Instance inst;
  inst.mesh = 0;
  const float rows[12] = {1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0};
  inst.object_to_world = Transform::from_rows(rows);
  inst.slot_material = {0};
  t.scene.instances.push_back(inst);
  for (const MaterialDesc& d : t.scene.materials)
    t.materials.emplace_back(d, std::span<const Texture>{});
  return t;
}

double triangle_solid_angle(Vec3f a, Vec3f b, Vec3f c) {
  const double la = length(a), lb = length(b), lc = length(c);
  const double num = std::fabs(dot(a, cross(b, c)));
  const double den = la * lb * lc + dot(a, b) * lc + dot(a, c) * lb + dot(b, c) * la;
  return 2.0 * std::atan2(num, den);
}

// Lambert: E = L/2 sum_i angle(v_i, v_i+1) (n . unit(v_i x v_i+1)), polygon above the plane.
double triangle_irradiance(double L, Vec3f a, Vec3f b, Vec3f c, Vec3f n) {
  const Vec3f v[3] = {normalize(a), normalize(b), normalize(c)};
  double sum = 0;
  for (int i = 0; i < 3; ++i) {
    const Vec3f p = v[i], q = v[(i + 1) % 3];
    const double angle = std::acos(std::clamp(double(dot(p, q)), -1.0, 1.0));
    sum += angle * dot(n, normalize(cross(p, q)));
  }
  return std::fabs(L / 2.0 * sum);
}

TEST(EmissiveTriangle, SolidAngleAndIrradianceBothSides) {
  const Vec3f v0(-0.5f, -0.3f, 1.5f), v1(0.8f, -0.2f, 1.7f), v2(0.1f, 0.9f, 1.2f);
  TriangleScene t = triangle_scene(v0, v1, v2, 3.0f);
  const LightSampler lights(t.scene, t.materials, {});
  ASSERT_FALSE(lights.empty());
  // Receiver below the triangle, then above it (two-sided emission), then far below (area
  // sampling instead of spherical-triangle sampling).
  for (const float z : {0.0f, 3.0f, -25.0f}) {
    const Vec3f ref(0.1f, 0.05f, z);
    const Vec3f n = z <= 0.0f ? Vec3f(0, 0.2f, 1) : Vec3f(0, -0.1f, -1);
    const Vec3f nn = normalize(n);
    const test::Estimate e = test::estimate(lights, ref, nn, 250000);
    const double omega = triangle_solid_angle(v0 - ref, v1 - ref, v2 - ref);
    EXPECT_NEAR(e.solid_angle, omega, 5e-3 * omega) << z;
    const double E = triangle_irradiance(3.0, v0 - ref, v1 - ref, v2 - ref, nn);
    EXPECT_NEAR(e.irradiance, E, 3e-3 * E) << z;
  }
}

TEST(EmissiveTriangle, LargeTriangleCloseAbove) {
  // Half of a 1.2 m panel 0.1 m under a ceiling (the Blender mesh_light scene): receivers close
  // to a triangle subtending a large solid angle, above its interior, near an edge and outside.
  const Vec3f v0(-0.6f, -0.6f, 0.0f), v1(0.6f, -0.6f, 0.0f), v2(0.6f, 0.6f, 0.0f);
  TriangleScene t = triangle_scene(v0, v1, v2, 2.0f);
  const LightSampler lights(t.scene, t.materials, {});
  const Vec3f nn(0, 0, -1);
  for (const Vec3f ref : {Vec3f(0.3f, -0.2f, 0.1f), Vec3f(0.55f, 0.4f, 0.1f),
                          Vec3f(0.8f, -0.7f, 0.1f), Vec3f(0.2f, -0.3f, 0.02f)}) {
    const test::Estimate e = test::estimate(lights, ref, nn, 250000);
    const double omega = triangle_solid_angle(v0 - ref, v1 - ref, v2 - ref);
    EXPECT_NEAR(e.solid_angle, omega, 5e-3 * omega) << ref.x << " " << ref.y << " " << ref.z;
    const double E = triangle_irradiance(2.0, v0 - ref, v1 - ref, v2 - ref, nn);
    EXPECT_NEAR(e.irradiance, E, 3e-3 * E) << ref.x << " " << ref.y << " " << ref.z;
  }
}

TEST(EmissiveTriangle, PdfTriangleMatchesSample) {
  const Vec3f v0(-0.5f, -0.3f, 1.5f), v1(0.8f, -0.2f, 1.7f), v2(0.1f, 0.9f, 1.2f);
  TriangleScene t = triangle_scene(v0, v1, v2, 2.0f);
  // A second light so that the selection probability is not 1.
  Light p;
  p.light_to_world = test::light_frame({5, 5, 5}, {0, 0, -1});
  p.power = 300.0f;
  t.scene.lights.push_back(p);
  const LightSampler lights(t.scene, t.materials, {});
  const Vec3f ref(0.2f, 0.1f, -0.5f);
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    const LightSample s =
        lights.sample(ref, (i + 0.5f) / 400.0f, {(i % 20 + 0.5f) / 20.0f, (i / 20 + 0.5f) / 20.0f});
    if (!s.valid || s.is_delta) continue;
    ++checked;
    const float pdf = lights.pdf_triangle(0, 0, ref, s.position, s.normal);
    EXPECT_NEAR(pdf, s.pdf, 1e-4f * s.pdf);
    EXPECT_NEAR(s.radiance.x, 2.0f, 1e-6f);
  }
  EXPECT_GT(checked, 10);
  // Unknown primitive / instance: zero.
  EXPECT_EQ(lights.pdf_triangle(0, 1, ref, v0, {0, 0, 1}), 0.0f);
  EXPECT_EQ(lights.pdf_triangle(3, 0, ref, v0, {0, 0, 1}), 0.0f);
}

TEST(EmissiveTriangle, SelectedProportionallyToPower) {
  // Two instances of one mesh with two triangles: areas 1/2 and 2, emission 1 and 3 (slots).
  Scene scene = test::black_scene();
  scene.materials.push_back(test::emission_material({1, 1, 1}, 1.0f));
  scene.materials.push_back(test::emission_material({1, 1, 1}, 3.0f));
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 1}, {0, 2, 1}};
  mesh.indices = {0, 1, 2, 3, 4, 5};
  mesh.material_slot = {0, 1};
  scene.meshes.push_back(mesh);
  for (int k = 0; k < 2; ++k) {
    Instance inst;
    inst.object_to_world.m[0][3] = float(k * 10);
    inst.slot_material = {0, 1};
    scene.instances.push_back(inst);
  }
  std::vector<Material> materials;
  for (const MaterialDesc& d : scene.materials)
    materials.emplace_back(d, std::span<const Texture>{});
  const LightSampler lights(scene, materials, {});
  // Power ratio per instance: 0.5 * 1 : 2 * 3 = 1 : 12; selection pmf = power / total.
  const Vec3f ref(0.2f, 0.2f, -1.0f);
  const double total = 2.0 * (0.5 * 1.0 + 2.0 * 3.0);
  const double pmf_small = 0.5 / total, pmf_big = 6.0 / total;
  const LightSample s = lights.sample(ref, 0.0f, {0.3f, 0.3f});  // first entry: small, inst 0
  ASSERT_TRUE(s.valid);
  // Large and near: sampled by solid angle, density pmf / Omega.
  const double omega =
      triangle_solid_angle(Vec3f(0, 0, 0) - ref, Vec3f(1, 0, 0) - ref, Vec3f(0, 1, 0) - ref);
  EXPECT_NEAR(s.pdf, pmf_small / omega, 1e-4 * s.pdf);
  // Count selections with stratified u_select.
  int counts[2] = {0, 0};
  const int n = 13000;
  for (int i = 0; i < n; ++i) {
    const LightSample t = lights.sample(ref, (i + 0.5f) / n, {0.3f, 0.3f});
    ASSERT_TRUE(t.valid);
    counts[t.position.z > 0.5f ? 1 : 0]++;
  }
  EXPECT_NEAR(counts[0] / double(n), 2 * pmf_small, 1e-3);
  EXPECT_NEAR(counts[1] / double(n), 2 * pmf_big, 1e-3);
}

// A constant world is seen by escaping rays but never light-sampled (as Cycles' automatic world
// sampling): every light sample goes to the lamp, and the world's MIS density is 0 so BSDF
// sampling alone carries it (its irradiance pi L: Render furnace tests).
TEST(ConstantWorld, IsSeenButNotSampled) {
  Scene scene = test::black_scene();
  scene.world.color = {0.2f, 0.4f, 0.6f};
  scene.world.strength = 2.5f;
  Light lamp;
  lamp.type = Light::Type::Point;
  lamp.power = 1.0f;
  lamp.light_to_world = test::light_frame({0, 0, 3}, {0, 0, -1});
  scene.lights.push_back(lamp);
  const LightSampler lights(scene, {}, {});
  ASSERT_TRUE(lights.has_environment());
  EXPECT_FLOAT_EQ(lights.environment({0, 0, 1}).y, 1.0f);
  EXPECT_EQ(lights.pdf_environment({0, 1, 0}), 0.0f);
  EXPECT_FALSE(lights.needs_selection());
  for (int i = 0; i < 64; ++i) {
    const LightSample s = lights.sample({1, 2, 0}, (i + 0.5f) / 64, {0.3f, 0.7f});
    ASSERT_TRUE(s.valid);
    EXPECT_FALSE(s.is_infinite);
  }
  // Alone, it leaves nothing to sample.
  scene.lights.clear();
  const LightSampler world_only(scene, {}, {});
  EXPECT_TRUE(world_only.has_environment());
  EXPECT_TRUE(world_only.empty());
}

// A light sample evaluates the emitter's material as a hit on it would: with its instance, its
// triangle and its texture coordinates (Cycles sets up the shader at the sampled point of the
// object). A quad of two triangles, turned 90 degrees about z, scaled 2x and moved; emission
// colours: a Wireframe 0.3 wide, a Vector Transform of (0.5, -0.2, 0.9) from object to world,
// the Object and Generated coordinates.
TEST(EmissiveTriangle, LightSamplesSeeTheirInstance) {
  Scene scene = test::black_scene();
  Mesh quad;
  quad.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  quad.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(quad);
  const float rows[12] = {0, -2, 0, 0.5f, 2, 0, 0, 0.25f, 0, 0, 2, 3};
  const Transform to_world = Transform::from_rows(rows);
  const Transform to_object = to_world.inverse();
  InputNode wire;
  wire.kind = InputNodeKind::Wireframe;
  wire.value_a = FloatInput(0.3f);
  InputNode turned;
  turned.kind = InputNodeKind::VectorTransform;
  turned.a = ColorInput(Spectrum(0.5f, -0.2f, 0.9f));
  turned.vector_transform = {VectorTransformDesc::Type::Vector, VectorTransformDesc::Space::Object,
                             VectorTransformDesc::Space::World};
  InputNode object, generated;
  object.kind = generated.kind = InputNodeKind::Coordinates;
  object.vector.source = TexCoordSource::Object;
  generated.vector.source = TexCoordSource::Generated;
  for (const InputNode& node : {wire, turned, object, generated}) {
    MaterialDesc d = test::emission_material({0, 0, 0}, 1.0f);
    d.inputs = {node};
    d.nodes[0].color = ColorInput(Spectrum(0.0f));
    d.nodes[0].color.node = 0;
    scene.materials.push_back(d);
  }
  std::vector<Material> materials;
  for (const MaterialDesc& d : scene.materials)
    materials.emplace_back(d, std::span<const Texture>{});
  for (uint32_t m = 0; m < materials.size(); ++m) {
    Scene one = scene;
    Instance inst;
    inst.mesh = 0;
    inst.object_to_world = to_world;
    inst.slot_material = {int32_t(m)};
    one.instances = {inst};
    const LightSampler lights(one, materials, {});
    ASSERT_FALSE(lights.empty());
    int wires = 0;
    const int n = 400;
    for (int i = 0; i < n; ++i) {
      const Vec2f u((i % 20 + 0.5f) / 20.0f, (i / 20 + 0.5f) / 20.0f);
      const LightSample s = lights.sample({0.3f, 0.2f, 0.0f}, (i + 0.5f) / n, u);
      ASSERT_TRUE(s.valid);
      const Vec3f o = to_object.point(s.position);
      Vec3f want;
      if (m == 0) {
        // Triangle 0 or 1 of the quad: the one whose side of the diagonal holds the point.
        const uint32_t t = o.x >= o.y ? 0 : 1;
        Vec3f c[3];
        for (int k = 0; k < 3; ++k) c[k] = to_world.point(quad.positions[quad.indices[3 * t + k]]);
        want = Vec3f(wireframe(c, s.position, 0.3f));
        wires += want.x > 0.0f ? 1 : 0;
      } else if (m == 1) {
        want = {0.2f * 2.0f, 0.5f * 2.0f, 0.9f * 2.0f};
      } else {
        want = m == 2 ? o : (o + Vec3f(1.0f)) * 0.5f;
      }
      EXPECT_NEAR(s.radiance.x, want.x, 1e-4f) << m << " " << i;
      EXPECT_NEAR(s.radiance.y, want.y, 1e-4f) << m << " " << i;
      EXPECT_NEAR(s.radiance.z, want.z, 1e-4f) << m << " " << i;
    }
    // Both wires (the edges and the diagonal) and the faces between them were sampled.
    if (m == 0) {
      EXPECT_GT(wires, n / 10);
      EXPECT_LT(wires, n * 9 / 10);
    }
  }
}
}  // namespace
}  // namespace gdpt
