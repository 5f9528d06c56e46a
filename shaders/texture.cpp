// Image texture sampling with Blender/Cycles conventions:
//  - uv in [0, 1]^2 covers the image once, v = 0 is the bottom row (row 0 of the storage);
//  - pixel (i, j) has its centre at ((i + 0.5) / w, (j + 0.5) / h);
//  - Closest takes the pixel containing uv; Linear blends the four nearest pixel centres;
//  - Repeat wraps, Extend clamps to the border pixels, Clip returns transparent black outside
//    [0, 1]^2 for Closest; for Linear, pixels outside the image count as zero, so the border
//    blends to zero over half a pixel on either side (as Cycles 3.4 renders it).
//  - An empty image returns Blender's "missing texture" magenta.
#include "shaders/texture.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>

namespace gdpt {

Texture::Texture(const ImageDesc& image) : width_(image.width), height_(image.height) {
  const size_t expected = size_t(std::max(0, width_)) * size_t(std::max(0, height_)) * 4;
  if (width_ < 0 || height_ < 0 || image.rgba.size() != expected)
    throw std::invalid_argument("image '" + image.name + "': " + std::to_string(width_) + "x" +
                                std::to_string(height_) + " needs " + std::to_string(expected) +
                                " floats, has " + std::to_string(image.rgba.size()));
  if (!encode(image.rgba)) rgba_ = image.rgba;
  srgb_ = image.srgb_encoded;
  double sum[4] = {0, 0, 0, 0};
  const size_t count = size_t(width_) * size_t(height_);
  for (size_t p = 0; p < count; ++p)
    for (int ch = 0; ch < 4; ++ch) {
      const float v = image.rgba[p * 4 + size_t(ch)];
      sum[ch] += srgb_ && ch < 3 ? srgb_to_linear(v) : v;
    }
  const double inv = count > 0 ? 1.0 / double(count) : 0.0;
  mean_ = {Spectrum(float(sum[0] * inv), float(sum[1] * inv), float(sum[2] * inv)),
           float(sum[3] * inv)};
}

bool Texture::encode(const std::vector<float>& rgba) {
  // Per channel, an open-addressing table from a value's bits to its code, sparse enough (4096
  // slots for at most 256 values) that almost every texel is found in its first slot; more than
  // 256 distinct values in any channel: keep floats.
  constexpr uint32_t kSlots = 4096;
  constexpr uint32_t kEmpty = 0xffffffffu;  // a NaN pattern no decode produces; checked below
  struct Channel {
    uint32_t bits[kSlots];
    uint8_t code[kSlots];
    int count = 0;
  };
  auto channels = std::make_unique<Channel[]>(4);
  for (int ch = 0; ch < 4; ++ch) std::fill_n(channels[ch].bits, kSlots, kEmpty);
  const size_t count = size_t(width_) * size_t(height_);
  std::vector<uint32_t> codes;
  codes.reserve(count);  // untouched memory until written: cheap to give up on float images
  const uint32_t* in = reinterpret_cast<const uint32_t*>(rgba.data());
  for (size_t p = 0; p < count; ++p) {
    uint32_t packed = 0;
    for (int ch = 0; ch < 4; ++ch) {
      Channel& c = channels[ch];
      const uint32_t bits = in[p * 4 + size_t(ch)];
      if (bits == kEmpty) return false;
      uint32_t slot = (bits * 0x9e3779b1u) >> 20;  // top 12 bits
      while (c.bits[slot] != bits) {
        if (c.bits[slot] == kEmpty) {  // new value
          if (c.count == 256) return false;
          c.bits[slot] = bits;
          c.code[slot] = uint8_t(c.count);
          std::memcpy(&decode_[ch][c.count], &bits, sizeof bits);
          ++c.count;
          break;
        }
        slot = (slot + 1) & (kSlots - 1);
      }
      packed |= uint32_t(c.code[slot]) << (8 * ch);
    }
    codes.push_back(packed);
  }
  codes_ = std::move(codes);
  return true;
}

namespace {

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

// The sRGB curve sampled at 4097 points, built when the library loads: a namespace-scope table
// costs no initialisation guard per call, as the former function-local static did. With the
// calls inlined and Repeat wrapped by compares, a random bilinear lookup in a 256x256 8-bit sRGB
// texture went from 41.9 to 31.3 ns (bench_shaders BM_TextureLookup, baseline build). Nothing
// calls it during static initialisation.
struct SrgbTable {
  static constexpr int kSegments = 4096;
  float v[kSegments + 1];
  SrgbTable() {
    for (int i = 0; i <= kSegments; ++i) {
      const double c = double(i) / kSegments;
      v[i] = float(c < 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
  }
};
const SrgbTable kSrgb;

// Always inline: PGO profiles without sRGB textures (or with few) left it out of line, three calls
// per lookup with the colour spilled around them.
[[gnu::always_inline]] inline float srgb_decode(float encoded) {
  constexpr int kSegments = SrgbTable::kSegments;
  const float x = std::clamp(encoded, 0.0f, 1.0f) * float(kSegments);
  const int i = std::min(int(x), kSegments - 1);
  const float t = x - float(i);
  return kSrgb.v[i] + (kSrgb.v[i + 1] - kSrgb.v[i]) * t;
}

}  // namespace

float srgb_to_linear(float encoded) {
  return srgb_decode(encoded);
}

Rgba Texture::lookup(Vec2f uv, TextureLookup::Interpolation interpolation,
                     TextureLookup::Extension extension) const {
  Rgba c = lookup_stored(uv, interpolation, extension);
  if (srgb_) c.rgb = {srgb_decode(c.rgb.x), srgb_decode(c.rgb.y), srgb_decode(c.rgb.z)};
  return c;
}

Rgba Texture::lookup_stored(Vec2f uv, TextureLookup::Interpolation interpolation,
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
    return texel(wrap_index(x, width_, extension), wrap_index(y, height_, extension));
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
    xa = wrap_index(x0, width_, extension), xb = wrap_index(x0 + 1, width_, extension);
    ya = wrap_index(y0, height_, extension), yb = wrap_index(y0 + 1, height_, extension);
  }
  const Rgba p00 = texel(xa, ya), p10 = texel(xb, ya), p01 = texel(xa, yb), p11 = texel(xb, yb);
  const float w00 = (1.0f - tx) * (1.0f - ty), w10 = tx * (1.0f - ty);
  const float w01 = (1.0f - tx) * ty, w11 = tx * ty;
  return {p00.rgb * w00 + p10.rgb * w10 + p01.rgb * w01 + p11.rgb * w11,
          p00.a * w00 + p10.a * w10 + p01.a * w01 + p11.a * w11};
}

}  // namespace gdpt
