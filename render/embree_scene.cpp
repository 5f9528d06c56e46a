#include "render/embree_scene.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <xmmintrin.h>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

#include "core/shadow_terminator.h"
#include "scene/generated_mapping.h"
#include "shaders/object_nodes.h"

namespace gdpt {

namespace {
void compute_unit_normals(const Vec3f* positions, const uint32_t* indices, size_t tris,
                          float winding, float (*out)[4]);
}  // namespace

EmbreeScene::EmbreeScene(const Scene& scene, int32_t default_material)
    : scene_(&scene), default_material_(default_material) {
  // Embree's device configuration: $GDPT_EMBREE_CONFIG when set (e.g. "isa=sse4.2", "verbose=2",
  // for benchmarking Embree's kernels on a given machine), else its AVX2 kernels at most. On an
  // AVX-512 CPU Embree would pick its AVX-512 kernels, which render slower on Zen 5
  // (docs/performance.md).
  const char* config = std::getenv("GDPT_EMBREE_CONFIG");
  device_ = rtcNewDevice(config ? config : "max_isa=avx2");
  if (!device_) throw std::runtime_error("Embree: rtcNewDevice failed");

  // How often each mesh is placed: a mesh placed once is flattened into the top level in world
  // space (one BVH traversal instead of two); a mesh placed several times is built once in object
  // space and instanced, so memory does not grow with the instance count. Tiny shared meshes
  // (kFlattenBudget triangles over all their placements, e.g. a 12-triangle box placed twice) are
  // flattened too: the copies cost less memory than an instance's own bookkeeping, and a ray then
  // skips the instance transform and the second traversal (Cornell box with two instanced
  // boxes: fewer instructions per sample).
  constexpr size_t kFlattenBudget = 256;
  std::vector<size_t> uses(scene.meshes.size(), 0);
  for (const Instance& inst : scene.instances)
    if (inst.mesh < scene.meshes.size()) ++uses[inst.mesh];
  std::vector<bool> instanced(scene.meshes.size(), false);
  for (size_t m = 0; m < scene.meshes.size(); ++m)
    instanced[m] = uses[m] >= 2 && uses[m] * scene.meshes[m].triangle_count() > kFlattenBudget;

  auto new_triangle_geometry = [&](const Mesh& mesh, const Transform* to_world) {
    const size_t tris = mesh.triangle_count();
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree-owned buffers: they carry the padding Embree's SIMD loads need.
    auto* vb = static_cast<Vec3f*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(Vec3f), mesh.positions.size()));
    for (size_t v = 0; v < mesh.positions.size(); ++v)
      vb[v] = to_world ? to_world->point(mesh.positions[v]) : mesh.positions[v];
    auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), tris));
    std::memcpy(ib, mesh.indices.data(), tris * 3 * sizeof(uint32_t));
    rtcCommitGeometry(geom);
    return geom;
  };

  // --- Bottom level: one scene per instanced mesh ---
  mesh_scenes_.assign(scene.meshes.size(), nullptr);
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const Mesh& mesh = scene.meshes[m];
    const size_t tris = mesh.triangle_count();
    if (tris == 0 || mesh.positions.empty()) continue;
    for (uint32_t idx : mesh.indices)
      if (idx >= mesh.positions.size())
        throw std::invalid_argument("mesh " + std::to_string(m) + ": vertex index " +
                                    std::to_string(idx) + " out of range");
    triangles_ += tris;
    if (!instanced[m]) continue;
    RTCGeometry geom = new_triangle_geometry(mesh, nullptr);
    RTCScene s = rtcNewScene(device_);
    rtcSetSceneBuildQuality(s, RTC_BUILD_QUALITY_HIGH);
    rtcAttachGeometryByID(s, geom, 0);
    rtcReleaseGeometry(geom);
    rtcCommitScene(s);
    mesh_scenes_[m] = s;
  }

  // --- Top level: instances of shared meshes, world-space copies of single-use meshes ---
  top_ = rtcNewScene(device_);
  // Sized once: hits keep pointers into it.
  shading_instances_.resize(scene.instances.size());
  for (size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& inst = scene.instances[i];
    if (inst.mesh >= scene.meshes.size()) continue;
    const Mesh& mesh = scene.meshes[inst.mesh];
    if (mesh.triangle_count() == 0 || mesh.positions.empty()) continue;
    const Transform& T = inst.object_to_world;
    shading_instances_[i] = {T, T.inverse(), mesh.positions.data(), mesh.indices.data()};
    shading_instances_[i].terminator_frequency =
        terminator_frequency(inst.terminator_shading_offset);
    const float det = T.m[0][0] * (T.m[1][1] * T.m[2][2] - T.m[1][2] * T.m[2][1]) -
                      T.m[0][1] * (T.m[1][0] * T.m[2][2] - T.m[1][2] * T.m[2][0]) +
                      T.m[0][2] * (T.m[1][0] * T.m[2][1] - T.m[1][1] * T.m[2][0]);
    if (!(std::fabs(det) > 0.0f) || !std::isfinite(det)) continue;  // flattened: invisible
    RTCGeometry geom;
    const Vec3f* world_positions = nullptr;
    if (mesh_scenes_[inst.mesh]) {
      geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_INSTANCE);
      rtcSetGeometryInstancedScene(geom, mesh_scenes_[inst.mesh]);
      // Embree's RTC_FORMAT_FLOAT3X4_ROW_MAJOR matches our row-major 3x4 layout.
      rtcSetGeometryTransform(geom, 0, RTC_FORMAT_FLOAT3X4_ROW_MAJOR, &T.m[0][0]);
      rtcCommitGeometry(geom);
    } else {
      geom = new_triangle_geometry(mesh, &T);
      // The top-level scene keeps the geometry, hence this buffer, alive.
      world_positions =
          static_cast<const Vec3f*>(rtcGetGeometryBufferData(geom, RTC_BUFFER_TYPE_VERTEX, 0));
    }
    // Ray visibility: Embree skips the geometry for rays whose mask shares no bit with this.
    rtcSetGeometryMask(geom, inst.visibility);
    rtcCommitGeometry(geom);
    const unsigned id = rtcAttachGeometry(top_, geom);
    rtcReleaseGeometry(geom);
    if (id >= instances_.size()) instances_.resize(id + 1);
    InstanceData& d = instances_[id];
    d.index = uint32_t(i);
    if (top_ids_.size() <= i) top_ids_.resize(i + 1, 0);
    top_ids_[i] = id;
    d.terminator_cutoff = inst.terminator_geometry_offset;
    d.shading = &shading_instances_[i];
    d.world_space = world_positions != nullptr;
    d.winding = det < 0.0f ? -1.0f : 1.0f;
    d.positions = world_positions ? world_positions : mesh.positions.data();
    d.object_positions = mesh.positions.data();
    d.indices = mesh.indices.data();
    const size_t tris = mesh.triangle_count();
    if (world_positions) {
      HugePageVector<UnitNormal>& normals = unit_normals_.emplace_back(tris);
      compute_unit_normals(world_positions, d.indices, tris, d.winding, &normals[0].v);
      d.unit_normals = normals.data();
    }
    if (!mesh.corner_normals.empty()) {
      d.corner_normals = mesh.corner_normals.data();
      d.corner_normal_tris = uint32_t(std::min(mesh.corner_normals.size() / 3, tris));
    }
    if (!mesh.vertex_normals.empty()) d.vertex_normals = mesh.vertex_normals.data();
    if (!mesh.corner_uvs.empty()) {
      d.corner_uvs = mesh.corner_uvs.data();
      d.corner_uv_tris = uint32_t(std::min(mesh.corner_uvs.size() / 3, tris));
    }
    if (!mesh.corner_colors.empty()) {
      d.corner_colors = mesh.corner_colors.data();
      d.corner_color_tris = uint32_t(std::min(mesh.corner_colors.size() / 3, tris));
    }
    if (mesh.vertex_pointiness.size() == mesh.positions.size())
      d.vertex_pointiness = mesh.vertex_pointiness.data();
    if (!mesh.triangle_island_random.empty()) {
      d.triangle_island_random = mesh.triangle_island_random.data();
      d.island_random_tris = uint32_t(std::min(mesh.triangle_island_random.size(), tris));
    }
    if (!mesh.corner_tangents.empty()) {
      if (mesh.corner_tangent_signs.size() != mesh.corner_tangents.size())
        throw std::invalid_argument("mesh " + std::to_string(inst.mesh) + ": " +
                                    std::to_string(mesh.corner_tangents.size()) +
                                    " corner tangents but " +
                                    std::to_string(mesh.corner_tangent_signs.size()) + " signs");
      d.corner_tangents = mesh.corner_tangents.data();
      d.corner_tangent_signs = mesh.corner_tangent_signs.data();
      d.corner_tangent_tris = uint32_t(std::min(mesh.corner_tangents.size() / 3, tris));
    }
    // Slot -> material with the default applied (-1 and out-of-range indices).
    auto resolve = [&](int32_t mat) {
      return (mat >= 0 && mat < default_material_) ? mat : default_material_;
    };
    for (int32_t m : inst.slot_material) d.slot_materials.push_back(resolve(m));
    auto material_of = [&](size_t prim) {
      const int32_t slot = prim < mesh.material_slot.size() ? mesh.material_slot[prim] : 0;
      return slot >= 0 && size_t(slot) < d.slot_materials.size() ? d.slot_materials[size_t(slot)]
                                                                 : default_material_;
    };
    d.uniform_material = material_of(0);
    for (size_t prim = 1; prim < tris && d.uniform_material >= 0; ++prim)
      if (material_of(prim) != d.uniform_material) d.uniform_material = -1;
    if (d.uniform_material < 0) {
      d.material_slot = mesh.material_slot.data();
      d.material_slot_count = uint32_t(mesh.material_slot.size());
    }
    const Transform inv = T.inverse();
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 3; ++r) {
        d.to_world_cols[c][r] = T.m[r][c];
        // The inverse transpose's column c = the inverse's row c.
        if (c < 3) d.normal_cols[c][r] = inv.m[c][r];
      }
    instanced_triangles_ += mesh.triangle_count();
  }
  rtcSetSceneBuildQuality(top_, RTC_BUILD_QUALITY_MEDIUM);
  rtcCommitScene(top_);
  // Errors here are programming errors (bad buffers); surface them instead of rendering garbage.
  const RTCError err = rtcGetDeviceError(device_);
  if (err != RTC_ERROR_NONE)
    throw std::runtime_error("Embree: scene build failed with error " + std::to_string(int(err)));
  RTCBounds b;
  rtcGetSceneBounds(top_, &b);
  const float extent = std::max({std::fabs(b.lower_x), std::fabs(b.lower_y), std::fabs(b.lower_z),
                                 std::fabs(b.upper_x), std::fabs(b.upper_y), std::fabs(b.upper_z)});
  // An empty scene has inverted (infinite) bounds: keep the unit scale.
  if (std::isfinite(extent) && extent > 0.0f) offset_scale_ = std::min(extent, 1.0f);
}

