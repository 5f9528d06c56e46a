// Small scenes and render helpers shared by the G-PT tests and benchmark.
#pragma once

#include <atomic>
#include <cmath>
#include <vector>

#include "integrators/render_session.h"
#include "reconstruct/reconstruct.h"
#include "scene/scene.h"
#include "testing/materials.h"

namespace gdpt::gradient_test {

using test::single_node;

inline MaterialDesc diffuse(Spectrum c) {
  return single_node(ShaderNodeKind::Diffuse, c);
}
// `roughness` is Blender's roughness (GGX alpha = roughness^2).
inline MaterialDesc glossy(Spectrum c, float roughness) {
  return single_node(ShaderNodeKind::Glossy, c, roughness);
}
inline MaterialDesc glass(float roughness, float ior = 1.5f) {
  return single_node(ShaderNodeKind::Glass, Spectrum(1.0f), roughness, ior);
}
inline MaterialDesc emissive(Spectrum c, float strength) {
  MaterialDesc m = single_node(ShaderNodeKind::Emission, c);
  m.nodes[0].strength = FloatInput(strength);
  return m;
}

inline Transform transform(float ax, float ay, Vec3f t) {
  // R = Ry(ay) * Rx(ax), then translate.
  const float cx = std::cos(ax), sx = std::sin(ax), cy = std::cos(ay), sy = std::sin(ay);
  Transform T;
  const float rx[3][3] = {{1, 0, 0}, {0, cx, -sx}, {0, sx, cx}};
  const float ry[3][3] = {{cy, 0, sy}, {0, 1, 0}, {-sy, 0, cy}};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      float v = 0.0f;
      for (int k = 0; k < 3; ++k) v += ry[r][k] * rx[k][c];
      T.m[r][c] = v;
    }
  T.m[0][3] = t.x;
  T.m[1][3] = t.y;
  T.m[2][3] = t.z;
  return T;
}

