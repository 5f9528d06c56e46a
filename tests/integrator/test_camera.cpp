// Camera projection against hand-computed Blender/Cycles viewplanes: sensor fits, shift, pixel
// aspect, orthographic, depth of field and clipping. Raster y = 0 is the bottom row.
#include <gtest/gtest.h>

#include <cmath>
#include <iterator>

#include "core/warp_disk.h"
#include "render/camera.h"
#include "shaders/object_nodes.h"

namespace gdpt {
namespace {

// Camera at the origin looking down -Z (Blender's identity camera), 50 mm lens.
Camera base_camera(int w, int h) {
  Camera c;
  c.width = w;
  c.height = h;
  c.focal_length_mm = 50.0f;
  c.sensor_width_mm = 36.0f;
  c.sensor_height_mm = 24.0f;
  c.clip_start = 0.01f;
  return c;
}

Vec2f project(const Camera& c, Vec3f p) {
  Vec2f r;
  EXPECT_TRUE(CameraModel(c).project(p, r));
  return r;
}

TEST(Camera, AutoFitLandscapeUsesSensorWidthAcrossWidth) {
  const Camera c = base_camera(200, 100);
  // Half-width of the view at depth 10: 10 * 18 / 50 = 3.6 m; half-height = 1.8 m.
  const Vec2f right = project(c, {3.6f, 0.0f, -10.0f});
  EXPECT_NEAR(right.x, 200.0f, 1e-3f);
  EXPECT_NEAR(right.y, 50.0f, 1e-3f);
  const Vec2f top = project(c, {0.0f, 1.8f, -10.0f});
  EXPECT_NEAR(top.x, 100.0f, 1e-3f);
  EXPECT_NEAR(top.y, 100.0f, 1e-3f);  // +Y is up: the top row has the largest y
  const Vec2f q = project(c, {-1.8f, -0.9f, -10.0f});
  EXPECT_NEAR(q.x, 50.0f, 1e-3f);
  EXPECT_NEAR(q.y, 25.0f, 1e-3f);
}

TEST(Camera, PerspectiveRayDirectionsMatchTheSensor) {
  // Right edge of a 200x100 image at 50 mm / 36 mm: direction (18/50, 0, -1); top edge (0, 9/50).
  const CameraModel cam(base_camera(200, 100));
  const Ray r = cam.generate_ray({200.0f, 50.0f}, {0.5f, 0.5f});
  EXPECT_NEAR(r.direction.x / -r.direction.z, 0.36f, 1e-6f);
  EXPECT_NEAR(r.direction.y, 0.0f, 1e-6f);
  const Ray t = cam.generate_ray({100.0f, 100.0f}, {0.5f, 0.5f});
  EXPECT_NEAR(t.direction.y / -t.direction.z, 0.18f, 1e-6f);
  const Ray b = cam.generate_ray({100.0f, 0.0f}, {0.5f, 0.5f});
  EXPECT_LT(b.direction.y, 0.0f);  // raster y = 0 is the bottom row
}

TEST(Camera, AutoFitPortraitUsesSensorWidthAcrossHeight) {
  const Camera c = base_camera(100, 200);
  const Vec2f top = project(c, {0.0f, 3.6f, -10.0f});
  EXPECT_NEAR(top.y, 200.0f, 1e-3f);
  const Vec2f right = project(c, {1.8f, 0.0f, -10.0f});
  EXPECT_NEAR(right.x, 100.0f, 1e-3f);
}

TEST(Camera, VerticalFitUsesSensorHeight) {
  Camera c = base_camera(200, 100);
  c.sensor_fit = Camera::SensorFit::Vertical;
  // Half-height at depth 10: 10 * 12 / 50 = 2.4 m, half-width 4.8 m.
  EXPECT_NEAR(project(c, {0.0f, 2.4f, -10.0f}).y, 100.0f, 1e-3f);
  EXPECT_NEAR(project(c, {4.8f, 0.0f, -10.0f}).x, 200.0f, 1e-3f);
}

TEST(Camera, HorizontalFitOnPortraitImage) {
  Camera c = base_camera(100, 200);
  c.sensor_fit = Camera::SensorFit::Horizontal;
  EXPECT_NEAR(project(c, {3.6f, 0.0f, -10.0f}).x, 100.0f, 1e-3f);
  EXPECT_NEAR(project(c, {0.0f, 7.2f, -10.0f}).y, 200.0f, 1e-3f);
}

TEST(Camera, ShiftIsInUnitsOfTheLargerDimension) {
  Camera c = base_camera(200, 100);
  c.shift_x = 0.5f;   // half the width: the optical axis moves to the left edge
  c.shift_y = 0.25f;  // a quarter of the WIDTH = half the height: axis moves to the bottom edge
  const Vec2f centre = project(c, {0.0f, 0.0f, -10.0f});
  EXPECT_NEAR(centre.x, 0.0f, 1e-3f);
  EXPECT_NEAR(centre.y, 0.0f, 1e-3f);
}

TEST(Camera, PixelAspectStretchesHorizontally) {
  Camera c = base_camera(100, 100);
  c.pixel_aspect = 2.0f;  // the image is 200 x 100 "square" units wide: horizontal fit
  EXPECT_NEAR(project(c, {3.6f, 0.0f, -10.0f}).x, 100.0f, 1e-3f);
  EXPECT_NEAR(project(c, {0.0f, 1.8f, -10.0f}).y, 100.0f, 1e-3f);
}

TEST(Camera, OrthographicScaleAcrossFittedDimension) {
  Camera c = base_camera(200, 100);
  c.projection = Camera::Projection::Orthographic;
  c.ortho_scale = 4.0f;  // 4 m across the width, 2 m across the height
  const Vec2f p = project(c, {1.0f, 0.5f, -3.0f});
  EXPECT_NEAR(p.x, 150.0f, 1e-3f);
  EXPECT_NEAR(p.y, 75.0f, 1e-3f);
  const Ray r = CameraModel(c).generate_ray({150.0f, 75.0f}, {0.5f, 0.5f});
  EXPECT_NEAR(r.direction.z, -1.0f, 1e-6f);
  EXPECT_NEAR(r.origin.x, 1.0f, 1e-5f);
  EXPECT_NEAR(r.origin.y, 0.5f, 1e-5f);
  c.shift_x = 0.25f;  // a quarter of the larger dimension = 1 m
  EXPECT_NEAR(project(c, {1.0f, 0.5f, -3.0f}).x, 100.0f, 1e-3f);
}

TEST(Camera, GeneratedRaysProjectBackToTheirRasterPosition) {
  Camera c = base_camera(64, 48);
  // A rotated, translated camera.
  const float a = 0.3f;
  const float rows[12] = {std::cos(a), 0,    std::sin(a),  1.0f, 0,           1,
                          0,           2.0f, -std::sin(a), 0,    std::cos(a), -3.0f};
  c.camera_to_world = Transform::from_rows(rows);
  c.shift_x = 0.1f;
  c.shift_y = -0.05f;
  const CameraModel cam(c);
  for (Vec2f raster : {Vec2f(0.5f, 0.5f), Vec2f(63.2f, 1.7f), Vec2f(10.0f, 47.9f)}) {
    const Ray r = cam.generate_ray(raster, {0.5f, 0.5f});
    EXPECT_NEAR(length(r.direction), 1.0f, 1e-5f);
    Vec2f back;
    ASSERT_TRUE(cam.project(r.origin + r.direction * 7.0f, back));
    EXPECT_NEAR(back.x, raster.x, 1e-3f);
    EXPECT_NEAR(back.y, raster.y, 1e-3f);
  }
}

TEST(Camera, ClipStartIsAlongTheViewAxis) {
  Camera c = base_camera(200, 100);
  c.clip_start = 0.5f;
  const Ray centre = CameraModel(c).generate_ray({100.0f, 50.0f}, {0.5f, 0.5f});
  EXPECT_NEAR(centre.t_min, 0.5f, 1e-6f);
  const Ray corner = CameraModel(c).generate_ray({200.0f, 100.0f}, {0.5f, 0.5f});
  // Planar clipping: t_min * cos(angle to the axis) = clip_start.
  EXPECT_NEAR(corner.t_min * -corner.direction.z, 0.5f, 1e-5f);
}

TEST(Camera, ThinLensRaysConvergeOnTheFocusPlane) {
  Camera c = base_camera(100, 100);
  c.aperture_radius = 0.2f;
  c.focus_distance = 5.0f;
  const CameraModel cam(c);
  EXPECT_TRUE(cam.has_dof());
  const Vec2f raster(30.3f, 71.1f);
  const Ray pin = CameraModel(base_camera(100, 100)).generate_ray(raster, {0.5f, 0.5f});
  const Vec3f focus_point = pin.direction * (5.0f / -pin.direction.z);
  float max_r = 0.0f;
  for (Vec2f lens : {Vec2f(0.1f, 0.2f), Vec2f(0.9f, 0.5f), Vec2f(0.01f, 0.99f)}) {
    const Ray r = cam.generate_ray(raster, lens);
    EXPECT_NEAR(r.origin.z, 0.0f, 1e-6f);
    max_r = std::max(max_r, std::hypot(r.origin.x, r.origin.y));
    EXPECT_LE(std::hypot(r.origin.x, r.origin.y), 0.2f + 1e-6f);
    const float t = 5.0f / -r.direction.z;
    const Vec3f p = r.origin + r.direction * t;
    EXPECT_NEAR(p.x, focus_point.x, 1e-4f);
    EXPECT_NEAR(p.y, focus_point.y, 1e-4f);
  }
  EXPECT_GT(max_r, 0.1f);  // the lens sample really moves the origin
}

TEST(Camera, ConcentricDiskIsInsideAndCoversTheDisk) {
  double mean_r2 = 0.0;
  const int n = 64;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vec2f d = square_to_disk_concentric({(i + 0.5f) / n, (j + 0.5f) / n});
      const float r2 = d.x * d.x + d.y * d.y;
      EXPECT_LE(r2, 1.0f + 1e-5f);
      mean_r2 += r2;
    }
  // Uniform on the unit disk: E[r^2] = 1/2.
  EXPECT_NEAR(mean_r2 / (n * n), 0.5, 2e-3);
}

// Shading nodes' camera (Vector Transform, Wireframe): Cycles' camera space clears the camera
// object's scale and looks down +z; the pixel footprint at a point is the change of the camera
// ray's direction over one pixel (Cycles' dD, averaged over x and y) times its distance.
TEST(Camera, ShadingCameraIsCyclesCameraSpace) {
  Camera c = base_camera(200, 100);
  // Scaled 2x, turned 90 degrees about y (looking down world -x), at (1, 2, 3).
  c.camera_to_world = Transform::from_rows(
      std::data({0.0f, 0.0f, 2.0f, 1.0f, 0.0f, 2.0f, 0.0f, 2.0f, -2.0f, 0.0f, 0.0f, 3.0f}));
  const CameraModel model(c);
  const ShadingCamera s = model.shading_camera();
  const Vec3f p = s.world_to_camera.point({-3.0f, 2.5f, 3.0f});  // 4 ahead, 0.5 up
  EXPECT_NEAR(p.x, 0.0f, 1e-6f);
  EXPECT_NEAR(p.y, 0.5f, 1e-6f);
  EXPECT_NEAR(p.z, 4.0f, 1e-6f);
  const Vec3f right = s.camera_to_world.vector({1.0f, 0.0f, 0.0f});  // unit: scale cleared
  EXPECT_NEAR(right.z, -1.0f, 1e-6f);
  EXPECT_FALSE(s.orthographic);
  for (const Vec2f raster : {Vec2f(100.0f, 50.0f), Vec2f(150.3f, 70.2f), Vec2f(3.5f, 96.0f)}) {
    const Ray r = model.generate_ray(raster, {0.5f, 0.5f});
    const Ray rx = model.generate_ray(raster + Vec2f(1.0f, 0.0f), {0.5f, 0.5f});
    const Ray ry = model.generate_ray(raster + Vec2f(0.0f, 1.0f), {0.5f, 0.5f});
    const float want =
        5.0f * 0.5f * (length(rx.direction - r.direction) + length(ry.direction - r.direction));
    EXPECT_NEAR(pixel_footprint(s, r.origin + r.direction * 5.0f), want, 1e-3f * want);
  }
  // Orthographic: the pixel's size (ortho scale 6 over 200 pixels), wherever the point is.
  c.projection = Camera::Projection::Orthographic;
  c.camera_to_world = Transform();
  const ShadingCamera o = CameraModel(c).shading_camera();
  EXPECT_TRUE(o.orthographic);
  EXPECT_NEAR(pixel_footprint(o, {1.0f, 2.0f, -30.0f}), 0.03f, 1e-7f);
}

}  // namespace
}  // namespace gdpt
