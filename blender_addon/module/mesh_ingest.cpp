// See mesh_ingest.h. The gathers run after every index they follow has been checked, so their
// inner loops index without checks.
#include "blender_addon/module/mesh_ingest.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "core/huge_pages.h"

namespace gdpt::ingest {

namespace {

[[noreturn]] void reject(const char* array, const std::string& why) {
  throw std::invalid_argument(std::string(array) + ": " + why);
}

void require_nonempty(size_t size, const char* array, const char* what) {
  if (size == 0) reject(array, std::string("empty (a mesh needs at least one ") + what + ")");
}

// An optional array: empty, or exactly `per_item` values per item.
template <typename T>
const T* optional_data(std::span<const T> a, size_t items, size_t per_item, const char* array,
                       const char* item) {
  if (a.empty()) return nullptr;
  if (a.size() != items * per_item)
    reject(array, "expected " + std::to_string(items * per_item) + " values (" +
                      std::to_string(per_item) + " per " + item + ", " + std::to_string(items) +
                      " " + item + "s), got " + std::to_string(a.size()));
  return a.data();
}

// Every value of `a` in [0, bound); `what` names what the values index.
void check_indices(std::span<const int32_t> a, size_t bound, const char* array, const char* what) {
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i] < 0 || size_t(a[i]) >= bound)
      reject(array, "value " + std::to_string(i) + " is " + std::to_string(a[i]) +
                        ", out of range [0, " + std::to_string(bound) + ") " + what);
}

// Positions: a whole number of vertices, at least one, all finite (a NaN or infinite vertex
// makes the BVH's bounds and every ray through them meaningless).
size_t check_positions(std::span<const float> positions) {
  require_nonempty(positions.size(), "positions", "vertex");
  if (positions.size() % 3 != 0)
    reject("positions", "size " + std::to_string(positions.size()) + " is not a multiple of 3");
  for (size_t i = 0; i < positions.size(); ++i)
    if (!std::isfinite(positions[i]))
      reject("positions", "vertex " + std::to_string(i / 3) + " coordinate " +
                              std::to_string(i % 3) + " is " + std::to_string(positions[i]) +
                              " (every vertex must be finite)");
  return positions.size() / 3;
}

void check_material_slots(std::span<const int32_t> slots, const char* array) {
  check_indices(slots, size_t(kMaxMaterialSlots), array, "(Blender's material slots)");
}

bool any_nonzero(std::span<const int32_t> a) {
  for (const int32_t v : a)
    if (v != 0) return true;
  return false;
}

template <typename V>
void copy_floats(std::vector<V>& out, const float* src, size_t count) {
  static_assert(std::is_trivially_copyable_v<V> && sizeof(V) % sizeof(float) == 0);
  reserve_fresh(out, count);
  out.resize(count);
  std::memcpy(static_cast<void*>(out.data()), src, count * sizeof(V));
}

// The loop arrays after their checks: sizes agree, every loop's vertex is in range.
struct CornerSource {
  const float* positions = nullptr;
  size_t vertex_count = 0;
  const int32_t* loop_vertex = nullptr;
  size_t loop_count = 0;
  const float* normals = nullptr;  // per loop or per vertex, or null
  bool normals_per_loop = false;
  const float* loop_uvs = nullptr;
  const float* loop_tangents = nullptr;
  const float* loop_colors = nullptr;
};

CornerSource corner_source(const LoopArrays& in) {
  CornerSource s;
  s.vertex_count = check_positions(in.positions);
  s.positions = in.positions.data();
  require_nonempty(in.loop_vertex.size(), "loop_vertex", "loop");
  check_indices(in.loop_vertex, s.vertex_count, "loop_vertex", "(the mesh's vertices)");
  s.loop_vertex = in.loop_vertex.data();
  s.loop_count = in.loop_vertex.size();
  s.normals_per_loop = in.normals_per_loop;
  s.normals = in.normals_per_loop
                  ? optional_data(in.normals, s.loop_count, 3, "normals", "loop")
                  : optional_data(in.normals, s.vertex_count, 3, "normals", "vertex");
  s.loop_uvs = optional_data(in.loop_uvs, s.loop_count, 2, "loop_uvs", "loop");
  s.loop_tangents = optional_data(in.loop_tangents, s.loop_count, 4, "loop_tangents", "loop");
  s.loop_colors = optional_data(in.loop_colors, s.loop_count, 3, "loop_colors", "loop");
  return s;
}

