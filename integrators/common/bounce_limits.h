// Cycles' per-kind bounce limits (Light Paths > Max Bounces > Diffuse / Glossy / Transmission):
// once a path has scattered more often than a kind's limit allows, its next surface only ends it
// (emission and MIS there, no light sample, no scattering), as past the total limit
// (RenderSettings::max_bounces). Events count by the kind of ray they spawn (ray_kind_of_lobe);
// straight transparent crossings count for none.
#pragma once

#include <cstdint>

#include "scene/render_settings.h"
#include "scene/scene.h"

namespace gdpt {

struct BounceCounts {
  int diffuse = 0, glossy = 0, transmission = 0;

  void add(uint32_t kind) {
    diffuse += kind == kRayDiffuse;
    glossy += kind == kRayGlossy;
    transmission += kind == kRayTransmission;
  }
  bool over(const RenderSettings& s) const {
    return diffuse > s.max_diffuse_bounces || glossy > s.max_glossy_bounces ||
           transmission > s.max_transmission_bounces;
  }
};

}  // namespace gdpt
