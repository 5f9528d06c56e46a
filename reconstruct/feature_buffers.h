// The inputs of the Feature reconstruction, made ready for the per-pixel filters: the base image
// (the gradient-domain solution of all samples, or the primal) and its two halves with
// non-finite values masked, and the guide features (albedo, normal, depth) with their
// variances.
#pragma once

#include <cstdint>
#include <vector>

#include "core/huge_pages.h"
#include "reconstruct/reconstruct.h"

namespace gdpt::detail {

// Per-pixel validity bits.
enum FeatureValidity : uint8_t { kImagesValid = 1, kFeaturesValid = 2 };

struct FeatureBuffers {
  int width = 0, height = 0;
  int features = 0;  // feature channels present (albedo 3, normal 3, depth 1)
  FreshHugeVector<float> a, b,
      all;                          // RGB: the halves and the image of all samples, 0 where missing
  FreshHugeVector<float> half_var;  // RGB (Var A + Var B) / 2, unbiased per pixel
  // Feature values and variances, one plane (width x height) per channel, so that the filters'
  // loops over pixels read contiguous floats: albedo RGB, normal XYZ, depth (zeros for an absent
  // feature, which then adds nothing to a distance).
  FreshHugeVector<float> feature, feature_var;
  FreshHugeVector<uint8_t> valid;  // FeatureValidity bits per pixel
  int missing = 0;                 // pixels with some non-finite input
};

inline constexpr int kFeatureChannels = 7;

// `a`, `b`: the halves' images (RGB); `all`: the image the chosen filter is applied to;
// `variance_a` / `variance_b`: the halves' variances (RGB), both or neither: without them
// (A - B)^2 / 2 stands in, unbiased for independent halves (candidate_selection.h).
FeatureBuffers prepare_feature_buffers(const ReconstructionInput& in, const float* a,
                                       const float* b, const float* all, const float* variance_a,
                                       const float* variance_b);

// Mean of `channels`-channel `src` over the (2 radius + 1)^2 box around each pixel, clipped to
// the image (the mean of the pixels inside). Row-chunked and deterministic; dst may be src.
void box_filter(const float* src, int channels, int width, int height, int radius, float* dst);

}  // namespace gdpt::detail
