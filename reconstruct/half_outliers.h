// Fireflies of one half: a pixel far brighter in one half's primal than in the other half's and
// than its neighbourhood is an outlier of that half (a rare path both halves would see given
// enough samples). Left in, it survives the identity and the colour-tolerant filters, or is spread
// by the wide ones, as an isolated bright speckle.
//
// Test (on the primal halves, where a firefly is one pixel): the brighter half's luminance above
// kHalfOutlierRatio times the larger of the other half's and the median of the halves' mean over
// the 8 neighbours. Where it fires, the outlier half's image and the image of all samples are
// scaled by the ratio of the halves' limited to their original sum (the brighter half limited to
// that bound), but each is kept at or above kHalfOutlierRatio times the median of its own 8
// neighbours (a gradient-domain solve may already have spread or removed the firefly); for the
// image of all samples, the lower of that median and the primal mean's (the test's): a solve that
// spread the firefly onto the neighbours raised their median, which alone kept a spread firefly
// of the demo scene at 4x the reference.
// Converging halves agree, so the test stops firing as samples grow and the reconstruction stays
// consistent; a real one-pixel highlight is in both halves and is kept.
//
// Fireflies of both halves: with the primal halves' variances, a pixel where each half is above
// kHalfOutlierRatio times the neighbours' median and each half's variance of the mean is at least
// kHalfDominance times its mean squared (one sample carries the half: one bright sample among
// dark ones gives about 1, two equal ones about 0.47) holds two rare paths, one per half; both
// halves and all samples are limited to the neighbourhood's bound, with the floors above. On the
// demo that was the one isolated speckle left (both halves 3.7-3.8 on a 0.5 floor, from one path
// of about 53 each). A highlight most samples see has a small variance and is kept; so is a pixel
// inside a bright region (most of its 8 neighbours bright, their median too). As samples grow, more
// than one sample per half sees a real feature and the test stops firing.
#pragma once

namespace gdpt::detail {

inline constexpr float kHalfOutlierRatio = 3.f;
// Luminance floor of the bounds, so black regions keep faint light.
inline constexpr float kHalfOutlierFloor = 1e-3f;
// Variance of a half's mean over its mean squared from which one sample carries it.
inline constexpr float kHalfDominance = 0.5f;

// Limits the outliers of halves `a` and `b` (RGB, width x height) in place, found by the tests on
// `primal_a` and `primal_b` (the same pointers when the primal itself is filtered) and their RGB
// variances of the mean (optional, both or neither: without them only one-half fireflies are
// limited), and scales `all` alike; pixels with a non-finite value are left as they are. Returns
// the pixels where a test fired. Bit-identical at any thread count.
int limit_half_outliers(int width, int height, const float* primal_a, const float* primal_b,
                        float* a, float* b, float* all, const float* variance_a = nullptr,
                        const float* variance_b = nullptr);

}  // namespace gdpt::detail
