// End-to-end path tracer tests against analytic oracles (white furnace, sun and point light on a
// Lambert plane), plus determinism, robustness (never NaN/Inf), cancel, instancing, the Emission
// pass split and the feature specialisation. Images are tiny; sample counts are what the 1%
// tolerances need with the stratified sampler.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "integrators/integrator.h"
#include "integrators/render_session.h"
#include "render/scene_context.h"
#include "testing/materials.h"

namespace gdpt {
namespace {

// --- Scene helpers ---

MaterialDesc diffuse(Spectrum color, float roughness = 0.0f) {
  return test::single_node(ShaderNodeKind::Diffuse, color, roughness);
}

MaterialDesc glossy(Spectrum color, float roughness) {
  return test::single_node(ShaderNodeKind::Glossy, color, roughness);
}

MaterialDesc emission(Spectrum color, float strength) {
  return test::emission_material(color, strength);
}

Transform translation(Vec3f t) {
  Transform T;
  T.m[0][3] = t.x;
  T.m[1][3] = t.y;
  T.m[2][3] = t.z;
  return T;
}

Transform rotation_x(float a, Vec3f t = Vec3f(0.0f)) {
  Transform T = translation(t);
  T.m[1][1] = std::cos(a);
  T.m[1][2] = -std::sin(a);
  T.m[2][1] = std::sin(a);
  T.m[2][2] = std::cos(a);
  return T;
}

// Square in z = 0 of half-size h, normal +z.
Mesh quad(float h) {
  Mesh m;
  m.positions = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

// Flat-shaded UV sphere (a convex polyhedron, so the furnace identity holds exactly).
Mesh sphere(float r, int seg, int rings, Vec3f c = Vec3f(0.0f)) {
  Mesh m;
  for (int i = 0; i <= rings; ++i) {
    const float th = kPi * float(i) / float(rings);
    for (int j = 0; j < seg; ++j) {
      const float ph = 2.0f * kPi * float(j) / float(seg);
      m.positions.push_back(
          c + Vec3f(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th)) * r);
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < seg; ++j) {
      const uint32_t a = uint32_t(i * seg + j), b = uint32_t(i * seg + (j + 1) % seg);
      const uint32_t c2 = a + uint32_t(seg), d = b + uint32_t(seg);
      if (i > 0) m.indices.insert(m.indices.end(), {a, c2, b});
      if (i < rings - 1) m.indices.insert(m.indices.end(), {b, c2, d});
    }
  return m;
}

Instance place(uint32_t mesh, int32_t material, Transform t = Transform()) {
  Instance i;
  i.mesh = mesh;
  i.object_to_world = t;
  i.slot_material = {material};
  return i;
}

// Orthographic camera at `height` looking straight down, `scale` metres across.
Camera top_camera(int res, float scale, float height = 10.0f) {
  Camera c;
  c.projection = Camera::Projection::Orthographic;
  c.ortho_scale = scale;
  c.camera_to_world = translation({0, 0, height});
  c.width = c.height = res;
  return c;
}

struct Image {
  int w = 0, h = 0;
  std::vector<float> primal, emission;
  std::vector<float> alpha, depth, object_index, material_index;  // 1 per pixel
  std::vector<float> gradient_x;                                  // 3 per pixel
  std::vector<float> normal, mist;  // 3 / 1 per pixel when the render computes them, else empty
  uint32_t min_samples = 0;
  float at(int x, int y, int c = 0) const { return primal[size_t(y * w + x) * 3 + c]; }
};

Image render(const Scene& scene, RenderSettings s, std::string* summary = nullptr) {
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  Image img;
  img.w = session.film().width();
  img.h = session.film().height();
  img.primal.resize(session.film().pixel_count() * 3);
  img.emission.resize(session.film().pixel_count() * 3);
  session.film().primal_rgb(img.primal.data());
  session.film().emission_rgb(img.emission.data());
  for (auto* v : {&img.alpha, &img.depth, &img.object_index, &img.material_index})
    v->resize(session.film().pixel_count());
  session.film().alpha(img.alpha.data());
  session.film().depth(img.depth.data());
  session.film().object_index(img.object_index.data());
  session.film().material_index(img.material_index.data());
  img.gradient_x.resize(session.film().pixel_count() * 3);
  session.film().gradient_x_rgb(img.gradient_x.data());
  if (session.film().has_normal()) {
    img.normal.resize(session.film().pixel_count() * 3);
    session.film().normal(img.normal.data());
  }
  if (session.film().has_mist()) {
    img.mist.resize(session.film().pixel_count());
    session.film().mist(img.mist.data());
  }
  img.min_samples = session.film().min_samples();
  if (summary) *summary = session.features_summary();
  return img;
}

RenderSettings pt(int spp, uint32_t seed = 1) {
  RenderSettings s;
  s.mode = RenderSettings::Mode::PT;
  s.samples = spp;
  s.seed = seed;
  s.threads = 2;
  return s;
}

// --- Analytic oracles ---

TEST(Render, WhiteFurnace) {
  Scene scene;
  scene.meshes.push_back(sphere(1.0f, 48, 24));
  scene.materials.push_back(diffuse(Spectrum(1.0f)));
  scene.instances.push_back(place(0, 0));
  scene.world.color = Spectrum(1.0f);
  scene.world.strength = 1.0f;
  scene.camera = top_camera(16, 1.2f);  // only the sphere's cap is in view
  const Image img = render(scene, pt(64));
  double sum = 0.0;
  for (int y = 0; y < img.h; ++y)
    for (int x = 0; x < img.w; ++x) {
      sum += img.at(x, y, 1);
      EXPECT_NEAR(img.at(x, y, 1), 1.0f, 0.05f) << x << "," << y;
    }
  EXPECT_NEAR(sum / (img.w * img.h), 1.0, 0.01);
}

// `plane` (placed by `placement`) with `material` under a sun of irradiance 3 tilted by `theta`
// about x, seen from straight above by an 8x8 orthographic camera, on a black world.
Scene sunlit_plane(Mesh plane, MaterialDesc material, float theta, Transform placement = {},
                   float sun_angle = 0.0f) {
  Scene scene;
  scene.meshes.push_back(std::move(plane));
  scene.materials.push_back(std::move(material));
  scene.instances.push_back(place(0, 0, placement));
  scene.world.color = Spectrum(0.0f);
  Light sun;
  sun.type = Light::Type::Sun;
  sun.power = 3.0f;
  sun.sun_angle = sun_angle;
  sun.light_to_world = rotation_x(theta, {0, 0, 20});
  scene.lights.push_back(sun);
  scene.camera = top_camera(8, 2.0f);
  return scene;
}

// Radiance of sunlit_plane's albedo-0.5 plane when cos(normal, sun) = cosine: 0.5 E cos / pi.
double lambert_radiance(double cosine) {
  return 0.5 * 3.0 * cosine / kPi;
}

// Mean of channel ch over the image: the primal, plus the emission when asked.
double channel_mean(const Image& img, int ch, bool with_emission = false) {
  double sum = 0.0;
  for (size_t i = size_t(ch); i < img.primal.size(); i += 3)
    sum += img.primal[i] + (with_emission ? img.emission[i] : 0.0f);
  return sum / double(img.primal.size() / 3);
}

// Mean primal of a render of direct light only.
double mean_direct(const Scene& scene, RenderSettings s) {
  s.max_bounces = 0;
  const Image img = render(scene, s);
  double sum = 0.0;
  for (float v : img.primal) sum += v;
  return sum / double(img.primal.size());
}

// Plane of albedo 0.5 under a sun of irradiance E at angle theta: L = albedo E cos(theta) / pi.
void sun_test(float theta, float sun_angle) {
  const Scene scene = sunlit_plane(quad(50.0f), diffuse(Spectrum(0.5f)), theta, {}, sun_angle);
  const double expect = lambert_radiance(std::cos(theta));
  EXPECT_NEAR(mean_direct(scene, pt(16)), expect, 0.01 * expect) << "theta " << theta;
}

TEST(Render, SunOnLambertPlane) {
  for (float theta : {0.0f, 0.5f, 1.1f}) sun_test(theta, 0.0f);
}

// Rotation by `spin` about z, then by `tilt` about x, then translation by t.
Transform tilt_spin(float tilt, float spin, Vec3f t) {
  const float ct = std::cos(tilt), st = std::sin(tilt), cs = std::cos(spin), ss = std::sin(spin);
  Transform T = translation(t);
  const float r[3][3] = {{cs, -ss, 0}, {ct * ss, ct * cs, -st}, {st * ss, st * cs, ct}};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) T.m[i][j] = r[i][j];
  return T;
}

// Overlapping coplanar faces of different objects (two instances of one mesh, and another mesh
// placed once, in world space) are each lit as a lone plane: a shadow ray leaving one face must
// not stop on the other at distance ~0. The planes are tilted, spun and moved off the origin so
// their hit positions carry rounding. Cycles 3.4 shades such faces black (it skips only the ray's
// own triangle): the streaks that made the benchmark's instances scene disagree with it.
TEST(Render, CoplanarFacesOfOtherObjectsDoNotShadow) {
  constexpr float kTheta = 0.5f, kTilt = 0.3f;
  const Vec3f origin(0.37f, 1.13f, 0.71f);
  Scene scene =
      sunlit_plane(quad(50.0f), diffuse(Spectrum(0.5f)), kTheta, tilt_spin(kTilt, 0.7f, origin));
  scene.instances.push_back(place(0, 0, tilt_spin(kTilt, 2.1f, origin)));
  scene.meshes.push_back(quad(40.0f));
  scene.instances.push_back(place(1, 0, tilt_spin(kTilt, -1.3f, origin)));
  const double expect = lambert_radiance(std::cos(kTheta - kTilt));
  for (RenderSettings::Mode mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    RenderSettings s = pt(16);
    s.mode = mode;
    EXPECT_NEAR(mean_direct(scene, s), expect, 0.01 * expect) << int(mode);
  }
}

// A Normal Map node with a constant colour tilts the shading normal of a plane whose tangents
// run along +x: the sun straight above then lights it with cos(tilt), Lambert's law on the mapped
// normal. Strength 0.5 and an instance rotated about z (tangents turn with it) check the
// tangent-space construction; G-PT shades with the same normals.
TEST(Render, NormalMapTiltsTheShadingNormalAsCycles) {
  constexpr float kTilt = 0.6f;  // direction (sin, 0, cos) of the map, radians from the normal
  struct Case {
    float strength, rotate_z, sun_theta;
    double cosine;  // expected cos(mapped normal, sun)
  };
  const double sx = std::sin(kTilt), cz = std::cos(kTilt);
  // Strength 0.5: x halved, z moved half-way to 1.
  const double hx = 0.5 * sx, hz = 1.0 + (cz - 1.0) * 0.5;
  const Case cases[] = {
      {1.0f, 0.0f, 0.0f, cz},
      {0.5f, 0.0f, 0.0f, hz / std::sqrt(hx * hx + hz * hz)},
      // Rotated 90 degrees about z: normal (0, sin, cos); the sun tilted about x by 0.5 comes
      // from (0, -sin 0.5, cos 0.5).
      {1.0f, kPi / 2, 0.5f, std::cos(kTilt + 0.5)},
  };
  for (const Case& c : cases)
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      Mesh plane = quad(50.0f);
      plane.corner_tangents.assign(6, Vec3f(1, 0, 0));
      plane.corner_tangent_signs.assign(6, 1.0f);
      MaterialDesc m = diffuse(Spectrum(0.5f));
      m.normal_map.enabled = true;
      m.normal_map.color =
          ColorInput(Spectrum(0.5f + 0.5f * float(sx), 0.5f, 0.5f + 0.5f * float(cz)));
      m.normal_map.strength = c.strength;
      Transform rot;
      rot.m[0][0] = rot.m[1][1] = std::cos(c.rotate_z);
      rot.m[0][1] = -std::sin(c.rotate_z);
      rot.m[1][0] = std::sin(c.rotate_z);
      const Scene scene = sunlit_plane(plane, m, c.sun_theta, rot);
      RenderSettings s = pt(16);
      s.mode = mode;
      const double expect = lambert_radiance(c.cosine);
      EXPECT_NEAR(mean_direct(scene, s), expect, 0.005 * expect)
          << "strength " << c.strength << " rotation " << c.rotate_z << " G-PT "
          << (mode == RenderSettings::Mode::GPT);
    }
}

// A Color Attribute node: the albedo is the mesh's interpolated corner colour (a plane whose
// corners are all one colour, under a sun straight above: L = colour E / pi per channel), PT and
// G-PT; a mesh without colours reads black, as in Cycles.
TEST(Render, ColorAttributeIsTheInterpolatedCornerColour) {
  const Spectrum c(0.2f, 0.5f, 0.8f);
  for (const bool with_colors : {true, false})
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      Mesh plane = quad(50.0f);
      if (with_colors) plane.corner_colors.assign(6, c);
      MaterialDesc m = diffuse(Spectrum(0.9f));
      InputNode attribute;
      attribute.kind = InputNodeKind::Attribute;
      m.inputs.push_back(attribute);
      m.nodes[0].color.node = 0;
      const Scene scene = sunlit_plane(plane, m, 0.0f);
      RenderSettings s = pt(4);
      s.mode = mode;
      s.max_bounces = 0;
      const Image img = render(scene, s);
      for (int ch = 0; ch < 3; ++ch) {
        const double expect = with_colors ? c[ch] * 3.0 / kPi : 0.0;
        EXPECT_NEAR(channel_mean(img, ch), expect, 1e-3 * (1.0 + expect))
            << "channel " << ch << " colours " << with_colors << " G-PT "
            << (mode == RenderSettings::Mode::GPT);
      }
    }
}

// The 100 m quad with UVs spanning [0, 1]^2.
Mesh uv_quad() {
  Mesh plane = quad(50.0f);
  plane.corner_uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
  return plane;
}

// A two-texel image, black then white: a height ramp along u (2 x 1) or v (1 x 2).
ImageDesc ramp_image(int width, int height) {
  ImageDesc ramp;
  ramp.name = "ramp";
  ramp.width = width;
  ramp.height = height;
  ramp.rgba = {0, 0, 0, 1, 1, 1, 1, 1};
  return ramp;
}

// Albedo 0.5, bumped by the red channel of image 0 (a ramp), distance 10.
MaterialDesc ramp_bumped() {
  MaterialDesc m = diffuse(Spectrum(0.5f));
  m.bumps.emplace_back();
  m.bumps[0].height.texture.image = 0;
  m.bumps[0].height.texture.extension = TextureLookup::Extension::Extend;
  m.bumps[0].height.channel = FloatInput::Channel::Red;
  m.bumps[0].distance = 10.0f;
  return m;
}

