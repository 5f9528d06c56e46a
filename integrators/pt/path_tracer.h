// Unidirectional path tracer: next-event estimation and BSDF sampling combined by the power
// heuristic (delta lights and delta lobes take the only technique that can produce them), Russian
// roulette, Cycles' max_bounces semantics and an optional sample clamp.
//
// Bounce semantics (Cycles' max_bounces with the per-type limits set high): the camera ray's hit
// is vertex 0. Vertices 0..max_bounces sample lights and the BSDF; vertex max_bounces + 1 (and an
// escape after it) only adds the emission the last BSDF ray found, MIS-weighted. max_bounces = 0
// is therefore direct lighting.
//
// Film outputs: emission seen by the camera ray (emissive surfaces and the world) goes to the
// emission accumulator (the Emission pass, never shifted); everything else to primal.
// Analytic lights with a surface (sphere, area, sun disc) are visible to camera rays, as in Cycles
// 3.x (lights_intersect runs for camera rays unless the object's camera visibility is off).
//
// Specialisation: the kernel is a template over the scene features that change per-sample work
// (depth of field, world lookups, analytic-light intersection, emissive triangles, transparent
// shadows); one of the 32 instantiations is chosen per session from SceneContext::features().
//
// Transparency (Transparent BSDF, Principled alpha) as Cycles: crossings are not bounces, keep the
// camera-path status and the MIS state; shadow rays are attenuated by the surfaces they cross.
#pragma once

#include <cstdint>
#include <string>

#include "integrators/integrator.h"

namespace gdpt {

// Features the path tracer kernel is specialised on (a subset of features.h bits).
uint32_t path_tracer_specialised_features(uint32_t scene_features);

}  // namespace gdpt
