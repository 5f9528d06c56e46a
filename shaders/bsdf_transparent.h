// Transparent BSDF: light passes straight through (wo = -wi), scaled by the colour. A delta lobe:
// eval and pdf are 0, sample() returns value = weight, pdf = 1.
#pragma once

#include "shaders/closure.h"

namespace gdpt::transparent {

inline Spectrum eval(const Closure&, Vec3f, Vec3f) {
  return Spectrum(0.0f);
}

inline float pdf(const Closure&, Vec3f, Vec3f) {
  return 0.0f;
}

inline BsdfSample sample(const Closure& c, Vec3f wi, float, Vec2f) {
  BsdfSample s;
  s.wo = -wi;
  s.value = c.weight;
  s.pdf = 1.0f;
  s.eta = 1.0f;
  s.roughness = 0.0f;
  s.lobe = kLobeTransmission | kLobeDelta;
  s.valid = true;
  return s;
}

inline float albedo_hint(const Closure&, Vec3f) {
  return 1.0f;
}

}  // namespace gdpt::transparent
