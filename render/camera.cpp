#include "render/camera.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/warp_disk.h"

namespace gdpt {

CameraModel::CameraModel(const Camera& cam) {
  camera_to_world_ = cam.camera_to_world;
  world_to_camera_ = cam.camera_to_world.inverse();
  ortho_ = cam.projection == Camera::Projection::Orthographic;
  width_ = std::max(cam.width, 1);
  height_ = std::max(cam.height, 1);
  inv_width_ = 1.0f / float(width_);
  inv_height_ = 1.0f / float(height_);
  if (cam.has_region()) {
    if (cam.region_x < 0 || cam.region_y < 0 || cam.region_x + cam.region_width > width_ ||
        cam.region_y + cam.region_height > height_)
      throw std::invalid_argument(
          "camera: render region " + std::to_string(cam.region_width) + "x" +
          std::to_string(cam.region_height) + " at (" + std::to_string(cam.region_x) + ", " +
          std::to_string(cam.region_y) + ") is not inside the " + std::to_string(width_) + "x" +
          std::to_string(height_) + " frame");
    region_x_ = cam.region_x;
    region_y_ = cam.region_y;
  }

  // Viewplane as Cycles' blender_camera_viewplane(): the fitted dimension spans [-1, 1] before
  // scaling, the other one [-1/aspect, 1/aspect] after the division below.
  const float pixel_aspect = cam.pixel_aspect > 0.0f ? cam.pixel_aspect : 1.0f;
  const float xratio = float(width_) * pixel_aspect;
  const float yratio = float(height_);
  bool horizontal_fit;
  float sensor_size;
  switch (cam.sensor_fit) {
    case Camera::SensorFit::Horizontal:
      horizontal_fit = true;
      sensor_size = cam.sensor_width_mm;
      break;
    case Camera::SensorFit::Vertical:
      horizontal_fit = false;
      sensor_size = cam.sensor_height_mm;
      break;
    case Camera::SensorFit::Auto:
    default:
      horizontal_fit = xratio > yratio;
      sensor_size = cam.sensor_width_mm;
      break;
  }
  float aspectratio, xaspect, yaspect;
  if (horizontal_fit) {
    aspectratio = xratio / yratio;
    xaspect = aspectratio;
    yaspect = 1.0f;
  } else {
    aspectratio = yratio / xratio;
    xaspect = 1.0f;
    yaspect = aspectratio;
  }
  if (ortho_) {
    xaspect = xaspect * cam.ortho_scale / (aspectratio * 2.0f);
    yaspect = yaspect * cam.ortho_scale / (aspectratio * 2.0f);
    aspectratio = cam.ortho_scale / 2.0f;
  }
  const float dx = 2.0f * aspectratio * cam.shift_x;
  const float dy = 2.0f * aspectratio * cam.shift_y;
  left_ = -xaspect + dx;
  right_ = xaspect + dx;
  bottom_ = -yaspect + dy;
  top_ = yaspect + dy;
  // Cycles: fov = 2 atan(0.5 sensor / lens / aspectratio), screen unit = tan(fov / 2).
  const float lens = std::max(cam.focal_length_mm, 1e-4f);
  tan_half_ = ortho_ ? 1.0f : (0.5f * sensor_size / lens) / aspectratio;

  aperture_radius_ = std::max(cam.aperture_radius, 0.0f);
  focus_distance_ = std::max(cam.focus_distance, 1e-4f);
  clip_start_ = std::max(cam.clip_start, 0.0f);
  clip_end_ = std::max(cam.clip_end, clip_start_);

  pinhole_ = !ortho_ && !(aperture_radius_ > 0.0f);
  if (pinhole_) {
    // Camera-space direction (sx tan_half, sy tan_half, -1) with s affine in the raster position.
    pinhole_origin_ = camera_to_world_.point(Vec3f(0.0f));
    w0_ = camera_to_world_.vector(Vec3f(left_ * tan_half_, bottom_ * tan_half_, -1.0f));
    wx_ = camera_to_world_.vector(Vec3f((right_ - left_) * inv_width_ * tan_half_, 0.0f, 0.0f));
    wy_ = camera_to_world_.vector(Vec3f(0.0f, (top_ - bottom_) * inv_height_ * tan_half_, 0.0f));
  }
}

Ray CameraModel::generate_ray_general(Vec2f raster, Vec2f lens) const {
  const Vec2f s = raster_to_screen(raster);
  Vec3f origin, dir;
  float z_scale;  // distance along the ray per unit of view depth
  if (!ortho_) {
    const Vec3f d(s.x * tan_half_, s.y * tan_half_, -1.0f);  // view depth 1
    origin = Vec3f(0.0f);
    dir = d;
    if (aperture_radius_ > 0.0f) {
      // Thin lens: all rays through the pixel converge on the focus plane (depth focus_distance).
      const Vec2f l = square_to_disk_concentric(lens) * aperture_radius_;
      origin = Vec3f(l.x, l.y, 0.0f);
      dir = d * focus_distance_ - origin;
    }
    const float len = length(dir);
    dir = dir / len;
    z_scale = 1.0f / std::max(-dir.z, 1e-8f);
  } else {
    origin = Vec3f(s.x, s.y, 0.0f);
    dir = Vec3f(0.0f, 0.0f, -1.0f);
    if (aperture_radius_ > 0.0f) {
      const Vec2f l = square_to_disk_concentric(lens) * aperture_radius_;
      const Vec3f focus = origin + dir * focus_distance_;
      origin = origin + Vec3f(l.x, l.y, 0.0f);
      dir = normalize(focus - origin);
    }
    z_scale = 1.0f / std::max(-dir.z, 1e-8f);
  }
  Ray ray;
  ray.origin = camera_to_world_.point(origin);
  // Camera transforms may carry scale: renormalise in world space. Clip distances are along the
  // view axis in camera space, as Cycles (the camera object's scale does not change them).
  const Vec3f wd = camera_to_world_.vector(dir);
  const float wl = length(wd);
  ray.direction = wd / wl;
  ray.t_min = clip_start_ * z_scale * wl;
  ray.t_max = clip_end_ * z_scale * wl;
  return ray;
}

void CameraModel::generate_offset_rays(Vec2f raster, Vec2f lens, const bool mask[4],
                                       Ray out[4]) const {
  // One raster unit moves the screen position by these amounts.
  const float sx = (right_ - left_) * inv_width_, sy = (top_ - bottom_) * inv_height_;
  const float step_x[4] = {1.0f, 0.0f, -1.0f, 0.0f}, step_y[4] = {0.0f, 1.0f, 0.0f, -1.0f};
  const Vec2f s = raster_to_screen(raster);
  if (ortho_) {
    // The direction does not depend on the raster position; the origin moves in the view plane.
    const Ray base = generate_ray(raster, lens);
    const Vec3f ax = camera_to_world_.column(0) * sx, ay = camera_to_world_.column(1) * sy;
    for (int k = 0; k < 4; ++k) {
      if (!mask[k]) continue;
      out[k] = base;
      out[k].origin = base.origin + ax * step_x[k] + ay * step_y[k];
    }
    return;
  }
  // Perspective (as generate_ray): camera-space direction d = (s.x t, s.y t, -1), times the focus
  // distance minus the lens point with depth of field. Its z component f is the same for every
  // raster position, so along the ray t_min = clip_start |W| / f for the world direction W.
  Vec3f origin(0.0f);
  Vec3f dir(s.x * tan_half_, s.y * tan_half_, -1.0f);
  float scale = tan_half_;
  if (aperture_radius_ > 0.0f) {
    const Vec2f l = square_to_disk_concentric(lens) * aperture_radius_;
    origin = Vec3f(l.x, l.y, 0.0f);
    dir = dir * focus_distance_ - origin;
    scale *= focus_distance_;
  }
  const float depth = -dir.z;
  const Vec3f world_origin = camera_to_world_.point(origin);
  const Vec3f w = camera_to_world_.vector(dir);
  const Vec3f ax = camera_to_world_.column(0) * (sx * scale);
  const Vec3f ay = camera_to_world_.column(1) * (sy * scale);
  for (int k = 0; k < 4; ++k) {
    if (!mask[k]) continue;
    const Vec3f wk = w + ax * step_x[k] + ay * step_y[k];
    const float len = length(wk);
    const float z_scale = len / std::max(depth, 1e-8f * len);
    out[k].origin = world_origin;
    out[k].direction = wk / len;
    out[k].t_min = clip_start_ * z_scale;
    out[k].t_max = clip_end_ * z_scale;
  }
}

ShadingCamera CameraModel::shading_camera() const {
  // Cycles clears the camera object's scale and looks down +z: unit columns, z negated.
  Transform t = camera_to_world_;
  for (int c = 0; c < 3; ++c) {
    const float l = length(t.column(c));
    const float s = (l > 0.0f ? 1.0f / l : 1.0f) * (c == 2 ? -1.0f : 1.0f);
    for (int r = 0; r < 3; ++r) t.m[r][c] *= s;
  }
  ShadingCamera out;
  out.camera_to_world = t;
  out.world_to_camera = t.inverse();
  out.orthographic = ortho_;
  // One raster unit on the image plane at unit depth (perspective) or in world units.
  const float sx = (right_ - left_) * inv_width_, sy = (top_ - bottom_) * inv_height_;
  if (ortho_) {
    out.pixel_x = sx * length(camera_to_world_.column(0));
    out.pixel_y = sy * length(camera_to_world_.column(1));
  } else {
    out.pixel_x = sx * tan_half_;
    out.pixel_y = sy * tan_half_;
  }
  return out;
}

bool CameraModel::project(Vec3f world, Vec2f& raster) const {
  const Vec3f p = world_to_camera_.point(world);
  Vec2f s;
  if (!ortho_) {
    if (p.z >= 0.0f) return false;
    s = {p.x / (-p.z) / tan_half_, p.y / (-p.z) / tan_half_};
  } else {
    s = {p.x, p.y};
  }
  raster = {(s.x - left_) / (right_ - left_) * float(width_),
            (s.y - bottom_) / (top_ - bottom_) * float(height_)};
  return true;
}

}  // namespace gdpt
