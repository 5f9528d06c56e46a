// One-node materials shared by the integrator, light and gradient tests.
#pragma once

#include "scene/material_desc.h"

namespace gdpt::test {

// A material made of one BSDF node (Diffuse, Glossy, Glass, Principled, Transparent).
inline MaterialDesc single_node(ShaderNodeKind kind, Spectrum color, float roughness = 0.0f,
                                float ior = 1.45f) {
  MaterialDesc m;
  ShaderNode n;
  n.kind = kind;
  n.color = ColorInput(color);
  n.roughness = FloatInput(roughness);
  n.ior = FloatInput(ior);
  m.nodes.push_back(n);
  m.root = 0;
  return m;
}

// Blender's Emission shader alone: radiance = colour * strength.
inline MaterialDesc emission_material(Spectrum color, float strength) {
  MaterialDesc m;
  m.name = "emission";
  ShaderNode n;
  n.kind = ShaderNodeKind::Emission;
  n.color = ColorInput(color);
  n.strength = FloatInput(strength);
  m.nodes.push_back(n);
  m.root = 0;
  return m;
}

}  // namespace gdpt::test
