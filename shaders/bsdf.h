// The BSDF interface shared by PT and G-PT: a shading point's material evaluates to a ClosureSet,
// a weighted sum of BSDF lobes (like Cycles' closures), sampled and evaluated in the local shading
// frame (normal = +z).
//
// Lobe conventions (wi, wo, eval, pdf, delta lobes, roughness) are in closure.h. A set made of a
// single Lambert lobe, the commonest, is evaluated and sampled inline, without the mixture code.
#pragma once

#include "core/vec.h"
#include "shaders/bsdf_lambert.h"
#include "shaders/closure.h"

namespace gdpt {

// At most kMaxClosures lobes per shading point: fixed storage, no allocation in the hot loop.
inline constexpr int kMaxClosures = 8;

class ClosureSet {
 public:
  void clear() {
    count_ = 0;
    emission_ = Spectrum(0.0f);
    shadowing_ = false;
    own_frames_ = false;
    terminator_k_ = 1.0f;
  }
  // Becomes a copy of `other` (only its live lobes are copied: cheaper than assignment).
  void assign(const ClosureSet& other) {
    count_ = other.count_;
    for (int i = 0; i < count_; ++i) closures_[i] = other.closures_[i];
    emission_ = other.emission_;
    shadowing_ = other.shadowing_;
    unperturbed_ = other.unperturbed_;
    own_frames_ = other.own_frames_;
    interpolated_ = other.interpolated_;
    ng_ = other.ng_;
    terminator_k_ = other.terminator_k_;
  }
  // Cycles' bump shadowing (Conty Estevez et al. 2019, Cycles 3.4's bump_shadowing_term): at a
  // point whose shading normal a normal map or bump replaced, the diffuse lobes' values (not
  // their densities) are scaled by a smooth cut-off of directions that the unperturbed normal
  // would see at a grazing angle, which hides the bump terminator. `unperturbed`: the interpolated
  // normal in the local frame (the perturbed one is +z).
  void set_bump_shadowing(Vec3f unperturbed) {
    shadowing_ = true;
    unperturbed_ = unperturbed;
  }
  // Cycles' shadow terminator shading offset of the object (core/shadow_terminator.h): every
  // lobe's value (not its density) towards a direction above the lobe's normal is scaled by
  // terminator_shading_factor of frequency k. k <= 1 leaves the set as it is.
  void set_terminator_shift(float k) {
    if (!(k > 1.0f)) return;
    terminator_k_ = k;
    shadowing_ = true;  // off the single-Lambert fast path
  }
  // Whether a lobe keeps the interpolated normal under a normal map or bump
  // (Closure::interpolated_normal).
  bool has_interpolated_normal_lobes() const {
    for (int i = 0; i < count_; ++i)
      if (closures_[i].interpolated_normal) return true;
    return false;
  }
  // From now on those lobes are evaluated in their own frame about `n` (unit, local: the shading
  // frame's +z is the perturbed normal); `ng`: the geometric normal facing wi, local. Each lobe
  // then decides reflection against transmission about its own normal and contributes only
  // where that agrees with the side of the geometric surface wo is on (Cycles decides per
  // closure), and side_ok() leaves the decision to the lobes.
  void set_interpolated_normal(Vec3f n, Vec3f ng) {
    own_frames_ = true;
    interpolated_ = n;
    ng_ = ng;
    // Off the single-Lambert fast path (which tests shadowing_ alone); the shadowing factor of
    // the default unperturbed normal (+z) is 1.
    shadowing_ = true;
  }
  bool has_own_frames() const { return own_frames_; }
  // Whether wo (local; cos_ng: its cosine with the geometric normal facing wi) may carry light:
  // reflection and transmission must agree between the shading frame and the geometric
  // surface, or light leaks through it. Integrators test this before eval() and after sample().
  bool side_ok(Vec3f wo, float cos_ng) const {
    // With own frames the lobes decide, inside eval / pdf / sample.
    return ((cos_ng > 0.0f) == (wo.z > 0.0f) || own_frames_) && cos_ng != 0.0f;
  }
  // Adds a lobe; weights that are zero are dropped; a full set drops the lobe of least weight.
  void add(const Closure& c);
  void add_emission(Spectrum e) { emission_ += e; }

