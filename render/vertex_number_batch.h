// The Samplers of a row segment's pixels, and their paths' random numbers for one sample index
// computed together: each pixel's camera jitter and, for its first vertices, the light point and
// BSDF direction (Sampler::vertex_numbers), exactly the values the pixel's Sampler returns.
//
// Drawn one path at a time, each vertex's numbers are a ~70-cycle chain of dependent multiplies
// (hash, index shuffle, Sobol matrix, Owen scramble); a timing-only variant with an LCG in their
// place rendered measurably faster (docs/performance.md). Here the hashes, which depend on the
// pixel and the dimension but not on the sample index, are computed once per segment (prepare), and
// each sample's numbers (fill) run eight pixels per AVX2 register: the same integer steps, so the
// same values, at a fraction of the cost. Numbers of vertices a path never reaches are wasted,
// hence only the first kMaxVertices; later vertices draw from the Sampler.
//
// Without AVX2 (the x86-64 baseline build) no vertex is batched (vertices() is 0: every vertex
// draws from the Sampler, at no extra cost there) and fill() takes each pixel's camera jitter from
// its Sampler.
#pragma once

#include <cstdint>
#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "render/sampler.h"

namespace gdpt {

class VertexNumberBatch {
 public:
  static constexpr int kMaxPixels = 16;  // a camera-ray stream (PathTracer::render_tile)
#if defined(__AVX2__)
  static constexpr int kMaxVertices = 4;  // vertices 0-3: two 6D points (Sampler)
#else
  static constexpr int kMaxVertices = 0;
#endif

  // Pixels (x0 + j, y), j < count, of a render with `seed` (starts their Samplers); numbers for
  // vertices below `vertices` (clamped to kMaxVertices), light points only when `lights`.
  void prepare(uint32_t seed, int x0, int y, int count, int vertices, bool lights);

  // Every prepared pixel's Sampler at sample `index`, and its numbers.
  void fill(uint32_t index);

  const Sampler& sampler(int j) const {
    return samplers_[j];
  }

  int vertices() const {
    return vertices_;
  }
  Vec2f camera(int j) const {
    return {cam_[0][j], cam_[1][j]};
  }
  // Pixel j's numbers of vertex v: batched below vertices(), else from its Sampler.
  Sampler::VertexNumbers vertex_numbers(int j, int v) const {
#if defined(__AVX2__)
    if (v < vertices_) {
      Sampler::VertexNumbers u;
      u.light = {light_[v][0][j], light_[v][1][j]};
      u.dir = {dir_[v][0][j], dir_[v][1][j]};
      return u;
    }
#endif
    return samplers_[j].vertex_numbers(v, lights_);
  }

