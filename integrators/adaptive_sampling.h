// Adaptive sampling (Cycles' Noise Threshold): which pixels still take samples. After each pass
// from the minimum sample count on (RenderSession ends a pass there, and then every 4 samples at
// most), a pixel's relative noise is the standard deviation of its
// estimate (the primal mean and, in G-PT, the means of its own gradient halves:
// Film::pixel_variance) over the square root of its luminance, Cycles' measure (noise / sqrt(I):
// between absolute and relative, as the eye weighs it after a view transform). A pixel stops when
// its own and its 3x3 neighbours' noise are below the threshold: a rare path one pixel has seen is
// likely in the next pixel too, which may not have met it yet. A pixel that stopped does not
// start again.
//
// Every pixel's samples stay a prefix of its own sample indices, so a pixel that stops holds what
// a render of its sample count would (the halves' split apart); the film's per-pixel means, the
// gradients' per-base-pixel halves and the Variance pass hold for any mix of counts. With the
// feature passes, pixels stop only after an even number of samples (the halves stay equal).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "render/film.h"
#include "scene/render_settings.h"

namespace gdpt {

// The samples every pixel takes before any may stop: settings.adaptive_min_samples, or (0) a
// quarter of settings.samples rounded up to even, 4 to 64 (a time-limited render's sample count
// is unbounded); with the feature passes rounded up to even; never more than settings.samples.
int adaptive_min_samples(const RenderSettings& settings);

// A pixel's relative noise as compared with the threshold (Film::pixel_variance, ..._luminance).
double adaptive_noise(const Film& film, size_t i);

// Updates `mask` (width x height of `film`; empty or of another size: every pixel sampling): 1 for
// the pixels that keep sampling, 0 for those that stop (a 0 stays 0: a stopped pixel never takes
// later sample indices), and returns how many keep sampling. Runs in the caller's TBB arena.
size_t update_sampling_mask(const Film& film, float threshold, std::vector<uint8_t>& mask);

}  // namespace gdpt
