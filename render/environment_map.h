// Equirectangular environment (Blender World > Environment Texture) with importance sampling.
//
// Mapping (Cycles' direction_to_equirectangular, kernel/camera/projection.h: range
// (-2 pi, pi, -pi, pi)), for a unit lookup direction d:
//   u = 0.5 - atan2(d.y, d.x) / (2 pi)     (+X at the image centre, +Y at u = 0.25)
//   v = 1 - acos(d.z) / pi                 (+Z at the top row; rows are stored bottom-up)
// The lookup direction is rotation.vector(world direction) (World::rotation, the Mapping node);
// the rotation is assumed orthonormal (no scale), so densities are unchanged by it.
// Radiance: bilinear filtering of the scene-linear pixels (wrap in u, clamp in v) times
// strength, as the Environment Texture node's default Linear interpolation.
//
// Sampling: a 2-D piecewise-constant distribution over a grid of at most 2048 x 1024 cells, each
// cell's weight the maximum luminance of the pixels its bilinear footprint touches (so the pdf
// is positive wherever the filtered radiance is) times sin(theta) at the cell centre. The
// density in solid angle is p_uv / (2 pi^2 sin theta).
#pragma once

#include "core/transform.h"
#include "core/vec.h"
#include "render/light_distribution.h"
#include "scene/material_desc.h"

namespace gdpt {

class EnvironmentMap {
 public:
  // `image` must outlive the map (it is the Scene's ImageDesc; no copy of the pixels is made).
  EnvironmentMap(const ImageDesc& image, const Transform& rotation, float strength);

  Spectrum eval(Vec3f world_direction) const;
  // Unit world direction and its solid-angle density (0 when the map is black).
  Vec3f sample(Vec2f u, float* pdf) const;
  float pdf(Vec3f world_direction) const;
  // Radiance averaged over the sphere (solid-angle weighted), for light selection by power.
  Spectrum average() const { return average_; }
  bool black() const { return distribution_.empty(); }

  static Vec2f direction_to_uv(Vec3f unit_direction);
  static Vec3f uv_to_direction(Vec2f uv);

 private:
  Spectrum stored_texel(int x, int y) const;  // as stored (x wraps, y clamps)
  Spectrum decoded(Spectrum stored) const;    // linear (sRGB-encoded images decoded)
  Spectrum texel(int x, int y) const;         // decoded
  Spectrum lookup(Vec2f uv) const;

  const ImageDesc* image_;
  Transform rotation_, inverse_rotation_;
  float strength_;
  Distribution2D distribution_;
  Spectrum average_{0.0f, 0.0f, 0.0f};
};

}  // namespace gdpt
