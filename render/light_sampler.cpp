// LightSampler: one power-proportional CDF over every emitter of the scene (analytic lights,
// emissive triangles, the world), then the emitter's own sampling routine.
//
// Light selection weights are power estimates (W, luminance of the colour):
//   point I*4pi, spot the same times the cone's solid-angle fraction, area pi L A, emissive
//   triangle 2 pi L_avg A (two-sided), sun E pi R^2 and world 4 pi^2 R^2 L_avg, with R the
//   radius of the scene's bounding sphere (the power the scene can intercept).
// A constant-colour world is not a light (as Cycles' automatic world sampling): sampling it
// uniformly finds nothing cosine-weighted BSDF sampling does not, and would take a share of the
// light samples from the lamps. Escaping rays still see it (environment()).
// Lights with zero power, area or radius-related degeneracy never enter the CDF, so sample()
// cannot pick them and intersect() ignores them.
#include "render/light_sampler.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "render/environment_map.h"
#include "render/light_distribution.h"
#include "render/lights/area_light.h"
#include "render/lights/point_light.h"
#include "render/lights/sun_light.h"
#include "render/lights/triangle_light.h"
#include "scene/generated_mapping.h"

namespace gdpt {

namespace {

enum class Kind : uint8_t { Point, Area, Sun, Triangle, World };

struct Entry {
  Kind kind;
  uint32_t index;  // into the vector of that kind (unused for World)
};

uint64_t triangle_key(uint32_t instance, uint32_t primitive) {
  return (uint64_t(instance) << 32) | uint64_t(primitive);
}

// Radius of a sphere bounding every instance (1 when the scene has no geometry).
float scene_radius(const Scene& scene) {
  std::vector<std::pair<Vec3f, Vec3f>> mesh_bounds(scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    Vec3f lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
    for (const Vec3f& p : scene.meshes[m].positions) {
      lo = min(lo, p);
      hi = max(hi, p);
    }
    mesh_bounds[m] = {lo, hi};
  }
  Vec3f lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (const Instance& inst : scene.instances) {
    if (inst.mesh >= mesh_bounds.size()) continue;
    const auto [a, b] = mesh_bounds[inst.mesh];
    if (!(a.x <= b.x)) continue;
    for (int c = 0; c < 8; ++c) {
      const Vec3f corner((c & 1) ? b.x : a.x, (c & 2) ? b.y : a.y, (c & 4) ? b.z : a.z);
      const Vec3f p = inst.object_to_world.point(corner);
      lo = min(lo, p);
      hi = max(hi, p);
    }
  }
  if (!(lo.x <= hi.x)) return 1.0f;
  const float r = 0.5f * length(hi - lo);
  return (r > 0.0f && std::isfinite(r)) ? r : 1.0f;
}

}  // namespace

struct LightSampler::Impl {
  std::span<const Material> materials;
  std::vector<lights::SunLight> suns;
  std::vector<lights::TriangleLight> triangles;
  std::vector<ShadingInstance> shading_instances;  // per Scene::instances; triangles point in
  std::vector<uint64_t> triangle_keys;             // sorted, parallel to `triangles`

  std::vector<Entry> entries;
  Distribution1D selection;

  // A Background's radiance: its environment map, or its constant colour x strength.
  struct BackgroundRadiance {
    std::optional<EnvironmentMap> environment;  // none for a constant or a black image
    Spectrum constant{0.0f, 0.0f, 0.0f};

    // Sets it up from `b` (the Scene's images outlive it); returns the mean radiance over the
    // sphere (0 when black).
    Spectrum set(const Background& b, const Scene& scene) {
      if (b.image >= 0 && size_t(b.image) < scene.images.size()) {
        environment.emplace(scene.images[size_t(b.image)], b.rotation, b.strength);
        if (!environment->black()) return environment->average();
        environment.reset();
        return Spectrum(0.0f);
      }
      constant = max(b.color * b.strength, Spectrum(0.0f));
      return constant;
    }
    Spectrum eval(Vec3f d) const { return environment ? environment->eval(d) : constant; }
  };

  bool world_enabled = false;  // non-black world: escaping rays see it
  float world_pmf = 0.0f;      // > 0 only for an image world, in the CDF (a constant one is not)
  BackgroundRadiance world;

