// The inputs of the Feature reconstruction, made ready for the per-pixel regression: the two
// primal halves and their variances with non-finite values masked, and the guide features
// stacked per pixel and scaled to unit spread over the image.
#pragma once

#include <cstdint>
#include <vector>

#include "reconstruct/reconstruct.h"

namespace gdpt::detail {

// Guide (3) + albedo (3) + normal (3) + depth (1).
inline constexpr int kMaxFeatures = 10;

// Per-pixel validity bits.
enum FeatureValidity : uint8_t { kHalvesValid = 1, kFeaturesValid = 2 };

struct FeatureBuffers {
  int width = 0, height = 0;
  int count = 0;                // features per pixel, <= kMaxFeatures
  std::vector<float> features;  // `count` per pixel, scaled to unit standard deviation
  std::vector<float> noise;     // `count` per pixel: the features' variance in those units
  // Per feature: the colour channel a guide channel predicts with slope `guide_slope` (undoing
  // the scaling), or -1 for the other features.
  int guide_colour[kMaxFeatures];
  float guide_slope[kMaxFeatures];
  std::vector<float> a, b;      // RGB halves, 0 where missing
  std::vector<float> smooth_a;  // RGB halves box-filtered over 3x3 (the NLM patch means)
  std::vector<float> smooth_b;
  std::vector<float> patch_var_a;  // RGB variance of those 3x3 means
  std::vector<float> patch_var_b;
  std::vector<float> half_var;  // RGB (Var A + Var B) / 2, unbiased per pixel
  std::vector<uint8_t> valid;   // FeatureValidity bits per pixel
  int missing = 0;              // pixels with some non-finite input
};

// `guide` (RGB, may be null) is the gradient-domain solution. Features that are absent or
// constant over the image are left out.
FeatureBuffers prepare_feature_buffers(const ReconstructionInput& in, const float* guide);

// Mean of `channels`-channel `src` over the (2 radius + 1)^2 box around each pixel, clipped to
// the image (the mean of the pixels inside). Row-chunked and deterministic.
void box_filter(const float* src, int channels, int width, int height, int radius, float* dst);

}  // namespace gdpt::detail