// A Bump node whose height rises linearly along u (a 2x1 texture 0 -> 1, bilinear: slope 2 per
// unit of u between the pixel centres) on a 100 m plane mapped to [0, 1]^2: grad h = 0.02 / m
// along x, so with distance 10 the normal tilts to normalize(0, 0, 1) - (0.2, 0, 0)) and the sun
// straight above lights it with cos = 1 / sqrt(1.04); strength 0.5 mixes it half-way back
// towards the normal; invert tilts the other way (same cosine). PT and G-PT.
TEST(Render, BumpTiltsTheNormalAgainstTheHeightGradient) {
  const ImageDesc ramp = ramp_image(2, 1);
  const double tilted = 1.0 / std::sqrt(1.04);
  // Strength 0.5: normalize(0.5 n' + 0.5 n), n' = (-0.2, 0, 1) / sqrt(1.04).
  const double hx = 0.5 * -0.2 / std::sqrt(1.04), hz = 0.5 / std::sqrt(1.04) + 0.5;
  const double half = hz / std::sqrt(hx * hx + hz * hz);
  struct Case {
    float strength;
    bool invert;
    double cosine;
  };
  for (const Case& c :
       {Case{1.0f, false, tilted}, Case{0.5f, false, half}, Case{1.0f, true, tilted}})
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      MaterialDesc m = ramp_bumped();
      m.bumps[0].strength = c.strength;
      m.bumps[0].invert = c.invert;
      Scene scene = sunlit_plane(uv_quad(), m, 0.0f);
      scene.images.push_back(ramp);
      RenderSettings s = pt(4);
      s.mode = mode;
      const double expect = lambert_radiance(c.cosine);
      EXPECT_NEAR(mean_direct(scene, s), expect, 1e-3 * expect)
          << "strength " << c.strength << " invert " << c.invert << " G-PT "
          << (mode == RenderSettings::Mode::GPT);
    }
}

// A Bump fed by another Bump tilts the normal the first one gave, against its height's gradient
// taken in the plane normal to that normal (Cycles' surface gradient against its N). The first
// bump tilts n to n1 = (-0.2, 0, 1) / sqrt(1.04) as above; a second one rising along v (grad
// (0, 0.02, 0), normal to n1) adds -0.2 y: cos = 1 / 1.04; a second one along u (grad (0.02, 0,
// 0)) gains the component 0.02 a / b along z that makes it normal to n1 = (-a, 0, b), so n2 =
// (-a - 0.2, 0, b - 0.04); leaving it out gives (-a - 0.2, 0, b), 0.6% brighter. PT and G-PT.
TEST(Render, ChainedBumpsTiltTheNormalTheFirstGave) {
  const double a = 0.2 / std::sqrt(1.04), b = 1.0 / std::sqrt(1.04);
  const double along_u = (b - 0.04) / std::hypot(a + 0.2, b - 0.04);
  for (const bool second_along_v : {true, false})
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      MaterialDesc m = ramp_bumped();
      m.bumps.push_back(m.bumps[0]);
      if (second_along_v) m.bumps[1].height.texture.image = 1;
      Scene scene = sunlit_plane(uv_quad(), m, 0.0f);
      scene.images = {ramp_image(2, 1), ramp_image(1, 2)};
      RenderSettings s = pt(4);
      s.mode = mode;
      const double expect = lambert_radiance(second_along_v ? 1.0 / 1.04 : along_u);
      EXPECT_NEAR(mean_direct(scene, s), expect, 1e-3 * expect)
          << "second along v " << second_along_v << " G-PT " << (mode == RenderSettings::Mode::GPT);
    }
}

// The bump belongs to the surface: seen from its back (the quad wound the other way), a height
// ramp along v gives the same world-space tilt of the surface's normal, flipped towards the
// viewer, as Cycles 3.4 renders inside-out meshes. With the sun tilted towards -y the two sides'
// cosines differ: normalize(z -+ 0.2 y) against (0, -sin t, cos t). The front side also shows
// Cycles' bump shadowing: g = cos(z, sun) / (cos(n, sun) cos(z, n)) < 1 scales the diffuse value
// by -g^3 + g^2 + g (the back side's g > 1: no change).
TEST(Render, BumpOnABackFaceKeepsTheSurfacesTilt) {
  const ImageDesc ramp = ramp_image(1, 2);
  constexpr float kTheta = 0.5f;
  for (const bool back : {false, true}) {
    Mesh plane = uv_quad();
    if (back) {
      plane.indices = {0, 2, 1, 0, 3, 2};
      plane.corner_uvs = {{0, 0}, {1, 1}, {1, 0}, {0, 0}, {0, 1}, {1, 1}};
    }
    Scene scene = sunlit_plane(plane, ramp_bumped(), kTheta);
    scene.images.push_back(ramp);
    // Height h = v / 100 over the 100 m quad: tilt 0.2 along -y (front) or +y (back, facing).
    const double ny = back ? 0.2 : -0.2;
    const double cosine = (-ny * std::sin(kTheta) + std::cos(kTheta)) / std::sqrt(1.04);
    const double g = std::min(std::cos(kTheta) / (cosine / std::sqrt(1.04)), 1.0);
    const double expect = lambert_radiance(cosine) * (-g * g * g + g * g + g);
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      RenderSettings s = pt(4);
      s.mode = mode;
      EXPECT_NEAR(mean_direct(scene, s), expect, 2e-3 * expect)
          << "back " << back << " G-PT " << (mode == RenderSettings::Mode::GPT);
    }
  }
}

// A height linear in a position-based coordinate (Object y) on the same quad seen from its back:
// Cycles 3.4 steps Object and Position along its tangents on either side (only attributes step
// against them on a back face), so the back tilts the seen normal towards -y as the front does,
// and both sides light as the front side of the test above. h = y / 50 (distance 10: tilt 0.2).
TEST(Render, BumpOfAPositionOnABackFaceTiltsAsOnTheFront) {
  constexpr float kTheta = 0.5f;
  const double cosine = (0.2 * std::sin(kTheta) + std::cos(kTheta)) / std::sqrt(1.04);
  const double g = std::min(std::cos(kTheta) / (cosine / std::sqrt(1.04)), 1.0);
  const double expect = lambert_radiance(cosine) * (-g * g * g + g * g + g);
  for (const bool back : {false, true}) {
    Mesh plane = uv_quad();
    if (back) {
      plane.indices = {0, 2, 1, 0, 3, 2};
      plane.corner_uvs = {{0, 0}, {1, 1}, {1, 0}, {0, 0}, {0, 1}, {1, 1}};
    }
    MaterialDesc m = diffuse(Spectrum(0.5f));
    InputNode coords;
    coords.kind = InputNodeKind::Coordinates;
    coords.vector.source = TexCoordSource::Object;
    InputNode y;
    y.kind = InputNodeKind::Separate;
    y.a.node = 0;
    y.channel = 1;
    InputNode height;
    height.kind = InputNodeKind::Math;
    height.math = MathOp::Multiply;
    height.value_a.node = 1;
    height.value_b = FloatInput(0.02f);
    m.inputs = {coords, y, height};
    m.bumps.emplace_back();
    m.bumps[0].height.node = 2;
    m.bumps[0].distance = 10.0f;
    const Scene scene = sunlit_plane(plane, m, kTheta);
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      RenderSettings s = pt(4);
      s.mode = mode;
      EXPECT_NEAR(mean_direct(scene, s), expect, 2e-3 * expect)
          << "back " << back << " G-PT " << (mode == RenderSettings::Mode::GPT);
    }
  }
}

// The Displacement output as bump (replaces_normal) tilts the surface's own normal, as Cycles'
// set_normal writes sd->N: the front side of the test above without the bump shadowing factor.
TEST(Render, DisplacementAsBumpReplacesTheNormalWithoutBumpShadowing) {
  const ImageDesc ramp = ramp_image(1, 2);
  constexpr float kTheta = 0.5f;
  MaterialDesc m = ramp_bumped();
  m.bumps[0].replaces_normal = true;
  Scene scene = sunlit_plane(uv_quad(), m, kTheta);
  scene.images.push_back(ramp);
  const double cosine = (0.2 * std::sin(kTheta) + std::cos(kTheta)) / std::sqrt(1.04);
  const double expect = lambert_radiance(cosine);
  for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    RenderSettings s = pt(4);
    s.mode = mode;
    EXPECT_NEAR(mean_direct(scene, s), expect, 2e-3 * expect)
        << "G-PT " << (mode == RenderSettings::Mode::GPT);
  }
}

// The object's shadow terminator shading offset darkens a sunlit plane by Cycles' shifted cosine:
// offset 0.5 (k = 4/3) under a sun at t from the normal scales L = 0.5 E cos(t) / pi to
// 0.5 E max(cos(k t), 0) / pi; at t = 1.2 (k t past 90 degrees) the plane goes black. PT and
// G-PT (both take it through shading_closures).
TEST(Render, TerminatorShadingOffsetShiftsTheCosine) {
  for (const float theta : {0.6f, 1.0f, 1.2f})
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      Scene scene = sunlit_plane(quad(50.0f), diffuse(Spectrum(0.5f)), theta);
      scene.instances[0].terminator_shading_offset = 0.5f;
      RenderSettings s = pt(4);
      s.mode = mode;
      const double expect = lambert_radiance(std::max(std::cos(4.0 / 3.0 * theta), 0.0));
      EXPECT_NEAR(mean_direct(scene, s), expect, 1e-3 * expect + 1e-6)
          << "theta " << theta << " G-PT " << (mode == RenderSettings::Mode::GPT);
    }
}

// A vector displacement's height is the displacement's component along the normal (Cycles'
// bump_from_displacement), its vector taken to world space by the node's space. The image ramps
// along v in one channel only, as the scalar test above (tilt 0.2 along -y when it is the height).
// Tangent space is Cycles' x tangent, y normal, z bitangent: the green ramp tilts, blue does not;
// red does only through the tangent's component along the normal (Cycles reads the interpolated
// tangent as it is): with t = (1, 0, 0.5) half the tilt. World space: blue tilts, green does not.
// Object space reads the object's transform: blue under a z scale of 2 tilts twice as much
// (O^T n = 2 z). Seen from its back (the quad wound the other way, n = -z), the height is the
// component along the normal facing the ray (Cycles' sd->N, +z): the surface's own normal tilts
// by it, flipped, so world-space blue tilts the other way (-0.2). PT and G-PT.
TEST(Render, VectorDisplacementTiltsByItsComponentAlongTheNormal) {
  using Space = BumpDesc::VectorSpace;
  constexpr float kTheta = 0.5f;
  struct Case {
    Space space;
    Spectrum channel;
    float tangent_z, scale_z;
    double tilt;
    bool back = false;
  };
  const Spectrum red(1, 0, 0), green(0, 1, 0), blue(0, 0, 1);
  for (const Case& c :
       {Case{Space::Tangent, green, 0.0f, 1.0f, 0.2}, Case{Space::Tangent, blue, 0.0f, 1.0f, 0.0},
        Case{Space::Tangent, red, 0.0f, 1.0f, 0.0}, Case{Space::Tangent, red, 0.5f, 1.0f, 0.1},
        Case{Space::World, blue, 0.0f, 1.0f, 0.2}, Case{Space::World, green, 0.0f, 1.0f, 0.0},
        Case{Space::Object, blue, 0.0f, 2.0f, 0.4},
        Case{Space::World, blue, 0.0f, 1.0f, -0.2, true}}) {
    MaterialDesc m = ramp_bumped();
    m.bumps[0].replaces_normal = true;
    m.bumps[0].vector_space = c.space;
    m.bumps[0].vector.texture = m.bumps[0].height.texture;
    Mesh plane = uv_quad();
    plane.corner_tangents.assign(6, Vec3f(1.0f, 0.0f, c.tangent_z));
    plane.corner_tangent_signs.assign(6, 1.0f);
    if (c.back) {
      plane.indices = {0, 2, 1, 0, 3, 2};
      plane.corner_uvs = {{0, 0}, {1, 1}, {1, 0}, {0, 0}, {0, 1}, {1, 1}};
    }
    Transform placement;
    placement.m[2][2] = c.scale_z;
    Scene scene = sunlit_plane(plane, m, kTheta, placement);
    ImageDesc ramp = ramp_image(1, 2);
    for (int k = 0; k < 3; ++k) ramp.rgba[size_t(4 + k)] = c.channel[k];
    scene.images.push_back(ramp);
    const double cosine =
        (c.tilt * std::sin(kTheta) + std::cos(kTheta)) / std::sqrt(1.0 + c.tilt * c.tilt);
    const double expect = lambert_radiance(cosine);
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      RenderSettings s = pt(4);
      s.mode = mode;
      EXPECT_NEAR(mean_direct(scene, s), expect, 2e-3 * expect)
          << "space " << int(c.space) << " tilt " << c.tilt << " G-PT "
          << (mode == RenderSettings::Mode::GPT);
    }
  }
}

