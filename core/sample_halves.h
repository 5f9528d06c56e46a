// The Feature reconstruction's two halves of a pixel's samples are its even and odd GLOBAL sample
// indices, so that renders of disjoint sample ranges (RenderSettings::sample_offset) merge into
// the halves of the render of all their samples. Both halves draw from the one scrambled Sobol
// sequence a render without them uses, A its first `split` points and B the next `split`: with
// split = ceil(N / 2) the N samples of the frame are its first N points, so the image of all
// samples is the plain render's, bit for bit, and each half is a stratified segment of its own.
// (Halves from two independently scrambled sequences cost the image of all samples its
// stratification, 23% relMSE on the benchmark's instances scene; halves split by parity of one
// sequence fill complementary strata and differ far more than their noise: docs/reconstruct.md.)
#pragma once

#include <cstdint>

namespace gdpt {

// Whether the sample of global index `sample_index` is in half A (even indices; else half B).
inline bool in_half_a(uint32_t sample_index) {
  return sample_index % 2 == 0;
}

// Of n samples with indices offset, offset + 1, ..., how many have an even index.
inline uint32_t even_sample_count(uint32_t offset, uint32_t n) {
  return uint32_t((uint64_t(offset) + n + 1) / 2 - (uint64_t(offset) + 1) / 2);
}

// The halves' split for a frame of `total` samples: ceil(total / 2) pairs, at least 1.
inline uint32_t half_split(uint64_t total) {
  return uint32_t(total > 1 ? (total + 1) / 2 : 1);
}

// The Sobol index global sample `sample_index` draws its numbers from, halves split at `split`
// pairs: pair p = sample_index / 2 of half h (0: A) takes index (2 (p / split) + h) split +
// p % split. Past split pairs (a time-limited render that ran longer than its estimate) the
// halves go on in further segments of `split` points, A's before B's, so the samples still cover
// a prefix of the sequence whenever a segment is full.
inline uint32_t half_sequence_index(uint32_t sample_index, uint32_t split) {
  const uint64_t pair = sample_index / 2, h = sample_index % 2;
  return uint32_t((2 * (pair / split) + h) * split + pair % split);
}

}  // namespace gdpt
