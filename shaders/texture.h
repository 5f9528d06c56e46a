// Image texture sampling (bilinear or closest, repeat / extend / clip), scene-linear RGBA.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/vec.h"
#include "scene/material_desc.h"

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
namespace texture_detail {
// The sRGB curve sampled at 4097 points (texture.cpp): a namespace-scope table costs no
// initialisation guard per call, as a function-local static did.
struct SrgbTable {
  static constexpr int kSegments = 4096;
  float v[kSegments + 1];
  SrgbTable();
};
extern const SrgbTable kSrgb;
}  // namespace texture_detail

// The sRGB curve (encoded [0, 1] -> linear), from a 4096-segment table with linear
// interpolation: within 1e-7 of the exact curve, without a pow per channel and lookup. Always
// inline: PGO profiles without sRGB textures (or with few) left it out of line, three calls per
// texture lookup with the colour spilled around them.
[[gnu::always_inline]] inline float srgb_to_linear(float encoded) {
  using texture_detail::kSrgb;
  constexpr int kSegments = texture_detail::SrgbTable::kSegments;
  const float x = std::clamp(encoded, 0.0f, 1.0f) * float(kSegments);
  const int i = std::min(int(x), kSegments - 1);
  const float t = x - float(i);
  return kSrgb.v[i] + (kSrgb.v[i + 1] - kSrgb.v[i]) * t;
}
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

namespace texture_detail {

// Pixel index along one axis for the extension mode; -1 means "outside" (Clip).
inline int wrap_index(int i, int n, TextureLookup::Extension ext) {
  switch (ext) {
    case TextureLookup::Extension::Repeat: {
      const int r = i % n;
      return r < 0 ? r + n : r;
    }
    case TextureLookup::Extension::Extend:
      return std::clamp(i, 0, n - 1);
    case TextureLookup::Extension::Clip:
      return (i < 0 || i >= n) ? -1 : i;
  }
  return -1;
}

}  // namespace texture_detail

// The lookups are inline (here rather than in texture.cpp) so that they inline into the material
// code: returned from a call, the Rgba went through the stack in pieces the store buffer could not
// forward (a 16-byte load of an 8-byte and a 4-byte store) on every lookup.
inline Rgba Texture::lookup(Vec2f uv, TextureLookup::Interpolation interpolation,
                            TextureLookup::Extension extension) const {
  Rgba c = lookup_stored(uv, interpolation, extension);
  if (srgb_) c.rgb = {srgb_to_linear(c.rgb.x), srgb_to_linear(c.rgb.y), srgb_to_linear(c.rgb.z)};
  return c;
}

inline Rgba Texture::lookup_stored(Vec2f uv, TextureLookup::Interpolation interpolation,
                                   TextureLookup::Extension extension) const {
  if (width_ == 0 || height_ == 0) return {Spectrum(1.0f, 0.0f, 1.0f), 1.0f};
  if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return {Spectrum(0.0f), 0.0f};

  float u = uv.x, v = uv.y;
  switch (extension) {
    case TextureLookup::Extension::Repeat:
      // Reduce first so that huge coordinates do not overflow the integer pixel index.
      u -= std::floor(u);
      v -= std::floor(v);
      break;
    case TextureLookup::Extension::Extend:
      u = std::clamp(u, -1.0f, 2.0f);
      v = std::clamp(v, -1.0f, 2.0f);
      break;
    case TextureLookup::Extension::Clip:
      // Closest: nothing outside [0, 1]^2. Linear: pixels outside count as zero, so the image
      // fades out over half a pixel beyond its border (Cycles 3.4 does this; checked by render).
      if (interpolation == TextureLookup::Interpolation::Closest &&
          (u < 0.0f || u > 1.0f || v < 0.0f || v > 1.0f))
        return {Spectrum(0.0f), 0.0f};
      u = std::clamp(u, -1.0f, 2.0f);
      v = std::clamp(v, -1.0f, 2.0f);
      break;
  }

  auto texel = [&](int x, int y) -> Rgba {
    if (x < 0 || y < 0) return {Spectrum(0.0f), 0.0f};
    return this->texel(size_t(y) * size_t(width_) + size_t(x));
  };

  if (interpolation == TextureLookup::Interpolation::Closest) {
    // u == 1 exactly belongs to the last pixel (Clip / Extend) or wraps to the first (Repeat).
    int x = int(std::floor(u * float(width_)));
    int y = int(std::floor(v * float(height_)));
    if (extension == TextureLookup::Extension::Clip) {
      x = std::min(x, width_ - 1);
      y = std::min(y, height_ - 1);
    }
    return texel(texture_detail::wrap_index(x, width_, extension),
                 texture_detail::wrap_index(y, height_, extension));
  }

  // Bilinear between the four pixel centres around (u, v).
  const float fx = u * float(width_) - 0.5f, fy = v * float(height_) - 0.5f;
  const float x0f = std::floor(fx), y0f = std::floor(fy);
  const float tx = fx - x0f, ty = fy - y0f;
  const int x0 = int(x0f), y0 = int(y0f);
  int xa, xb, ya, yb;
  if (extension == TextureLookup::Extension::Repeat) {
    // u and v are in [0, 1] here, so x0 is in [-1, width - 1]: one compare wraps each index,
    // instead of wrap_index's integer division.
    xa = x0 < 0 ? x0 + width_ : x0;
    xb = x0 + 1 >= width_ ? x0 + 1 - width_ : x0 + 1;
    ya = y0 < 0 ? y0 + height_ : y0;
    yb = y0 + 1 >= height_ ? y0 + 1 - height_ : y0 + 1;
  } else {
    xa = texture_detail::wrap_index(x0, width_, extension),
    xb = texture_detail::wrap_index(x0 + 1, width_, extension);
    ya = texture_detail::wrap_index(y0, height_, extension),
    yb = texture_detail::wrap_index(y0 + 1, height_, extension);
  }
  const Rgba p00 = texel(xa, ya), p10 = texel(xb, ya), p01 = texel(xa, yb), p11 = texel(xb, yb);
  const float w00 = (1.0f - tx) * (1.0f - ty), w10 = tx * (1.0f - ty);
  const float w01 = (1.0f - tx) * ty, w11 = tx * ty;
  return {p00.rgb * w00 + p10.rgb * w10 + p01.rgb * w01 + p11.rgb * w11,
          p00.a * w00 + p10.a * w10 + p01.a * w01 + p11.a * w11};
}

}  // namespace gdpt
