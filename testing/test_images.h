// Synthetic images with known ground truth for the reconstruction tests.
#pragma once

#include <cmath>
#include <random>
#include <vector>

namespace gdpt::test {

// An asymmetric (neither x- nor y-symmetric) RGB image: smooth ramps, a sine texture and a bright
// off-centre disc with a hard edge, values in about [0.05, 2.5].
inline std::vector<float> make_image(int w, int h, float scale = 1.f) {
  std::vector<float> img(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float u = (x + 0.5f) / w, v = (y + 0.5f) / h;
      const float disc = (u - 0.3f) * (u - 0.3f) + (v - 0.7f) * (v - 0.7f) < 0.04f ? 1.5f : 0.f;
      for (int c = 0; c < 3; ++c) {
        const float base = 0.05f + 0.4f * u + 0.2f * v * v * (c + 1) +
                           0.1f * std::sin(7.f * u + 3.f * v + c) + disc * (0.5f + 0.25f * c);
        img[3 * (size_t(y) * w + x) + c] = scale * std::max(base, 0.05f);
      }
    }
  return img;
}

// Exact forward differences with the Neumann rows (last column / row) set to zero.
inline void exact_gradients(const std::vector<float>& img, int w, int h, std::vector<float>& gx,
                            std::vector<float>& gy) {
  gx.assign(img.size(), 0.f);
  gy.assign(img.size(), 0.f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const size_t i = 3 * (size_t(y) * w + x) + c;
        if (x + 1 < w) gx[i] = float(double(img[i + 3]) - img[i]);
        if (y + 1 < h) gy[i] = float(double(img[i + 3 * size_t(w)]) - img[i]);
      }
}

// Gaussian noise of standard deviation sigma, made exactly zero-mean per channel.
inline std::vector<float> zero_mean_noise(size_t pixels, float sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> normal(0.f, sigma);
  std::vector<float> n(pixels * 3);
  for (float& v : n) v = normal(rng);
  for (int c = 0; c < 3; ++c) {
    double mean = 0;
    for (size_t i = 0; i < pixels; ++i) mean += n[3 * i + c];
    mean /= double(pixels);
    for (size_t i = 0; i < pixels; ++i) n[3 * i + c] -= float(mean);
  }
  return n;
}

inline std::vector<float> add(const std::vector<float>& a, const std::vector<float>& b) {
  std::vector<float> r(a.size());
  for (size_t i = 0; i < a.size(); ++i) r[i] = a[i] + b[i];
  return r;
}

// |a - b| / |b| over all values.
inline double relative_error(const std::vector<float>& a, const std::vector<float>& b) {
  double num = 0, den = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    num += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
    den += double(b[i]) * b[i];
  }
  return std::sqrt(num / den);
}

inline double rms_error(const std::vector<float>& a, const std::vector<float>& b) {
  double num = 0;
  for (size_t i = 0; i < a.size(); ++i) num += (double(a[i]) - b[i]) * (double(a[i]) - b[i]);
  return std::sqrt(num / double(a.size()));
}

}  // namespace gdpt::test
