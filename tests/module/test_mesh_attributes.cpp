// The Geometry node's derived mesh attributes (blender_addon/module/mesh_attributes.h) against
// answers known in closed form: Pointiness on a cube (convex corners) and a flat grid (0.5),
// welded split vertices, and Random Per Island's island representatives (union by rank).
#include "blender_addon/module/mesh_attributes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "shaders/procedural_texture.h"

namespace gdpt::ingest {
namespace {

// A unit cube's corners (vertex i at the bits of i), its 12 edges and angle-weighted normals.
struct Cube {
  std::vector<Vec3f> positions, normals;
  std::vector<int32_t> edges;
  Cube() {
    for (int i = 0; i < 8; ++i) {
      const Vec3f p(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1));
      positions.push_back(p);
      normals.push_back(normalize(p * 2.0f - Vec3f(1.0f)));
      for (int bit = 1; bit < 8; bit <<= 1)
        if (!(i & bit)) edges.insert(edges.end(), {i, i | bit});
    }
  }
};

// Every corner of a cube: the mean edge direction (-1, -1, -1) / 3 against the normal
// (1, 1, 1) / sqrt 3, acos(-1 / sqrt 3) / pi, and its neighbours are the same.
const float kCubeCorner = std::acos(-1.0f / std::sqrt(3.0f)) / kPi;

TEST(MeshAttributes, PointinessOfCubeCorners) {
  const Cube cube;
  const std::vector<float> p = pointiness(cube.positions, cube.normals, cube.edges);
  ASSERT_EQ(p.size(), 8u);
  for (float v : p) EXPECT_NEAR(v, kCubeCorner, 1e-6f);
  EXPECT_NEAR(kCubeCorner, 0.6959f, 1e-4f);
}

// A cavity: the cube turned inside out (normals inward) reads 1 - the corner value.
TEST(MeshAttributes, PointinessOfCavity) {
  Cube cube;
  for (Vec3f& n : cube.normals) n = -n;
  for (float v : pointiness(cube.positions, cube.normals, cube.edges))
    EXPECT_NEAR(v, 1.0f - kCubeCorner, 1e-6f);
}

// A flat 4 x 4 grid of quads in z = 0 (edges along x and y): 0.5 everywhere, the interior
// vertex (2, 2) included.
TEST(MeshAttributes, PointinessOfFlatGridIsHalf) {
  std::vector<Vec3f> positions, normals;
  std::vector<int32_t> edges;
  for (int y = 0; y <= 4; ++y)
    for (int x = 0; x <= 4; ++x) {
      positions.emplace_back(float(x), float(y), 0.0f);
      normals.emplace_back(0.0f, 0.0f, 1.0f);
      const int v = y * 5 + x;
      if (x < 4) edges.insert(edges.end(), {v, v + 1});
      if (y < 4) edges.insert(edges.end(), {v, v + 5});
    }
  const std::vector<float> p = pointiness(positions, normals, edges);
  for (float v : p) EXPECT_NEAR(v, 0.5f, 1e-6f);
  EXPECT_NEAR(p[2 * 5 + 2], 0.5f, 1e-6f);
}

// The cube with every face split off (24 vertices, four per face, face normals): welded back
// into 8 corners, each with the normalised sum of its three face normals, as the closed cube.
TEST(MeshAttributes, PointinessWeldsSplitVertices) {
  std::vector<Vec3f> positions, normals;
  std::vector<int32_t> edges;
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      const int base = int(positions.size());
      for (int k = 0; k < 4; ++k) {
        Vec3f p(0.0f);
        p[axis] = float(side);
        p[(axis + 1) % 3] = float(k == 1 || k == 2);
        p[(axis + 2) % 3] = float(k >= 2);
        positions.push_back(p);
        Vec3f n(0.0f);
        n[axis] = side ? 1.0f : -1.0f;
        normals.push_back(n);
        edges.insert(edges.end(), {base + k, base + (k + 1) % 4});
      }
    }
  const std::vector<float> p = pointiness(positions, normals, edges);
  ASSERT_EQ(p.size(), 24u);
  for (float v : p) EXPECT_NEAR(v, kCubeCorner, 1e-6f);
}

float hashed(uint32_t island) {
  return float(hash_words(island)) * (1.0f / float(0xFFFFFFFFu));
}

// Two triangles 0-1-2 and 3-4-5: each island is named by the first vertex its edges join.
TEST(MeshAttributes, RandomPerIslandHashesTheIslandRepresentative) {
  const std::vector<int32_t> edges = {0, 1, 1, 2, 2, 0, 3, 4, 4, 5, 5, 3};
  const std::vector<uint32_t> tris = {1, 2, 0, 5, 3, 4};
  const std::vector<float> r = random_per_island(6, edges, tris);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_EQ(r[0], hashed(0));
  EXPECT_EQ(r[1], hashed(3));
  EXPECT_NE(r[0], r[1]);
  EXPECT_GE(r[0], 0.0f);
  EXPECT_LE(r[0], 1.0f);
}

// Union by rank: joining 1-2 first makes 1 the representative, and 0 then joins under it.
TEST(MeshAttributes, RandomPerIslandFollowsEdgeOrder) {
  const std::vector<uint32_t> tris = {0, 1, 2};
  EXPECT_EQ(random_per_island(3, std::vector<int32_t>{1, 2, 0, 1}, tris)[0], hashed(1));
  EXPECT_EQ(random_per_island(3, std::vector<int32_t>{0, 1, 1, 2}, tris)[0], hashed(0));
}

}  // namespace
}  // namespace gdpt::ingest