  int count() const { return count_; }
  const Closure& operator[](int i) const { return closures_[i]; }
  // For the integrators' light-path rules (integrators/common/light_path_filters.h), which
  // roughen or drop lobes of a copy: lobe i, and its removal (the others keep their order).
  Closure& lobe(int i) { return closures_[i]; }
  void remove(int i) {
    for (int k = i + 1; k < count_; ++k) closures_[k - 1] = closures_[k];
    --count_;
  }
  Spectrum emission() const { return emission_; }
  bool has_bsdf() const { return count_ > 0; }
  // Sum of the Transparent closures' weights: what passes straight through the surface (Cycles'
  // shader transparency; 1 - it is the surface's coverage).
  Spectrum transparency() const {
    Spectrum t(0.0f);
    for (int i = 0; i < count_; ++i)
      if (closures_[i].type == ClosureType::Transparent) t += closures_[i].weight;
    return t;
  }

  Spectrum eval(Vec3f wi, Vec3f wo) const {
    return single_lambert() ? lambert::eval(closures_[0], wi, wo) : eval_mixture(wi, wo);
  }
  // The bump shadowing factor of direction wo (1 without set_bump_shadowing).
  float diffuse_shadowing(Vec3f wo) const;
  // The factors the lobes' values take towards wo (bump shadowing, terminator shift).
  struct Attenuation {
    float diffuse = 1.0f;    // bump shadowing, diffuse lobes about the shading normal
    float shift = 1.0f;      // terminator shift about the shading normal (+z)
    float shift_own = 1.0f;  // terminator shift about the interpolated normal (own frames)
  };
  Attenuation attenuation(Vec3f wo) const;
  float pdf(Vec3f wi, Vec3f wo) const {
    return single_lambert() ? lambert::pdf(closures_[0], wi, wo) : pdf_mixture(wi, wo);
  }
  // eval() and pdf() of the same directions in one call (same values, one pass over the lobes),
  // for integrators that need both, e.g. next-event estimation and G-PT's shifted vertices.
  Spectrum eval_pdf(Vec3f wi, Vec3f wo, float& pdf_out) const {
    if (!single_lambert()) return eval_pdf_mixture(wi, wo, pdf_out);
    pdf_out = lambert::pdf(closures_[0], wi, wo);
    return lambert::eval(closures_[0], wi, wo);
  }
  // u_lobe picks the lobe (by weight luminance), u the direction within it.
  BsdfSample sample(Vec3f wi, float u_lobe, Vec2f u) const {
    return single_lambert() ? lambert::sample(closures_[0], wi, u_lobe, u)
                            : sample_mixture(wi, u_lobe, u);
  }
  // The delta lobes' discrete event `event` (kLobeReflection or kLobeTransmission) from wi as
  // one event: the direction they send wi in, the sum of their values and of their selection
  // times event probabilities, as sample() returns it for any of them. Invalid when no delta lobe
  // has that event or when the lobes that have it send wi in different directions. G-PT's shift
  // of a delta event evaluates it at the offset vertex (no lobe number: integrators/gpt).
  BsdfSample delta_event(Vec3f wi, uint8_t event) const;
  // Whether sample() reads u_lobe at all: only to pick among several lobes or, for a single
  // dielectric, reflection against refraction. Integrators skip drawing it otherwise.
  bool uses_lobe_choice() const {
    return count_ > 1 || (count_ == 1 && closures_[0].type == ClosureType::GGXDielectric);
  }
  // The world tangent of the first anisotropic lobe, which the shading frame's x axis follows
  // (shading_frame() in integrators/common/surface_frame.h); false without one.
  bool anisotropic_tangent(Vec3f& tangent) const {
    for (int i = 0; i < count_; ++i)
      if (is_anisotropic(closures_[i])) {
        tangent = closures_[i].tangent;
        return true;
      }
    return false;
  }
  // Whether an anisotropic lobe has a tangent other than the first one's.
  bool has_own_tangents() const;
  // Turns each anisotropic lobe whose tangent is not the first one's by the angle from the
  // shading frame's x axis to its own tangent projected onto the frame's tangent plane (Cycles'
  // make_orthonormals_tangent per closure), and gives it the first one's tangent: the lobes then
  // hold their orientation relative to `frame`, and a second call changes nothing.
  void orient_own_tangents(const Frame& frame);
  // Minimum roughness over non-delta lobes (1 for pure diffuse); 0 if only delta lobes.
  float roughness() const;
  bool has_delta() const;

