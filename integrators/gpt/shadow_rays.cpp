#include "integrators/gpt/shadow_rays.h"

namespace gdpt {

bool lamp_visible(const GptContext& g, const Vertex& v, const LightSample& ls,
                  const LightSample& seen, ClosureSet& scratch, Spectrum& le, uint32_t& rays) {
  if (!ls.cast_shadow) return true;  // Light::cast_shadow off: no shadow ray
  const Ray ray = light_ray_from(g.ctx.bvh(), v, seen.direction, seen.position, seen.is_infinite);
  if (ls.is_delta && g.transparent_shadows) {
    const Spectrum tr = g.ctx.transmittance(ray, scratch, rays);
    le *= tr;
    return !is_black(tr);
  }
  return !occluded(g, ray, rays);
}

}  // namespace gdpt
