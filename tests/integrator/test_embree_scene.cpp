// Embree BVH hit records: positions, normals through instance transforms, UVs, material slots,
// degenerate triangles, self-intersection avoidance far from the origin, instancing.
#include <gtest/gtest.h>

#include <cmath>

#include "core/frame.h"
#include "render/embree_scene.h"
#include "render/sampler.h"

namespace gdpt {
namespace {

// Unit quad in z = 0 spanning [-1, 1]^2, normal +z, two triangles with slots 0 and 1.
Mesh quad() {
  Mesh m;
  m.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.corner_uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
  m.material_slot = {0, 1};
  return m;
}

Transform translate_scale(Vec3f t, Vec3f s) {
  Transform T;
  T.m[0][0] = s.x;
  T.m[1][1] = s.y;
  T.m[2][2] = s.z;
  T.m[0][3] = t.x;
  T.m[1][3] = t.y;
  T.m[2][3] = t.z;
  return T;
}

Ray down(float x, float y, float z = 5.0f) {
  Ray r;
  r.origin = {x, y, z};
  r.direction = {0, 0, -1};
  return r;
}

TEST(EmbreeScene, HitRecordOfAnInstancedQuad) {
  Scene scene;
  scene.meshes.push_back(quad());
  Instance inst;
  inst.object_to_world = translate_scale({10, 0, 1}, {2, 2, 2});
  inst.slot_material = {4, 7};
  scene.instances.push_back(inst);
  EmbreeScene bvh(scene, 9);
  SurfaceHit hit;
  // World point (10.6, 1.4, 1) = object (0.3, 0.7, 0): upper-left triangle (slot 1).
  ASSERT_TRUE(bvh.intersect(down(10.6f, 1.4f), hit));
  EXPECT_NEAR(hit.t, 4.0f, 1e-5f);
  EXPECT_NEAR(hit.position.x, 10.6f, 1e-5f);
  EXPECT_NEAR(hit.position.z, 1.0f, 1e-6f);
  EXPECT_NEAR(hit.geometric_normal.z, 1.0f, 1e-6f);
  EXPECT_NEAR(hit.shading_normal.z, 1.0f, 1e-6f);  // flat: shading = geometric
  EXPECT_TRUE(hit.front_facing);
  EXPECT_NEAR(hit.uv.x, 0.65f, 1e-5f);
  EXPECT_NEAR(hit.uv.y, 0.85f, 1e-5f);
  EXPECT_EQ(hit.material, 7);
  ASSERT_TRUE(bvh.intersect(down(11.5f, -1.0f), hit));
  EXPECT_EQ(hit.material, 4);
  // From below: back face.
  Ray up = down(11.0f, 1.0f, -3.0f);
  up.direction = {0, 0, 1};
  ASSERT_TRUE(bvh.intersect(up, hit));
  EXPECT_FALSE(hit.front_facing);
  EXPECT_FALSE(bvh.intersect(down(13.5f, 0.0f), hit));  // outside the scaled quad
  EXPECT_TRUE(bvh.occluded(down(10.0f, 0.0f)));
  Ray short_ray = down(10.0f, 0.0f);
  short_ray.t_max = 3.9f;
  EXPECT_FALSE(bvh.occluded(short_ray));
}

TEST(EmbreeScene, OutOfRangeSlotsUseTheDefaultMaterial) {
  Scene scene;
  Mesh m = quad();
  m.material_slot = {0, 5};
  scene.meshes.push_back(m);
  Instance inst;
  inst.slot_material = {-1};
  scene.instances.push_back(inst);
  EmbreeScene bvh(scene, 3);
  SurfaceHit hit;
  ASSERT_TRUE(bvh.intersect(down(0.5f, -0.5f), hit));
  EXPECT_EQ(hit.material, 3);  // slot 0 -> -1 -> default
  ASSERT_TRUE(bvh.intersect(down(-0.5f, 0.5f), hit));
  EXPECT_EQ(hit.material, 3);  // slot 5 beyond the map -> default
}

TEST(EmbreeScene, NormalsTransformByInverseTranspose) {
  // A 45-degree ramp z = x, stretched by 2 along x: world surface z = x / 2, whose normal is
  // proportional to (-1/2, 0, 1), not to the scaled object normal (-2, 0, 1).
  Scene scene;
  Mesh m;
  m.positions = {{-1, -1, -1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, -1}};
  m.indices = {0, 1, 2, 0, 2, 3};
  const Vec3f n = normalize(Vec3f(-1, 0, 1));
  m.corner_normals.assign(6, n);
  scene.meshes.push_back(m);
  Instance inst;
  inst.object_to_world = translate_scale({0, 0, 0}, {2, 1, 1});
  scene.instances.push_back(inst);
  EmbreeScene bvh(scene, 0);
  SurfaceHit hit;
  ASSERT_TRUE(bvh.intersect(down(0.5f, 0.0f), hit));
  const Vec3f expect = normalize(Vec3f(-0.5f, 0, 1));
  EXPECT_NEAR(hit.position.z, 0.25f, 1e-5f);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(hit.geometric_normal[c], expect[c], 1e-5f);
    EXPECT_NEAR(hit.shading_normal[c], expect[c], 1e-5f);
  }
}

TEST(EmbreeScene, VertexNormalsShadeAsTheSameCornerNormals) {
  // Per-vertex normals give exactly the shading normals of the equivalent per-corner array, for
  // a flattened and for an instanced placement.
  Mesh a;
  a.positions = {{-1, -1, 0}, {1, -1, 0.3f}, {1, 1, 0}, {-1, 1, -0.2f}};
  a.indices = {0, 1, 2, 0, 2, 3};
  a.vertex_normals = {normalize(Vec3f(-0.3f, -0.2f, 1)), normalize(Vec3f(0.4f, -0.1f, 1)),
                      normalize(Vec3f(0.2f, 0.5f, 1)), normalize(Vec3f(-0.1f, 0.3f, 1))};
  Mesh b = a;
  b.vertex_normals.clear();
  for (uint32_t i : a.indices) b.corner_normals.push_back(a.vertex_normals[i]);
  for (int copies : {1, 2}) {
    Scene sa, sb;
    sa.meshes.push_back(a);
    sb.meshes.push_back(b);
    for (int c = 0; c < copies; ++c) {
      Instance inst;
      inst.object_to_world = translate_scale({0, 0, -3.0f * float(c)}, {1.5f, 1, 1});
      sa.instances.push_back(inst);
      sb.instances.push_back(inst);
    }
    EmbreeScene ba(sa, 0), bb(sb, 0);
    for (float x : {-0.9f, -0.3f, 0.2f, 0.8f})
      for (float y : {-0.7f, 0.1f, 0.6f}) {
        SurfaceHit ha, hb;
        ASSERT_TRUE(ba.intersect(down(x, y), ha));
        ASSERT_TRUE(bb.intersect(down(x, y), hb));
        for (int c = 0; c < 3; ++c) EXPECT_EQ(ha.shading_normal[c], hb.shading_normal[c]);
        EXPECT_GT(length(ha.shading_normal - ha.geometric_normal), 1e-3f);
      }
  }
}

TEST(EmbreeScene, DegenerateTrianglesNeverGiveNaN) {
  Scene scene;
  Mesh m;
  // A sliver (collinear), a point triangle and a normal triangle.
  m.positions = {{-1, 0, 0},   {0, 0, 0},   {1, 0, 0}, {0.2f, 0.2f, 0},
                 {-2, -2, -1}, {2, -2, -1}, {0, 2, -1}};
  m.indices = {0, 1, 2, 3, 3, 3, 4, 5, 6};
  m.corner_normals = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0},
                      {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};  // zero normals too
  scene.meshes.push_back(m);
  scene.instances.push_back(Instance{});
  EmbreeScene bvh(scene, 0);
  Sampler s;
  int hits = 0;
  for (uint32_t i = 0; i < 2000; ++i) {
    s.start(3, 0, 0, i);
    const Vec2f u = s.get2d(0);
    Ray r = down(u.x * 1.6f - 0.8f, (u.y - 0.5f) * 0.01f);
    SurfaceHit hit;
    if (!bvh.intersect(r, hit)) continue;
    ++hits;
    ASSERT_TRUE(is_finite(hit.geometric_normal));
    ASSERT_TRUE(is_finite(hit.shading_normal));
    ASSERT_NEAR(length(hit.shading_normal), 1.0f, 1e-4f);
  }
  EXPECT_EQ(hits, 2000);  // the big triangle underneath catches everything
}