 private:
  // The inline fast path (bump shadowing goes through the mixture code).
  bool single_lambert() const {
    return count_ == 1 && closures_[0].type == ClosureType::Lambert && !shadowing_;
  }
  // With own frames: whether lobe c may carry light towards wo (see set_interpolated_normal).
  bool lobe_side_ok(const Closure& c, Vec3f wi, Vec3f wo) const;
  // The mixture code with (kFramed) or without own frames (closure_set.cpp).
  template <bool kFramed>
  Spectrum eval_mixture_t(Vec3f wi, Vec3f wo) const;
  template <bool kFramed>
  float pdf_mixture_t(Vec3f wi, Vec3f wo) const;
  template <bool kFramed>
  Spectrum eval_pdf_mixture_t(Vec3f wi, Vec3f wo, float& pdf_out) const;
  template <bool kFramed>
  BsdfSample sample_mixture_t(Vec3f wi, float u_lobe, Vec2f u) const;
  template <bool kFramed>
  BsdfSample sample_single_t(Vec3f wi, float u_lobe, Vec2f u) const;  // count_ == 1
  template <bool kFramed>
  BsdfSample sample_several_t(Vec3f wi, float u_lobe, Vec2f u) const;  // count_ > 1
  template <bool kFramed>
  BsdfSample delta_event_t(Vec3f wi, uint8_t event) const;
  // Adds to `s`, the delta event of lobe k, the other delta lobes that send wi the same way
  // (selection weights w, their sum total).
  template <bool kFramed>
  void add_same_delta_events(int k, Vec3f wi, const float* w, float total, BsdfSample& s) const;
  template <bool kFramed>
  BsdfSample lobe_delta_event(int i, Vec3f wi, uint8_t event) const;
  // A delta lobe's value towards wo with the terminator shift about the lobe's normal.
  template <bool kFramed>
  Spectrum delta_shifted(const Closure& c, Spectrum value, Vec3f wo) const;
  // Any set (the same values as the fast path for a single Lambert lobe).
  Spectrum eval_mixture(Vec3f wi, Vec3f wo) const;
  float pdf_mixture(Vec3f wi, Vec3f wo) const;
  Spectrum eval_pdf_mixture(Vec3f wi, Vec3f wo, float& pdf_out) const;
  BsdfSample sample_mixture(Vec3f wi, float u_lobe, Vec2f u) const;

  Closure closures_[kMaxClosures];
  int count_ = 0;
  Spectrum emission_{0.0f, 0.0f, 0.0f};
  bool shadowing_ = false;
  Vec3f unperturbed_{0.0f, 0.0f, 1.0f};
  // set_interpolated_normal: the frame normal of the interpolated_normal lobes, and ng.
  bool own_frames_ = false;
  Vec3f interpolated_{0.0f, 0.0f, 1.0f};
  Vec3f ng_{0.0f, 0.0f, 1.0f};
  float terminator_k_ = 1.0f;  // set_terminator_shift
};

}  // namespace gdpt