void EmbreeScene::set_materials(std::span<const Material> materials) {
  materials_ = materials;
  auto reads = [&](int32_t m) {
    return m >= 0 && size_t(m) < materials.size() && materials[size_t(m)].reads_color_attribute();
  };
  auto perturbs = [&](int32_t m) {
    return m >= 0 && size_t(m) < materials.size() &&
           (materials[size_t(m)].has_normal_map() || !materials[size_t(m)].bumps().empty());
  };
  auto reads_coords = [&](int32_t m) {
    return m >= 0 && size_t(m) < materials.size() && materials[size_t(m)].reads_coordinates();
  };
  auto reads_attributes = [&](int32_t m) {
    return m >= 0 && size_t(m) < materials.size() &&
           materials[size_t(m)].reads_surface_attributes();
  };
  for (InstanceData& d : instances_) {
    d.writes_color =
        d.corner_colors != nullptr || reads(d.uniform_material) || reads(default_material_);
    d.perturbs_normal = perturbs(d.uniform_material) || perturbs(default_material_);
    d.writes_coords = reads_coords(d.uniform_material) || reads_coords(default_material_);
    d.writes_attributes =
        reads_attributes(d.uniform_material) || reads_attributes(default_material_);
    for (int32_t m : d.slot_materials) {
      d.writes_attributes = d.writes_attributes || reads_attributes(m);
      d.writes_color = d.writes_color || reads(m);
      d.perturbs_normal = d.perturbs_normal || perturbs(m);
      d.writes_coords = d.writes_coords || reads_coords(m);
    }
    if (d.writes_coords) set_generated_mapping(d, scene_->meshes[scene_->instances[d.index].mesh]);
  }
}

