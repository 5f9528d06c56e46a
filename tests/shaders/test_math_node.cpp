// Blender's Math node (shaders/math_node.h) against closed forms: each operation at ordinary
// operands, and Cycles' conventions where an operation is undefined (0, or a clamped argument).
#include <gtest/gtest.h>

#include <cmath>

#include "shaders/math_node.h"

namespace gdpt {
namespace {

float m(MathOp op, float a, float b = 0.0f, float c = 0.0f) {
  return math_node(op, a, b, c);
}

TEST(MathNode, ArithmeticAndPowers) {
  EXPECT_FLOAT_EQ(m(MathOp::Add, 0.2f, 0.3f), 0.5f);
  EXPECT_FLOAT_EQ(m(MathOp::Subtract, 0.9f, 0.3f), 0.6f);
  EXPECT_FLOAT_EQ(m(MathOp::Multiply, 0.5f, 0.6f), 0.3f);
  EXPECT_FLOAT_EQ(m(MathOp::Divide, 0.3f, 0.6f), 0.5f);
  EXPECT_FLOAT_EQ(m(MathOp::Divide, 0.3f, 0.0f), 0.0f);
  EXPECT_FLOAT_EQ(m(MathOp::MultiplyAdd, 2.0f, 3.0f, 0.5f), 6.5f);
  EXPECT_FLOAT_EQ(m(MathOp::Power, 0.25f, 0.5f), 0.5f);
  EXPECT_FLOAT_EQ(m(MathOp::Power, -2.0f, 3.0f), -8.0f);  // integer exponent of a negative base
  EXPECT_FLOAT_EQ(m(MathOp::Power, -2.0f, 0.5f), 0.0f);   // undefined: 0
  EXPECT_FLOAT_EQ(m(MathOp::Logarithm, 8.0f, 2.0f), 3.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Logarithm, -8.0f, 2.0f), 0.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Logarithm, 8.0f, 1.0f), 0.0f);  // log base 1: division by 0
  EXPECT_FLOAT_EQ(m(MathOp::Sqrt, 2.25f), 1.5f);
  EXPECT_FLOAT_EQ(m(MathOp::Sqrt, -4.0f), 0.0f);
  EXPECT_FLOAT_EQ(m(MathOp::InverseSqrt, 4.0f), 0.5f);
  EXPECT_FLOAT_EQ(m(MathOp::InverseSqrt, 0.0f), 0.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Absolute, -1.5f), 1.5f);
  EXPECT_FLOAT_EQ(m(MathOp::Exponent, 1.0f), std::exp(1.0f));
}

TEST(MathNode, ComparisonsAndSmoothExtrema) {
  EXPECT_FLOAT_EQ(m(MathOp::Minimum, 0.25f, 0.5f), 0.25f);
  EXPECT_FLOAT_EQ(m(MathOp::Maximum, 0.25f, 0.5f), 0.5f);
  EXPECT_FLOAT_EQ(m(MathOp::LessThan, 0.2f, 0.5f), 1.0f);
  EXPECT_FLOAT_EQ(m(MathOp::LessThan, 0.5f, 0.5f), 0.0f);
  EXPECT_FLOAT_EQ(m(MathOp::GreaterThan, 0.7f, 0.5f), 1.0f);
  EXPECT_FLOAT_EQ(m(MathOp::GreaterThan, 0.5f, 0.5f), 0.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Sign, -3.0f), -1.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Sign, 0.0f), 0.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Sign, 2.0f), 1.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Compare, 1.0f, 1.05f, 0.1f), 1.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Compare, 1.0f, 1.2f, 0.1f), 0.0f);
  // Smooth minimum of distance k: min(a, b) - h^3 k / 6, h = max(k - |a - b|, 0) / k; equal
  // operands lose k / 6, operands k apart are untouched; the maximum mirrors it.
  EXPECT_FLOAT_EQ(m(MathOp::SmoothMin, 1.0f, 1.0f, 0.6f), 0.9f);
  EXPECT_FLOAT_EQ(m(MathOp::SmoothMin, 1.0f, 1.6f, 0.6f), 1.0f);
  EXPECT_NEAR(m(MathOp::SmoothMin, 1.0f, 1.3f, 0.6f), 1.0f - 0.125f * 0.1f, 1e-6f);
  EXPECT_FLOAT_EQ(m(MathOp::SmoothMin, 1.0f, 2.0f, 0.0f), 1.0f);
  EXPECT_FLOAT_EQ(m(MathOp::SmoothMax, 1.0f, 1.0f, 0.6f), 1.1f);
}

