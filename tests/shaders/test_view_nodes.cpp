// Fresnel and Layer Weight (shaders/view_nodes.h) against values computed by hand from Cycles'
// formulas (kernel/svm/fresnel.h), and their use in a material: the view comes from
// ShadingContext::geometry, the closures are evaluated per view (never cached), and the Normal
// input reads the interpolated or the perturbed normal.
#include <gtest/gtest.h>

#include <cmath>

#include "shaders/material.h"
#include "shaders/view_nodes.h"

namespace gdpt {
namespace {

void expect_spectrum(Spectrum got, Spectrum want, float tol = 1e-6f) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

TEST(ViewNodes, FresnelFollowsCycles) {
  // IOR 1.5: ((1.5 - 1) / 2.5)^2 at normal incidence from either side.
  EXPECT_NEAR(fresnel_node(1.5f, 1.0f, false), 0.04f, 1e-6f);
  EXPECT_NEAR(fresnel_node(1.5f, 1.0f, true), 0.04f, 1e-6f);
  // cos 0.5: sin_t^2 = 0.75 / 2.25, r_s and r_p of cos_t = sqrt(2/3).
  EXPECT_NEAR(fresnel_node(1.5f, 0.5f, false), 0.0891867f, 1e-6f);
  EXPECT_NEAR(fresnel_node(1.5f, -0.5f, false), 0.0891867f, 1e-6f);  // the sign is ignored
  // From the back the IOR is inverted: cos 0.8 transmits (sin_t^2 = 0.36 * 2.25 = 0.81), cos
  // 0.5 is totally reflected.
  EXPECT_NEAR(fresnel_node(1.5f, 0.8f, true), 0.1141411f, 1e-6f);
  EXPECT_EQ(fresnel_node(1.5f, 0.5f, true), 1.0f);
  EXPECT_NEAR(fresnel_node(2.0f, 0.3f, false), 0.2687224f, 1e-6f);
  // IOR 1: no interface; IOR 0 is clamped to 1e-5 (almost everything reflects).
  EXPECT_NEAR(fresnel_node(1.0f, 0.3f, false), 0.0f, 1e-7f);
  EXPECT_GT(fresnel_node(0.0f, 1.0f, false), 0.99f);
}

TEST(ViewNodes, LayerWeightFollowsCycles) {
  // Fresnel output: blend 0.5 is IOR 2 from the front ((2 - 1) / 3)^2, IOR 0.5 from the back.
  EXPECT_NEAR(layer_weight_fresnel(0.5f, 1.0f, false), 1.0f / 9.0f, 1e-6f);
  EXPECT_NEAR(layer_weight_fresnel(0.5f, 1.0f, true), 1.0f / 9.0f, 1e-6f);
  EXPECT_NEAR(layer_weight_fresnel(0.5f, 0.3f, false), 0.2687224f, 1e-6f);
  EXPECT_NEAR(layer_weight_fresnel(0.5f, 0.9f, true), 0.1645630f, 1e-6f);
  EXPECT_EQ(layer_weight_fresnel(0.5f, 0.5f, true), 1.0f);            // sin_t^2 = 0.75 / 0.25 > 1
  EXPECT_NEAR(layer_weight_fresnel(0.0f, 0.4f, false), 0.0f, 1e-7f);  // IOR 1
  // Facing output: 1 - |cos|^e, e = 2 blend below a half, 0.5 / (1 - blend) above.
  EXPECT_NEAR(layer_weight_facing(0.5f, 0.6f), 0.4f, 1e-6f);
  EXPECT_NEAR(layer_weight_facing(0.5f, -0.6f), 0.4f, 1e-6f);
  EXPECT_NEAR(layer_weight_facing(0.25f, 0.6f), 1.0f - std::sqrt(0.6f), 1e-6f);
  EXPECT_NEAR(layer_weight_facing(0.75f, 0.6f), 0.64f, 1e-6f);
  EXPECT_NEAR(layer_weight_facing(0.0f, 0.6f), 0.0f, 1e-7f);   // e = 0
  EXPECT_NEAR(layer_weight_facing(1.0f, 0.6f), 1.0f, 1e-6f);   // e = 0.5 / 1e-5
  EXPECT_NEAR(layer_weight_facing(-1.0f, 0.6f), 0.0f, 1e-7f);  // clamped to 0
}

// An emission whose colour is input node 0 (strength 1), and the view from direction `in` onto
// a surface whose interpolated normal is +z and perturbed normal `bumped`.
MaterialDesc emission_of(const InputNode& n) {
  MaterialDesc d;
  ShaderNode e;
  e.kind = ShaderNodeKind::Emission;
  e.color.node = 0;
  d.nodes = {e};
  d.inputs = {n};
  d.root = 0;
  return d;
}

Spectrum seen(const Material& m, Vec3f in, bool front = true,
              Vec3f bumped = Vec3f(0.0f, 0.0f, 1.0f)) {
  const float side = front ? 1.0f : -1.0f;
  const ShadingGeometry g{in, Vec3f(0.0f, 0.0f, side), bumped * side, Vec3f(0.0f, 0.0f, side)};
  ShadingContext sc{{0.0f, 0.0f}, front};
  sc.geometry = &g;
  ClosureSet cs;
  m.evaluate(sc, cs);
  EXPECT_EQ(m.emission(sc).x, cs.emission().x);
  return cs.emission();
}

TEST(ViewNodes, MaterialsReadTheirOwnView) {
  InputNode fresnel;
  fresnel.kind = InputNodeKind::Fresnel;
  fresnel.value_a = FloatInput(1.5f);
  const Material m(emission_of(fresnel), {});
  EXPECT_TRUE(m.reads_view());
  EXPECT_FALSE(Material(MaterialDesc{}, {}).reads_view());
  // Two views of the same point: two values (no per-side cache).
  const Vec3f oblique(std::sqrt(0.75f), 0.0f, 0.5f);
  EXPECT_NEAR(seen(m, Vec3f(0.0f, 0.0f, 1.0f)).x, 0.04f, 1e-6f);
  EXPECT_NEAR(seen(m, oblique).x, 0.0891867f, 1e-6f);
  EXPECT_NEAR(seen(m, Vec3f(0.0f, 0.0f, 1.0f)).y, 0.04f, 1e-6f);  // grey
  // A back face: normals flipped to the incoming side, the IOR inverted.
  EXPECT_EQ(seen(m, -oblique, false).x, 1.0f);
  // Without a view (bump evaluation at the hit record): normal incidence.
  ClosureSet cs;
  m.evaluate(ShadingContext{{0.0f, 0.0f}, true}, cs);
  EXPECT_NEAR(cs.emission().x, 0.04f, 1e-6f);
  // The Normal input: the interpolated normal unless linked to the normal map / bump.
  const Vec3f tilted = normalize(Vec3f(std::sqrt(0.75f), 0.0f, 0.5f));
  EXPECT_NEAR(seen(m, Vec3f(0.0f, 0.0f, 1.0f), true, tilted).x, 0.04f, 1e-6f);
  fresnel.normal_linked = true;
  const Material linked(emission_of(fresnel), {});
  EXPECT_NEAR(seen(linked, Vec3f(0.0f, 0.0f, 1.0f), true, tilted).x, 0.0891867f, 1e-6f);

  // Layer Weight's outputs as a float (Mix Shader factor): Facing 1 - 0.5 at cos 0.5, blend 0.5.
  InputNode facing;
  facing.kind = InputNodeKind::LayerWeight;
  facing.value_a = FloatInput(0.5f);
  facing.channel = 1;
  MaterialDesc mix;
  ShaderNode a, b, f;
  a.kind = b.kind = ShaderNodeKind::Diffuse;
  a.color = ColorInput(Spectrum(1.0f, 0.0f, 0.0f));
  b.color = ColorInput(Spectrum(0.0f, 0.0f, 1.0f));
  f.kind = ShaderNodeKind::Mix;
  f.fac.node = 0;
  f.a = 0;
  f.b = 1;
  mix.nodes = {a, b, f};
  mix.inputs = {facing};
  mix.root = 2;
  const Material mixed(mix, {});
  EXPECT_TRUE(mixed.reads_view());
  const ShadingGeometry g{oblique, Vec3f(0.0f, 0.0f, 1.0f), Vec3f(0.0f, 0.0f, 1.0f),
                          Vec3f(0.0f, 0.0f, 1.0f)};
  ShadingContext sc{{0.0f, 0.0f}, true};
  sc.geometry = &g;
  ClosureSet set;
  mixed.evaluate(sc, set);
  ASSERT_EQ(set.count(), 2);
  EXPECT_NEAR(set[0].weight.x, 0.5f, 1e-6f);
  EXPECT_NEAR(set[1].weight.z, 0.5f, 1e-6f);
  // The Fresnel output of the same node: IOR 2 at cos 0.5.
  mix.inputs[0].channel = 0;
  const Material fresnel_mix(mix, {});
  set.clear();
  fresnel_mix.evaluate(sc, set);
  const float f2 = fresnel_dielectric(0.5f, 2.0f);
  EXPECT_NEAR(set[0].weight.x, 1.0f - f2, 1e-6f);
  EXPECT_NEAR(set[1].weight.z, f2, 1e-6f);
}

TEST(ViewNodes, GeometryOutputs) {
  InputNode geometry;
  geometry.kind = InputNodeKind::Geometry;
  auto output = [&](GeometryOutput which, Vec3f in, bool front) {
    geometry.geometry_output = which;
    return seen(Material(emission_of(geometry), {}), in, front, normalize(Vec3f(0.0f, 0.6f, 0.8f)));
  };
  const Vec3f in = normalize(Vec3f(0.3f, -0.2f, 0.9f));
  // Normal: the interpolated one (a bump does not change it), flipped on a back face.
  expect_spectrum(output(GeometryOutput::Normal, in, true), Vec3f(0.0f, 0.0f, 1.0f));
  expect_spectrum(output(GeometryOutput::Normal, -in, false), Vec3f(0.0f, 0.0f, -1.0f));
  expect_spectrum(output(GeometryOutput::TrueNormal, -in, false), Vec3f(0.0f, 0.0f, -1.0f));
  expect_spectrum(output(GeometryOutput::Incoming, in, true), in);
  expect_spectrum(output(GeometryOutput::Backfacing, in, true), Vec3f(0.0f));
  expect_spectrum(output(GeometryOutput::Backfacing, -in, false), Vec3f(1.0f));
  // Backfacing depends on the side only (the per-side cache keeps it); the others on the view.
  EXPECT_FALSE(Material(emission_of(geometry), {}).reads_view());
  geometry.geometry_output = GeometryOutput::Incoming;
  EXPECT_TRUE(Material(emission_of(geometry), {}).reads_view());
  // As a float (Math, Mix factor): the mean of the vector's components.
  MaterialDesc d = emission_of(geometry);
  InputNode math;
  math.kind = InputNodeKind::Math;
  math.math = MathOp::Add;
  math.value_a.node = 1;
  math.value_b = FloatInput(0.0f);
  d.inputs[0] = math;
  d.inputs.push_back(geometry);
  EXPECT_NEAR(seen(Material(d, {}), in, true).x, (in.x + in.y + in.z) / 3.0f, 1e-6f);
}

TEST(ViewNodes, LightPathOutputs) {
  InputNode light_path;
  light_path.kind = InputNodeKind::LightPath;
  auto output = [&](LightPathOutput which, const PathView* path) {
    light_path.light_path_output = which;
    const Material m(emission_of(light_path), {});
    EXPECT_TRUE(m.reads_path());
    EXPECT_FALSE(m.reads_view());
    ShadingContext sc{{0.0f, 0.0f}, true};
    sc.path = path;
    return m.emission(sc).x;
  };
  using L = LightPathOutput;
  // Without a path (and on the camera path): a camera ray of depth 0.
  EXPECT_EQ(output(L::IsCameraRay, nullptr), 1.0f);
  EXPECT_EQ(output(L::IsReflectionRay, nullptr), 0.0f);
  PathView camera;
  camera.ray_length = 3.5f;
  camera.transparent_depth = 1;  // crossings keep the camera path
  EXPECT_EQ(output(L::IsCameraRay, &camera), 1.0f);
  EXPECT_EQ(output(L::RayLength, &camera), 3.5f);
  EXPECT_EQ(output(L::TransparentDepth, &camera), 1.0f);
  // After a diffuse reflection and a glossy transmission.
  PathView p;
  p.lobe = kLobeTransmission | kLobeGlossy;
  p.ray_length = 0.25f;
  p.depth = 2;
  p.diffuse_depth = 1;
  p.transmission_depth = 1;
  EXPECT_EQ(output(L::IsCameraRay, &p), 0.0f);
  EXPECT_EQ(output(L::IsShadowRay, &p), 0.0f);
  EXPECT_EQ(output(L::IsDiffuseRay, &p), 0.0f);
  EXPECT_EQ(output(L::IsGlossyRay, &p), 1.0f);
  EXPECT_EQ(output(L::IsSingularRay, &p), 0.0f);
  EXPECT_EQ(output(L::IsReflectionRay, &p), 0.0f);
  EXPECT_EQ(output(L::IsTransmissionRay, &p), 1.0f);
  EXPECT_EQ(output(L::RayLength, &p), 0.25f);
  EXPECT_EQ(output(L::RayDepth, &p), 2.0f);
  EXPECT_EQ(output(L::DiffuseDepth, &p), 1.0f);
  EXPECT_EQ(output(L::GlossyDepth, &p), 0.0f);
  EXPECT_EQ(output(L::TransmissionDepth, &p), 1.0f);
  // A delta reflection is singular and glossy (Cycles' path_state_next).
  p.lobe = kLobeReflection | kLobeDelta;
  EXPECT_EQ(output(L::IsSingularRay, &p), 1.0f);
  EXPECT_EQ(output(L::IsGlossyRay, &p), 1.0f);
  EXPECT_EQ(output(L::IsReflectionRay, &p), 1.0f);
  p.lobe = kLobeReflection | kLobeDiffuse;
  EXPECT_EQ(output(L::IsDiffuseRay, &p), 1.0f);
  EXPECT_EQ(output(L::IsGlossyRay, &p), 0.0f);
  // A light sample's emission: no ray kind at all, camera included.
  PathView sample;
  sample.light_sample = true;
  for (L which : {L::IsCameraRay, L::IsDiffuseRay, L::IsGlossyRay, L::IsReflectionRay})
    EXPECT_EQ(output(which, &sample), 0.0f);
}

}  // namespace
}  // namespace gdpt
