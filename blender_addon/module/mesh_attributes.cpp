// See mesh_attributes.h.
#include "blender_addon/module/mesh_attributes.h"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <utility>

#include "shaders/procedural_texture.h"

namespace gdpt::ingest {

namespace {

float coordinate_sum(Vec3f p) {
  return p.x + p.y + p.z;
}

// For each vertex, the vertex it is welded to (itself when it is its group's own). Cycles finds
// a vertex's duplicate among those after it in an order by coordinate sum (equal positions: the
// higher index first), within 3 FLT_EPSILON of that sum and FLT_EPSILON of squared distance,
// then follows the chain to its end.
std::vector<uint32_t> weld_targets(std::span<const Vec3f> positions) {
  const size_t n = positions.size();
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    const Vec3f pa = positions[a], pb = positions[b];
    if (pa.x == pb.x && pa.y == pb.y && pa.z == pb.z) return a > b;
    return coordinate_sum(pa) < coordinate_sum(pb);
  });
  std::vector<uint32_t> target(n);
  for (size_t k = 0; k < n; ++k) {
    const uint32_t v = order[k];
    const Vec3f p = positions[v];
    target[v] = v;
    for (size_t j = k + 1; j < n; ++j) {
      const Vec3f q = positions[order[j]];
      if (coordinate_sum(q) - coordinate_sum(p) > 3.0f * FLT_EPSILON) break;
      if (length_squared(q - p) < FLT_EPSILON) {
        target[v] = order[j];
        break;
      }
    }
  }
  for (size_t v = 0; v < n; ++v) {
    uint32_t t = target[v];
    while (target[t] != t) t = target[t];
    target[v] = t;
  }
  return target;
}

// Calls f(a, b) once per edge between welded vertices, the first time the (unordered) pair is
// met in Blender's edge order.
template <typename F>
void for_each_welded_edge(std::span<const int32_t> edges, const std::vector<uint32_t>& weld,
                          F&& f) {
  std::unordered_set<uint64_t> seen;
  seen.reserve(edges.size() / 2);
  for (size_t e = 0; e + 1 < edges.size(); e += 2) {
    const uint32_t a = weld[size_t(edges[e])], b = weld[size_t(edges[e + 1])];
    const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
    if (seen.insert(key).second) f(a, b);
  }
}

Vec3f normalized_or_zero(Vec3f v) {
  const float len2 = length_squared(v);
  return len2 > 0.0f ? v / std::sqrt(len2) : Vec3f(0.0f);
}

}  // namespace

std::vector<float> pointiness(std::span<const Vec3f> positions,
                              std::span<const Vec3f> vertex_normals,
                              std::span<const int32_t> edges) {
  const size_t n = positions.size();
  const std::vector<uint32_t> weld = weld_targets(positions);
  // A welded group's normal: its members' normals summed, normalised.
  std::vector<Vec3f> normal(n, Vec3f(0.0f));
  for (size_t v = 0; v < n; ++v) normal[weld[v]] += vertex_normals[v];
  // Mean of the unit edge vectors leaving each group.
  std::vector<Vec3f> edge_sum(n, Vec3f(0.0f));
  std::vector<int> count(n, 0);
  for_each_welded_edge(edges, weld, [&](uint32_t a, uint32_t b) {
    const Vec3f d = normalized_or_zero(positions[b] - positions[a]);
    edge_sum[a] += d;
    edge_sum[b] -= d;
    ++count[a];
    ++count[b];
  });
  std::vector<float> raw(n, 0.0f);
  for (size_t v = 0; v < n; ++v) {
    if (weld[v] != v || count[v] == 0) continue;
    const float c = dot(normalized_or_zero(normal[v]), edge_sum[v] / float(count[v]));
    raw[v] = std::acos(std::clamp(c, -1.0f, 1.0f)) * kInvPi;
  }
  // Averaged with the edge neighbours (Cycles' approximation of a two-ring neighbourhood).
  std::vector<float> out = raw;
  std::fill(count.begin(), count.end(), 0);
  for_each_welded_edge(edges, weld, [&](uint32_t a, uint32_t b) {
    out[a] += raw[b];
    out[b] += raw[a];
    ++count[a];
    ++count[b];
  });
  for (size_t v = 0; v < n; ++v) out[v] /= float(count[v] + 1);
  for (size_t v = 0; v < n; ++v) out[v] = out[weld[v]];
  return out;
}

void add_geometry_attributes(Mesh& mesh, std::span<const int32_t> edges,
                             std::span<const float> vertex_normals, bool with_pointiness,
                             bool with_random_per_island) {
  const size_t n = mesh.positions.size();
  if (edges.size() % 2 != 0)
    throw std::invalid_argument("edges: size " + std::to_string(edges.size()) +
                                " is not a multiple of 2");
  for (size_t i = 0; i < edges.size(); ++i)
    if (edges[i] < 0 || size_t(edges[i]) >= n)
      throw std::invalid_argument("edges: value " + std::to_string(i) + " is " +
                                  std::to_string(edges[i]) + ", out of range [0, " +
                                  std::to_string(n) + ") (the mesh's vertices)");
  if (with_pointiness) {
    if (vertex_normals.size() != n * 3)
      throw std::invalid_argument("vertex_normals: expected " + std::to_string(n * 3) +
                                  " values (3 per vertex), got " +
                                  std::to_string(vertex_normals.size()));
    const std::span<const Vec3f> normals(reinterpret_cast<const Vec3f*>(vertex_normals.data()), n);
    mesh.vertex_pointiness = pointiness(mesh.positions, normals, edges);
  }
  if (with_random_per_island)
    mesh.triangle_island_random = random_per_island(n, edges, mesh.indices);
}

std::vector<float> random_per_island(size_t vertex_count, std::span<const int32_t> edges,
                                     std::span<const uint32_t> triangle_indices) {
  std::vector<uint32_t> parent(vertex_count);
  std::vector<uint32_t> rank(vertex_count, 0);
  std::iota(parent.begin(), parent.end(), 0u);
  auto find = [&](uint32_t x) {
    uint32_t root = x;
    while (parent[root] != root) root = parent[root];
    while (parent[x] != root) x = std::exchange(parent[x], root);
    return root;
  };
  for (size_t e = 0; e + 1 < edges.size(); e += 2) {
    uint32_t a = find(uint32_t(edges[e])), b = find(uint32_t(edges[e + 1]));
    if (a == b) continue;
    if (rank[a] < rank[b]) std::swap(a, b);  // the higher rank stays the representative
    parent[b] = a;
    if (rank[a] == rank[b]) ++rank[a];
  }
  const size_t triangles = triangle_indices.size() / 3;
  std::vector<float> out(triangles);
  for (size_t t = 0; t < triangles; ++t)
    out[t] = float(hash_words(find(triangle_indices[t * 3]))) * (1.0f / float(0xFFFFFFFFu));
  return out;
}

}  // namespace gdpt::ingest
