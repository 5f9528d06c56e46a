// Image texture sampling (bilinear or closest, repeat / extend / clip), scene-linear RGBA.
#pragma once

#include <vector>

#include "integrator/math/vec.h"
#include "shaders/material_desc.h"

namespace gdpt {

struct Rgba {
  Spectrum rgb;
  float a = 1.0f;
};

class Texture {
 public:
  explicit Texture(const ImageDesc& image);
  // uv in [0,1]^2 covers the image once; v = 0 is the bottom row.
  Rgba lookup(Vec2f uv, TextureLookup::Interpolation interpolation,
              TextureLookup::Extension extension) const;
  int width() const { return width_; }
  int height() const { return height_; }
  const float* rgba() const { return rgba_.data(); }

 private:
  int width_ = 0, height_ = 0;
  std::vector<float> rgba_;
};

}  // namespace gdpt