TEST(EmbreeScene, FlattenedHitsCarryTheirTrianglesUnitNormal) {
  // 64 small triangles in a row along x, each tilted its own way, placed once (flattened, whose
  // normals are computed at build time) by a transform that mirrors and scales: each hit's
  // geometric normal is its own world-space triangle's, facing the object's front side.
  Scene scene;
  Mesh m;
  Sampler s;
  constexpr int kTris = 64;
  for (int t = 0; t < kTris; ++t) {
    s.start(5, 0, 0, uint32_t(t));
    const Vec2f a = s.get2d(0), b = s.get2d(1);
    const float x = float(t), h = 0.4f;
    m.positions.push_back({x - h, -h, (a.x - 0.5f) * 0.5f});
    m.positions.push_back({x + h, -h, (a.y - 0.5f) * 0.5f});
    m.positions.push_back({x, h, (b.x - 0.5f) * 0.5f});
    for (uint32_t k = 0; k < 3; ++k) m.indices.push_back(uint32_t(3 * t) + k);
  }
  scene.meshes.push_back(m);
  Instance inst;
  inst.object_to_world = translate_scale({0.5f, 1.0f, 0.25f}, {-1.0f, 2.0f, 1.5f});
  scene.instances.push_back(inst);
  EmbreeScene bvh(scene, 0);
  const Transform& T = inst.object_to_world;
  for (int t = 0; t < kTris; ++t) {
    const Vec3f p0 = T.point(m.positions[size_t(3 * t)]),
                p1 = T.point(m.positions[size_t(3 * t + 1)]),
                p2 = T.point(m.positions[size_t(3 * t + 2)]);
    const Vec3f c = (p0 + p1 + p2) / 3.0f;
    SurfaceHit hit;
    ASSERT_TRUE(bvh.intersect(down(c.x, c.y), hit)) << t;
    EXPECT_EQ(hit.primitive, uint32_t(t));
    // The mirror (det < 0) reverses the world winding; the front side stays the object's (+z).
    const Vec3f expect = -normalize(cross(p1 - p0, p2 - p0));
    EXPECT_GT(expect.z, 0.0f);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(hit.geometric_normal[k], expect[k], 1e-6f) << t;
    EXPECT_TRUE(hit.front_facing);
  }
}

