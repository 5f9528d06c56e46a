// Per-pixel deterministic low-discrepancy sampler: Owen-scrambled Sobol (0,2)-sequence pairs with
// per-pixel, per-dimension hash scrambling (Burley 2020, "Practical Hash-based Owen Scrambling").
//
// Every 2D dimension pair uses the first two Sobol dimensions (a (0,2)-sequence, stratified in
// every elementary interval), with the sample index shuffled by a nested uniform scramble and each
// coordinate Owen-scrambled, all seeded by hash(seed, pixel, dimension). Pairs are therefore
// decorrelated from each other ("padding") while each stays well stratified over a pixel's
// samples. A value is a pure function of (seed, pixel, sample index, dimension): the image does not
// depend on thread count or tile order.
//
// Vertices 2k and 2k + 1 share one 6D point instead of three padded pairs: the even vertex's BSDF
// direction is Sobol dimensions 0-1, the odd vertex's direction 2-3 and its light point 4-5, all
// with the even vertex's index shuffle and each coordinate Owen-scrambled. The first four
// dimensions form a (2,m,4)-net, all six a (3,m,6)-net. So a bounce's direction is stratified
// jointly with the next direction (diffuse interreflection; the floor -> glossy ball -> lamp
// caustic) and with the lamp sample taken where it lands. This lowers the error per sample
// against padded pairs
// (docs/performance.md).
//
// Where SSSE3 and SSE4.1 are available (the x86-64-v3 module build) the coordinate scrambles of
// a pair, or of a vertex's two pairs, run in SSE lanes (GDPT_SAMPLER_SIMD): the same integer
// steps, hence the same values (tests/integrator/test_sampler.cpp builds both).
//
// Dimension layout (Sampler::Dim): camera jitter 2D, lens 2D, then per bounce kDimsPerBounce
// dimensions: light select 1D, light position 2D, BSDF lobe 1D, BSDF direction 2D, Russian
// roulette 1D. G-PT uses the same layout for its base path; without depth of field it takes the
// camera jitter from a sampler keyed to no pixel, start(seed, -1, -1, index): one jitter per
// sample index for the whole image (gradient_path_tracer.cpp, CameraGrid).
#pragma once

#include <cstdint>
#if defined(__SSSE3__) && defined(__SSE4_1__)
#include <immintrin.h>
#define GDPT_SAMPLER_SIMD 1  // x86-64-v2 and up (the x86-64-v3 module build)
#endif

#include "core/vec.h"

namespace gdpt {

namespace sampler_detail {

// The byte swap is one instruction (bswap), replacing the two widest swap stages.
inline uint32_t reverse_bits(uint32_t x) {
  x = __builtin_bswap32(x);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
}

// 32-bit integer hash (a "lowbias32"-style finaliser): good avalanche, cheap.
inline uint32_t hash_u32(uint32_t x) {
  x ^= x >> 16;
  x *= 0x21f0aaadu;
  x ^= x >> 15;
  x *= 0x735a2d97u;
  x ^= x >> 15;
  return x;
}
// 64-bit finaliser (MurmurHash3's fmix64): full avalanche, so one call per dimension yields the
// three 32-bit scramble seeds of a 2D sample.
inline uint64_t mix64(uint64_t z) {
  z ^= z >> 33;
  z *= 0xff51afd7ed558ccdull;
  z ^= z >> 33;
  z *= 0xc4ceb9fe1a85ec53ull;
  z ^= z >> 33;
  return z;
}

// Laine-Karras style permutation in reversed-bit order: each bit is flipped depending only on the
// bits below it, which after the reversal below is exactly an Owen scramble (Burley 2020).
constexpr uint32_t kLkMultipliers[4] = {0x6c50b47cu, 0xb82f1e52u, 0xc7afe638u, 0x8d22f6e6u};
inline uint32_t lk_permutation(uint32_t x, uint32_t seed) {
  x += seed;
  for (uint32_t m : kLkMultipliers) x ^= x * m;
  return x;
}
inline uint32_t nested_uniform_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits(lk_permutation(reverse_bits(x), seed));
}

// Sobol dimension 1 (the second) by its definition: generator matrix with
// v_k = v_{k-1} ^ (v_{k-1} >> 1), i.e. the Pascal matrix mod 2 (the tests check the tables below
// against it).
inline uint32_t sobol_dim1_slow(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i != 0; i >>= 1, v ^= v >> 1)
    if (i & 1u) r ^= v;
  return r;
}