// Lobes whose normal input is not linked to the material's bump keep the interpolated normal
// (Cycles gives an unlinked input sd->N), seen from straight above under a sun from
// (0, -sin t, cos t):
//  - a Diffuse with its Normal unlinked is lit with cos t, without bump shadowing;
//  - a Principled clearcoat alone (black base, no specular) reflects
//    L = E 0.25 F(wo.h, 1.5) D(h.n) G1(wi) G1(wo) / (4 wi.n) about n = +z when its Clearcoat
//    Normal is unlinked and about the bumped normal when it is linked (Cycles 3.4's coat: D the
//    GTR1 of alpha, G1 the GGX masking of alpha 0.25).
// Two set-ups: the ramp of the tests above along u (normal tilted to normalize(-0.2, 0, 1)) with
// t = 0.5, and the ramp along v (normalize(0, -0.2, 1)) with a sun 6 degrees above the horizon
// on the other side (t = -1.45), below the bumped normal's horizon: the unlinked lobes must still
// see it (each lobe decides reflection about its own normal), the linked coat must not. PT, G-PT.
TEST(Render, UnlinkedNormalInputsKeepTheInterpolatedNormal) {
  constexpr double kE = 3.0, kAlpha = 0.09;  // clearcoat roughness 0.3
  struct Setup {
    float theta;
    bool along_u;
    Vec3f bumped;
  };
  for (const Setup& setup : {Setup{0.5f, true, normalize(Vec3f(-0.2f, 0.0f, 1.0f))},
                             Setup{-1.45f, false, normalize(Vec3f(0.0f, -0.2f, 1.0f))}}) {
    const Vec3f sun(0.0f, -std::sin(setup.theta), std::cos(setup.theta)), view(0, 0, 1);
    auto coat = [&](Vec3f n) {
      if (dot(sun, n) <= 0.0f) return 0.0;
      auto g1 = [&](Vec3f w) {
        const double c = dot(w, n), t2 = (1.0 - c * c) / (c * c);
        return 2.0 / (1.0 + std::sqrt(1.0 + 0.0625 * t2));
      };
      const Vec3f h = normalize(sun + view);
      const double ch = dot(h, n), a2 = kAlpha * kAlpha;
      const double d = (a2 - 1.0) / (kPi * std::log(a2) * (1.0 + (a2 - 1.0) * ch * ch));
      const double ci = dot(sun, h), st2 = (1.0 - ci * ci) / 2.25, ct = std::sqrt(1.0 - st2);
      const double rs = (ci - 1.5 * ct) / (ci + 1.5 * ct), rp = (1.5 * ci - ct) / (1.5 * ci + ct);
      const double f = 0.5 * (rs * rs + rp * rp);
      return kE * 0.25 * f * d * g1(view) * g1(sun) / (4.0 * double(dot(view, n)));
    };
    struct Case {
      const char* name;
      MaterialDesc material;
      double expect;
    };
    MaterialDesc unlinked_diffuse = ramp_bumped();
    unlinked_diffuse.nodes[0].normal_linked = false;
    auto coated = [&](bool linked) {
      MaterialDesc m = ramp_bumped();
      ShaderNode& n = m.nodes[0];
      n.kind = ShaderNodeKind::Principled;
      n.color = ColorInput(Spectrum(0.0f));
      n.specular = FloatInput(0.0f);
      n.clearcoat = FloatInput(1.0f);
      n.clearcoat_roughness = FloatInput(0.3f);
      n.clearcoat_normal_linked = linked;
      return m;
    };
    const Case cases[] = {
        {"diffuse, Normal unlinked", unlinked_diffuse, lambert_radiance(std::cos(setup.theta))},
        {"clearcoat, Clearcoat Normal unlinked", coated(false), coat(view)},
        {"clearcoat, Clearcoat Normal linked", coated(true), coat(setup.bumped)},
    };
    EXPECT_GT(std::fabs(coat(view) - coat(setup.bumped)), 0.2 * coat(view));  // they differ
    for (const Case& c : cases)
      for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
        Scene scene = sunlit_plane(uv_quad(), c.material, setup.theta);
        scene.images.push_back(setup.along_u ? ramp_image(2, 1) : ramp_image(1, 2));
        RenderSettings s = pt(4);
        s.mode = mode;
        EXPECT_NEAR(mean_direct(scene, s), c.expect, 2e-3 * c.expect + 1e-6)
            << c.name << " theta " << setup.theta << " G-PT "
            << (mode == RenderSettings::Mode::GPT);
      }
  }
}

// An emitter whose colour is its texture coordinate (a Texture Coordinate output used as a
// colour): Object is the object-space position (through a Mapping that adds 1, so it stays
// positive), Generated the position mapped from the mesh's bounding box (+-1 in x and y, flat
// in z, whose size Blender sets to 1) to [0, 1], both independent of where the instance is;
// Position (plus 1) the world-space position.
// The camera sees world x in [0, 1], y in [-0.5, 0.5] of a quad moved by +0.5 in x.
TEST(Render, TextureCoordinatesAreObjectSpace) {
  for (const TexCoordSource source :
       {TexCoordSource::Object, TexCoordSource::Generated, TexCoordSource::Position}) {
    MaterialDesc m = emission(Spectrum(0.0f), 1.0f);
    InputNode coords;
    coords.kind = InputNodeKind::Coordinates;
    coords.vector.source = source;
    const bool generated = source == TexCoordSource::Generated;
    if (!generated)
      for (int r = 0; r < 3; ++r) coords.vector.mapping.m[r][3] = 1.0f;
    m.inputs = {coords};
    m.nodes[0].color.node = 0;
    Scene scene;
    scene.meshes.push_back(quad(1.0f));
    scene.materials.push_back(m);
    scene.instances.push_back(place(0, 0, translation({0.5f, 0.0f, 0.0f})));
    scene.world.color = Spectrum(0.0f);
    scene.camera = top_camera(8, 1.0f);
    scene.camera.camera_to_world = translation({0.5f, 0.0f, 10.0f});
    const Image img = render(scene, pt(64));
    // Object-space x of pixel column i: (i + 0.5) / 8 - 0.5, world x 0.5 more; y of row j like
    // the object-space x (either orientation: compared through means and spans).
    const double shift = source == TexCoordSource::Position ? 0.5 : 0.0;
    auto expect = [&](double p) { return generated ? (p + 1.0) * 0.5 : p + 1.0; };
    double mean[3] = {0, 0, 0};
    for (int y = 0; y < img.h; ++y)
      for (int x = 0; x < img.w; ++x)
        for (int c = 0; c < 3; ++c) mean[c] += img.emission[size_t(y * img.w + x) * 3 + c];
    for (double& v : mean) v /= img.w * img.h;
    const int src = int(source);
    EXPECT_NEAR(mean[0], expect(shift), 1e-3) << "source " << src;
    EXPECT_NEAR(mean[1], expect(0.0), 1e-3) << "source " << src;
    EXPECT_NEAR(mean[2], generated ? 0.5 : 1.0, 1e-4) << "source " << src;
    // Last column (row) against the first, each averaged over the image.
    const double span = expect(7.0 / 8.0) - expect(0.0);
    double dx = 0.0, dy = 0.0;
    auto at = [&](int x, int y, int c) { return img.emission[size_t(y * img.w + x) * 3 + c]; };
    for (int k = 0; k < 8; ++k) {
      dx += (at(7, k, 0) - at(0, k, 0)) / 8.0;
      dy += (at(k, 7, 1) - at(k, 0, 1)) / 8.0;
    }
    EXPECT_NEAR(std::fabs(dx), span, 2e-3) << "source " << src;
    EXPECT_NEAR(std::fabs(dy), span, 2e-3) << "source " << src;
  }
}

// A bump whose height is linear in a texture coordinate: Object x (also on an instance stretched
// 2x along x, which halves the world-space slope), Generated x (the plane's 100 m bounding box
// maps x to (x + 50) / 100) and the Geometry node's world Position x (a stretch leaves its slope
// alone), with UVs and without (differences along the triangle's edges). The
// height h = k * coordinate tilts the normal to normalize(N - distance grad h) exactly, as in the
// image-ramp test above.
TEST(Render, BumpDifferentiatesObjectSpaceCoordinates) {
  struct Case {
    TexCoordSource source;
    float scale_x, k;
    bool uvs;
    double cosine;
  };
  for (const Case& c :
       {Case{TexCoordSource::Object, 1.0f, 0.02f, true, 1.0 / std::sqrt(1.04)},
        Case{TexCoordSource::Object, 2.0f, 0.02f, true, 1.0 / std::sqrt(1.01)},
        Case{TexCoordSource::Generated, 1.0f, 2.0f, true, 1.0 / std::sqrt(1.04)},
        Case{TexCoordSource::Object, 2.0f, 0.02f, false, 1.0 / std::sqrt(1.01)},
        Case{TexCoordSource::Generated, 1.0f, 2.0f, false, 1.0 / std::sqrt(1.04)},
        Case{TexCoordSource::Position, 1.0f, 0.02f, true, 1.0 / std::sqrt(1.04)},
        Case{TexCoordSource::Position, 2.0f, 0.02f, false, 1.0 / std::sqrt(1.04)}}) {
    Mesh plane = c.uvs ? uv_quad() : quad(50.0f);
    MaterialDesc m = diffuse(Spectrum(0.5f));
    InputNode coords;
    coords.kind = InputNodeKind::Coordinates;
    coords.vector.source = c.source;
    InputNode x;
    x.kind = InputNodeKind::Separate;
    x.a.node = 0;
    InputNode height;
    height.kind = InputNodeKind::Math;
    height.math = MathOp::Multiply;
    height.value_a.node = 1;
    height.value_b = FloatInput(c.k);
    m.inputs = {coords, x, height};
    m.bumps.emplace_back();
    m.bumps[0].height.node = 2;
    m.bumps[0].distance = 10.0f;
    Transform stretch;
    stretch.m[0][0] = c.scale_x;
    const Scene scene = sunlit_plane(plane, m, 0.0f, stretch);
    const double expect = lambert_radiance(c.cosine);
    EXPECT_NEAR(mean_direct(scene, pt(4)), expect, 1e-3 * expect)
        << "source " << int(c.source) << " scale " << c.scale_x << " uvs " << c.uvs;
  }
}

TEST(Render, SoftSunOnLambertPlane) {
  sun_test(0.6f, 0.02f);  // a 1.1-degree disc: cos varies by < 1e-4 over it
}

// Point light of power P at height h: E = P / (4 pi h^2) below it, L = albedo E / pi.
double point_light_radiance(float h) {
  Scene scene;
  scene.meshes.push_back(quad(50.0f));
  scene.materials.push_back(diffuse(Spectrum(0.8f)));
  scene.instances.push_back(place(0, 0));
  scene.world.color = Spectrum(0.0f);
  Light l;
  l.type = Light::Type::Point;
  l.power = 100.0f;
  l.light_to_world = translation({0, 0, h});
  scene.lights.push_back(l);
  scene.camera = top_camera(4, 0.02f * h, 0.5f * h);
  const Image img = render(scene, pt(8));
  double sum = 0.0;
  for (float v : img.primal) sum += v;
  return sum / img.primal.size();
}

TEST(Render, PointLightInverseSquare) {
  const double l1 = point_light_radiance(1.0f), l2 = point_light_radiance(2.0f),
               l4 = point_light_radiance(4.0f);
  const double expect1 = 0.8 * 100.0 / (4.0 * kPi) / kPi;
  EXPECT_NEAR(l1, expect1, 0.01 * expect1);
  EXPECT_NEAR(l1 / l2, 4.0, 0.04);
  EXPECT_NEAR(l1 / l4, 16.0, 0.16);
}

// Point light of power P and radius r at height h over a Lambert plane. Cycles 3.4 (and GDPT,
// docs/lights.md) treats it as a disc of radius r facing the receiver with L = I / (pi r^2),
// I = P / (4 pi), so directly below E = pi L r^2 / (h^2 + r^2) = I / (h^2 + r^2). BSDF rays hit
// the light (LightSampler::intersect), so this checks the NEE / BSDF-hit MIS with a soft light.
TEST(Render, SoftPointLightMisMatchesTheAnalyticIrradiance) {
  Scene scene;
  scene.meshes.push_back(quad(50.0f));
  scene.materials.push_back(diffuse(Spectrum(0.8f)));
  scene.instances.push_back(place(0, 0));
  scene.world.color = Spectrum(0.0f);
  Light l;
  l.type = Light::Type::Point;
  l.power = 100.0f;
  l.radius = 0.6f;
  l.light_to_world = translation({0, 0, 1.0f});
  scene.lights.push_back(l);
  scene.camera = top_camera(4, 0.01f, 0.2f);
  const Image img = render(scene, pt(256));
  double sum = 0.0;
  for (float v : img.primal) sum += v;
  const double expect = 0.8 * 100.0 / (4.0 * kPi) / (1.0 + 0.36) / kPi;
  EXPECT_NEAR(sum / img.primal.size(), expect, 0.01 * expect);
}

// Disk area light of radius R at height h facing a Lambert plane: on the axis E = pi L R^2 /
// (h^2 + R^2). L is read back from the Emission pass by looking at the light, so the test checks
// the path tracer's NEE + BSDF-hit MIS against the lights' own radiance convention. A lone plane
// has no second bounce, so the image is the same with Max Bounces 0, where the BSDF ray is the
// path's last, traced for its distance only (PathTracer::trace); without that ray's MIS share of
// the lamp the image is 16% darker (checked).
TEST(Render, DiskAreaLightMisMatchesTheAnalyticIrradiance) {
  const float R = 0.8f, h = 1.0f;
  Light disk;
  disk.type = Light::Type::Area;
  disk.shape = Light::Shape::Disk;
  disk.size_x = disk.size_y = 2.0f * R;
  disk.power = 50.0f;
  disk.light_to_world = translation({0, 0, h});  // emits along -z
  disk.camera_visible = true;                    // the camera reads the lamp's radiance
  Scene look;
  look.world.color = Spectrum(0.0f);
  look.lights.push_back(disk);
  look.camera = top_camera(2, 0.01f, 0.0f);
  look.camera.camera_to_world = rotation_x(kPi, {0, 0, 0});  // looks up at the disk
  const Image seen = render(look, pt(1));
  const double L = seen.emission[0];
  ASSERT_GT(L, 0.0);

  Scene scene = look;
  scene.meshes.push_back(quad(50.0f));
  scene.materials.push_back(diffuse(Spectrum(0.5f)));
  scene.instances.push_back(place(0, 0));
  scene.camera = top_camera(4, 0.01f, 0.2f);
  const double expect = 0.5 * L * R * R / (h * h + R * R);
  for (int bounces : {8, 0}) {
    RenderSettings s = pt(256);
    s.max_bounces = bounces;
    const Image img = render(scene, s);
    double sum = 0.0;
    for (float v : img.primal) sum += v;
    EXPECT_NEAR(sum / img.primal.size(), expect, 0.01 * expect) << "max bounces " << bounces;
  }
}

// A floor (albedo 0.5) and a sheet 1 above it, under a sun of irradiance 3 straight down.
Scene sheet_over_floor(float sheet_half_size, const MaterialDesc& sheet, float sun_angle = 0.0f) {
  Scene scene;
  scene.meshes.push_back(quad(50.0f));
  scene.meshes.push_back(quad(sheet_half_size));
  scene.materials.push_back(diffuse(Spectrum(0.5f)));
  scene.materials.push_back(sheet);
  scene.instances.push_back(place(0, 0));
  scene.instances.push_back(place(1, 1, translation({0, 0, 1})));
  scene.world.color = Spectrum(0.0f);
  Light sun;
  sun.type = Light::Type::Sun;
  sun.power = 3.0f;
  sun.sun_angle = sun_angle;
  sun.light_to_world = translation({0, 0, 20});
  scene.lights.push_back(sun);
  return scene;
}

// A Transparent BSDF sheet of colour T between a sun and a Lambert floor, viewed from above through
// the sheet: light crosses it twice, L = albedo E cos / pi * T^2 (Cycles' transparent shadows).
// Transparent crossings are not bounces: max_bounces = 0 gives the same image, and with a soft
// sun the BSDF paths through the sheet are MIS-weighted against NEE from the floor.
MaterialDesc transparent(Spectrum color) {
  return test::single_node(ShaderNodeKind::Transparent, color, 0.0f);
}

