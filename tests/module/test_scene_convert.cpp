// The add-on module's SceneBuilder (blender_addon/module/scene_convert.h) under an embedded
// Python interpreter: the per-object and per-light settings it is handed arrive in the Scene's
// Instance and Light fields, and its instance_settings / light_settings (which the Blender tests
// read) report those fields.
#include "blender_addon/module/scene_convert.h"

#include <gtest/gtest.h>
#include <pybind11/embed.h>

#include <stdexcept>

namespace gdpt::python {
namespace {

using namespace pybind11::literals;

// A builder holding one triangle (mesh 0).
SceneBuilder with_triangle() {
  SceneBuilder b;
  FloatArray positions({3, 3});
  const float p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (int i = 0; i < 9; ++i) positions.mutable_data()[i] = p[i];
  IntArray indices({1, 3});
  for (int i = 0; i < 3; ++i) indices.mutable_data()[i] = i;
  EXPECT_EQ(b.add_mesh(positions, indices, std::nullopt, std::nullopt, std::nullopt), 0);
  return b;
}

FloatArray identity12() {
  FloatArray m(12);
  for (int i = 0; i < 12; ++i) m.mutable_data()[i] = (i % 5 == 0) ? 1.0f : 0.0f;
  return m;
}

TEST(SceneConvert, InstanceCarriesShadowCausticsFlags) {
  SceneBuilder b = with_triangle();
  b.add_instance(0, identity12(), py::list());  // defaults: neither
  b.add_instance(0, identity12(), py::list(), 3, kRayAll, false, 0.1f, 0.0f, true, false);
  b.add_instance(0, identity12(), py::list(), 0, kRayAll, false, 0.1f, 0.0f, false, true);
  b.add_instance(0, identity12(), py::list(), 0, kRayAll, true, 0.5f, 0.25f, true, true);
  const Scene& s = b.scene();
  ASSERT_EQ(s.instances.size(), 4u);
  EXPECT_FALSE(s.instances[0].caustics_caster);
  EXPECT_FALSE(s.instances[0].caustics_receiver);
  EXPECT_TRUE(s.instances[1].caustics_caster);
  EXPECT_FALSE(s.instances[1].caustics_receiver);
  EXPECT_FALSE(s.instances[2].caustics_caster);
  EXPECT_TRUE(s.instances[2].caustics_receiver);
  EXPECT_TRUE(s.instances[3].caustics_caster);
  EXPECT_TRUE(s.instances[3].caustics_receiver);
  // The other per-object settings still land where they did.
  EXPECT_EQ(s.instances[1].pass_index, 3.0f);
  EXPECT_TRUE(s.instances[3].holdout);
  EXPECT_EQ(s.instances[3].terminator_geometry_offset, 0.5f);
  EXPECT_EQ(s.instances[3].terminator_shading_offset, 0.25f);

  const py::dict d1 = b.instance_settings(1), d2 = b.instance_settings(2);
  EXPECT_TRUE(d1["caustics_caster"].cast<bool>());
  EXPECT_FALSE(d1["caustics_receiver"].cast<bool>());
  EXPECT_FALSE(d2["caustics_caster"].cast<bool>());
  EXPECT_TRUE(d2["caustics_receiver"].cast<bool>());
  EXPECT_EQ(d1["pass_index"].cast<float>(), 3.0f);
  EXPECT_EQ(b.instance_settings(3)["terminator_shading_offset"].cast<float>(), 0.25f);
  EXPECT_THROW(b.instance_settings(4), std::invalid_argument);
  EXPECT_THROW(b.instance_settings(-1), std::invalid_argument);
}

TEST(SceneConvert, LightCarriesShadowCausticsFlag) {
  SceneBuilder b;
  b.add_light(py::dict("type"_a = "POINT"));  // no key: Cycles' default, off
  b.add_light(py::dict("type"_a = "SUN", "caustics_light"_a = true));
  b.add_light(py::dict("type"_a = "AREA", "caustics_light"_a = true, "cast_shadow"_a = false));
  b.add_light(py::dict("type"_a = "SPOT", "caustics_light"_a = false));
  const Scene& s = b.scene();
  ASSERT_EQ(s.lights.size(), 4u);
  EXPECT_FALSE(s.lights[0].caustics_light);
  EXPECT_TRUE(s.lights[0].cast_shadow);
  EXPECT_TRUE(s.lights[1].caustics_light);
  EXPECT_TRUE(s.lights[2].caustics_light);
  EXPECT_FALSE(s.lights[2].cast_shadow);
  EXPECT_FALSE(s.lights[3].caustics_light);

  EXPECT_FALSE(b.light_settings(0)["caustics_light"].cast<bool>());
  EXPECT_TRUE(b.light_settings(2)["caustics_light"].cast<bool>());
  EXPECT_FALSE(b.light_settings(2)["cast_shadow"].cast<bool>());
  EXPECT_THROW(b.light_settings(4), std::invalid_argument);
}

}  // namespace
}  // namespace gdpt::python

// SceneBuilder takes numpy arrays and dicts: the interpreter lives for the whole run.
int main(int argc, char** argv) {
  pybind11::scoped_interpreter python;
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