void EmbreeScene::set_generated_mapping(InstanceData& d, const Mesh& mesh) {
  const GeneratedMapping g = generated_mapping(mesh);
  for (int k = 0; k < 3; ++k) {
    d.generated_scale[k] = g.scale[k];
    d.generated_offset[k] = g.offset[k];
  }
}

EmbreeScene::~EmbreeScene() {
  if (top_) rtcReleaseScene(top_);
  for (RTCScene s : mesh_scenes_)
    if (s) rtcReleaseScene(s);
  if (device_) rtcReleaseDevice(device_);
}

void EmbreeScene::intersect_stream(const Ray* rays, const bool* valid, int n, bool* found,
                                   SurfaceHit* hits) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  constexpr int kChunk = 64;
  alignas(16) RTCRayHit rh[kChunk];
  for (int first = 0; first < n; first += kChunk) {
    const int m = std::min(kChunk, n - first);
    for (int j = 0; j < m; ++j) detail::to_embree(rays[first + j], valid[first + j], rh[j]);
    rtcIntersect1M(top_, &ctx, rh, unsigned(m), sizeof(RTCRayHit));
    for (int j = 0; j < m; ++j) {
      const int i = first + j;
      found[i] = valid[i] && read_hit(rh[j], rays[i].direction, hits[i]);
    }
  }
}

