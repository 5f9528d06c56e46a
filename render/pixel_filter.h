// The pixel filter as Cycles applies it: each camera sample's position in its pixel is drawn
// from the filter (importance sampling), and the sample counts fully for that pixel; the pixel's
// value is then the filter-weighted average of the image around its centre. The filter is
// separable: x and y are drawn independently from the same 1-D profile.
//
// Widths as Cycles defines them (scene.cycles.filter_width = w): the box covers [-w/2, w/2]
// around the pixel centre; the Gaussian exp(-8 x^2 / w^2) (sigma w/4) is cut at +-1.5 w; the
// Blackman-Harris window spans [-w, w]. Box of width 1 is the plain jitter over the pixel.
//
// G-PT's offset paths go through the neighbouring pixel at the base's position moved by one pixel
// (same filter sample), so primal and gradients estimate the same filtered image.
#pragma once

#include <algorithm>
#include <vector>

#include "core/vec.h"
#include "scene/render_settings.h"

namespace gdpt {

class PixelFilter {
 public:
  PixelFilter() = default;  // box of width 1
  // Throws std::invalid_argument for a width that is not a positive finite number.
  PixelFilter(PixelFilterType type, float width);

  // Sample position inside the pixel's frame, (0, 0) its lower-left corner, (0.5, 0.5) its
  // centre (it may lie outside [0, 1)^2 for wide filters), from `u` in [0, 1)^2.
  Vec2f position(Vec2f u) const { return {position_1d(u.x), position_1d(u.y)}; }
  // The raster position of frame pixel (px, py)'s camera sample: PT's camera rays and G-PT's
  // base paths (whose offsets move it by one pixel) both take it from here.
  Vec2f raster(int px, int py, Vec2f u) const {
    const Vec2f p = position(u);
    return {float(px) + p.x, float(py) + p.y};
  }

  PixelFilterType type() const { return type_; }
  float width() const { return width_; }
  // Half of the filter's support, in pixels, around the pixel centre.
  float radius() const { return radius_; }

 private:
  float position_1d(float u) const {
    // The box exactly (width 1: u itself, bit for bit the unfiltered jitter).
    if (cdf_.empty()) return u * width_ + 0.5f * (1.0f - width_);
    // The cell of the tabulated CDF holding u, from the guide table's first candidate, and u's
    // place in it: the sampled density is the filter's mass of each cell spread evenly over it.
    const int cells = int(cdf_.size()) - 1;
    int i = guide_[size_t(std::clamp(int(u * float(cells)), 0, cells - 1))];
    while (i < cells - 1 && cdf_[size_t(i) + 1] <= u) ++i;
    const float mass = cdf_[size_t(i) + 1] - cdf_[size_t(i)];
    const float f = mass > 0.0f ? std::clamp((u - cdf_[size_t(i)]) / mass, 0.0f, 1.0f) : 0.5f;
    return 0.5f - radius_ + (float(i) + f) * cell_;
  }

  PixelFilterType type_ = PixelFilterType::Box;
  float width_ = 1.0f, radius_ = 0.5f;
  float cell_ = 0.0f;       // width of a CDF cell, pixels
  std::vector<float> cdf_;  // normalised CDF at -radius + i * cell_, from 0 to 1
  // guide_[k]: the cell holding u = k / cells (the first whose upper CDF value exceeds it).
  std::vector<int> guide_;
};

}  // namespace gdpt
