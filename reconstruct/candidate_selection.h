// Per-pixel choice among candidate filters by an unbiased estimate of their error.
//
// With independent halves A and B (variances VA, VB) and their filtered versions FA (from A
// alone) and FB (from B alone), E[(FA - B)^2] = MSE(FA) + VB, and the mean of the shared bias and
// the halved independent noise gives, for (FA + FB) / 2:
//   e = ((FA - B)^2 + (FB - A)^2) / 2 - (VA + VB) / 2 - (FA - FB)^2 / 4.
// e is unbiased but noisy per pixel; it is averaged over a window before candidates are compared.
// The comparison weighs each channel's e by 1 / (g^2 + eps), g a candidate-independent guide of
// the pixel's colour: the error compared is relative, so a few bright pixels (a light seen in a
// mirror, a noisy highlight edge) cannot choose, for a whole window, a filter that spreads them
// over their dark neighbours.
#pragma once

#include <cstdint>
#include <vector>

#include "reconstruct/feature_buffers.h"

namespace gdpt::detail {

inline constexpr int kErrorSmoothingRadius = 10;
inline constexpr float kRelativeErrorEpsilon = 1e-2f;

struct CandidateChoice {
  std::vector<float> image;     // RGB: the chosen candidate's filter applied to all samples
  std::vector<float> error;     // per pixel, its smoothed error estimate (mean over RGB)
  std::vector<float> relative;  // per pixel, its smoothed relative error estimate (the key)
  std::vector<float> weight;    // RGB: 1 / (guide^2 + eps); empty: absolute errors compared
  std::vector<uint8_t> index;   // per pixel, the chosen candidate
};

// Per pixel e (mean over RGB) of the candidate with filtered halves fa, fb_half; 0 where the
// halves are missing. With `weight` (RGB), also the weighted mean to `relative`.
void candidate_error(const FeatureBuffers& fb, const float* fa, const float* fb_half, float* error,
                     const float* weight = nullptr, float* relative = nullptr);

// choice.weight from `guide` (RGB, candidate-independent): 1 / (guide^2 + eps) per channel.
void set_relative_weights(const FeatureBuffers& fb, const float* guide, CandidateChoice& choice);

// Offers candidate `index` (halves filtered to fa, fb_half; the image of all samples to
// `filtered`): pixels whose smoothed relative error beats the current choice take `filtered` (the
// first candidate offered is taken everywhere; ties keep the earlier one).
void offer_candidate(const FeatureBuffers& fb, int index, const float* fa, const float* fb_half,
                     const float* filtered, CandidateChoice& choice);

}  // namespace gdpt::detail
