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

// lookup3's two kinds of rounds: x -= z, x ^= rot(z, k), z += y (mix) and x ^= y, x -= rot(y, k)
// (final).
constexpr void mix_round(uint32_t& x, uint32_t y, uint32_t& z, int k) {
  x -= z;
  x ^= rotate(z, k);
  z += y;
}
constexpr void final_round(uint32_t& x, uint32_t y, int k) {
  x ^= y;
  x -= rotate(y, k);
}

// lookup3's final mixing of (a, b, c); the hash is c.
constexpr uint32_t final_mix(uint32_t a, uint32_t b, uint32_t c) {
  final_round(c, b, 14);
  final_round(a, c, 11);
  final_round(b, a, 25);
  final_round(c, b, 16);
  final_round(a, c, 4);
  final_round(b, a, 14);
  final_round(c, b, 24);
  return c;
}

// lookup3's mixing of (a, b, c) between blocks of three words.
constexpr void mix(uint32_t& a, uint32_t& b, uint32_t& c) {
  mix_round(a, b, c, 4);
  mix_round(b, c, a, 6);
  mix_round(c, a, b, 8);
  mix_round(a, b, c, 16);
  mix_round(b, c, a, 19);
  mix_round(c, a, b, 4);
}

constexpr float kHashScale = 1.0f / float(0xFFFFFFFFu);

// A cell's random point in [0, 1)^3 (Cycles' hash_float3_to_float3).
Vec3f cell_random(Vec3f k) {
  const uint32_t x = std::bit_cast<uint32_t>(k.x), y = std::bit_cast<uint32_t>(k.y),
                 z = std::bit_cast<uint32_t>(k.z);
  return {float(hash_words(x, y, z)) * kHashScale,
          float(hash_words(x, y, z, std::bit_cast<uint32_t>(1.0f))) * kHashScale,
          float(hash_words(x, y, z, std::bit_cast<uint32_t>(2.0f))) * kHashScale};
}