// Sobol dimensions 1 to 5, from Joe and Kuo's primitive polynomials and initial direction numbers
// (degree s, coefficient bits a, m_1..m_s): x+1 (1, 0, 1), x^2+x+1 (2, 1, 1 3), x^3+x+1
// (3, 1, 1 3 1), x^3+x^2+1 (3, 2, 1 1 1), x^4+x+1 (4, 1, 1 1 3 3); the rest by the standard
// recurrence.
inline uint32_t sobol_dim_slow(int dim, uint32_t i) {
  struct Poly {
    int s;
    uint32_t a, m[4];
  };
  static constexpr Poly kPolys[5] = {{1, 0, {1, 0, 0, 0}},
                                     {2, 1, {1, 3, 0, 0}},
                                     {3, 1, {1, 3, 1, 0}},
                                     {3, 2, {1, 1, 1, 0}},
                                     {4, 1, {1, 1, 3, 3}}};
  const Poly& p = kPolys[dim - 1];
  uint32_t m[32] = {};
  for (int k = 0; k < p.s; ++k) m[k] = p.m[k];
  for (int k = p.s; k < 32; ++k) {
    uint32_t v = m[k - p.s] ^ (m[k - p.s] << p.s);
    for (int j = 1; j < p.s; ++j)
      if ((p.a >> (p.s - 1 - j)) & 1u) v ^= m[k - j] << j;
    m[k] = v;
  }
  uint32_t r = 0;
  for (int k = 0; i != 0; i >>= 1, ++k)
    if (i & 1u) r ^= m[k] << (31 - k);
  return r;
}
// Each dimension is linear over GF(2), so it is the XOR of four per-byte tables. The tables store
// reverse_bits(sobol_dim(.)) (still linear): the Owen scramble that follows works on reversed
// bits, so this saves two reversals per 2D sample.
struct SobolTables {
  uint32_t t[5][4][256];  // dimensions 1..5
  SobolTables() {
    for (int d = 0; d < 5; ++d)
      for (uint32_t b = 0; b < 4; ++b)
        for (uint32_t v = 0; v < 256; ++v)
          t[d][b][v] = reverse_bits(sobol_dim_slow(d + 1, v << (8 * b)));
  }
};
inline const SobolTables kSobolTables;
inline uint32_t reversed_sobol_dim(int dim, uint32_t i) {  // dim in 1..5
  const auto& t = kSobolTables.t[dim - 1];
  return t[0][i & 0xffu] ^ t[1][(i >> 8) & 0xffu] ^ t[2][(i >> 16) & 0xffu] ^ t[3][i >> 24];
}
inline uint32_t sobol_dim1(uint32_t i) {
  return reverse_bits(reversed_sobol_dim(1, i));
}

// A 2D sample's coordinate scramble seeds from its hash h: the high half of h (x) and of a
// multiple of h (y).
inline uint32_t pair_seed_x(uint64_t h) {
  return uint32_t(h >> 32);
}
inline uint32_t pair_seed_y(uint64_t h) {
  return uint32_t((h * 0x9e3779b97f4a7c15ull) >> 32);
}

inline float to_unit_float(uint32_t x) {
  return float(x >> 8) * 0x1p-24f;  // in [0, 1), exactly representable
}

#if GDPT_SAMPLER_SIMD
// Byte-shuffle tables of reverse_bits() in SIMD lanes (here and in vertex_number_batch.h): the
// byte swap of each 32-bit lane, and rev4(n) << 4 and rev4(n) for each nibble value n.
struct alignas(16) ShuffleTable {
  uint8_t b[16];
  __m128i load() const { return _mm_load_si128(reinterpret_cast<const __m128i*>(b)); }
};
inline constexpr ShuffleTable kByteSwap32 = {
    {3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12}};
inline constexpr ShuffleTable kReversedNibbleHigh = {{0x00, 0x80, 0x40, 0xc0, 0x20, 0xa0, 0x60,
                                                      0xe0, 0x10, 0x90, 0x50, 0xd0, 0x30, 0xb0,
                                                      0x70, 0xf0}};
inline constexpr ShuffleTable kReversedNibbleLow = {
    {0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf}};

// reverse_bits() in four 32-bit lanes: a byte swap, then each byte reversed through two nibble
// tables.
inline __m128i reverse_bits4(__m128i x) {
  x = _mm_shuffle_epi8(x, kByteSwap32.load());
  const __m128i nibble = _mm_set1_epi8(0x0f);
  const __m128i lo = _mm_and_si128(x, nibble);
  const __m128i hi = _mm_and_si128(_mm_srli_epi16(x, 4), nibble);
  return _mm_or_si128(_mm_shuffle_epi8(kReversedNibbleHigh.load(), lo),
                      _mm_shuffle_epi8(kReversedNibbleLow.load(), hi));
}
// reverse_bits(lk_permutation(x, seed)) in four lanes.
inline __m128i nested_scramble_reversed4(__m128i x, __m128i seed) {
  x = _mm_add_epi32(x, seed);
  for (uint32_t m : kLkMultipliers)
    x = _mm_xor_si128(x, _mm_mullo_epi32(x, _mm_set1_epi32(int(m))));
  return reverse_bits4(x);
}
// to_unit_float(reverse_bits(lk_permutation(r, seed))) in four lanes, the same integer steps, so
// the same floats (conversions of values below 2^24 are exact).
inline __m128 scrambled4(__m128i r, __m128i seed) {
  const __m128i x = _mm_srli_epi32(nested_scramble_reversed4(r, seed), 8);
  return _mm_mul_ps(_mm_cvtepi32_ps(x), _mm_set1_ps(0x1p-24f));
}
#endif

}  // namespace sampler_detail

