// The add-on's mesh arrays -> Mesh (blender_addon/module/mesh_ingest.h): every malformed array is
// rejected with a message naming the array and the offending element, and valid meshes come out
// as the arrays say.
#include "blender_addon/module/mesh_ingest.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace gdpt::ingest {
namespace {

using Floats = std::vector<float>;
using Ints = std::vector<int32_t>;

// A unit quad in z = 0: vertices 0..3 counter-clockwise, one polygon of four loops.
const Floats kQuad = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
const Ints kQuadLoops = {0, 1, 2, 3};

// The message of the std::invalid_argument `f` throws; fails the test when it throws nothing.
template <typename F>
std::string rejection(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

// `message` starts with the array's name and mentions every one of `parts`.
void expect_names(const std::string& message, const std::string& array,
                  std::initializer_list<const char*> parts) {
  EXPECT_EQ(message.rfind(array + ": ", 0), 0u) << message;
  for (const char* part : parts) EXPECT_NE(message.find(part), std::string::npos) << message;
}

LoopArrays quad_loops() {
  LoopArrays a;
  a.positions = kQuad;
  a.loop_vertex = kQuadLoops;
  return a;
}

TEST(MeshIngest, ValidTrianglesAreCopied) {
  const Ints indices = {0, 1, 2, 0, 2, 3};
  Floats normals(18 * 1, 0.0f);
  for (size_t i = 2; i < normals.size(); i += 3) normals[i] = 1.0f;
  const Floats uvs = {0, 0, 1, 0, 1, 1, 0, 0, 1, 1, 0, 1};
  const Ints slots = {0, 1};
  const Mesh m = mesh_from_triangles(kQuad, indices, normals, uvs, slots);
  ASSERT_EQ(m.positions.size(), 4u);
  EXPECT_EQ(m.positions[2].x, 1.0f);
  EXPECT_EQ(m.positions[2].y, 1.0f);
  EXPECT_EQ(m.indices, std::vector<uint32_t>({0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(m.corner_normals.size(), 6u);
  EXPECT_EQ(m.corner_normals[5].z, 1.0f);
  ASSERT_EQ(m.corner_uvs.size(), 6u);
  EXPECT_EQ(m.corner_uvs[5].y, 1.0f);
  EXPECT_EQ(m.material_slot, Ints({0, 1}));
}

TEST(MeshIngest, ValidQuadPolygonIsSplitAlong02) {
  LoopArrays a = quad_loops();
  const Floats loop_uvs = {0, 0, 1, 0, 1, 1, 0, 1};
  a.loop_uvs = loop_uvs;
  const Ints start = {0}, total = {4}, material = {2};
  const Mesh m = mesh_from_polys(a, start, total, material);
  EXPECT_EQ(m.indices, std::vector<uint32_t>({0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(m.corner_uvs.size(), 6u);
  EXPECT_EQ(m.corner_uvs[4].x, 1.0f);  // loop 2
  EXPECT_EQ(m.material_slot, Ints({2, 2}));
}

// Blender's vertex normals: each polygon's normal weighted by its angle at the vertex. Two
// triangles meet at O = (0, 0, 0) and Y = (0, 1, 0): one in z = 0 (normal +z, 90 degrees at O,
// 45 at Y), one in x = 0 (normal +x, 45 degrees at O, 90 at Y): O's normal (1, 0, 2) / sqrt 5, Y's
// (2, 0, 1) / sqrt 5. A cube's corners (three quads at 90 degrees): (+-1, +-1, +-1) / sqrt 3.
TEST(MeshIngest, SmoothVertexNormalsWeighPolygonsByCornerAngle) {
  LoopArrays a;
  const Floats positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 1, 1};
  const Ints loops = {0, 1, 2, 0, 2, 3};
  a.positions = positions;
  a.loop_vertex = loops;
  const Ints start = {0, 3}, total = {3, 3};
  const Mesh m = mesh_from_polys(a, start, total, {}, true);
  ASSERT_EQ(m.vertex_normals.size(), 4u);
  const float r5 = 1.0f / std::sqrt(5.0f);
  EXPECT_NEAR(m.vertex_normals[0].x, r5, 1e-6f);
  EXPECT_NEAR(m.vertex_normals[0].y, 0.0f, 1e-6f);
  EXPECT_NEAR(m.vertex_normals[0].z, 2.0f * r5, 1e-6f);
  EXPECT_NEAR(m.vertex_normals[2].x, 2.0f * r5, 1e-6f);
  EXPECT_NEAR(m.vertex_normals[2].z, r5, 1e-6f);
  EXPECT_NEAR(m.vertex_normals[1].z, 1.0f, 1e-6f);  // only in the first triangle
  EXPECT_NEAR(m.vertex_normals[3].x, 1.0f, 1e-6f);  // only in the second

  // A unit cube of six outward quads.
  const Floats cube = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1};
  const Ints faces = {0, 3, 2, 1, 4, 5, 6, 7, 0, 1, 5, 4, 1, 2, 6, 5, 2, 3, 7, 6, 3, 0, 4, 7};
  LoopArrays c;
  c.positions = cube;
  c.loop_vertex = faces;
  const Ints cube_start = {0, 4, 8, 12, 16, 20}, fours = {4, 4, 4, 4, 4, 4};
  const Mesh box = mesh_from_polys(c, cube_start, fours, {}, true);
  ASSERT_EQ(box.vertex_normals.size(), 8u);
  const float r3 = 1.0f / std::sqrt(3.0f);
  for (size_t v = 0; v < 8; ++v) {
    const Vec3f want((cube[3 * v] - 0.5f) * 2.0f * r3, (cube[3 * v + 1] - 0.5f) * 2.0f * r3,
                     (cube[3 * v + 2] - 0.5f) * 2.0f * r3);
    EXPECT_NEAR(box.vertex_normals[v].x, want.x, 1e-6f) << v;
    EXPECT_NEAR(box.vertex_normals[v].y, want.y, 1e-6f) << v;
    EXPECT_NEAR(box.vertex_normals[v].z, want.z, 1e-6f) << v;
  }
  // Finite coordinates near FLT_MAX: their differences overflow a float, the normals do not.
  const float big = 3e38f;
  const Floats huge = {-big, -big, 0, big, -big, 0, 0, big, 0};
  const Ints tri = {0, 1, 2}, zero = {0}, three = {3};
  LoopArrays h;
  h.positions = huge;
  h.loop_vertex = tri;
  const Mesh far = mesh_from_polys(h, zero, three, {}, true);
  ASSERT_EQ(far.vertex_normals.size(), 3u);
  for (const Vec3f& n : far.vertex_normals) EXPECT_NEAR(n.z, 1.0f, 1e-6f);
  // Blender's own normals given too: refused, not silently replaced.
  LoopArrays given = c;
  const Floats normals(24, 0.0f);
  given.normals = normals;
  expect_names(rejection([&] { mesh_from_polys(given, cube_start, fours, {}, true); }), "normals",
               {"smooth_vertex_normals"});
}

TEST(MeshIngest, ValidLoopTrianglesGatherCorners) {
  LoopArrays a = quad_loops();
  const Floats normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  a.normals = normals;  // per vertex: kept per vertex
  const Ints corners = {3, 2, 1};
  const Mesh m = mesh_from_loops(a, corners, Ints{});
  EXPECT_EQ(m.indices, std::vector<uint32_t>({3, 2, 1}));
  EXPECT_EQ(m.vertex_normals.size(), 4u);
  EXPECT_TRUE(m.corner_normals.empty());
  EXPECT_TRUE(m.material_slot.empty());
}

TEST(MeshIngest, RejectsEmptyArrays) {
  expect_names(rejection([] {
                 mesh_from_triangles({}, Ints{0, 0, 0}, {}, {}, {});
               }),
               "positions", {"empty"});
  expect_names(rejection([] { mesh_from_triangles(kQuad, {}, {}, {}, {}); }), "indices", {"empty"});
  LoopArrays no_loops = quad_loops();
  no_loops.loop_vertex = {};
  expect_names(rejection([&] { mesh_from_polys(no_loops, Ints{0}, Ints{3}, {}); }), "loop_vertex",
               {"empty"});
  expect_names(rejection([] { mesh_from_polys(quad_loops(), {}, {}, {}); }), "loop_start",
               {"empty"});
  expect_names(rejection([] { mesh_from_loops(quad_loops(), {}, {}); }), "corner_loops", {"empty"});
}

TEST(MeshIngest, RejectsPartialElements) {
  const Floats five = {0, 0, 0, 1, 0};
  expect_names(rejection([&] {
                 mesh_from_triangles(five, Ints{0, 0, 0}, {}, {}, {});
               }),
               "positions", {"5", "multiple of 3"});
  expect_names(rejection([] {
                 mesh_from_triangles(kQuad, Ints{0, 1, 2, 3}, {}, {}, {});
               }),
               "indices", {"4", "multiple of 3"});
  expect_names(rejection([] {
                 mesh_from_loops(quad_loops(), Ints{0, 1}, {});
               }),
               "corner_loops", {"2", "multiple of 3"});
}

TEST(MeshIngest, RejectsIndicesOutOfRange) {
  expect_names(rejection([] {
                 mesh_from_triangles(kQuad, Ints{0, 1, 2, 0, 2, 4}, {}, {}, {});
               }),
               "indices", {"value 5 is 4", "[0, 4)"});
  expect_names(rejection([] {
                 mesh_from_triangles(kQuad, Ints{0, -1, 2}, {}, {}, {});
               }),
               "indices", {"value 1 is -1"});
  LoopArrays bad_vertex = quad_loops();
  const Ints loops = {0, 1, 7, 3};
  bad_vertex.loop_vertex = loops;
  expect_names(rejection([&] { mesh_from_polys(bad_vertex, Ints{0}, Ints{4}, {}); }), "loop_vertex",
               {"value 2 is 7", "[0, 4)"});
  expect_names(rejection([] {
                 mesh_from_loops(quad_loops(), Ints{0, 1, 4}, {});
               }),
               "corner_loops", {"value 2 is 4", "[0, 4)"});
  expect_names(rejection([] {
                 mesh_from_polys(quad_loops(), Ints{0, 2}, Ints{4, 3}, {});
               }),
               "loop_start", {"value 1 is 2", "[2, 5)", "[0, 4)"});
  expect_names(rejection([] { mesh_from_polys(quad_loops(), Ints{-2}, Ints{3}, {}); }),
               "loop_start", {"value 0 is -2"});
  expect_names(rejection([] { mesh_from_polys(quad_loops(), Ints{0}, Ints{5}, {}); }), "loop_total",
               {"value 0 is 5", "3 or 4"});
  expect_names(rejection([] { mesh_from_polys(quad_loops(), Ints{0}, Ints{2}, {}); }), "loop_total",
               {"value 0 is 2"});
}

TEST(MeshIngest, RejectsNonFinitePositions) {
  for (const float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
        -std::numeric_limits<float>::infinity()}) {
    Floats p = kQuad;
    p[7] = bad;  // vertex 2, y
    expect_names(rejection([&] {
                   mesh_from_triangles(p, Ints{0, 1, 2}, {}, {}, {});
                 }),
                 "positions", {"vertex 2 coordinate 1", "finite"});
    LoopArrays a = quad_loops();
    a.positions = p;
    expect_names(rejection([&] { mesh_from_polys(a, Ints{0}, Ints{4}, {}); }), "positions",
                 {"vertex 2"});
  }
}

TEST(MeshIngest, RejectsMismatchedLengths) {
  const Ints tri = {0, 1, 2};
  expect_names(rejection([&] { mesh_from_triangles(kQuad, tri, Floats(8), {}, {}); }),
               "corner_normals", {"expected 9", "got 8"});
  expect_names(rejection([&] { mesh_from_triangles(kQuad, tri, {}, Floats(7), {}); }), "corner_uvs",
               {"expected 6", "got 7"});
  expect_names(rejection([&] {
                 mesh_from_triangles(kQuad, tri, {}, {}, Ints{0, 0});
               }),
               "material_slot", {"expected 1", "got 2"});
  const Ints start = {0}, total = {4};
  const Floats three(3), nine(9), eleven(11), fifteen(15);
  LoopArrays a = quad_loops();
  a.normals = three;
  expect_names(rejection([&] { mesh_from_polys(a, start, total, {}); }), "normals",
               {"expected 12", "per vertex", "got 3"});
  a = quad_loops();
  a.normals = nine;
  a.normals_per_loop = true;
  expect_names(rejection([&] { mesh_from_polys(a, start, total, {}); }), "normals",
               {"expected 12", "per loop", "got 9"});
  a = quad_loops();
  a.loop_uvs = nine;
  expect_names(rejection([&] { mesh_from_polys(a, start, total, {}); }), "loop_uvs",
               {"expected 8", "got 9"});
  a = quad_loops();
  a.loop_tangents = fifteen;
  expect_names(rejection([&] { mesh_from_polys(a, start, total, {}); }), "loop_tangents",
               {"expected 16", "got 15"});
  a = quad_loops();
  a.loop_colors = eleven;
  expect_names(rejection([&] { mesh_from_polys(a, start, total, {}); }), "loop_colors",
               {"expected 12", "got 11"});
  expect_names(rejection([&] {
                 mesh_from_polys(quad_loops(), start, Ints{4, 4}, {});
               }),
               "loop_total", {"expected 1", "got 2"});
  expect_names(rejection([&] {
                 mesh_from_polys(quad_loops(), start, total, Ints{0, 0});
               }),
               "poly_material", {"expected 1", "got 2"});
  expect_names(rejection([&] {
                 mesh_from_loops(quad_loops(), tri, Ints{0, 0});
               }),
               "material_slot", {"expected 1", "got 2"});
}

TEST(MeshIngest, RejectsMaterialSlotsOutOfRange) {
  const Ints tri = {0, 1, 2};
  expect_names(rejection([&] { mesh_from_triangles(kQuad, tri, {}, {}, Ints{-1}); }),
               "material_slot", {"value 0 is -1", "[0, 32767)"});
  expect_names(rejection([&] { mesh_from_loops(quad_loops(), tri, Ints{kMaxMaterialSlots}); }),
               "material_slot", {"value 0 is 32767"});
  expect_names(rejection([] { mesh_from_polys(quad_loops(), Ints{0}, Ints{4}, Ints{-3}); }),
               "poly_material", {"value 0 is -3"});
}

// Found by fuzz_mesh_ingest (a false alarm of its own check, which summed the coordinates): finite
// coordinates near FLT_MAX are finite, so they are accepted and copied bit for bit.
TEST(MeshIngest, AcceptsFiniteCoordinatesNearFloatMax) {
  const float big = std::numeric_limits<float>::max();
  const Floats p = {0, 0, 0, -9.1e-41f, -0.99999f * big, -1.06e37f, 2.3e-41f, 0, 0};
  const Mesh m = mesh_from_triangles(p, Ints{0, 1, 2}, {}, {}, {});
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[1].y, -0.99999f * big);
  EXPECT_EQ(m.positions[1].x, -9.1e-41f);  // denormals kept
}

}  // namespace
}  // namespace gdpt::ingest
