// The Feature reconstruction (ReconstructionNorm::Feature): feature-guided filters of the
// gradient-domain solution, chosen per pixel by an error estimate from two halves of the samples.
//
//   1. base images: the solution of all samples with settings.feature_guide at settings.alpha,
//      and, from the gradient halves, each half's own solution by the same norm (a shorter L1
//      schedule; only used to estimate errors). Without gradient halves, or with the guide None,
//      the base is the primal: its halves and their mean. With the variance buffer, also the
//      Weighted solutions of the halves and their mean: one more candidate, taken as it is;
//   2. per candidate filter (feature_bilateral.h): each half filtered alone and the solution of
//      all samples filtered alike, all three divided by the albedo before and multiplied by it
//      after (the filters smooth the illumination; textures stay sharp); with the primal halves'
//      variances, their colour distances count each pixel's noise;
//   3. per pixel the candidate with the smallest smoothed relative error estimate of the halves
//      (candidate_selection.h; relative to a guide colour from two more filters of all samples),
//      then the choices blended over the estimate's window (blend_choices); output = the blend
//      of the candidates applied to all samples (+ emission).
//
// Memory beyond the inputs: at most about 528 bytes per pixel, 528 MB per megapixel, while the
// windows are filtered (feature buffers 105, the solved halves and image 36, the Weighted
// candidate's three images 36, their albedo-divided copies and the albedo 48, the choice and its
// weights 33, every candidate's image and key for the blend 208, the windows' raw error estimates
// 48, the pixels' noise for the colour distances 12, with the halves' variances; the guide's two
// filtered copies, 24, and the identity's filtered halves and estimates, 32, before; the Weighted
// candidate's estimate and key, 8, and the blend's scratch, 24, after the estimates and the
// divided copies are released), plus the gradient-domain solves' own buffers while they run.
#pragma once

#include <vector>

#include "reconstruct/feature_bilateral.h"
#include "reconstruct/reconstruct.h"

namespace gdpt {

struct FeatureReconstruction {
  std::vector<float> image;  // RGB, without emission
  // Per pixel: the chosen candidate's index and estimated squared error of the halves' mean (the
  // image blends that candidate with those its neighbours chose).
  std::vector<float> error;
  std::vector<uint8_t> chosen;
  int features = 0;  // feature channels used
  int missing = 0;   // pixels with some non-finite input
  int limited = 0;   // pixels where one half or both were limited as outliers (half_outliers.h)
  // Wall time of the steps: the outlier limit and feature buffers; the filters (with the
  // relative-error guide and the albedo division); the error estimates and choice; the blend.
  double prepare_seconds = 0.0, filter_seconds = 0.0, select_seconds = 0.0, blend_seconds = 0.0;
};

// One more candidate taken as it is: its image of each half and of all samples (RGB).
struct IdentityCandidate {
  const float *a = nullptr, *b = nullptr, *all = nullptr;
};

// Steps 2 and 3 on given base images (RGB): halves `a`, `b` (variances optional, both or
// neither) and `all`, with the features of `input`, in the caller's TBB arena. chosen[i] indexes
// detail::default_bilateral_candidates(), then `extra` (optional; its images must stay alive
// during the call).
FeatureReconstruction feature_filter(const ReconstructionInput& input, const float* a,
                                     const float* b, const float* all,
                                     const float* variance_a = nullptr,
                                     const float* variance_b = nullptr,
                                     const IdentityCandidate* extra = nullptr);

// reconstruct() for ReconstructionNorm::Feature: the base images, then feature_filter, then the
// output rule (+ emission, non-finite -> 0).
std::vector<float> reconstruct_feature(const ReconstructionInput& input,
                                       const ReconstructionSettings& settings,
                                       ReconstructionReport* report);

}  // namespace gdpt