float voronoi_distance(Vec3f a, Vec3f b, VoronoiMetric metric, float exponent) {
  const Vec3f d = a - b;
  switch (metric) {
    case VoronoiMetric::Euclidean:
      return length(d);
    case VoronoiMetric::Manhattan:
      return std::fabs(d.x) + std::fabs(d.y) + std::fabs(d.z);
    case VoronoiMetric::Chebyshev:
      return std::max(std::fabs(d.x), std::max(std::fabs(d.y), std::fabs(d.z)));
    case VoronoiMetric::Minkowski:
      return std::pow(std::pow(std::fabs(d.x), exponent) + std::pow(std::fabs(d.y), exponent) +
                          std::pow(std::fabs(d.z), exponent),
                      1.0f / exponent);
  }
  return length(d);
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

// --- Noise in 1, 2 and 4 dimensions (the 3D one above is the common case) ---

// A point of up to four coordinates.
struct Point4 {
  float v[4] = {0.0f, 0.0f, 0.0f, 0.0f};
};

// Dot product of (x, y) with one of Perlin's 2D gradients (8 entries, Cycles' grad2).
inline float gradient2(uint32_t hash, float x, float y) {
  const uint32_t h = hash & 7u;
  const float u = h < 4 ? x : y, v = 2.0f * (h < 4 ? y : x);
  return ((h & 1u) ? -u : u) + ((h & 2u) ? -v : v);
}

// Dot product with one of the 4D gradients (32 entries, Cycles' grad4).
inline float gradient4(uint32_t hash, float x, float y, float z, float w) {
  const uint32_t h = hash & 31u;
  const float u = h < 24 ? x : y, v = h < 16 ? y : z, s = h < 8 ? z : w;
  return ((h & 1u) ? -u : u) + ((h & 2u) ? -v : v) + ((h & 4u) ? -s : s);
}

inline float lerp(float a, float b, float t) {
  return (1.0f - t) * a + t * b;
}

// Perlin noise of dimension n (1, 2 or 4) at p, unscaled.
float perlin_n(int n, const Point4& p) {
  int c[4];
  float f[4], fade_f[4];
  for (int k = 0; k < n; ++k) {
    f[k] = cell(p.v[k], c[k]);
    fade_f[k] = fade(f[k]);
  }
  if (n == 1) {
    auto g = [&](int d) {
      const uint32_t h = hash_words(uint32_t(c[0] + d)) & 15u;
      const float grad = float(1 + (h & 7u));
      return ((h & 8u) ? -grad : grad) * (f[0] - float(d));
    };
    return g(0) + fade_f[0] * (g(1) - g(0));
  }
  if (n == 2) {
    auto g = [&](int dx, int dy) {
      return gradient2(hash_words(uint32_t(c[0] + dx), uint32_t(c[1] + dy)), f[0] - float(dx),
                       f[1] - float(dy));
    };
    const float u = fade_f[0], v = fade_f[1];
    return lerp(lerp(g(0, 0), g(1, 0), u), lerp(g(0, 1), g(1, 1), u), v);
  }
  // 4D: two trilinear blends of 8 corners each, blended along w.
  auto g = [&](int dx, int dy, int dz, int dw) {
    return gradient4(hash_words(uint32_t(c[0] + dx), uint32_t(c[1] + dy), uint32_t(c[2] + dz),
                                uint32_t(c[3] + dw)),
                     f[0] - float(dx), f[1] - float(dy), f[2] - float(dz), f[3] - float(dw));
  };
  const float u = fade_f[0], v = fade_f[1], t = fade_f[2];
  auto tri = [&](int dw) {
    return lerp(
        lerp(lerp(g(0, 0, 0, dw), g(1, 0, 0, dw), u), lerp(g(0, 1, 0, dw), g(1, 1, 0, dw), u), v),
        lerp(lerp(g(0, 0, 1, dw), g(1, 0, 1, dw), u), lerp(g(0, 1, 1, dw), g(1, 1, 1, dw), u), v),
        t);
  };
  return lerp(tri(0), tri(1), fade_f[3]);
}

// Cycles' noise_scale1 / 2 / 4, non-finite results as 0.
float signed_noise_n(int n, const Point4& p) {
  const float scale = n == 1 ? 0.25f : n == 2 ? 0.6616f : 0.8344f;
  const float r = perlin_n(n, p);
  return scale * (std::isfinite(r) ? r : 0.0f);
}

Point4 scaled(int n, Point4 p, float s) {
  for (int k = 0; k < n; ++k) p.v[k] *= s;
  return p;
}

Point4 added(int n, Point4 p, const Point4& q) {
  for (int k = 0; k < n; ++k) p.v[k] += q.v[k];
  return p;
}

// fractal_noise() in dimension n.
float fractal_noise_n(int n, const Point4& p, float detail, float roughness) {
  float scale = 1.0f, amplitude = 1.0f, total = 0.0f, sum = 0.0f;
  detail = std::clamp(detail, 0.0f, 15.0f);
  roughness = std::clamp(roughness, 0.0f, 1.0f);
  const int octaves = int(detail);
  for (int i = 0; i <= octaves; ++i) {
    sum += (0.5f * signed_noise_n(n, scaled(n, p, scale)) + 0.5f) * amplitude;
    total += amplitude;
    amplitude *= roughness;
    scale *= 2.0f;
  }
  const float rest = detail - std::floor(detail);
  if (rest == 0.0f) return sum / total;
  const float more = sum + (0.5f * signed_noise_n(n, scaled(n, p, scale)) + 0.5f) * amplitude;
  return (1.0f - rest) * (sum / total) + rest * (more / (total + amplitude));
}

// Cycles' random_float_offset / random_float2_offset / random_float4_offset of `seed`.
Point4 seed_offset_n(int n, float seed) {
  const uint32_t s = std::bit_cast<uint32_t>(seed);
  Point4 o;
  if (n == 1) {
    o.v[0] = 100.0f + float(hash_words(s)) / float(0xFFFFFFFFu) * 100.0f;
    return o;
  }
  for (int k = 0; k < n; ++k)
    o.v[k] = 100.0f +
             float(hash_words(s, std::bit_cast<uint32_t>(float(k)))) / float(0xFFFFFFFFu) * 100.0f;
  return o;
}

}  // namespace

