// The add-on's flat mesh arrays -> a validated gdpt::Mesh, with no Python types, so the checks can
// be unit-tested and fuzzed (tests/module/, fuzz/) without an interpreter.
//
// Every array is checked before anything is read through it: sizes against each other, every
// index against the array it indexes, positions finite. A bad array throws std::invalid_argument
// (ValueError in Python) naming the array, the offending element and the valid range; nothing is
// ever read out of bounds. Optional arrays are absent when empty.
#pragma once

#include <cstdint>
#include <span>

#include "scene/scene.h"

namespace gdpt::ingest {

// Blender's material slots per object (MAXMAT): a slot index at or above it cannot come from a
// real mesh.
inline constexpr int32_t kMaxMaterialSlots = 32767;

// Blender's own per-loop arrays, shared by the loop-triangle and polygon paths.
struct LoopArrays {
  std::span<const float> positions;      // 3 per vertex
  std::span<const int32_t> loop_vertex;  // per loop: index into the vertices
  std::span<const float> normals;        // 3 per loop (normals_per_loop) or per vertex, or empty
  bool normals_per_loop = false;
  std::span<const float> loop_uvs;       // 2 per loop, or empty
  std::span<const float> loop_tangents;  // 4 per loop (tangent, bitangent sign), or empty
  std::span<const float> loop_colors;    // 3 per loop (linear RGB), or empty
};

// Triangles given directly: indices 3 per triangle into the vertices; corner_normals 9 and
// corner_uvs 6 per triangle, material_slot 1 per triangle (each may be empty).
Mesh mesh_from_triangles(std::span<const float> positions, std::span<const int32_t> indices,
                         std::span<const float> corner_normals, std::span<const float> corner_uvs,
                         std::span<const int32_t> material_slot);

// Loop triangles: corner_loops 3 per triangle into the loops; material_slot 1 per triangle or
// empty.
Mesh mesh_from_loops(const LoopArrays& loops, std::span<const int32_t> corner_loops,
                     std::span<const int32_t> material_slot);

// Triangles and quads from Blender's polygon arrays (loop_start, loop_total: one per polygon),
// triangulated with Blender's loop-triangle rule; poly_material 1 per polygon or empty.
// `smooth_vertex_normals` (loops.normals empty): the vertex normals of a smooth-shaded mesh
// computed here as Blender defines them (smooth_vertex_normals()).
Mesh mesh_from_polys(const LoopArrays& loops, std::span<const int32_t> loop_start,
                     std::span<const int32_t> loop_total, std::span<const int32_t> poly_material,
                     bool smooth_vertex_normals = false);

// Blender's vertex normals of a polygon mesh (3 floats per vertex in `positions`; polygons of
// 3 or 4 corners, already validated): each polygon's normal weighted by its corner angle at the
// vertex, summed in polygon order and normalised (a vertex of no area: its position's
// direction). Blender sums the same terms over threads in the order they finish, so its own
// normals of one mesh differ by a float rounding step from one evaluation to the next, and so
// would renders that read them (docs/conventions.md, Determinism).
std::vector<Vec3f> smooth_vertex_normals(std::span<const float> positions,
                                         std::span<const int32_t> loop_vertex,
                                         std::span<const int32_t> loop_start,
                                         std::span<const int32_t> loop_total);

}  // namespace gdpt::ingest