namespace {

// complete_hit()'s vector work in SSE2 lanes (x, y, z; w = 0). Each lane does the scalar code's
// operations in the same order (no FMA contraction on the x86-64 baseline), so hits are
// bit-identical to the Vec3f form, which GCC half-vectorised with shuffles and spills.
inline __m128 load3(const Vec3f& v) {
  const __m128 xy = _mm_loadl_pi(_mm_setzero_ps(), reinterpret_cast<const __m64*>(&v.x));
  return _mm_movelh_ps(xy, _mm_load_ss(&v.z));
}
inline __m128 load2(const Vec2f& v) {
  return _mm_loadl_pi(_mm_setzero_ps(), reinterpret_cast<const __m64*>(&v.x));
}
inline void store3(Vec3f& out, __m128 a) {
  _mm_storel_pi(reinterpret_cast<__m64*>(&out.x), a);
  _mm_store_ss(&out.z, _mm_movehl_ps(a, a));
}
// (a.x b.x + a.y b.y) + a.z b.z, as dot().
inline float dot3(__m128 a, __m128 b) {
  const __m128 m = _mm_mul_ps(a, b);
  const __m128 y = _mm_shuffle_ps(m, m, _MM_SHUFFLE(1, 1, 1, 1));
  return _mm_cvtss_f32(_mm_add_ss(_mm_add_ss(m, y), _mm_movehl_ps(m, m)));
}
inline __m128 cross3(__m128 a, __m128 b) {
  const __m128 a_yzx = _mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 0, 2, 1));
  const __m128 b_zxy = _mm_shuffle_ps(b, b, _MM_SHUFFLE(3, 1, 0, 2));
  const __m128 a_zxy = _mm_shuffle_ps(a, a, _MM_SHUFFLE(3, 1, 0, 2));
  const __m128 b_yzx = _mm_shuffle_ps(b, b, _MM_SHUFFLE(3, 0, 2, 1));
  return _mm_sub_ps(_mm_mul_ps(a_yzx, b_zxy), _mm_mul_ps(a_zxy, b_yzx));
}
// (a w + b u) + c v: barycentric interpolation in the order of the scalar code.
inline __m128 interpolate(__m128 a, __m128 b, __m128 c, __m128 w, __m128 u, __m128 v) {
  return _mm_add_ps(_mm_add_ps(_mm_mul_ps(a, w), _mm_mul_ps(b, u)), _mm_mul_ps(c, v));
}
// Row r: (M[r][0] x + M[r][1] y) + M[r][2] z, from M's columns.
inline __m128 linear3(const float (*cols)[4], __m128 v) {
  const __m128 x = _mm_shuffle_ps(v, v, _MM_SHUFFLE(0, 0, 0, 0));
  const __m128 y = _mm_shuffle_ps(v, v, _MM_SHUFFLE(1, 1, 1, 1));
  const __m128 z = _mm_shuffle_ps(v, v, _MM_SHUFFLE(2, 2, 2, 2));
  return _mm_add_ps(
      _mm_add_ps(_mm_mul_ps(_mm_load_ps(cols[0]), x), _mm_mul_ps(_mm_load_ps(cols[1]), y)),
      _mm_mul_ps(_mm_load_ps(cols[2]), z));
}
inline __m128 normalize_or(__m128 v, __m128 fallback) {
  const float l2 = dot3(v, v);
  // 0 < l2 < inf: fails for zero, infinite and NaN lengths.
  if (!(l2 > 0.0f && l2 < std::numeric_limits<float>::infinity())) return fallback;
  // sqrtps, not std::sqrt: the same value without the errno fallback call, whose presence made
  // complete_hit() save registers and spill.
  return _mm_div_ps(v, _mm_sqrt_ps(_mm_set1_ps(l2)));
}

void compute_unit_normals(const Vec3f* positions, const uint32_t* indices, size_t tris,
                          float winding, float (*out)[4]) {
  // In parallel (the caller's arena): large meshes would otherwise add to the export time.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tris, 16384),
                    [&](const tbb::blocked_range<size_t>& r) {
                      const __m128 zero = _mm_setzero_ps(), w = _mm_set1_ps(winding);
                      for (size_t t = r.begin(); t != r.end(); ++t) {
                        const uint32_t* idx = indices + t * 3;
                        const __m128 p0 = load3(positions[idx[0]]), p1 = load3(positions[idx[1]]),
                                     p2 = load3(positions[idx[2]]);
                        const __m128 e = cross3(_mm_sub_ps(p1, p0), _mm_sub_ps(p2, p0));
                        _mm_store_ps(out[t], normalize_or(_mm_mul_ps(e, w), zero));
                      }
                    });
}

}  // namespace

SurfaceAttributes EmbreeScene::attributes_at(const InstanceData& d, uint32_t primitive,
                                             const uint32_t* idx, float u, float v) {
  SurfaceAttributes a;
  a.barycentric = Vec2f(u, v);
  if (d.vertex_pointiness) {
    const float* P = d.vertex_pointiness;
    a.pointiness = (1.0f - u - v) * P[idx[0]] + u * P[idx[1]] + v * P[idx[2]];
  }
  if (primitive < d.island_random_tris) a.random_per_island = d.triangle_island_random[primitive];
  return a;
}