uint32_t hash_words(uint32_t a) {
  const uint32_t init = 0xdeadbeefu + (1u << 2) + 13u;
  return final_mix(init + a, init, init);
}

uint32_t hash_words(uint32_t a, uint32_t b) {
  const uint32_t init = 0xdeadbeefu + (2u << 2) + 13u;
  return final_mix(init + a, init + b, init);
}

uint32_t hash_words(uint32_t a, uint32_t b, uint32_t c) {
  const uint32_t init = 0xdeadbeefu + (3u << 2) + 13u;
  return final_mix(init + a, init + b, init + c);
}

uint32_t hash_words(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
  const uint32_t init = 0xdeadbeefu + (4u << 2) + 13u;
  uint32_t x = init + a, y = init + b, z = init + c;
  mix(x, y, z);
  x += d;
  return final_mix(x, y, z);
}

// Calls f(offset) for the cells within r of a point's cell, z outermost and x innermost (the
// order of Cycles' loops, which decides ties).
template <class F>
void for_each_cell(int r, F f) {
  for (int k = -r; k <= r; ++k)
    for (int j = -r; j <= r; ++j)
      for (int i = -r; i <= r; ++i) f(Vec3f(float(i), float(j), float(k)));
}

VoronoiResult voronoi_f1(Vec3f p, float randomness, VoronoiMetric metric, float exponent) {
  const Vec3f cell(std::floor(p.x), std::floor(p.y), std::floor(p.z));
  const Vec3f local = p - cell;
  VoronoiResult r;
  float nearest = 8.0f;
  Vec3f nearest_offset(0.0f), nearest_point(0.0f);
  for_each_cell(1, [&](Vec3f offset) {
    const Vec3f point = offset + cell_random(cell + offset) * randomness;
    const float d = voronoi_distance(point, local, metric, exponent);
    if (d < nearest) {
      nearest = d;
      nearest_offset = offset;
      nearest_point = point;
    }
  });
  r.distance = nearest;
  r.color = cell_random(cell + nearest_offset);
  r.position = nearest_point + cell;
  return r;
}

VoronoiResult voronoi_f2(Vec3f p, float randomness, VoronoiMetric metric, float exponent) {
  const Vec3f cell(std::floor(p.x), std::floor(p.y), std::floor(p.z));
  const Vec3f local = p - cell;
  float d1 = 8.0f, d2 = 8.0f;
  Vec3f offset1(0.0f), point1(0.0f), offset2(0.0f), point2(0.0f);
  for_each_cell(1, [&](Vec3f offset) {
    const Vec3f point = offset + cell_random(cell + offset) * randomness;
    const float d = voronoi_distance(point, local, metric, exponent);
    if (d < d1) {  // the former nearest becomes the second
      d2 = d1;
      offset2 = offset1;
      point2 = point1;
      d1 = d;
      offset1 = offset;
      point1 = point;
    } else if (d < d2) {
      d2 = d;
      offset2 = offset;
      point2 = point;
    }
  });
  VoronoiResult r;
  r.distance = d2;
  r.color = cell_random(cell + offset2);
  r.position = point2 + cell;
  return r;
}

VoronoiResult voronoi_smooth_f1(Vec3f p, float smoothness, float randomness, VoronoiMetric metric,
                                float exponent) {
  const Vec3f cell(std::floor(p.x), std::floor(p.y), std::floor(p.z));
  const Vec3f local = p - cell;
  float distance = 8.0f;
  Spectrum color(0.0f);
  Vec3f position(0.0f);
  for_each_cell(2, [&](Vec3f offset) {
    const Vec3f random = cell_random(cell + offset);
    const Vec3f point = offset + random * randomness;
    const float d = voronoi_distance(point, local, metric, exponent);
    // Polynomial smooth minimum: weight h of this point, and the dip that keeps it C1.
    const float x = std::clamp(0.5f + 0.5f * (distance - d) / smoothness, 0.0f, 1.0f);
    const float h = x * x * (3.0f - 2.0f * x);
    float correction = smoothness * h * (1.0f - h);
    distance = distance + (d - distance) * h - correction;
    correction /= 1.0f + 3.0f * smoothness;
    color = color + (random - color) * h - Spectrum(correction);
    position = position + (point - position) * h - Vec3f(correction);
  });
  VoronoiResult r;
  r.distance = distance;
  r.color = color;
  r.position = cell + position;
  return r;
}