  // World::camera_view, when set (never sampled as a light).
  bool camera_view = false;
  bool camera_enabled = false;  // non-black
  BackgroundRadiance camera;
};

LightSampler::LightSampler(const Scene& scene, std::span<const Material> materials,
                           std::span<const Texture> /*textures: the world reads Scene::images*/)
    : impl_(std::make_unique<Impl>()) {
  Impl& I = *impl_;
  I.materials = materials;
  const float radius = scene_radius(scene);
  std::vector<float> weights;

  // --- Analytic lights ---------------------------------------------------------------------
  for (const Light& l : scene.lights) {
    if (!(l.power > 0.0f) || !std::isfinite(l.power) || is_black(l.color)) continue;
    switch (l.type) {
      case Light::Type::Point:
      case Light::Type::Spot: {
        lights::PointLight s = lights::PointLight::from_light(l);
        s.camera_visible = l.camera_visible;
        s.cast_shadow = l.cast_shadow;
        const float p = s.power();
        if (!(p > 0.0f) || !std::isfinite(p)) break;
        I.entries.push_back({Kind::Point, uint32_t(points_.size())});
        points_.push_back(s);
        weights.push_back(p);
        break;
      }
      case Light::Type::Area: {
        lights::AreaLight a = lights::AreaLight::from_light(l);
        a.camera_visible = l.camera_visible;
        a.cast_shadow = l.cast_shadow;
        a.caustics = l.caustics_light;
        const float p = a.power();
        if (!(p > 0.0f) || !std::isfinite(p)) break;
        I.entries.push_back({Kind::Area, uint32_t(areas_.size())});
        areas_.push_back(a);
        weights.push_back(p);
        break;
      }
      case Light::Type::Sun: {
        lights::SunLight s = lights::SunLight::from_light(l);
        s.camera_visible = l.camera_visible;
        s.cast_shadow = l.cast_shadow;
        const float p = s.power(radius);
        if (!(p > 0.0f) || !std::isfinite(p)) break;
        I.entries.push_back({Kind::Sun, uint32_t(I.suns.size())});
        I.suns.push_back(s);
        weights.push_back(p);
        break;
      }
    }
  }

  // --- Emissive triangles (instances in order, primitives in order: keys come out sorted) ----
  std::vector<int32_t> emissive_material;  // per slot of the current instance, -1 = not emissive
  I.shading_instances.resize(scene.instances.size());  // sized once: triangles point in
  for (uint32_t inst_index = 0; inst_index < scene.instances.size(); ++inst_index) {
    const Instance& inst = scene.instances[inst_index];
    if (inst.mesh >= scene.meshes.size()) continue;
    emissive_material.assign(inst.slot_material.size(), -1);
    bool any = false;
    for (size_t slot = 0; slot < inst.slot_material.size(); ++slot) {
      const int32_t m = inst.slot_material[slot];
      if (m >= 0 && size_t(m) < materials.size() && materials[size_t(m)].is_emissive() &&
          luminance(materials[size_t(m)].average_emission()) > 0.0f) {
        emissive_material[slot] = m;
        any = true;
      }
    }
    if (!any) continue;
    const Mesh& mesh = scene.meshes[inst.mesh];
    const Transform& m = inst.object_to_world;
    const GeneratedMapping generated = generated_mapping(mesh);
    ShadingInstance& shading = I.shading_instances[inst_index];
    shading = {m, m.inverse(), mesh.positions.data(), mesh.indices.data()};
    shading.generated_scale = generated.scale;
    shading.generated_offset = generated.offset;
    for (uint32_t tri = 0; tri < mesh.triangle_count(); ++tri) {
      const int32_t slot = mesh.material_slot.empty() ? 0 : mesh.material_slot[tri];
      if (slot < 0 || size_t(slot) >= emissive_material.size()) continue;
      const int32_t mat = emissive_material[size_t(slot)];
      if (mat < 0) continue;
      const uint32_t* idx = &mesh.indices[size_t(tri) * 3];
      if (idx[0] >= mesh.positions.size() || idx[1] >= mesh.positions.size() ||
          idx[2] >= mesh.positions.size())
        continue;
      lights::TriangleLight t;
      t.p0 = m.point(mesh.positions[idx[0]]);
      t.e1 = m.point(mesh.positions[idx[1]]) - t.p0;
      t.e2 = m.point(mesh.positions[idx[2]]) - t.p0;
      const Vec3f n = cross(t.e1, t.e2);
      const float len = length(n);
      t.area = 0.5f * len;
      if (!(t.area > 0.0f) || !std::isfinite(t.area)) continue;  // degenerate: skip
      t.normal = n / len;
      if (!mesh.corner_uvs.empty()) {
        t.uv0 = mesh.corner_uvs[size_t(tri) * 3 + 0];
        t.uv1 = mesh.corner_uvs[size_t(tri) * 3 + 1];
        t.uv2 = mesh.corner_uvs[size_t(tri) * 3 + 2];
      }
      if (!mesh.corner_colors.empty()) {
        t.color0 = mesh.corner_colors[size_t(tri) * 3 + 0];
        t.color1 = mesh.corner_colors[size_t(tri) * 3 + 1];
        t.color2 = mesh.corner_colors[size_t(tri) * 3 + 2];
      }
      if (mesh.vertex_pointiness.size() == mesh.positions.size()) {
        t.pointiness0 = mesh.vertex_pointiness[idx[0]];
        t.pointiness1 = mesh.vertex_pointiness[idx[1]];
        t.pointiness2 = mesh.vertex_pointiness[idx[2]];
      }
      if (tri < mesh.triangle_island_random.size())
        t.island_random = mesh.triangle_island_random[tri];
      t.material = uint32_t(mat);
      t.instance = &shading;
      t.primitive = tri;
      t.finish();
      const float p = t.power(materials[size_t(mat)].average_emission());
      if (!(p > 0.0f) || !std::isfinite(p)) continue;
      I.entries.push_back({Kind::Triangle, uint32_t(I.triangles.size())});
      I.triangles.push_back(t);
      I.triangle_keys.push_back(triangle_key(inst_index, tri));
      weights.push_back(p);
    }
  }

  // --- World ---------------------------------------------------------------------------------
  const World& w = scene.world;
  const Spectrum world_average = I.world.set(w, scene);
  {
    const float p = 4.0f * kPi * kPi * radius * radius * luminance(world_average);
    if (p > 0.0f && std::isfinite(p)) {
      I.world_enabled = true;
      if (I.world.environment) {
        I.entries.push_back({Kind::World, 0});
        weights.push_back(p);
      }
    } else {
      I.world.constant = Spectrum(0.0f);
    }
  }

  if (w.camera_view) {
    I.camera_view = true;
    const Spectrum average = I.camera.set(*w.camera_view, scene);
    I.camera_enabled = !is_black(average) && std::isfinite(luminance(average));
  }

  single_area_ = areas_.size() == 1 && points_.empty() && I.suns.empty();
  only_area_ = single_area_ && I.entries.size() == 1;
  emitters_ = I.entries.size();

  // --- Selection CDF, and each light's own probability for MIS --------------------------------
  I.selection = Distribution1D(weights);
  for (uint32_t e = 0; e < I.entries.size(); ++e) {
    const float pmf = I.selection.pmf(e);
    const Entry& en = I.entries[e];
    switch (en.kind) {
      case Kind::Point:
        points_[en.index].select_pmf = pmf;
        break;
      case Kind::Area:
        areas_[en.index].select_pmf = pmf;
        if (areas_[en.index].area > 0.0f) areas_[en.index].area_pdf = pmf / areas_[en.index].area;
        break;
      case Kind::Sun:
        I.suns[en.index].select_pmf = pmf;
        break;
      case Kind::Triangle:
        I.triangles[en.index].select_pmf = pmf;
        break;
      case Kind::World:
        I.world_pmf = pmf;
        break;
    }
  }
}

LightSampler::~LightSampler() = default;

bool LightSampler::has_environment() const {
  return impl_->world_enabled;
}

LightSample LightSampler::sample_any(Vec3f ref, float u_select, Vec2f u) const {
  const Impl& I = *impl_;
  LightSample s;
  if (I.entries.empty()) return s;
  // A single emitter (a Cornell box's lamp) needs no CDF search: its pmf is 1.
  float pmf = I.entries.size() == 1 ? 1.0f : 0.0f;
  const Entry e =
      I.entries.size() == 1 ? I.entries[0] : I.entries[I.selection.sample_discrete(u_select, &pmf)];
  if (!(pmf > 0.0f)) return s;
  bool ok = false;
  switch (e.kind) {
    case Kind::Point:
      ok = points_[e.index].sample(ref, u, s);
      s.cast_shadow = points_[e.index].cast_shadow;
      break;
    case Kind::Area:
      ok = areas_[e.index].sample(ref, u, s);
      s.cast_shadow = areas_[e.index].cast_shadow;
      s.caustics = areas_[e.index].caustics;
      break;
    case Kind::Sun:
      ok = I.suns[e.index].sample(ref, u, s);
      s.cast_shadow = I.suns[e.index].cast_shadow;
      break;
    case Kind::Triangle: {
      const lights::TriangleLight& t = I.triangles[e.index];
      ok = t.sample(ref, u, I.materials[t.material], s);
      break;
    }
    case Kind::World: {  // an image world (a constant one is never in the CDF)
      float pdf = 0.0f;
      const Vec3f d = I.world.environment->sample(u, &pdf);
      if (pdf > 0.0f) {
        s.direction = d;
        s.radiance = I.world.eval(d);
        s.position = ref + d;
        s.normal = -d;
        s.distance = std::numeric_limits<float>::infinity();
        s.pdf = pdf;
        s.is_delta = false;
        s.is_infinite = true;
        s.valid = true;
        ok = true;
      }
      break;
    }
  }
  if (!ok || !(s.pdf > 0.0f) || !std::isfinite(s.pdf) || !is_finite(s.radiance))
    s = LightSample{};  // one named result, as sample_only_area
  else
    s.pdf *= pmf;
  return s;
}

float LightSampler::pdf_triangle(uint32_t instance, uint32_t primitive, Vec3f ref_position,
                                 Vec3f light_position, Vec3f /*light_normal*/) const {
  // The stored geometric normal is used (as sample() does), not the caller's normal.
  const Impl& I = *impl_;
  const uint64_t key = triangle_key(instance, primitive);
  const auto it = std::lower_bound(I.triangle_keys.begin(), I.triangle_keys.end(), key);
  if (it == I.triangle_keys.end() || *it != key) return 0.0f;
  const lights::TriangleLight& t = I.triangles[size_t(it - I.triangle_keys.begin())];
  const float pdf = t.pdf(ref_position, light_position) * t.select_pmf;
  return std::isfinite(pdf) ? pdf : 0.0f;
}

void LightSampler::fill_hit(const lights::PointLight& l, Vec3f origin, Vec3f direction, float t,
                            LightHit& hit) {
  l.fill_hit(origin, direction, t, hit);
  hit.pdf *= l.select_pmf;
  hit.camera_visible = l.camera_visible;
}

void LightSampler::fill_hit(const lights::AreaLight& l, Vec3f origin, Vec3f direction, float t,
                            LightHit& hit) {
  l.fill_hit(origin, direction, t, hit);
  hit.pdf *= l.select_pmf;
  hit.area_pdf = l.area_pdf;
  hit.camera_visible = l.camera_visible;
  hit.caustics = l.caustics;
}

bool LightSampler::intersect_any(Vec3f origin, Vec3f direction, float t_max, LightHit& hit) const {
  float best = t_max;
  const lights::PointLight* point = nullptr;
  const lights::AreaLight* area = nullptr;
  for (const lights::PointLight& s : points_) {
    const float t = s.intersect_t(origin, direction, best);
    if (t > 0.0f) {
      best = t;
      point = &s;
    }
  }
  for (const lights::AreaLight& a : areas_) {
    const float t = a.intersect_t(origin, direction, best);
    if (t > 0.0f) {
      best = t;
      area = &a;
      point = nullptr;
    }
  }
  if (point) {
    fill_hit(*point, origin, direction, best, hit);
    return true;
  }
  if (area) {
    fill_hit(*area, origin, direction, best, hit);
    return true;
  }
  // Sun discs sit at infinity: only rays that escape the scene reach them, i.e. rays whose
  // t_max is still unbounded (Ray::t_max defaults to 1e30, or +inf).
  if (t_max >= 1e30f) {
    for (const lights::SunLight& s : impl_->suns) {
      if (s.hit(direction)) {
        s.fill_hit(origin, direction, hit);
        hit.pdf *= s.select_pmf;
        hit.camera_visible = s.camera_visible;
        return true;
      }
    }
  }
  return false;
}

Spectrum LightSampler::environment(Vec3f direction) const {
  const Impl& I = *impl_;
  return I.world_enabled ? I.world.eval(direction) : Spectrum(0.0f);
}

Spectrum LightSampler::camera_environment(Vec3f direction) const {
  const Impl& I = *impl_;
  if (!I.camera_view) return environment(direction);
  return I.camera_enabled ? I.camera.eval(direction) : Spectrum(0.0f);
}

bool LightSampler::has_camera_environment() const {
  const Impl& I = *impl_;
  return I.camera_view ? I.camera_enabled : I.world_enabled;
}

float LightSampler::pdf_environment(Vec3f direction) const {
  const Impl& I = *impl_;
  return I.world_pmf > 0.0f ? I.world.environment->pdf(direction) * I.world_pmf : 0.0f;
}

bool LightSampler::has_camera_visible_lights() const {
  const Impl& I = *impl_;
  const auto visible = [](const auto& l) { return l.camera_visible; };
  return std::any_of(points_.begin(), points_.end(), visible) ||
         std::any_of(areas_.begin(), areas_.end(), visible) ||
         std::any_of(I.suns.begin(), I.suns.end(), visible);
}

}  // namespace gdpt
