#include "render/light_distribution.h"

#include <algorithm>
#include <cmath>

namespace gdpt {

Distribution1D::Distribution1D(std::span<const float> values)
    : func_(values.begin(), values.end()), cdf_(values.size() + 1, 0.0) {
  for (float& f : func_)
    if (!(f > 0.0f) || !std::isfinite(f)) f = 0.0f;
  // Accumulate in double: emissive meshes can have millions of entries.
  for (size_t i = 0; i < func_.size(); ++i) cdf_[i + 1] = cdf_[i] + func_[i];
  total_ = cdf_.back();
  if (total_ > 0.0) {
    for (double& c : cdf_) c /= total_;
  } else {
    // Degenerate: keep a uniform CDF so that sampling stays well defined (pmf() reports 0).
    for (size_t i = 0; i < cdf_.size(); ++i)
      cdf_[i] = func_.empty() ? 0.0 : double(i) / double(func_.size());
  }
  if (!cdf_.empty()) cdf_.back() = 1.0;
}

uint32_t Distribution1D::sample_discrete(float u, float* pmf_out, float* u_remapped) const {
  if (func_.empty()) {
    if (pmf_out) *pmf_out = 0.0f;
    return 0;
  }
  // Last i with cdf_[i] <= u, skipping zero-probability bins (equal consecutive cdf values).
  const double ud = std::clamp(double(u), 0.0, std::nextafter(1.0, 0.0));
  const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), ud);
  const size_t i = std::min<size_t>(size_t(it - cdf_.begin()) - 1, func_.size() - 1);
  const double width = cdf_[i + 1] - cdf_[i];
  if (pmf_out) *pmf_out = total_ > 0.0 ? float(width) : 0.0f;
  if (u_remapped)
    *u_remapped = width > 0.0 ? std::min(float((ud - cdf_[i]) / width), 0.99999994f) : 0.0f;
  return uint32_t(i);
}

float Distribution1D::pmf(uint32_t index) const {
  if (index >= func_.size() || !(total_ > 0.0)) return 0.0f;
  return float(double(func_[index]) / total_);
}

float Distribution1D::sample_continuous(float u, float* pdf, uint32_t* index) const {
  float u_in_bin = 0.0f, p = 0.0f;
  const uint32_t i = sample_discrete(u, &p, &u_in_bin);
  if (index) *index = i;
  if (pdf) *pdf = p * float(func_.size());
  return std::min((float(i) + u_in_bin) / float(func_.size()), 0.99999994f);
}

float Distribution1D::pdf_continuous(float x) const {
  if (func_.empty()) return 0.0f;
  const int n = int(func_.size());
  const int i = std::clamp(int(x * float(n)), 0, n - 1);
  return pmf(uint32_t(i)) * float(n);
}

Distribution2D::Distribution2D(std::span<const float> values, int nx, int ny) : nx_(nx), ny_(ny) {
  conditional_.reserve(size_t(ny));
  std::vector<float> row_sums(static_cast<size_t>(ny));
  for (int j = 0; j < ny; ++j) {
    conditional_.emplace_back(values.subspan(size_t(j) * size_t(nx), size_t(nx)));
    row_sums[size_t(j)] = float(conditional_.back().total());
  }
  marginal_ = Distribution1D(row_sums);
}

Vec2f Distribution2D::sample(Vec2f u, float* pdf) const {
  float pdf_row = 0.0f, pdf_col = 0.0f;
  uint32_t row = 0;
  const float y = marginal_.sample_continuous(u.y, &pdf_row, &row);
  const float x = conditional_[row].sample_continuous(u.x, &pdf_col);
  if (pdf) *pdf = pdf_row * pdf_col;
  return {x, y};
}

float Distribution2D::pdf(Vec2f p) const {
  if (marginal_.empty()) return 0.0f;
  const int j = std::clamp(int(p.y * float(ny_)), 0, ny_ - 1);
  return marginal_.pdf_continuous(p.y) * conditional_[size_t(j)].pdf_continuous(p.x);
}

}  // namespace gdpt