Scene transparent_sheet_scene(float sun_angle) {
  Scene scene = sheet_over_floor(50.0f, transparent(Spectrum(0.5f, 0.25f, 1.0f)), sun_angle);
  scene.camera = top_camera(4, 1.0f, 5.0f);
  return scene;
}

TEST(Render, TransparentSurfacesPassLightAndAreNotBounces) {
  const Spectrum T(0.5f, 0.25f, 1.0f);
  for (float angle : {0.0f, 0.05f}) {
    const Scene scene = transparent_sheet_scene(angle);
    for (int bounces : {0, 4})
      for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
        // G-PT: the delta sun only (its shadow rays see through the sheet; a soft sun's light
        // through it arrives by BSDF sampling alone). At max_bounces 0 the floor is reached
        // through the sheet only because crossings are no bounces.
        if (mode == RenderSettings::Mode::GPT && angle > 0.0f) continue;
        RenderSettings s = pt(64);
        s.mode = mode;
        s.max_bounces = bounces;
        const Image img = render(scene, s);
        for (int c = 0; c < 3; ++c) {
          double sum = 0.0;
          for (size_t i = size_t(c); i < img.primal.size(); i += 3) sum += img.primal[i];
          const double expect = 0.5 * 3.0 / kPi * T[c] * T[c];
          EXPECT_NEAR(sum / (img.primal.size() / 3), expect, 0.01 * expect)
              << "sun angle " << angle << " max_bounces " << bounces << " channel " << c << " mode "
              << int(mode);
        }
      }
  }
}

// Disk area light seen from the floor through a transparent sheet: the BSDF-hit MIS weight must
// use the light's density from the floor vertex (where NEE ran), not from the sheet.
// A world whose camera rays see their own background (World::camera_view, Blender's Mix of two
// Backgrounds by Light Path's Is Camera Ray): a Lambert floor (albedo 0.5) under the lighting
// sky A is lit by A alone (L = 0.5 A: uniform sky over an unobstructed plane), the camera looking
// up sees the camera view V, and through a Transparent sheet (colour T) it still sees T V, as a
// camera ray crossing a transparent surface stays a camera ray. PT and G-PT (primal + emission:
// G-PT takes paths through the sheet into the primal).
TEST(Render, CameraRaysSeeTheWorldsCameraView) {
  const Spectrum a(0.5f, 0.4f, 0.3f), view(0.1f, 0.2f, 0.45f), tint(0.5f, 0.25f, 1.0f);
  struct Case {
    const char* name;
    bool floor, up, sheet;
    Spectrum expect;
  };
  const Case cases[] = {
      {"floor lit by the lighting world", true, false, false, a * 0.5f},
      {"sky seen by the camera", false, true, false, view * 2.0f},
      {"sky through a transparent sheet", false, true, true, view * 2.0f * tint},
  };
  for (const Case& c : cases)
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      Scene scene;
      scene.world.color = a;
      scene.world.camera_view = Background{view, 2.0f, -1, Transform()};
      scene.meshes.push_back(quad(50.0f));
      scene.materials.push_back(c.sheet ? transparent(tint) : diffuse(Spectrum(0.5f)));
      // The floor at z = 0; the sheet at z = 12, above a camera at z = 10 looking up (+z).
      scene.instances.push_back(place(0, 0, translation({0.0f, 0.0f, c.sheet ? 12.0f : 0.0f})));
      if (!c.floor && !c.sheet) scene.instances.clear();
      scene.camera = top_camera(8, 2.0f);
      if (c.up) scene.camera.camera_to_world = rotation_x(kPi, {0.0f, 0.0f, 10.0f});
      RenderSettings s = pt(16);
      s.mode = mode;
      s.max_bounces = 0;
      const Image img = render(scene, s);
      for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(channel_mean(img, ch, true), c.expect[ch], 2e-3 * (1.0 + c.expect[ch]))
            << c.name << " channel " << ch << " G-PT " << (mode == RenderSettings::Mode::GPT);
      }
    }
}

TEST(Render, AreaLightThroughTransparentSheetMis) {
  const float R = 0.8f, h = 1.0f;
  Light disk;
  disk.type = Light::Type::Area;
  disk.shape = Light::Shape::Disk;
  disk.size_x = disk.size_y = 2.0f * R;
  disk.power = 50.0f;
  disk.light_to_world = translation({0, 0, h});
  disk.camera_visible = true;  // the camera reads the lamp's radiance
  Scene look;
  look.world.color = Spectrum(0.0f);
  look.lights.push_back(disk);
  look.camera = top_camera(2, 0.01f, 0.0f);
  look.camera.camera_to_world = rotation_x(kPi, {0, 0, 0});
  const double L = render(look, pt(1)).emission[0];
  ASSERT_GT(L, 0.0);

  Scene scene = transparent_sheet_scene(0.0f);
  scene.instances[1].object_to_world = translation({0, 0, 0.5f});
  scene.lights = {disk};
  scene.camera = top_camera(4, 0.01f, 0.2f);  // between floor and sheet: sees the floor directly
  const Image img = render(scene, pt(256));
  const Spectrum T(0.5f, 0.25f, 1.0f);
  for (int c = 0; c < 3; ++c) {
    double sum = 0.0;
    for (size_t i = size_t(c); i < img.primal.size(); i += 3) sum += img.primal[i];
    const double expect = 0.5 * L * R * R / (h * h + R * R) * T[c];
    EXPECT_NEAR(sum / (img.primal.size() / 3), expect, 0.01 * expect) << "channel " << c;
  }
}

TEST(Render, EmissionSeenThroughTransparentSurfacesIsCameraVisible) {
  Scene scene = transparent_sheet_scene(0.0f);
  scene.lights.clear();
  scene.materials[0] = emission(Spectrum(1.0f), 2.0f);
  const Image img = render(scene, pt(4));
  for (size_t i = 0; i < img.primal.size(); i += 3) {
    EXPECT_FLOAT_EQ(img.emission[i], 2.0f * 0.5f);
    EXPECT_FLOAT_EQ(img.emission[i + 1], 2.0f * 0.25f);
    EXPECT_EQ(img.primal[i], 0.0f);
  }
}

// Film > Transparent: camera rays that reach the world leave it out (no Emission) and give alpha 0,
// through a Transparent sheet alpha 1 - mean(sheet colour) (Cycles' alpha); surfaces keep alpha 1
// and their light, the world still lighting them. Left half of the view: world (under a sheet in
// the second case), right half: a floor. PT and G-PT (whose offsets cross the sheet with the base).
TEST(Render, TransparentBackgroundLeavesTheWorldOutAndGivesCoverage) {
  for (const bool sheet : {false, true}) {
    Scene scene;
    scene.meshes.push_back(quad(1.0f));
    scene.materials.push_back(diffuse(Spectrum(0.5f)));
    scene.instances.push_back(place(0, 0, translation({1, 0, 0})));  // x in [0, 2]
    if (sheet) {
      scene.materials.push_back(transparent(Spectrum(0.5f, 0.25f, 1.0f)));
      scene.instances.push_back(place(0, 1, translation({-1, 0, 1})));  // x in [-2, 0]
    }
    scene.world.color = Spectrum(0.5f);
    scene.camera = top_camera(4, 2.0f, 5.0f);
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      RenderSettings s = pt(16);
      s.mode = mode;
      const Image opaque = render(scene, s);
      s.transparent_background = true;
      const Image clear = render(scene, s);
      const std::vector<float>&primal = clear.primal, &emission = clear.emission,
            &alpha = clear.alpha;
      const float world_alpha = sheet ? 1.0f - (0.5f + 0.25f + 1.0f) / 3.0f : 0.0f;
      for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
          const size_t i = size_t(y * 4 + x);
          const bool floor = x >= 2;
          EXPECT_NEAR(alpha[i], floor ? 1.0f : world_alpha, 1e-6f) << x << " " << y;
          for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(emission[3 * i + c], 0.0f) << x << " " << y;
            if (floor) {
              EXPECT_EQ(primal[3 * i + c], opaque.primal[3 * i + c]);
            } else if (!sheet) {
              EXPECT_FLOAT_EQ(opaque.emission[3 * i + c], 0.5f);
            } else {  // the world seen through the sheet is left out too
              EXPECT_EQ(primal[3 * i + c], 0.0f) << x << " " << y << " mode " << int(mode);
              // (Opaque: PT counts the world behind the sheet as camera-visible emission, G-PT
              // as primal, reached by its base path.)
              EXPECT_GT(opaque.primal[3 * i + c] + opaque.emission[3 * i + c], 0.0f);
            }
          }
          if (floor) {
            EXPECT_GT(primal[3 * i], 0.0f);
          }
        }
    }
  }
}

// Depth pass: the view-axis distance of sample 0's camera hit (Cycles), 1e10 without one; the
// object's and material's pass indices there (0 without a hit); kept across passes (one sample
// per pass here), PT and G-PT, perspective and orthographic.
TEST(Render, DepthPassIsSampleZerosViewAxisDistance) {
  Scene scene;
  scene.meshes.push_back(quad(1.0f));
  scene.materials.push_back(diffuse(Spectrum(0.5f)));
  scene.materials[0].pass_index = 5.0f;
  scene.instances.push_back(place(0, 0, translation({1, 0, 0})));  // right half of the view
  scene.instances[0].pass_index = 3.0f;
  scene.world.color = Spectrum(0.5f);
  for (const bool ortho : {true, false}) {
    scene.camera = top_camera(4, 2.0f, 7.0f);
    if (!ortho) scene.camera.projection = Camera::Projection::Perspective;
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      RenderSettings s = pt(3);
      s.mode = mode;
      s.samples_per_pass = 1;
      const Image img = render(scene, s);
      const std::vector<float>&depth = img.depth, &object = img.object_index,
            &material = img.material_index;
      int floor = 0;
      for (size_t i = 0; i < 16; ++i) {
        const bool hit = depth[i] < 1e9f;
        floor += hit;
        if (hit) {
          EXPECT_NEAR(depth[i], 7.0f, 1e-5f) << i;
        } else {
          EXPECT_EQ(depth[i], 1e10f) << i;
        }
        EXPECT_EQ(object[i], hit ? 3.0f : 0.0f) << i;
        EXPECT_EQ(material[i], hit ? 5.0f : 0.0f) << i;
      }
      EXPECT_GE(floor, ortho ? 8 : 2) << ortho;  // ortho: exactly the right half
      EXPECT_LT(floor, 16) << ortho;
    }
  }
}

// Normal and Mist passes (integrators/common/data_passes.h, Cycles' definitions), PT and G-PT: a
// quad 7 below an orthographic camera covering the right half of the view. Normal: the shading
// normal turned towards the camera, (0, 0, 1), also for the quad seen from its back; 0 for the sky.
// Mist: 1 - (1 - clamp((7 - start) / depth) ^ falloff), 1 for the sky. Off: the film has none.
TEST(Render, NormalAndMistPassesAsCycles) {
  for (const bool back : {false, true}) {
    Scene scene;
    Mesh m = quad(1.0f);
    if (back) m.indices = {0, 2, 1, 0, 3, 2};  // winding reversed: the camera sees the back
    scene.meshes.push_back(m);
    scene.materials.push_back(diffuse(Spectrum(0.5f)));
    scene.instances.push_back(place(0, 0, translation({1, 0, 0})));
    scene.world.color = Spectrum(0.5f);
    scene.camera = top_camera(4, 2.0f, 7.0f);
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT})
      for (const float falloff : {1.0f, 2.0f, 0.5f, 3.0f}) {
        RenderSettings s = pt(4);
        s.mode = mode;
        s.normal_pass = s.mist_pass = true;
        s.mist_start = 2.0f;
        s.mist_depth = 10.0f;
        s.mist_falloff = falloff;
        const Image img = render(scene, s);
        const std::vector<float>&normal = img.normal, &mist = img.mist;
        const float expected = 1.0f - (1.0f - std::pow(0.5f, falloff));
        for (int y = 0; y < 4; ++y)
          for (int x = 0; x < 4; ++x) {
            const size_t i = size_t(y) * 4 + size_t(x);
            const bool hit = x >= 2;  // ortho: the right half exactly
            EXPECT_EQ(normal[3 * i], 0.0f) << i;
            EXPECT_EQ(normal[3 * i + 1], 0.0f) << i;
            EXPECT_FLOAT_EQ(normal[3 * i + 2], hit ? 1.0f : 0.0f) << i << " back " << back;
            EXPECT_NEAR(mist[i], hit ? expected : 1.0f, 1e-6f) << i << " falloff " << falloff;
          }
      }
  }
  // A perspective camera measures mist from its position: farther off-axis, more mist.
  Scene scene;
  scene.meshes.push_back(quad(10.0f));
  scene.materials.push_back(diffuse(Spectrum(0.5f)));
  scene.instances.push_back(place(0, 0));
  scene.camera = top_camera(8, 2.0f, 7.0f);
  scene.camera.projection = Camera::Projection::Perspective;
  RenderSettings s = pt(16);
  s.mist_pass = true;
  s.mist_start = 0.0f;
  s.mist_depth = 14.0f;
  s.mist_falloff = 1.0f;
  const Image persp = render(scene, s);
  EXPECT_TRUE(persp.normal.empty());  // not requested: not stored
  const std::vector<float>& mist = persp.mist;
  const float centre = mist[3 * 8 + 3], corner = mist[0];
  EXPECT_GT(centre, 0.5f);  // 7 / 14 on the axis, a little more off it
  EXPECT_LT(centre, 0.52f);
  EXPECT_GT(corner, centre + 0.01f);
  // Through a Transparent sheet of colour 0.7 (coverage 0.3 < 0.5) 1 above the floor, PT and
  // G-PT: the normal is the floor's; mist (start 2, depth 10, linear) adds the sheet's (1 - 0.4)
  // x 0.3 and the floor's (1 - 0.5) x 0.7: the pass reads 1 - 0.53.
  for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    Scene sheet = sheet_over_floor(50.0f, transparent(Spectrum(0.7f)));
    sheet.camera = top_camera(4, 2.0f, 7.0f);
    RenderSettings st = pt(4);
    st.mode = mode;
    st.normal_pass = st.mist_pass = true;
    st.mist_start = 2.0f;
    st.mist_depth = 10.0f;
    st.mist_falloff = 1.0f;
    const Image through = render(sheet, st);
    const std::vector<float>&n = through.normal, &m = through.mist;
    for (size_t i = 0; i < 16; ++i) {
      EXPECT_FLOAT_EQ(n[3 * i + 2], 1.0f) << i << " mode " << int(mode);
      EXPECT_NEAR(m[i], 0.47f, 1e-5f) << i << " mode " << int(mode);
    }
  }
  // No data passes requested: none stored.
  RenderSession plain(scene, pt(1));
  EXPECT_FALSE(plain.film().has_normal());
  EXPECT_FALSE(plain.film().has_mist());
}

