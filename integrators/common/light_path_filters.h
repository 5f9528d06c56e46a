// Cycles' Light Paths > Caustics rules (kernel/integrator/surface_shader.h and svm_closure.h in
// Cycles 3.4), applied to the closures of a vertex from the state of the path arriving there
// (PathState::min_ray_pdf, PathState::diffuse_ray). PT and G-PT's base and offset paths call the
// same rule; G-PT's offsets take the base's path state, so base and offset shade a vertex they
// share, or their corresponding vertices, with the same lobes.
//  - Filter Glossy (blur_glossy > 0): after a bounce whose sampling density was low (diffuse,
//    rough glossy), glossy lobes are roughened: GGX alpha raised to sqrt(1 - pdf / blur) / 2,
//    where pdf is the lowest BSDF sampling density along the path (delta bounces not counted).
//  - Caustics off: after a diffuse bounce (the last scattering, transparent crossings aside),
//    glossy reflection lobes (reflective) and refraction lobes (refractive) are dropped. A glass
//    lobe (Glass BSDF, Principled transmission: Cycles' two closures, reflection weighted by F
//    and refraction by 1 - F, in one lobe) loses its reflected or refracted part, or all of it
//    when both are off; a Multiscatter GGX glass lobe (Closure::multiscatter: Cycles' single
//    random-walk closure) is kept whole unless both are off.
// Smooth glass (Sharp, or GGX at roughness 0) is blurred like any glossy lobe, as Cycles 3.4
// does with Filter Glossy on, except on a shadow caustics caster (`sharp_caster`): manifold NEE
// connects through it smooth, and BSDF sampling must take the same chain.
#pragma once

#include <cmath>
#include <limits>

#include "integrators/common/path_state.h"
#include "scene/render_settings.h"
#include "shaders/bsdf.h"
#include "shaders/microfacet.h"

namespace gdpt {

class LightPathFilters {
 public:
  LightPathFilters() = default;
  explicit LightPathFilters(const RenderSettings& s)
      : inv_blur_(s.blur_glossy > 0.0f ? 1.0f / s.blur_glossy
                                       : std::numeric_limits<float>::infinity()),
        reflective_(s.caustics_reflective),
        refractive_(s.caustics_refractive) {}

  // Whether the rule may change any closures at all (off: Filter Glossy 0 and caustics on).
  bool enabled() const { return std::isfinite(inv_blur_) || !reflective_ || !refractive_; }

  // The GGX alpha glossy lobes are raised to at a vertex reached with `state` (0: none).
  float blur_alpha(const PathState& state) const {
    if (!std::isfinite(inv_blur_)) return 0.0f;
    const float blur_pdf = inv_blur_ * state.min_ray_pdf;
    return blur_pdf < 1.0f ? 0.5f * std::sqrt(1.0f - blur_pdf) : 0.0f;
  }
  bool drops_reflection(const PathState& state) const { return state.diffuse_ray && !reflective_; }
  bool drops_refraction(const PathState& state) const { return state.diffuse_ray && !refractive_; }
  // Whether apply() would change a set at a vertex reached with `state`.
  bool active(const PathState& state) const {
    return blur_alpha(state) > 0.0f || drops_reflection(state) || drops_refraction(state);
  }

  // Rewrites `set` (a copy the caller owns) for a vertex reached with `state`; `sharp_caster`:
  // the vertex is on a shadow caustics caster (SceneContext::is_sharp_caster).
  void apply(const PathState& state, ClosureSet& set, bool sharp_caster) const {
    const float blur = blur_alpha(state);
    const bool no_reflection = drops_reflection(state), no_refraction = drops_refraction(state);
    for (int i = set.count() - 1; i >= 0; --i) {
      Closure& c = set.lobe(i);
      const Kind kind = kind_of(c);
      if ((kind == Kind::Reflection && no_reflection) ||
          (kind == Kind::Refraction && no_refraction) ||
          (kind == Kind::Glass && no_reflection && no_refraction)) {
        set.remove(i);
        continue;
      }
      if (kind == Kind::Glass && !c.multiscatter) {
        c.drop_reflection = no_reflection;
        c.drop_refraction = no_refraction;
      }
      if (kind == Kind::Other ||
          (sharp_caster && kind != Kind::Reflection && is_delta_alpha(c.alpha)))
        continue;
      if (c.alpha < blur) c.alpha = blur;
      if (is_anisotropic(c) && c.alpha_y < blur) c.alpha_y = blur;  // Cycles raises both widths
    }
  }

 private:
  enum class Kind { Reflection, Refraction, Glass, Other };
  static Kind kind_of(const Closure& c) {
    switch (c.type) {
      case ClosureType::GGXReflection:
      case ClosureType::GGXMultiscatter:
      case ClosureType::Clearcoat:
        return Kind::Reflection;
      case ClosureType::GGXDielectric:
        return c.fresnel == FresnelMode::RefractionOnly ? Kind::Refraction : Kind::Glass;
      default:
        return Kind::Other;
    }
  }

  float inv_blur_ = std::numeric_limits<float>::infinity();
  bool reflective_ = true, refractive_ = true;
};

}  // namespace gdpt
