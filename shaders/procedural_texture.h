// Blender's procedural textures as Cycles 3.4 computes them (kernel/svm/checker.h, noise.h,
// fractal_noise.h, noisetex.h), so that a scene textured with them renders as in Cycles:
// - Checker: alternating cells of side 1 (before the node's Scale);
// - Noise (3D): fractal Brownian motion of Perlin's improved gradient noise, hashed with Bob
//   Jenkins' lookup3 as Cycles does, so the pattern itself (not only its statistics) matches.
#pragma once

#include "integrator/math/vec.h"

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

// Bob Jenkins' lookup3 hashes of 2 and 3 words (Cycles' hash_uint2 / hash_uint3).
uint32_t hash_words(uint32_t a, uint32_t b);
uint32_t hash_words(uint32_t a, uint32_t b, uint32_t c);

}  // namespace gdpt
