#include "shaders/ggx_albedo.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "shaders/bsdf_ggx_reflection.h"

namespace gdpt {

namespace {

constexpr int kSize = 32;        // nodes along mu and along sqrt(alpha)
constexpr int kStrata = 96;      // quadrature points per axis of the visible-normal square
constexpr float kMinMu = 1e-4f;  // the mu = 0 node, where the lobe is undefined

struct AlbedoTable {
  std::array<float, kSize * kSize> e{};  // e[row (sqrt alpha) * kSize + column (mu)]
  std::array<float, kSize> average{};

  AlbedoTable() {
    for (int r = 0; r < kSize; ++r) {
      const float root = float(r) / float(kSize - 1);
      for (int m = 0; m < kSize; ++m)
        e[r * kSize + m] = directional(std::max(float(m) / float(kSize - 1), kMinMu), root * root);
      average[r] = cosine_average(&e[r * kSize]);
    }
  }

  // Midpoint quadrature of value / pdf over the lobe's visible-normal sampler: the lobe's own
  // formulas, so that the table matches what it renders.
  static float directional(float mu, float alpha) {
    Closure c;
    c.type = ClosureType::GGXReflection;
    c.alpha = alpha;
    if (is_delta_alpha(alpha)) return 1.0f;
    const Vec3f wi(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
    double sum = 0.0;
    for (int i = 0; i < kStrata; ++i)
      for (int j = 0; j < kStrata; ++j) {
        const Vec2f u((i + 0.5f) / kStrata, (j + 0.5f) / kStrata);
        const BsdfSample s = ggx_reflection::sample(c, wi, 0.0f, u);
        if (s.valid && s.pdf > 0.0f) sum += double(s.value.x) / double(s.pdf);
      }
    return float(sum / (double(kStrata) * kStrata));
  }

  // 2 int_0^1 E(mu) mu dmu of the piecewise-linear E (exact: Simpson on each segment).
  static float cosine_average(const float* row) {
    double sum = 0.0;
    for (int m = 0; m + 1 < kSize; ++m) {
      const double a = double(m) / (kSize - 1), b = double(m + 1) / (kSize - 1);
      sum += (b - a) / 6.0 * (a * (2.0 * row[m] + row[m + 1]) + b * (row[m] + 2.0 * row[m + 1]));
    }
    return float(2.0 * sum);
  }
};

const AlbedoTable& table() {
  static const AlbedoTable t;  // thread-safe initialisation
  return t;
}

// Position x in [0, 1] on a kSize-node axis: the lower node and the fraction towards the next.
void locate(float x, int& i, float& f) {
  const float p = std::clamp(x, 0.0f, 1.0f) * float(kSize - 1);
  i = std::min(int(p), kSize - 2);
  f = p - float(i);
}

}  // namespace

float ggx_albedo(float mu, float alpha) {
  const AlbedoTable& t = table();
  int r, m;
  float fr, fm;
  locate(std::sqrt(std::clamp(alpha, 0.0f, 1.0f)), r, fr);
  locate(mu, m, fm);
  const float* a = &t.e[r * kSize + m];
  const float* b = a + kSize;
  const float lo = a[0] + (a[1] - a[0]) * fm, hi = b[0] + (b[1] - b[0]) * fm;
  return lo + (hi - lo) * fr;
}

float ggx_average_albedo(float alpha) {
  const AlbedoTable& t = table();
  int r;
  float fr;
  locate(std::sqrt(std::clamp(alpha, 0.0f, 1.0f)), r, fr);
  return t.average[r] + (t.average[r + 1] - t.average[r]) * fr;
}

}  // namespace gdpt