// Feature passes (integrators/common/feature_passes.h), PT and G-PT.
struct FeatureImage {
  std::vector<float> primal, a, b, albedo, normal, depth;
  std::vector<float> var_a, var_b, var_albedo, var_normal, var_depth;
};

FeatureImage render_features(const Scene& scene, RenderSettings s) {
  s.feature_passes = true;
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  const Film& film = session.film();
  EXPECT_TRUE(film.has_features());
  using P = Film::FeaturePass;
  auto get = [&](P p, bool variance) {
    std::vector<float> v(film.pixel_count() * size_t(Film::feature_channels(p)));
    variance ? film.feature_variance(p, v.data()) : film.feature(p, v.data());
    return v;
  };
  FeatureImage f;
  f.primal.resize(film.pixel_count() * 3);
  film.primal_rgb(f.primal.data());
  f.a = get(P::PrimalA, false);
  f.b = get(P::PrimalB, false);
  f.albedo = get(P::Albedo, false);
  f.normal = get(P::Normal, false);
  f.depth = get(P::Depth, false);
  f.var_a = get(P::PrimalA, true);
  f.var_b = get(P::PrimalB, true);
  f.var_albedo = get(P::Albedo, true);
  f.var_normal = get(P::Normal, true);
  f.var_depth = get(P::Depth, true);
  return f;
}

// A diffuse plane of colour (0.3, 0.5, 0.7) tilted by 0.4 rad about x under an orthographic top
// camera: every sample's albedo is the colour and its normal the plane's (0, -sin 0.4, cos 0.4),
// so the means are those and the variances 0; the depth is the camera ray's length to the plane,
// 7 at the plane's centre line, varying over the pixels across the tilt.
TEST(Render, FeaturePassesOfADiffusePlane) {
  Scene scene;
  scene.meshes.push_back(quad(10.0f));
  scene.materials.push_back(diffuse(Spectrum(0.3f, 0.5f, 0.7f)));
  scene.instances.push_back(place(0, 0, rotation_x(0.4f)));
  scene.world.color = Spectrum(1.0f);
  scene.camera = top_camera(8, 2.0f, 7.0f);
  for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    RenderSettings s = pt(6);
    s.mode = mode;
    const FeatureImage f = render_features(scene, s);
    for (size_t i = 0; i < 64; ++i) {
      for (int c = 0; c < 3; ++c) {
        EXPECT_FLOAT_EQ(f.albedo[3 * i + c], 0.3f + 0.2f * float(c)) << i << " mode " << int(mode);
        EXPECT_NEAR(f.var_albedo[3 * i + c], 0.0f, 1e-12f) << i;
        EXPECT_NEAR(f.var_normal[3 * i + c], 0.0f, 1e-12f) << i;
      }
      EXPECT_NEAR(f.normal[3 * i], 0.0f, 1e-6f) << i;
      EXPECT_NEAR(f.normal[3 * i + 1], -std::sin(0.4f), 1e-5f) << i;
      EXPECT_NEAR(f.normal[3 * i + 2], std::cos(0.4f), 1e-5f) << i;
      // y in [-1, 1] over the view: the plane's height there is y tan 0.4.
      EXPECT_GT(f.depth[i], 7.0f - 0.43f) << i;
      EXPECT_LT(f.depth[i], 7.0f + 0.43f) << i;
      EXPECT_GT(f.var_depth[i], 0.0f) << i;  // jittered samples see different heights
    }
    EXPECT_LT(f.depth[8 * 7], f.depth[0]);  // top row (y = +1) is higher up: closer
  }
}

// A mirror (Glossy, roughness 0, colour m) tilted 45 degrees under an orthographic top camera
// sends every camera ray sideways onto a diffuse wall out of the view: the albedo is m x the
// wall's colour (Cycles multiplies the specular weights crossed), the normal the wall's turned
// towards the ray (0, 1, 0), the depth the path's length to the wall (its second segment weighted
// by m). A rough glossy (alpha 0.25 > 0.075) in its place is the feature hit itself: its colour,
// normal and distance.
TEST(Render, FeaturePassesThroughAMirror) {
  const Spectrum wall(0.25f, 0.5f, 0.75f);
  for (const float m : {1.0f, 0.8f})
    for (const float roughness : {0.0f, 0.5f}) {
      Scene scene;
      scene.meshes.push_back(quad(1.5f));
      scene.meshes.push_back(quad(10.0f));
      scene.materials.push_back(glossy(Spectrum(m), roughness));
      scene.materials.push_back(diffuse(wall));
      scene.instances.push_back(place(0, 0, rotation_x(kPi / 4.0f)));
      scene.instances.push_back(place(1, 1, rotation_x(kPi / 2.0f, {0, -3, 0})));
      scene.world.color = Spectrum(1.0f);
      scene.camera = top_camera(4, 2.0f, 7.0f);
      for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
        RenderSettings s = pt(4);
        s.mode = mode;
        const FeatureImage f = render_features(scene, s);
        const bool mirror = roughness == 0.0f;
        const Vec3f n = mirror ? Vec3f(0, 1, 0) : Vec3f(0, -std::sqrt(0.5f), std::sqrt(0.5f));
        for (size_t i = 0; i < 16; ++i) {
          for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(f.albedo[3 * i + c], mirror ? m * wall[c] : m, 1e-6f)
                << i << " m " << m << " rough " << roughness << " mode " << int(mode);
            EXPECT_NEAR(f.normal[3 * i + c], n[c], 1e-5f) << i << " rough " << roughness;
          }
          // Down 7 - y to the mirror (z = y), then y + 3 to the wall weighted by m: 10 for m = 1.
          // The rough glossy: its own distance.
          const float lo = !mirror ? 5.9f : m == 1.0f ? 10.0f - 1e-4f : 9.2f - 1e-4f;
          const float hi = !mirror ? 8.1f : m == 1.0f ? 10.0f + 1e-4f : 9.6f + 1e-4f;
          EXPECT_GE(f.depth[i], lo) << i << " m " << m << " rough " << roughness;
          EXPECT_LE(f.depth[i], hi) << i << " m " << m << " rough " << roughness;
        }
      }
    }
}

// A Principled plane (base (0.3, 0.5, 0.7), specular 0.5, roughness 0.5) seen head-on: every
// lobe is rough, and the albedo is the base colour plus the specular lobe's weight times its
// Fresnel colour at normal incidence, F0 = 0.08 x 0.5 = 0.04 (Cycles scales it so: the weight
// alone is 1 and would give base + 1).
TEST(Render, FeatureAlbedoOfPrincipledCountsTheSpecularFresnel) {
  Scene scene;
  scene.meshes.push_back(quad(10.0f));
  MaterialDesc m = test::single_node(ShaderNodeKind::Principled, Spectrum(0.3f, 0.5f, 0.7f), 0.5f);
  m.nodes[0].specular = FloatInput(0.5f);
  scene.materials.push_back(m);
  scene.instances.push_back(place(0, 0));
  scene.world.color = Spectrum(1.0f);
  scene.camera = top_camera(4, 2.0f, 7.0f);
  for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    RenderSettings s = pt(2);
    s.mode = mode;
    const FeatureImage f = render_features(scene, s);
    for (size_t i = 0; i < 16; ++i)
      for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(f.albedo[3 * i + c], 0.3f + 0.2f * float(c) + 0.04f, 1e-4f)
            << i << " mode " << int(mode);
  }
}

// The halves: A the even sample indices, B the odd ones, each the mean of its half, so that with
// an even count their average is the primal exactly (up to float rounding); each half's variance
// of its mean positive, and a film without the passes holds none. PT and G-PT draw half A from
// the first half of the sample sequence and B from the second (core/sample_halves.h), so the
// image of all samples is the render without the passes, bit for bit. The halves are then
// anti-correlated only by what the whole sequence stratifies better than its halves:
// E[(A - B)^2] over Var A + Var B (measured across seeds) is 1.09 (PT) and 0.97 (G-PT) here;
// halves split by the parity of one sequence gave about 1.5.
// A diffuse ball on a diffuse plane under a white sky, seen from above (32 x 32).
Scene ball_under_sky() {
  Scene scene;
  scene.meshes.push_back(quad(10.0f));
  scene.meshes.push_back(sphere(0.5f, 12, 8, {0, 0, 0.5f}));
  scene.materials.push_back(diffuse(Spectrum(0.6f)));
  scene.instances.push_back(place(0, 0));
  scene.instances.push_back(place(1, 0));
  scene.world.color = Spectrum(1.0f);
  scene.camera = top_camera(32, 2.5f, 7.0f);
  return scene;
}

TEST(Render, FeaturePassesPrimalHalves) {
  const Scene scene = ball_under_sky();
  for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    RenderSettings s = pt(64);
    s.mode = mode;
    s.samples_per_pass = 24;  // halves by the global sample index, across passes
    const FeatureImage f = render_features(scene, s);
    RenderSettings plain = s;
    plain.feature_passes = false;
    const Image without = render(scene, plain);
    ASSERT_EQ(without.primal.size(), f.primal.size());
    double differ = 0.0;
    for (size_t k = 0; k < f.primal.size(); ++k) {
      ASSERT_EQ(f.primal[k], without.primal[k]) << k << " mode " << int(mode);
      EXPECT_NEAR(0.5f * (f.a[k] + f.b[k]), f.primal[k], 1e-6f * (1.0f + f.primal[k])) << k;
      EXPECT_GE(f.var_a[k], 0.0f) << k;
      differ += std::fabs(f.a[k] - f.b[k]);
    }
    EXPECT_GT(differ / double(f.primal.size()), 1e-3) << "halves identical, mode " << int(mode);
    {
      // Var A + Var B from a render with another seed (independent of this one by construction).
      RenderSettings other = s;
      other.seed = s.seed + 1;
      const FeatureImage g = render_features(scene, other);
      double same = 0.0, across = 0.0;
      for (size_t k = 0; k < f.primal.size(); ++k) {
        same += double(f.a[k] - f.b[k]) * (f.a[k] - f.b[k]);
        across += 0.5 * (double(f.a[k] - g.a[k]) * (f.a[k] - g.a[k]) +
                         double(f.b[k] - g.b[k]) * (f.b[k] - g.b[k]));
      }
      std::printf("mode %d halves: (A - B)^2 over Var A + Var B from two seeds: %.3f\n", int(mode),
                  same / across);
      EXPECT_GT(same / across, 0.8);
      EXPECT_LT(same / across, 1.25);
    }
    double var = 0.0;
    for (float v : f.var_a) var += v;
    EXPECT_GT(var, 0.0);
  }
  RenderSession off(scene, pt(1));
  EXPECT_FALSE(off.film().has_features());
}

// A time-limited render cannot split its halves at a frame total it does not know: it splits them
// where its first sample's time predicts, far below a sample count it cannot reach.
TEST(Render, TimeLimitedHalvesSplitAtThePredictedCount) {
  const Scene scene = ball_under_sky();
  RenderSettings s = pt(1 << 20);
  s.mode = RenderSettings::Mode::GPT;
  s.feature_passes = true;
  s.time_limit = 0.3;
  s.samples_per_pass = 1;
  RenderSession session(scene, s);
  EXPECT_EQ(session.film().half_split(), 1u << 19);
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  const uint32_t split = session.film().half_split(), done = session.film().min_samples();
  std::printf("%u samples in 0.3 s, halves split at %u pairs\n", done, split);
  EXPECT_GE(split, 1u);
  EXPECT_LT(split, 1u << 19);
  EXPECT_GT(done, 1u);
}

// G-PT's gradients over the primal's halves (Film::gradient_x_half_rgb / gradient_y_half_rgb).
struct HalfGradients {
  std::vector<float> x, y, xa, xb, ya, yb;
};

HalfGradients render_half_gradients(const Scene& scene, RenderSettings s) {
  s.mode = RenderSettings::Mode::GPT;
  s.feature_passes = true;
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  const Film& film = session.film();
  EXPECT_TRUE(film.has_half_gradients());
  HalfGradients g;
  for (auto* v : {&g.x, &g.y, &g.xa, &g.xb, &g.ya, &g.yb}) v->resize(film.pixel_count() * 3);
  film.gradient_x_rgb(g.x.data());
  film.gradient_y_rgb(g.y.data());
  using H = Film::SampleHalf;
  film.gradient_x_half_rgb(H::A, g.xa.data());
  film.gradient_x_half_rgb(H::B, g.xb.data());
  film.gradient_y_half_rgb(H::A, g.ya.data());
  film.gradient_y_half_rgb(H::B, g.yb.data());
  return g;
}

// Two renders' halves agree where they hold the same samples (same values: sample values depend
// only on seed, pixel and global index).
void expect_same_half(const std::vector<float>& a, const std::vector<float>& b,
                      const std::string& what) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k)
    ASSERT_NEAR(a[k], b[k], 1e-5f * (1.0f + std::fabs(b[k]))) << what << " " << k;
}

