// The G-PT's pair weights beyond shift_mapping.h's mis_weight_over_pdf: the light density the
// weights see, and the event part of a merged (connected or dead) offset's weight.
#pragma once

#include "integrators/gpt/shift_mapping.h"

namespace gdpt {

// Event part of the pair weight for a merged offset (add_merged in offset_path.h): Y p_tech /
// (p_L^2 + p_B^2), 0 when both densities are 0 (mis_weight_over_pdf's zero denominator).
inline shift::Vec3d connected_event(shift::Vec3d y, double p_tech, double p_light, double p_bsdf) {
  const double d = p_light * p_light + p_bsdf * p_bsdf;
  return d > 0.0 ? y * (p_tech / d) : shift::Vec3d();
}

// Light-technique density of a light point in the pair weights: for an area light the density
// of uniform area sampling, area_pdf d^2 / cos_l (d the distance from the vertex, cos_l the
// cosine at the light), whichever way sample() picks the point from that vertex (the spherical
// rectangle where the light subtends more than 0.1 sr); the sampling density `pdf` for every
// other light. The power heuristic's weights of a path pair's four techniques sum to one for
// any such density function of the pair's vertices, as long as all four use the same one: the
// base's light technique is then weighted by p_mis^2 / pdf instead of p_mis (light_tech()).
// The offsets' light densities then need neither an intersection with the light nor the
// spherical rectangle's solid angle from their own vertex.
inline float mis_light_pdf(float area_pdf, float pdf, float d, float cos_l) {
  return area_pdf > 0.0f ? area_pdf * (d * d) / cos_l : pdf;
}

// The technique term of a light sample drawn with density `pdf` and weighted with `p_mis`:
// mis_weight_over_pdf(..., light_tech(...)) = w / (p pdf) with w the heuristic of p_mis.
inline double light_tech(float p_mis, float pdf) {
  return p_mis == pdf ? double(pdf) : double(p_mis) * double(p_mis) / double(pdf);
}

}  // namespace gdpt
