// Small fixed-size vectors used everywhere in the core. Plain structs, no SIMD
// types in the interface: Embree does the wide work, the shading code is scalar.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace gdpt {

struct Vec2f {
  float x = 0.0f, y = 0.0f;
  constexpr Vec2f() = default;
  constexpr Vec2f(float x_, float y_) : x(x_), y(y_) {}
  constexpr Vec2f operator+(Vec2f o) const { return {x + o.x, y + o.y}; }
  constexpr Vec2f operator-(Vec2f o) const { return {x - o.x, y - o.y}; }
  constexpr Vec2f operator*(float s) const { return {x * s, y * s}; }
  constexpr float operator[](int i) const { return i == 0 ? x : y; }
};

struct Vec3f {
  float x = 0.0f, y = 0.0f, z = 0.0f;
  constexpr Vec3f() = default;
  constexpr explicit Vec3f(float s) : x(s), y(s), z(s) {}
  constexpr Vec3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}

  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr Vec3f operator-() const { return {-x, -y, -z}; }
  constexpr Vec3f operator+(Vec3f o) const { return {x + o.x, y + o.y, z + o.z}; }
  constexpr Vec3f operator-(Vec3f o) const { return {x - o.x, y - o.y, z - o.z}; }
  constexpr Vec3f operator*(Vec3f o) const { return {x * o.x, y * o.y, z * o.z}; }
  constexpr Vec3f operator/(Vec3f o) const { return {x / o.x, y / o.y, z / o.z}; }
  constexpr Vec3f operator*(float s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3f operator/(float s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3f& operator+=(Vec3f o) {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  constexpr Vec3f& operator-=(Vec3f o) {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  constexpr Vec3f& operator*=(Vec3f o) {
    x *= o.x;
    y *= o.y;
    z *= o.z;
    return *this;
  }
  constexpr Vec3f& operator*=(float s) {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
  constexpr Vec3f& operator/=(float s) {
    x /= s;
    y /= s;
    z /= s;
    return *this;
  }
  constexpr bool operator==(const Vec3f&) const = default;
};

constexpr Vec3f operator*(float s, Vec3f v) {
  return v * s;
}

constexpr float dot(Vec3f a, Vec3f b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3f cross(Vec3f a, Vec3f b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
constexpr float length_squared(Vec3f v) {
  return dot(v, v);
}
inline float length(Vec3f v) {
  return std::sqrt(dot(v, v));
}
inline Vec3f normalize(Vec3f v) {
  return v / length(v);
}
inline Vec3f abs(Vec3f v) {
  return {std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)};
}
constexpr Vec3f min(Vec3f a, Vec3f b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
constexpr Vec3f max(Vec3f a, Vec3f b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
constexpr float max_component(Vec3f v) {
  return std::max(v.x, std::max(v.y, v.z));
}
constexpr float min_component(Vec3f v) {
  return std::min(v.x, std::min(v.y, v.z));
}
// Branch-free: 0 * x is +-0 for finite x and NaN for infinite or NaN x, so the sum is 0 exactly
// when all three are finite (the film tests every path's radiance).
constexpr bool is_finite(Vec3f v) {
  return v.x * 0.0f + v.y * 0.0f + v.z * 0.0f == 0.0f;
}
constexpr Vec3f lerp(Vec3f a, Vec3f b, float t) {
  return a * (1.0f - t) + b * t;
}
// Clamped to [0, 1] (per component): Cycles' saturatef / saturate.
constexpr float saturate(float x) {
  return x < 0.0f ? 0.0f : (x > 1.0f ? 1.0f : x);
}
constexpr Vec3f saturate(Vec3f v) {
  return {saturate(v.x), saturate(v.y), saturate(v.z)};
}

// Colour: linear RGB in the scene-linear space of the Blender file (Rec.709 primaries by default).
using Spectrum = Vec3f;

// Rec.709 / sRGB luminance weights, as Blender's default OCIO config.
constexpr float luminance(Spectrum c) {
  return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z;
}
constexpr bool is_black(Spectrum c) {
  return c.x == 0.0f && c.y == 0.0f && c.z == 0.0f;
}

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;
inline constexpr float kInv4Pi = 0.07957747154594766788f;

}  // namespace gdpt
