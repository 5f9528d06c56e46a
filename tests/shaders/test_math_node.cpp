// Blender's Math and Vector Math nodes (shaders/math_node.h, vector_math_node.h) against closed
// forms: each operation at ordinary operands, and Cycles' conventions where an operation is
// undefined (0, or a clamped argument).
#include <gtest/gtest.h>

#include <cmath>

#include "shaders/math_node.h"
#include "shaders/vector_math_node.h"

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

void expect_vec(Vec3f got, Vec3f want, float tol = 1e-6f) {
  EXPECT_NEAR(got.x, want.x, tol);
  EXPECT_NEAR(got.y, want.y, tol);
  EXPECT_NEAR(got.z, want.z, tol);
}

TEST(VectorMathNode, EveryOperation) {
  const Vec3f a(1.0f, -2.0f, 3.0f), b(0.5f, 4.0f, -1.0f), c(0.25f, 0.0f, 2.0f);
  float value = -1.0f;
  auto v = [&](VectorMathOp op, Vec3f x = Vec3f(1.0f, -2.0f, 3.0f),
               Vec3f y = Vec3f(0.5f, 4.0f, -1.0f),
               float scale = 2.0f) { return vector_math_node(op, x, y, c, scale, value); };
  expect_vec(v(VectorMathOp::Add), Vec3f(1.5f, 2.0f, 2.0f));
  expect_vec(v(VectorMathOp::Subtract), Vec3f(0.5f, -6.0f, 4.0f));
  expect_vec(v(VectorMathOp::Multiply), Vec3f(0.5f, -8.0f, -3.0f));
  expect_vec(v(VectorMathOp::Divide, a, Vec3f(2.0f, 0.0f, -1.0f)), Vec3f(0.5f, 0.0f, -3.0f));
  expect_vec(v(VectorMathOp::MultiplyAdd), Vec3f(0.75f, -8.0f, -1.0f));
  expect_vec(v(VectorMathOp::CrossProduct), cross(a, b));
  EXPECT_FLOAT_EQ(value, 0.0f);  // vector operations leave the Value at 0
  // Project a onto b: b (a.b / b.b) = b (-10.5 / 17.25).
  expect_vec(v(VectorMathOp::Project), b * (-10.5f / 17.25f));
  // Reflect about the plane of normal z: z negated.
  expect_vec(v(VectorMathOp::Reflect, a, Vec3f(0.0f, 0.0f, 2.0f)), Vec3f(1.0f, -2.0f, -3.0f));
  // Refract straight down through z with eta 1: unchanged; total internal reflection: 0.
  expect_vec(v(VectorMathOp::Refract, Vec3f(0.0f, 0.0f, -1.0f), Vec3f(0.0f, 0.0f, 1.0f), 1.0f),
             Vec3f(0.0f, 0.0f, -1.0f));
  expect_vec(v(VectorMathOp::Refract, normalize(Vec3f(1.0f, 0.0f, -0.2f)), Vec3f(0, 0, 1), 1.5f),
             Vec3f(0.0f));
  // Snell at eta 0.5 from 60 degrees: sin 30 degrees... sin_t = 0.5 sin 60.
  const Vec3f in(std::sin(1.0471976f), 0.0f, -std::cos(1.0471976f));
  const Vec3f t = v(VectorMathOp::Refract, in, Vec3f(0, 0, 1), 0.5f);
  EXPECT_NEAR(t.x, 0.5f * std::sin(1.0471976f), 1e-6f);
  EXPECT_NEAR(length(t), 1.0f, 1e-6f);
  // Faceforward: a when c faces against b, else -a.
  expect_vec(
      vector_math_node(VectorMathOp::Faceforward, a, Vec3f(0, 0, 1), Vec3f(0, 0, -1), 0.0f, value),
      a);
  expect_vec(
      vector_math_node(VectorMathOp::Faceforward, a, Vec3f(0, 0, 1), Vec3f(0, 0, 1), 0.0f, value),
      -a);
  v(VectorMathOp::DotProduct);
  EXPECT_FLOAT_EQ(value, -10.5f);
  v(VectorMathOp::Distance);
  EXPECT_FLOAT_EQ(value, std::sqrt(0.25f + 36.0f + 16.0f));
  v(VectorMathOp::Length);
  EXPECT_FLOAT_EQ(value, std::sqrt(14.0f));
  EXPECT_TRUE(vector_math_gives_value(VectorMathOp::Length));
  EXPECT_FALSE(vector_math_gives_value(VectorMathOp::Scale));
  expect_vec(v(VectorMathOp::Scale), Vec3f(2.0f, -4.0f, 6.0f));
  expect_vec(v(VectorMathOp::Normalize), a / std::sqrt(14.0f));
  expect_vec(v(VectorMathOp::Normalize, Vec3f(0.0f)), Vec3f(0.0f));
  // Component-wise: the Math node's operation per component (c the third operand).
  expect_vec(v(VectorMathOp::Snap, Vec3f(5.5f, -0.5f, 3.0f), Vec3f(2.0f, 2.0f, 0.0f)),
             Vec3f(4.0f, -2.0f, 0.0f));
  expect_vec(v(VectorMathOp::Floor, Vec3f(1.5f, -1.5f, 2.0f)), Vec3f(1.0f, -2.0f, 2.0f));
  expect_vec(v(VectorMathOp::Ceil, Vec3f(1.5f, -1.5f, 2.0f)), Vec3f(2.0f, -1.0f, 2.0f));
  expect_vec(v(VectorMathOp::Modulo, Vec3f(5.5f, -5.5f, 1.0f), Vec3f(2.0f, 2.0f, 0.0f)),
             Vec3f(1.5f, -1.5f, 0.0f));
  // Wrap into [c, b): 5.5 into [0.25, 3), -2 into [0, 4), 1 with max 1 and min 2 (range -1).
  expect_vec(v(VectorMathOp::Wrap, Vec3f(5.5f, -2.0f, 1.0f), Vec3f(3.0f, 4.0f, 1.0f)),
             Vec3f(2.75f, 2.0f, 2.0f));
  expect_vec(v(VectorMathOp::Fraction, Vec3f(1.25f, -1.25f, 0.0f)), Vec3f(0.25f, 0.75f, 0.0f));
  expect_vec(v(VectorMathOp::Absolute), Vec3f(1.0f, 2.0f, 3.0f));
  expect_vec(v(VectorMathOp::Minimum), Vec3f(0.5f, -2.0f, -1.0f));
  expect_vec(v(VectorMathOp::Maximum), Vec3f(1.0f, 4.0f, 3.0f));
  expect_vec(v(VectorMathOp::Sine), Vec3f(std::sin(1.0f), std::sin(-2.0f), std::sin(3.0f)));
  expect_vec(v(VectorMathOp::Cosine), Vec3f(std::cos(1.0f), std::cos(-2.0f), std::cos(3.0f)));
  expect_vec(v(VectorMathOp::Tangent), Vec3f(std::tan(1.0f), std::tan(-2.0f), std::tan(3.0f)),
             1e-5f);
}

}  // namespace
}  // namespace gdpt
