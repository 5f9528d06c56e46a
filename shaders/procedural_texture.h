// Blender's procedural textures as Cycles 3.4 computes them (kernel/svm/checker.h, noise.h,
// fractal_noise.h, noisetex.h), so that a scene textured with them renders as in Cycles:
// - Checker: alternating cells of side 1 (before the node's Scale);
// - Noise (3D): fractal Brownian motion of Perlin's improved gradient noise, hashed with Bob
//   Jenkins' lookup3 as Cycles does, so the pattern itself (not only its statistics) matches;
// - Voronoi (3D, F1): the nearest jittered cell point, with the same hashes;
// - Gradient: the seven profiles;
// - Wave: bands and rings with the three profiles and noise distortion;
// - Musgrave (3D): the five fractal types;
// - Magic and White Noise (3D).
#pragma once

#include <cstdint>

#include "core/vec.h"
#include "scene/node_types.h"

namespace gdpt {

// 1 where the Checker Texture shows Color1, 0 where it shows Color2, at p (already scaled).
float checker_texture(Vec3f p);

// Perlin gradient noise in [-1, 1] (Cycles' snoise_3d: scaled by 0.982, non-finite -> 0).
float signed_noise(Vec3f p);

// The 3D Noise Texture at p (already scaled): Fac in [0, 1] and, when `color`, the Color output
// (Fac and two more fBm evaluations at fixed offsets). detail is clamped to [0, 15], roughness to
// [0, 1]; distortion displaces p by noise first.
struct NoiseTextureResult {
  float fac = 0.5f;
  Spectrum color{0.5f};
};
NoiseTextureResult noise_texture(Vec3f p, float detail, float roughness, float distortion,
                                 bool color);

// The Noise Texture in `dimensions` 1, 2, 3 or 4 (Blender's Dimensions): it reads w alone (1D),
// (p.x, p.y) (2D), p (3D, as noise_texture) or (p, w) (4D), all already scaled; Perlin noise of
// that dimension with Cycles' hashes and scales, the same fractal sum, distortion and Color.
NoiseTextureResult noise_texture(int dimensions, Vec3f p, float w, float detail, float roughness,
                                 float distortion, bool color);

// The 3D Voronoi Texture's F1 feature at p (already scaled): the nearest of one jittered point
// per unit cell (jitter = randomness, in [0, 1]) by the metric, its distance, its cell's random
// colour and its position (Cycles' voronoi_f1_3d).
struct VoronoiResult {
  float distance = 0.0f;
  Spectrum color{0.0f};
  Vec3f position{0.0f};
};
VoronoiResult voronoi_f1(Vec3f p, float randomness, VoronoiMetric metric, float exponent);
// The second nearest point instead (Cycles' voronoi_f2_3d).
VoronoiResult voronoi_f2(Vec3f p, float randomness, VoronoiMetric metric, float exponent);
// F1 blended smoothly over the 5x5x5 neighbouring cells' points, smoothness in [0, 0.5] (the
// node's Smoothness / 2, clamped): distance, colour and position (Cycles' voronoi_smooth_f1_3d).
VoronoiResult voronoi_smooth_f1(Vec3f p, float smoothness, float randomness, VoronoiMetric metric,
                                float exponent);
// Euclidean distance to the nearest edge of the (Euclidean) F1 cell containing p (Cycles'
// voronoi_distance_to_edge_3d).
float voronoi_distance_to_edge(Vec3f p, float randomness);

// The Gradient Texture's value at p, before the node's clamp to [0, 1] (Cycles' svm_gradient).
float gradient_texture(Vec3f p, GradientType type);

// The Wave Texture at p (already scaled): bands along an axis or the diagonal, or rings around an
// axis or a point, phase-shifted, distorted by fractal noise, through a sine, saw or triangle
// profile (Cycles' svm_wave).
float wave_texture(Vec3f p, const WaveDesc& wave, float distortion, float detail,
                   float detail_scale, float detail_roughness, float phase);

// The 3D Musgrave Texture at p (already scaled): Musgrave's fractals of Perlin noise with
// roughness exponent `dimension` (H), lacunarity, detail octaves, offset and gain (Cycles 3.4's
// noise_musgrave_*_3d, before Blender 4.1 folded them into the Noise Texture).
float musgrave_texture(Vec3f p, MusgraveType type, float detail, float dimension, float lacunarity,
                       float offset, float gain);

// The 3D White Noise Texture at p: a value and a colour in [0, 1] hashed from p's float bits
// (Cycles' hash_float3_to_float and hash_float3_to_float3).
float white_noise(Vec3f p);
Spectrum white_noise_color(Vec3f p);

// The Magic Texture at p (already scaled): sines and cosines of the coordinates, folded `depth`
// (0 to 10) more times into each other, scaled by distortion (Cycles' svm_magic).
Spectrum magic_texture(Vec3f p, int depth, float distortion);

// The Brick Texture at p (already scaled), as Cycles 3.4's svm_brick: rows of height row_height
// holding bricks of width brick_width; every offset_frequency-th row (rows counted from 0, so
// row 0 too) shifts by offset * width and every squash_frequency-th row's bricks are `squash`
// times as wide (neither when either frequency is 0). Returns the brick's tint (an integer hash
// of its row and column, plus bias, clamped to [0, 1]) and the mortar factor (1 within
// mortar_size of the brick's edges, 0 beyond; with mortar_smooth > 0 the edge of that band is a
// smoothstep over the last mortar_smooth of it).
struct BrickSample {
  float tint;
  float mortar;
};
BrickSample brick_texture(Vec3f p, const BrickDesc& brick, float mortar_size, float mortar_smooth,
                          float bias, float brick_width, float row_height);

// Bob Jenkins' lookup3 hashes of 1 to 4 words (Cycles' hash_uint, hash_uint2 / 3 / 4).
uint32_t hash_words(uint32_t a);
uint32_t hash_words(uint32_t a, uint32_t b);
uint32_t hash_words(uint32_t a, uint32_t b, uint32_t c);
uint32_t hash_words(uint32_t a, uint32_t b, uint32_t c, uint32_t d);

}  // namespace gdpt