// The halves of G-PT's gradients: over 5 samples (A = indices 0, 2, 4; B = 1, 3), split across
// passes, their count-weighted mean (3 A + 2 B) / 5 is Gradient X / Y to float rounding, and
// they differ (independent noise). The parity is the global sample index's, as Primal A's: a
// render of samples 1..3 has B = {1, 3}, the B of a render of samples 0..3, and A = {2}, the A
// of a render of sample 2 alone. A PT film, or one without the feature passes, keeps none.
TEST(Render, FeaturePassesGradientHalves) {
  Scene scene;
  scene.meshes.push_back(quad(10.0f));
  scene.meshes.push_back(sphere(0.5f, 12, 8, {0, 0, 0.5f}));
  scene.materials.push_back(diffuse(Spectrum(0.6f)));
  scene.instances.push_back(place(0, 0));
  scene.instances.push_back(place(1, 0));
  scene.world.color = Spectrum(1.0f);
  scene.camera = top_camera(8, 2.5f, 7.0f);
  RenderSettings s = pt(5);
  s.samples_per_pass = 2;
  const HalfGradients g = render_half_gradients(scene, s);
  double differ = 0.0, magnitude = 0.0;
  for (size_t k = 0; k < g.x.size(); ++k) {
    EXPECT_NEAR((3.0f * g.xa[k] + 2.0f * g.xb[k]) / 5.0f, g.x[k],
                1e-6f * (1.0f + std::fabs(g.x[k])))
        << k;
    EXPECT_NEAR((3.0f * g.ya[k] + 2.0f * g.yb[k]) / 5.0f, g.y[k],
                1e-6f * (1.0f + std::fabs(g.y[k])))
        << k;
    differ += std::fabs(g.xa[k] - g.xb[k]) + std::fabs(g.ya[k] - g.yb[k]);
    magnitude += std::fabs(g.x[k]) + std::fabs(g.y[k]);
  }
  EXPECT_GT(magnitude / double(g.x.size()), 1e-3) << "no gradients";
  EXPECT_GT(differ / double(g.x.size()), 1e-3) << "halves identical";

  RenderSettings from1 = pt(3), all4 = pt(4), only2 = pt(1);
  from1.sample_offset = 1;
  only2.sample_offset = 2;
  const HalfGradients g1 = render_half_gradients(scene, from1);
  const HalfGradients g4 = render_half_gradients(scene, all4);
  const HalfGradients g2 = render_half_gradients(scene, only2);
  expect_same_half(g1.xb, g4.xb, "B of samples 1..3 against 0..3, x");
  expect_same_half(g1.yb, g4.yb, "B of samples 1..3 against 0..3, y");
  expect_same_half(g1.xa, g2.xa, "A of samples 1..3 against 2, x");
  expect_same_half(g1.ya, g2.ya, "A of samples 1..3 against 2, y");

  RenderSettings pt_features = pt(2);
  pt_features.feature_passes = true;
  RenderSession pt_session(scene, pt_features);
  EXPECT_FALSE(pt_session.film().has_half_gradients());
  RenderSettings gpt_plain = pt(2);
  gpt_plain.mode = RenderSettings::Mode::GPT;
  RenderSession plain_session(scene, gpt_plain);
  EXPECT_FALSE(plain_session.film().has_half_gradients());
}

// Renders a sheet_over_floor scene under an 8 x 8 top view with direct light only and checks
// its primal: `inside` on the sheet's square (pixels 2..5), `outside` around it.
void expect_square(const Scene& scene, RenderSettings::Mode mode, float inside, float outside,
                   const std::string& what) {
  RenderSettings s = pt(4);
  s.mode = mode;
  s.max_bounces = 0;
  const Image img = render(scene, s);
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x) {
      const bool in = x >= 2 && x < 6 && y >= 2 && y < 6;
      EXPECT_NEAR(img.at(x, y), in ? inside : outside, 1e-4f)
          << what << ", pixel " << x << "," << y << ", mode " << int(mode);
    }
}

// Object > Visibility > Ray Visibility (Instance::visibility, RayKind): a 1 x 1 blocker 1 above
// a floor, under a sun straight down, direct light only (albedo 0.8 / 0.5: radiance 0.8 E / pi on
// the blocker, 0.5 E / pi on the lit floor). Seen from above through the blocker's square:
// the blocker (all visible); the floor in its shadow (hidden from the camera); the lit floor
// (hidden from camera and shadow rays). Outside the square the floor is lit in every case.
TEST(Render, RayVisibilityHidesInstancesFromRayKinds) {
  Scene scene = sheet_over_floor(0.5f, diffuse(Spectrum(0.8f)));
  scene.camera = top_camera(8, 2.0f);  // pixels 2..5 lie inside the blocker's square
  const float lit_floor = 0.5f * 3.0f / float(kPi), lit_blocker = 0.8f * 3.0f / float(kPi);
  struct Case {
    uint32_t visibility;
    float inside;
  };
  const uint32_t secondary = kRayDiffuse | kRayGlossy | kRayTransmission;
  for (const Case c : {Case{kRayAll, lit_blocker}, Case{kRayAll & ~kRayCamera, 0.0f},
                       Case{secondary, lit_floor}, Case{kRayCamera | secondary, lit_blocker}})
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      scene.instances[1].visibility = c.visibility;
      expect_square(scene, mode, c.inside, lit_floor, "visibility " + std::to_string(c.visibility));
    }
}

// Each per-kind flag alone: a surface under a white world (radiance 1) is seen from above through
// a black 100 x 100 lid that the camera never sees; the lid is visible to one kind of ray (and
// to shadow rays, so the world's light samples are blocked too) or hidden from it. Diffuse floor
// of albedo 0.5: 0.5 under the world, 0 under the lid. Mirror (Glossy, roughness 0, colour 0.7):
// 0.7 or 0. Glass sheet (IOR 1.5, normal incidence, the lid below it): Fresnel R = 0.04 goes up
// to the world in both cases, 1 - R down through the sheet to the world or the lid.
TEST(Render, RayVisibilityEachKindAlone) {
  struct Case {
    const char* name;
    MaterialDesc surface;
    uint32_t kind;
    float lid_z, under_world, under_lid, tolerance;
  };
  const float r = 0.04f;
  const Case cases[] = {
      {"diffuse", diffuse(Spectrum(0.5f)), kRayDiffuse, 2.0f, 0.5f, 0.0f, 0.01f},
      {"glossy", glossy(Spectrum(0.7f), 0.0f), kRayGlossy, 2.0f, 0.7f, 0.0f, 1e-4f},
      {"transmission", test::single_node(ShaderNodeKind::Glass, Spectrum(1.0f), 0.0f, 1.5f),
       kRayTransmission, -2.0f, 1.0f, r, 0.01f}};
  const uint32_t kinds = kRayDiffuse | kRayGlossy | kRayTransmission;
  for (const Case& c : cases)
    for (const bool visible : {true, false})
      for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
        Scene scene;
        scene.meshes.push_back(quad(50.0f));
        scene.materials.push_back(c.surface);
        scene.materials.push_back(diffuse(Spectrum(0.0f)));
        scene.instances.push_back(place(0, 0));
        scene.instances.push_back(place(0, 1, translation({0, 0, c.lid_z})));
        // Visible: to this kind and to shadow rays only. Hidden: to the other two kinds only.
        scene.instances[1].visibility = visible ? (c.kind | kRayShadow) : (kinds & ~c.kind);
        scene.world.color = Spectrum(1.0f);
        scene.world.strength = 1.0f;
        scene.camera = top_camera(8, 2.0f, 5.0f);
        RenderSettings s = pt(256);
        s.mode = mode;
        const Image img = render(scene, s);
        double mean = 0.0;
        for (int y = 0; y < 8; ++y)
          for (int x = 0; x < 8; ++x) mean += img.at(x, y) / 64.0;
        const float expect = visible ? c.under_lid : c.under_world;
        EXPECT_NEAR(mean, expect, c.tolerance)
            << c.name << (visible ? " visible" : " hidden") << ", mode " << int(mode);
      }
}

// Light::cast_shadow off (Cycles' Cast Shadow): the sun's light samples skip the shadow ray, so
// the floor under the sheet (hidden from the camera, direct light only) is lit as the floor
// around it; on, it is in shadow. PT and G-PT.
TEST(Render, LampWithoutCastShadowIsUnoccluded) {
  Scene scene = sheet_over_floor(0.5f, diffuse(Spectrum(0.8f)));
  scene.instances[1].visibility = kRayAll & ~kRayCamera;
  scene.camera = top_camera(8, 2.0f);
  const float lit_floor = 0.5f * 3.0f / float(kPi);
  for (const bool cast : {true, false})
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      scene.lights[0].cast_shadow = cast;
      expect_square(scene, mode, cast ? 0.0f : lit_floor, lit_floor,
                    std::string("cast shadow ") + (cast ? "on" : "off"));
    }
}

// Holdout (Instance::holdout): the 1 x 1 sheet of the test above, seen from above, is black,
// with coverage 0 under Film > Transparent (1 without), and still casts its shadow; the floor
// around it is lit. G-PT's gradients across the holdout's edge are the primal's steps.
TEST(Render, HoldoutIsBlackAndUncovered) {
  Scene scene = sheet_over_floor(0.5f, diffuse(Spectrum(0.8f)));
  scene.instances[1].holdout = true;
  scene.camera = top_camera(8, 2.0f);
  // Combined (primal + emission) `outside` the square and 0 inside, alpha `covered` inside under
  // Film > Transparent (else 1), G-PT's x gradients the steps of its primal; PT and G-PT.
  auto check = [&](int max_bounces, float outside, float covered, const char* what) {
    for (const bool transparent : {false, true})
      for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
        RenderSettings s = pt(4);
        s.mode = mode;
        s.max_bounces = max_bounces;
        s.transparent_background = transparent;
        const Image img = render(scene, s);
        for (int y = 0; y < 8; ++y)
          for (int x = 0; x < 8; ++x) {
            const size_t i = size_t(y) * 8 + size_t(x);
            const bool inside = x >= 2 && x < 6 && y >= 2 && y < 6;
            EXPECT_NEAR(img.primal[3 * i] + img.emission[3 * i], inside ? 0.0f : outside, 1e-4f)
                << what << " " << x << "," << y << " mode " << int(mode) << " transparent "
                << transparent;
            EXPECT_NEAR(img.alpha[i], inside && transparent ? covered : 1.0f, 1e-6f)
                << what << " " << x << "," << y;
            if (x < 7) {  // dx(x) = I(x + 1) - I(x)
              EXPECT_NEAR(img.gradient_x[3 * i], img.primal[3 * (i + 1)] - img.primal[3 * i], 1e-4f)
                  << what << " " << x << "," << y << " mode " << int(mode);
            }
          }
      }
  };
  check(0, 0.5f * 3.0f / float(kPi), 0.0f, "direct");
  // Seen through a Transparent sheet (colour 0.5, over everything at height 2): the holdout is
  // still black, its coverage the sheet's 0.5; around it the emitting floor (radiance 1) shows
  // at 0.5 (PT files it as camera-visible emission, G-PT as primal; max_bounces 1: G-PT counts
  // the crossing as a bounce).
  scene.lights.clear();
  scene.materials[0] = emission(Spectrum(1.0f), 1.0f);
  scene.materials[1] = diffuse(Spectrum(0.0f));
  scene.meshes.push_back(quad(50.0f));
  scene.materials.push_back(transparent(Spectrum(0.5f)));
  scene.instances.push_back(place(2, 2, translation({0, 0, 2})));
  check(1, 0.5f, 0.5f, "behind the sheet");
}

// Per-kind bounce limits (bounce_limits.h, Cycles' Diffuse / Glossy / Transmission bounces):
// in a scene whose surfaces are all of one kind, a limit of n on that kind ends the paths exactly
// where a total limit of n does (bit-identical images, PT and G-PT), a limit on another kind
// changes nothing, and a lower limit darkens the image (fewer bounces of light).
TEST(Render, PerKindBounceLimitsEndPathsAsTheTotalLimitDoes) {
  for (const bool glossy_scene : {false, true}) {
    Scene scene = sheet_over_floor(
        0.5f, glossy_scene ? glossy(Spectrum(0.9f), 0.4f) : diffuse(Spectrum(0.8f)));
    scene.materials[0] = glossy_scene ? glossy(Spectrum(0.7f), 0.3f) : diffuse(Spectrum(0.5f));
    scene.world.color = Spectrum(0.3f);
    scene.lights.clear();  // the world alone: light between the sheet and the floor bounces
    scene.camera = top_camera(8, 2.0f);
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      RenderSettings s = pt(8);
      s.mode = mode;
      s.rr_depth = 100;  // no roulette: the limits alone end the paths
      auto mean = [](const Image& img) {
        double sum = 0.0;
        for (float v : img.primal) sum += v;
        return sum / double(img.primal.size());
      };
      RenderSettings total = s;
      total.max_bounces = 1;
      RenderSettings by_kind = s;
      (glossy_scene ? by_kind.max_glossy_bounces : by_kind.max_diffuse_bounces) = 1;
      RenderSettings other = s;
      (glossy_scene ? other.max_diffuse_bounces : other.max_glossy_bounces) = 0;
      other.max_transmission_bounces = 0;
      const Image a = render(scene, total), b = render(scene, by_kind), c = render(scene, other),
                  full = render(scene, s);
      EXPECT_EQ(a.primal, b.primal) << "glossy " << glossy_scene << " mode " << int(mode);
      EXPECT_EQ(c.primal, full.primal) << "glossy " << glossy_scene << " mode " << int(mode);
      EXPECT_LT(mean(b), 0.995 * mean(full)) << "glossy " << glossy_scene;
    }
  }
  RenderSettings bad = pt(1);
  bad.max_glossy_bounces = -1;
  EXPECT_THROW(RenderSession(sheet_over_floor(0.5f, diffuse(Spectrum(0.5f))), bad),
               std::invalid_argument);
}

// --- Light-path semantics ---

TEST(Render, CameraVisibleEmissionGoesToTheEmissionPass) {
  Scene scene;
  scene.meshes.push_back(quad(10.0f));
  scene.materials.push_back(emission(Spectrum(1.0f, 0.5f, 0.25f), 2.0f));
  scene.instances.push_back(place(0, 0));
  scene.world.color = Spectrum(0.0f);
  scene.camera = top_camera(4, 1.0f);
  const Image img = render(scene, pt(4));
  for (size_t i = 0; i < img.primal.size(); i += 3) {
    EXPECT_FLOAT_EQ(img.emission[i], 2.0f);
    EXPECT_FLOAT_EQ(img.emission[i + 1], 1.0f);
    EXPECT_FLOAT_EQ(img.emission[i + 2], 0.5f);
    EXPECT_EQ(img.primal[i], 0.0f);
  }
}

// An area light seen directly by the camera: its radiance in the Emission pass (camera-visible, as
// Cycles 3.x), nothing in primal. Cycles 3.4's area radiance is P / (4 A) (docs/lights.md).
// Camera rays see a lamp only when its object is visible to the camera (Blender's
// Object.visible_camera, off by default in 3.4: verified with Cycles 3.4.1, where an area lamp of
// 100 W and 2 m x 2 m renders 6.25 = P / (4 A) with the flag and black without). PT and G-PT alike.
TEST(Render, CameraSeesAreaLightsOnlyWhenCameraVisible) {
  for (const bool visible : {true, false})
    for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      Scene scene;
      scene.world.color = Spectrum(0.0f);
      Light area;
      area.type = Light::Type::Area;
      area.shape = Light::Shape::Rectangle;
      area.size_x = 2.0f;
      area.size_y = 0.5f;
      area.power = 10.0f;
      area.color = Spectrum(1.0f, 0.5f, 0.25f);
      area.light_to_world = translation({0, 0, 3});  // emits along -z
      area.camera_visible = visible;
      scene.lights.push_back(area);
      scene.camera = top_camera(4, 0.4f, 0.0f);
      scene.camera.camera_to_world = rotation_x(kPi, {0, 0, 0});  // looks up (+z)
      RenderSettings s = pt(4);
      s.mode = mode;
      const Image img = render(scene, s);
      const float expect = visible ? 10.0f / (4.0f * 1.0f) : 0.0f;
      for (size_t i = 0; i < img.primal.size(); i += 3) {
        EXPECT_NEAR(img.emission[i], expect, 1e-4f * expect) << "visible " << visible;
        EXPECT_NEAR(img.emission[i + 1], 0.5f * expect, 1e-4f * expect) << "visible " << visible;
        EXPECT_EQ(img.primal[i], 0.0f);
      }
    }
}

