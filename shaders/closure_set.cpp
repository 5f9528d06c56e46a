// ClosureSet: a weighted sum of lobes, evaluated and sampled as one BSDF.
//
// Sampling is one-sample MIS over lobes: a lobe k is chosen with probability s_k proportional
// to luminance(weight_k) * albedo_hint_k(wi), it samples wo, and the returned value and pdf are
// those of the whole mixture, sum_j eval_j and sum_j s_j pdf_j, so that value / pdf agrees with
// eval() / pdf(). A delta lobe's event is summed alike over the delta lobes that send wi the
// same way (value sum_j value_j, pdf sum_j s_j probability_j; delta_event()).
#include <algorithm>

#include "core/frame.h"
#include "core/shadow_terminator.h"
#include "shaders/bsdf.h"
#include "shaders/bsdf_clearcoat.h"
#include "shaders/bsdf_ggx_dielectric.h"
#include "shaders/bsdf_ggx_multiscatter.h"
#include "shaders/bsdf_ggx_reflection.h"
#include "shaders/bsdf_lambert.h"
#include "shaders/bsdf_oren_nayar.h"
#include "shaders/bsdf_principled_diffuse.h"
#include "shaders/bsdf_principled_sheen.h"
#include "shaders/bsdf_translucent.h"
#include "shaders/bsdf_transparent.h"
#include "shaders/bsdf_velvet.h"