void EmbreeScene::complete_hit(uint32_t top_id, uint32_t primitive, float u, float v,
                               const Vec3f& dir, SurfaceHit& hit) const {
  const InstanceData& d = instances_[top_id];
  const uint32_t* idx = d.indices + size_t(primitive) * 3;
  const float w = 1.0f - u - v;
  hit.instance = d.index;
  hit.primitive = primitive;
  hit.bary = Vec2f(u, v);
  hit.shading_instance = d.shading;
  const __m128 W = _mm_set1_ps(w), U = _mm_set1_ps(u), V = _mm_set1_ps(v);

  const __m128 p0 = load3(d.positions[idx[0]]), p1 = load3(d.positions[idx[1]]),
               p2 = load3(d.positions[idx[2]]);
  const __m128 D = load3(dir);
  // Degenerate triangles have no normal: face the ray so shading stays finite.
  const __m128 minus_dir = _mm_xor_ps(D, _mm_set1_ps(-0.0f));
  __m128 position, ng;
  if (d.world_space) {
    position = interpolate(p0, p1, p2, W, U, V);
    ng = _mm_load_ps(d.unit_normals[primitive].v);
    if (_mm_movemask_ps(_mm_cmpneq_ps(ng, _mm_setzero_ps())) == 0) ng = minus_dir;
  } else {
    const __m128 e = cross3(_mm_sub_ps(p1, p0), _mm_sub_ps(p2, p0));
    const __m128 p = interpolate(p0, p1, p2, W, U, V);
    position = _mm_add_ps(linear3(d.to_world_cols, p), _mm_load_ps(d.to_world_cols[3]));
    ng = normalize_or(linear3(d.normal_cols, e), minus_dir);
  }
  store3(hit.position, position);
  store3(hit.geometric_normal, ng);
  hit.front_facing = dot3(D, ng) < 0.0f;

  __m128 ns = ng;
  if (primitive < d.corner_normal_tris) {
    const Vec3f* N = d.corner_normals + size_t(primitive) * 3;
    const __m128 n = interpolate(load3(N[0]), load3(N[1]), load3(N[2]), W, U, V);
    ns = normalize_or(linear3(d.normal_cols, n), ng);
  } else if (d.vertex_normals) {
    const Vec3f* N = d.vertex_normals;
    const __m128 n = interpolate(load3(N[idx[0]]), load3(N[idx[1]]), load3(N[idx[2]]), W, U, V);
    ns = normalize_or(linear3(d.normal_cols, n), ng);
  }
  store3(hit.shading_normal, ns);
  __m128 uv = _mm_setzero_ps();
  if (primitive < d.corner_uv_tris) {
    const Vec2f* T = d.corner_uvs + size_t(primitive) * 3;
    uv = interpolate(load2(T[0]), load2(T[1]), load2(T[2]), W, U, V);
  }
  _mm_storel_pi(reinterpret_cast<__m64*>(&hit.uv.x), uv);
  if (d.writes_color) [[unlikely]] {
    __m128 color = _mm_setzero_ps();
    if (primitive < d.corner_color_tris) {
      const Vec3f* C = d.corner_colors + size_t(primitive) * 3;
      color = interpolate(load3(C[0]), load3(C[1]), load3(C[2]), W, U, V);
    }
    store3(hit.color, color);
  }
  if (d.writes_attributes) [[unlikely]]
    hit.attributes = attributes_at(d, primitive, idx, u, v);
  if (d.writes_coords) [[unlikely]] {
    const Vec3f* P = d.object_positions;
    const __m128 object =
        interpolate(load3(P[idx[0]]), load3(P[idx[1]]), load3(P[idx[2]]), W, U, V);
    store3(hit.coords.object, object);
    hit.coords.position = hit.position;
    hit.coords.normal_cols = d.normal_cols;
    hit.coords.uv_tangent = Vec3f(0.0f);
    if (primitive < d.corner_tangent_tris) {
      const Vec3f* T = d.corner_tangents + size_t(primitive) * 3;
      store3(hit.coords.uv_tangent, interpolate(load3(T[0]), load3(T[1]), load3(T[2]), W, U, V));
    }
    store3(hit.coords.generated, _mm_add_ps(_mm_mul_ps(object, _mm_load_ps(d.generated_scale)),
                                            _mm_load_ps(d.generated_offset)));
  }

  if (d.uniform_material >= 0) {
    hit.material = d.uniform_material;
  } else {
    const int32_t slot = primitive < d.material_slot_count ? d.material_slot[primitive] : 0;
    hit.material = slot >= 0 && size_t(slot) < d.slot_materials.size()
                       ? d.slot_materials[size_t(slot)]
                       : default_material_;
  }
  hit.perturbed = false;
  if (d.perturbs_normal) [[unlikely]] {
    hit.unperturbed_normal = hit.shading_normal;
    perturb_normal(d, primitive, u, v, hit);
    hit.perturbed = !(hit.shading_normal == hit.unperturbed_normal);
  }
}

namespace {

// The linear part of a transform (its columns, InstanceData::to_world_cols) applied to v (a
// direction, or a position whose translation cancels in differences).
Vec3f world_direction(const float (*cols)[4], Vec3f v) {
  Vec3f w;
  for (int r = 0; r < 3; ++r) w[r] = cols[0][r] * v.x + cols[1][r] * v.y + cols[2][r] * v.z;
  return w;
}

}  // namespace

void EmbreeScene::world_corners(const InstanceData& d, uint32_t prim, SmoothTriangle& t) {
  const uint32_t* idx = d.indices + size_t(prim) * 3;
  for (int i = 0; i < 3; ++i) {
    const Vec3f p = d.positions[idx[i]];
    t.p[i] = d.world_space
                 ? p
                 : world_direction(d.to_world_cols, p) +
                       Vec3f(d.to_world_cols[3][0], d.to_world_cols[3][1], d.to_world_cols[3][2]);
  }
}

