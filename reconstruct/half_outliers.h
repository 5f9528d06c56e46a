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
#pragma once

namespace gdpt::detail {

inline constexpr float kHalfOutlierRatio = 3.f;
// Luminance floor of the bounds, so black regions keep faint light.
inline constexpr float kHalfOutlierFloor = 1e-3f;

// Limits the outliers of halves `a` and `b` (RGB, width x height) in place, found by the test on
// `primal_a` and `primal_b` (the same pointers when the primal itself is filtered), and scales
// `all` alike; pixels with a non-finite value are left as they are. Returns the pixels where the
// test fired. Bit-identical at any thread count.
int limit_half_outliers(int width, int height, const float* primal_a, const float* primal_b,
                        float* a, float* b, float* all);

}  // namespace gdpt::detail
