// The Feature reconstruction (ReconstructionNorm::Feature): NFOR-style first-order regression of
// the primal halves on the guide features, the gradient-domain solution among them.
//
//   1. guide = reconstruct(primal, gradients) with settings.feature_guide (L1 by default) at
//      settings.feature_guide_alpha;
//   2. per candidate filter: FA = regression of half A with weights from half B, FB likewise
//      (feature_regression.h);
//   3. per pixel the candidate with the smallest smoothed error estimate (candidate_selection.h);
//      output = (FA + FB) / 2 of that candidate (+ emission).
//
// Memory beyond the inputs, counted from the buffers with all features (10 channels): about
// 290 bytes per pixel, 290 MB per megapixel (feature buffers 165, the two halves' candidate
// outputs 48, the choice 17, the models of one half 17, guide and output 24, box-filter scratch
// 12), plus the guide solve's own buffers while it runs.
#pragma once

#include <vector>

#include "reconstruct/feature_regression.h"
#include "reconstruct/reconstruct.h"

namespace gdpt {

struct FeatureReconstruction {
  std::vector<float> image;     // RGB, without emission
  std::vector<float> error;     // per pixel: estimated squared error of `image`, mean over RGB
  std::vector<uint8_t> chosen;  // per pixel: index of the candidate filter used
  int features = 0;             // guide feature channels used
  int missing = 0;              // pixels with some non-finite input
  double prepare_seconds = 0.0, filter_seconds = 0.0, select_seconds = 0.0;
};

// The candidate windows tried per pixel: 9 and 17 pixels wide, each with and without the guide
// among the features (chosen[i] = 2 x window + with guide, when there is a guide).
std::vector<detail::CandidateFilter> default_feature_candidates();

// Steps 2 and 3 for given `guide` (RGB, may be null: no guide feature), in the caller's TBB
// arena. Needs input.primal_a and primal_b; throws std::invalid_argument otherwise.
FeatureReconstruction feature_regression(
    const ReconstructionInput& input, const float* guide,
    const std::vector<detail::CandidateFilter>& candidates = default_feature_candidates());

// reconstruct() for ReconstructionNorm::Feature: the guide, then feature_regression, then the
// output rule (+ emission, non-finite -> 0).
std::vector<float> reconstruct_feature(const ReconstructionInput& input,
                                       const ReconstructionSettings& settings,
                                       ReconstructionReport* report);

}  // namespace gdpt
