// Procedural textures (shaders/procedural_texture.h). That they are Cycles' own patterns is
// checked against Cycles renders (blender.agreement_materials, case procedural_textures); here
// the properties that hold for any correct implementation.
#include "shaders/procedural_texture.h"

#include <gtest/gtest.h>

#include <algorithm>

#include <cmath>
#include <random>

namespace gdpt {
namespace {

TEST(ProceduralTexture, PerlinNoiseVanishesOnTheLattice) {
  for (int x = -3; x <= 3; ++x)
    for (int y = -3; y <= 3; ++y)
      for (int z = -3; z <= 3; ++z)
        EXPECT_EQ(signed_noise(Vec3f(float(x), float(y), float(z))), 0.0f) << x << y << z;
}

TEST(ProceduralTexture, NoiseIsBoundedCenteredAndContinuous) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-50.0f, 50.0f);
  double sum = 0.0;
  constexpr int kN = 20000;
  for (int i = 0; i < kN; ++i) {
    const Vec3f p(u(rng), u(rng), u(rng));
    const float n = signed_noise(p);
    ASSERT_LE(std::fabs(n), 1.0f) << p.x << " " << p.y << " " << p.z;
    sum += n;
    // Lipschitz: the gradient of Perlin noise is bounded (well below 4 per unit here).
    const float step = 1e-3f;
    EXPECT_LE(std::fabs(signed_noise(p + Vec3f(step, 0.0f, 0.0f)) - n), 4.0f * step);
    const NoiseTextureResult t = noise_texture(p, 2.0f, 0.5f, 0.0f, true);
    ASSERT_GE(t.fac, 0.0f);
    ASSERT_LE(t.fac, 1.0f);
    EXPECT_EQ(t.color.x, t.fac);
  }
  EXPECT_NEAR(sum / kN, 0.0, 0.01);
}

// Blender 3.4's fractal noise: detail n gives n + 1 octaves normalised by the amplitude sum, a
// fractional detail blends the two neighbouring integer details linearly, and roughness 0
// leaves only the first octave.
TEST(ProceduralTexture, FractalDetailAndRoughness) {
  const Vec3f p(0.37f, -1.21f, 2.72f);
  auto fac = [&](float detail, float roughness) {
    return noise_texture(p, detail, roughness, 0.0f, false).fac;
  };
  EXPECT_NEAR(fac(0.0f, 0.5f), 0.5f * signed_noise(p) + 0.5f, 1e-7f);
  const float one = fac(1.0f, 0.5f), two = fac(2.0f, 0.5f);
  EXPECT_NEAR(fac(1.25f, 0.5f), 0.75f * one + 0.25f * two, 1e-6f);
  // Detail 1, roughness 0.5: (n(p) + 0.5 n(2p)) / 1.5 of the unsigned noise.
  const float n1 = 0.5f * signed_noise(p) + 0.5f, n2 = 0.5f * signed_noise(p * 2.0f) + 0.5f;
  EXPECT_NEAR(one, (n1 + 0.5f * n2) / 1.5f, 1e-6f);
  EXPECT_EQ(fac(5.0f, 0.0f), fac(0.0f, 0.0f));
  // Clamps: detail to [0, 15], roughness to [0, 1].
  EXPECT_EQ(fac(40.0f, 0.5f), fac(15.0f, 0.5f));
  EXPECT_EQ(fac(2.0f, 3.0f), fac(2.0f, 1.0f));
  // Distortion moves the lookup; the colour's channels are independent fBm evaluations.
  EXPECT_NE(noise_texture(p, 2.0f, 0.5f, 1.0f, false).fac, fac(2.0f, 0.5f));
  const NoiseTextureResult c = noise_texture(p, 2.0f, 0.5f, 0.0f, true);
  EXPECT_NE(c.color.y, c.color.x);
  EXPECT_NE(c.color.z, c.color.y);
}

