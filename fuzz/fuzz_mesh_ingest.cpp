// libFuzzer target: the add-on's mesh arrays -> Mesh (blender_addon/module/mesh_ingest.h). Any
// input either throws std::invalid_argument or yields a mesh whose every index is in range and
// whose per-corner arrays have 3 entries per triangle; ASan and UBSan watch every read.
#include <cmath>
#include <cstdlib>
#include <span>
#include <stdexcept>

#include "blender_addon/module/mesh_ingest.h"
#include "fuzz/mesh_ingest_input.h"

namespace {

using gdpt::Mesh;

std::span<const float> floats(const std::vector<uint32_t>& a) {
  return {reinterpret_cast<const float*>(a.data()), a.size()};
}
std::span<const int32_t> ints(const std::vector<uint32_t>& a) {
  return {reinterpret_cast<const int32_t*>(a.data()), a.size()};
}

void require(bool ok) {
  if (!ok) std::abort();  // an accepted mesh that breaks an invariant the renderer trusts
}

void check_mesh(const Mesh& m) {
  const size_t triangles = m.triangle_count();
  require(m.indices.size() == 3 * triangles && triangles > 0);
  for (uint32_t i : m.indices) require(i < m.positions.size());
  // Each coordinate on its own: a sum of finite coordinates near FLT_MAX overflows.
  for (const auto& p : m.positions)
    require(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z));
  for (size_t n : {m.corner_normals.size(), m.corner_uvs.size(), m.corner_tangents.size(),
                   m.corner_tangent_signs.size(), m.corner_colors.size()})
    require(n == 0 || n == 3 * triangles);
  require(m.vertex_normals.empty() || m.vertex_normals.size() == m.positions.size());
  for (const auto& n : m.vertex_normals)
    require(std::isfinite(n.x) && std::isfinite(n.y) && std::isfinite(n.z));
  require(m.material_slot.empty() || m.material_slot.size() == triangles);
  for (int32_t s : m.material_slot) require(s >= 0 && s < gdpt::ingest::kMaxMaterialSlots);
}

Mesh ingest(const gdpt::fuzz::MeshInput& in) {
  using gdpt::fuzz::MeshMode;
  const auto& a = in.arrays;
  if (in.mode == MeshMode::Triangles)
    return gdpt::ingest::mesh_from_triangles(floats(a[0]), ints(a[1]), floats(a[2]), floats(a[3]),
                                             ints(a[4]));
  gdpt::ingest::LoopArrays loops;
  loops.positions = floats(a[0]);
  loops.loop_vertex = ints(a[1]);
  loops.normals = floats(a[2]);
  loops.normals_per_loop = in.normals_per_loop;
  loops.loop_uvs = floats(a[3]);
  loops.loop_tangents = floats(a[4]);
  loops.loop_colors = floats(a[5]);
  if (in.mode == MeshMode::Loops)
    return gdpt::ingest::mesh_from_loops(loops, ints(a[6]), ints(a[7]));
  // The flag also asks for the add-on's smooth vertex normals (refused with normals given).
  return gdpt::ingest::mesh_from_polys(loops, ints(a[6]), ints(a[7]), ints(a[8]),
                                       in.normals_per_loop);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const gdpt::fuzz::MeshInput in = gdpt::fuzz::decode_mesh_input(data, size);
  try {
    check_mesh(ingest(in));
  } catch (const std::invalid_argument&) {
    // Rejected with a message: what bad input must do.
  }
  return 0;
}
