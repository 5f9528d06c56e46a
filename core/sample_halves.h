// The Feature reconstruction's two halves of a pixel's samples are its even and odd GLOBAL sample
// indices, so that renders of disjoint sample ranges (RenderSettings::sample_offset) merge into
// the halves of the render of all their samples.
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

}  // namespace gdpt
