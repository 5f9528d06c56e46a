#include "integrators/gpt/shadow_rays.h"

#include <cmath>
#include <limits>

namespace gdpt {

bool occluded(const GptContext& g, const Vertex& v, const Vec3f& dir, float t_max, uint32_t kind,
              uint32_t& rays) {
  ++rays;
  return g.ctx.bvh().occluded(shadow_ray(v, dir, t_max, kind));
}

bool lamp_visible(const GptContext& g, const Vertex& v, const LightSample& ls, const Vec3f& dir,
                  float distance, bool infinite, ClosureSet& scratch, Spectrum& le,
                  uint32_t& rays) {
  if (!ls.cast_shadow) return true;  // Light::cast_shadow off: no shadow ray
  const float t_max = infinite ? std::numeric_limits<float>::infinity() : distance * (1.0f - 1e-4f);
  if (ls.is_delta && g.transparent_shadows) {
    const Spectrum tr = g.ctx.transmittance(shadow_ray(v, dir, t_max, kRayShadow), scratch, rays);
    le *= tr;
    return !is_black(tr);
  }
  return !occluded(g, v, dir, t_max, kRayShadow, rays);
}

}  // namespace gdpt