TEST(EmbreeScene, OffsetRaysDoNotSelfIntersectFarFromTheOrigin) {
  // A tilted plane 1e4 m away: float spacing there is ~1e-3 m; naive epsilons fail at this scale.
  Scene scene;
  Mesh m;
  const float c = 1.0e4f;
  m.positions = {{c - 100, c - 100, c - 30},
                 {c + 100, c - 100, c + 30},
                 {c + 100, c + 100, c + 30},
                 {c - 100, c + 100, c - 30}};
  m.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(m);
  scene.instances.push_back(Instance{});
  EmbreeScene bvh(scene, 0);
  Sampler s;
  int self_hits = 0;
  for (uint32_t i = 0; i < 4000; ++i) {
    s.start(11, 0, 0, i);
    const Vec2f u = s.get2d(0), v = s.get2d(1);
    Ray r = down(c + (u.x - 0.5f) * 50.0f, c + (u.y - 0.5f) * 50.0f, c + 200.0f);
    SurfaceHit hit;
    ASSERT_TRUE(bvh.intersect(r, hit));
    const Vec3f n = hit.geometric_normal;  // faces +z-ish, the side we came from
    // Grazing directions leaving the upper side.
    const Frame f(n);
    const float phi = 2.0f * kPi * v.x, cos_t = 0.001f + 0.05f * v.y;
    const float sin_t = std::sqrt(1.0f - cos_t * cos_t);
    Ray out;
    out.origin = offset_ray_origin(hit.position, n, bvh.offset_scale());
    out.direction = f.to_world({sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t});
    SurfaceHit again;
    if (bvh.intersect(out, again)) ++self_hits;
  }
  EXPECT_EQ(self_hits, 0);
}

TEST(EmbreeScene, HitsReportSceneInstanceIndices) {
  // Instance 0 is flattened to zero volume (skipped), instance 1 places a single-use mesh (stored
  // in world space), instances 2 and 3 share a mesh (Embree instances).
  Scene scene;
  scene.meshes = {quad(), quad()};
  Instance flat;
  flat.object_to_world = translate_scale({0, 0, 0}, {1, 1, 0});
  scene.instances.push_back(flat);
  Instance single;
  single.mesh = 1;
  single.object_to_world = translate_scale({0, 0, 1}, {1, 1, 1});
  single.slot_material = {2, 2};
  scene.instances.push_back(single);
  for (float x : {5.0f, 10.0f}) {
    Instance shared;
    shared.object_to_world = translate_scale({x, 0, 0}, {1, 1, 1});
    scene.instances.push_back(shared);
  }
  EmbreeScene bvh(scene, 3);
  SurfaceHit hit;
  ASSERT_TRUE(bvh.intersect(down(0.2f, -0.5f), hit));
  EXPECT_EQ(hit.instance, 1u);
  EXPECT_EQ(hit.material, 2);
  EXPECT_NEAR(hit.position.z, 1.0f, 1e-6f);
  ASSERT_TRUE(bvh.intersect(down(5.2f, -0.5f), hit));
  EXPECT_EQ(hit.instance, 2u);
  EXPECT_EQ(hit.material, 3);  // no slot map: default
  ASSERT_TRUE(bvh.intersect(down(10.2f, -0.5f), hit));
  EXPECT_EQ(hit.instance, 3u);
  EXPECT_EQ(bvh.triangle_count(), 4u);
}

