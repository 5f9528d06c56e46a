// Image texture sampling (bilinear or closest, repeat / extend / clip), scene-linear RGBA.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "integrator/math/vec.h"
#include "shaders/material_desc.h"

namespace gdpt {

struct Rgba {
  Spectrum rgb;
  float a = 1.0f;
};

// Storage: when every channel takes at most 256 distinct values (any 8-bit image, also after a
// per-channel colour-space conversion such as sRGB to linear), texels are kept as four 8-bit
// codes with one 256-entry decode table per channel: a quarter of the memory of float RGBA, so
// that bilinear lookups, which land anywhere in the image at every bounce, miss the caches far
// less. Lookups return the same values either way (the tables hold the exact floats).
// The sRGB curve (encoded [0, 1] -> linear), from a 4096-segment table with linear
// interpolation: within 1e-7 of the exact curve, without a pow per channel and lookup.
float srgb_to_linear(float encoded);
inline Spectrum srgb_to_linear(Spectrum encoded) {
  return {srgb_to_linear(encoded.x), srgb_to_linear(encoded.y), srgb_to_linear(encoded.z)};
}

class Texture {
 public:
  explicit Texture(const ImageDesc& image);
  // uv in [0,1]^2 covers the image once; v = 0 is the bottom row.
  Rgba lookup(Vec2f uv, TextureLookup::Interpolation interpolation,
              TextureLookup::Extension extension) const;
  int width() const { return width_; }
  int height() const { return height_; }
  Rgba mean() const { return mean_; }  // over all pixels (decoded)
  bool coded() const { return !codes_.empty(); }

 private:
  // The lookup in stored values (sRGB-encoded for srgb_ images).
  Rgba lookup_stored(Vec2f uv, TextureLookup::Interpolation interpolation,
                     TextureLookup::Extension extension) const;
  bool encode(const std::vector<float>& rgba);  // fills codes_ and decode_; false: > 256 values
  Rgba texel(size_t index) const {
    if (!codes_.empty()) {
      const uint32_t c = codes_[index];
      return {Spectrum(decode_[0][c & 0xffu], decode_[1][(c >> 8) & 0xffu],
                       decode_[2][(c >> 16) & 0xffu]),
              decode_[3][c >> 24]};
    }
    const float* p = rgba_.data() + index * 4;
    return {Spectrum(p[0], p[1], p[2]), p[3]};
  }

  int width_ = 0, height_ = 0;
  std::vector<float> rgba_;      // float RGBA, when not coded
  std::vector<uint32_t> codes_;  // R | G << 8 | B << 16 | A << 24, when coded
  float decode_[4][256] = {};    // per channel: code -> value
  bool srgb_ = false;            // ImageDesc::srgb_encoded
  Rgba mean_;
};

}  // namespace gdpt
