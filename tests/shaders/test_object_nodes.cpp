// Vector Transform and Wireframe (shaders/object_nodes.h) against values worked out by hand from
// Cycles 3.4's svm_node_vector_transform and svm_wireframe, and their use in a material: the
// instance, triangle and camera come from the ShadingContext and Material::set_camera, and the
// closures are evaluated per hit (never cached per side).
#include <gtest/gtest.h>

#include <cmath>
#include <iterator>

#include "shaders/material.h"
#include "shaders/object_nodes.h"

namespace gdpt {
namespace {

using Type = VectorTransformDesc::Type;
using Space = VectorTransformDesc::Space;

void expect_vec(Vec3f got, Vec3f want, float tol = 1e-5f) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

Transform rows(std::initializer_list<float> r) {
  return Transform::from_rows(std::data(r));
}

// An instance rotated 90 degrees about z, stretched 2x along its own x, moved to (1, 2, 3):
// object x -> world 2y, object y -> world -x, object z -> world z.
ShadingInstance stretched_instance() {
  const Transform t = rows({0, -1, 0, 1, 2, 0, 0, 2, 0, 0, 1, 3});
  return {t, t.inverse(), nullptr, nullptr};
}

// Blender's camera at (0, 0, 5) looking down world -z (its identity rotation) as Cycles sees it
// (CameraModel::shading_camera): x right, y up, z = 5 - world z (forward).
ShadingCamera camera_above() {
  ShadingCamera c;
  c.camera_to_world = rows({1, 0, 0, 0, 0, 1, 0, 0, 0, 0, -1, 5});
  c.world_to_camera = c.camera_to_world.inverse();
  return c;
}

Vec3f through(Vec3f v, Type type, Space from, Space to, const ShadingInstance* inst) {
  return vector_transform(v, {type, from, to}, inst, camera_above());
}

TEST(ObjectNodes, VectorTransformObjectSpace) {
  const ShadingInstance inst = stretched_instance();
  // Points move with the translation, vectors do not.
  expect_vec(through({1, 0, 0}, Type::Point, Space::Object, Space::World, &inst), {1, 4, 3});
  expect_vec(through({1, 0, 0}, Type::Vector, Space::Object, Space::World, &inst), {0, 2, 0});
  expect_vec(through({1, 4, 3}, Type::Point, Space::World, Space::Object, &inst), {1, 0, 0});
  expect_vec(through({0, 2, 0}, Type::Vector, Space::World, Space::Object, &inst), {1, 0, 0});
  // Normals by the inverse transpose, renormalised: (1, 1, 0) becomes (-1, 0.5, 0) / |.|, which
  // stays normal to the image of the tangent (1, -1, 0) -> (1, 2, 0) (a vector would not).
  const Vec3f n = through({1, 1, 0}, Type::Normal, Space::Object, Space::World, &inst);
  expect_vec(n, Vec3f(-1.0f, 0.5f, 0.0f) / std::sqrt(1.25f));
  EXPECT_NEAR(dot(n, Vec3f(1, 2, 0)), 0.0f, 1e-6f);
  EXPECT_GT(std::fabs(dot(through({1, 1, 0}, Type::Vector, Space::Object, Space::World, &inst),
                          Vec3f(1, 2, 0))),
            0.5f);
  expect_vec(through(n, Type::Normal, Space::World, Space::Object, &inst),
             Vec3f(1, 1, 0) / std::sqrt(2.0f));
  // The same space on both sides: untouched, not even normalised (Cycles does nothing).
  expect_vec(through({0, 0, 3}, Type::Normal, Space::World, Space::World, &inst), {0, 0, 3});
  expect_vec(through({0, 0, 3}, Type::Normal, Space::Object, Space::Object, &inst), {0, 0, 3});
  // Without an instance object space is world space.
  expect_vec(through({1, 0, 0}, Type::Point, Space::Object, Space::World, nullptr), {1, 0, 0});
}

TEST(ObjectNodes, VectorTransformCameraSpace) {
  const ShadingInstance inst = stretched_instance();
  // z is the distance in front of the camera (Cycles' camera space), not Blender's -z.
  expect_vec(through({1, 2, 0}, Type::Point, Space::World, Space::Camera, nullptr), {1, 2, 5});
  expect_vec(through({0, 0, -1}, Type::Vector, Space::World, Space::Camera, nullptr), {0, 0, 1});
  expect_vec(through({0, 0, 2}, Type::Normal, Space::World, Space::Camera, nullptr), {0, 0, -1});
  expect_vec(through({1, 2, 5}, Type::Point, Space::Camera, Space::World, nullptr), {1, 2, 0});
  // Through world space: object (1, 0, 0) is world (1, 4, 3), 2 in front of the camera.
  expect_vec(through({1, 0, 0}, Type::Point, Space::Object, Space::Camera, &inst), {1, 4, 2});
  expect_vec(through({1, 4, 2}, Type::Point, Space::Camera, Space::Object, &inst), {1, 0, 0});
  expect_vec(through({0, 0, 1}, Type::Vector, Space::Camera, Space::Object, &inst), {0, 0, -1});
}

TEST(ObjectNodes, WireframeWorldSize) {
  const Vec3f tri[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  // 0.04 from the edge along x: inside a wire 0.1 wide (half each side), outside one 0.07 wide.
  EXPECT_EQ(wireframe(tri, {0.3f, 0.04f, 0}, 0.1f), 1.0f);
  EXPECT_EQ(wireframe(tri, {0.3f, 0.04f, 0}, 0.07f), 0.0f);
  // The hypotenuse (a quad's diagonal): (0.45, 0.5) is 0.05 / sqrt 2 = 0.0354 from it.
  EXPECT_EQ(wireframe(tri, {0.45f, 0.5f, 0}, 0.071f), 1.0f);
  EXPECT_EQ(wireframe(tri, {0.45f, 0.5f, 0}, 0.07f), 0.0f);
  // (0.3, 0.3): 0.3 from both legs, 0.4 / sqrt 2 = 0.283 from the hypotenuse.
  EXPECT_EQ(wireframe(tri, {0.3f, 0.3f, 0}, 0.56f), 0.0f);
  EXPECT_EQ(wireframe(tri, {0.3f, 0.3f, 0}, 0.57f), 1.0f);
  EXPECT_EQ(wireframe(tri, {0.3f, 0.3f, 0}, -0.57f), 1.0f);  // squared, as Cycles
  EXPECT_EQ(wireframe(tri, {0.3f, 0.3f, 0}, 0.0f), 0.0f);
}

TEST(ObjectNodes, WireframePixelWidth) {
  ShadingCamera cam = camera_above();
  cam.pixel_x = cam.pixel_y = 0.001f;
  // Straight ahead 10 away: the direction turns by 0.001 / sqrt(1 + 1e-6) per pixel.
  const float spread = 2.0f * std::sin(0.5f * std::atan(0.001f));
  EXPECT_NEAR(pixel_footprint(cam, {0, 0, -5}), 10.0f * spread, 1e-7f);
  // Off axis the pixel subtends less: at 45 degrees cos^2 along x, cos along y.
  const float off = pixel_footprint(cam, {10, 0, -5});
  EXPECT_NEAR(off / (std::sqrt(200.0f) * spread), 0.5f * (0.5f + std::sqrt(0.5f)), 1e-3f);
  cam.orthographic = true;
  cam.pixel_y = 0.003f;
  EXPECT_NEAR(pixel_footprint(cam, {7, 3, -50}), 0.002f, 1e-9f);
  // Seen head-on the footprint is the width; at 60 degrees off the normal +z both basis steps
  // ((1, -1, 0) and (1, 1, 0) over sqrt 2) lose sin^2 / 2 of their squared length.
  EXPECT_NEAR(wireframe_pixel_width(0.01f, {0, 0, 1}, {0, 0, 1}), 0.01f, 1e-8f);
  const float s = std::sin(kPi / 3.0f), c = std::cos(kPi / 3.0f);
  EXPECT_NEAR(wireframe_pixel_width(0.01f, {0, 0, 1}, {s, 0, c}),
              0.01f * std::sqrt(1.0f - 0.5f * s * s), 1e-7f);
  EXPECT_NEAR(wireframe_pixel_width(0.01f, {0, 0, -1}, {s, 0, c}),
              0.01f * std::sqrt(1.0f - 0.5f * s * s), 1e-7f);  // either side
}

// An emission whose colour is input node `color` of `inputs` (strength 1).
MaterialDesc emission_of(std::vector<InputNode> inputs, int32_t color) {
  MaterialDesc d;
  ShaderNode e;
  e.kind = ShaderNodeKind::Emission;
  e.color.node = color;
  d.nodes = {e};
  d.inputs = std::move(inputs);
  d.root = 0;
  return d;
}

Spectrum emitted(const Material& m, const ShadingContext& sc) {
  ClosureSet cs;
  m.evaluate(sc, cs);
  EXPECT_EQ(m.emission(sc).x, cs.emission().x);
  return cs.emission();
}

TEST(ObjectNodes, MaterialsReadTheirInstanceAndCamera) {
  InputNode t;
  t.kind = InputNodeKind::VectorTransform;
  t.a = ColorInput(Spectrum(0.0f, 0.0f, -1.0f));
  t.vector_transform = {Type::Vector, Space::Object, Space::Camera};
  Material m(emission_of({t}, 0), {});
  EXPECT_FALSE(m.reads_view());
  m.set_camera(camera_above());
  // Object -z is world -z, the way the camera looks: camera-space +z, read as a colour.
  const ShadingInstance inst = stretched_instance();
  ShadingContext sc{{0.0f, 0.0f}, true};
  sc.instance = &inst;
  expect_vec(emitted(m, sc), {0, 0, 1});
  // Another instance at the same side: its own transform (nothing cached per side).
  const ShadingInstance tilted{rows({1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0}),
                               rows({1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0}), nullptr, nullptr};
  sc.instance = &tilted;
  expect_vec(emitted(m, sc), {0, 1, 0});
}

TEST(ObjectNodes, MaterialsReadTheirTriangle) {
  const Vec3f positions[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const uint32_t indices[6] = {0, 1, 2, 0, 2, 3};
  const Transform twice = rows({2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0});
  const ShadingInstance quad{twice, twice.inverse(), positions, indices};
  InputNode w;
  w.kind = InputNodeKind::Wireframe;
  w.value_a = FloatInput(0.2f);
  const Material m(emission_of({w}, 0), {});
  EXPECT_TRUE(m.reads_coordinates());
  TexCoords at;
  ShadingContext sc{{0.0f, 0.0f}, true};
  sc.coords = &at;
  sc.instance = &quad;
  // World-space edges of the scaled quad: (1, 0.08) is 0.08 from the bottom edge of triangle 0.
  at.position = {1.0f, 0.08f, 0.0f};
  EXPECT_EQ(emitted(m, sc).x, 1.0f);
  at.position = {1.2f, 0.12f, 0.0f};  // 0.12 from the edge, 1.08 / sqrt 2 from the diagonal
  EXPECT_EQ(emitted(m, sc).x, 0.0f);
  // The diagonal shows: (1, 1.1) is 0.1 / sqrt 2 from it, in triangle 1.
  at.position = {1.0f, 1.1f, 0.0f};
  sc.primitive = 1;
  EXPECT_EQ(emitted(m, sc).x, 1.0f);
  // Without the triangle: no wire.
  sc.instance = nullptr;
  EXPECT_EQ(emitted(m, sc).x, 0.0f);

  // In pixels: 4 px of about 0.001 rad at about 10 m head-on, 0.0399 m wide.
  w.pixel_size = true;
  w.value_a = FloatInput(4.0f);
  Material px(emission_of({w}, 0), {});
  EXPECT_TRUE(px.reads_view());
  ShadingCamera cam = camera_above();
  cam.pixel_x = cam.pixel_y = 0.001f;
  cam.camera_to_world.m[2][3] = 10.0f;  // 10 above the quad
  cam.world_to_camera = cam.camera_to_world.inverse();
  px.set_camera(cam);
  sc.instance = &quad;
  const ShadingGeometry head_on{{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  sc.geometry = &head_on;
  // Triangle 1's left edge: inside at 0.0197, outside at 0.0203.
  at.position = {0.0197f, 1.0f, 0.0f};
  EXPECT_EQ(emitted(px, sc).x, 1.0f);
  at.position = {0.0203f, 1.0f, 0.0f};
  EXPECT_EQ(emitted(px, sc).x, 0.0f);
  // Seen at 60 degrees the pixel width shrinks (wireframe_pixel_width): 0.0197 is outside.
  const float s = std::sin(kPi / 3.0f), c = std::cos(kPi / 3.0f);
  const ShadingGeometry oblique{{s, 0, c}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  sc.geometry = &oblique;
  at.position = {0.0197f, 1.0f, 0.0f};
  EXPECT_EQ(emitted(px, sc).x, 0.0f);
  at.position = {0.0155f, 1.0f, 0.0f};
  EXPECT_EQ(emitted(px, sc).x, 1.0f);
}

}  // namespace
}  // namespace gdpt
