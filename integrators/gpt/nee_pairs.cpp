#include "integrators/gpt/nee_pairs.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "integrators/common/manifold_nee.h"
#include "integrators/common/mis.h"
#include "integrators/gpt/caustic_pairs.h"
#include "integrators/gpt/mis_weights.h"
#include "integrators/gpt/shadow_rays.h"

namespace gdpt {

namespace {

using shift::PathDensities;
using shift::Vec3d;

}  // namespace

bool offset_light(const LightSampler& lights, Vec3f y, float u_select, Vec2f u_light,
                  const LightSample& ls, LightSample& out) {
  if (ls.is_infinite) {
    // World and sun: sampled directions do not depend on the reference point.
    out = lights.sample(y, u_select, u_light);
    return out.valid && out.is_infinite && length_squared(out.direction - ls.direction) < 1e-10f;
  }
  if (ls.area_pdf > 0.0f) {
    // Area light: the same point is reachable from y when y lies on its emitting side (it
    // emits the same radiance everywhere); its density in the weights is mis_light_pdf().
    const Vec3f to = ls.position - y;
    const float d = length(to);
    if (!(d > 0.0f)) return false;
    out = ls;
    out.direction = to / d;
    out.distance = d;
    const float cos_l = -dot(out.direction, ls.normal);
    // Behind the one-sided light: sample() from y skips it, so the pair is consistent.
    if (!(cos_l > 0.0f)) return false;
    out.pdf = mis_light_pdf(ls.area_pdf, 0.0f, d, cos_l);
    return std::isfinite(out.pdf);
  }
  const float scale = std::max(1.0f, max_component(abs(ls.position)));
  if (!ls.is_delta) {
    // Analytic lights (area, sphere) are sampled in solid angle from the reference point:
    // evaluate the base's point from y by intersecting the light instead.
    const Vec3f to = ls.position - y;
    const float d = length(to);
    if (!(d > 0.0f)) return false;
    const Vec3f dir = to / d;
    LightHit lh;
    // The same point on the same surface: point/spot lights with a radius are discs facing
    // each receiver, so y's disc passes near (never through) the base's point with another
    // normal; accepting it would shift onto a different light surface (biased gradients).
    if (lights.intersect(y, dir, d * (1.0f + 1e-3f), lh) &&
        length_squared(lh.position - ls.position) <= 1e-6f * scale * scale &&
        length_squared(lh.normal - ls.normal) <= kSameNormal2) {
      out.radiance = lh.radiance;
      out.position = ls.position;
      out.normal = ls.normal;
      out.direction = dir;
      out.distance = d;
      out.pdf = lh.pdf;
      out.is_delta = false;
      out.is_infinite = false;
      // sample() rejects a direction the light does not emit into (outside a spot's cone):
      // from y this point then has density 0, exactly like the base at y skipping it.
      out.valid = lh.pdf > 0.0f && !is_black(lh.radiance);
      return out.valid;
    }
  }
  // Point lights and emissive triangles (sampled by area): the same random numbers give the
  // same point.
  out = lights.sample(y, u_select, u_light);
  return out.valid && length_squared(out.position - ls.position) < 1e-8f * scale * scale;
}

Arrival offset_arrival(const GptContext& g, const Vertex& v, const LightSample& ls, LightSample& lo,
                       Vec3f& wo, Spectrum& f, float& pdf, ClosureSet& scratch, uint32_t& rays) {
  f = Spectrum(0.0f);
  if (!light_dir(g.ctx.bvh(), v, lo.direction, wo)) return Arrival::None;
  f = v.closures->eval_pdf(v.wi, wo, pdf);
  if (is_black(f) || is_black(lo.radiance)) return Arrival::None;
  // The same lamp as the base's sample (its cast_shadow and is_delta).
  return lamp_visible(g, v, ls, lo, scratch, lo.radiance, rays) ? Arrival::Visible
                                                                : Arrival::Blocked;
}

void nee_pairs(const GptContext& g, const Vertex& base, const BasePath& bp, const LightSample& ls,
               float u_select, Vec2f u_light, unsigned open_mask, PathScratch& scratch,
               SampleResult& out) {
  const ClosureSet& bc = *base.closures;
  Offset* off = scratch.off;
  // --- Base ---
  Vec3f wo;
  Spectrum fs(0.0f);
  float pdf_fs = 0.0f;
  bool visible = false;
  Spectrum le = ls.radiance;  // arriving: times the transmittance of delta lamps' rays
  if (light_dir(g.ctx.bvh(), base, ls.direction, wo)) {
    fs = bc.eval_pdf(base.wi, wo, pdf_fs);
    if (!is_black(fs) && !is_black(ls.radiance))
      visible = lamp_visible(g, base, ls, ls, scratch.shadow_closures, le, out.rays);
  }
  const float pdf_bsdf = (!ls.is_delta && visible) ? pdf_fs : 0.0f;
  if (visible) {
    const float w = ls.is_delta ? 1.0f : power_heuristic(ls.pdf, pdf_bsdf);
    out.primal += bp.beta * fs * le * (w / ls.pdf);
  }
  const Vec3d cb = visible ? mul(mul(bp.fb, fs), le) : Vec3d();
  // The pair weights see the light technique through mis_light_pdf().
  const float pl_mis = ls.is_infinite ? ls.pdf
                                      : mis_light_pdf(ls.area_pdf, ls.pdf, ls.distance,
                                                      -dot(ls.direction, ls.normal));
  const double tech_l = light_tech(pl_mis, ls.pdf);
  const PathDensities db{bp.pb, pl_mis, pdf_bsdf};

  // --- Merged offsets (connected or dead) ---
  if (visible)
    add_merged(off, bp.fb, bp.pb, connected_event(mul(Vec3d(fs), le), tech_l, pl_mis, pdf_bsdf));

  // --- Open offsets ---
  // First pass: the offsets' light samples and the shadow rays of the not-connected
  // ones. Each is its own occlusion query: Embree's 4-ray packets (rtcOccluded4) of these
  // rays from neighbouring points towards the same light point cost more time.
  enum class NeeCase : uint8_t { Skip, Shared, NoLight, Shifted, Caustic };
  NeeCase nc[kOffsets];
  LightSample* lo = scratch.lo;
  double J[kOffsets];
  Vec3f* wo_o = scratch.wo_o;
  Spectrum* fo = scratch.fo;
  float pdf_fo[kOffsets];
  bool test[kOffsets] = {false, false, false, false};
  bool blocked[kOffsets] = {false, false, false, false};
  shift::ReconnectionBase& light_base = scratch.light_base;  // set on demand
  bool light_base_set = false;
  for (unsigned m = open_mask; m != 0; m &= m - 1) {
    const int k = std::countr_zero(m);
    const Offset& o = off[k];
    nc[k] = NeeCase::Skip;
    if (o.link != Link::NotConnected) {
      nc[k] = NeeCase::Shared;
      continue;
    }
    if (!ls.is_delta && !o.nee_on) continue;  // not shifted: dropped on both sides
    if (!offset_light(g.ctx.lights(), o.v.hit.position, u_select, u_light, ls, lo[k])) {
      // The light cannot be sampled from y (e.g. y is behind a one-sided area light):
      // the offset has density 0, the base keeps its full weight. The base at y skips
      // this light sample as well, so the pair stays consistent.
      nc[k] = NeeCase::NoLight;
      continue;
    }
    nc[k] = NeeCase::Shifted;
    if (!light_base_set && !ls.is_delta && !ls.is_infinite) {
      light_base = shift::reconnection_base(base.hit.position, ls.position, ls.normal);
      light_base_set = true;
    }
    J[k] = ls.is_delta || ls.is_infinite
               ? 1.0
               : shift::light_reconnection_jacobian(light_base, o.v.hit.position);
    const Arrival a = offset_arrival(g, o.v, ls, lo[k], wo_o[k], fo[k], pdf_fo[k],
                                     scratch.shadow_closures, out.rays);
    test[k] = a != Arrival::None;
    blocked[k] = a == Arrival::Blocked;
    // Casters on the offset's own segment (caustic_pairs.h): its refracted path, in the base's
    // solid-angle measure (d A(y) = d omega d^2 / cos_l at the base).
    if ((!test[k] || blocked[k]) && runs_shadow_caustics(g.ctx, o.v.hit, ls)) {
      const CausticEvent e =
          caustic_event(g, o.v, ls, caustic_share(bp.state, g.settings), scratch, out.rays);
      if (e.casters > 0) {
        nc[k] = NeeCase::Caustic;
        fo[k] = e.valid ? o.v.closures->eval(o.v.wi, e.wo) * e.transport *
                              (ls.distance * ls.distance / std::fabs(dot(ls.direction, ls.normal)))
                        : Spectrum(0.0f);
      }
    }
  }
  // Second pass: contributions and weights.
  for (unsigned m = open_mask; m != 0; m &= m - 1) {
    const int k = std::countr_zero(m);
    Offset& o = off[k];
    Vec3d co;
    PathDensities d_off{0.0, 0.0, 0.0};
    switch (nc[k]) {
      case NeeCase::Skip:
        continue;
      case NeeCase::NoLight:
        break;
      case NeeCase::Shared: {
        // Recently connected: the shared vertex seen from the offset's own wi.
        Spectrum f_r(0.0f);
        float pdf_o = 0.0f;
        if (wo.z != 0.0f && visible) {
          if (o.shared == &bc && same_side(base, o.wi_shared, base.wi, wo)) {
            f_r = fs;
            pdf_o = pdf_fs;
          } else {
            f_r = o.shared->eval_pdf(o.wi_shared, wo, pdf_o);
          }
          if (ls.is_delta) pdf_o = 0.0f;
        }
        co = mul(mul(o.f, f_r), le);
        d_off = shift::offset_densities(o.p, 1.0, pl_mis, pdf_o);
        break;
      }
      case NeeCase::Caustic:
        co = mul(o.f, Vec3d(fo[k]));
        d_off = shift::offset_densities(o.p, 1.0, pl_mis, 0.0);
        break;
      case NeeCase::Shifted: {
        const bool vis_o = test[k] && !blocked[k];
        const float pdf_o = (!ls.is_delta && vis_o) ? pdf_fo[k] : 0.0f;
        co = vis_o ? mul(mul(o.f, fo[k]), lo[k].radiance) * J[k] : Vec3d();
        d_off = shift::offset_densities(o.p, J[k], lo[k].pdf, pdf_o);
        break;
      }
    }
    const double w = shift::mis_weight_over_pdf(db, d_off, tech_l);
    o.grad = o.grad + (co - cb) * w;
  }
}

}  // namespace gdpt