TEST(MathNode, Rounding) {
  EXPECT_FLOAT_EQ(m(MathOp::Round, 2.5f), 3.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Round, -2.5f), -2.0f);  // floor(a + 0.5)
  EXPECT_FLOAT_EQ(m(MathOp::Floor, -1.2f), -2.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Ceil, -1.2f), -1.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Trunc, -1.7f), -1.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Trunc, 1.7f), 1.0f);
  EXPECT_NEAR(m(MathOp::Fract, -1.25f), 0.75f, 1e-6f);        // a - floor(a): always in [0, 1)
  EXPECT_NEAR(m(MathOp::Modulo, -5.5f, 2.0f), -1.5f, 1e-6f);  // C's fmod: the sign of a
  EXPECT_FLOAT_EQ(m(MathOp::Modulo, 5.5f, 0.0f), 0.0f);
  EXPECT_NEAR(m(MathOp::Wrap, 5.5f, 2.0f, 1.0f), 1.5f, 1e-6f);  // into [min 1, max 2)
  EXPECT_NEAR(m(MathOp::Wrap, -0.25f, 1.0f, 0.0f), 0.75f, 1e-6f);
  EXPECT_FLOAT_EQ(m(MathOp::Wrap, 5.5f, 1.0f, 1.0f), 1.0f);  // empty range: the minimum
  EXPECT_FLOAT_EQ(m(MathOp::Snap, 5.5f, 2.0f), 4.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Snap, -0.5f, 2.0f), -2.0f);
  EXPECT_FLOAT_EQ(m(MathOp::Snap, 5.5f, 0.0f), 0.0f);
  // Ping-pong of scale 2: 0 -> 2 -> 0 -> 2 ...
  EXPECT_NEAR(m(MathOp::PingPong, 1.5f, 2.0f), 1.5f, 1e-6f);
  EXPECT_NEAR(m(MathOp::PingPong, 2.5f, 2.0f), 1.5f, 1e-6f);
  EXPECT_NEAR(m(MathOp::PingPong, 4.5f, 2.0f), 0.5f, 1e-6f);
  EXPECT_NEAR(m(MathOp::PingPong, -0.5f, 2.0f), 0.5f, 1e-6f);
  EXPECT_FLOAT_EQ(m(MathOp::PingPong, 4.5f, 0.0f), 0.0f);
}

TEST(MathNode, Trigonometry) {
  const float pi = 3.14159265f;
  EXPECT_NEAR(m(MathOp::Sine, pi / 6), 0.5f, 1e-6f);
  EXPECT_NEAR(m(MathOp::Cosine, pi / 3), 0.5f, 1e-6f);
  EXPECT_NEAR(m(MathOp::Tangent, pi / 4), 1.0f, 1e-6f);
  EXPECT_NEAR(m(MathOp::Arcsine, 0.5f), pi / 6, 1e-6f);
  EXPECT_NEAR(m(MathOp::Arcsine, 2.0f), pi / 2, 1e-6f);  // argument clamped to [-1, 1]
  EXPECT_NEAR(m(MathOp::Arccosine, -2.0f), pi, 1e-6f);
  EXPECT_NEAR(m(MathOp::Arctangent, 1.0f), pi / 4, 1e-6f);
  EXPECT_NEAR(m(MathOp::Arctan2, 1.0f, -1.0f), 3 * pi / 4, 1e-6f);  // atan2(a, b)
  EXPECT_NEAR(m(MathOp::Sinh, 1.0f), 0.5f * (std::exp(1.0f) - std::exp(-1.0f)), 1e-6f);
  EXPECT_NEAR(m(MathOp::Cosh, 1.0f), 0.5f * (std::exp(1.0f) + std::exp(-1.0f)), 1e-6f);
  EXPECT_NEAR(m(MathOp::Tanh, 1.0f), std::tanh(1.0f), 1e-7f);
  EXPECT_NEAR(m(MathOp::Radians, 180.0f), pi, 1e-6f);
  EXPECT_NEAR(m(MathOp::Degrees, pi), 180.0f, 1e-4f);
}

}  // namespace
}  // namespace gdpt
