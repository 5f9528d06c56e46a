#include "reconstruct/feature_bilateral.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <stdexcept>

#include <tbb/enumerable_thread_specific.h>

#include "reconstruct/candidate_selection.h"
#include "reconstruct/parallel.h"

// More builds of the filters' pixel loops, for CPUs with AVX2 or AVX-512, where the tree is built
// without them (GCC and Clang on x86-64). This file is compiled with -ffp-contract=off: no build
// fuses a multiply and an add, so all round alike.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__AVX2__)
#define GDPT_FILTER_AVX2 1
#else
#define GDPT_FILTER_AVX2 0
#endif
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__AVX512F__)
#define GDPT_FILTER_AVX512 1
#else
#define GDPT_FILTER_AVX512 0
#endif

namespace gdpt::detail {

namespace {

inline constexpr int kMaxImages = 3;
inline constexpr int kMaxRanges = kColourToleranceCount;
inline constexpr int kMaxWindows = int(std::size(kWindows));
// Feature distances beyond this give weights below 1e-5 of the centre's: skipped.
inline constexpr float kNegligibleDistance = 23.f;
// Keeps the relative colour tolerance finite on black pixels.
inline constexpr float kRangeFloor = 1e-3f;
// Weight of the pixels' noise in the colour distances: the variances are the primal halves', and
// the gradient-domain solutions the filters see are less noisy (on the benchmark renders 0.5, 0.7,
// 1 and 2 gave 2.763, 2.760, 2.743 and 2.719x L1; at 0.7 no cell is 2% worse than without noise).
inline constexpr float kNoiseWeight = 0.7f;
// Pixels of a row filtered together: their sums (every window, tolerance and image: 37 KB) stay
// near while every tap adds to them; 64 rather than 32 halves the per-tap setup of the wide loops
// (7% less CPU here; 96 and 128 no better).
inline constexpr int kBlock = 64;

// v where `keep`, else 0: a select by bit mask, so the loops over pixels stay branch-free.
inline float masked(bool keep, float v) {
  return std::bit_cast<float>(std::bit_cast<uint32_t>(v) & (0u - uint32_t(keep)));
}

// e^x for x <= 0 (0 below -87, NaN for NaN) within 2 ulp of std::exp, in plain arithmetic so that
// the loops over pixels vectorise (std::exp is a libm call per value).
inline float exp_nonpositive(float x) {
  constexpr float kLow = -87.f, kShift = 12582912.f;  // 1.5 * 2^23: adding it rounds to integer
  const float xc = x < kLow ? kLow : x;
  const float t = xc * 1.44269504f + kShift;
  const float n = t - kShift;
  const float r = (xc - n * 0.693359375f) - n * -2.12194440e-4f;  // x - n ln 2 in two parts
  float p = 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  p = p * r * r + r + 1.f;
  const int32_t e = std::bit_cast<int32_t>(t) - std::bit_cast<int32_t>(kShift);
  const float scale = std::bit_cast<float>((e + 127) << 23);
  return masked(!(x < kLow), p * scale);
}

// The identity, except that a missing pixel takes the mean of its valid 3x3 neighbours (its
// value is 0 in the masked images, which no error estimate can see: it has no halves).
void identity_filter(const FeatureBuffers& fb, const float* const* images, float* const* out,
                     int count, const float* multiply) {
  const int W = fb.width, H = fb.height;
  parallel_rows(H, [&](int y0, int y1) {
    const size_t i0 = 3 * size_t(y0) * W;
    for (int k = 0; k < count; ++k)
      std::memcpy(out[k] + i0, images[k] + i0, sizeof(float) * 3 * size_t(y1 - y0) * W);
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < W; ++x) {
        const size_t i = size_t(y) * W + x;
        if (fb.valid[i] & kImagesValid) continue;
        for (int k = 0; k < count; ++k) {
          float sum[3] = {0.f, 0.f, 0.f}, n = 0.f;
          for (int yy = std::max(0, y - 1); yy <= std::min(H - 1, y + 1); ++yy)
            for (int xx = std::max(0, x - 1); xx <= std::min(W - 1, x + 1); ++xx) {
              const size_t j = size_t(yy) * W + xx;
              if (!(fb.valid[j] & kImagesValid)) continue;
              for (int c = 0; c < 3; ++c) sum[c] += images[k][3 * j + c];
              n += 1.f;
            }
          for (int c = 0; c < 3; ++c) out[k][3 * i + c] = n > 0.f ? sum[c] / n : 0.f;
        }
      }
    if (multiply)
      for (int k = 0; k < count; ++k)
        for (size_t i = i0; i < 3 * size_t(y1) * W; ++i) out[k][i] *= multiply[i];
  });
}

// One filter call's inputs and outputs: several windows filtered in one pass over their taps.
struct FilterJob {
  const FeatureBuffers& fb;
  int windows;
  const BilateralWindow* window;
  int reach;                // the largest radius
  const float* inv_range2;  // per colour tolerance; 0: none
  // Per colour tolerance: the one 4x wider whose colour weight, to the 16th power, is this one's
  // (four squarings instead of an exponential), or -1.
  const int* squared_from;
  int ranges;
  const float* const* images;
  int count;
  float* const* out;      // [(window * ranges + tolerance) * count + image]; null: not written
  const float* multiply;  // RGB factor of every output, or null
  // [window * ranges + tolerance]: the error estimates of images 0 and 1 (the halves), or null.
  const CandidateEstimates* estimates;
  const float* weight;  // RGB weights of the relative estimate, or null
  // Per image: each pixel's noise (variance summed over RGB), widening its colour distances; or
  // null: the colour tolerances alone.
  const float* const* noise;
};

// The rows [y0 - reach, y1 + reach) of a chunk, clipped to the image, as planes: the images'
// channels and the validity bits, so that the loops over pixels read contiguous floats.
struct ChunkPlanes {
  int first_row = 0, width = 0;
  FreshHugeVector<float> colour;   // (image * 3 + channel) planes
  FreshHugeVector<int32_t> valid;  // FeatureValidity bits
  FreshHugeVector<float> noise;    // per image, with job.noise
  size_t plane = 0;                // floats per plane
  const float* channel(int k, int c, int y) const {
    return colour.data() + size_t(3 * k + c) * plane + size_t(y - first_row) * width;
  }
  const int32_t* valid_row(int y) const { return valid.data() + size_t(y - first_row) * width; }
  const float* noise_row(int k, int y) const {
    return noise.data() + size_t(k) * plane + size_t(y - first_row) * width;
  }
};

// Fills `p` (a thread's scratch, reused chunk after chunk: every element read is written here).
void fill_chunk_planes(const FilterJob& job, int y0, int y1, ChunkPlanes& p) {
  const int W = job.fb.width, H = job.fb.height;
  p.first_row = std::max(0, y0 - job.reach);
  const int last = std::min(H, y1 + job.reach);
  p.width = W;
  p.plane = size_t(last - p.first_row) * W;
  p.colour.resize(3 * job.count * p.plane);
  p.valid.resize(p.plane);
  const size_t base = size_t(p.first_row) * W;
  for (size_t i = 0; i < p.plane; ++i) p.valid[i] = job.fb.valid[base + i];
  for (int k = 0; k < job.count; ++k)
    for (int c = 0; c < 3; ++c) {
      float* d = p.colour.data() + size_t(3 * k + c) * p.plane;
      const float* s = job.images[k] + 3 * base + c;
      for (size_t i = 0; i < p.plane; ++i) d[i] = s[3 * i];
    }
  if (!job.noise) return;
  p.noise.resize(job.count * p.plane);
  for (int k = 0; k < job.count; ++k)
    std::copy(job.noise[k] + base, job.noise[k] + base + p.plane, p.noise.begin() + k * p.plane);
}

// Per pixel of a block: the sums of weighted colours and weights, per window, tolerance, image.
struct BlockSums {
  float num[kMaxWindows][kMaxRanges][kMaxImages][3][kBlock];
  float den[kMaxWindows][kMaxRanges][kMaxImages][kBlock];
};

// Feature weights of the tap (dx, dy) for the pixels [x0, x1) of row y (0 for a tap left out).
// wf[x - xb] for x in [x0, x1).
void feature_weights(const FilterJob& job, const ChunkPlanes& p, int y, int dy, int dx, int x0,
                     int x1, int xb, float* wf) {
  const FeatureBuffers& fb = job.fb;
  const size_t n = size_t(fb.width) * fb.height;
  const size_t i0 = size_t(y) * fb.width, j0 = size_t(y + dy) * fb.width;
  const float* f = fb.feature.data();
  const float* v = fb.feature_var.data();
  const int32_t* vi = p.valid_row(y);
  const int32_t* vj = p.valid_row(y + dy);
  const bool centre_tap = dx == 0 && dy == 0;
  const float ta = kAlbedoTolerance * kAlbedoTolerance, tn = kNormalTolerance * kNormalTolerance;
  for (int x = x0; x < x1; ++x) {
    const size_t i = i0 + x, j = j0 + x + dx;
    float d = 0.f;
    for (int c = 0; c < 3; ++c) {
      const size_t ca = c * n, cn = (3 + c) * n;
      const float da = f[ca + i] - f[ca + j], dn = f[cn + i] - f[cn + j];
      d += da * da / (ta + v[ca + i] + v[ca + j]) + dn * dn / (tn + v[cn + i] + v[cn + j]);
    }
    const size_t cd = 6 * n;
    const float td = kDepthTolerance * f[cd + i], dd = f[cd + i] - f[cd + j];
    d += dd * dd / (td * td + v[cd + i] + v[cd + j] + 1e-12f);
    const bool centre_features = vi[x] & kFeaturesValid;
    // A centre without features weighs its neighbours by colour alone, so only itself.
    const bool near = bool(vj[x + dx] & kFeaturesValid) & (d <= kNegligibleDistance);
    const bool keep = bool(vj[x + dx] & kImagesValid) & (centre_features ? near : centre_tap);
    wf[x - xb] = masked(keep, exp_nonpositive(-0.5f * (centre_features ? d : 0.f)));
  }
}

// Adds one tap's colours q (offset by dx) with weights wf (times `colour` unless null) to sums.
inline void accumulate(const float* wf, const float* colour, const float* const* q, int dx, int x0,
                       int x1, int xb, float* n0, float* n1, float* n2, float* den) {
  if (colour) {
    for (int x = x0; x < x1; ++x) {
      const float a = wf[x - xb], w = masked(a > 0.f, a * colour[x - xb]);
      n0[x - xb] += w * q[0][x + dx];
      n1[x - xb] += w * q[1][x + dx];
      n2[x - xb] += w * q[2][x + dx];
      den[x - xb] += w;
    }
  } else {
    for (int x = x0; x < x1; ++x) {
      const float w = wf[x - xb];
      n0[x - xb] += w * q[0][x + dx];
      n1[x - xb] += w * q[1][x + dx];
      n2[x - xb] += w * q[2][x + dx];
      den[x - xb] += w;
    }
  }
}

// Colour weights from the relative distances dc (squared difference over 3 lum^2 of the centre).
void tolerant_colour_weights(const FilterJob& job, int x0, int x1, int xb, const float* dc,
                             float (*colour)[kBlock]) {
  for (int t = 0; t < job.ranges; ++t) {
    const float inv = job.inv_range2[t];
    if (inv > 0.f && job.squared_from[t] < 0)
      for (int x = x0; x < x1; ++x) colour[t][x - xb] = exp_nonpositive(-0.5f * dc[x - xb] * inv);
  }
  for (int t = 0; t < job.ranges; ++t) {
    if (job.squared_from[t] < 0) continue;
    const float* from = colour[job.squared_from[t]];
    for (int x = x0; x < x1; ++x) {
      const float e2 = from[x - xb] * from[x - xb], e4 = e2 * e2, e8 = e4 * e4;
      colour[t][x - xb] = e8 * e8;
    }
  }
}

// Colour weights whose distance is the squared difference over the tolerance's share of the
// centre's brightness plus both pixels' noise: a difference the noise explains is no edge.
// dc = d2 s, s = 1 / (3 lum^2) (0: no colour test): d2 / (3 lum^2 tol^2 + w noise).
void noisy_colour_weights(const FilterJob& job, const ChunkPlanes& p, int k, int y, int dy, int dx,
                          int x0, int x1, int xb, const float* scale, const float* dc,
                          float (*colour)[kBlock]) {
  const float *nc = p.noise_row(k, y), *nq = p.noise_row(k, y + dy);
  // The factors every tolerance shares, once per tap (the same roundings as per tolerance).
  float noise[kBlock], half[kBlock];
  for (int x = x0; x < x1; ++x) {
    noise[x - xb] = kNoiseWeight * (nc[x] + nq[x + dx]) * scale[kBlock * k + x - xb];
    half[x - xb] = -0.5f * dc[x - xb];
  }
  int t[kMaxRanges], active = 0;
  for (int u = 0; u < job.ranges; ++u)
    if (job.inv_range2[u] > 0.f) t[active++] = u;
  int a = 0;
  for (; a + 1 < active; a += 2) {  // two tolerances per loop: two independent chains
    const float i0 = job.inv_range2[t[a]], i1 = job.inv_range2[t[a + 1]];
    float *c0 = colour[t[a]], *c1 = colour[t[a + 1]];
    for (int x = x0 - xb; x < x1 - xb; ++x) {
      c0[x] = exp_nonpositive(half[x] * i0 / (1.f + noise[x] * i0));
      c1[x] = exp_nonpositive(half[x] * i1 / (1.f + noise[x] * i1));
    }
  }
  for (; a < active; ++a) {
    const float inv = job.inv_range2[t[a]];
    float* c = colour[t[a]];
    for (int x = x0 - xb; x < x1 - xb; ++x)
      c[x] = exp_nonpositive(half[x] * inv / (1.f + noise[x] * inv));
  }
}

// Adds the tap (dx, dy) to the sums of the pixels [x0, x1) of row y (block starting at xb) of the
// windows in `windows` (bit w: window w): its weights are computed once for all of them.
void add_tap(const FilterJob& job, const ChunkPlanes& p, int y, int dy, int dx, int x0, int x1,
             int xb, const float* scale, unsigned windows, BlockSums& s) {
  float wf[kBlock], dc[kBlock], colour[kMaxRanges][kBlock];
  feature_weights(job, p, y, dy, dx, x0, x1, xb, wf);
  for (int k = 0; k < job.count; ++k) {
    const float *p0 = p.channel(k, 0, y), *p1 = p.channel(k, 1, y), *p2 = p.channel(k, 2, y);
    // The tap's colours, offset by dx (inside the row for x in [x0, x1)).
    const float* q[3] = {p.channel(k, 0, y + dy), p.channel(k, 1, y + dy), p.channel(k, 2, y + dy)};
    for (int x = x0; x < x1; ++x) {
      const float d0 = q[0][x + dx] - p0[x], d1 = q[1][x + dx] - p1[x], d2 = q[2][x + dx] - p2[x];
      dc[x - xb] = (d0 * d0 + d1 * d1 + d2 * d2) * scale[kBlock * k + x - xb];
    }
    if (job.noise) {
      noisy_colour_weights(job, p, k, y, dy, dx, x0, x1, xb, scale, dc, colour);
    } else {
      tolerant_colour_weights(job, x0, x1, xb, dc, colour);
    }
    for (int w = 0; w < job.windows; ++w) {
      if (!(windows >> w & 1u)) continue;
      for (int t = 0; t < job.ranges; ++t)
        accumulate(wf, job.inv_range2[t] > 0.f ? colour[t] : nullptr, q, dx, x0, x1, xb,
                   s.num[w][t][k][0], s.num[w][t][k][1], s.num[w][t][k][2], s.den[w][t][k]);
    }
  }
}

// The windows (bits) with a tap at (dx, dy).
unsigned windows_with_tap(const FilterJob& job, int dx, int dy) {
  unsigned m = 0;
  for (int w = 0; w < job.windows; ++w) {
    const BilateralWindow& win = job.window[w];
    if (std::abs(dx) <= win.radius && std::abs(dy) <= win.radius && dx % win.stride == 0 &&
        dy % win.stride == 0)
      m |= 1u << w;
  }
  return m;
}

// Writes the pixels [xb, xe) of row y from the sums: the outputs asked for and the estimates.
void write_block(const FilterJob& job, int y, int xb, int xe, const BlockSums& s) {
  const size_t row = size_t(y) * job.fb.width;
  const float* m = job.multiply ? job.multiply + 3 * row : nullptr;
  for (int w = 0; w < job.windows; ++w)
    for (int t = 0; t < job.ranges; ++t) {
      float halves[2][3 * kBlock];
      for (int k = 0; k < job.count; ++k) {
        float* o = job.out[(w * job.ranges + t) * job.count + k];
        const bool estimated = job.estimates && k < 2;
        if (!o && !estimated) continue;
        const float* in = job.images[k] + 3 * row;
        for (int x = xb; x < xe; ++x) {
          const float den = s.den[w][t][k][x - xb];
          for (int c = 0; c < 3; ++c) {
            const float v0 = den > 0.f ? s.num[w][t][k][c][x - xb] / den : in[3 * x + c];
            const float v = m ? v0 * m[3 * x + c] : v0;
            if (o) o[3 * (row + x) + c] = v;
            if (estimated) halves[k][3 * (x - xb) + c] = v;
          }
        }
      }
      if (!job.estimates) continue;
      const CandidateEstimates& e = job.estimates[w * job.ranges + t];
      for (int x = xb; x < xe; ++x)
        pixel_error(job.fb, row + x, halves[0] + 3 * (x - xb), halves[1] + 3 * (x - xb), job.weight,
                    e.error, e.relative);
    }
}

// Filters the pixels [xb, xe) of row y: every tap of every window, in the order of the rows.
void filter_block(const FilterJob& job, const ChunkPlanes& p, int y, int xb, int xe, BlockSums& s) {
  const int W = job.fb.width, H = job.fb.height, r = job.reach;
  float scale[kMaxImages * kBlock];
  const int32_t* vi = p.valid_row(y);
  for (int k = 0; k < job.count; ++k) {
    const float *p0 = p.channel(k, 0, y), *p1 = p.channel(k, 1, y), *p2 = p.channel(k, 2, y);
    for (int x = xb; x < xe; ++x) {
      const float lum = std::max(0.f, (p0[x] + p1[x] + p2[x]) * (1.f / 3.f)) + kRangeFloor;
      // A missing centre has no colour to compare with: features alone weigh its neighbours.
      scale[kBlock * k + x - xb] = (vi[x] & kImagesValid) ? 1.f / (3.f * lum * lum) : 0.f;
    }
  }
  std::memset(&s.num, 0, sizeof(s.num[0]) * job.windows);
  std::memset(&s.den, 0, sizeof(s.den[0]) * job.windows);
  // Each window sees its own taps in the order of its rows, as if filtered alone.
  for (int dy = -r; dy <= r; ++dy) {
    if (y + dy < 0 || y + dy >= H) continue;
    for (int dx = -r; dx <= r; ++dx) {
      const unsigned windows = windows_with_tap(job, dx, dy);
      const int x0 = std::max(xb, -dx), x1 = std::min(xe, W - dx);
      if (windows && x0 < x1) add_tap(job, p, y, dy, dx, x0, x1, xb, scale, windows, s);
    }
  }
  write_block(job, y, xb, xe, s);
}

// The inverse squared tolerances and which tolerances' weights are another's to the 16th power.
void range_setup(const float* ranges, int range_count, float* inv_range2, int* squared_from) {
  for (int t = 0; t < range_count; ++t)
    inv_range2[t] = ranges[t] > 0.f ? 1.f / (ranges[t] * ranges[t]) : 0.f;
  for (int t = 0; t < range_count; ++t) {
    squared_from[t] = -1;
    for (int u = 0; u < range_count; ++u)
      if (inv_range2[u] > 0.f &&
          std::abs(inv_range2[t] - 16.f * inv_range2[u]) <= 1e-6f * inv_range2[t])
        squared_from[t] = u;
  }
  for (int t = 0; t < range_count; ++t)  // from a weight computed directly only
    if (squared_from[t] >= 0 && squared_from[squared_from[t]] >= 0) squared_from[t] = -1;
}

// The pixels of rows [y0, y1), inlined whole into each build of filter_rows below.
inline void filter_rows_inline(const FilterJob& job, const ChunkPlanes& planes, int y0, int y1) {
  BlockSums sums;
  for (int y = y0; y < y1; ++y)
    for (int xb = 0; xb < job.fb.width; xb += kBlock)
      filter_block(job, planes, y, xb, std::min(job.fb.width, xb + kBlock), sums);
}

__attribute__((flatten)) void filter_rows_baseline(const FilterJob& job, const ChunkPlanes& planes,
                                                   int y0, int y1) {
  filter_rows_inline(job, planes, y0, y1);
}

#if GDPT_FILTER_AVX2
// 8 floats per instruction instead of 4.
__attribute__((target("avx2"), flatten)) void filter_rows_avx2(const FilterJob& job,
                                                               const ChunkPlanes& planes, int y0,
                                                               int y1) {
  filter_rows_inline(job, planes, y0, y1);
}
#endif

#if GDPT_FILTER_AVX512
// 16 floats per instruction (the 64-pixel blocks' loops, 12% faster than AVX2 on the Zen 5 here).
__attribute__((target("avx512f,avx512vl,avx512bw,avx512dq"), flatten)) void filter_rows_avx512(
    const FilterJob& job, const ChunkPlanes& planes, int y0, int y1) {
  filter_rows_inline(job, planes, y0, y1);
}
#endif

std::atomic<int> build_limit{int(FilterBuild::Avx512)};

void filter_rows(const FilterJob& job, const ChunkPlanes& planes, int y0, int y1) {
  [[maybe_unused]] const int limit = build_limit.load(std::memory_order_relaxed);
#if GDPT_FILTER_AVX512
  if (limit >= int(FilterBuild::Avx512) && filter_build_available(FilterBuild::Avx512))
    return filter_rows_avx512(job, planes, y0, y1);
#endif
#if GDPT_FILTER_AVX2
  if (limit >= int(FilterBuild::Avx2) && filter_build_available(FilterBuild::Avx2))
    return filter_rows_avx2(job, planes, y0, y1);
#endif
  filter_rows_baseline(job, planes, y0, y1);
}

void run(const FilterJob& job) {
  tbb::enumerable_thread_specific<ChunkPlanes> scratch;
  parallel_rows(job.fb.height, [&](int y0, int y1) {
    ChunkPlanes& planes = scratch.local();
    fill_chunk_planes(job, y0, y1, planes);
    filter_rows(job, planes, y0, y1);
  });
}

}  // namespace

