#include "render/environment_map.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "shaders/texture.h"  // srgb_to_linear

namespace gdpt {

namespace {
constexpr int kMaxCellsX = 2048, kMaxCellsY = 1024;

int wrap(int i, int n) {
  const int r = i % n;
  return r < 0 ? r + n : r;
}
}  // namespace

Vec2f EnvironmentMap::direction_to_uv(Vec3f d) {
  float u = 0.5f - std::atan2(d.y, d.x) * (0.5f * kInvPi);
  if (u >= 1.0f) u -= 1.0f;
  if (u < 0.0f) u += 1.0f;
  const float v = 1.0f - std::acos(std::clamp(d.z, -1.0f, 1.0f)) * kInvPi;
  return {u, v};
}

Vec3f EnvironmentMap::uv_to_direction(Vec2f uv) {
  const float phi = kPi - 2.0f * kPi * uv.x;
  const float theta = kPi * (1.0f - uv.y);
  const float sin_theta = std::sin(theta);
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), std::cos(theta)};
}

Spectrum EnvironmentMap::stored_texel(int x, int y) const {
  const int w = image_->width, h = image_->height;
  const size_t i = (size_t(std::clamp(y, 0, h - 1)) * size_t(w) + size_t(wrap(x, w))) * 4;
  const float* p = image_->rgba.data() + i;
  return {p[0], p[1], p[2]};
}

Spectrum EnvironmentMap::decoded(Spectrum stored) const {
  if (!image_->srgb_encoded) return stored;
  return srgb_to_linear(stored);
}

Spectrum EnvironmentMap::texel(int x, int y) const {
  return decoded(stored_texel(x, y));
}

Spectrum EnvironmentMap::lookup(Vec2f uv) const {
  // Pixel centres at (i + 0.5) / width. 8-bit sRGB images are interpolated encoded, then
  // decoded (as Texture::lookup, and Cycles).
  const float x = uv.x * float(image_->width) - 0.5f;
  const float y = uv.y * float(image_->height) - 0.5f;
  const float fx = std::floor(x), fy = std::floor(y);
  const float tx = x - fx, ty = y - fy;
  const int ix = int(fx), iy = int(fy);
  return decoded(lerp(lerp(stored_texel(ix, iy), stored_texel(ix + 1, iy), tx),
                      lerp(stored_texel(ix, iy + 1), stored_texel(ix + 1, iy + 1), tx), ty));
}

EnvironmentMap::EnvironmentMap(const ImageDesc& image, const Transform& rotation, float strength)
    : image_(&image),
      rotation_(rotation),
      inverse_rotation_(rotation.inverse()),
      strength_(strength) {
  const int w = image.width, h = image.height;
  if (w <= 0 || h <= 0 || image.rgba.size() < size_t(w) * size_t(h) * 4 || !(strength > 0.0f)) {
    image_ = nullptr;
    return;
  }
  // Average radiance, weighted by the solid angle of each pixel row.
  double sum[3] = {0, 0, 0}, weight = 0;
  for (int y = 0; y < h; ++y) {
    const double s = std::sin(kPi * (double(y) + 0.5) / double(h));
    for (int x = 0; x < w; ++x) {
      const Spectrum c = max(texel(x, y), Spectrum(0.0f));
      for (int k = 0; k < 3; ++k) sum[k] += s * double(c[k]);
    }
    weight += s * double(w);
  }
  average_ =
      Spectrum(float(sum[0] / weight), float(sum[1] / weight), float(sum[2] / weight)) * strength;

  // Sampling grid: each cell takes the maximum over every pixel its bilinear footprint reads.
  const int nx = std::min(w, kMaxCellsX), ny = std::min(h, kMaxCellsY);
  std::vector<float> lum(size_t(w) * size_t(h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      lum[size_t(y) * size_t(w) + size_t(x)] =
          std::max(0.0f, luminance(max(texel(x, y), Spectrum(0.0f))));
  std::vector<float> cells(size_t(nx) * size_t(ny));
  for (int j = 0; j < ny; ++j) {
    // Rows read by v in [j/ny, (j+1)/ny): floor(v h - 0.5) .. floor(v h - 0.5) + 1.
    const int y0 = int(std::floor(double(j) * h / ny - 0.5));
    const int y1 = int(std::floor(double(j + 1) * h / ny - 0.5)) + 1;
    const float sin_theta = std::sin(kPi * (float(j) + 0.5f) / float(ny));
    for (int i = 0; i < nx; ++i) {
      const int x0 = int(std::floor(double(i) * w / nx - 0.5));
      const int x1 = int(std::floor(double(i + 1) * w / nx - 0.5)) + 1;
      float m = 0.0f;
      for (int y = y0; y <= y1; ++y) {
        const size_t row = size_t(std::clamp(y, 0, h - 1)) * size_t(w);
        for (int x = x0; x <= x1; ++x) m = std::max(m, lum[row + size_t(wrap(x, w))]);
      }
      cells[size_t(j) * size_t(nx) + size_t(i)] = m * sin_theta;
    }
  }
  distribution_ = Distribution2D(cells, nx, ny);
}

Spectrum EnvironmentMap::eval(Vec3f world_direction) const {
  if (!image_) return Spectrum(0.0f);
  const Vec3f d = normalize(rotation_.vector(world_direction));
  return lookup(direction_to_uv(d)) * strength_;
}

Vec3f EnvironmentMap::sample(Vec2f u, float* pdf) const {
  if (!image_ || distribution_.empty()) {
    *pdf = 0.0f;
    return {0.0f, 0.0f, 1.0f};
  }
  float pdf_uv = 0.0f;
  const Vec2f uv = distribution_.sample(u, &pdf_uv);
  const Vec3f d = uv_to_direction(uv);
  const float sin_theta = std::sqrt(d.x * d.x + d.y * d.y);
  *pdf = sin_theta > 0.0f ? pdf_uv / (2.0f * kPi * kPi * sin_theta) : 0.0f;
  return normalize(inverse_rotation_.vector(d));
}

float EnvironmentMap::pdf(Vec3f world_direction) const {
  if (!image_ || distribution_.empty()) return 0.0f;
  const Vec3f d = normalize(rotation_.vector(world_direction));
  const float sin_theta = std::sqrt(d.x * d.x + d.y * d.y);
  if (!(sin_theta > 0.0f)) return 0.0f;
  return distribution_.pdf(direction_to_uv(d)) / (2.0f * kPi * kPi * sin_theta);
}

}  // namespace gdpt
