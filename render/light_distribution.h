// Piecewise-constant distributions used by light sampling: a 1-D table (light selection by power,
// one row of an environment map) and a 2-D table (equirectangular importance sampling, a
// marginal over rows times a conditional per row).
//
// Construction allocates; sampling and pdf queries are const, allocation-free and thread-safe.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/vec.h"

namespace gdpt {

class Distribution1D {
 public:
  Distribution1D() = default;
  // Negative and non-finite values are treated as 0.
  explicit Distribution1D(std::span<const float> values);

  size_t size() const { return func_.size(); }
  // Sum of the values (the integral over [0,1] times size()).
  double total() const { return total_; }
  bool empty() const { return !(total_ > 0.0); }

  // Index i with probability values[i] / total. `u_remapped` is u rescaled to [0,1) inside the
  // chosen bin, so one random number can be reused.
  uint32_t sample_discrete(float u, float* pmf = nullptr, float* u_remapped = nullptr) const;
  float pmf(uint32_t index) const;

  // Continuous sample x in [0,1) with density values[i] * size() / total on bin i.
  float sample_continuous(float u, float* pdf, uint32_t* index = nullptr) const;
  float pdf_continuous(float x) const;

 private:
  std::vector<float> func_;
  std::vector<double> cdf_;  // size()+1 entries, cdf_[0] = 0, cdf_.back() = 1
  double total_ = 0.0;
};

// Density on [0,1]^2, piecewise constant on an nx x ny grid; cell (i, j) is column i, row j.
class Distribution2D {
 public:
  Distribution2D() = default;
  // values: nx * ny, row-major (row j starts at j * nx).
  Distribution2D(std::span<const float> values, int nx, int ny);

  bool empty() const { return marginal_.empty(); }
  // Point in [0,1)^2 and its density with respect to area on [0,1]^2.
  Vec2f sample(Vec2f u, float* pdf) const;
  float pdf(Vec2f p) const;

 private:
  int nx_ = 0, ny_ = 0;
  std::vector<Distribution1D> conditional_;  // one per row
  Distribution1D marginal_;                  // over rows
};

}  // namespace gdpt
