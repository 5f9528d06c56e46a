// The operations and options of Blender's shader nodes, as plain data that scene/material_desc.h
// stores and shaders/ evaluates (math_node.h, vector_math_node.h, procedural_texture.h).
#pragma once

#include <cstdint>

namespace gdpt {

enum class MathOp : uint8_t {
  Add,
  Subtract,
  Multiply,
  Divide,
  MultiplyAdd,
  Power,
  Logarithm,
  Sqrt,
  InverseSqrt,
  Absolute,
  Exponent,
  Minimum,
  Maximum,
  LessThan,
  GreaterThan,
  Sign,
  Compare,
  SmoothMin,
  SmoothMax,
  Round,
  Floor,
  Ceil,
  Trunc,
  Fract,
  Modulo,
  Wrap,
  Snap,
  PingPong,
  Sine,
  Cosine,
  Tangent,
  Arcsine,
  Arccosine,
  Arctangent,
  Arctan2,
  Sinh,
  Cosh,
  Tanh,
  Radians,
  Degrees,
};

enum class VectorMathOp : uint8_t {
  Add,
  Subtract,
  Multiply,
  Divide,
  MultiplyAdd,
  CrossProduct,
  Project,
  Reflect,
  Refract,
  Faceforward,
  DotProduct,
  Distance,
  Length,
  Scale,
  Normalize,
  Snap,
  Floor,
  Ceil,
  Modulo,
  Wrap,
  Fraction,
  Absolute,
  Minimum,
  Maximum,
  Sine,
  Cosine,
  Tangent,
};

enum class VoronoiMetric : uint8_t { Euclidean, Manhattan, Chebyshev, Minkowski };

enum class GradientType : uint8_t {
  Linear,
  Quadratic,
  Easing,
  Diagonal,
  Spherical,
  QuadraticSphere,
  Radial
};

struct WaveDesc {
  enum class Type : uint8_t { Bands, Rings } type = Type::Bands;
  // Bands: X, Y, Z, Diagonal; rings: X, Y, Z, Spherical.
  enum class Direction : uint8_t { X, Y, Z, Other } direction = Direction::X;
  enum class Profile : uint8_t { Sine, Saw, Triangle } profile = Profile::Sine;
};

enum class MusgraveType : uint8_t {
  Fbm,
  Multifractal,
  HeteroTerrain,
  HybridMultifractal,
  RidgedMultifractal
};

// Blender's Vector Transform node: what the vector is (a point moves with the translation, a
// normal with the inverse transpose) and the spaces it converts between.
struct VectorTransformDesc {
  enum class Type : uint8_t { Point, Vector, Normal } type = Type::Vector;
  enum class Space : uint8_t { World, Object, Camera };
  Space from = Space::World, to = Space::Object;
};

// The microfacet distribution of Blender's Glossy, Glass and Refraction BSDFs
// (shaders/microfacet.h); AshikhminShirley: Glossy and Anisotropic only
// (shaders/ashikhmin_shirley.h); MultiscatterGGX: Glossy, Glass and Principled only, GGX plus its
// multiple-scattering lobe (shaders/bsdf_ggx_multiscatter.h) or, on glass, GGX scaled to conserve
// energy (Closure::multiscatter); never a Closure's distribution.
enum class MicrofacetDistribution : uint8_t { GGX, Beckmann, AshikhminShirley, MultiscatterGGX };

struct BrickDesc {
  float offset = 0.5f;
  int offset_frequency = 2;
  float squash = 1.0f;
  int squash_frequency = 2;
};

}  // namespace gdpt