float voronoi_distance_to_edge(Vec3f p, float randomness) {
  const Vec3f cell(std::floor(p.x), std::floor(p.y), std::floor(p.z));
  const Vec3f local = p - cell;
  // The nearest point (squared Euclidean distance), then the nearest bisector plane to it.
  Vec3f to_closest(0.0f);
  float nearest = 8.0f;
  for_each_cell(1, [&](Vec3f offset) {
    const Vec3f to_point = offset + cell_random(cell + offset) * randomness - local;
    const float d = dot(to_point, to_point);
    if (d < nearest) {
      nearest = d;
      to_closest = to_point;
    }
  });
  float edge = 8.0f;
  for_each_cell(1, [&](Vec3f offset) {
    const Vec3f to_point = offset + cell_random(cell + offset) * randomness - local;
    const Vec3f across = to_point - to_closest;
    if (dot(across, across) > 0.0001f)
      edge = std::min(edge, dot((to_closest + to_point) / 2.0f, normalize(across)));
  });
  return edge;
}

float gradient_texture(Vec3f p, GradientType type) {
  switch (type) {
    case GradientType::Linear:
      return p.x;
    case GradientType::Quadratic: {
      const float r = std::max(p.x, 0.0f);
      return r * r;
    }
    case GradientType::Easing: {
      const float r = std::clamp(p.x, 0.0f, 1.0f), t = r * r;
      return 3.0f * t - 2.0f * t * r;
    }
    case GradientType::Diagonal:
      return (p.x + p.y) * 0.5f;
    case GradientType::Radial:
      return std::atan2(p.y, p.x) / (2.0f * 3.14159265358979f) + 0.5f;
    case GradientType::Spherical:
    case GradientType::QuadraticSphere: {
      // Just below 1, as Cycles: a point on the unit sphere gives exactly 0.
      const float r = std::max(0.999999f - length(p), 0.0f);
      return type == GradientType::Spherical ? r : r * r;
    }
  }
  return p.x;
}

float wave_texture(Vec3f p, const WaveDesc& wave, float distortion, float detail,
                   float detail_scale, float detail_roughness, float phase) {
  constexpr float kPi = 3.14159265358979f;
  // Nudged off unit coordinates, as Cycles does.
  p = (p + Vec3f(0.000001f)) * 0.999999f;
  using D = WaveDesc::Direction;
  float n;
  if (wave.type == WaveDesc::Type::Bands) {
    n = wave.direction == D::X   ? p.x * 20.0f
        : wave.direction == D::Y ? p.y * 20.0f
        : wave.direction == D::Z ? p.z * 20.0f
                                 : (p.x + p.y + p.z) * 10.0f;
  } else {
    Vec3f r = p;  // rings around an axis drop that axis; spherical rings keep all three
    if (wave.direction == D::X) r.x = 0.0f;
    if (wave.direction == D::Y) r.y = 0.0f;
    if (wave.direction == D::Z) r.z = 0.0f;
    n = length(r) * 20.0f;
  }
  n += phase;
  if (distortion != 0.0f)
    n += distortion * (fractal_noise(p * detail_scale, detail, detail_roughness) * 2.0f - 1.0f);
  switch (wave.profile) {
    case WaveDesc::Profile::Sine:
      return 0.5f + 0.5f * std::sin(n - 0.5f * kPi);
    case WaveDesc::Profile::Saw:
      n /= 2.0f * kPi;
      return n - std::floor(n);
    case WaveDesc::Profile::Triangle:
      n /= 2.0f * kPi;
      return std::fabs(n - std::floor(n + 0.5f)) * 2.0f;
  }
  return 0.0f;
}