// An emissive ceiling lights a floor through BSDF sampling and NEE on emissive triangles (MIS).
// Two parallel infinite-ish planes: irradiance from a uniform radiance-Le ceiling = pi Le, so the
// floor's radiance is albedo Le at one bounce (max_bounces = 0: direct light only).
TEST(Render, EmissiveCeilingDirectLight) {
  Scene scene;
  scene.meshes.push_back(quad(200.0f));
  scene.materials.push_back(diffuse(Spectrum(0.5f)));
  scene.materials.push_back(emission(Spectrum(1.0f), 1.5f));
  scene.instances.push_back(place(0, 0));
  // Ceiling at z = 1 facing down (rotated by pi about X).
  scene.instances.push_back(place(0, 1, rotation_x(kPi, {0, 0, 1})));
  scene.world.color = Spectrum(0.0f);
  scene.camera = top_camera(4, 0.5f, 0.5f);
  RenderSettings s = pt(64);
  s.max_bounces = 0;
  const Image img = render(scene, s);
  double sum = 0.0;
  for (float v : img.primal) sum += v;
  // The 400 m plane at height 1 subtends all but ~1e-5 of the hemisphere's projected solid angle.
  EXPECT_NEAR(sum / img.primal.size(), 0.5 * 1.5, 0.01 * 0.75);
}

// Clamp: every primal sample is scaled to a largest component of at most `clamp`; the Emission
// pass is not clamped. The emissive-ceiling floor averages 0.75 unclamped.
TEST(Render, ClampBoundsPrimalSamples) {
  Scene scene;
  scene.meshes.push_back(quad(200.0f));
  scene.materials.push_back(diffuse(Spectrum(0.5f)));
  scene.materials.push_back(emission(Spectrum(1.0f), 1.5f));
  scene.instances.push_back(place(0, 0));
  scene.instances.push_back(place(0, 1, rotation_x(kPi, {0, 0, 1})));
  scene.world.color = Spectrum(0.0f);
  scene.camera = top_camera(4, 0.5f, 0.5f);
  RenderSettings s = pt(64);
  s.max_bounces = 0;
  s.clamp = 0.3f;
  const Image img = render(scene, s);
  double sum = 0.0;
  for (float v : img.primal) {
    EXPECT_LE(v, 0.3f + 1e-6f);
    sum += v;
  }
  EXPECT_GT(sum / img.primal.size(), 0.1);
  EXPECT_LT(sum / img.primal.size(), 0.3 + 1e-6);
  // Looking at the emitter from below: 1.5 in the Emission pass, untouched by the clamp.
  scene.camera.camera_to_world = rotation_x(kPi, {0, 0, 0.5f});
  const Image up = render(scene, s);
  EXPECT_FLOAT_EQ(up.emission[0], 1.5f);
}

// Floor of albedo a = 0.5 under a ceiling at height 1 that emits Le = 1 and reflects with albedo
// b = 0.5 (Add shader), seen from above by a `res`-pixel camera.
Scene emitting_ceiling_over_floor(int res) {
  Scene scene;
  scene.meshes.push_back(quad(400.0f));
  scene.materials.push_back(diffuse(Spectrum(0.5f)));
  MaterialDesc ceiling = emission(Spectrum(1.0f), 1.0f);
  ShaderNode d;
  d.kind = ShaderNodeKind::Diffuse;
  d.color = ColorInput(Spectrum(0.5f));
  ceiling.nodes.push_back(d);
  ShaderNode add;
  add.kind = ShaderNodeKind::Add;
  add.a = 0;
  add.b = 1;
  ceiling.nodes.push_back(add);
  ceiling.root = 2;
  scene.materials.push_back(ceiling);
  scene.instances.push_back(place(0, 0));
  scene.instances.push_back(place(0, 1, rotation_x(kPi, {0, 0, 1})));
  scene.world.color = Spectrum(0.0f);
  scene.camera = top_camera(res, 0.5f, 0.5f);
  return scene;
}

// Floor of albedo a under a ceiling that emits Le and reflects with albedo b (Add shader). Paths
// floor -> ceiling (-> floor -> ceiling)^k carry a Le (a b)^k and need 2k + 1 bounces after the
// camera ray, with Cycles' meaning of max_bounces (0 = direct light only): 0, 1 -> a Le;
// 2, 3 -> a Le (1 + a b); 4 -> a Le (1 + a b + (a b)^2).
TEST(Render, MaxBouncesFollowsCycles) {
  const Scene scene = emitting_ceiling_over_floor(4);
  RenderSettings s = pt(64);
  const double ab = 0.25;
  const std::pair<int, double> cases[] = {
      {0, 0.5}, {1, 0.5}, {2, 0.5 * (1 + ab)}, {4, 0.5 * (1 + ab + ab * ab)}};
  for (const auto& [bounces, expect] : cases) {
    s.max_bounces = bounces;
    const Image img = render(scene, s);
    double sum = 0.0;
    for (float v : img.primal) sum += v;
    EXPECT_NEAR(sum / img.primal.size(), expect, 0.01 * expect) << "max_bounces " << bounces;
  }
}

// Russian roulette (q = min(sqrt(max throughput), 1)) keeps the estimate unbiased while it ends
// paths early: the scene of MaxBouncesFollowsCycles with 64 bounces converges to the series
// a Le / (1 - a b) = 2/3 whether roulette starts at the first vertex, at the default vertex (3)
// or never; starting at the first vertex traces far fewer rays.
TEST(Render, RussianRouletteIsUnbiasedAndShortensPaths) {
  const Scene scene = emitting_ceiling_over_floor(8);
  const double expect = 0.5 / (1.0 - 0.25);
  uint64_t rays[3] = {};
  const int depths[3] = {0, RenderSettings{}.rr_depth, 64};
  for (int i = 0; i < 3; ++i) {
    RenderSettings s = pt(256);
    s.max_bounces = 64;
    s.rr_depth = depths[i];
    RenderSession session(scene, s);
    std::atomic<bool> cancel{false};
    session.render(nullptr, cancel);
    std::vector<float> primal(session.film().pixel_count() * 3);
    session.film().primal_rgb(primal.data());
    double sum = 0.0;
    for (float v : primal) sum += v;
    EXPECT_NEAR(sum / primal.size(), expect, 0.01 * expect) << "rr_depth " << depths[i];
    rays[i] = session.rays_traced();
  }
  // Without roulette a path bounces until max_bounces (~130 rays); from the first vertex on,
  // survival falls geometrically.
  EXPECT_LT(double(rays[0]), 0.2 * double(rays[2]));
  EXPECT_LT(rays[1], rays[2]);
  RenderSettings bad = pt(1);
  bad.rr_depth = -1;
  EXPECT_THROW(RenderSession(scene, bad), std::invalid_argument);
}

// Thin lens: emissive stripes on the focus plane render as with a pinhole; moving the focus away
// blurs them (the gradient energy of the stripes' edges drops; total variation would not).
TEST(Render, DepthOfFieldFocusesOnTheFocusPlane) {
  Scene scene;
  scene.materials.push_back(emission(Spectrum(1.0f), 1.0f));
  scene.materials.push_back(emission(Spectrum(0.0f), 0.0f));
  for (int i = 0; i < 8; ++i) {
    Mesh stripe;
    const float x0 = -2.0f + 0.5f * float(i), x1 = x0 + 0.5f;
    stripe.positions = {{x0, -2, 0}, {x1, -2, 0}, {x1, 2, 0}, {x0, 2, 0}};
    stripe.indices = {0, 1, 2, 0, 2, 3};
    scene.meshes.push_back(stripe);
    scene.instances.push_back(place(uint32_t(i), i % 2));
  }
  scene.world.color = Spectrum(0.0f);
  Camera cam;
  cam.camera_to_world = translation({0, 0, 5});
  cam.width = cam.height = 16;
  cam.focal_length_mm = 100.0f;  // 1.8 m across at 5 m: stripes 4.4 px wide
  scene.camera = cam;
  auto contrast = [](const Image& img) {
    double c = 0.0;
    for (size_t i = 0; i + 3 < img.emission.size(); i += 3)
      c += (img.emission[i + 3] - img.emission[i]) * (img.emission[i + 3] - img.emission[i]);
    return c;
  };
  const Image pinhole = render(scene, pt(64));
  scene.camera.aperture_radius = 0.1f;
  scene.camera.focus_distance = 5.0f;
  std::string summary;
  const Image focused = render(scene, pt(64), &summary);
  EXPECT_NE(summary.find("dof"), std::string::npos);
  scene.camera.focus_distance = 2.0f;
  const Image blurred = render(scene, pt(64));
  double diff = 0.0, sum = 0.0;
  for (size_t i = 0; i < pinhole.emission.size(); ++i) {
    diff += std::fabs(pinhole.emission[i] - focused.emission[i]);
    sum += pinhole.emission[i];
  }
  EXPECT_LT(diff / sum, 0.03);
  EXPECT_NEAR(contrast(focused), contrast(pinhole), 0.03 * contrast(pinhole));
  // Focused 3 m in front of the plane: a blur disc of radius 0.1 * 3 / 2 = 0.15 m on the plane,
  // wider than a pixel's 0.11 m footprint, spreads each edge over about three pixels.
  EXPECT_LT(contrast(blurred), 0.7 * contrast(pinhole));
}

// --- Determinism, robustness, session behaviour ---

Scene cornell_like() {
  Scene scene;
  scene.meshes.push_back(quad(1.0f));
  scene.materials.push_back(diffuse(Spectrum(0.8f)));
  scene.materials.push_back(diffuse(Spectrum(0.8f, 0.1f, 0.1f)));
  scene.materials.push_back(diffuse(Spectrum(0.1f, 0.8f, 0.1f)));
  scene.materials.push_back(emission(Spectrum(1.0f), 8.0f));
  scene.instances.push_back(place(0, 0, rotation_x(-kPi / 2, {0, 1, 0})));  // back wall
  scene.instances.push_back(place(0, 0, translation({0, 0, -1})));          // floor
  scene.instances.push_back(place(0, 0, rotation_x(kPi, {0, 0, 1})));       // ceiling
  Transform left;                                                           // x = -1 facing +x
  left.m[0][0] = 0;
  left.m[0][2] = 1;
  left.m[2][0] = -1;
  left.m[2][2] = 0;
  left.m[0][3] = -1;
  scene.instances.push_back(place(0, 1, left));
  Transform right = left;
  right.m[0][2] = -1;
  right.m[2][0] = 1;
  right.m[0][3] = 1;
  scene.instances.push_back(place(0, 2, right));
  Transform lamp = rotation_x(kPi, {0, 0, 0.99f});
  for (int r = 0; r < 2; ++r)
    for (int c = 0; c < 2; ++c) lamp.m[r][c] *= 0.25f;
  scene.instances.push_back(place(0, 3, lamp));
  Light point;
  point.power = 20.0f;
  point.light_to_world = translation({0.3f, -0.2f, 0.5f});
  scene.lights.push_back(point);
  scene.world.color = Spectrum(0.02f);
  Camera cam;
  cam.camera_to_world = rotation_x(kPi / 2, {0, -3.5f, 0});  // looks along +y
  cam.focal_length_mm = 35.0f;
  cam.width = 24;
  cam.height = 20;
  scene.camera = cam;
  return scene;
}

TEST(Render, BitIdenticalAcrossThreadCountsAndTileOrder) {
  const Scene scene = cornell_like();
  RenderSettings s = pt(4, 42);
  s.threads = 1;
  const Image one = render(scene, s);
  s.threads = 2;
  s.samples_per_pass = 2;
  const Image two = render(scene, s);
  s.samples = 20;  // 20 spp in one pass: split into 16 + 4 spp chunks per tile
  s.samples_per_pass = 20;
  const Image chunked = render(scene, s);
  s.threads = 1;
  s.samples_per_pass = 1;
  const Image passes = render(scene, s);
  ASSERT_EQ(chunked.primal, passes.primal);
  s.samples = 4;
  ASSERT_EQ(one.primal.size(), two.primal.size());
  for (size_t i = 0; i < one.primal.size(); ++i) ASSERT_EQ(one.primal[i], two.primal[i]) << i;

  // Tiles in reverse order, odd tile shapes, driving the integrator directly.
  const SceneContext ctx(scene, s);
  const auto pt_integrator = make_path_tracer(ctx, s);
  Film film(scene.camera.width, scene.camera.height);
  for (int y0 = scene.camera.height; y0 > 0; y0 -= 7)
    for (int x0 = scene.camera.width; x0 > 0; x0 -= 5)
      pt_integrator->render_tile({std::max(x0 - 5, 0), std::max(y0 - 7, 0), x0, y0}, 0, 4, film);
  std::vector<float> p(film.pixel_count() * 3);
  film.primal_rgb(p.data());
  for (size_t i = 0; i < p.size(); ++i) ASSERT_EQ(p[i], one.primal[i]) << i;

  double sum = 0.0;
  for (float v : one.primal) sum += v;
  EXPECT_GT(sum, 0.0);
  s.seed = 43;
  const Image other = render(scene, s);
  EXPECT_NE(other.primal, one.primal);
}

// A render region (Blender's border) is the same pixels as the whole frame's, bit for bit: its
// rays and sampler keys are the frame's. Checked with and without depth of field, and a region
// outside the frame is refused.
TEST(Render, RenderRegionIsTheFramesPixels) {
  for (const bool dof : {false, true}) {
    Scene scene = cornell_like();
    if (dof) {
      scene.camera.aperture_radius = 0.05f;
      scene.camera.focus_distance = 3.0f;
    }
    const RenderSettings s = pt(4, 7);
    const Image full = render(scene, s);
    scene.camera.region_x = 5;
    scene.camera.region_y = 3;
    scene.camera.region_width = 13;
    scene.camera.region_height = 9;
    const Image region = render(scene, s);
    ASSERT_EQ(region.w, 13);
    ASSERT_EQ(region.h, 9);
    double sum = 0.0;
    for (int y = 0; y < region.h; ++y)
      for (int x = 0; x < region.w; ++x)
        for (int c = 0; c < 3; ++c) {
          ASSERT_EQ(region.at(x, y, c), full.at(x + 5, y + 3, c)) << dof << " " << x << " " << y;
          sum += region.at(x, y, c);
        }
    EXPECT_GT(sum, 0.0);
  }
  Scene scene = cornell_like();
  scene.camera.region_x = 20;
  scene.camera.region_width = 5;  // 20 + 5 > 24
  scene.camera.region_height = 4;
  EXPECT_THROW(render(scene, pt(1)), std::invalid_argument);
}

