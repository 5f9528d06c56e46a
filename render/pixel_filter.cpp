#include "render/pixel_filter.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace gdpt {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kTableCells = 1024;  // as Cycles' filter table

// Blackman-Harris window coefficients (a0 - a1 cos v + a2 cos 2v - a3 cos 3v).
constexpr double kA0 = 0.35875, kA1 = 0.48829, kA2 = 0.14128, kA3 = 0.01168;

double support_radius(PixelFilterType type, double width) {
  switch (type) {
    case PixelFilterType::Gaussian:
      return 1.5 * width;
    case PixelFilterType::BlackmanHarris:
      return width;
    case PixelFilterType::Box:
      break;
  }
  return 0.5 * width;
}

// Integral of the 1-D profile from -radius to x (unnormalised), in closed form.
double profile_integral(PixelFilterType type, double width, double radius, double x) {
  switch (type) {
    case PixelFilterType::Gaussian: {
      const double s = width / 4.0 * std::sqrt(2.0);  // exp(-8 x^2 / w^2) = exp(-(x / s)^2)
      return 0.5 * std::sqrt(kPi) * s * (std::erf(x / s) - std::erf(-radius / s));
    }
    case PixelFilterType::BlackmanHarris: {
      // v runs over [0, 2 pi] across [-w, w].
      const auto antiderivative = [](double v) {
        return kA0 * v - kA1 * std::sin(v) + kA2 * std::sin(2.0 * v) / 2.0 -
               kA3 * std::sin(3.0 * v) / 3.0;
      };
      const double v = kPi * (x / width + 1.0);
      return width / kPi * (antiderivative(v) - antiderivative(0.0));
    }
    case PixelFilterType::Box:
      break;
  }
  return x + radius;
}

}  // namespace

PixelFilter::PixelFilter(PixelFilterType type, float width) : type_(type), width_(width) {
  if (!(width > 0.0f) || !std::isfinite(width))
    throw std::invalid_argument("pixel filter: width must be a positive number of pixels, got " +
                                std::to_string(width));
  const double radius = support_radius(type, double(width));
  radius_ = float(radius);
  if (type == PixelFilterType::Box) return;
  // The CDF at evenly spaced offsets, from the closed-form integral of the profile.
  const double total = profile_integral(type, width, radius, radius);
  cell_ = float(2.0 * radius / kTableCells);
  cdf_.resize(kTableCells + 1);
  for (int i = 0; i <= kTableCells; ++i)
    cdf_[size_t(i)] = float(
        profile_integral(type, width, radius, -radius + 2.0 * radius * i / kTableCells) / total);
  cdf_[0] = 0.0f;
  cdf_[kTableCells] = 1.0f;
  guide_.resize(kTableCells);
  int cell = 0;
  for (int k = 0; k < kTableCells; ++k) {
    const float u = float(k) / kTableCells;
    while (cell < kTableCells - 1 && cdf_[size_t(cell) + 1] <= u) ++cell;
    guide_[size_t(k)] = cell;
  }
}

}  // namespace gdpt
