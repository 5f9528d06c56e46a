// First-order (weighted linear) regression of one primal half on the guide features, with
// non-local-means weights computed from the OTHER half (NFOR's cross-filtering: the weights do
// not see the noise of the values they average).
//
// Models are fitted at centres on a grid `kCenterSpacing` pixels apart, each over a window of
// (2 kWindowRadius + 1)^2 samples taken every `stride` pixels; every pixel then evaluates the
// models of the four centres around it at its own features and blends them, bilinearly and by
// the same NLM weight (NFOR's collaborative step, on a sparse grid to bound the cost). The
// colour's slope on the guide (the gradient-domain solution) is pulled towards identity, every
// other slope towards zero: where the window cannot tell, the result falls back to the guide.
#pragma once

#include "reconstruct/feature_buffers.h"

namespace gdpt::detail {

inline constexpr int kWindowRadius = 4;
inline constexpr int kCenterSpacing = 5;

// Pull of the guide's slope towards identity per unit weight, in units of its spread.
inline constexpr float kGuideRidge = 0.05f;

// One window; it yields two candidates when the buffers have a guide: the regression without
// the guide and with it (the same weights and sums, two solves).
struct CandidateFilter {
  int stride = 1;         // window sample spacing: the window spans 2 kWindowRadius stride + 1
  float bandwidth = 1.f;  // NLM k: larger accepts larger colour differences
};

bool has_guide(const FeatureBuffers& fb);

// Writes the filtered RGB of `target` (fb.a or fb.b) without the guide to out[0] and, when
// has_guide(fb), with it to out[1]; `weight_mean` / `weight_var` are the other half's 3x3 patch
// means and their variances.
void cross_filter_half(const FeatureBuffers& fb, const float* target, const float* weight_mean,
                       const float* weight_var, const CandidateFilter& filter, float* const* out);

}  // namespace gdpt::detail