float musgrave_texture(Vec3f p, MusgraveType type, float detail, float dimension, float lacunarity,
                       float offset, float gain) {
  dimension = std::max(dimension, 1e-5f);
  detail = std::clamp(detail, 0.0f, 15.0f);
  lacunarity = std::max(lacunarity, 1e-5f);
  const int octaves = int(detail);
  const float rest = detail - std::floor(detail);
  const float step = std::pow(lacunarity, -dimension);  // amplitude ratio between octaves
  switch (type) {
    case MusgraveType::Fbm: {
      float value = 0.0f, amplitude = 1.0f;
      for (int i = 0; i < octaves; ++i) {
        value += signed_noise(p) * amplitude;
        amplitude *= step;
        p *= lacunarity;
      }
      if (rest != 0.0f) value += rest * signed_noise(p) * amplitude;
      return value;
    }
    case MusgraveType::Multifractal: {
      float value = 1.0f, amplitude = 1.0f;
      for (int i = 0; i < octaves; ++i) {
        value *= amplitude * signed_noise(p) + 1.0f;
        amplitude *= step;
        p *= lacunarity;
      }
      if (rest != 0.0f) value *= rest * amplitude * signed_noise(p) + 1.0f;
      return value;
    }
    case MusgraveType::HeteroTerrain: {
      // The first octave unscaled, later ones scaled by the value so far.
      float amplitude = step;
      float value = offset + signed_noise(p);
      p *= lacunarity;
      for (int i = 1; i < octaves; ++i) {
        value += (signed_noise(p) + offset) * amplitude * value;
        amplitude *= step;
        p *= lacunarity;
      }
      if (rest != 0.0f) value += rest * ((signed_noise(p) + offset) * amplitude * value);
      return value;
    }
    case MusgraveType::HybridMultifractal: {
      float amplitude = step;
      float value = signed_noise(p) + offset;
      float weight = gain * value;
      p *= lacunarity;
      for (int i = 1; weight > 0.001f && i < octaves; ++i) {
        weight = std::min(weight, 1.0f);
        const float signal = (signed_noise(p) + offset) * amplitude;
        amplitude *= step;
        value += weight * signal;
        weight *= gain * signal;
        p *= lacunarity;
      }
      if (rest != 0.0f && weight > 0.001f)
        value += rest * std::min(weight, 1.0f) * ((signed_noise(p) + offset) * amplitude);
      return value;
    }
    case MusgraveType::RidgedMultifractal: {
      float amplitude = step;
      float signal = offset - std::fabs(signed_noise(p));
      signal *= signal;
      float value = signal;
      for (int i = 1; i < octaves; ++i) {
        p *= lacunarity;
        const float weight = std::clamp(signal * gain, 0.0f, 1.0f);
        signal = offset - std::fabs(signed_noise(p));
        signal *= signal;
        signal *= weight;
        value += signal * amplitude;
        amplitude *= step;
      }
      return value;
    }
  }
  return 0.0f;
}

namespace {
// The Brick Texture's per-brick value in [0, 1): an integer hash of 31 bits (Cycles'
// brick_noise, unsigned arithmetic wrapping).
float brick_hash(uint32_t n) {
  n = (n + 1013u) & 0x7fffffffu;
  n = (n >> 13) ^ n;
  const uint32_t h = (n * (n * n * 60493u + 19990303u) + 1376312589u) & 0x7fffffffu;
  return 0.5f * (float(h) / 1073741824.0f);
}
}  // namespace