// Cells of side 1: Color1 where the cell indices' parities are (even, even, odd) and the like,
// Color2 at the origin's cell; points on a cell border are nudged inwards as Cycles does.
TEST(ProceduralTexture, CheckerCells) {
  EXPECT_EQ(checker_texture(Vec3f(0.5f, 0.5f, 0.5f)), 0.0f);
  EXPECT_EQ(checker_texture(Vec3f(1.5f, 0.5f, 0.5f)), 1.0f);
  EXPECT_EQ(checker_texture(Vec3f(0.5f, 1.5f, 0.5f)), 1.0f);
  EXPECT_EQ(checker_texture(Vec3f(0.5f, 0.5f, 1.5f)), 1.0f);
  EXPECT_EQ(checker_texture(Vec3f(1.5f, 1.5f, 0.5f)), 0.0f);
  EXPECT_EQ(checker_texture(Vec3f(1.5f, 1.5f, 1.5f)), 1.0f);
  // Mirrored about 0 by |floor|: cell -1 has index 1.
  EXPECT_EQ(checker_texture(Vec3f(-0.5f, 0.5f, 0.5f)), 1.0f);
  // A unit plane at scale 1: its corners' coordinates 0 and 1 stay in the first cell.
  EXPECT_EQ(checker_texture(Vec3f(0.0f, 0.0f, 0.5f)), 0.0f);
  EXPECT_EQ(checker_texture(Vec3f(0.999999f, 0.999999f, 0.5f)), 0.0f);
}

// With randomness 0 every cell's point is its corner: F1 is the nearest lattice point, exactly,
// under each metric.
TEST(ProceduralTexture, VoronoiWithoutJitterFindsTheNearestLatticePoint) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-20.0f, 20.0f);
  for (int i = 0; i < 2000; ++i) {
    const Vec3f p(u(rng), u(rng), u(rng));
    const Vec3f nearest(std::round(p.x), std::round(p.y), std::round(p.z));
    const Vec3f d = p - nearest;
    const VoronoiResult e = voronoi_f1(p, 0.0f, VoronoiMetric::Euclidean, 1.0f);
    EXPECT_NEAR(e.distance, length(d), 1e-5f);
    EXPECT_EQ(e.position, nearest);
    const VoronoiResult c = voronoi_f1(p, 0.0f, VoronoiMetric::Chebyshev, 1.0f);
    EXPECT_NEAR(c.distance, std::max(std::fabs(d.x), std::max(std::fabs(d.y), std::fabs(d.z))),
                1e-5f);
    // Minkowski with exponent 1 is Manhattan.
    const VoronoiResult m = voronoi_f1(p, 0.0f, VoronoiMetric::Minkowski, 1.0f);
    EXPECT_NEAR(m.distance, voronoi_f1(p, 0.0f, VoronoiMetric::Manhattan, 1.0f).distance, 1e-4f);
    // The colour is the cell's: the same anywhere near the same point.
    EXPECT_EQ(e.color, voronoi_f1(nearest + d * 0.5f, 0.0f, VoronoiMetric::Euclidean, 1.0f).color);
    for (float v : {e.color.x, e.color.y, e.color.z}) {
      EXPECT_GE(v, 0.0f);
      EXPECT_LE(v, 1.0f);
    }
  }
  // Jittered points stay within their cells: F1 is never farther than a cell diagonal.
  for (int i = 0; i < 2000; ++i) {
    const Vec3f p(u(rng), u(rng), u(rng));
    const VoronoiResult r = voronoi_f1(p, 1.0f, VoronoiMetric::Euclidean, 1.0f);
    EXPECT_LE(r.distance, std::sqrt(3.0f));
    EXPECT_NEAR(length(r.position - p), r.distance, 1e-4f);
  }
}