bool EmbreeScene::world_smooth_triangle(const InstanceData& d, uint32_t prim, SmoothTriangle& t) {
  const bool corner = prim < d.corner_normal_tris;
  if (!corner && !d.vertex_normals) return false;
  const uint32_t* idx = d.indices + size_t(prim) * 3;
  world_corners(d, prim, t);
  for (int i = 0; i < 3; ++i) {
    const Vec3f n = corner ? d.corner_normals[size_t(prim) * 3 + i] : d.vertex_normals[idx[i]];
    t.n[i] = normalize(world_direction(d.normal_cols, n));
  }
  return true;
}

void EmbreeScene::world_triangle(const SurfaceHit& hit, SmoothTriangle& t) const {
  const InstanceData& d = instances_[top_ids_[hit.instance]];
  if (world_smooth_triangle(d, hit.primitive, t)) return;
  world_corners(d, hit.primitive, t);
  for (int i = 0; i < 3; ++i) t.n[i] = hit.geometric_normal;
}

bool EmbreeScene::lifts_shadow_rays(const SurfaceHit& hit) const {
  const InstanceData& d = instances_[top_ids_[hit.instance]];
  return d.terminator_cutoff > 0.0f &&
         (hit.primitive < d.corner_normal_tris || d.vertex_normals != nullptr);
}

Vec3f EmbreeScene::shadow_ray_start(const SurfaceHit& hit, Vec3f l) const {
  const InstanceData& d = instances_[top_ids_[hit.instance]];
  const float side = hit.front_facing ? 1.0f : -1.0f;
  const Vec3f ns = (hit.perturbed ? hit.unperturbed_normal : hit.shading_normal) * side;
  Vec3f ng_side;
  const float amount =
      terminator_lift_amount(d.terminator_cutoff, ns, hit.geometric_normal * side, l, ng_side);
  SmoothTriangle t;
  if (amount == 0.0f || !world_smooth_triangle(d, hit.primitive, t)) return hit.position;
  const Vec3f b(1.0f - hit.bary.x - hit.bary.y, hit.bary.x, hit.bary.y);
  return hit.position + smooth_surface_lift(t, b, ng_side) * amount;
}

namespace {

// out = v / |v| when that is finite and non-zero (else out keeps its value); whether it was set.
bool set_unit(Vec3f v, Vec3f& out) {
  const float l2 = length_squared(v);
  if (!(l2 > 0.0f) || !std::isfinite(l2)) return false;
  out = v / std::sqrt(l2);
  return true;
}

}  // namespace

// Cycles builds the normal-mapped normal in object space, x t + y s (n x t) + z n, and moves it
// to world space as a normal. Here the same combination is formed in world space around the
// (unit) shading normal: the tangent moves as a direction, keeping its object-space length (the
// interpolated MikkTSpace tangent is ~unit there, as the normal), and a mirroring transform
// flips n x t. Equal to Cycles' up to normalisation for rotations, mirrors and uniform scales.
void EmbreeScene::perturb_normal(const InstanceData& d, uint32_t primitive, float u, float v,
                                 SurfaceHit& hit) const {
  if (size_t(hit.material) >= materials_.size()) return;
  const Material& material = materials_[size_t(hit.material)];
  const std::vector<BumpDesc>& bumps = material.bumps();
  size_t k = 0;
  if (k < bumps.size() && bumps[k].replaces_normal) bump_normal(d, primitive, hit, material, k++);
  if (material.has_normal_map()) normal_map_normal(d, primitive, u, v, hit, material);
  for (; k < bumps.size(); ++k) bump_normal(d, primitive, hit, material, k);
}

void EmbreeScene::normal_map_normal(const InstanceData& d, uint32_t primitive, float u, float v,
                                    SurfaceHit& hit, const Material& material) const {
  if (primitive >= d.corner_tangent_tris) return;
  const float w = 1.0f - u - v;
  const Vec3f* T = d.corner_tangents + size_t(primitive) * 3;
  const float* S = d.corner_tangent_signs + size_t(primitive) * 3;
  const Vec3f t_object = T[0] * w + T[1] * u + T[2] * v;
  const float sign = S[0] * w + S[1] * u + S[2] * v;
  Vec3f t = world_direction(d.to_world_cols, t_object);
  const float tl = length(t);
  if (!(tl > 0.0f) || !std::isfinite(tl)) return;  // no tangent here (no UVs): unchanged
  t = t * (length(t_object) / tl);
  const Vec3f n = hit.shading_normal;
  const Vec3f b = cross(n, t) * (sign * d.winding);
  const Vec3f c = material.normal_map_direction(shading_context(d, hit));
  set_unit(t * c.x + b * c.y + n * c.z, hit.shading_normal);
}