bool filter_build_available(FilterBuild build) {
#if GDPT_FILTER_AVX2
  static const bool avx2 = __builtin_cpu_supports("avx2");
  if (build == FilterBuild::Avx2) return avx2;
#endif
#if GDPT_FILTER_AVX512
  static const bool avx512 =
      __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
  if (build == FilterBuild::Avx512) return avx512;
#endif
  return build == FilterBuild::Baseline;
}

void limit_filter_build(FilterBuild highest) {
  build_limit.store(int(highest), std::memory_order_relaxed);
}

std::vector<BilateralCandidate> default_bilateral_candidates() {
  std::vector<BilateralCandidate> c = {{{0, 1}, 0.f}};
  for (const BilateralWindow& w : kWindows)
    for (float range : kColourTolerances) c.push_back({w, range});
  return c;
}

void bilateral_filter(const FeatureBuffers& fb, const BilateralWindow& window, const float* ranges,
                      int range_count, const float* const* images, int count, float* const* out,
                      const float* multiply) {
  if (window.radius == 0) {
    for (int t = 0; t < range_count; ++t)
      identity_filter(fb, images, out + t * count, count, multiply);
    return;
  }
  float inv_range2[kMaxRanges];
  int squared_from[kMaxRanges];
  range_setup(ranges, range_count, inv_range2, squared_from);
  run(FilterJob{fb, 1, &window, window.radius, inv_range2, squared_from, range_count, images, count,
                out, multiply, nullptr, nullptr, nullptr});
}

void bilateral_candidates(const FeatureBuffers& fb, const BilateralWindow* windows,
                          int window_count, const float* ranges, int range_count,
                          const float* const* images, float* const* out,
                          const CandidateEstimates* estimates, const float* weight,
                          const float* multiply, const float* const* noise) {
  if (window_count > kMaxWindows)
    throw std::invalid_argument("bilateral_candidates: too many windows");
  float inv_range2[kMaxRanges];
  int squared_from[kMaxRanges];
  range_setup(ranges, range_count, inv_range2, squared_from);
  int reach = 0;
  for (int w = 0; w < window_count; ++w) {
    if (windows[w].radius < 1) throw std::invalid_argument("bilateral_candidates: radius 0");
    reach = std::max(reach, windows[w].radius);
  }
  // Outputs per (window, tolerance): the halves are not kept, the image of all samples is.
  std::vector<float*> outs(size_t(window_count) * range_count * 3, nullptr);
  for (size_t c = 0; c < size_t(window_count) * range_count; ++c) outs[3 * c + 2] = out[c];
  run(FilterJob{fb, window_count, windows, reach, inv_range2, squared_from, range_count, images, 3,
                outs.data(), multiply, estimates, weight, noise});
}

}  // namespace gdpt::detail