 private:
  int count_ = 0, vertices_ = 0;
  bool lights_ = false;
  Sampler samplers_[kMaxPixels];
  alignas(32) float cam_[2][kMaxPixels] = {};  // [component][pixel]
#if defined(__AVX2__)
  // Per pixel (lane j), the seeds of each 2D dimension: index shuffle (idx) and the x and y
  // coordinate scrambles, from that dimension's hash as Sampler::get2d derives them.
  struct PairSeeds {
    alignas(32) uint32_t idx[kMaxPixels];
    alignas(32) uint32_t x[kMaxPixels];
    alignas(32) uint32_t y[kMaxPixels];
  };
  static void set_seeds(PairSeeds& s, int j, uint64_t pixel_key, uint32_t dim) {
    const uint64_t h = sampler_detail::mix64(pixel_key ^ dim);
    s.idx[j] = uint32_t(h);
    s.x[j] = sampler_detail::pair_seed_x(h);
    s.y[j] = sampler_detail::pair_seed_y(h);
  }
  PairSeeds cam_seeds_;
  PairSeeds dir_seeds_[kMaxVertices], light_seeds_[kMaxVertices];
  alignas(32) float dir_[kMaxVertices][2][kMaxPixels] = {};    // [vertex][component][pixel]
  alignas(32) float light_[kMaxVertices][2][kMaxPixels] = {};  // zero without lights
#endif
};

inline void VertexNumberBatch::prepare(uint32_t seed, int x0, int y, int count, int vertices,
                                       bool lights) {
  count_ = count < kMaxPixels ? count : kMaxPixels;
  vertices_ = vertices < 0 ? 0 : vertices < kMaxVertices ? vertices : kMaxVertices;
  lights_ = lights;
  for (int j = 0; j < count_; ++j) samplers_[j].start(seed, x0 + j, y, 0);
#if defined(__AVX2__)
  for (int j = 0; j < kMaxPixels; ++j) {
    // Lanes past count repeat the last pixel: full registers, results unused.
    const int px = x0 + (j < count_ ? j : count_ - 1);
    const uint64_t key = Sampler::pixel_key(seed, px, y);
    set_seeds(cam_seeds_, j, key, Sampler::kDimCamera);
    for (int v = 0; v < vertices_; ++v) {
      // An odd vertex's index is its even predecessor's direction index (Sampler).
      set_seeds(dir_seeds_[v], j, key, Sampler::bounce_dim(v, Sampler::kBsdfDir));
      set_seeds(light_seeds_[v], j, key, Sampler::bounce_dim(v, Sampler::kLightPoint));
    }
  }
#endif
}

#if defined(__AVX2__)
namespace sampler_detail {

// reverse_bits() in eight lanes: reverse_bits4's tables in both halves.
inline __m256i reverse_bits8(__m256i x) {
  const auto both = [](const ShuffleTable& t) { return _mm256_broadcastsi128_si256(t.load()); };
  x = _mm256_shuffle_epi8(x, both(kByteSwap32));
  const __m256i nibble = _mm256_set1_epi8(0x0f);
  const __m256i lo = _mm256_and_si256(x, nibble);
  const __m256i hi = _mm256_and_si256(_mm256_srli_epi16(x, 4), nibble);
  return _mm256_or_si256(_mm256_shuffle_epi8(both(kReversedNibbleHigh), lo),
                         _mm256_shuffle_epi8(both(kReversedNibbleLow), hi));
}
// reverse_bits(lk_permutation(x, seed)) in eight lanes.
inline __m256i nested_scramble_reversed8(__m256i x, __m256i seed) {
  x = _mm256_add_epi32(x, seed);
  for (uint32_t m : kLkMultipliers)
    x = _mm256_xor_si256(x, _mm256_mullo_epi32(x, _mm256_set1_epi32(int(m))));
  return reverse_bits8(x);
}
// to_unit_float(reverse_bits(lk_permutation(r, seed))) in eight lanes.
inline __m256 scrambled8(__m256i r, __m256i seed) {
  const __m256i x = _mm256_srli_epi32(nested_scramble_reversed8(r, seed), 8);
  return _mm256_mul_ps(_mm256_cvtepi32_ps(x), _mm256_set1_ps(0x1p-24f));
}
// reversed_sobol_dim(dim, i) in eight lanes: the XOR of four byte-table gathers.
inline __m256i reversed_sobol_dim8(int dim, __m256i i) {
  const auto& t = kSobolTables.t[dim - 1];
  const __m256i byte = _mm256_set1_epi32(0xff);
  const auto gather = [](const uint32_t* table, __m256i index) {
    return _mm256_i32gather_epi32(reinterpret_cast<const int*>(table), index, 4);
  };
  const __m256i a = gather(t[0], _mm256_and_si256(i, byte));
  const __m256i b = gather(t[1], _mm256_and_si256(_mm256_srli_epi32(i, 8), byte));
  const __m256i c = gather(t[2], _mm256_and_si256(_mm256_srli_epi32(i, 16), byte));
  const __m256i d = gather(t[3], _mm256_srli_epi32(i, 24));
  return _mm256_xor_si256(_mm256_xor_si256(a, b), _mm256_xor_si256(c, d));
}

}  // namespace sampler_detail

inline void VertexNumberBatch::fill(uint32_t index) {
  using namespace sampler_detail;
  for (int j = 0; j < count_; ++j) samplers_[j].set_index(index);
  const __m256i ri = _mm256_set1_epi32(int(reverse_bits(index)));
  auto load = [](const uint32_t* p) {
    return _mm256_load_si256(reinterpret_cast<const __m256i*>(p));
  };
  for (int g = 0; g < count_; g += 8) {
    // Sampler::get2d: shuffled index i, then Sobol dimensions 0 (i itself, reversed) and 1.
    const auto pair = [&](const PairSeeds& s, __m256i i, __m256i ry, float* out_x, float* out_y) {
      _mm256_store_ps(out_x + g, scrambled8(i, load(s.x + g)));
      _mm256_store_ps(out_y + g, scrambled8(ry, load(s.y + g)));
    };
    const auto shuffled = [&](const PairSeeds& s) {
      return nested_scramble_reversed8(ri, load(s.idx + g));
    };
    const __m256i ic = shuffled(cam_seeds_);
    pair(cam_seeds_, ic, reversed_sobol_dim8(1, ic), cam_[0], cam_[1]);
    for (int v = 0; v < vertices_; v += 2) {
      // Even vertex: its direction and light point, each with its own index shuffle.
      const __m256i id = shuffled(dir_seeds_[v]);
      pair(dir_seeds_[v], id, reversed_sobol_dim8(1, id), dir_[v][0], dir_[v][1]);
      if (lights_) {
        const __m256i il = shuffled(light_seeds_[v]);
        pair(light_seeds_[v], il, reversed_sobol_dim8(1, il), light_[v][0], light_[v][1]);
      }
      if (v + 1 >= vertices_) break;
      // Odd vertex: Sobol dimensions 2-5 of the even vertex's direction index.
      pair(dir_seeds_[v + 1], reversed_sobol_dim8(2, id), reversed_sobol_dim8(3, id),
           dir_[v + 1][0], dir_[v + 1][1]);
      if (lights_)
        pair(light_seeds_[v + 1], reversed_sobol_dim8(4, id), reversed_sobol_dim8(5, id),
             light_[v + 1][0], light_[v + 1][1]);
    }
  }
}
#else
inline void VertexNumberBatch::fill(uint32_t index) {
  for (int j = 0; j < count_; ++j) {
    Sampler& s = samplers_[j];
    s.set_index(index);
    const Vec2f c = s.get2d(Sampler::kDimCamera);
    cam_[0][j] = c.x;
    cam_[1][j] = c.y;
  }
}
#endif

}  // namespace gdpt