// A vector displacement's height is dot(M V, n) for the frame M of its space and the interpolated
// normal n (world, facing the ray), i.e. dot(V, M^T n): this returns M^T n. Tangent space (Cycles'
// svm_node_vector_displacement): x along the corner tangent t, y along the object-space normal
// n_o = normalize(O^T n) (O: the object's linear part), z along n_o x t, so M = O [t n_o b] and,
// b being normal to n_o, M^T n = |O^T n| (t . n_o, 1, 0). Without a tangent here (no UV map) the
// x term is dropped (Cycles then takes dP/du, which lies nearly in the surface too).
Vec3f EmbreeScene::displacement_along(const InstanceData& d, uint32_t primitive,
                                      const SurfaceHit& hit, const BumpDesc& bump) {
  // Cycles dots with sd->N, which faces the incoming ray: on a back face the height changes sign
  // (bump_normal then tilts the surface's own normal, flipped, by it).
  const Vec3f n = hit.front_facing ? hit.shading_normal : -hit.shading_normal;
  if (bump.vector_space == BumpDesc::VectorSpace::World) return n;
  if (bump.vector_space == BumpDesc::VectorSpace::None) return Vec3f(0.0f);
  const auto& cols = d.to_world_cols;
  const Vec3f on(dot(Vec3f(cols[0][0], cols[0][1], cols[0][2]), n),
                 dot(Vec3f(cols[1][0], cols[1][1], cols[1][2]), n),
                 dot(Vec3f(cols[2][0], cols[2][1], cols[2][2]), n));  // O^T n
  if (bump.vector_space == BumpDesc::VectorSpace::Object) return on;
  const float len = length(on);
  if (!(len > 0.0f)) return Vec3f(0.0f);
  float t_n = 0.0f;
  if (primitive < d.corner_tangent_tris) {
    const Vec3f* T = d.corner_tangents + size_t(primitive) * 3;
    const Vec2f b = hit.bary;
    const Vec3f t = T[0] * (1.0f - b.x - b.y) + T[1] * b.x + T[2] * b.y;
    t_n = dot(t, on) / len;
  }
  return Vec3f(len * t_n, len, 0.0f);
}