// Square in z = 0 of half-size h, normal +z.
inline Mesh quad(float h) {
  Mesh m;
  m.positions = {{-h, -h, 0}, {h, -h, 0}, {h, h, 0}, {-h, h, 0}};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

// Smooth-shaded UV sphere.
inline Mesh sphere(float r, int seg, int rings) {
  Mesh m;
  std::vector<Vec3f> normals;
  for (int i = 0; i <= rings; ++i) {
    const float th = kPi * float(i) / float(rings);
    for (int j = 0; j < seg; ++j) {
      const float ph = 2.0f * kPi * float(j) / float(seg);
      const Vec3f n(std::sin(th) * std::cos(ph), std::sin(th) * std::sin(ph), std::cos(th));
      m.positions.push_back(n * r);
      normals.push_back(n);
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < seg; ++j) {
      const uint32_t a = uint32_t(i * seg + j), b = uint32_t(i * seg + (j + 1) % seg);
      const uint32_t c = a + uint32_t(seg), d = b + uint32_t(seg);
      if (i > 0) m.indices.insert(m.indices.end(), {a, c, b});
      if (i < rings - 1) m.indices.insert(m.indices.end(), {b, c, d});
    }
  for (uint32_t idx : m.indices) m.corner_normals.push_back(normals[idx]);
  return m;
}

inline Instance place(uint32_t mesh, int32_t material, Transform t) {
  Instance i;
  i.mesh = mesh;
  i.object_to_world = t;
  i.slot_material = {material};
  return i;
}

enum class SceneKind {
  CornellDiffuse,
  CornellGlossy,
  CornellGlass,
  Environment,
  Corner,
  MixedLights
};

// Cornell-like box [-1, 1]^3 open towards +z, camera on +z looking in. Materials:
//  0 white diffuse, 1 red, 2 green, 3 object material (per kind), 4 emitter (unused by default).
// `light_size`: area light side (m) under the ceiling.
inline Scene make_scene(SceneKind kind, int res, float object_roughness = 0.3f,
                        float light_size = 0.6f) {
  Scene s;
  s.world.color = Spectrum(0.0f);
  s.meshes.push_back(quad(1.0f));             // 0: wall
  s.meshes.push_back(sphere(0.45f, 24, 12));  // 1: sphere
  s.meshes.push_back(quad(0.35f));            // 2: block face
  s.materials.push_back(diffuse({0.75f, 0.75f, 0.75f}));
  s.materials.push_back(diffuse({0.7f, 0.15f, 0.12f}));
  s.materials.push_back(diffuse({0.15f, 0.6f, 0.15f}));
  switch (kind) {
    case SceneKind::CornellGlossy:
      s.materials.push_back(glossy({0.9f, 0.8f, 0.6f}, object_roughness));
      break;
    case SceneKind::CornellGlass:
      s.materials.push_back(glass(object_roughness));
      break;
    default:
      s.materials.push_back(diffuse({0.5f, 0.5f, 0.8f}));
      break;
  }
  const float h = kPi / 2;
  if (kind == SceneKind::Environment) {
    // A floor with a sphere and a tilted panel under a constant sky.
    s.world.color = Spectrum(0.8f, 0.9f, 1.0f);
    s.instances.push_back(place(0, 0, transform(-h, 0, {0, -1, 0})));
    s.instances.push_back(place(1, 3, transform(0, 0, {-0.3f, -0.55f, 0})));
    s.instances.push_back(place(2, 1, transform(-0.4f, 0.5f, {0.5f, -0.5f, -0.3f})));
  } else {
    s.instances.push_back(place(0, 0, transform(-h, 0, {0, -1, 0})));  // floor
    s.instances.push_back(place(0, 0, transform(h, 0, {0, 1, 0})));    // ceiling
    s.instances.push_back(place(0, 0, transform(0, 0, {0, 0, -1})));   // back
    s.instances.push_back(place(0, 1, transform(0, h, {-1, 0, 0})));   // left (red)
    s.instances.push_back(place(0, 2, transform(0, -h, {1, 0, 0})));   // right (green)
    s.instances.push_back(place(1, 3, transform(0, 0, {-0.3f, -0.55f, -0.1f})));
    s.instances.push_back(place(2, 0, transform(-0.3f, 0.6f, {0.45f, -0.6f, 0.2f})));
    Light l;
    l.type = Light::Type::Area;
    l.power = 12.0f * light_size * light_size / 0.36f;
    l.size_x = l.size_y = light_size;
    l.light_to_world = transform(-h, 0, {0, 0.98f, 0});  // emits towards -y
    s.lights.push_back(l);
  }
  if (kind == SceneKind::MixedLights) {
    // Replace the area light: an emissive quad (triangle lights, sampled by area), a point light
    // (delta), a sphere light (sampled in solid angle) and a sun through the open side.
    s.lights.clear();
    s.materials.push_back(emissive({1.0f, 0.9f, 0.8f}, 6.0f));  // 4
    s.meshes.push_back(quad(0.2f));                             // 3
    s.instances.push_back(place(3, 4, transform(h, 0, {0.3f, 0.97f, -0.2f})));
    Light point;
    point.type = Light::Type::Point;
    point.power = 3.0f;
    point.light_to_world = transform(0, 0, {-0.5f, 0.6f, 0.3f});
    s.lights.push_back(point);
    Light ball;
    ball.type = Light::Type::Point;
    ball.power = 4.0f;
    ball.radius = 0.1f;
    ball.light_to_world = transform(0, 0, {0.5f, 0.5f, -0.4f});
    s.lights.push_back(ball);
    Light sun;
    sun.type = Light::Type::Sun;
    sun.power = 1.5f;
    sun.sun_angle = 0.05f;
    sun.light_to_world = transform(0.9f, 0.4f, {0, 0, 5});
    s.lights.push_back(sun);
  }
  Camera& c = s.camera;
  c.width = c.height = res;
  c.focal_length_mm = 35.0f;
  c.sensor_width_mm = 36.0f;
  if (kind == SceneKind::Corner) {
    // Looking into the top-left back corner of the room: three walls meet in view.
    c.camera_to_world = transform(0.45f, 0.6f, {0.2f, -0.2f, 0.6f});
    c.focal_length_mm = 20.0f;
  } else {
    c.camera_to_world = transform(0, 0, {0, 0, 3.4f});
  }
  return s;
}

// A diffuse box [-1, 1]^3 open towards +z whose only light is an emissive mesh panel (Emission
// shader only, two-sided, strength `strength`) of half-size 0.3 a hair (`gap`) below the ceiling,
// facing down, as a Blender user models a ceiling lamp. The camera inside the box looks straight
// up at the panel's edge x = 0.3: half the frame sees the panel, half the ceiling beside it, whose
// light arrives at grazing angles past the panel. `at` moves the whole scene: far from the origin
// (as Blender scenes often are) positions carry rounding errors far above a short segment's length.
inline Scene make_panel_scene(int res, Vec3f at = {0, 0, 0}, float gap = 1e-3f,
                              float strength = 10.0f) {
  Scene s;
  s.world.color = Spectrum(0.0f);
  s.meshes.push_back(quad(1.0f));  // 0: wall
  s.meshes.push_back(quad(0.3f));  // 1: panel
  s.materials.push_back(diffuse({0.75f, 0.75f, 0.75f}));
  s.materials.push_back(diffuse({0.7f, 0.15f, 0.12f}));
  s.materials.push_back(diffuse({0.15f, 0.6f, 0.15f}));
  s.materials.push_back(emissive({1.0f, 1.0f, 1.0f}, strength));
  const float h = kPi / 2;
  s.instances.push_back(place(0, 0, transform(-h, 0, {0, -1, 0})));         // floor
  s.instances.push_back(place(0, 0, transform(h, 0, {0, 1, 0})));           // ceiling
  s.instances.push_back(place(0, 0, transform(0, 0, {0, 0, -1})));          // back
  s.instances.push_back(place(0, 1, transform(0, h, {-1, 0, 0})));          // left (red)
  s.instances.push_back(place(0, 2, transform(0, -h, {1, 0, 0})));          // right (green)
  s.instances.push_back(place(1, 3, transform(h, 0, {0, 1.0f - gap, 0})));  // panel
  Camera& c = s.camera;
  c.width = c.height = res;
  c.focal_length_mm = 50.0f;
  c.sensor_width_mm = 36.0f;
  c.camera_to_world = transform(h, 0, {0.3f, -0.6f, 0.0f});  // looks up (+y)
  for (Instance& i : s.instances) {
    i.object_to_world.m[0][3] += at.x;
    i.object_to_world.m[1][3] += at.y;
    i.object_to_world.m[2][3] += at.z;
  }
  c.camera_to_world.m[0][3] += at.x;
  c.camera_to_world.m[1][3] += at.y;
  c.camera_to_world.m[2][3] += at.z;
  return s;
}

// A smooth glass ball (radius 0.45, IOR `ior`, at height 1) above a diffuse floor z = 0 under a
// 0.3 m square lamp at height 3 facing down; the camera looks down at the floor at 45 degrees,
// at the ball's caustic (at IOR 1.5 the lamp's image lies on the floor). `shadow_caustics`: the
// floor receives, the ball casts and the lamp lights Shadow Caustics (manifold NEE).
inline Scene make_caustic_scene(int res, bool shadow_caustics, float ior = 1.5f,
                                float height = 1.0f, float lamp = 0.3f) {
  Scene s;
  s.world.color = Spectrum(0.0f);
  s.meshes.push_back(quad(1.5f));
  s.meshes.push_back(sphere(0.45f, 48, 24));
  s.materials.push_back(diffuse({0.8f, 0.8f, 0.8f}));
  s.materials.push_back(glass(0.0f, ior));
  s.instances.push_back(place(0, 0, transform(0, 0, {0, 0, 0})));
  s.instances.push_back(place(1, 1, transform(0, 0, {0, 0, height})));
  s.instances[0].caustics_receiver = shadow_caustics;
  s.instances[1].caustics_caster = shadow_caustics;
  Light l;
  l.type = Light::Type::Area;
  l.power = 20.0f;
  l.size_x = l.size_y = lamp;
  l.light_to_world = transform(0, 0, {0, 0, 3.0f});  // emits towards -z
  l.caustics_light = shadow_caustics;
  s.lights.push_back(l);
  Camera& c = s.camera;
  c.width = c.height = res;
  c.focal_length_mm = 200.0f;  // the floor around the caustic, the ball out of view
  c.sensor_width_mm = 36.0f;
  c.camera_to_world = transform(kPi / 4, 0, {0, -2.5f, 2.5f});
  return s;
}

struct Passes {
  int w = 0, h = 0;
  std::vector<float> primal, dx, dy, emission, variance, failures;
  double lum(const std::vector<float>& v, int x, int y) const {
    const size_t i = size_t(y * w + x) * 3;
    return 0.2126 * v[i] + 0.7152 * v[i + 1] + 0.0722 * v[i + 2];
  }
  double var(int x, int y, int c) const { return variance[size_t(y * w + x) * 3 + c]; }
};

inline RenderSettings settings(RenderSettings::Mode mode, int spp, uint32_t seed, int threads = 2) {
  RenderSettings s;
  s.mode = mode;
  s.samples = spp;
  s.seed = seed;
  s.threads = threads;
  s.samples_per_pass = spp;
  return s;
}

// Every pass of a film, in the RGB / per-pixel layouts above.
inline Passes read_film(const Film& f) {
  Passes p;
  p.w = f.width();
  p.h = f.height();
  const size_t n = f.pixel_count();
  p.primal.resize(n * 3);
  p.dx.resize(n * 3);
  p.dy.resize(n * 3);
  p.emission.resize(n * 3);
  p.variance.resize(n * 3);
  p.failures.resize(n);
  f.primal_rgb(p.primal.data());
  f.gradient_x_rgb(p.dx.data());
  f.gradient_y_rgb(p.dy.data());
  f.emission_rgb(p.emission.data());
  f.variance3(p.variance.data());
  f.shift_failures(p.failures.data());
  return p;
}

inline Passes render(const Scene& scene, const RenderSettings& s) {
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  return read_film(session.film());
}

// The G-PT passes `g` solved by L2 (alpha 0.2); `with_emission` adds the Emission pass.
inline std::vector<float> reconstruct_l2(const Passes& g, bool with_emission = false) {
  ReconstructionInput in;
  in.width = g.w;
  in.height = g.h;
  in.primal = g.primal.data();
  in.gradient_x = g.dx.data();
  in.gradient_y = g.dy.data();
  if (with_emission) in.emission = g.emission.data();
  ReconstructionSettings rs;
  rs.norm = ReconstructionNorm::L2;
  rs.alpha = 0.2f;
  rs.threads = 2;
  return reconstruct(in, rs);
}

// Relative MSE of the G-PT papers: mean over pixels and channels of (a - ref)^2 / (ref^2 + 0.01).
inline double rel_mse(const std::vector<float>& a, const std::vector<float>& ref) {
  double s = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = double(a[i]) - ref[i];
    s += d * d / (double(ref[i]) * ref[i] + 1e-2);
  }
  return s / double(a.size());
}

}  // namespace gdpt::gradient_test
