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

struct BilateralWindow {
  int radius = 0;  // taps up to radius pixels away; 0 is the identity
  int stride = 1;  // pixels between taps
};

// The windows (3, 5 and 7 px dense, 9 px every other pixel) and colour tolerances (relative to the
// centre's brightness; 0: none) of the candidate set.
inline constexpr BilateralWindow kWindows[] = {{1, 1}, {2, 1}, {3, 1}, {4, 2}};
inline constexpr float kColourTolerances[] = {0.05f, 0.2f, 0.f};
inline constexpr int kColourToleranceCount = 3;

struct BilateralCandidate {
  BilateralWindow window;
  float range = 0.f;
};

// The candidate set: the identity first, then each window with each colour tolerance.
std::vector<BilateralCandidate> default_bilateral_candidates();

// Filters `images` (count RGB images, each 0 where fb marks it missing) with each of the `ranges`
// colour tolerances at once into out[r * count + k]: the feature weights are shared, the colour
// weights come from each image itself (so a filtered half depends on that half alone). Missing
// pixels get weight 0; a pixel without valid features keeps its value. With `multiply` (RGB),
// every output is multiplied by it as it is written (the same floats as a pass after the filter).
void bilateral_filter(const FeatureBuffers& fb, const BilateralWindow& window, const float* ranges,
                      int range_count, const float* const* images, int count, float* const* out,
                      const float* multiply = nullptr);

// Where bilateral_candidates writes a candidate's error estimates (candidate_selection.h,
// candidate_error): per pixel, `error`, and `relative` unless null.
struct CandidateEstimates {
  float* error = nullptr;
  float* relative = nullptr;
};

// The candidates of `windows` (radius >= 1; at most std::size(kWindows)) x `ranges` in one pass:
// each tap's weights are computed once for every window that has it. images = {half A, half B,
// all samples}: per candidate c = window * range_count + range, out[c] gets the image of all
// samples filtered (times `multiply`) and estimates[c] candidate_error of the filtered halves
// (with `weight`), which are not kept. Bit-identical to bilateral_filter per window followed by
// candidate_error. With `noise` (per image, one plane: each pixel's variance summed over RGB, in
// the images' units), a colour distance is the squared difference over the tolerance's share of
// the centre's brightness plus both pixels' noise, so a difference the noise explains (a sample
// that one pixel happened to draw) does not keep a pixel apart from its neighbours.
void bilateral_candidates(const FeatureBuffers& fb, const BilateralWindow* windows,
                          int window_count, const float* ranges, int range_count,
                          const float* const* images, float* const* out,
                          const CandidateEstimates* estimates, const float* weight,
                          const float* multiply = nullptr, const float* const* noise = nullptr);

// The builds of the filters' pixel loops: the tree's own and, on x86-64 CPUs that have them, AVX2
// and AVX-512 ones (where the tree is built without); all give the same floats, bit for bit. The
// filters run the widest available one up to limit_filter_build's (for the test that compares
// them; not thread-safe against running filters).
enum class FilterBuild { Baseline, Avx2, Avx512 };
bool filter_build_available(FilterBuild build);
void limit_filter_build(FilterBuild highest);

inline void bilateral_filter(const FeatureBuffers& fb, const BilateralCandidate& candidate,
                             const float* const* images, float* const* out, int count) {
  bilateral_filter(fb, candidate.window, &candidate.range, 1, images, count, out);
}

}  // namespace gdpt::detail
