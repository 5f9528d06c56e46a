// Material trees: Mix / Add weights, node -> closure mapping (Diffuse, Glossy, Glass,
// Principled v1, Emission, Transparent), texture inputs through the Mapping transform,
// feature flags, average emission, and malformed trees.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "shaders/fresnel.h"
#include "shaders/material.h"

namespace gdpt {
namespace {

ShaderNode node(ShaderNodeKind kind, Spectrum color = Spectrum(0.8f)) {
  ShaderNode n;
  n.kind = kind;
  n.color = ColorInput(color);
  n.roughness = FloatInput(0.0f);
  return n;
}

ClosureSet eval(const Material& m, Vec2f uv = {0.25f, 0.25f}) {
  ClosureSet s;
  m.evaluate(ShadingContext{uv, true}, s);
  return s;
}

void expect_spectrum(Spectrum got, Spectrum want, float tol = 1e-6f) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

TEST(Material, DefaultIsCyclesGreyDiffuse) {
  for (const Material& m : {Material(), Material(MaterialDesc{}, {})}) {
    const ClosureSet s = eval(m);
    ASSERT_EQ(s.count(), 1);
    EXPECT_EQ(s[0].type, ClosureType::Lambert);
    expect_spectrum(s[0].weight, Spectrum(0.8f));
    EXPECT_EQ(m.features(), 0u);
    EXPECT_FALSE(m.is_emissive());
  }
}

TEST(Material, MixAndAddWeights) {
  // Add(Mix(Diffuse red rough 0.5, Glossy r 0.5, fac 0.25), Emission (1,2,3) x 2)
  MaterialDesc d;
  d.name = "tree";
  d.nodes.push_back(node(ShaderNodeKind::Add));  // 0
  d.nodes[0].a = 1;
  d.nodes[0].b = 4;
  d.nodes.push_back(node(ShaderNodeKind::Mix));  // 1
  d.nodes[1].fac = FloatInput(0.25f);
  d.nodes[1].a = 2;
  d.nodes[1].b = 3;
  d.nodes.push_back(node(ShaderNodeKind::Diffuse, Spectrum(1, 0, 0)));  // 2
  d.nodes[2].roughness = FloatInput(0.5f);
  d.nodes.push_back(node(ShaderNodeKind::Glossy, Spectrum(1.0f)));  // 3
  d.nodes[3].roughness = FloatInput(0.5f);
  d.nodes.push_back(node(ShaderNodeKind::Emission, Spectrum(1, 2, 3)));  // 4
  d.nodes[4].strength = FloatInput(2.0f);
  d.root = 0;
  const Material m(d, {});
  const ClosureSet s = eval(m);
  ASSERT_EQ(s.count(), 2);
  EXPECT_EQ(s[0].type, ClosureType::OrenNayar);
  EXPECT_FLOAT_EQ(s[0].alpha, 0.5f);
  expect_spectrum(s[0].weight, Spectrum(0.75f, 0, 0));
  EXPECT_EQ(s[1].type, ClosureType::GGXReflection);
  EXPECT_EQ(s[1].fresnel, FresnelMode::None);
  EXPECT_FLOAT_EQ(s[1].alpha, 0.25f);  // roughness^2
  expect_spectrum(s[1].weight, Spectrum(0.25f));
  expect_spectrum(s.emission(), Spectrum(2, 4, 6));
  expect_spectrum(m.emission(ShadingContext{}), Spectrum(2, 4, 6));
  expect_spectrum(m.average_emission(), Spectrum(2, 4, 6));
  EXPECT_EQ(m.features(), uint32_t(kFeatureGlossy | kFeatureEmission));

  // Mix factors outside [0, 1] clamp, as Cycles.
  d.nodes[1].fac = FloatInput(1.5f);
  const ClosureSet s2 = eval(Material(d, {}));
  ASSERT_EQ(s2.count(), 1);
  EXPECT_EQ(s2[0].type, ClosureType::GGXReflection);
}

TEST(Material, TexturedInputsGoThroughTheMapping) {
  // 2x2 texture, bottom row red 0.2 / 0.6, top row 0.9 / 1.0.
  ImageDesc img;
  img.width = 2;
  img.height = 2;
  img.rgba = {0.2f, 0.1f, 0.0f, 1, 0.6f, 0.3f, 0.0f, 1, 0.9f, 0.0f, 0.0f, 1, 1.0f, 1.0f, 1.0f, 1};
  const std::vector<Texture> textures{Texture(img)};

  MaterialDesc d;
  d.nodes.push_back(node(ShaderNodeKind::Mix));  // fac from the red channel
  d.nodes[0].fac.texture.image = 0;
  d.nodes[0].fac.texture.interpolation = TextureLookup::Interpolation::Closest;
  d.nodes[0].fac.channel = FloatInput::Channel::Red;
  // Mapping: uv -> (uv.x + 0.5, uv.y): the lookup at u = 0.25 reads pixel x = 1.
  d.nodes[0].fac.texture.vector.mapping.m[0][3] = 0.5f;
  d.nodes[0].a = 1;
  d.nodes[0].b = 2;
  d.nodes.push_back(node(ShaderNodeKind::Diffuse));
  d.nodes[1].color.texture.image = 0;  // base colour from the texture, bilinear
  d.nodes.push_back(node(ShaderNodeKind::Transparent, Spectrum(1.0f)));
  d.root = 0;
  const Material m(d, textures);
  EXPECT_TRUE(m.features() & kFeatureTextures);
  EXPECT_TRUE(m.features() & kFeatureTransparent);
  const ClosureSet s = eval(m, {0.25f, 0.25f});
  ASSERT_EQ(s.count(), 2);
  // fac = red of pixel (1, 0) = 0.6; diffuse colour = pixel (0, 0) = (0.2, 0.1, 0).
  expect_spectrum(s[0].weight, Spectrum(0.2f, 0.1f, 0.0f) * 0.4f);
  expect_spectrum(s[1].weight, Spectrum(0.6f));
}

TEST(Material, PrincipledMetallicReflectsBaseColourAtNormalIncidence) {
  const Spectrum base(0.9f, 0.5f, 0.2f);
  auto principled = [](Spectrum c) {
    MaterialDesc d;
    ShaderNode n = node(ShaderNodeKind::Principled, c);
    n.metallic = FloatInput(1.0f);
    n.roughness = FloatInput(0.3f);
    d.nodes.push_back(n);
    d.root = 0;
    return Material(d, {});
  };
  const ClosureSet s = eval(principled(base));
  const ClosureSet white = eval(principled(Spectrum(1.0f)));
  ASSERT_EQ(s.count(), 1);  // metallic: no diffuse, no transmission
  EXPECT_EQ(s[0].fresnel, FresnelMode::PrincipledV1);
  const Vec3f n(0, 0, 1);
  const Spectrum ratio = s.eval(n, n) / white.eval(n, n);
  expect_spectrum(ratio, base, 1e-5f);
  // Towards grazing the Fresnel blend goes to white.
  const Vec3f g = normalize(Vec3f(1, 0, 0.02f)), go = normalize(Vec3f(-1, 0, 0.02f));
  const Spectrum r2 = s.eval(g, go) / white.eval(g, go);
  EXPECT_GT(r2.z, 0.8f);
}

TEST(Material, PrincipledWeightsFollowCycles) {
  MaterialDesc d;
  ShaderNode n = node(ShaderNodeKind::Principled, Spectrum(0.5f, 0.4f, 0.3f));
  n.roughness = FloatInput(0.5f);
  n.metallic = FloatInput(0.2f);
  n.transmission = FloatInput(0.5f);
  n.specular = FloatInput(0.5f);
  n.ior = FloatInput(1.5f);
  n.alpha = FloatInput(0.8f);
  n.emission = ColorInput(Spectrum(1, 1, 0));
  n.emission_strength = FloatInput(3.0f);
  d.nodes.push_back(n);
  d.root = 0;
  const Material m(d, {});
  const ClosureSet s = eval(m);
  ASSERT_EQ(s.count(), 4);  // transparent, diffuse, specular, glass
  EXPECT_EQ(s[0].type, ClosureType::Transparent);
  expect_spectrum(s[0].weight, Spectrum(0.2f));
  EXPECT_EQ(s[1].type, ClosureType::PrincipledDiffuse);
  // 0.8 alpha * (1 - 0.2) * (1 - 0.5) * base
  expect_spectrum(s[1].weight, Spectrum(0.5f, 0.4f, 0.3f) * 0.32f);
  EXPECT_FLOAT_EQ(s[1].alpha, 0.5f);
  EXPECT_EQ(s[2].type, ClosureType::GGXReflection);
  // specular weight 1 - transmission (1 - metallic) = 0.6
  expect_spectrum(s[2].weight, Spectrum(0.8f * 0.6f));
  EXPECT_FLOAT_EQ(s[2].alpha, 0.25f);
  EXPECT_NEAR(fresnel_f0(s[2].ior), 0.04f, 1e-5f);  // F0 = 0.08 specular
  // cspec0 = 0.08 * 0.5 * (1 - 0.2) + base * 0.2
  expect_spectrum(s[2].f0, Spectrum(0.032f) + Spectrum(0.5f, 0.4f, 0.3f) * 0.2f, 1e-6f);
  EXPECT_EQ(s[3].type, ClosureType::GGXDielectric);
  expect_spectrum(s[3].weight, Spectrum(0.8f * 0.4f));
  expect_spectrum(s[3].transmission_tint, Spectrum(0.5f, 0.4f, 0.3f));
  EXPECT_FLOAT_EQ(s[3].ior, 1.5f);
  ClosureSet back;
  m.evaluate(ShadingContext{{0.0f, 0.0f}, false}, back);
  EXPECT_FLOAT_EQ(back[3].ior, 1.0f / 1.5f);  // leaving the object
  EXPECT_FLOAT_EQ(back[2].ior, s[2].ior);     // the specular F0 does not depend on the side
  expect_spectrum(s.emission(), Spectrum(2.4f, 2.4f, 0.0f), 1e-5f);  // inside the alpha mix
  EXPECT_EQ(m.features(), uint32_t(kFeatureGlossy | kFeatureTransmission | kFeatureEmission |
                                   kFeatureTransparent | kFeatureDelta));
}

// Sheen: weight sheen * mix(1, base / lum(base), tint) * (1 - metallic)(1 - transmission), lum
// the Rec.709 luminance; none without diffuse (metallic 1) or at sheen 0.
TEST(Material, PrincipledSheenFollowsCycles) {
  auto sheen_of = [](float sheen, float metallic) {
    MaterialDesc d;
    ShaderNode n = node(ShaderNodeKind::Principled, Spectrum(0.5f, 0.4f, 0.3f));
    n.metallic = FloatInput(metallic);
    n.transmission = FloatInput(0.5f);
    n.sheen = FloatInput(sheen);
    n.sheen_tint = FloatInput(0.25f);
    d.nodes.push_back(n);
    d.root = 0;
    const ClosureSet s = eval(Material(d, {}));
    for (int i = 0; i < s.count(); ++i)
      if (s[i].type == ClosureType::PrincipledSheen) return std::optional<Closure>(s[i]);
    return std::optional<Closure>();
  };
  const std::optional<Closure> c = sheen_of(0.8f, 0.2f);
  ASSERT_TRUE(c.has_value());
  const float lum = 0.2126729f * 0.5f + 0.7151522f * 0.4f + 0.0721750f * 0.3f;
  const Spectrum tint = Spectrum(0.75f) + Spectrum(0.5f, 0.4f, 0.3f) / lum * 0.25f;
  expect_spectrum(c->weight, tint * (0.8f * 0.8f * 0.5f), 1e-6f);
  EXPECT_FALSE(sheen_of(0.0f, 0.2f).has_value());
  EXPECT_FALSE(sheen_of(0.8f, 1.0f).has_value());
}

// Subsurface s: Cycles' BSSRDF below its minimum radius is the whole PrincipledDiffuse
// (retro-reflection and Lambert parts) of mix(base, subsurface colour, s); on camera paths the
// other lobes keep the base colour, after a diffuse bounce they take the mix too.
TEST(Material, PrincipledSubsurfaceIsCyclesDiffuseFallback) {
  const Spectrum base(0.8f, 0.2f, 0.1f), sss(0.1f, 0.3f, 0.9f);
  const Spectrum mixed = base * 0.3f + sss * 0.7f;
  MaterialDesc d;
  ShaderNode n = node(ShaderNodeKind::Principled, base);
  n.subsurface = FloatInput(0.7f);
  n.subsurface_color = ColorInput(sss);
  n.metallic = FloatInput(0.2f);
  d.nodes.push_back(n);
  d.root = 0;
  const Material m(d, {});
  EXPECT_TRUE(m.reads_path());  // the metallic lobe's colour depends on the path
  for (const int16_t diffuse_depth : {0, 1}) {
    PathView path;
    path.depth = path.diffuse_depth = diffuse_depth;
    ShadingContext ctx{{0.25f, 0.25f}, true};
    ctx.path = &path;
    ClosureSet s;
    m.evaluate(ctx, s);
    ASSERT_EQ(s.count(), 2);
    EXPECT_EQ(s[0].type, ClosureType::PrincipledDiffuse);
    expect_spectrum(s[0].weight, mixed * 0.8f);
    EXPECT_EQ(s[1].type, ClosureType::GGXReflection);
    const Spectrum metal = diffuse_depth > 0 ? mixed : base;
    expect_spectrum(s[1].f0, Spectrum(0.08f * 0.5f * 0.8f) + metal * 0.2f);
  }
  // Without lobes that read the base colour the material stays constant.
  d.nodes[0].metallic = FloatInput(0.0f);
  const Material plain(d, {});
  EXPECT_FALSE(plain.reads_path());
  expect_spectrum(eval(plain)[0].weight, mixed);
  d.nodes[0].subsurface = FloatInput(0.0f);
  expect_spectrum(eval(Material(d, {}))[0].weight, base);
}

// Clearcoat: a Clearcoat lobe of alpha clearcoat_roughness^2, weight 0.25 clearcoat (times alpha
// and the mix weight, not reduced by metallic or transmission), whose Fresnel is the dielectric
// one of IOR 1.5: a smooth coat reflects 0.25 F(cos_i) of the light at every incidence. Lobes
// inherit whether their normal input is linked to the material's perturbation.
TEST(Material, PrincipledClearcoatFollowsCycles) {
  MaterialDesc d;
  ShaderNode n = node(ShaderNodeKind::Principled, Spectrum(0.5f, 0.4f, 0.3f));
  n.metallic = FloatInput(1.0f);
  n.clearcoat = FloatInput(0.6f);
  n.clearcoat_roughness = FloatInput(0.2f);
  n.alpha = FloatInput(0.5f);
  n.normal_linked = true;
  n.clearcoat_normal_linked = false;
  d.nodes.push_back(n);
  d.root = 0;
  const ClosureSet s = eval(Material(d, {}));
  ASSERT_EQ(s.count(), 3);  // transparent, metal, clearcoat
  const Closure& coat = s[2];
  EXPECT_EQ(coat.type, ClosureType::Clearcoat);
  expect_spectrum(coat.weight, Spectrum(0.25f * 0.6f * 0.5f));
  EXPECT_FLOAT_EQ(coat.alpha, 0.04f);
  EXPECT_TRUE(coat.interpolated_normal);
  EXPECT_FALSE(s[1].interpolated_normal);
  EXPECT_EQ(Material(d, {}).features() & kFeatureGlossy, uint32_t(kFeatureGlossy));

  // Smooth coat alone (black base, no specular): delta reflection of value 0.25 F(cos_i, 1.5).
  ShaderNode smooth = node(ShaderNodeKind::Principled, Spectrum(0.0f));
  smooth.specular = FloatInput(0.0f);
  smooth.clearcoat = FloatInput(1.0f);
  smooth.clearcoat_roughness = FloatInput(0.0f);
  MaterialDesc ds;
  ds.nodes.push_back(smooth);
  ds.root = 0;
  const Material ms(ds, {});
  EXPECT_EQ(ms.features() & kFeatureDelta, uint32_t(kFeatureDelta));
  const ClosureSet c = eval(ms);
  ASSERT_EQ(c.count(), 1);
  for (float cos_i : {1.0f, 0.7f, 0.3f, 0.05f}) {
    const Vec3f wi(std::sqrt(1.0f - cos_i * cos_i), 0.0f, cos_i);
    const BsdfSample b = c.sample(wi, 0.5f, Vec2f(0.3f, 0.6f));
    ASSERT_TRUE(b.valid && b.is_delta());
    // Dielectric Fresnel of 1.5 in double.
    const double ci = cos_i, st2 = (1.0 - ci * ci) / 2.25, ct = std::sqrt(1.0 - st2);
    const double rs = (ci - 1.5 * ct) / (ci + 1.5 * ct), rp = (1.5 * ci - ct) / (1.5 * ci + ct);
    EXPECT_NEAR(b.weight().y, 0.25 * 0.5 * (rs * rs + rp * rp), 1e-6) << cos_i;
  }
  // No coat at clearcoat 0.
  smooth.clearcoat = FloatInput(0.0f);
  ds.nodes[0] = smooth;
  EXPECT_EQ(eval(Material(ds, {})).count(), 0);
}

TEST(Material, GlassNodes) {
  MaterialDesc d;
  ShaderNode g = node(ShaderNodeKind::Glass, Spectrum(0.9f));
  g.ior = FloatInput(1.33f);
  d.nodes.push_back(g);
  d.root = 0;
  const Material smooth(d, {});
  EXPECT_EQ(smooth.features(), uint32_t(kFeatureGlossy | kFeatureTransmission | kFeatureDelta));
  ClosureSet s = eval(smooth);
  ASSERT_EQ(s.count(), 1);
  EXPECT_EQ(s[0].type, ClosureType::GGXDielectric);
  EXPECT_TRUE(s.has_delta());

  // Hit from the back (leaving the object): the integrators orient the frame towards the ray,
  // so the closure carries the inverse IOR.
  ClosureSet back;
  smooth.evaluate(ShadingContext{{0.0f, 0.0f}, false}, back);
  EXPECT_FLOAT_EQ(back[0].ior, 1.0f / 1.33f);
  EXPECT_FLOAT_EQ(s[0].ior, 1.33f);

  d.nodes[0].roughness = FloatInput(0.3f);
  const Material rough(d, {});
  EXPECT_EQ(rough.features(), uint32_t(kFeatureGlossy | kFeatureTransmission));
  s = eval(rough);
  EXPECT_FLOAT_EQ(s[0].alpha, 0.09f);
  EXPECT_FALSE(s.has_delta());

  d.nodes[0].ior = FloatInput(1.0f);  // index matched: a pass-through
  s = eval(Material(d, {}));
  ASSERT_EQ(s.count(), 1);
  EXPECT_EQ(s[0].type, ClosureType::Transparent);
}

// Anisotropic BSDF (Cycles 3.4): alpha = r^2 times (1 - a) along the tangent and over it across
// (swapped for a < 0), Rotation in turns; the default tangent runs around the object's Z axis
// through the generated coordinates, taken to world space by the normal matrix. Principled:
// r^2 / aspect and r^2 aspect, aspect = sqrt(1 - 0.9 a), on the specular lobe only.
TEST(Material, AnisotropicWidthsAndRadialTangent) {
  MaterialDesc d;
  ShaderNode a = node(ShaderNodeKind::Anisotropic, Spectrum(0.9f));
  a.roughness = FloatInput(0.3f);
  a.anisotropy = FloatInput(0.8f);
  a.rotation = FloatInput(0.25f);
  d.nodes.push_back(a);
  d.root = 0;
  const Material m(d, {});
  EXPECT_TRUE(m.reads_coordinates());
  EXPECT_TRUE(m.features() & kFeatureTextures);  // per hit: the tangent varies
  // Normal matrix of a quarter turn about x: object y -> world z.
  const float cols[3][4] = {{1, 0, 0, 0}, {0, 0, 1, 0}, {0, -1, 0, 0}};
  TexCoords tc;
  tc.generated = Vec3f(0.9f, 0.5f, 0.2f);
  tc.normal_cols = cols;
  ShadingContext at{{0.0f, 0.0f}, true};
  at.coords = &tc;
  ClosureSet s;
  m.evaluate(at, s);
  ASSERT_EQ(s.count(), 1);
  EXPECT_NEAR(s[0].alpha, 0.09f * 0.2f, 1e-6f);
  EXPECT_NEAR(s[0].alpha_y, 0.09f / 0.2f, 1e-5f);
  EXPECT_NEAR(s[0].rotation.x, 0.0f, 1e-6f);
  EXPECT_NEAR(s[0].rotation.y, 1.0f, 1e-6f);
  // Object-space radial tangent (-(y - 0.5), x - 0.5, 0) = (0, 0.4, 0), world (0, 0, 0.4).
  expect_spectrum(s[0].tangent, Vec3f(0.0f, 0.0f, 0.4f));

  d.nodes[0].anisotropy = FloatInput(-0.5f);
  ClosureSet neg;
  Material(d, {}).evaluate(at, neg);
  EXPECT_NEAR(neg[0].alpha, 0.09f / 0.5f, 1e-6f);
  EXPECT_NEAR(neg[0].alpha_y, 0.09f * 0.5f, 1e-6f);
  d.nodes[0].anisotropy = FloatInput(0.0f);
  ClosureSet iso;
  Material(d, {}).evaluate(at, iso);
  EXPECT_FALSE(is_anisotropic(iso[0]));
  EXPECT_FLOAT_EQ(iso[0].alpha, 0.09f);

  MaterialDesc p;
  ShaderNode pr = node(ShaderNodeKind::Principled, Spectrum(0.8f, 0.5f, 0.3f));
  pr.roughness = FloatInput(0.3f);
  pr.metallic = FloatInput(1.0f);
  pr.anisotropy = FloatInput(0.8f);
  pr.tangent.axis = 0;  // radial about X: (0, -(z - 0.5), y - 0.5) = (0, 0.3, 0)
  p.nodes.push_back(pr);
  p.root = 0;
  ClosureSet ps;
  Material(p, {}).evaluate(at, ps);
  ASSERT_EQ(ps.count(), 1);
  const float aspect = std::sqrt(1.0f - 0.72f);
  EXPECT_NEAR(ps[0].alpha, 0.09f / aspect, 1e-6f);
  EXPECT_NEAR(ps[0].alpha_y, 0.09f * aspect, 1e-6f);
  expect_spectrum(ps[0].tangent, Vec3f(0.0f, 0.0f, 0.3f));

  // A Tangent node's UV Map direction: the mesh's tangent through the same normal matrix.
  d.nodes[0].anisotropy = FloatInput(0.8f);
  d.nodes[0].tangent.source = TangentInput::Source::UVMap;
  tc.uv_tangent = Vec3f(0.0f, 2.0f, 0.0f);
  ClosureSet uv;
  Material(d, {}).evaluate(at, uv);
  expect_spectrum(uv[0].tangent, Vec3f(0.0f, 0.0f, 2.0f));

  // Geometry's Tangent output: the default tangent made unit and normal to N (Cycles'
  // primitive_tangent), here an emission colour. World radial (0, 0, 0.4) about N = (0, 0.6, 0.8).
  MaterialDesc e;
  InputNode geometry;
  geometry.kind = InputNodeKind::Geometry;
  geometry.geometry_output = GeometryOutput::Tangent;
  e.inputs.push_back(geometry);
  ShaderNode emit = node(ShaderNodeKind::Emission);
  emit.color.node = 0;
  e.nodes.push_back(emit);
  e.root = 0;
  const Material em(e, {});
  EXPECT_TRUE(em.reads_coordinates());
  const ShadingGeometry view{Vec3f(0, 0, 1), Vec3f(0, 0.6f, 0.8f), Vec3f(0, 0.6f, 0.8f),
                             Vec3f(0, 0.6f, 0.8f)};
  at.geometry = &view;
  expect_spectrum(em.emission(at), Vec3f(0.0f, -0.8f, 0.6f), 1e-5f);
}

// A texture's vector can be any input node's result (TexCoordSource::Node): a Checker read at
// Vector Math (UV + (0.3, 0, 0)) equals a Checker read at UV through a Mapping that adds the
// same; a vector (a coordinate, a Vector Math Vector) read by a float socket is the mean of its
// components (Cycles' vector-to-float conversion), a Value output is itself.
TEST(Material, TexturesReadVectorsFromInputNodes) {
  InputNode uv;
  uv.kind = InputNodeKind::Coordinates;
  InputNode shift;
  shift.kind = InputNodeKind::VectorMath;
  shift.vector_math = VectorMathOp::Add;
  shift.a.node = 0;
  shift.b = ColorInput(Spectrum(0.3f, 0.0f, 0.0f));
  InputNode checker;
  checker.kind = InputNodeKind::Checker;
  checker.value_a = FloatInput(4.0f);
  checker.a = ColorInput(Spectrum(0.9f));
  checker.b = ColorInput(Spectrum(0.1f));
  InputNode via_node = checker, via_mapping = checker;
  via_node.vector.source = TexCoordSource::Node;
  via_node.vector.node = 1;
  via_mapping.vector.mapping.m[0][3] = 0.3f;
  auto material = [&](const InputNode& tex) {
    MaterialDesc d;
    d.inputs = {uv, shift, tex};
    ShaderNode n = node(ShaderNodeKind::Diffuse);
    n.color.node = 2;
    d.nodes.push_back(n);
    d.root = 0;
    return Material(d, {});
  };
  const Material a = material(via_node), b = material(via_mapping);
  int dark = 0;
  for (float u = 0.01f; u < 1.0f; u += 0.0731f)
    for (float v = 0.02f; v < 1.0f; v += 0.0917f) {
      const float ca = eval(a, {u, v})[0].weight.x, cb = eval(b, {u, v})[0].weight.x;
      EXPECT_FLOAT_EQ(ca, cb) << u << "," << v;
      dark += ca < 0.5f;
    }
  EXPECT_GT(dark, 20);  // both colours seen

  // Float sockets: roughness from the shifted vector (mean), from the Length of the UV (itself).
  InputNode length = shift;
  length.vector_math = VectorMathOp::Length;
  length.fac_output = true;
  MaterialDesc d;
  d.inputs = {uv, shift, length};
  ShaderNode n = node(ShaderNodeKind::Diffuse);
  n.roughness.node = 1;
  d.nodes = {n};
  d.root = 0;
  EXPECT_NEAR(eval(Material(d, {}), {0.2f, 0.6f})[0].alpha, (0.5f + 0.6f) / 3.0f, 1e-6f);
  d.nodes[0].roughness.node = 2;
  EXPECT_NEAR(eval(Material(d, {}), {0.2f, 0.6f})[0].alpha, std::sqrt(0.04f + 0.36f), 1e-6f);
  // A vector from a node that does not exist is an error at load.
  via_node.vector.node = 7;
  EXPECT_THROW(material(via_node), std::invalid_argument);
}

TEST(Material, AverageEmissionUsesTextureMeans) {
  ImageDesc img;
  img.width = 2;
  img.height = 1;
  img.rgba = {1, 0, 0, 1, 0, 0, 1, 1};
  const std::vector<Texture> textures{Texture(img)};
  MaterialDesc d;
  ShaderNode e = node(ShaderNodeKind::Emission, Spectrum(1.0f));
  e.color.texture.image = 0;
  e.strength = FloatInput(4.0f);
  d.nodes.push_back(e);
  d.root = 0;
  const Material m(d, textures);
  EXPECT_TRUE(m.is_emissive());
  expect_spectrum(m.average_emission(), Spectrum(2, 0, 2));
  expect_spectrum(m.emission(ShadingContext{{0.25f, 0.5f}, true}), Spectrum(4, 0, 0));
  const ClosureSet s = eval(m, {0.75f, 0.5f});
  EXPECT_EQ(s.count(), 0);
  expect_spectrum(s.emission(), Spectrum(0, 0, 4));
}

// A diffuse material whose colour (or roughness) is input node 0 of `inputs`.
MaterialDesc diffuse_reading(std::vector<InputNode> inputs, bool roughness = false) {
  MaterialDesc d;
  d.nodes.push_back(node(ShaderNodeKind::Diffuse));
  (roughness ? d.nodes[0].roughness.node : d.nodes[0].color.node) = 0;
  d.root = 0;
  d.inputs = std::move(inputs);
  return d;
}

// Colour / math input nodes with Cycles' formulas (svm_mix, svm_math, invert), on constants
// and on a texture, nested, read by colour and float sockets.
TEST(Material, InputNodesFollowCycles) {
  const Spectrum a(0.2f, 0.5f, 0.8f), b(0.6f, 0.4f, 0.0f);
  auto diffuse_colour = [](const MaterialDesc& d, Vec2f uv = {0.25f, 0.25f},
                           std::span<const Texture> textures = {}) {
    const Material m(d, textures);
    const ClosureSet s = eval(m, uv);
    return s.count() ? s[0].weight : Spectrum(-1.0f);
  };
  auto mix = [&](MixBlend blend, float fac) {
    InputNode n;
    n.kind = InputNodeKind::Mix;
    n.blend = blend;
    n.fac = FloatInput(fac);
    n.a = ColorInput(a);
    n.b = ColorInput(b);
    return diffuse_colour(diffuse_reading({n}));
  };
  const float t = 0.25f;
  expect_spectrum(mix(MixBlend::Mix, t), a * 0.75f + b * 0.25f);
  expect_spectrum(mix(MixBlend::Add, t), a + b * t);
  expect_spectrum(mix(MixBlend::Multiply, t), a * (Spectrum(0.75f) + b * t));
  expect_spectrum(mix(MixBlend::Subtract, t), a - b * t);
  expect_spectrum(
      mix(MixBlend::Screen, t),
      Spectrum(1.0f) - (Spectrum(0.75f) + (Spectrum(1.0f) - b) * t) * (Spectrum(1.0f) - a));
  // Divide: a channel divided by 0 keeps a.
  expect_spectrum(mix(MixBlend::Divide, t),
                  Spectrum(0.75f * 0.2f + t * 0.2f / 0.6f, 0.75f * 0.5f + t * 0.5f / 0.4f, 0.8f));
  expect_spectrum(mix(MixBlend::Difference, t), a * 0.75f + Spectrum(0.4f, 0.1f, 0.8f) * t);
  expect_spectrum(mix(MixBlend::Darken, t), a * 0.75f + Spectrum(0.2f, 0.4f, 0.0f) * t);
  expect_spectrum(mix(MixBlend::Lighten, t), a * 0.75f + Spectrum(0.6f, 0.5f, 0.8f) * t);
  expect_spectrum(mix(MixBlend::Mix, 1.7f), b);  // factor clamped by default

  // Roughness from Math(op, x, y), clamped to [0, 1] only when asked; colour from Invert.
  auto math = [&](MathOp op, float x, float y, bool clamp) {
    InputNode n;
    n.kind = InputNodeKind::Math;
    n.math = op;
    n.clamp_result = clamp;
    n.value_a = FloatInput(x);
    n.value_b = FloatInput(y);
    // Diffuse roughness r > 0 gives Oren-Nayar with sigma r (clamped to [0, 1] by the node).
    const ClosureSet s = eval(Material(diffuse_reading({n}, true), {}));
    return s[0].alpha;
  };
  EXPECT_FLOAT_EQ(math(MathOp::Add, 0.2f, 0.3f, false), 0.5f);
  EXPECT_FLOAT_EQ(math(MathOp::Subtract, 0.9f, 0.3f, false), 0.6f);
  EXPECT_FLOAT_EQ(math(MathOp::Multiply, 0.5f, 0.6f, false), 0.3f);
  EXPECT_FLOAT_EQ(math(MathOp::Divide, 0.3f, 0.6f, false), 0.5f);
  EXPECT_FLOAT_EQ(math(MathOp::Divide, 0.3f, 0.0f, false), 0.0f);  // safe division
  EXPECT_FLOAT_EQ(math(MathOp::Power, 0.25f, 0.5f, false), 0.5f);
  EXPECT_FLOAT_EQ(math(MathOp::Minimum, 0.25f, 0.5f, false), 0.25f);
  EXPECT_FLOAT_EQ(math(MathOp::Maximum, 0.25f, 0.5f, false), 0.5f);
  EXPECT_FLOAT_EQ(math(MathOp::Subtract, 0.2f, 0.5f, true), 0.0f);

  // Nested, on a texture: colour = Multiply(texture, Invert(0.3 grey, fac from Math 0.5 * 2)).
  ImageDesc img;
  img.width = img.height = 1;
  img.rgba = {0.4f, 0.6f, 0.8f, 1.0f};
  const std::vector<Texture> textures{Texture(img)};
  InputNode mul;
  mul.kind = InputNodeKind::Mix;
  mul.blend = MixBlend::Multiply;
  mul.fac = FloatInput(1.0f);
  mul.a.texture.image = 0;
  mul.b.node = 1;
  InputNode inv;
  inv.kind = InputNodeKind::Invert;
  inv.a = ColorInput(Spectrum(0.3f));
  inv.fac.node = 2;
  InputNode half;
  half.kind = InputNodeKind::Math;
  half.math = MathOp::Multiply;
  half.value_a = FloatInput(0.5f);
  half.value_b = FloatInput(2.0f);
  MaterialDesc d = diffuse_reading({mul, inv, half});
  const Material m(d, textures);
  EXPECT_TRUE(m.features() & kFeatureTextures);
  expect_spectrum(diffuse_colour(d, {0.5f, 0.5f}, textures), Spectrum(0.4f, 0.6f, 0.8f) * 0.7f);
  // A float socket reads a colour result as its luminance.
  d.nodes[0].color = ColorInput(Spectrum(1.0f));
  d.nodes[0].roughness.node = 0;
  const ClosureSet s = eval(Material(d, textures), {0.5f, 0.5f});
  EXPECT_NEAR(s[0].alpha, luminance(Spectrum(0.4f, 0.6f, 0.8f) * 0.7f), 1e-6f);
  // Color ramp: three entries (0, 0.5, 1); linear between them, or the lower one (Constant);
  // fac clamped; the Alpha output as a float.
  {
    InputNode ramp;
    ramp.kind = InputNodeKind::Ramp;
    ramp.ramp = {1, 0, 0, 0.2f, 0, 1, 0, 0.4f, 0, 0, 1, 0.6f};
    ramp.fac = FloatInput(0.75f);
    InputNode alpha = ramp;
    alpha.ramp_alpha = true;
    MaterialDesc r = diffuse_reading({ramp, alpha});
    r.nodes[0].roughness.node = 1;
    ClosureSet s = eval(Material(r, {}));
    expect_spectrum(s[0].weight, Spectrum(0.0f, 0.5f, 0.5f));
    EXPECT_FLOAT_EQ(s[0].alpha, 0.5f);  // Oren-Nayar sigma = the ramp's alpha at 0.75
    r.inputs[0].ramp_interpolate = false;
    r.inputs[1].fac = FloatInput(7.0f);  // clamped to 1: the last entry
    s = eval(Material(r, {}));
    expect_spectrum(s[0].weight, Spectrum(0.0f, 1.0f, 0.0f));
    EXPECT_FLOAT_EQ(s[0].alpha, 0.6f);
    r.inputs[0].ramp.resize(6);  // not whole entries
    EXPECT_THROW(Material(r, {}), std::invalid_argument);
  }
  // Separate / Combine (RGB), Gamma, Bright / Contrast on constants.
  {
    auto colour_of = [](InputNode n, InputNode inner = InputNode()) {
      return eval(Material(diffuse_reading({n, inner}), {}))[0].weight;
    };
    InputNode sep;
    sep.kind = InputNodeKind::Separate;
    sep.a = ColorInput(Spectrum(0.4f, 0.6f, 0.8f));
    sep.channel = 1;
    InputNode comb;
    comb.kind = InputNodeKind::Combine;
    comb.value_a = FloatInput(0.1f);
    comb.value_b.node = 1;  // the green channel above, read as a float
    comb.value_c = FloatInput(0.3f);
    expect_spectrum(colour_of(comb, sep), Spectrum(0.1f, 0.6f, 0.3f));
    InputNode gamma;
    gamma.kind = InputNodeKind::Gamma;
    gamma.a = ColorInput(Spectrum(0.25f, -0.5f, 0.0f));
    gamma.value_a = FloatInput(2.0f);
    expect_spectrum(colour_of(gamma), Spectrum(0.0625f, -0.5f, 0.0f));  // only positive channels
    gamma.value_a = FloatInput(0.0f);
    expect_spectrum(colour_of(gamma), Spectrum(1.0f));
    InputNode bc;
    bc.kind = InputNodeKind::BrightContrast;
    bc.a = ColorInput(Spectrum(0.5f, 0.1f, 0.9f));
    bc.value_a = FloatInput(0.1f);  // bright
    bc.value_b = FloatInput(0.4f);  // contrast: 1.4 c + 0.1 - 0.2, at least 0
    expect_spectrum(colour_of(bc), Spectrum(0.6f, 0.04f, 1.16f), 1e-6f);
    // Hue/Saturation/Value: hue 0.5 is no shift, +1/3 turns red into green; saturation 0
    // leaves the value as grey; value scales; fac blends with the input.
    InputNode hsv;
    hsv.kind = InputNodeKind::HueSaturation;
    hsv.a = ColorInput(Spectrum(0.8f, 0.2f, 0.2f));
    hsv.fac = FloatInput(1.0f);
    hsv.value_a = FloatInput(0.5f);
    hsv.value_b = FloatInput(1.0f);
    hsv.value_c = FloatInput(1.0f);
    expect_spectrum(colour_of(hsv), Spectrum(0.8f, 0.2f, 0.2f), 1e-6f);
    hsv.value_a = FloatInput(0.5f + 1.0f / 3.0f);
    expect_spectrum(colour_of(hsv), Spectrum(0.2f, 0.8f, 0.2f), 1e-5f);
    hsv.value_a = FloatInput(0.5f);
    hsv.value_b = FloatInput(0.0f);
    hsv.value_c = FloatInput(0.5f);
    expect_spectrum(colour_of(hsv), Spectrum(0.4f), 1e-6f);
    hsv.fac = FloatInput(0.5f);
    expect_spectrum(colour_of(hsv), Spectrum(0.6f, 0.3f, 0.3f), 1e-6f);
    // RGB to BW: the luminance as grey.
    InputNode bw;
    bw.kind = InputNodeKind::ToBw;
    bw.a = ColorInput(Spectrum(0.4f, 0.6f, 0.8f));
    expect_spectrum(colour_of(bw), Spectrum(luminance(Spectrum(0.4f, 0.6f, 0.8f))));
    // Map Range (linear): 0.25 from [0, 0.5] to [1, 3] is 2; 0.75 gives 4, or 3 clamped; an
    // empty source range gives 0.
    InputNode mr;
    mr.kind = InputNodeKind::MapRange;
    mr.bounds = {0.0f, 0.5f, 1.0f, 3.0f};
    mr.value_a = FloatInput(0.25f);
    expect_spectrum(colour_of(mr), Spectrum(2.0f));
    mr.value_a = FloatInput(0.75f);
    expect_spectrum(colour_of(mr), Spectrum(4.0f));
    mr.clamp_result = true;
    expect_spectrum(colour_of(mr), Spectrum(3.0f));
    mr.bounds = {0.5f, 0.5f, 1.0f, 3.0f};
    expect_spectrum(colour_of(mr), Spectrum(1.0f));  // 0, then the node's clamp to [1, 3]
    mr.clamp_result = false;
    // Colour 0: the black diffuse lobe is dropped.
    EXPECT_EQ(eval(Material(diffuse_reading({mr}), {})).count(), 0);
    // Clamp: Min Max, and Range with swapped bounds.
    InputNode cl;
    cl.kind = InputNodeKind::Clamp;
    cl.value_a = FloatInput(0.9f);
    cl.value_b = FloatInput(0.2f);
    cl.value_c = FloatInput(0.5f);
    expect_spectrum(colour_of(cl), Spectrum(0.5f));
    cl.value_b = FloatInput(0.7f);                   // min > max
    expect_spectrum(colour_of(cl), Spectrum(0.5f));  // Min Max: max wins
    cl.clamp_range = true;
    expect_spectrum(colour_of(cl), Spectrum(0.7f));  // Range: clamped to [0.5, 0.7]
  }
  // Malformed: an index out of range, a cycle.
  d.inputs[1].fac.node = 7;
  EXPECT_THROW(Material(d, textures), std::invalid_argument);
  d.inputs[1].fac.node = 1;
  EXPECT_THROW(Material(d, textures), std::invalid_argument);
}

TEST(Material, UnlinkedShaderInputsAreNoClosure) {
  // Mix(unlinked, Emission 2 x (1, 1, 1), fac 0.25) inside Add(that, unlinked): Cycles gives an
  // unlinked shader input no closure, so only a quarter of the emission is left, no lobe.
  MaterialDesc d;
  d.nodes.push_back(node(ShaderNodeKind::Add));  // 0
  d.nodes[0].a = 1;
  d.nodes.push_back(node(ShaderNodeKind::Mix));  // 1
  d.nodes[1].fac = FloatInput(0.25f);
  d.nodes[1].b = 2;
  d.nodes.push_back(node(ShaderNodeKind::Emission, Spectrum(1.0f)));  // 2
  d.nodes[2].strength = FloatInput(2.0f);
  d.root = 0;
  const Material m(d, {});
  const ClosureSet s = eval(m);
  EXPECT_EQ(s.count(), 0);
  expect_spectrum(s.emission(), Spectrum(0.5f));
  d.nodes[1].b = -1;  // both unlinked: black
  const ClosureSet black = eval(Material(d, {}));
  EXPECT_EQ(black.count(), 0);
  expect_spectrum(black.emission(), Spectrum(0.0f));
}

TEST(Material, CurveAndBlackbodyNodes) {
  // A 3-entry table over [-1, 1]: column 0 is 0, 0.5, 2 (x -1, 0, 1), column 1 constant 0.3.
  InputNode curve;
  curve.kind = InputNodeKind::RgbCurves;
  curve.ramp = {0.0f, 0.3f, 0.0f, 0.0f, 0.5f, 0.3f, 0.0f, 0.0f, 2.0f, 0.3f, 0.0f, 0.0f};
  curve.bounds = {-1.0f, 1.0f, 0.0f, 1.0f};
  curve.fac = FloatInput(1.0f);
  MaterialDesc d;
  d.nodes.push_back(node(ShaderNodeKind::Emission));
  d.nodes[0].color.node = 0;
  d.root = 0;
  auto emission_of = [&](Spectrum in, float fac) {
    d.inputs = {curve};
    d.inputs[0].a = ColorInput(in);
    d.inputs[0].fac = FloatInput(fac);
    return eval(Material(d, {})).emission();
  };
  // Interpolated inside, extrapolated along the end segments outside, mixed by fac.
  expect_spectrum(emission_of(Spectrum(0.5f, 0.0f, 0.0f), 1.0f), Spectrum(1.25f, 0.3f, 0.0f));
  expect_spectrum(emission_of(Spectrum(2.0f, 0.0f, 0.0f), 1.0f), Spectrum(3.5f, 0.3f, 0.0f));
  expect_spectrum(emission_of(Spectrum(-2.0f, 0.0f, 0.0f), 1.0f), Spectrum(-0.5f, 0.3f, 0.0f));
  expect_spectrum(emission_of(Spectrum(0.5f, 0.0f, 0.0f), 0.5f), Spectrum(0.875f, 0.15f, 0.0f));
  curve.bounds[1] = -1.0f;  // an empty range is malformed
  d.inputs = {curve};
  EXPECT_THROW(Material(d, {}), std::invalid_argument);

  // Blackbody: Cycles' fit, continuous across its ranges, constant beyond 12000 K, clamped at 0.
  InputNode bb;
  bb.kind = InputNodeKind::Blackbody;
  auto blackbody = [&](float kelvin) {
    d.inputs = {bb};
    d.inputs[0].value_a = FloatInput(kelvin);
    return eval(Material(d, {})).emission();
  };
  for (float t : {965.0f, 1167.0f, 1449.0f, 1902.0f, 3315.0f, 6365.0f}) {
    const Spectrum below = blackbody(t * 0.9999f), above = blackbody(t);
    expect_spectrum(below, above, 0.02f);
  }
  expect_spectrum(blackbody(20000.0f), Spectrum(0.8262955f, 0.9945081f, 1.5663077f));
  const Spectrum candle = blackbody(1500.0f);
  EXPECT_GT(candle.x, candle.y);
  EXPECT_GT(candle.y, candle.z);
  EXPECT_GE(candle.z, 0.0f);
  EXPECT_EQ(blackbody(500.0f).y, 0.0f);  // negative green below 800 K, clamped
}

TEST(Material, MalformedTreesThrow) {
  MaterialDesc d;
  d.name = "broken";
  d.nodes.push_back(node(ShaderNodeKind::Mix));
  d.nodes[0].a = 0;  // cycle
  d.nodes[0].b = 0;
  d.root = 0;
  EXPECT_THROW(Material(d, {}), std::invalid_argument);
  d.nodes[0].a = 5;  // out of range
  EXPECT_THROW(Material(d, {}), std::invalid_argument);
  MaterialDesc t;
  t.nodes.push_back(node(ShaderNodeKind::Diffuse));
  t.nodes[0].color.texture.image = 2;  // no such texture
  t.root = 0;
  EXPECT_THROW(Material(t, {}), std::invalid_argument);
}

}  // namespace
}  // namespace gdpt