TEST(ProceduralTexture, GradientProfiles) {
  const Vec3f p(0.6f, 0.2f, 0.1f);
  EXPECT_FLOAT_EQ(gradient_texture(p, GradientType::Linear), 0.6f);
  EXPECT_FLOAT_EQ(gradient_texture(p, GradientType::Quadratic), 0.36f);
  EXPECT_FLOAT_EQ(gradient_texture(Vec3f(-0.5f, 0, 0), GradientType::Quadratic), 0.0f);
  EXPECT_FLOAT_EQ(gradient_texture(p, GradientType::Easing), 3 * 0.36f - 2 * 0.216f);
  EXPECT_FLOAT_EQ(gradient_texture(p, GradientType::Diagonal), 0.4f);
  const float r = 0.999999f - std::sqrt(0.41f);
  EXPECT_FLOAT_EQ(gradient_texture(p, GradientType::Spherical), r);
  EXPECT_FLOAT_EQ(gradient_texture(p, GradientType::QuadraticSphere), r * r);
  EXPECT_FLOAT_EQ(gradient_texture(Vec3f(0, 1, 0), GradientType::Spherical), 0.0f);
  EXPECT_FLOAT_EQ(gradient_texture(Vec3f(0, 1, 0), GradientType::Radial), 0.75f);
  EXPECT_FLOAT_EQ(gradient_texture(Vec3f(-1, -1e-9f, 0), GradientType::Radial), 0.0f);
}

// Bands along x: n = 20 x' + phase with x' = (x + 1e-6) 0.999999 (Cycles' nudge), through the
// three profiles; rings around z: n = 20 |(x', y')|; distortion 0 leaves them exact.
TEST(ProceduralTexture, WaveProfiles) {
  constexpr float kPi = 3.14159265358979f;
  const Vec3f p(0.13f, 0.4f, 0.7f);
  const Vec3f q = (p + Vec3f(0.000001f)) * 0.999999f;
  WaveDesc bands;
  const float n = 20.0f * q.x + 0.3f;
  EXPECT_NEAR(wave_texture(p, bands, 0.0f, 2.0f, 1.0f, 0.5f, 0.3f),
              0.5f + 0.5f * std::sin(n - 0.5f * kPi), 1e-5f);
  bands.profile = WaveDesc::Profile::Saw;
  const float t = n / (2.0f * kPi);
  EXPECT_NEAR(wave_texture(p, bands, 0.0f, 2.0f, 1.0f, 0.5f, 0.3f), t - std::floor(t), 1e-5f);
  bands.profile = WaveDesc::Profile::Triangle;
  EXPECT_NEAR(wave_texture(p, bands, 0.0f, 2.0f, 1.0f, 0.5f, 0.3f),
              2.0f * std::fabs(t - std::floor(t + 0.5f)), 1e-5f);
  WaveDesc rings;
  rings.type = WaveDesc::Type::Rings;
  rings.direction = WaveDesc::Direction::Z;
  EXPECT_NEAR(wave_texture(p, rings, 0.0f, 2.0f, 1.0f, 0.5f, 0.0f),
              0.5f + 0.5f * std::sin(20.0f * std::hypot(q.x, q.y) - 0.5f * kPi), 1e-5f);
  // Distortion adds distortion * (2 fBm - 1) to n: the same fBm as the Noise Texture's Fac.
  const float fbm = noise_texture(q * 1.5f, 2.0f, 0.5f, 0.0f, false).fac;
  bands.profile = WaveDesc::Profile::Saw;
  const float td = (n + 0.8f * (2.0f * fbm - 1.0f)) / (2.0f * kPi);
  EXPECT_NEAR(wave_texture(p, bands, 0.8f, 2.0f, 1.5f, 0.5f, 0.3f), td - std::floor(td), 1e-5f);
}

