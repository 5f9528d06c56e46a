// Camera rays with Blender/Cycles projection: sensor fit (Auto / Horizontal / Vertical), focal
// length against the fitted sensor size, shift in units of the fitted dimension, pixel aspect,
// orthographic (ortho_scale across the fitted dimension), thin-lens depth of field (uniform disk of
// aperture_radius focused at focus_distance) and clip_start / clip_end measured along the view
// axis as Cycles does.
//
// Raster coordinates: (0, 0) is the bottom-left corner of the image, (width, height) the top
// right; pixel (x, y) covers [x, x+1) x [y, y+1). y = 0 is the BOTTOM row (Blender's convention).
//
// Pixel filter: the raster position of a camera sample comes from PixelFilter (pixel_filter.h),
// Cycles' importance-sampled filters; G-PT's offsets move that position by +-1 pixel.
#pragma once

#include <cmath>

#include "core/transform.h"
#include "core/vec.h"
#include "scene/scene.h"
#include "shaders/shading_context.h"

namespace gdpt {

struct Ray {
  Vec3f origin;
  Vec3f direction;  // unit, but for shadow rays to a finite point: the segment, t in [0, 1)
  // Before t_min: t_max and kind then do not sit next to each other as Embree's tfar and mask
  // do, so GCC does not copy them to Embree's ray as one 8-byte load of two fields just stored
  // separately (a store-forwarding stall on every ray).
  uint32_t kind = kRayCamera;  // RayKind: which instances it sees (Instance::visibility)
  float t_min = 0.0f;
  float t_max = 1e30f;
};

class CameraModel {
 public:
  CameraModel() = default;
  explicit CameraModel(const Camera& camera);

  // Ray through raster position `raster` (pixel units, y up) and lens sample `lens` in [0,1)^2
  // (ignored without depth of field). Shifting `raster` by +-1 with the same `lens` is how G-PT
  // builds its offset paths.
  // Inline (forced: GCC keeps it out of the path tracer's large trace loop): the pinhole case,
  // one per sample, is a handful of operations next to the call.
  [[gnu::always_inline]] Ray generate_ray(Vec2f raster, Vec2f lens) const {
    if (!pinhole_) return generate_ray_general(raster, lens);
    const Vec3f w = w0_ + wx_ * raster.x + wy_ * raster.y;
    const float len = length(w);
    Ray ray;
    ray.origin = pinhole_origin_;
    ray.direction = w / len;
    ray.t_min = clip_start_ * len;
    ray.t_max = clip_end_ * len;
    return ray;
  }

  // G-PT's offset rays: the rays through raster + (+1, 0), (0, +1), (-1, 0), (0, -1) (in that
  // order, where `mask` is set) with the same lens sample, equal to generate_ray() up to
  // rounding. The camera-space direction is affine in the raster position, so each ray costs one
  // step from the common part and a normalisation instead of a full generate_ray().
  // Used by G-PT only with depth of field (without it, offsets reuse neighbours' camera rays).
  void generate_offset_rays(Vec2f raster, Vec2f lens, const bool mask[4], Ray out[4]) const;

  // Distance of a world point in front of the camera along its view axis (Blender's Depth pass).
  float view_depth(Vec3f world) const { return -world_to_camera_.point(world).z; }
  // Distance of a world point from the camera as Cycles' mist measures it: from the camera's
  // position (perspective), along the view axis (orthographic).
  float camera_distance(Vec3f world) const {
    const Vec3f c = world_to_camera_.point(world);
    return ortho_ ? std::fabs(c.z) : length(c);
  }

  // The camera as shading nodes see it (Cycles' camera space, the pixel footprint).
  ShadingCamera shading_camera() const;

  // World point -> raster position (pinhole); returns false behind the camera. For tests.
  bool project(Vec3f world, Vec2f& raster) const;

  // Offset of the rendered image in the frame (Camera::region_x / region_y; 0 without a region):
  // integrators add it to image pixel coordinates to get raster positions and sampler keys.
  int region_x() const { return region_x_; }
  int region_y() const { return region_y_; }

  bool has_dof() const { return aperture_radius_ > 0.0f; }
  bool orthographic() const { return ortho_; }
  int width() const { return width_; }
  int height() const { return height_; }
  Vec3f position() const { return camera_to_world_.translation(); }

 private:
  Ray generate_ray_general(Vec2f raster, Vec2f lens) const;  // orthographic, depth of field
  // Raster -> screen (viewplane) coordinates.
  Vec2f raster_to_screen(Vec2f raster) const {
    return {left_ + (right_ - left_) * raster.x * inv_width_,
            bottom_ + (top_ - bottom_) * raster.y * inv_height_};
  }

  Transform camera_to_world_, world_to_camera_;
  bool ortho_ = false;
  int width_ = 1, height_ = 1;  // the frame
  int region_x_ = 0, region_y_ = 0;
  float inv_width_ = 1.0f, inv_height_ = 1.0f;
  // Viewplane in screen units, after shift.
  float left_ = -1.0f, right_ = 1.0f, bottom_ = -1.0f, top_ = 1.0f;
  // Perspective: camera-space direction = (sx * tan_half_, sy * tan_half_, -1).
  // Orthographic: camera-space origin = (sx, sy, 0) (screen units are metres).
  float tan_half_ = 1.0f;
  float aperture_radius_ = 0.0f, focus_distance_ = 10.0f;
  float clip_start_ = 0.1f, clip_end_ = 1000.0f;
  // Pinhole perspective (no depth of field), the common case: the unnormalised world direction
  // is affine in the raster position, W = w0 + x wx + y wy, and |W| is the distance along the
  // ray per unit of view depth (clip distances scale by it).
  bool pinhole_ = false;
  Vec3f pinhole_origin_, w0_, wx_, wy_;
};

}  // namespace gdpt