class Sampler {
 public:
  // Dimension layout shared by all integrators.
  enum Dim : uint32_t {
    kDimCamera = 0,      // 2D raster jitter
    kDimLens = 1,        // 2D lens position
    kDimFirstBounce = 2  // bounce b starts at kDimFirstBounce + b * kDimsPerBounce
  };
  enum BounceDim : uint32_t {
    kLightSelect = 0,  // 1D
    kLightPoint = 1,   // 2D
    kBsdfLobe = 2,     // 1D
    kBsdfDir = 3,      // 2D
    kRoulette = 4,     // 1D
    kDimsPerBounce = 5
  };

  // Starts sample `index` of pixel (x, y) for a render with `seed`.
  void start(uint32_t seed, int x, int y, uint32_t index) {
    pixel_key_ = pixel_key(seed, x, y);
    set_index(index);
  }
  // Another sample index of the same pixel.
  void set_index(uint32_t index) { reversed_index_ = sampler_detail::reverse_bits(index); }
  // The hash of (seed, pixel) that every dimension's hash starts from.
  static uint64_t pixel_key(uint32_t seed, int x, int y) {
    using namespace sampler_detail;
    return mix64((uint64_t(uint32_t(y)) << 32 | uint32_t(x)) ^
                 uint64_t(hash_u32(seed)) * 0x9e3779b97f4a7c15ull);
  }

  static uint32_t bounce_dim(int bounce, BounceDim d) {
    return kDimFirstBounce + uint32_t(bounce) * kDimsPerBounce + d;
  }

  // The 2D numbers a path vertex always uses: light point (when the scene has lights) and BSDF
  // direction. Integrators draw them before the vertex's ray is traced: each is a ~70-cycle
  // chain of dependent multiplies that would stall the shading code waiting for it, while
  // drawn early it runs alongside Embree's traversal. Dimensions are indexed: drawing one that
  // ends up unused changes no other value.
  struct VertexNumbers {
    Vec2f light, dir;
  };
  VertexNumbers vertex_numbers(int vertex, bool lights) const {
    if (vertex & 1) return odd_vertex_numbers(vertex, lights);
#if GDPT_SAMPLER_SIMD
    if (lights) return even_vertex_numbers(vertex);
#endif
    VertexNumbers u;
    if (lights) u.light = get2d(bounce_dim(vertex, kLightPoint));
    u.dir = get2d(bounce_dim(vertex, kBsdfDir));
    return u;
  }

  // Written with the reversals folded: nested_uniform_scramble(v, s) =
  // reverse_bits(lk_permutation(reverse_bits(v), s)), Sobol dimension 0 is reverse_bits(i) and
  // the tables of the other dimensions already return reversed bits.
  // The seeds of the index shuffle and of the coordinate scrambles all come from one 64-bit hash
  // of (pixel key, dim): its low and high halves, and for y the high half of a multiple of it.
  float get1d(uint32_t dim) const {
    using namespace sampler_detail;
    const uint64_t h = mix64(pixel_key_ ^ dim);
    return scrambled(shuffle(uint32_t(h)), uint32_t(h >> 32));
  }

  // Out of line: inlined into the PT kernel it cost more instructions than the call (+41 per
  // Cornell-box sample, register pressure in the path loop).
  [[gnu::noinline]] Vec2f get2d(uint32_t dim) const {
    const uint64_t h = sampler_detail::mix64(pixel_key_ ^ dim);
    const uint32_t i = shuffle(uint32_t(h));
    return scrambled_pair(i, sampler_detail::reversed_sobol_dim(1, i), h);
  }

#if GDPT_SAMPLER_SIMD
  // An even vertex's two pairs, get2d(light point) and get2d(direction), with their four
  // coordinate scrambles in one register. Out of line as get2d.
  [[gnu::noinline]] VertexNumbers even_vertex_numbers(int vertex) const {
    using namespace sampler_detail;
    const uint64_t hd = mix64(pixel_key_ ^ bounce_dim(vertex, kBsdfDir));
    const uint64_t hl = mix64(pixel_key_ ^ bounce_dim(vertex, kLightPoint));
    // shuffle() of both seeds in two lanes.
    const __m128i ids =
        nested_scramble_reversed4(_mm_set1_epi32(int(reversed_index_)),
                                  _mm_setr_epi32(int(uint32_t(hd)), int(uint32_t(hl)), 0, 0));
    const uint32_t id = uint32_t(_mm_cvtsi128_si32(ids)), il = uint32_t(_mm_extract_epi32(ids, 1));
    const PointPair p =
        scrambled_pairs(id, reversed_sobol_dim(1, id), hd, il, reversed_sobol_dim(1, il), hl);
    return {p.second, p.first};
  }
#endif