// Fills a Mesh from `triangles` triangles whose corner loops `corners(emit, emit_material)`
// produces in order (emit(loop) per corner, emit_material(slot) per triangle); loops must be in
// range. One pass per output array: a 1M-triangle mesh writes about 80 MB of fresh memory, so
// the buffers are reserved as huge pages first (reserve_fresh) and each streams through its own.
template <typename Corners>
Mesh gather_mesh(const CornerSource& src, size_t triangles, bool with_material,
                 const Corners& corners) {
  Mesh mesh;
  const size_t corner_count = triangles * 3;
  copy_floats(mesh.positions, src.positions, src.vertex_count);
  reserve_fresh(mesh.indices, corner_count);
  corners([&](int32_t loop) { mesh.indices.push_back(uint32_t(src.loop_vertex[loop])); },
          [](int32_t) {});
  if (src.normals && src.normals_per_loop) {
    const float* n = src.normals;
    reserve_fresh(mesh.corner_normals, corner_count);
    corners(
        [&](int32_t loop) {
          const size_t i = 3 * size_t(loop);
          mesh.corner_normals.emplace_back(n[i], n[i + 1], n[i + 2]);
        },
        [](int32_t) {});
  } else if (src.normals) {
    // Vertex normals stay per vertex (Mesh::vertex_normals): no per-corner copy.
    copy_floats(mesh.vertex_normals, src.normals, src.vertex_count);
  }
  if (src.loop_uvs) {
    const float* uv = src.loop_uvs;
    reserve_fresh(mesh.corner_uvs, corner_count);
    corners(
        [&](int32_t loop) {
          mesh.corner_uvs.emplace_back(uv[2 * size_t(loop)], uv[2 * size_t(loop) + 1]);
        },
        [](int32_t) {});
  }
  if (src.loop_tangents) {
    const float* t = src.loop_tangents;
    reserve_fresh(mesh.corner_tangents, corner_count);
    reserve_fresh(mesh.corner_tangent_signs, corner_count);
    corners(
        [&](int32_t loop) {
          const size_t i = 4 * size_t(loop);
          mesh.corner_tangents.emplace_back(t[i], t[i + 1], t[i + 2]);
          mesh.corner_tangent_signs.push_back(t[i + 3]);
        },
        [](int32_t) {});
  }
  if (src.loop_colors) {
    const float* c = src.loop_colors;
    reserve_fresh(mesh.corner_colors, corner_count);
    corners(
        [&](int32_t loop) {
          const size_t i = 3 * size_t(loop);
          mesh.corner_colors.emplace_back(c[i], c[i + 1], c[i + 2]);
        },
        [](int32_t) {});
  }
  if (with_material) {
    reserve_fresh(mesh.material_slot, triangles);
    corners([](int32_t) {}, [&](int32_t slot) { mesh.material_slot.push_back(slot); });
  }
  return mesh;
}

// Blender 3.4's loop-triangle split of quad p (loops s..s+3): along 0-2 (0-1-2 + 0-2-3) unless,
// seen along the face normal n = (v0 - v2) x (v1 - v3), v1 and v3 are not strictly on opposite
// sides of the 0-2 diagonal; then along 1-3 (0-1-3 + 1-2-3). That covers folded, concave and
// degenerate quads (two corners at one position, as at the poles of a quad sphere), where the 1-3
// split keeps the real triangle's own corners. Quads within rounding of such a tie may split
// either way, as in Blender, whose result depends on how its cached face normal was computed.
bool quad_splits_1_3(const CornerSource& src, int32_t s) {
  auto vertex = [&](int32_t loop) {
    const size_t v = 3 * size_t(src.loop_vertex[loop]);
    return Vec3f(src.positions[v], src.positions[v + 1], src.positions[v + 2]);
  };
  const Vec3f v0 = vertex(s), v1 = vertex(s + 1), v2 = vertex(s + 2), v3 = vertex(s + 3);
  Vec3f n = cross(v0 - v2, v1 - v3);  // Blender's normal_quad_v3
  const float len2 = dot(n, n);
  n = len2 > 1e-35f ? n * (1.0f / std::sqrt(len2)) : Vec3f(0.0f);  // and normalize_v3
  const Vec3f tangent = cross(v2 - v0, n);
  const float d = dot(v0, tangent);
  return dot(v3, tangent) >= d || dot(v1, tangent) <= d;
}

