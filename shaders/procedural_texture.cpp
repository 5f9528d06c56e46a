#include "shaders/procedural_texture.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>

namespace gdpt {

namespace {

constexpr uint32_t rotate(uint32_t x, int k) {
  return (x << k) | (x >> (32 - k));
}

// lookup3's final mixing of (a, b, c); the hash is c.
constexpr uint32_t final_mix(uint32_t a, uint32_t b, uint32_t c) {
  c ^= b;
  c -= rotate(b, 14);
  a ^= c;
  a -= rotate(c, 11);
  b ^= a;
  b -= rotate(a, 25);
  c ^= b;
  c -= rotate(b, 16);
  a ^= c;
  a -= rotate(c, 4);
  b ^= a;
  b -= rotate(a, 14);
  c ^= b;
  c -= rotate(b, 24);
  return c;
}

// Quintic fade 6t^5 - 15t^4 + 10t^3, in Cycles' evaluation order.
inline float fade(float t) {
  return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f);
}

// Dot product of (x, y, z) with one of Perlin's 12 edge gradients (16 entries), chosen by hash.
inline float gradient(uint32_t hash, float x, float y, float z) {
  const uint32_t h = hash & 15u;
  const float u = h < 8 ? x : y;
  const float vt = (h == 12 || h == 14) ? x : z;
  const float v = h < 4 ? y : vt;
  return ((h & 1u) ? -u : u) + ((h & 2u) ? -v : v);
}

// Integer cell and fraction, as Cycles' floorfrac.
inline float cell(float x, int& i) {
  const float f = std::floor(x);
  i = int(f);
  return x - f;
}

float perlin(float x, float y, float z) {
  int X, Y, Z;
  const float fx = cell(x, X), fy = cell(y, Y), fz = cell(z, Z);
  const float u = fade(fx), v = fade(fy), w = fade(fz);
  auto g = [&](int dx, int dy, int dz) {
    return gradient(hash_words(uint32_t(X + dx), uint32_t(Y + dy), uint32_t(Z + dz)),
                    fx - float(dx), fy - float(dy), fz - float(dz));
  };
  // Trilinear blend of the eight corner values, in Cycles' order (tri_mix).
  const float u1 = 1.0f - u, v1 = 1.0f - v, w1 = 1.0f - w;
  return w1 * (v1 * (g(0, 0, 0) * u1 + g(1, 0, 0) * u) + v * (g(0, 1, 0) * u1 + g(1, 1, 0) * u)) +
         w * (v1 * (g(0, 0, 1) * u1 + g(1, 0, 1) * u) + v * (g(0, 1, 1) * u1 + g(1, 1, 1) * u));
}

// Unsigned noise in [0, 1].
inline float unsigned_noise(Vec3f p) {
  return 0.5f * signed_noise(p) + 0.5f;
}

// Blender 3.4's fractal noise: floor(detail) + 1 octaves of doubling frequency, amplitudes
// scaled by roughness, normalised by their sum; a fractional detail blends in one more octave.
float fractal_noise(Vec3f p, float detail, float roughness) {
  float scale = 1.0f, amplitude = 1.0f, total = 0.0f, sum = 0.0f;
  detail = std::clamp(detail, 0.0f, 15.0f);
  roughness = std::clamp(roughness, 0.0f, 1.0f);
  const int n = int(detail);
  for (int i = 0; i <= n; ++i) {
    sum += unsigned_noise(p * scale) * amplitude;
    total += amplitude;
    amplitude *= roughness;
    scale *= 2.0f;
  }
  const float rest = detail - std::floor(detail);
  if (rest == 0.0f) return sum / total;
  const float more = sum + unsigned_noise(p * scale) * amplitude;
  return (1.0f - rest) * (sum / total) + rest * (more / (total + amplitude));
}

// Cycles' random_float3_offset(seed): a fixed point in [100, 200]^3 per seed, where the Color
// output and the distortion read the noise so that their channels are independent.
Vec3f seed_offset(float seed) {
  const uint32_t s = std::bit_cast<uint32_t>(seed);
  auto h = [&](float k) {
    return 100.0f + float(hash_words(s, std::bit_cast<uint32_t>(k))) / float(0xFFFFFFFFu) * 100.0f;
  };
  return {h(0.0f), h(1.0f), h(2.0f)};
}

}  // namespace

uint32_t hash_words(uint32_t a, uint32_t b) {
  const uint32_t init = 0xdeadbeefu + (2u << 2) + 13u;
  return final_mix(init + a, init + b, init);
}

uint32_t hash_words(uint32_t a, uint32_t b, uint32_t c) {
  const uint32_t init = 0xdeadbeefu + (3u << 2) + 13u;
  return final_mix(init + a, init + b, init + c);
}

float signed_noise(Vec3f p) {
  const float r = perlin(p.x, p.y, p.z);
  return 0.9820f * (std::isfinite(r) ? r : 0.0f);
}

float checker_texture(Vec3f p) {
  // Nudged off the cell borders, as Cycles does, so that integer coordinates (a unit plane at
  // scale 1) do not flicker between cells.
  const auto index = [](float x) {
    return int(std::fabs(std::floor((x + 0.000001f) * 0.999999f)));
  };
  const int xi = index(p.x), yi = index(p.y), zi = index(p.z);
  return ((xi % 2 == yi % 2) == (zi % 2 != 0)) ? 1.0f : 0.0f;
}

NoiseTextureResult noise_texture(Vec3f p, float detail, float roughness, float distortion,
                                 bool color) {
  if (distortion != 0.0f)
    p += Vec3f(signed_noise(p + seed_offset(0.0f)), signed_noise(p + seed_offset(1.0f)),
               signed_noise(p + seed_offset(2.0f))) *
         distortion;
  NoiseTextureResult r;
  r.fac = fractal_noise(p, detail, roughness);
  r.color = Spectrum(r.fac);
  if (color)
    r.color = {r.fac, fractal_noise(p + seed_offset(3.0f), detail, roughness),
               fractal_noise(p + seed_offset(4.0f), detail, roughness)};
  return r;
}

}  // namespace gdpt