// Musgrave's fractals in closed form for one and two octaves (noise n = signed_noise, octave
// amplitude ratio s = lacunarity^-dimension), and a fractional detail blending the next octave.
TEST(ProceduralTexture, MusgraveFractals) {
  const Vec3f p(0.31f, -0.77f, 1.9f);
  const float lac = 2.1f, dim = 1.2f, off = 0.8f, gain = 1.3f;
  const float s = std::pow(lac, -dim);
  const float n1 = signed_noise(p), n2 = signed_noise(p * lac);
  auto m = [&](MusgraveType t, float detail) {
    return musgrave_texture(p, t, detail, dim, lac, off, gain);
  };
  EXPECT_NEAR(m(MusgraveType::Fbm, 1.0f), n1, 1e-6f);
  EXPECT_NEAR(m(MusgraveType::Fbm, 2.0f), n1 + s * n2, 1e-6f);
  EXPECT_NEAR(m(MusgraveType::Fbm, 1.5f), n1 + 0.5f * s * n2, 1e-6f);
  EXPECT_NEAR(m(MusgraveType::Multifractal, 2.0f), (n1 + 1.0f) * (s * n2 + 1.0f), 1e-6f);
  const float hetero1 = off + n1;
  EXPECT_NEAR(m(MusgraveType::HeteroTerrain, 1.0f), hetero1, 1e-6f);
  EXPECT_NEAR(m(MusgraveType::HeteroTerrain, 2.0f), hetero1 + (n2 + off) * s * hetero1, 1e-6f);
  const float hybrid1 = n1 + off, weight = std::min(gain * hybrid1, 1.0f);
  EXPECT_NEAR(m(MusgraveType::HybridMultifractal, 2.0f),
              hybrid1 + (gain * hybrid1 > 0.001f ? weight * (n2 + off) * s : 0.0f), 1e-6f);
  const float r1 = (off - std::fabs(n1)) * (off - std::fabs(n1));
  const float r2 =
      (off - std::fabs(n2)) * (off - std::fabs(n2)) * std::clamp(r1 * gain, 0.0f, 1.0f);
  EXPECT_NEAR(m(MusgraveType::RidgedMultifractal, 1.0f), r1, 1e-6f);
  EXPECT_NEAR(m(MusgraveType::RidgedMultifractal, 2.0f), r1 + r2 * s, 1e-6f);
}

// White noise is the lookup3 hash of the coordinates' float bits: at (0, 0, 0), where an unlinked
// White Noise Texture reads, Cycles 3.4 rendered exactly (0.61106765, 0.10291273, 0.8651527)
// (an emissive plane, tenth session); any other point gives other values in [0, 1].
TEST(ProceduralTexture, WhiteNoiseIsCyclesHash) {
  const Spectrum c = white_noise_color(Vec3f(0.0f));
  EXPECT_NEAR(c.x, 0.61106765f, 1e-7f);
  EXPECT_NEAR(c.y, 0.10291273f, 1e-7f);
  EXPECT_NEAR(c.z, 0.8651527f, 1e-7f);
  EXPECT_EQ(white_noise(Vec3f(0.0f)), c.x);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(-100.0f, 100.0f);
  double sum = 0.0;
  for (int i = 0; i < 10000; ++i) {
    const float v = white_noise(Vec3f(u(rng), u(rng), u(rng)));
    ASSERT_GE(v, 0.0f);
    ASSERT_LE(v, 1.0f);
    sum += v;
  }
  EXPECT_NEAR(sum / 10000.0, 0.5, 0.01);
}

// Noise in 1, 2 and 4 dimensions: zero on the integer lattice (Fac 0.5 at detail 0), bounded,
// the 3D case identical to noise_texture(p, ...), 1D reading only w and 2D only (x, y).
TEST(ProceduralTexture, NoiseDimensions) {
  for (int dims : {1, 2, 4})
    for (int i = -2; i <= 2; ++i)
      EXPECT_EQ(noise_texture(dims, Vec3f(float(i), float(-i), 3.0f), float(i + 1), 0.0f, 0.5f,
                              0.0f, false)
                    .fac,
                0.5f)
          << dims;
  const Vec3f p(0.37f, -1.21f, 2.72f);
  EXPECT_EQ(noise_texture(3, p, 0.9f, 2.5f, 0.6f, 0.3f, true).color,
            noise_texture(p, 2.5f, 0.6f, 0.3f, true).color);
  EXPECT_EQ(noise_texture(1, p, 0.9f, 2.0f, 0.5f, 0.0f, false).fac,
            noise_texture(1, Vec3f(5.0f, 6.0f, 7.0f), 0.9f, 2.0f, 0.5f, 0.0f, false).fac);
  EXPECT_EQ(noise_texture(2, p, 0.9f, 2.0f, 0.5f, 0.0f, false).fac,
            noise_texture(2, Vec3f(p.x, p.y, 9.0f), -4.0f, 2.0f, 0.5f, 0.0f, false).fac);
  EXPECT_NE(noise_texture(4, p, 0.9f, 2.0f, 0.5f, 0.0f, false).fac,
            noise_texture(4, p, 0.4f, 2.0f, 0.5f, 0.0f, false).fac);
  std::mt19937 rng(8);
  std::uniform_real_distribution<float> u(-30.0f, 30.0f);
  for (int dims : {1, 2, 4})
    for (int i = 0; i < 3000; ++i) {
      const NoiseTextureResult r =
          noise_texture(dims, Vec3f(u(rng), u(rng), u(rng)), u(rng), 3.0f, 0.7f, 0.5f, true);
      for (float v : {r.color.x, r.color.y, r.color.z}) {
        ASSERT_GE(v, 0.0f) << dims;
        ASSERT_LE(v, 1.0f) << dims;
      }
    }
}