// Double precision: differences of finite float coordinates near FLT_MAX overflow in float.
struct D3 {
  double x = 0.0, y = 0.0, z = 0.0;
};
D3 operator-(const D3& a, const D3& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
D3 scaled(const D3& a, double k) {
  return {a.x * k, a.y * k, a.z * k};
}
double dot3(const D3& a, const D3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
D3 cross3(const D3& a, const D3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
// `a` made unit; zero when it has no length (Blender's normalize_v3 of a zero vector).
D3 unit3(const D3& a) {
  const double len = std::sqrt(dot3(a, a));
  return len > 0.0 ? scaled(a, 1.0 / len) : D3{};
}

}  // namespace

Mesh mesh_from_triangles(std::span<const float> positions, std::span<const int32_t> indices,
                         std::span<const float> corner_normals, std::span<const float> corner_uvs,
                         std::span<const int32_t> material_slot) {
  const size_t vertex_count = check_positions(positions);
  require_nonempty(indices.size(), "indices", "triangle");
  if (indices.size() % 3 != 0)
    reject("indices", "size " + std::to_string(indices.size()) + " is not a multiple of 3");
  check_indices(indices, vertex_count, "indices", "(the mesh's vertices)");
  const size_t triangles = indices.size() / 3;
  const float* normals = optional_data(corner_normals, triangles, 9, "corner_normals", "triangle");
  const float* uvs = optional_data(corner_uvs, triangles, 6, "corner_uvs", "triangle");
  const int32_t* slots = optional_data(material_slot, triangles, 1, "material_slot", "triangle");
  check_material_slots(material_slot, "material_slot");

  Mesh mesh;
  copy_floats(mesh.positions, positions.data(), vertex_count);
  mesh.indices.assign(indices.begin(), indices.end());  // all non-negative: checked above
  if (normals) copy_floats(mesh.corner_normals, normals, triangles * 3);
  if (uvs) copy_floats(mesh.corner_uvs, uvs, triangles * 3);
  if (slots) mesh.material_slot.assign(slots, slots + triangles);
  return mesh;
}

Mesh mesh_from_loops(const LoopArrays& loops, std::span<const int32_t> corner_loops,
                     std::span<const int32_t> material_slot) {
  const CornerSource src = corner_source(loops);
  require_nonempty(corner_loops.size(), "corner_loops", "triangle");
  if (corner_loops.size() % 3 != 0)
    reject("corner_loops",
           "size " + std::to_string(corner_loops.size()) + " is not a multiple of 3");
  check_indices(corner_loops, src.loop_count, "corner_loops", "(the mesh's loops)");
  const size_t triangles = corner_loops.size() / 3;
  const int32_t* slot = optional_data(material_slot, triangles, 1, "material_slot", "triangle");
  check_material_slots(material_slot, "material_slot");
  const int32_t* corners = corner_loops.data();
  return gather_mesh(src, triangles, slot && any_nonzero(material_slot),
                     [&](const auto& emit, const auto& emit_material) {
                       for (size_t t = 0; t < triangles; ++t) {
                         emit(corners[3 * t]);
                         emit(corners[3 * t + 1]);
                         emit(corners[3 * t + 2]);
                         emit_material(slot ? slot[t] : 0);
                       }
                     });
}

std::vector<Vec3f> smooth_vertex_normals(std::span<const float> positions,
                                         std::span<const int32_t> loop_vertex,
                                         std::span<const int32_t> loop_start,
                                         std::span<const int32_t> loop_total) {
  const size_t vertex_count = positions.size() / 3;
  auto at = [&](int32_t loop) {
    const size_t v = 3 * size_t(loop_vertex[size_t(loop)]);
    return D3{positions[v], positions[v + 1], positions[v + 2]};
  };
  std::vector<D3> sums(vertex_count);
  for (size_t p = 0; p < loop_start.size(); ++p) {
    const int32_t s = loop_start[p], n = loop_total[p];
    // Blender's normal_tri_v3 / normal_quad_v3 (the quad's diagonals).
    const D3 face = unit3(n == 3 ? cross3(at(s + 1) - at(s), at(s + 2) - at(s))
                                 : cross3(at(s) - at(s + 2), at(s + 1) - at(s + 3)));
    for (int32_t i = 0; i < n; ++i) {
      const D3 here = at(s + i);
      // A zero-length edge's direction is zero: a right angle, as in Blender.
      const D3 to_prev = unit3(at(s + (i + n - 1) % n) - here);
      const D3 to_next = unit3(at(s + (i + 1) % n) - here);
      const double angle = std::acos(std::clamp(dot3(to_prev, to_next), -1.0, 1.0));
      D3& sum = sums[size_t(loop_vertex[size_t(s + i)])];
      sum = {sum.x + face.x * angle, sum.y + face.y * angle, sum.z + face.z * angle};
    }
  }
  std::vector<Vec3f> normals(vertex_count);
  for (size_t v = 0; v < vertex_count; ++v) {
    D3 u = unit3(sums[v]);
    // A vertex of no area: its position's direction (Blender's fallback), else +z.
    if (dot3(u, u) == 0.0)
      u = unit3(D3{positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]});
    if (dot3(u, u) == 0.0) u = D3{0.0, 0.0, 1.0};
    normals[v] = Vec3f(float(u.x), float(u.y), float(u.z));
  }
  return normals;
}

Mesh mesh_from_polys(const LoopArrays& loops, std::span<const int32_t> loop_start,
                     std::span<const int32_t> loop_total, std::span<const int32_t> poly_material,
                     bool smooth_vertex_normals_wanted) {
  const CornerSource src = corner_source(loops);
  const size_t poly_count = loop_start.size();
  require_nonempty(poly_count, "loop_start", "polygon");
  if (loop_total.size() != poly_count)
    reject("loop_total", "expected " + std::to_string(poly_count) +
                             " values (one per polygon, as loop_start), got " +
                             std::to_string(loop_total.size()));
  const int32_t* material = optional_data(poly_material, poly_count, 1, "poly_material", "polygon");
  check_material_slots(poly_material, "poly_material");
  const int32_t* start = loop_start.data();
  const int32_t* total = loop_total.data();
  size_t triangles = 0;
  for (size_t p = 0; p < poly_count; ++p) {
    if (total[p] < 3 || total[p] > 4)
      reject("loop_total", "value " + std::to_string(p) + " is " + std::to_string(total[p]) +
                               " (only triangles and quads: 3 or 4)");
    if (start[p] < 0 || size_t(start[p]) + size_t(total[p]) > src.loop_count)
      reject("loop_start", "value " + std::to_string(p) + " is " + std::to_string(start[p]) +
                               ": polygon loops [" + std::to_string(start[p]) + ", " +
                               std::to_string(int64_t(start[p]) + total[p]) +
                               ") out of range [0, " + std::to_string(src.loop_count) + ")");
    triangles += size_t(total[p] - 2);
  }
  if (smooth_vertex_normals_wanted && src.normals)
    reject("normals", "given with smooth_vertex_normals (the vertex normals are computed here)");
  // The split is chosen once per quad, not once per output array.
  std::vector<uint8_t> flip(poly_count, 0);
  for (size_t p = 0; p < poly_count; ++p)
    if (total[p] == 4) flip[p] = quad_splits_1_3(src, start[p]);
  Mesh mesh = gather_mesh(src, triangles, material && any_nonzero(poly_material),
                          [&](const auto& emit, const auto& emit_material) {
                            for (size_t p = 0; p < poly_count; ++p) {
                              const int32_t s = start[p];
                              const int32_t m = material ? material[p] : 0;
                              if (total[p] == 3) {
                                emit(s), emit(s + 1), emit(s + 2), emit_material(m);
                              } else if (!flip[p]) {
                                emit(s), emit(s + 1), emit(s + 2), emit_material(m);
                                emit(s), emit(s + 2), emit(s + 3), emit_material(m);
                              } else {
                                emit(s), emit(s + 1), emit(s + 3), emit_material(m);
                                emit(s + 1), emit(s + 2), emit(s + 3), emit_material(m);
                              }
                            }
                          });
  if (smooth_vertex_normals_wanted)
    mesh.vertex_normals =
        smooth_vertex_normals(loops.positions, loops.loop_vertex, loop_start, loop_total);
  return mesh;
}

}  // namespace gdpt::ingest