// The viewport's restart on a moved view: after set_camera (another position, resolution and
// projection) a session renders bit for bit what a new session with that camera renders, in PT
// and G-PT; an unusable camera is refused and the session keeps rendering its own.
TEST(Render, SetCameraRendersAsANewSession) {
  for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    const Scene scene = cornell_like();
    RenderSettings s = pt(2, 5);
    s.mode = mode;
    Scene moved = scene;
    moved.camera.width = 20;
    moved.camera.height = 14;
    moved.camera.camera_to_world.m[0][3] += 0.3f;
    moved.camera.projection = Camera::Projection::Orthographic;
    moved.camera.ortho_scale = 3.0f;

    RenderSession session(scene, s);
    std::atomic<bool> cancel{false};
    session.render(nullptr, cancel);
    Camera bad = moved.camera;
    bad.width = 0;
    EXPECT_THROW(session.set_camera(bad), std::invalid_argument);
    session.set_camera(moved.camera);
    ASSERT_EQ(session.film().min_samples(), 0u);  // the film starts over
    session.render(nullptr, cancel);
    const Image fresh = render(moved, s);
    ASSERT_EQ(session.film().width(), fresh.w);
    ASSERT_EQ(session.film().height(), fresh.h);
    std::vector<float> primal(session.film().pixel_count() * 3), gx(primal.size());
    session.film().primal_rgb(primal.data());
    session.film().gradient_x_rgb(gx.data());
    EXPECT_EQ(primal, fresh.primal);
    EXPECT_EQ(gx, fresh.gradient_x);
    Scene resized = scene;  // the first view at the new size: the view really changed
    resized.camera.width = moved.camera.width;
    resized.camera.height = moved.camera.height;
    EXPECT_NE(primal, render(resized, s).primal);
  }
}

// The viewport's restarts through start resolutions: a session keeps the films of a few sizes and
// clears them on the way back; every restart renders what a new session of its camera renders,
// including after a size was dropped (more sizes than the session keeps).
TEST(Render, RestartsAcrossSizesRenderAsNewSessions) {
  const Scene scene = cornell_like();
  RenderSettings s = pt(2, 5);
  s.mode = RenderSettings::Mode::GPT;
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  for (const int divider : {4, 2, 1, 4, 2, 1, 8, 3, 5, 1, 4}) {
    Scene sized = scene;
    sized.camera.width = scene.camera.width / divider;
    sized.camera.height = scene.camera.height / divider;
    session.set_camera(sized.camera);
    ASSERT_EQ(session.film().min_samples(), 0u) << divider;
    session.render(nullptr, cancel);
    std::vector<float> primal(session.film().pixel_count() * 3), gx(primal.size());
    session.film().primal_rgb(primal.data());
    session.film().gradient_x_rgb(gx.data());
    const Image fresh = render(sized, s);
    EXPECT_EQ(primal, fresh.primal) << "divider " << divider;
    EXPECT_EQ(gx, fresh.gradient_x) << "divider " << divider;
  }
}

// The viewport's in-place update: after update() with moved and brighter lamps, another material
// colour, another world and other settings, a session keeps its BVH and renders bit for bit what
// a new session of the changed scene renders, in PT and G-PT; a moved instance rebuilds it (same
// image as a new session again); an unusable scene is refused and the session keeps its own.
TEST(Render, UpdateRendersAsANewSession) {
  for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    const Scene scene = cornell_like();
    RenderSettings s = pt(2, 5);
    s.mode = mode;
    auto film_of = [](const RenderSession& session) {
      std::vector<float> v(session.film().pixel_count() * 3);
      session.film().primal_rgb(v.data());
      return v;
    };
    auto expect_as_new = [&](RenderSession& session, const Scene& changed, const RenderSettings& st,
                             const char* what) {
      std::atomic<bool> cancel{false};
      ASSERT_EQ(session.film().min_samples(), 0u) << what;  // the film starts over
      session.render(nullptr, cancel);
      EXPECT_EQ(film_of(session), render(changed, st).primal) << what << " mode " << int(mode);
      EXPECT_NE(film_of(session), render(scene, s).primal) << what << ": nothing changed";
    };
    RenderSession session(scene, s);
    std::atomic<bool> cancel{false};
    session.render(nullptr, cancel);

    Scene shaded = scene;
    shaded.lights[0].light_to_world.m[0][3] -= 0.5f;
    shaded.lights[0].power *= 2.0f;
    shaded.materials[1] = diffuse(Spectrum(0.1f, 0.1f, 0.8f));
    shaded.world.color = Spectrum(0.3f, 0.2f, 0.1f);
    RenderSettings s2 = s;
    s2.max_bounces = 2;
    s2.samples = 3;
    EXPECT_TRUE(session.update(shaded, s2));
    expect_as_new(session, shaded, s2, "lamp, material, world and settings");

    Scene bad = shaded;
    bad.world.image = 3;  // no such image
    EXPECT_THROW(session.update(bad, s2), std::invalid_argument);
    session.set_camera(shaded.camera);
    expect_as_new(session, shaded, s2, "after a refused update");

    Scene moved = shaded;
    moved.instances[1].object_to_world.m[2][3] += 0.2f;
    EXPECT_FALSE(session.update(moved, s2));
    expect_as_new(session, moved, s2, "a moved instance");

    // The shadow terminator offsets live in the BVH's instance data: a new BVH.
    Scene offset = moved;
    offset.instances[1].terminator_shading_offset = 0.8f;
    offset.instances[1].terminator_geometry_offset = 0.5f;
    EXPECT_FALSE(session.update(offset, s2));
    expect_as_new(session, offset, s2, "shadow terminator offsets");
  }
}

TEST(Render, NeverNaNOrInf) {
  Scene scene = cornell_like();
  // Degenerate triangles, zero-length and inverted shading normals, zero-roughness glossy,
  // zero-area area light, zero-radius point light touching a surface.
  Mesh bad;
  bad.positions = {{-0.5f, 0, -0.5f},    {0.5f, 0, -0.5f},    {0.5f, 0, -0.5f},  {0, 0.2f, 0.2f},
                   {-0.5f, 0.3f, -0.9f}, {0.5f, 0.3f, -0.9f}, {0.0f, 0.5f, 0.3f}};
  bad.indices = {0, 1, 2, 3, 3, 3, 4, 5, 6};
  const Vec3f n = normalize(Vec3f(0, -1, 0));
  bad.corner_normals = {Vec3f(0.0f), Vec3f(0.0f), Vec3f(0.0f), n, n, n, -n, n * -1.0f, -n};
  scene.meshes.push_back(bad);
  scene.materials.push_back(glossy(Spectrum(0.9f), 0.0f));
  scene.instances.push_back(place(1, 4));
  scene.instances.push_back(place(1, 0, translation({0.2f, -0.3f, 0.1f})));
  Light area;
  area.type = Light::Type::Area;
  area.size_x = 0.0f;
  area.size_y = 0.0f;
  area.power = 50.0f;
  area.light_to_world = translation({0, 0, 0.8f});
  scene.lights.push_back(area);
  Light touching;
  touching.power = 10.0f;
  touching.light_to_world = translation({0, 0, -1.0f});  // on the floor
  scene.lights.push_back(touching);
  const Image img = render(scene, pt(8));
  for (float v : img.primal) ASSERT_TRUE(std::isfinite(v));
  for (float v : img.emission) ASSERT_TRUE(std::isfinite(v));
}

// A render cancelled after three passes keeps exactly the image of a three-sample render with the
// same seed (primal, emission and gradients), in PT and G-PT.
TEST(Render, CancelKeepsFinishedPasses) {
  const Scene scene = cornell_like();
  for (const auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
    RenderSettings s = pt(1000);
    s.mode = mode;
    RenderSession session(scene, s);
    std::atomic<bool> cancel{false};
    int calls = 0;
    session.render(
        [&](const RenderProgress& p) {
          ++calls;
          EXPECT_EQ(p.samples_done, calls);
          EXPECT_EQ(p.samples_total, 1000);
          if (calls == 3) cancel = true;
        },
        cancel);
    EXPECT_EQ(calls, 3);
    const Film& film = session.film();
    for (int y = 0; y < film.height(); ++y)
      for (int x = 0; x < film.width(); ++x) ASSERT_EQ(film.samples(x, y), 3u);
    s.samples = 3;
    const Image full = render(scene, s);
    std::vector<float> primal(film.pixel_count() * 3), emission(primal.size()), dx(primal.size());
    film.primal_rgb(primal.data());
    film.emission_rgb(emission.data());
    film.gradient_x_rgb(dx.data());
    ASSERT_EQ(primal.size(), full.primal.size());
    double sum = 0.0;
    for (size_t i = 0; i < primal.size(); ++i) {
      ASSERT_EQ(primal[i], full.primal[i]) << "mode " << int(mode) << ", value " << i;
      ASSERT_EQ(emission[i], full.emission[i]) << "mode " << int(mode) << ", value " << i;
      ASSERT_EQ(dx[i], full.gradient_x[i]) << "mode " << int(mode) << ", value " << i;
      sum += primal[i];
    }
    EXPECT_GT(sum, 0.0);  // a lit image, not two empty ones
  }
}

TEST(Render, CancelFromAnotherThreadStopsQuickly) {
  Scene scene = cornell_like();
  scene.camera.width = 160;
  scene.camera.height = 120;
  RenderSettings s = pt(1 << 20);
  s.samples_per_pass = 1024;  // one pass would take many seconds: cancel must not wait for it
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  std::thread stopper([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    cancel = true;
  });
  const auto t0 = std::chrono::steady_clock::now();
  session.render(nullptr, cancel);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  stopper.join();
  EXPECT_LT(secs, 1.2);
  const uint32_t n = session.film().samples(0, 0);
  EXPECT_EQ(n % 1024, 0u);
  EXPECT_EQ(session.film().min_samples(), n);  // a cancelled pass is discarded everywhere
}

TEST(Render, TimeLimitStopsTheRender) {
  RenderSettings s = pt(1 << 20);
  s.time_limit = 0.2;
  RenderSession session(cornell_like(), s);
  std::atomic<bool> cancel{false};
  const auto t0 = std::chrono::steady_clock::now();
  session.render(nullptr, cancel);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 1.0);
  EXPECT_GT(session.film().min_samples(), 0u);
}

TEST(Render, InstancesRenderLikeCopies) {
  Scene inst, copies;
  const Mesh ball = sphere(0.4f, 16, 8);
  inst.meshes.push_back(ball);
  for (Scene* s : {&inst, &copies}) {
    s->meshes.push_back(quad(20.0f));
    s->materials.push_back(diffuse(Spectrum(0.7f, 0.5f, 0.3f)));
    s->world.color = Spectrum(0.5f);
    s->camera = top_camera(24, 4.0f);
  }
  inst.instances.push_back(place(1, 0));
  copies.instances.push_back(place(0, 0));
  for (int i = 0; i < 4; ++i) {
    const Vec3f c(-1.2f + 0.8f * float(i), 0.3f * float(i % 2), 0.5f);
    inst.instances.push_back(place(0, 0, translation(c)));
    copies.meshes.push_back(sphere(0.4f, 16, 8, c));
    copies.instances.push_back(place(uint32_t(copies.meshes.size() - 1), 0));
  }
  const Image a = render(inst, pt(32)), b = render(copies, pt(32));
  double diff = 0.0, sum = 0.0;
  for (size_t i = 0; i < a.primal.size(); ++i) {
    diff += std::fabs(a.primal[i] - b.primal[i]);
    sum += a.primal[i];
  }
  // Same samples, geometry equal up to float rounding of the transform.
  EXPECT_LT(diff / sum, 1e-3);
}

TEST(Render, ForcedFeaturesGiveTheSameImage) {
  const Scene scene = cornell_like();
  std::string lean, forced;
  RenderSettings s = pt(4);
  const Image a = render(scene, s, &lean);
  s.force_all_features = true;
  const Image b = render(scene, s, &forced);
  EXPECT_EQ(lean.find("dof"), std::string::npos);
  EXPECT_NE(forced.find("(forced)"), std::string::npos);
  double diff = 0.0, sum = 0.0;
  for (size_t i = 0; i < a.primal.size(); ++i) {
    diff += std::fabs(a.primal[i] - b.primal[i]);
    sum += a.primal[i];
  }
  EXPECT_LT(diff / sum, 1e-5);
}

TEST(Render, PtGradientsAreForwardDifferencesOfPrimal) {
  RenderSession session(cornell_like(), pt(2));
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  const Film& f = session.film();
  std::vector<float> p(f.pixel_count() * 3), dx(p.size()), dy(p.size());
  f.primal_rgb(p.data());
  f.gradient_x_rgb(dx.data());
  f.gradient_y_rgb(dy.data());
  const int w = f.width();
  for (int y = 0; y + 1 < f.height(); ++y)
    for (int x = 0; x + 1 < w; ++x) {
      const size_t i = size_t(y * w + x) * 3;
      EXPECT_NEAR(dx[i], p[i + 3] - p[i], 1e-5f);
      EXPECT_NEAR(dy[i], p[i + size_t(w) * 3] - p[i], 1e-5f);
    }
}

TEST(Render, InvalidScenesThrowEmptyScenesRender) {
  Scene bad = cornell_like();
  bad.camera.width = 0;
  EXPECT_THROW(RenderSession(bad, pt(1)), std::invalid_argument);
  Scene bad_mesh = cornell_like();
  bad_mesh.instances[0].mesh = 99;
  EXPECT_THROW(RenderSession(bad_mesh, pt(1)), std::invalid_argument);
  Scene empty;
  empty.world.color = Spectrum(0.0f);
  empty.camera.width = 8;
  empty.camera.height = 4;
  const Image img = render(empty, pt(2));
  for (float v : img.primal) EXPECT_EQ(v, 0.0f);
  EXPECT_EQ(img.min_samples, 2u);
}

}  // namespace
}  // namespace gdpt
