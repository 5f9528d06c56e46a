// Blender's Vector Math node as Cycles 3.4 computes it (svm_vector_math,
// kernel/svm/vector_math.h): a, b, c the three vector inputs, `scale` the float input (Scale;
// IOR for Refract). Dot Product, Distance and Length give a Value (written to `value`, the
// Vector output is then 0); every other operation a Vector. Component-wise operations share the
// Math node's definitions and safe conventions (math_node.h).
#pragma once

#include <cmath>
#include <cstdint>

#include "core/vec.h"
#include "scene/node_types.h"
#include "shaders/math_node.h"

namespace gdpt {

// Whether the operation's result is the Value output.
inline bool vector_math_gives_value(VectorMathOp op) {
  return op == VectorMathOp::DotProduct || op == VectorMathOp::Distance ||
         op == VectorMathOp::Length;
}

inline Vec3f vector_math_node(VectorMathOp op, Vec3f a, Vec3f b, Vec3f c, float scale,
                              float& value) {
  value = 0.0f;
  // The Math node's operation on each component.
  auto each = [&](MathOp m) {
    return Vec3f(math_node(m, a.x, b.x, c.x), math_node(m, a.y, b.y, c.y),
                 math_node(m, a.z, b.z, c.z));
  };
  switch (op) {
    case VectorMathOp::Add:
      return a + b;
    case VectorMathOp::Subtract:
      return a - b;
    case VectorMathOp::Multiply:
      return Vec3f(a.x * b.x, a.y * b.y, a.z * b.z);
    case VectorMathOp::Divide:
      return each(MathOp::Divide);
    case VectorMathOp::MultiplyAdd:
      return each(MathOp::MultiplyAdd);
    case VectorMathOp::CrossProduct:
      return cross(a, b);
    case VectorMathOp::Project: {  // a projected onto b
      const float len2 = dot(b, b);
      return len2 != 0.0f ? b * (dot(a, b) / len2) : Vec3f(0.0f);
    }
    case VectorMathOp::Reflect: {  // a mirrored about the plane of normal b
      const float len = length(b);
      if (!(len > 0.0f)) return a;
      const Vec3f n = b / len;
      return a - n * (2.0f * dot(a, n));
    }
    case VectorMathOp::Refract: {  // a through the plane of normal b, eta = scale
      const float len = length(b);
      const Vec3f n = len > 0.0f ? b / len : Vec3f(0.0f);
      const float d = dot(n, a);
      const float k = 1.0f - scale * scale * (1.0f - d * d);
      if (k < 0.0f) return Vec3f(0.0f);
      return a * scale - n * (scale * d + std::sqrt(k));
    }
    case VectorMathOp::Faceforward:  // a, flipped unless c faces against b
      return dot(c, b) < 0.0f ? a : -a;
    case VectorMathOp::DotProduct:
      value = dot(a, b);
      return Vec3f(0.0f);
    case VectorMathOp::Distance:
      value = length(a - b);
      return Vec3f(0.0f);
    case VectorMathOp::Length:
      value = length(a);
      return Vec3f(0.0f);
    case VectorMathOp::Scale:
      return a * scale;
    case VectorMathOp::Normalize: {
      const float len = length(a);
      return len != 0.0f ? a / len : Vec3f(0.0f);
    }
    case VectorMathOp::Snap:
      return each(MathOp::Snap);
    case VectorMathOp::Floor:
      return each(MathOp::Floor);
    case VectorMathOp::Ceil:
      return each(MathOp::Ceil);
    case VectorMathOp::Modulo:
      return each(MathOp::Modulo);
    case VectorMathOp::Wrap:
      return each(MathOp::Wrap);
    case VectorMathOp::Fraction:
      return each(MathOp::Fract);
    case VectorMathOp::Absolute:
      return each(MathOp::Absolute);
    case VectorMathOp::Minimum:
      return each(MathOp::Minimum);
    case VectorMathOp::Maximum:
      return each(MathOp::Maximum);
    case VectorMathOp::Sine:
      return each(MathOp::Sine);
    case VectorMathOp::Cosine:
      return each(MathOp::Cosine);
    case VectorMathOp::Tangent:
      return each(MathOp::Tangent);
  }
  return Vec3f(0.0f);
}

}  // namespace gdpt
