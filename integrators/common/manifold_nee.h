// Manifold next-event estimation (Hanika, Droske and Fascione 2015): Cycles' Shadow Caustics.
//
// Light that reaches a diffuse surface through smooth glass (a lamp focused by a glass ball onto
// the floor) is found by path tracing only when a BSDF sample happens to leave through the glass
// towards the lamp: rare, bright paths, the speckles of a caustic. Here a light sample of a lamp
// with Shadow Caustics, taken at a surface of a caustics receiver, whose straight segment crosses
// caustics casters, seeds a Newton walk on the specular manifold: the caster vertices move
// until every one refracts by Snell's law between its neighbours, and the path so found carries
// the lamp's light with its generalized geometry term (the density of the light point mapped
// through the refractions).
//
// Settings, as in Cycles (Blender 3.4):
//  - Object > Shading > Caustics > Cast Shadow Caustics (Instance::caustics_caster): a
//    refractive object: its material a single smooth Glass or Refraction BSDF (else no
//    connection), its normals those the walk follows (interpolated corner normals).
//  - ... > Receive Shadow Caustics (Instance::caustics_receiver): where the light samples run it.
//  - Light > Shadow Caustics (Light::caustics_light): area lamps only here (Cycles also takes
//    point, spot and sun lamps and the world).
// A path that left a receiver by a non-delta BSDF sample, then only refracted through casters and
// met a caustics lamp, is also one the walk from its receiver may find: the two techniques share
// it by multiple importance sampling (power heuristic in the light point's area measure), so
// where the geometry term spikes (the caustic's folds) BSDF sampling takes over. Paths the walk
// does not find (several refracted paths join the two points, or a chain of another number of
// interfaces) stay with BSDF sampling alone, so every path counts once. Filter Glossy leaves the
// casters sharp (light_path_filters.h). Without Refractive Caustics manifold NEE carries the
// chains alone and every such BSDF-sampled path is dropped, as Cycles does always.
#pragma once

#include <cmath>
#include <cstdint>

#include "core/vec.h"
#include "integrators/common/path_state.h"
#include "render/embree_scene.h"
#include "render/lights/light_sample.h"
#include "render/scene_context.h"
#include "shaders/bsdf.h"

namespace gdpt {

inline constexpr int kMaxCausticCasters = 4;

// A caustic path from a receiver point to a light point through caster refractions.
struct CausticConnection {
  Vec3f direction;  // unit, world: from the receiver towards the first caster vertex
  // Caster transmittances x lamp radiance x the generalized geometry term d omega / d A(y): the
  // path's contribution per unit area of the light point, the receiver's BSDF aside.
  Spectrum transport{0.0f};
  float solid_angle_per_area = 0.0f;  // d omega / d A(y) at the receiver: the geometry term
  float refraction_pdf = 1.0f;        // BSDF sampling's chance to refract at every caster vertex
  int casters = 0;                    // casters on the straight segment (the seed), found or not
  bool valid = false;
};

// How manifold NEE and BSDF sampling share the caustic paths leaving a receiver, fixed where the
// path leaves it (from the path state before that bounce).
struct CausticShare {
  // BSDF sampling takes the smooth chains manifold NEE connects: false without refractive
  // caustics; then Cycles' rule (see above).
  bool mis = false;
  // Casters a BSDF-sampled path leaving the receiver may refract through and still meet a lamp
  // (Cycles' bounce limits, counted as if the receiver's own bounce were of every kind).
  int reach = 0;
};
CausticShare caustic_share(const PathState& before, const RenderSettings& s);

// Manifold NEE's MIS weight for the connection `c` from a receiver of geometric normal `ng_x`,
// its light point sampled with area density `area_pdf` (LightSample::area_pdf, the same from every
// vertex). BSDF sampling's density is a cosine-weighted receiver's |cos| / pi times the chance
// to refract at every caster and the geometry term: a function of the path's points alone, so a
// G-PT base and the offsets that share its chain weigh it alike.
float manifold_nee_weight(const CausticConnection& c, const CausticShare& share, float area_pdf,
                          Vec3f ng_x);

// Whether the light sample `ls` taken at `hit` runs manifold NEE.
inline bool runs_shadow_caustics(const SceneContext& ctx, const SurfaceHit& hit,
                                 const LightSample& ls) {
  return ctx.shadow_caustics() && ls.caustics && ls.area_pdf > 0.0f &&
         ctx.is_caustics_receiver(hit);
}

// The density per unit area of the light point of `ls`, sampled from the receiver along the
// straight segment (solid-angle density times cos_l / d^2).
inline float light_area_density(const LightSample& ls) {
  return ls.pdf * std::fabs(dot(ls.direction, ls.normal)) / (ls.distance * ls.distance);
}

// The caustic path from the receiver point `x` (geometric normal `ng_x`, on the side the light
// is sampled from) to the light point of `ls` (an area lamp sampled from x): found when the
// straight segment crosses casters and the walk converges to a valid, unoccluded chain.
// `scratch` holds the casters' closures; `rays` counts the rays traced.
CausticConnection caustic_connection(const SceneContext& ctx, Vec3f x, Vec3f ng_x,
                                     const LightSample& ls, ClosureSet& scratch, uint32_t& rays);

// The BSDF side of the rule that keeps the estimates apart. A path that left a receiver by a
// non-delta BSDF sample, refracted through casters only and met a caustics lamp is also manifold
// NEE's when the walk from that receiver to the point it met finds this very path (the same
// first direction): it then takes the complement of manifold_nee_weight(). Where the walk finds
// another path or none (several refracted paths join the two points), BSDF sampling keeps it
// whole: every path is counted once. One per path, updated at every scattering vertex.
struct CausticChain {
  uint8_t state = 0;   // 0: none; 1: just left a receiver; 2: refracted through casters since
  CausticShare share;  // as fixed when it left the receiver
  Vec3f receiver, receiver_ng, direction;  // the receiver point, its side, the direction left

  // The event `bs` at `hit`, leaving in the world direction `wo` (any length); `share` is
  // caustic_share() of the path state before the event.
  void scattered(const SceneContext& ctx, const SurfaceHit& hit, const BsdfSample& bs, Vec3f wo,
                 const CausticShare& from_here) {
    if (!ctx.shadow_caustics()) return;
    const bool refraction = bs.is_delta() && (bs.lobe & kLobeTransmission) != 0 && bs.eta != 1.0f;
    if (refraction && ctx.is_caustics_caster(hit)) {
      state = state != 0 ? 2 : 0;
    } else if (!bs.is_delta() && ctx.is_caustics_receiver(hit)) {
      state = 1;
      share = from_here;
      receiver = hit.position;
      receiver_ng =
          dot(wo, hit.geometric_normal) > 0.0f ? hit.geometric_normal : -hit.geometric_normal;
      direction = normalize(wo);
    } else {
      state = 0;
    }
  }
  // The weight of the light of the lamp point `lh` met now: 1 unless manifold NEE shares it
  // (`scratch` holds the casters' closures of the walk, `rays` counts its rays).
  float weight(const SceneContext& ctx, const LightHit& lh, ClosureSet& scratch,
               uint32_t& rays) const;
};

}  // namespace gdpt
