// Where a path stands in Cycles' light-path rules (kernel/integrator/path_state.h): bounce and
// transparent-crossing counts, the per-kind limits, whether it is still the camera path, and a
// Russian roulette decided at one bounce that takes effect past the next hit. PT and G-PT's base
// path keep one each.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>

#include "core/vec.h"
#include "integrators/common/bounce_limits.h"
#include "integrators/common/russian_roulette.h"
#include "render/film.h"
#include "render/sampler.h"
#include "render/scene_context.h"
#include "scene/render_settings.h"

namespace gdpt {

struct PathState {
  int bounce = 0;           // scattering events (Cycles' bounces), transparent crossings excluded
  int transparent = 0;      // straight transparent crossings (Cycles' transparent bounces)
  BounceCounts kinds;       // scattering events by kind, for the per-kind limits
  bool camera_path = true;  // nothing but transparent crossings since the camera
  uint8_t lobe = 0;         // LobeFlags of the last scattering event (0 on the camera path)
  // A roulette that takes effect past the next hit (roulette_past_next_hit): stopped, that hit
  // is the path's last; survived, what follows the hit's emission is divided by rr_divide.
  bool rr_stop = false;
  float rr_divide = 1.0f;
  // For Cycles' Filter Glossy and caustics rules (light_path_filters.h): the lowest BSDF
  // sampling density of the path's scattering events (delta ones aside), and whether the last
  // scattering event was diffuse (Cycles' PATH_RAY_DIFFUSE; transparent crossings keep both).
  float min_ray_pdf = std::numeric_limits<float>::infinity();
  bool diffuse_ray = false;

  // Past the limits the next surface only ends the path: emission and MIS there, no light
  // sample, no scattering.
  bool last(const RenderSettings& s) const {
    return rr_stop || bounce > s.max_bounces || transparent > kMaxTransparentBounces ||
           kinds.over(s);
  }

  // Counts the event that spawned the next ray: a straight transparent crossing is no bounce,
  // counts for no per-kind limit and keeps the camera-path status.
  void count_event(bool crossing, uint32_t ray_kind, uint8_t event_lobe) {
    if (crossing) {
      ++transparent;
      return;
    }
    ++bounce;
    kinds.add(ray_kind);
    camera_path = false;
    lobe = event_lobe;
  }

  // What the Light Path node sees at the next surface, reached by a segment of `ray_length`.
  PathView view(float ray_length) const {
    PathView v;
    v.lobe = lobe;
    v.ray_length = ray_length;
    v.depth = int16_t(bounce);
    v.diffuse_depth = int16_t(kinds.diffuse);
    v.glossy_depth = int16_t(kinds.glossy);
    v.transmission_depth = int16_t(kinds.transmission);
    v.transparent_depth = int16_t(transparent);
    return v;
  }

  // The BSDF sample of a scattering event (not a transparent crossing), after count_event().
  void scattered(const BsdfSample& bs) {
    diffuse_ray = (bs.lobe & kLobeDiffuse) != 0;
    if (!bs.is_delta()) min_ray_pdf = std::min(min_ray_pdf, bs.pdf);
  }

  // The roulette after a real bounce (count_event() already called) of throughput `beta` that
  // sampled `lobe` at vertex `vertex`. Returns the continuation probability to divide by now
  // (1: nothing to do) or 0 when the path stops here; a decision past the next hit sets rr_stop
  // or rr_divide instead. Either order is unbiased, as long as survivors match stopped paths.
  float roulette(const RenderSettings& s, uint32_t scene_features, Spectrum beta, uint32_t lobe,
                 const Sampler& sampler, int vertex) {
    if (bounce - 1 < s.rr_depth) return 1.0f;
    const float q = roulette_continuation(beta);
    if (q >= 1.0f) return 1.0f;
    const bool past_next_hit = roulette_past_next_hit(lobe, scene_features);
    const bool survive = sampler.get1d(Sampler::bounce_dim(vertex, Sampler::kRoulette)) < q;
    if (past_next_hit) {
      if (survive)
        rr_divide = q;
      else
        rr_stop = true;  // the last ray, for the lamp, emitter or world it may find
      return 1.0f;
    }
    return survive ? q : 0.0f;
  }

  // After the emission at the end of a segment: the division a survived deferred roulette owes
  // (1 when none).
  float take_deferred_division() {
    const float q = rr_divide;
    rr_divide = 1.0f;
    return q;
  }

  // Film > Transparent: a camera path that escapes or ends at a holdout covers the pixel by what
  // its transparent crossings took (Cycles' alpha).
  void set_alpha(const RenderSettings& s, Spectrum beta, float& alpha) const {
    if (camera_path && s.transparent_background) alpha = uncovered_alpha(beta);
  }
};

// A holdout met by the camera path ends it as an escape into a black world would (Cycles).
inline bool holdout_ends_path(const SceneContext& ctx, bool camera_path, const SurfaceHit& hit) {
  return camera_path && ctx.has_holdout() && ctx.is_holdout(hit);
}

// The end of a path's last segment only ends it: unless something reads the hit (emissive
// triangles, a holdout test, an offset's shift) the distance alone is traced.
inline bool distance_only(bool last, bool hit_read) {
  return last && !hit_read;
}

}  // namespace gdpt
