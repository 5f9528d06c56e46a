// The Geometry node's topology-derived mesh attributes, computed from Blender's vertices, vertex
// normals and edges as Cycles 3.4's Blender sync does (intern/cycles/blender/mesh.cpp), so a
// material reading them renders as in Cycles. No Python: unit-tested in tests/module/.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/vec.h"
#include "scene/scene.h"

namespace gdpt::ingest {

// Cycles' Pointiness, one value per vertex in [0, 1]: at each vertex, the angle between its
// normal and the mean of its unit edge vectors over pi (0.5 on a flat surface, above in convex
// corners, below in cavities), then averaged with its edge neighbours. Vertices at the same
// position (split edges) are welded first, so a split does not show. edges: Blender's edges, two
// vertex indices each; vertex_normals: Blender's, one per vertex. Indices must be in range.
std::vector<float> pointiness(std::span<const Vec3f> positions,
                              std::span<const Vec3f> vertex_normals,
                              std::span<const int32_t> edges);

// Cycles' Random Per Island, one value per triangle: the hash (to [0, 1]) of the island of the
// triangle's first vertex, islands being the vertex sets connected by edges, each named by its
// representative in a union-by-rank disjoint set joined in edge order (Cycles' DisjointSet).
// triangle_indices: 3 per triangle. Indices must be in range.
std::vector<float> random_per_island(size_t vertex_count, std::span<const int32_t> edges,
                                     std::span<const uint32_t> triangle_indices);

// Fills mesh.vertex_pointiness and / or mesh.triangle_island_random from Blender's edges (2 per
// edge) and vertex normals (3 per vertex; read for Pointiness only). Throws
// std::invalid_argument naming the array when a size or an index is out of range.
void add_geometry_attributes(Mesh& mesh, std::span<const int32_t> edges,
                             std::span<const float> vertex_normals, bool pointiness,
                             bool random_per_island);

}  // namespace gdpt::ingest
