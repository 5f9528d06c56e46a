// The per-pixel Owen-scrambled Sobol sampler: range, purity (same inputs -> same value),
// stratification of every 2D pair over a power-of-two sample count, decorrelation across pixels
// and dimensions, and every value against its definition in scalar steps. This file is built twice:
// test_sampler (the x86-64 baseline: scalar code) and, on a CPU with SSSE3 and SSE4.1,
// test_sampler_simd (the sampler's SSE lanes, as in the x86-64-v3 module build).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "render/sampler.h"
#include "render/vertex_number_batch.h"

#if defined(GDPT_TEST_EXPECTS_SAMPLER_SIMD) && !defined(GDPT_SAMPLER_SIMD)
#error "test_sampler_simd must build the sampler's SIMD path"
#endif
#if defined(GDPT_TEST_EXPECTS_AVX2) && !defined(__AVX2__)
#error "test_sampler_avx2 must build VertexNumberBatch's AVX2 lanes"
#endif

namespace gdpt {
namespace {

TEST(Sampler, ValuesAreInUnitIntervalAndPure) {
  Sampler a, b;
  for (uint32_t s = 0; s < 64; ++s) {
    a.start(7, 3, 5, s);
    b.start(7, 3, 5, s);
    for (uint32_t d = 0; d < 20; ++d) {
      const Vec2f u = a.get2d(d);
      EXPECT_GE(u.x, 0.0f);
      EXPECT_LT(u.x, 1.0f);
      EXPECT_GE(u.y, 0.0f);
      EXPECT_LT(u.y, 1.0f);
      EXPECT_EQ(u.x, b.get2d(d).x);
      EXPECT_EQ(a.get1d(d), b.get1d(d));
    }
  }
}

// 256 samples of a (0,2)-sequence: every elementary interval of area 1/256 holds exactly one point.
TEST(Sampler, TwoDimensionalPairsAreElementaryIntervalStratified) {
  const int n = 256;
  for (uint32_t dim : {0u, 1u, 5u, 13u}) {
    for (int log_x = 0; log_x <= 8; ++log_x) {
      const int nx = 1 << log_x, ny = n / nx;
      std::vector<int> cells(n, 0);
      Sampler s;
      for (int i = 0; i < n; ++i) {
        s.start(1234, 17, 9, uint32_t(i));
        const Vec2f u = s.get2d(dim);
        ++cells[size_t(int(u.y * ny) * nx + int(u.x * nx))];
      }
      for (int c : cells) ASSERT_EQ(c, 1) << "dim " << dim << " grid " << nx << "x" << ny;
    }
  }
}

// Progressive rendering relies on every power-of-two prefix of a pixel's samples being a net, and
// so is every aligned block [j 2^m, (j + 1) 2^m) (the index shuffle maps aligned blocks to aligned
// blocks): in 2D one point in each elementary interval of area 2^-m, in 1D one per 1/2^m bin. For
// several seeds, pixels (including large coordinates) and dimensions.
TEST(Sampler, PrefixesAndAlignedBlocksAreNets) {
  struct Pixel {
    uint32_t seed;
    int x, y;
  };
  for (const Pixel p : {Pixel{1, 0, 0}, Pixel{77, 17, 9}, Pixel{0xdeadbeefu, 4095, 2160}})
    for (uint32_t dim : {0u, 1u, 2u, 7u, 13u, 40u})
      for (int m = 0; m <= 7; ++m) {
        const int n = 1 << m;
        for (uint32_t block : {0u, 1u, 5u}) {
          std::vector<int> bins(size_t(n), 0);
          std::vector<Vec2f> u(static_cast<size_t>(n));
          Sampler s;
          for (int i = 0; i < n; ++i) {
            s.start(p.seed, p.x, p.y, block * uint32_t(n) + uint32_t(i));
            u[size_t(i)] = s.get2d(dim);
            ++bins[size_t(s.get1d(dim) * float(n))];
          }
          for (int b : bins)
            ASSERT_EQ(b, 1) << "1D dim " << dim << " m " << m << " block " << block;
          for (int log_x = 0; log_x <= m; ++log_x) {
            const int nx = 1 << log_x, ny = n / nx;
            std::vector<int> cells(size_t(n), 0);
            for (const Vec2f v : u)
              ++cells[size_t(int(v.y * float(ny)) * nx + int(v.x * float(nx)))];
            for (int c : cells)
              ASSERT_EQ(c, 1) << "2D dim " << dim << " m " << m << " block " << block << " grid "
                              << nx << "x" << ny;
          }
        }
      }
}

// Across pixels, a given sample's x and y and the x of two dimensions are independent: they fall in
// the same half for about half of 4096 pixels (sigma 0.008). Guards the seed derivation: the three
// scramble seeds of a dimension come from one hash, and dimensions differ only in its input.
TEST(Sampler, CoordinatesAndDimensionsAreIndependentAcrossPixels) {
  const int pixels = 4096;
  for (uint32_t index : {0u, 1u, 6u}) {
    int same_xy = 0, same_dims = 0;
    for (int p = 0; p < pixels; ++p) {
      Sampler s;
      s.start(3, p % 64, p / 64, index);
      const Vec2f a = s.get2d(Sampler::bounce_dim(1, Sampler::kLightPoint));
      const Vec2f b = s.get2d(Sampler::bounce_dim(1, Sampler::kBsdfDir));
      same_xy += (a.x < 0.5f) == (a.y < 0.5f);
      same_dims += (a.x < 0.5f) == (b.x < 0.5f);
    }
    EXPECT_NEAR(double(same_xy) / pixels, 0.5, 0.04) << index;
    EXPECT_NEAR(double(same_dims) / pixels, 0.5, 0.04) << index;
  }
}

TEST(Sampler, SobolTablesMatchTheGeneratorMatrix) {
  for (uint32_t i : {0u, 1u, 2u, 3u, 255u, 256u, 0x12345678u, 0xdeadbeefu, 0xffffffffu})
    EXPECT_EQ(sampler_detail::sobol_dim1(i), sampler_detail::sobol_dim1_slow(i)) << i;
}

TEST(Sampler, SobolDimensionsTwoToFiveTablesMatchTheRecurrence) {
  for (int d = 2; d <= 5; ++d)
    for (uint32_t i : {1u, 2u, 3u, 255u, 256u, 0x12345678u, 0xffffffffu})
      EXPECT_EQ(sampler_detail::reverse_bits(sampler_detail::reversed_sobol_dim(d, i)),
                sampler_detail::sobol_dim_slow(d, i))
          << d << " " << i;
  // Sobol dimension 2 starts 0, 1/2, 3/4, 1/4, 3/8, 7/8, 5/8, 1/8.
  const double expected[8] = {0, 0.5, 0.75, 0.25, 0.375, 0.875, 0.625, 0.125};
  for (uint32_t i = 0; i < 8; ++i)
    EXPECT_EQ(sampler_detail::sobol_dim_slow(2, i) * 0x1p-32, expected[i]) << i;
}

// Whether every elementary box of volume 2^(t - m) in the given coordinates (a list of 1D
// values per sample) holds exactly 2^t of the n = 2^m samples: a (t,m,s)-net.
bool is_net(const std::vector<std::vector<float>>& pts, int m, int t) {
  const size_t dims = pts[0].size();
  std::vector<int> level(dims, 0);
  // Every split of m - t binary digits among the coordinates.
  bool ok = true;
  auto visit = [&](auto&& self, size_t d, int left) -> void {
    if (!ok) return;
    if (d + 1 == dims) {
      level[d] = left;
      std::vector<int> cells(size_t(1) << (m - t), 0);
      for (const auto& p : pts) {
        uint32_t c = 0;
        for (size_t k = 0; k < dims; ++k) c = c << level[k] | uint32_t(p[k] * float(1 << level[k]));
        ++cells[c];
      }
      for (int c : cells) ok = ok && c == (1 << t);
      return;
    }
    for (int l = 0; l <= left; ++l) {
      level[d] = l;
      self(self, d + 1, left - l);
    }
  };
  visit(visit, 0, m - t);
  return ok;
}

// Vertices 0 and 1 (and 2 and 3) share one 6D point: vertex 0's direction, vertex 1's direction
// and vertex 1's light point. The directions form a (2,m,4)-net, all six coordinates a
// (3,m,6)-net, also for aligned blocks; the odd vertex's pairs alone are (1,m,2)- and
// (2,m,2)-nets (Sobol dimensions 2-3 and 4-5). Independent pairs fail: about 40% of the 4D boxes
// would hold another count.
TEST(Sampler, ConsecutiveVerticesShareOneSixDimensionalNet) {
  for (int even : {0, 2})
    for (int m : {5, 6})
      for (uint32_t block : {0u, 3u}) {
        const int n = 1 << m;
        std::vector<std::vector<float>> dirs, all, odd_dir, odd_light;
        Sampler s;
        for (int i = 0; i < n; ++i) {
          s.start(41, 6, 11, block * uint32_t(n) + uint32_t(i));
          const Sampler::VertexNumbers a = s.vertex_numbers(even, true);
          const Sampler::VertexNumbers b = s.vertex_numbers(even + 1, true);
          dirs.push_back({a.dir.x, a.dir.y, b.dir.x, b.dir.y});
          all.push_back({a.dir.x, a.dir.y, b.dir.x, b.dir.y, b.light.x, b.light.y});
          odd_dir.push_back({b.dir.x, b.dir.y});
          odd_light.push_back({b.light.x, b.light.y});
        }
        EXPECT_TRUE(is_net(dirs, m, 2)) << even << " " << m << " " << block;
        EXPECT_TRUE(is_net(all, m, 3)) << even << " " << m << " " << block;
        EXPECT_TRUE(is_net(odd_dir, m, 1)) << even << " " << m << " " << block;
        EXPECT_TRUE(is_net(odd_light, m, 2)) << even << " " << m << " " << block;
        EXPECT_FALSE(is_net(dirs, m, 1)) << "t = 2 is the best the first four dimensions reach";
      }
}

// Sampler's values by their definition (sampler.h), one scalar step at a time: the pixel key and
// the reversed index of start(), then per 2D pair one 64-bit hash of (key, dimension) whose low
// half seeds the index shuffle and whose high halves seed the two coordinate scrambles.
struct ScalarSampler {
  uint64_t key;
  uint32_t reversed_index;
  ScalarSampler(uint32_t seed, int x, int y, uint32_t index) {
    using namespace sampler_detail;
    key = mix64((uint64_t(uint32_t(y)) << 32 | uint32_t(x)) ^
                uint64_t(hash_u32(seed)) * 0x9e3779b97f4a7c15ull);
    reversed_index = reverse_bits(index);
  }
  static float scramble(uint32_t reversed_value, uint32_t seed) {
    using namespace sampler_detail;
    return to_unit_float(reverse_bits(lk_permutation(reversed_value, seed)));
  }
  static uint32_t seed_y(uint64_t h) { return uint32_t((h * 0x9e3779b97f4a7c15ull) >> 32); }
  uint32_t shuffled(uint64_t h) const {
    using namespace sampler_detail;
    return reverse_bits(lk_permutation(reversed_index, uint32_t(h)));
  }
  // Sobol dimensions (d, d + 1) of shuffled index i (d = 0: dimension 0 is i reversed, i.e. the
  // reversed value is i itself).
  static Vec2f pair(uint32_t i, int d, uint64_t h) {
    using namespace sampler_detail;
    const uint32_t rx = d == 0 ? i : reversed_sobol_dim(d, i);
    return {scramble(rx, uint32_t(h >> 32)), scramble(reversed_sobol_dim(d + 1, i), seed_y(h))};
  }
  Vec2f get2d(uint32_t dim) const {
    const uint64_t h = sampler_detail::mix64(key ^ dim);
    return pair(shuffled(h), 0, h);
  }
  Sampler::VertexNumbers vertex(int v) const {
    if (!(v & 1))
      return {get2d(Sampler::bounce_dim(v, Sampler::kLightPoint)),
              get2d(Sampler::bounce_dim(v, Sampler::kBsdfDir))};
    using sampler_detail::mix64;
    const uint32_t i = shuffled(mix64(key ^ Sampler::bounce_dim(v - 1, Sampler::kBsdfDir)));
    return {pair(i, 4, mix64(key ^ Sampler::bounce_dim(v, Sampler::kLightPoint))),
            pair(i, 2, mix64(key ^ Sampler::bounce_dim(v, Sampler::kBsdfDir)))};
  }
};

TEST(Sampler, ValuesMatchTheirScalarDefinition) {
  std::mt19937 rng(7);
  for (int k = 0; k < 20000; ++k) {
    const uint32_t seed = rng(), index = rng() >> (rng() % 32);
    const int x = int(rng() % 4096) - 8, y = int(rng() % 4096) - 8;
    Sampler s;
    s.start(seed, x, y, index);
    const ScalarSampler ref(seed, x, y, index);
    const Vec2f cam = s.get2d(Sampler::kDimCamera), want_cam = ref.get2d(Sampler::kDimCamera);
    ASSERT_EQ(cam.x, want_cam.x);
    ASSERT_EQ(cam.y, want_cam.y);
    const int v = int(rng() % 16);
    for (bool lights : {true, false}) {
      const Sampler::VertexNumbers u = s.vertex_numbers(v, lights), want = ref.vertex(v);
      ASSERT_EQ(u.dir.x, want.dir.x) << v;
      ASSERT_EQ(u.dir.y, want.dir.y) << v;
      if (lights) {
        ASSERT_EQ(u.light.x, want.light.x) << v;
        ASSERT_EQ(u.light.y, want.light.y) << v;
      }
    }
  }
}

#if GDPT_SAMPLER_SIMD
TEST(Sampler, SimdLanesMatchTheScalarSteps) {
  using namespace sampler_detail;
  std::mt19937 rng(11);
  for (int k = 0; k < 100000; ++k) {
    alignas(16) uint32_t x[4], seed[4], rev[4], nested[4];
    alignas(16) float unit[4];
    for (int l = 0; l < 4; ++l) x[l] = rng(), seed[l] = rng();
    const __m128i X = _mm_load_si128(reinterpret_cast<const __m128i*>(x));
    const __m128i S = _mm_load_si128(reinterpret_cast<const __m128i*>(seed));
    _mm_store_si128(reinterpret_cast<__m128i*>(rev), reverse_bits4(X));
    _mm_store_si128(reinterpret_cast<__m128i*>(nested), nested_scramble_reversed4(X, S));
    _mm_store_ps(unit, scrambled4(X, S));
    for (int l = 0; l < 4; ++l) {
      ASSERT_EQ(rev[l], reverse_bits(x[l]));
      ASSERT_EQ(nested[l], reverse_bits(lk_permutation(x[l], seed[l])));
      ASSERT_EQ(unit[l], to_unit_float(reverse_bits(lk_permutation(x[l], seed[l]))));
    }
  }
}
#endif

TEST(Sampler, OneDimensionalValuesAreStratified) {
  const int n = 128;
  std::vector<int> bins(n, 0);
  Sampler s;
  for (int i = 0; i < n; ++i) {
    s.start(99, 1, 2, uint32_t(i));
    ++bins[size_t(s.get1d(Sampler::bounce_dim(3, Sampler::kRoulette)) * n)];
  }
  for (int b : bins) EXPECT_EQ(b, 1);
}

TEST(Sampler, PixelsDimensionsAndSeedsAreDecorrelated) {
  // Correlation of the first coordinate between two pixels / two dimensions / two seeds over
  // 1024 samples must be near zero (it would be 1 without per-pixel scrambling).
  auto correlation = [](auto fa, auto fb) {
    const int n = 1024;
    double sa = 0, sb = 0, sab = 0, saa = 0, sbb = 0;
    for (int i = 0; i < n; ++i) {
      const double a = fa(uint32_t(i)), b = fb(uint32_t(i));
      sa += a;
      sb += b;
      sab += a * b;
      saa += a * a;
      sbb += b * b;
    }
    const double cov = sab / n - (sa / n) * (sb / n);
    return cov / std::sqrt((saa / n - (sa / n) * (sa / n)) * (sbb / n - (sb / n) * (sb / n)));
  };
  auto value = [](uint32_t seed, int x, uint32_t dim) {
    return [=](uint32_t i) {
      Sampler s;
      s.start(seed, x, 0, i);
      return double(s.get2d(dim).x);
    };
  };
  EXPECT_LT(std::fabs(correlation(value(1, 0, 0), value(1, 1, 0))), 0.1);
  EXPECT_LT(std::fabs(correlation(value(1, 0, 0), value(1, 0, 1))), 0.1);
  EXPECT_LT(std::fabs(correlation(value(1, 0, 0), value(2, 0, 0))), 0.1);
}

TEST(Sampler, MeanConvergesFasterThanRandom) {
  // Integrate f(x, y) = x * y (exact 1/4) with 256 samples in many pixels: the RMS error of a
  // stratified (0,2)-sequence is far below the 1/sqrt(n) Monte Carlo error (~0.013 here).
  double err2 = 0.0;
  const int pixels = 64, n = 256;
  for (int p = 0; p < pixels; ++p) {
    Sampler s;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      s.start(5, p, 0, uint32_t(i));
      const Vec2f u = s.get2d(Sampler::bounce_dim(0, Sampler::kBsdfDir));
      sum += double(u.x) * u.y;
    }
    err2 += (sum / n - 0.25) * (sum / n - 0.25);
  }
  EXPECT_LT(std::sqrt(err2 / pixels), 0.002);
}

// VertexNumberBatch returns each pixel's Sampler values bit for bit: camera jitter and every
// batched vertex's light point and direction, for full and partial segments (count < 8 and
// between 8 and 16), with and without lights, sample indices from 0 to past 2^24. Vertices are
// batched only with AVX2 (test_sampler_avx2, built as the x86-64-v3 module is).
TEST(VertexNumberBatch, EqualsEachPixelsSampler) {
  struct Segment {
    uint32_t seed;
    int x0, y, count;
  };
  int cameras = 0, vertices_checked = 0;
  for (const Segment seg :
       {Segment{1, 0, 0, 16}, Segment{77, 33, 9, 5}, Segment{0xdeadbeefu, 4080, 2159, 11}})
    for (int vertices : {0, 1, 3, 4, 9})
      for (bool lights : {true, false}) {
        VertexNumberBatch batch;
        batch.prepare(seg.seed, seg.x0, seg.y, seg.count, vertices, lights);
        ASSERT_EQ(batch.vertices(), std::min(vertices, VertexNumberBatch::kMaxVertices));
        for (uint32_t index : {0u, 1u, 2u, 3u, 17u, 255u, 1000u, 65535u, (1u << 24) + 5u}) {
          batch.fill(index);
          for (int j = 0; j < seg.count; ++j) {
            Sampler s;
            s.start(seg.seed, seg.x0 + j, seg.y, index);
            const Vec2f c = s.get2d(Sampler::kDimCamera);
            ASSERT_EQ(batch.camera(j).x, c.x) << "pixel " << j << " index " << index;
            ASSERT_EQ(batch.camera(j).y, c.y);
            ++cameras;
            for (int v = 0; v < batch.vertices(); ++v) {
              const Sampler::VertexNumbers u = s.vertex_numbers(v, lights);
              const Sampler::VertexNumbers b = batch.vertex_numbers(j, v);
              ASSERT_EQ(b.dir.x, u.dir.x) << "pixel " << j << " vertex " << v << " index " << index;
              ASSERT_EQ(b.dir.y, u.dir.y);
              ++vertices_checked;
              if (!lights) continue;
              ASSERT_EQ(b.light.x, u.light.x) << "pixel " << j << " vertex " << v;
              ASSERT_EQ(b.light.y, u.light.y);
            }
          }
        }
      }
  EXPECT_EQ(cameras, 32 * 10 * 9);
#if defined(__AVX2__)
  EXPECT_EQ(VertexNumberBatch::kMaxVertices, 4);
  EXPECT_GT(vertices_checked, 1000);
#else
  EXPECT_EQ(vertices_checked, 0);
#endif
}

}  // namespace
}  // namespace gdpt