// Magic: at depth 0 the three waves divided by 2 distortion; one fold rewrites y; distortion 0
// flattens every depth above 0 to grey.
TEST(ProceduralTexture, MagicFolds) {
  const Vec3f p(0.21f, -0.4f, 0.33f);
  const float d = 1.5f;
  const float x = std::sin((p.x + p.y + p.z) * 5.0f) * d;
  const float y = std::cos((-p.x + p.y - p.z) * 5.0f) * d;
  const float z = -std::cos((-p.x - p.y + p.z) * 5.0f) * d;
  const Spectrum c0 = magic_texture(p, 0, d);
  EXPECT_NEAR(c0.x, 0.5f - x / d / (2.0f * d), 1e-6f);
  EXPECT_NEAR(c0.z, 0.5f - z / d / (2.0f * d), 1e-6f);
  const Spectrum c1 = magic_texture(p, 1, d);
  EXPECT_NEAR(c1.x, 0.5f - x / (2.0f * d), 1e-6f);
  EXPECT_NEAR(c1.y, 0.5f + std::cos(x - y + z) * d / (2.0f * d), 1e-6f);
  EXPECT_NEAR(c1.z, 0.5f - z / (2.0f * d), 1e-6f);
  EXPECT_EQ(magic_texture(p, 3, 0.0f), Spectrum(0.5f));
}

// Brick Texture closed forms at Blender's defaults (width 0.5, row height 0.25, mortar 0.02,
// offset 0.5 every 2nd row counted from row 0, squash 1): where a point falls in its brick
// decides the mortar; the tint is one value per brick.
TEST(ProceduralTexture, BrickRowsOffsetsAndMortar) {
  auto at = [&](float x, float y, float smooth = 0.0f, const BrickDesc& d = BrickDesc()) {
    return brick_texture(Vec3f(x, y, 0.0f), d, 0.02f, smooth, 0.0f, 0.5f, 0.25f);
  };
  // Row 1 (not offset): x 0.25 is a brick's centre, x 0.51 within 0.02 of its left edge.
  EXPECT_EQ(at(0.25f, 0.375f).mortar, 0.0f);
  EXPECT_EQ(at(0.51f, 0.375f).mortar, 1.0f);
  EXPECT_EQ(at(0.25f, 0.26f).mortar, 1.0f);  // 0.01 above the row's bottom
  // Row 0 is offset by half a brick: x 0.26 lies 0.01 past an edge there, mid-brick in row 1.
  EXPECT_EQ(at(0.26f, 0.125f).mortar, 1.0f);
  EXPECT_EQ(at(0.26f, 0.375f).mortar, 0.0f);
  // Row -1 (-1 % 2 = -1, as C's remainder): not offset.
  EXPECT_EQ(at(0.26f, -0.125f).mortar, 0.0f);
  EXPECT_EQ(at(0.51f, -0.125f).mortar, 1.0f);
  // Smooth mortar: at 0.015 from an edge the band depth is 1 - 0.015 / 0.02 = 0.25, half of the
  // smooth width 0.5: smoothstep(0.5) = 0.5.
  EXPECT_NEAR(at(0.265f, 0.375f, 0.5f).mortar, 0.0f, 1e-6f);
  EXPECT_NEAR(at(0.515f, 0.375f, 0.5f).mortar, 0.5f, 1e-5f);
  // Squash 0.5 on every 2nd row: row 0's bricks are 0.25 wide (offset 0.125).
  BrickDesc squashed;
  squashed.squash = 0.5f;
  EXPECT_EQ(at(0.125f + 0.01f, 0.125f, 0.0f, squashed).mortar, 1.0f);  // 0.01 past an edge
  EXPECT_EQ(at(0.25f, 0.125f, 0.0f, squashed).mortar, 0.0f);           // mid-brick
  // Frequency 0: no offset or squash anywhere.
  BrickDesc plain;
  plain.offset_frequency = 0;
  EXPECT_EQ(at(0.26f, 0.125f, 0.0f, plain).mortar, 0.0f);
  // One tint per brick, in [0, 1], varying between bricks.
  std::vector<float> tints;
  for (int k = 0; k < 20; ++k) {
    const float x = 0.5f * float(k) + 0.25f;
    const float t = at(x, 0.375f).tint;
    EXPECT_EQ(at(x + 0.1f, 0.4f).tint, t);
    EXPECT_GE(t, 0.0f);
    EXPECT_LE(t, 1.0f);
    tints.push_back(t);
  }
  std::sort(tints.begin(), tints.end());
  EXPECT_GT(std::unique(tints.begin(), tints.end()) - tints.begin(), 15);
}

