// Deterministic row-parallel loops for the reconstruction passes.
//
// Images are cut into fixed chunks of `kRowsPerChunk` rows whatever the thread count, and every
// reduction is summed chunk by chunk in chunk order, so a solve gives bit-identical results on 1
// or 32 threads. Loops run in the caller's TBB arena (reconstruct() sets one up from
// ReconstructionSettings::threads).
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace gdpt::detail {

// Flush-to-zero and denormals-are-zero for the duration of one chunk. CG residuals and IRLS
// directions decay into the float denormal range late in a solve, and denormal arithmetic is
// far slower on x86 (docs/reconstruct.md, "Benchmark").
// Values below 1e-38 are irrelevant to an image. MXCSR is per thread, so it is set per chunk and
// restored, leaving the caller's threads as they were.
class FlushDenormals {
 public:
#if defined(__SSE__)
  FlushDenormals() : saved_(_mm_getcsr()) {
    _mm_setcsr(saved_ | 0x8040u);
  }  // FTZ | DAZ
  ~FlushDenormals() {
    _mm_setcsr(saved_);
  }

 private:
  unsigned saved_;
#endif
};

// 8 rows of a 1080p RGB float image are ~180 KB per array: big enough to amortise scheduling,
// small enough that the five arrays a stencil pass touches stay in L2.
inline constexpr int kRowsPerChunk = 8;

inline int chunk_count(int height) {
  return (height + kRowsPerChunk - 1) / kRowsPerChunk;
}

// body(y_begin, y_end) for every chunk, in parallel.
template <class Body>
void parallel_rows(int height, const Body& body) {
  const int chunks = chunk_count(height);
  tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& r) {
    const FlushDenormals ftz;
    for (int c = r.begin(); c != r.end(); ++c)
      body(c * kRowsPerChunk, std::min(height, (c + 1) * kRowsPerChunk));
  });
}

// Deterministic reduction of N doubles: body(y_begin, y_end, std::array<double, N>& sums) adds
// its chunk's contribution to `sums` (zeroed per chunk); the chunk sums are then added in order.
// The body accumulates into a local array, stored once per chunk: neighbouring entries of
// `partial` share cache lines and belong to chunks of different threads (false sharing).
template <int N, class Body>
std::array<double, N> parallel_rows_sum(int height, const Body& body) {
  const int chunks = chunk_count(height);
  std::vector<std::array<double, N>> partial(chunks);
  tbb::parallel_for(tbb::blocked_range<int>(0, chunks, 1), [&](const tbb::blocked_range<int>& r) {
    const FlushDenormals ftz;
    for (int c = r.begin(); c != r.end(); ++c) {
      std::array<double, N> sums{};
      body(c * kRowsPerChunk, std::min(height, (c + 1) * kRowsPerChunk), sums);
      partial[c] = sums;
    }
  });
  std::array<double, N> total{};
  for (const auto& p : partial)
    for (int i = 0; i < N; ++i) total[i] += p[i];
  return total;
}

}  // namespace gdpt::detail
