// Per-pixel choice among candidate filters by an unbiased estimate of their error.
//
// With independent halves A and B (variances VA, VB) and their filtered versions FA (from A
// alone) and FB (from B alone), E[(FA - B)^2] = MSE(FA) + VB, and the mean of the shared bias and
// the halved independent noise gives, for (FA + FB) / 2:
//   e = ((FA - B)^2 + (FB - A)^2) / 2 - (VA + VB) / 2 - (FA - FB)^2 / 4.
// e is unbiased but noisy per pixel; it is averaged over a window before candidates are compared.
// The engine's halves are two segments of one stratified sequence (core/sample_halves.h), which
// keeps the image of all samples as stratified as a render without halves; they are then
// anti-correlated by what the whole stratifies better than its halves, and e overstates the
// noise terms a little (the halves' (A - B)^2 / 4 read 1.00-1.44x the primal's true error on
// the benchmark scenes at 5 s, docs/reconstruct.md).
// The comparison weighs each channel's e by 1 / (g^2 + eps), g a candidate-independent guide of
// the pixel's colour: the error compared is relative, so a few bright pixels (a light seen in a
// mirror, a noisy highlight edge) cannot choose, for a whole window, a filter that spreads them
// over their dark neighbours.
//
// The per-pixel choice is then smoothed: each pixel blends the candidates in the proportions its
// (2 kErrorSmoothingRadius + 1)^2 neighbourhood chose them (neighbouring choices are noisy picks
// among near-equal candidates; their mean has less error than any one of them). The neighbourhood
// is no wider than the estimate's window, so every neighbour's choice weighed this pixel's error,
// and a candidate whose own estimate here is far above the best is left out (a neighbour's choice
// must not bring a wide filter onto a bright spot it would spread).
#pragma once

#include <cstdint>
#include <vector>

#include "reconstruct/feature_buffers.h"

namespace gdpt::detail {

inline constexpr int kErrorSmoothingRadius = 10;
inline constexpr float kRelativeErrorEpsilon = 1e-2f;
// A candidate enters a pixel's blend while its estimate is at most best + tolerance * |best|.
inline constexpr float kBlendTolerance = 16.f;

struct CandidateChoice {
  std::vector<float> image;         // RGB: the chosen candidate's filter applied to all samples
  std::vector<float> error;         // per pixel, its smoothed error estimate (mean over RGB)
  FreshHugeVector<float> relative;  // per pixel, its smoothed relative error estimate (the key)
  FreshHugeVector<float> weight;    // RGB: 1 / (guide^2 + eps); empty: absolute errors compared
  std::vector<uint8_t> index;       // per pixel, the chosen candidate
  // Every candidate offered: its image of all samples (RGB; the caller's, kept alive until
  // blend_choices) and its key, for blend_choices.
  std::vector<const float*> images;
  std::vector<FreshHugeVector<float>> keys;
};

// Per pixel e (mean over RGB) of the candidate with filtered halves fa, fb_half; 0 where the
// halves are missing. With `weight` (RGB), also the weighted mean to `relative`.
void candidate_error(const FeatureBuffers& fb, const float* fa, const float* fb_half, float* error,
                     const float* weight = nullptr, float* relative = nullptr);

// candidate_error at pixel i from the filtered halves' colours fa, fb_half (RGB of pixel i).
inline void pixel_error(const FeatureBuffers& fb, size_t i, const float* fa, const float* fb_half,
                        const float* weight, float* error, float* relative) {
  float e = 0.f, r = 0.f;
  if (fb.valid[i] & kImagesValid) {
    for (int c = 0; c < 3; ++c) {
      const size_t k = 3 * i + c;
      const float da = fa[c] - fb.b[k], db = fb_half[c] - fb.a[k], dd = fa[c] - fb_half[c];
      const float ec = 0.5f * (da * da + db * db) - fb.half_var[k] - 0.25f * dd * dd;
      e += ec;
      if (weight) r += weight[k] * ec;
    }
  }
  error[i] = e * (1.f / 3.f);
  if (relative) relative[i] = r * (1.f / 3.f);
}

// choice.weight from `guide` (RGB, candidate-independent): 1 / (guide^2 + eps) per channel.
void set_relative_weights(const FeatureBuffers& fb, const float* guide, CandidateChoice& choice);

// Offers candidate `index` (halves filtered to fa, fb_half; the image of all samples to
// `filtered`): pixels whose smoothed relative error beats the current choice take `filtered` (the
// first candidate offered is taken everywhere; ties keep the earlier one). Candidates are offered
// with index 0, 1, 2, ... in turn; `filtered` must stay alive until blend_choices.
void offer_candidate(const FeatureBuffers& fb, int index, const float* fa, const float* fb_half,
                     const float* filtered, CandidateChoice& choice);

// offer_candidate from the candidate's estimates (candidate_error's, as bilateral_candidates
// writes them): `error`, smoothed in place (the caller's scratch), and `relative` (with
// choice.weight; unused without), which becomes the candidate's key.
void offer_estimates(const FeatureBuffers& fb, int index, float* error,
                     FreshHugeVector<float> relative, const float* filtered,
                     CandidateChoice& choice);

// After the last offer: choice.image becomes the blend of the candidates in the proportions the
// neighbourhood chose them (see above); the offered images and keys are released.
void blend_choices(const FeatureBuffers& fb, CandidateChoice& choice);

}  // namespace gdpt::detail
