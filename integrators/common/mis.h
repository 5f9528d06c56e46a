// Multiple importance sampling between next-event estimation and BSDF sampling (Veach 1997).
#pragma once

namespace gdpt {

// Power heuristic (exponent 2) with one sample per technique: a^2 / (a^2 + b^2), 0 when both are
// 0. It beats the balance heuristic where one technique is far better (small lights, glossy).
inline float power_heuristic(float a, float b) {
  const float a2 = a * a, b2 = b * b;
  return a2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

}  // namespace gdpt