namespace gdpt {

namespace {

// Static dispatch on the closure type (a switch keeps everything inlined; no virtual calls).
#define GDPT_DISPATCH(c, call)           \
  switch ((c).type) {                    \
    case ClosureType::Lambert:           \
      return lambert::call;              \
    case ClosureType::OrenNayar:         \
      return oren_nayar::call;           \
    case ClosureType::PrincipledDiffuse: \
      return principled_diffuse::call;   \
    case ClosureType::PrincipledSheen:   \
      return principled_sheen::call;     \
    case ClosureType::GGXReflection:     \
      return ggx_reflection::call;       \
    case ClosureType::GGXMultiscatter:   \
      return ggx_multiscatter::call;     \
    case ClosureType::GGXDielectric:     \
      return ggx_dielectric::call;       \
    case ClosureType::Clearcoat:         \
      return clearcoat::call;            \
    case ClosureType::Transparent:       \
      return transparent::call;          \
    case ClosureType::Translucent:       \
      return translucent::call;          \
    case ClosureType::Velvet:            \
      return velvet::call;               \
  }                                      \
  return {};

Spectrum lobe_eval_local(const Closure& c, Vec3f wi, Vec3f wo) {
  GDPT_DISPATCH(c, eval(c, wi, wo))
}
float lobe_pdf_local(const Closure& c, Vec3f wi,
                     Vec3f wo){GDPT_DISPATCH(c, pdf(c, wi, wo))} BsdfSample
    lobe_sample_local(const Closure& c, Vec3f wi, float u_choice, Vec2f u) {
  GDPT_DISPATCH(c, sample(c, wi, u_choice, u))
}
float lobe_albedo_hint_local(const Closure& c, Vec3f wi){GDPT_DISPATCH(c, albedo_hint(c, wi))}

// The frame of a lobe about its own normal n; an anisotropic lobe's x axis is the shading frame's
// (its tangent) projected onto the plane of n, as Cycles' make_orthonormals_tangent.
Frame lobe_frame(const Closure& c, Vec3f n) {
  if (!is_anisotropic(c)) return Frame(n);
  const Vec3f s = Vec3f(1.0f, 0.0f, 0.0f) - n * n.x;
  const float len2 = length_squared(s);
  if (!(len2 > 1e-12f)) return Frame(n);
  const Vec3f x = s / std::sqrt(len2);
  return Frame(x, cross(n, x), n);
}

// A lobe of a set with own frames: one that keeps the interpolated normal `n` sees wi and wo in
// the frame of n.
Spectrum lobe_eval_framed(const Closure& c, Vec3f n, Vec3f wi, Vec3f wo) {
  if (c.interpolated_normal) {
    const Frame f = lobe_frame(c, n);
    return lobe_eval_local(c, f.to_local(wi), f.to_local(wo));
  }
  return lobe_eval_local(c, wi, wo);
}
float lobe_pdf_framed(const Closure& c, Vec3f n, Vec3f wi, Vec3f wo) {
  if (c.interpolated_normal) {
    const Frame f = lobe_frame(c, n);
    return lobe_pdf_local(c, f.to_local(wi), f.to_local(wo));
  }
  return lobe_pdf_local(c, wi, wo);
}
BsdfSample lobe_sample_framed(const Closure& c, Vec3f n, Vec3f wi, float u_choice, Vec2f u) {
  if (c.interpolated_normal) {
    const Frame f = lobe_frame(c, n);
    const Vec3f wi_local = f.to_local(wi);
    BsdfSample s = lobe_sample_local(c, wi_local, u_choice, u);
    if (!s.valid) return s;
    s.wo = f.to_world(s.wo);
    // Value and density of the direction as returned, rounded through the frame, so that they
    // equal eval() and pdf() there (near the lobe's horizon G1 magnifies the rounding).
    if (!s.is_delta()) {
      const Vec3f wo_local = f.to_local(s.wo);
      s.value = lobe_eval_local(c, wi_local, wo_local);
      s.pdf = lobe_pdf_local(c, wi_local, wo_local);
      s.valid = s.pdf > 0.0f;
    }
    return s;
  }
  return lobe_sample_local(c, wi, u_choice, u);
}
float lobe_albedo_hint_framed(const Closure& c, Vec3f n, Vec3f wi) {
  if (c.interpolated_normal) return lobe_albedo_hint_local(c, lobe_frame(c, n).to_local(wi));
  return lobe_albedo_hint_local(c, wi);
}
// The lobe calls of a set with own frames (kFramed; `n` ClosureSet::interpolated_) or without:
// sets without them, all but a few, run exactly the code they ran before own frames existed.
template <bool kFramed>
Spectrum lobe_eval(const Closure& c, Vec3f n, Vec3f wi, Vec3f wo) {
  if constexpr (kFramed) return lobe_eval_framed(c, n, wi, wo);
  return lobe_eval_local(c, wi, wo);
}
template <bool kFramed>
float lobe_pdf(const Closure& c, Vec3f n, Vec3f wi, Vec3f wo) {
  if constexpr (kFramed) return lobe_pdf_framed(c, n, wi, wo);
  return lobe_pdf_local(c, wi, wo);
}
template <bool kFramed>
BsdfSample lobe_sample(const Closure& c, Vec3f n, Vec3f wi, float u_choice, Vec2f u) {
  if constexpr (kFramed) return lobe_sample_framed(c, n, wi, u_choice, u);
  return lobe_sample_local(c, wi, u_choice, u);
}
template <bool kFramed>
float lobe_albedo_hint(const Closure& c, Vec3f n, Vec3f wi) {
  if constexpr (kFramed) return lobe_albedo_hint_framed(c, n, wi);
  return lobe_albedo_hint_local(c, wi);
}
#undef GDPT_DISPATCH

bool lobe_is_delta(const Closure& c) {
  switch (c.type) {
    case ClosureType::Transparent:
      return true;
    case ClosureType::GGXReflection:
    case ClosureType::Clearcoat:
      return is_delta_alpha(mirror_test_alpha(c));
    case ClosureType::GGXDielectric:
      // An index-matched rough interface still has a (zero-weight) glossy reflection; its
      // transmission is a delta pass-through, so it counts as delta for classification.
      return is_delta_alpha(c.alpha) || std::fabs(c.ior - 1.0f) < 1e-4f;
    default:
      return false;
  }
}

bool lobe_is_diffuse(const Closure& c) {
  return c.type == ClosureType::Lambert || c.type == ClosureType::OrenNayar ||
         c.type == ClosureType::PrincipledDiffuse || c.type == ClosureType::PrincipledSheen ||
         c.type == ClosureType::Translucent || c.type == ClosureType::Velvet;
}

// Whether two delta events send wi the same way: lobes about one normal compute the direction
// alike, and an index-matched interface's pass-through bends it by less than 1e-4.
bool same_delta_direction(Vec3f a, Vec3f b) {
  return dot(a, b) > 1.0f - 1e-6f;
}

// Unnormalised selection weights; returns their sum.
template <bool kFramed>
float selection_weights(const Closure* closures, int count, Vec3f n, Vec3f wi, float* w) {
  float total = 0.0f;
  for (int i = 0; i < count; ++i) {
    w[i] = selection_luminance(closures[i].weight) * lobe_albedo_hint<kFramed>(closures[i], n, wi);
    total += w[i];
  }
  return total;
}

}  // namespace

void ClosureSet::add(const Closure& c) {
  if (is_black(c.weight)) return;
  if (count_ < kMaxClosures) {
    closures_[count_++] = c;
    return;
  }
  // Full: keep the kMaxClosures strongest lobes.
  int weakest = 0;
  for (int i = 1; i < count_; ++i)
    if (selection_luminance(closures_[i].weight) < selection_luminance(closures_[weakest].weight))
      weakest = i;
  if (selection_luminance(c.weight) > selection_luminance(closures_[weakest].weight))
    closures_[weakest] = c;
}

float ClosureSet::diffuse_shadowing(Vec3f wo) const {
  if (!shadowing_) return 1.0f;
  // g = cos(unperturbed, wo) / (cos(perturbed, wo) cos(unperturbed, perturbed)); 1 from g = 1 on,
  // 0 below 0, the cubic -g^3 + g^2 + g between (C1 at g = 1).
  const float den = wo.z * unperturbed_.z;
  const float g = den != 0.0f ? dot(unperturbed_, wo) / den : 0.0f;
  if (g >= 1.0f) return 1.0f;
  if (g < 0.0f) return 0.0f;
  const float g2 = g * g;
  return -g2 * g + g2 + g;
}

ClosureSet::Attenuation ClosureSet::attenuation(Vec3f wo) const {
  Attenuation a;
  if (!shadowing_) return a;
  a.diffuse = diffuse_shadowing(wo);
  if (terminator_k_ > 1.0f) {
    a.shift = terminator_shading_factor(wo.z, terminator_k_);
    if (own_frames_) a.shift_own = terminator_shading_factor(dot(interpolated_, wo), terminator_k_);
  }
  return a;
}

// A lobe's value with the bump shadowing of diffuse lobes and the terminator shift applied.
// Lobes about their own (interpolated) normal are not bump-shadowed: Cycles shadows the closures
// whose normal is not the interpolated one.
template <bool kFramed>
Spectrum shadowed(const Closure& c, Spectrum value, const ClosureSet::Attenuation& a) {
  if constexpr (kFramed)
    if (c.interpolated_normal) return a.shift_own != 1.0f ? value * a.shift_own : value;
  const float f = lobe_is_diffuse(c) ? a.diffuse * a.shift : a.shift;
  return f != 1.0f ? value * f : value;
}

template <bool kFramed>
Spectrum ClosureSet::delta_shifted(const Closure& c, Spectrum value, Vec3f wo) const {
  if (!(terminator_k_ > 1.0f)) return value;
  float cos_wo = wo.z;
  if constexpr (kFramed)
    if (c.interpolated_normal) cos_wo = dot(interpolated_, wo);
  return value * terminator_shading_factor(cos_wo, terminator_k_);
}

bool ClosureSet::lobe_side_ok(const Closure& c, Vec3f wi, Vec3f wo) const {
  const float cos_ng = dot(ng_, wo);
  if (cos_ng == 0.0f) return false;
  const bool reflection =
      c.interpolated_normal ? dot(interpolated_, wi) * dot(interpolated_, wo) > 0.0f : wo.z > 0.0f;
  return (cos_ng > 0.0f) == reflection;
}

// With own frames (kFramed) each lobe also decides reflection against transmission itself
// (lobe_side_ok); see set_interpolated_normal.
Spectrum ClosureSet::eval_mixture(Vec3f wi, Vec3f wo) const {
  return own_frames_ ? eval_mixture_t<true>(wi, wo) : eval_mixture_t<false>(wi, wo);
}
float ClosureSet::pdf_mixture(Vec3f wi, Vec3f wo) const {
  return own_frames_ ? pdf_mixture_t<true>(wi, wo) : pdf_mixture_t<false>(wi, wo);
}
Spectrum ClosureSet::eval_pdf_mixture(Vec3f wi, Vec3f wo, float& pdf_out) const {
  return own_frames_ ? eval_pdf_mixture_t<true>(wi, wo, pdf_out)
                     : eval_pdf_mixture_t<false>(wi, wo, pdf_out);
}
BsdfSample ClosureSet::sample_mixture(Vec3f wi, float u_lobe, Vec2f u) const {
  return own_frames_ ? sample_mixture_t<true>(wi, u_lobe, u)
                     : sample_mixture_t<false>(wi, u_lobe, u);
}

template <bool kFramed>
Spectrum ClosureSet::eval_mixture_t(Vec3f wi, Vec3f wo) const {
  const Attenuation sh = attenuation(wo);
  Spectrum f(0.0f);
  for (int i = 0; i < count_; ++i) {
    if constexpr (kFramed)
      if (!lobe_side_ok(closures_[i], wi, wo)) continue;
    f += shadowed<kFramed>(closures_[i], lobe_eval<kFramed>(closures_[i], interpolated_, wi, wo),
                           sh);
  }
  return f;
}

template <bool kFramed>
float ClosureSet::pdf_mixture_t(Vec3f wi, Vec3f wo) const {
  if (count_ == 1) {
    if constexpr (kFramed)
      if (!lobe_side_ok(closures_[0], wi, wo)) return 0.0f;
    return lobe_pdf<kFramed>(closures_[0], interpolated_, wi, wo);
  }
  float w[kMaxClosures];
  const float total = selection_weights<kFramed>(closures_, count_, interpolated_, wi, w);
  if (!(total > 0.0f)) return 0.0f;
  float p = 0.0f;
  for (int i = 0; i < count_; ++i) {
    if constexpr (kFramed)
      if (!lobe_side_ok(closures_[i], wi, wo)) continue;
    if (w[i] > 0.0f) p += w[i] * lobe_pdf<kFramed>(closures_[i], interpolated_, wi, wo);
  }
  return p / total;
}

template <bool kFramed>
Spectrum ClosureSet::eval_pdf_mixture_t(Vec3f wi, Vec3f wo, float& pdf_out) const {
  const Attenuation sh = attenuation(wo);
  if (count_ == 1) {
    if constexpr (kFramed)
      if (!lobe_side_ok(closures_[0], wi, wo)) {
        pdf_out = 0.0f;
        return Spectrum(0.0f);
      }
    pdf_out = lobe_pdf<kFramed>(closures_[0], interpolated_, wi, wo);
    return shadowed<kFramed>(closures_[0], lobe_eval<kFramed>(closures_[0], interpolated_, wi, wo),
                             sh);
  }
  // The loops of eval() and pdf() merged, each sum in the same order: identical values.
  float w[kMaxClosures];
  const float total = selection_weights<kFramed>(closures_, count_, interpolated_, wi, w);
  Spectrum f(0.0f);
  float p = 0.0f;
  for (int i = 0; i < count_; ++i) {
    if constexpr (kFramed)
      if (!lobe_side_ok(closures_[i], wi, wo)) continue;
    f += shadowed<kFramed>(closures_[i], lobe_eval<kFramed>(closures_[i], interpolated_, wi, wo),
                           sh);
    if (w[i] > 0.0f) p += w[i] * lobe_pdf<kFramed>(closures_[i], interpolated_, wi, wo);
  }
  pdf_out = total > 0.0f ? p / total : 0.0f;
  return f;
}

// Each of these returns prvalues or one named result only, so that the sample is built in the
// caller's slot: copying out a sample that lobe_sample_local had just stored field by field
// loaded it back in 16-byte pieces, a store-forwarding stall on every BSDF sample.
template <bool kFramed>
BsdfSample ClosureSet::sample_mixture_t(Vec3f wi, float u_lobe, Vec2f u) const {
  if (count_ == 0) return {};
  return count_ == 1 ? sample_single_t<kFramed>(wi, u_lobe, u)
                     : sample_several_t<kFramed>(wi, u_lobe, u);
}

template <bool kFramed>
BsdfSample ClosureSet::sample_single_t(Vec3f wi, float u_lobe, Vec2f u) const {
  BsdfSample s = lobe_sample<kFramed>(closures_[0], interpolated_, wi, u_lobe, u);
  if constexpr (kFramed)
    if (s.valid && !lobe_side_ok(closures_[0], wi, s.wo)) s = BsdfSample{};
  if (s.valid && shadowing_)
    s.value = s.is_delta() ? delta_shifted<kFramed>(closures_[0], s.value, s.wo)
                           : shadowed<kFramed>(closures_[0], s.value, attenuation(s.wo));
  return s;
}

template <bool kFramed>
BsdfSample ClosureSet::sample_several_t(Vec3f wi, float u_lobe, Vec2f u) const {
  // --- Pick a lobe; the leftover of u_lobe within its interval drives the lobe's own choice.
  float w[kMaxClosures];
  const float total = selection_weights<kFramed>(closures_, count_, interpolated_, wi, w);
  int k = 0;
  float u_choice = 0.0f;
  if (total > 0.0f) {
    const float target = u_lobe * total;
    float cdf = 0.0f;
    for (; k < count_ - 1; ++k) {
      if (target < cdf + w[k]) break;
      cdf += w[k];
    }
    while (w[k] <= 0.0f && k > 0) --k;  // rounding at the top end: fall back to a live lobe
    u_choice = std::clamp((target - cdf) / w[k], 0.0f, 0.99999994f);
  }
  BsdfSample s = total > 0.0f ? lobe_sample<kFramed>(closures_[k], interpolated_, wi, u_choice, u)
                              : BsdfSample{};
  if (!s.valid) return s;
  if constexpr (kFramed)
    if (!lobe_side_ok(closures_[k], wi, s.wo)) {
      s = BsdfSample{};
      return s;
    }

  const float sel_k = w[k] / total;
  if (s.is_delta()) {
    // Delta lobes sending wi the same way (mirrors mixed by a factor, a mirror and a glass's
    // reflection) make one event, whose value and probability are their sums, as for the
    // non-delta lobes below: the same numbers as delta_event() of that event.
    s.pdf *= sel_k;
    s.value = delta_shifted<kFramed>(closures_[k], s.value, s.wo);
    add_same_delta_events<kFramed>(k, wi, w, total, s);
    return s;
  }

  // --- One-sample MIS: the mixture's value and density at the sampled direction.
  const Attenuation sh = attenuation(s.wo);
  Spectrum value = shadowed<kFramed>(closures_[k], s.value, sh);
  float pdf = w[k] * s.pdf;
  for (int i = 0; i < count_; ++i) {
    if (i == k) continue;
    if constexpr (kFramed)
      if (!lobe_side_ok(closures_[i], wi, s.wo)) continue;
    value += shadowed<kFramed>(closures_[i],
                               lobe_eval<kFramed>(closures_[i], interpolated_, wi, s.wo), sh);
    if (w[i] > 0.0f) pdf += w[i] * lobe_pdf<kFramed>(closures_[i], interpolated_, wi, s.wo);
  }
  s.value = value;
  s.pdf = pdf / total;
  s.valid = s.pdf > 0.0f;
  return s;
}

template <bool kFramed>
BsdfSample ClosureSet::lobe_delta_event(int i, Vec3f wi, uint8_t event) const {
  const Closure& c = closures_[i];
  if (!lobe_is_delta(c)) return {};
  // A delta lobe's only random choice is reflection against transmission: force it.
  const float u_choice = (event & kLobeReflection) ? 0.0f : 0.99999994f;
  BsdfSample s = lobe_sample<kFramed>(c, interpolated_, wi, u_choice, Vec2f(0.5f, 0.5f));
  if (!s.valid || !s.is_delta() || (s.lobe & event) == 0) return {};
  if constexpr (kFramed)
    if (!lobe_side_ok(c, wi, s.wo)) return {};
  s.value = delta_shifted<kFramed>(c, s.value, s.wo);
  return s;
}

template <bool kFramed>
void ClosureSet::add_same_delta_events(int k, Vec3f wi, const float* w, float total,
                                       BsdfSample& s) const {
  const uint8_t event = s.lobe & (kLobeReflection | kLobeTransmission);
  for (int i = 0; i < count_; ++i) {
    if (i == k || !(w[i] > 0.0f)) continue;
    const BsdfSample e = lobe_delta_event<kFramed>(i, wi, event);
    if (e.valid && same_delta_direction(e.wo, s.wo)) {
      s.value += e.value;
      s.pdf += w[i] / total * e.pdf;
    }
  }
}

BsdfSample ClosureSet::delta_event(Vec3f wi, uint8_t event) const {
  return own_frames_ ? delta_event_t<true>(wi, event) : delta_event_t<false>(wi, event);
}

template <bool kFramed>
BsdfSample ClosureSet::delta_event_t(Vec3f wi, uint8_t event) const {
  float w[kMaxClosures] = {1.0f};
  float total = 1.0f;
  if (count_ > 1) total = selection_weights<kFramed>(closures_, count_, interpolated_, wi, w);
  BsdfSample sum;
  if (!(total > 0.0f)) return sum;
  for (int i = 0; i < count_; ++i) {
    if (!(w[i] > 0.0f)) continue;
    const BsdfSample e = lobe_delta_event<kFramed>(i, wi, event);
    if (!e.valid) continue;
    if (!sum.valid) {
      sum = e;
      sum.pdf *= w[i] / total;
    } else if (same_delta_direction(e.wo, sum.wo)) {
      sum.value += e.value;
      sum.pdf += w[i] / total * e.pdf;
    } else {
      return BsdfSample{};  // two directions: the event names none
    }
  }
  sum.valid = sum.valid && sum.pdf > 0.0f;
  return sum;
}

bool ClosureSet::has_own_tangents() const {
  Vec3f first;
  if (!anisotropic_tangent(first)) return false;
  for (int i = 0; i < count_; ++i)
    if (is_anisotropic(closures_[i]) && !(closures_[i].tangent == first)) return true;
  return false;
}

void ClosureSet::orient_own_tangents(const Frame& frame) {
  Vec3f first;
  if (!anisotropic_tangent(first)) return;
  for (int i = 0; i < count_; ++i) {
    Closure& c = closures_[i];
    if (!is_anisotropic(c) || c.tangent == first) continue;
    const Vec3f t = frame.to_local(c.tangent);
    const float len = std::sqrt(t.x * t.x + t.y * t.y);
    c.tangent = first;
    // A tangent along the normal names no direction: the lobe follows the frame's, as there.
    if (!(len > 1e-10f) || !std::isfinite(len)) continue;
    const float ct = t.x / len, st = t.y / len, cr = c.rotation.x, sr = c.rotation.y;
    c.rotation = Vec2f(ct * cr - st * sr, st * cr + ct * sr);
  }
}

float ClosureSet::roughness() const {
  float r = 2.0f;
  for (int i = 0; i < count_; ++i) {
    const Closure& c = closures_[i];
    if (lobe_is_delta(c) && !(c.type == ClosureType::GGXDielectric && !is_delta_alpha(c.alpha)))
      continue;
    // The multiple-scattering lobe is as smooth as a diffuse one.
    const bool smooth = lobe_is_diffuse(c) || c.type == ClosureType::GGXMultiscatter;
    r = std::min(r, smooth ? 1.0f : std::clamp(min_alpha(c), 0.0f, 1.0f));
  }
  return r > 1.0f ? (count_ > 0 && has_delta() ? 0.0f : 1.0f) : r;
}

bool ClosureSet::has_delta() const {
  for (int i = 0; i < count_; ++i)
    if (lobe_is_delta(closures_[i])) return true;
  return false;
}

}  // namespace gdpt
