// Screened Poisson reconstruction of an image from a noisy primal and its noisy gradients:
//   minimise || alpha (I - primal) ||_p^p + || Dx I - dx ||_p^p + || Dy I - dy ||_p^p
// with forward differences and zero (Neumann) rows at the last column / row, per RGB channel.
// Images are interleaved RGB float, `width * height * 3`, in rows as stored (the gradient
// convention dy(x, y) = I(x, y + 1) - I(x, y) refers to those rows).
#pragma once

#include <cstdint>
#include <vector>

namespace gdpt {

enum class ReconstructionNorm : uint8_t { L2, L1, Weighted, None };

struct ReconstructionSettings {
  ReconstructionNorm norm = ReconstructionNorm::L1;
  float alpha = 0.2f;  // must be > 0
  int threads = 0;     // 0 = all cores
};

struct ReconstructionInput {
  int width = 0, height = 0;
  const float* primal = nullptr;      // RGB
  const float* gradient_x = nullptr;  // RGB
  const float* gradient_y = nullptr;  // RGB
  const float* variance = nullptr;    // 3 per pixel (primal, dx, dy luminance); Weighted only
  const float* emission = nullptr;    // RGB, optional: added to the solution
};

struct ReconstructionReport {
  int iterations = 0;      // total inner iterations
  double objective = 0.0;  // final value of the objective for the chosen norm
  double seconds = 0.0;
};

// Returns RGB `width * height * 3`. Throws std::invalid_argument on bad input (alpha <= 0, sizes,
// missing variance for Weighted). NaN/Inf input values are treated as missing data.
std::vector<float> reconstruct(const ReconstructionInput& input,
                               const ReconstructionSettings& settings,
                               ReconstructionReport* report = nullptr);

}  // namespace gdpt