  // An odd vertex's numbers: Sobol dimensions 2-3 (direction) and 4-5 (light point) of the 6D
  // point whose dimensions 0-1 are the previous vertex's direction, get2d(first): the same
  // shuffled index, computed once, and their own coordinate scrambles. Out of line as get2d.
  [[gnu::noinline]] VertexNumbers odd_vertex_numbers(int vertex, bool lights) const {
    using namespace sampler_detail;
    const uint32_t i = shuffle(uint32_t(mix64(pixel_key_ ^ bounce_dim(vertex - 1, kBsdfDir))));
    VertexNumbers u;
#if GDPT_SAMPLER_SIMD
    // Both pairs in one register (the light pair's lanes are unused without lights).
    const uint64_t hd = mix64(pixel_key_ ^ bounce_dim(vertex, kBsdfDir));
    const uint64_t hl = lights ? mix64(pixel_key_ ^ bounce_dim(vertex, kLightPoint)) : 0;
    const PointPair p = scrambled_pairs(reversed_sobol_dim(2, i), reversed_sobol_dim(3, i), hd,
                                        lights ? reversed_sobol_dim(4, i) : 0,
                                        lights ? reversed_sobol_dim(5, i) : 0, hl);
    u.dir = p.first;
    if (lights) u.light = p.second;
#else
    if (lights)
      u.light = scrambled_pair(reversed_sobol_dim(4, i), reversed_sobol_dim(5, i),
                               mix64(pixel_key_ ^ bounce_dim(vertex, kLightPoint)));
    u.dir = scrambled_pair(reversed_sobol_dim(2, i), reversed_sobol_dim(3, i),
                           mix64(pixel_key_ ^ bounce_dim(vertex, kBsdfDir)));
#endif
    return u;
  }

 private:
  // The sample index shuffled by a nested uniform scramble: aligned blocks of 2^m indices map to
  // aligned blocks, so every such block stays a net.
  uint32_t shuffle(uint32_t seed) const {
    using namespace sampler_detail;
    return reverse_bits(lk_permutation(reversed_index_, seed));
  }
  // Owen-scrambled coordinate in [0, 1) from its reversed-bit Sobol value r.
  static float scrambled(uint32_t r, uint32_t seed) {
    using namespace sampler_detail;
    return to_unit_float(reverse_bits(lk_permutation(r, seed)));
  }
#if GDPT_SAMPLER_SIMD
  // Two Owen-scrambled points in one register: (rx0, ry0) with hash h0, (rx1, ry1) with h1.
  struct PointPair {
    Vec2f first, second;
  };
  static PointPair scrambled_pairs(uint32_t rx0, uint32_t ry0, uint64_t h0, uint32_t rx1,
                                   uint32_t ry1, uint64_t h1) {
    alignas(16) float v[4];
    _mm_store_ps(v,
                 sampler_detail::scrambled4(_mm_setr_epi32(int(rx0), int(ry0), int(rx1), int(ry1)),
                                            _mm_setr_epi32(int(sampler_detail::pair_seed_x(h0)),
                                                           int(sampler_detail::pair_seed_y(h0)),
                                                           int(sampler_detail::pair_seed_x(h1)),
                                                           int(sampler_detail::pair_seed_y(h1)))));
    return {{v[0], v[1]}, {v[2], v[3]}};
  }
#endif
  // Owen-scrambled point from the reversed-bit Sobol coordinates rx, ry and their hash h.
  static Vec2f scrambled_pair(uint32_t rx, uint32_t ry, uint64_t h) {
#if GDPT_SAMPLER_SIMD
    return scrambled_pairs(rx, ry, h, 0, 0, 0).first;
#else
    return {scrambled(rx, sampler_detail::pair_seed_x(h)),
            scrambled(ry, sampler_detail::pair_seed_y(h))};
#endif
  }

  uint64_t pixel_key_ = 0;
  uint32_t reversed_index_ = 0;
};

}  // namespace gdpt