// Without jitter the Voronoi points are the integer lattice: at p = (3.1, 4.2, 5.3) the second
// nearest is (3, 4, 6) at sqrt(0.01 + 0.04 + 0.49), the nearest cell wall (a bisector plane) is
// z = 5.5, 0.2 away, and a tiny smoothness leaves F1; with jitter, F2 >= F1 everywhere and the
// distance to the edge is at most half the gap between the two nearest points.
TEST(ProceduralTexture, VoronoiF2SmoothF1AndDistanceToEdge) {
  const Vec3f p(3.1f, 4.2f, 5.3f);
  const VoronoiResult f2 = voronoi_f2(p, 0.0f, VoronoiMetric::Euclidean, 1.0f);
  EXPECT_NEAR(f2.distance, std::sqrt(0.01f + 0.04f + 0.49f), 1e-5f);
  EXPECT_NEAR(f2.position.z, 6.0f, 1e-5f);
  EXPECT_NEAR(voronoi_distance_to_edge(p, 0.0f), 0.2f, 1e-5f);
  const VoronoiResult f1 = voronoi_f1(p, 0.0f, VoronoiMetric::Euclidean, 1.0f);
  const VoronoiResult smooth = voronoi_smooth_f1(p, 1e-4f, 0.0f, VoronoiMetric::Euclidean, 1.0f);
  EXPECT_NEAR(smooth.distance, f1.distance, 1e-4f);
  EXPECT_NEAR(smooth.position.x, f1.position.x, 1e-3f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-10.0f, 10.0f);
  for (int i = 0; i < 500; ++i) {
    const Vec3f q(u(rng), u(rng), u(rng));
    const VoronoiResult a = voronoi_f1(q, 1.0f, VoronoiMetric::Euclidean, 1.0f);
    const VoronoiResult b = voronoi_f2(q, 1.0f, VoronoiMetric::Euclidean, 1.0f);
    EXPECT_GE(b.distance, a.distance);
    const float edge = voronoi_distance_to_edge(q, 1.0f);
    EXPECT_GE(edge, -1e-5f);
    // The bisector plane of the two nearest points a, b lies (F2^2 - F1^2) / (2 |a - b|) away.
    EXPECT_LE(edge, 0.5f * (b.distance - a.distance) * (b.distance + a.distance) /
                            length(b.position - a.position) +
                        1e-4f);
  }
}

}  // namespace
}  // namespace gdpt