// Cycles' bump (svm_node_set_bump) tilts N against the surface gradient of the height, from
// heights at the hit and at two offsets of one pixel footprint (its compact ray differential)
// along the tangents make_orthonormals(Ng) gives: N' = normalize(|det| N - distance sign(det)
// surfgrad). The step matters: a height with detail finer than a pixel (a fractal noise of many
// octaves) differs over a footprint by far less than its true slope says, so a differential step
// would tilt the normal much more than Cycles does. Where no camera gives a footprint, the
// gradient comes from forward differences of a small step (the derivative). Heights are read at
// an offset through the dual basis (g_i . a_j = delta_ij) of two directions a0, a1 of the
// triangle's plane: dP/du and dP/dv (a step in UV) when the mesh has UVs, else the triangle's
// edges (a step in barycentrics). Every coordinate moves with the step (UV, and object-space
// coordinates along the object-space image of the direction), so image and procedural heights
// both differentiate. On a back face Cycles 3.4 negates dP/du and dP/dv before solving for the
// attributes' differentials (shader_setup_from_ray, differential_dudv_compact), so attribute
// coordinates (UV, Generated, Pointiness, Parametric) move against the step there while
// position-based ones (Object, Position, and what derives from them) move with it.
void EmbreeScene::bump_normal(const InstanceData& d, uint32_t primitive, SurfaceHit& hit,
                              const Material& material, size_t bump) const {
  const uint32_t* idx = d.indices + size_t(primitive) * 3;
  const Vec3f* P = d.object_positions;
  Vec3f p[3];
  for (int k = 0; k < 3; ++k) {
    const Vec3f q = d.positions[idx[k]];
    p[k] = d.world_space ? q
                         : world_direction(d.to_world_cols, q);  // differences only: no translation
  }
  const Vec3f e1 = p[1] - p[0], e2 = p[2] - p[0];
  const Vec3f o1 = P[idx[1]] - P[idx[0]], o2 = P[idx[2]] - P[idx[0]];
  // Directions in world (a) and object (o) space and their UV and barycentric steps, per unit
  // step.
  Vec3f a[2] = {e1, e2}, o[2] = {o1, o2};
  Vec2f duv[2] = {Vec2f(0.0f, 0.0f), Vec2f(0.0f, 0.0f)};
  Vec2f dbary[2] = {Vec2f(1.0f, 0.0f), Vec2f(0.0f, 1.0f)};
  if (primitive < d.corner_uv_tris) {
    const Vec2f* T = d.corner_uvs + size_t(primitive) * 3;
    const float du1 = T[1].x - T[0].x, dv1 = T[1].y - T[0].y;
    const float du2 = T[2].x - T[0].x, dv2 = T[2].y - T[0].y;
    const float det = du1 * dv2 - du2 * dv1;
    if (std::fabs(det) > 0.0f) {  // dP/du, dP/dv
      a[0] = (e1 * dv2 - e2 * dv1) / det;
      a[1] = (e2 * du1 - e1 * du2) / det;
      o[0] = (o1 * dv2 - o2 * dv1) / det;
      o[1] = (o2 * du1 - o1 * du2) / det;
      dbary[0] = Vec2f(dv2 / det, -dv1 / det);
      dbary[1] = Vec2f(-du2 / det, du1 / det);
      duv[0] = Vec2f(1.0f, 0.0f);
      duv[1] = Vec2f(0.0f, 1.0f);
    } else {
      duv[0] = T[1] - T[0];
      duv[1] = T[2] - T[0];
    }
  }
  const Vec3f ng = cross(e1, e2);
  const Vec3f along = displacement_along(d, primitive, hit, material.bumps()[bump]);
  const float jac = dot(ng, cross(a[0], a[1]));
  if (!(std::fabs(jac) > 0.0f) || !std::isfinite(jac)) return;
  const Vec3f g0 = cross(a[1], ng) / jac, g1 = cross(ng, a[0]) / jac;
  ShadingContext at = shading_context(d, hit);
  const float h0 = material.bump_height(bump, at, along);
  const TexCoords base = hit.coords;
  // The side the ray sees: +1 on a front face, -1 on a back face.
  const float side = hit.front_facing ? 1.0f : -1.0f;
  // The height at the hit moved by c0 a0 + c1 a1 (attributes by side times that).
  auto height_at = [&](float c0, float c1) {
    const float s0 = side * c0, s1 = side * c1;
    at.uv = hit.uv + duv[0] * s0 + duv[1] * s1;
    TexCoords shifted = base;
    if (d.writes_coords) {
      const Vec3f object = o[0] * c0 + o[1] * c1;
      shifted.object = base.object + object;
      shifted.position = base.position + a[0] * c0 + a[1] * c1;
      for (int c = 0; c < 3; ++c)
        shifted.generated[c] = base.generated[c] + object[c] * (side * d.generated_scale[c]);
    }
    at.coords = d.writes_coords ? &shifted : nullptr;
    // Mesh attributes (Pointiness, Parametric) move too, as Cycles differentiates them for bump.
    SurfaceAttributes moved;
    if (d.writes_attributes) {
      const Vec2f b = hit.attributes.barycentric + dbary[0] * s0 + dbary[1] * s1;
      moved = attributes_at(d, primitive, idx, b.x, b.y);
    }
    at.attributes = d.writes_attributes ? &moved : nullptr;
    return material.bump_height(bump, at, along);
  };
  const BumpDesc& b = material.bumps()[bump];
  const float distance = b.invert ? -b.distance : b.distance;
  const Vec3f n = hit.shading_normal;
  Vec3f bumped;
  const float footprint = pixel_footprint(material.camera(), hit.position);
  if (footprint > 0.0f && std::isfinite(footprint)) {
    // Cycles tilts the normals of the side the ray sees (sd->N, sd->Ng flipped on a back face)
    // and its tangents belong to that geometric normal; the result is turned back to the
    // surface's side here.
    const Vec3f ng_seen = normalize(ng * side);
    const Vec3f n_seen = n * side;
    Vec3f tx = ng_seen.x != ng_seen.y || ng_seen.x != ng_seen.z
                   ? Vec3f(ng_seen.z - ng_seen.y, ng_seen.x - ng_seen.z, ng_seen.y - ng_seen.x)
                   : Vec3f(ng_seen.z - ng_seen.y, ng_seen.x + ng_seen.z, -ng_seen.y - ng_seen.x);
    tx = normalize(tx) * footprint;
    const Vec3f ty = cross(ng_seen, tx);
    const float hx = height_at(dot(g0, tx), dot(g1, tx));
    const float hy = height_at(dot(g0, ty), dot(g1, ty));
    const Vec3f rx = cross(ty, n_seen), ry = cross(n_seen, tx);
    const float det = dot(tx, rx);
    const Vec3f surfgrad = rx * (hx - h0) + ry * (hy - h0);
    const float sign = det < 0.0f ? -1.0f : 1.0f;
    if (!set_unit(n_seen * std::fabs(det) - surfgrad * (distance * sign), bumped)) return;
    bumped = bumped * side;
  } else {
    // In UV: about a quarter texel of a 256 image; in barycentrics: a 1024th of the triangle.
    constexpr float kStep = 1.0f / 1024.0f;
    const float h1 = height_at(kStep, 0.0f), h2 = height_at(0.0f, kStep);
    Vec3f grad = (g0 * (h1 - h0) + g1 * (h2 - h0)) / kStep;
    // The same directional derivatives, in the plane normal to n (Cycles' surface gradient):
    // moves grad along the face normal; it matters where n is tilted, by smoothing or an
    // earlier bump.
    const float ng_n = dot(ng, n);
    if (std::fabs(ng_n) > 1e-3f * length(ng)) grad = grad - ng * (dot(grad, n) / ng_n);
    // Tilted on the seen side as above (n side - grad distance), turned back.
    if (!set_unit(n - grad * (side * distance), bumped)) return;
  }
  const float strength = std::max(b.strength, 0.0f);
  set_unit(bumped * strength + n * (1.0f - strength), hit.shading_normal);
  // Displacement as bump: the tilted normal is the surface's own (not a perturbation of it).
  if (b.replaces_normal) hit.unperturbed_normal = hit.shading_normal;
}

}  // namespace gdpt