TEST(EmbreeScene, ManyInstancesShareOneMesh) {
  Scene scene;
  scene.meshes.push_back(quad());
  for (int i = 0; i < 100; ++i) {
    Instance inst;
    inst.object_to_world = translate_scale({float(3 * i), 0, float(i % 3)}, {1, 1, 1});
    scene.instances.push_back(inst);
  }
  EmbreeScene bvh(scene, 0);
  EXPECT_EQ(bvh.triangle_count(), 2u);
  EXPECT_EQ(bvh.instanced_triangle_count(), 200u);
  SurfaceHit hit;
  for (int i = 0; i < 100; ++i) {
    ASSERT_TRUE(bvh.intersect(down(float(3 * i) + 0.3f, 0.2f), hit));
    EXPECT_EQ(hit.instance, uint32_t(i));
    EXPECT_NEAR(hit.position.z, float(i % 3), 1e-5f);
  }
}

// The right triangle of test_shadow_terminator.cpp (x, y in [0, 1], z = 0) with its tilted
// vertex normals: at the centroid the lift towards the curved surface is 0.28 times the
// interpolated normal (0.04, 0.08, 0.8), taken whole by a light along +x (at the terminator).
Mesh tilted_triangle() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {0, 1, 2};
  m.vertex_normals = {{-0.48f, -0.36f, 0.8f}, {0.6f, 0, 0.8f}, {0, 0.6f, 0.8f}};
  return m;
}

TEST(EmbreeScene, ShadowRaysStartOnTheCurvedSurfaceOfSmoothTriangles) {
  // One placement (flattened to world space) and two of another copy (two-level instancing),
  // scaled by 2: the lift scales with the object, as Cycles' object-space lift does.
  Scene scene;
  scene.meshes = {tilted_triangle(), tilted_triangle(), tilted_triangle()};
  Instance flat_placed;
  flat_placed.mesh = 0;
  flat_placed.object_to_world = translate_scale({5, 0, 0}, {1, 1, 1});
  scene.instances.push_back(flat_placed);
  for (float y : {10.0f, 20.0f}) {
    Instance inst;
    inst.mesh = 1;
    inst.object_to_world = translate_scale({0, y, 0}, {2, 2, 2});
    scene.instances.push_back(inst);
  }
  Instance off = flat_placed;  // Geometry Offset 0: no lift
  off.mesh = 2;
  off.object_to_world = translate_scale({-5, 0, 0}, {1, 1, 1});
  off.terminator_geometry_offset = 0.0f;
  scene.instances.push_back(off);
  EmbreeScene bvh(scene, 0);
  const Vec3f lift = Vec3f(0.04f, 0.08f, 0.8f) * 0.28f, light(1, 0, 0);
  const float third = 1.0f / 3.0f;
  struct Case {
    Vec3f at;
    float scale;
  };
  for (const Case& c :
       {Case{{5 + third, third, 0}, 1.0f}, Case{{2 * third, 10 + 2 * third, 0}, 2.0f},
        Case{{2 * third, 20 + 2 * third, 0}, 2.0f}}) {
    SurfaceHit hit;
    ASSERT_TRUE(bvh.intersect(down(c.at.x, c.at.y), hit));
    EXPECT_TRUE(bvh.lifts_shadow_rays(hit));
    const Vec3f start = bvh.shadow_ray_start(hit, light);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(start[k], c.at[k] + c.scale * lift[k], 2e-5f) << k;
    // Well above the terminator (light straight up): no lift.
    EXPECT_EQ(bvh.shadow_ray_start(hit, Vec3f(0, 0, 1)), hit.position);
  }
  SurfaceHit hit;
  ASSERT_TRUE(bvh.intersect(down(-5 + third, third), hit));
  EXPECT_FALSE(bvh.lifts_shadow_rays(hit));
  EXPECT_EQ(bvh.shadow_ray_start(hit, light), hit.position);
}

TEST(EmbreeScene, MirroringTransformsKeepTheObjectSpaceFrontFace) {
  // The quad faces +z in object space; mirrored in x its inverse-transpose normal still faces +z
  // (Cycles keeps the object's orientation for negatively scaled objects), although the world
  // winding is reversed. Placed once (flattened into world space) and 200 times (instanced).
  for (int copies : {1, 200}) {
    Scene scene;
    scene.meshes.push_back(quad());
    for (int i = 0; i < copies; ++i) {
      Instance inst;
      inst.object_to_world = translate_scale({float(3 * i), 0, 0}, {-1, 1, 1});
      scene.instances.push_back(inst);
    }
    EmbreeScene bvh(scene, 0);
    SurfaceHit hit;
    ASSERT_TRUE(bvh.intersect(down(0.3f, 0.2f), hit)) << copies;
    EXPECT_NEAR(hit.geometric_normal.z, 1.0f, 1e-6f) << copies;
    EXPECT_TRUE(hit.front_facing) << copies;
    EXPECT_NEAR(hit.position.x, 0.3f, 1e-6f) << copies;
  }
}

}  // namespace
}  // namespace gdpt