BrickSample brick_texture(Vec3f p, const BrickDesc& b, float mortar_size, float mortar_smooth,
                          float bias, float brick_width, float row_height) {
  const int row = int(std::floor(p.y / row_height));
  float offset = 0.0f;
  if (b.offset_frequency != 0 && b.squash_frequency != 0) {
    // C's remainder (negative for negative rows), as Cycles.
    if (row % b.squash_frequency == 0) brick_width *= b.squash;
    if (row % b.offset_frequency == 0) offset = brick_width * b.offset;
  }
  const int column = int(std::floor((p.x + offset) / brick_width));
  const float x = (p.x + offset) - brick_width * float(column);
  const float y = p.y - row_height * float(row);
  const uint32_t key = (uint32_t(row) << 16) + (uint32_t(column) & 0xffffu);
  BrickSample s;
  s.tint = std::clamp(brick_hash(key) + bias, 0.0f, 1.0f);
  // Distance to the nearest edge of the brick, then the mortar band.
  const float edge = std::min(std::min(x, y), std::min(brick_width - x, row_height - y));
  if (edge >= mortar_size) {
    s.mortar = 0.0f;
  } else if (mortar_smooth == 0.0f) {
    s.mortar = 1.0f;
  } else {
    const float depth = 1.0f - edge / mortar_size;  // 0 at the band's inner edge, 1 at the brick's
    if (depth < mortar_smooth) {
      const float t = depth / mortar_smooth;
      s.mortar = t * t * (3.0f - 2.0f * t);
    } else {
      s.mortar = 1.0f;
    }
  }
  return s;
}

Spectrum magic_texture(Vec3f p, int depth, float distortion) {
  const float d = distortion;
  float x = std::sin((p.x + p.y + p.z) * 5.0f);
  float y = std::cos((-p.x + p.y - p.z) * 5.0f);
  float z = -std::cos((-p.x - p.y + p.z) * 5.0f);
  if (depth > 0) {
    x *= d;
    y *= d;
    z *= d;
  }
  // Each level rewrites one coordinate from all three (Cycles' fixed sequence), then scales it.
  for (int level = 1; level <= std::min(depth, 10); ++level) {
    switch (level) {
      case 1:
        y = -std::cos(x - y + z) * d;
        break;
      case 2:
        x = std::cos(x - y - z) * d;
        break;
      case 3:
        z = std::sin(-x - y - z) * d;
        break;
      case 4:
        x = -std::cos(-x + y - z) * d;
        break;
      case 5:
        y = -std::sin(-x + y + z) * d;
        break;
      case 6:
        y = -std::cos(-x + y + z) * d;
        break;
      case 7:
        x = std::cos(x + y + z) * d;
        break;
      case 8:
        z = std::sin(x + y - z) * d;
        break;
      case 9:
        x = -std::cos(-x - y + z) * d;
        break;
      default:
        y = -std::sin(x - y + z) * d;
        break;
    }
  }
  if (d != 0.0f) {
    x /= 2.0f * d;
    y /= 2.0f * d;
    z /= 2.0f * d;
  }
  return {0.5f - x, 0.5f - y, 0.5f - z};
}

float white_noise(Vec3f p) {
  return cell_random(p).x;
}
Spectrum white_noise_color(Vec3f p) {
  return cell_random(p);
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

NoiseTextureResult noise_texture(int dimensions, Vec3f p, float w, float detail, float roughness,
                                 float distortion, bool color) {
  if (dimensions == 3) return noise_texture(p, detail, roughness, distortion, color);
  const int n = dimensions == 1 ? 1 : dimensions == 2 ? 2 : 4;
  Point4 q;
  if (n == 1) {
    q.v[0] = w;
  } else {
    q.v[0] = p.x;
    q.v[1] = p.y;
    q.v[2] = p.z;
    q.v[3] = w;
  }
  // Distortion: each coordinate displaced by noise at its own seed offset (0, 1, ...); the
  // Color's other channels read the fractal at the next two seeds.
  if (distortion != 0.0f) {
    Point4 d;
    for (int k = 0; k < n; ++k)
      d.v[k] = signed_noise_n(n, added(n, q, seed_offset_n(n, float(k)))) * distortion;
    q = added(n, q, d);
  }
  NoiseTextureResult r;
  r.fac = fractal_noise_n(n, q, detail, roughness);
  r.color = Spectrum(r.fac);
  if (color)
    r.color = {r.fac,
               fractal_noise_n(n, added(n, q, seed_offset_n(n, float(n))), detail, roughness),
               fractal_noise_n(n, added(n, q, seed_offset_n(n, float(n + 1))), detail, roughness)};
  return r;
}

}  // namespace gdpt
