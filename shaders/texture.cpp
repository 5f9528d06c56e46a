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

// The sRGB curve sampled at 4097 points, built when the library loads (texture_detail::kSrgb).
// Nothing calls it during static initialisation.
namespace texture_detail {
SrgbTable::SrgbTable() {
  for (int i = 0; i <= kSegments; ++i) {
    const double c = double(i) / kSegments;
    v[i] = float(c < 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
  }
}
const SrgbTable kSrgb;
}  // namespace texture_detail

}  // namespace gdpt
