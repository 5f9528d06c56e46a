// Blender's Math node as Cycles 3.4 computes it (svm_math, kernel/svm/math_util.h, with the safe
// helpers of util/math_float.h): undefined results are 0 (division, modulo and snap by 0, the
// power of a negative base to a non-integer, logarithms of non-positive values, the inverse
// square root of a non-positive value), square roots and arc sines / cosines clamp their argument
// into the domain. Three operands: c is used by Multiply Add, Compare (epsilon), Smooth Minimum /
// Maximum (distance) and Wrap (minimum).
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdint>

#include "scene/node_types.h"

namespace gdpt {

namespace math_node_detail {
inline float safe_divide(float a, float b) {
  return b != 0.0f ? a / b : 0.0f;
}
// Cycles' smoothminf: the polynomial smooth minimum of distance k.
inline float smooth_min(float a, float b, float k) {
  if (k == 0.0f) return std::fmin(a, b);
  const float h = std::fmax(k - std::fabs(a - b), 0.0f) / k;
  return std::fmin(a, b) - h * h * h * k * (1.0f / 6.0f);
}
inline float fract(float x) {
  return x - std::floor(x);
}
}  // namespace math_node_detail

inline float math_node(MathOp op, float a, float b, float c) {
  using namespace math_node_detail;
  constexpr float kPiF = 3.14159265358979323846f;
  switch (op) {
    case MathOp::Add:
      return a + b;
    case MathOp::Subtract:
      return a - b;
    case MathOp::Multiply:
      return a * b;
    case MathOp::Divide:
      return safe_divide(a, b);
    case MathOp::MultiplyAdd:
      return a * b + c;
    case MathOp::Power:
      if (a < 0.0f && b != std::trunc(b)) return 0.0f;
      return std::pow(a, b);
    case MathOp::Logarithm:
      if (a <= 0.0f || b <= 0.0f) return 0.0f;
      return safe_divide(std::log(a), std::log(b));
    case MathOp::Sqrt:
      return std::sqrt(std::fmax(a, 0.0f));
    case MathOp::InverseSqrt:
      return a > 0.0f ? 1.0f / std::sqrt(a) : 0.0f;
    case MathOp::Absolute:
      return std::fabs(a);
    case MathOp::Exponent:
      return std::exp(a);
    case MathOp::Minimum:
      return std::fmin(a, b);
    case MathOp::Maximum:
      return std::fmax(a, b);
    case MathOp::LessThan:
      return a < b ? 1.0f : 0.0f;
    case MathOp::GreaterThan:
      return a > b ? 1.0f : 0.0f;
    case MathOp::Sign:
      return a == 0.0f ? 0.0f : a < 0.0f ? -1.0f : 1.0f;
    case MathOp::Compare:
      return a == b || std::fabs(a - b) <= std::fmax(c, FLT_EPSILON) ? 1.0f : 0.0f;
    case MathOp::SmoothMin:
      return smooth_min(a, b, c);
    case MathOp::SmoothMax:
      return -smooth_min(-a, -b, c);
    case MathOp::Round:
      return std::floor(a + 0.5f);
    case MathOp::Floor:
      return std::floor(a);
    case MathOp::Ceil:
      return std::ceil(a);
    case MathOp::Trunc:
      return a >= 0.0f ? std::floor(a) : std::ceil(a);
    case MathOp::Fract:
      return fract(a);
    case MathOp::Modulo:
      return b != 0.0f ? std::fmod(a, b) : 0.0f;
    case MathOp::Wrap: {  // into [c, b)
      const float range = b - c;
      return range != 0.0f ? a - range * std::floor((a - c) / range) : c;
    }
    case MathOp::Snap:
      return std::floor(safe_divide(a, b)) * b;
    case MathOp::PingPong:
      return b != 0.0f ? std::fabs(fract((a - b) / (b * 2.0f)) * b * 2.0f - b) : 0.0f;
    case MathOp::Sine:
      return std::sin(a);
    case MathOp::Cosine:
      return std::cos(a);
    case MathOp::Tangent:
      return std::tan(a);
    case MathOp::Arcsine:
      return std::asin(std::clamp(a, -1.0f, 1.0f));
    case MathOp::Arccosine:
      return std::acos(std::clamp(a, -1.0f, 1.0f));
    case MathOp::Arctangent:
      return std::atan(a);
    case MathOp::Arctan2:
      return std::atan2(a, b);
    case MathOp::Sinh:
      return std::sinh(a);
    case MathOp::Cosh:
      return std::cosh(a);
    case MathOp::Tanh:
      return std::tanh(a);
    case MathOp::Radians:
      return a * (kPiF / 180.0f);
    case MathOp::Degrees:
      return a * (180.0f / kPiF);
  }
  return 0.0f;
}

}  // namespace gdpt
