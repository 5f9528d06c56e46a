// Edge-aware window filters guided by the features: a cross-bilateral filter whose weights fall
// with the distance in albedo, normal and depth (each over its tolerance plus the two pixels'
// feature variances) and, optionally, with the colour difference relative to the centre pixel's
// brightness. The candidates of the Feature reconstruction are these filters at several window
// sizes and colour tolerances.
#pragma once

#include <vector>

#include "reconstruct/feature_buffers.h"

namespace gdpt::detail {

// Feature tolerances: albedo (reflectance units), normal (unit vectors), depth (relative).
inline constexpr float kAlbedoTolerance = 0.05f;
inline constexpr float kNormalTolerance = 0.1f;
inline constexpr float kDepthTolerance = 0.05f;

struct BilateralCandidate {
  int radius = 0;     // window (2 radius + 1)^2; 0 is the identity
  float range = 0.f;  // colour tolerance relative to the centre's brightness; 0: none
};

// The candidate set: the identity first, then each window with each colour tolerance.
std::vector<BilateralCandidate> default_bilateral_candidates();

// Filters `images` (count RGB images, each 0 where fb marks it missing) into `out`: the feature
// weights are shared, the colour weights come from each image itself (so a filtered half depends
// on that half alone). Missing pixels get weight 0; a pixel without valid features keeps its value.
void bilateral_filter(const FeatureBuffers& fb, const BilateralCandidate& candidate,
                      const float* const* images, float* const* out, int count);

}  // namespace gdpt::detail
