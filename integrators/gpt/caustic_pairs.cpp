#include "integrators/gpt/caustic_pairs.h"

#include <bit>
#include <cmath>

#include "integrators/common/manifold_nee.h"
#include "integrators/gpt/mis_weights.h"
#include "integrators/gpt/nee_pairs.h"
#include "integrators/gpt/offset_path.h"

namespace gdpt {

namespace {

using shift::PathDensities;
using shift::Vec3d;

// An offset whose straight segment to the base's light point is clear: its plain light sample,
// in the light point's area measure (d omega / d A = cos_l / d^2 at the offset's vertex).
void plain_offset(const GptContext& g, const Offset& o, const LightSample& ls, float u_select,
                  Vec2f u_light, float p_mis, PathScratch& scratch, uint32_t& rays, Vec3d& co,
                  PathDensities& d_off) {
  LightSample lo;
  if (!offset_light(g.ctx.lights(), o.v.hit.position, u_select, u_light, ls, lo)) return;
  Vec3f wo;
  float pdf_fo = 0.0f;
  Spectrum fo;
  const bool visible = offset_arrival(g, o.v, ls, lo, wo, fo, pdf_fo, scratch.shadow_closures,
                                      rays) == Arrival::Visible;
  const float to_area = std::fabs(dot(lo.direction, lo.normal)) / (lo.distance * lo.distance);
  if (visible) co = mul(o.f, Vec3d(fo * lo.radiance * to_area));
  d_off = shift::offset_densities(o.p, 1.0, p_mis, visible ? pdf_fo * to_area : 0.0f);
}

}  // namespace

CausticEvent caustic_event(const GptContext& g, const Vertex& v, const LightSample& ls,
                           const CausticShare& share, PathScratch& scratch, uint32_t& rays) {
  const Vec3f ng = dot(ls.position - v.hit.position, v.ng) > 0.0f ? v.ng : -v.ng;
  const CausticConnection c =
      caustic_connection(g.ctx, v.hit.position, ng, ls, scratch.shadow_closures, rays);
  CausticEvent e;
  e.casters = c.casters;
  e.transport = c.transport * manifold_nee_weight(c, share, ls.area_pdf, ng);
  e.valid = c.valid && light_dir(g.ctx.bvh(), v, c.direction, e.wo);
  return e;
}

bool caustic_pairs(const GptContext& g, const Vertex& base, const BasePath& bp,
                   const LightSample& ls, float u_select, Vec2f u_light, unsigned open_mask,
                   PathScratch& scratch, SampleResult& out) {
  // Offsets shade with the base's path state: one share for the pair.
  const CausticShare share = caustic_share(bp.state, g.settings);
  const CausticEvent eb = caustic_event(g, base, ls, share, scratch, out.rays);
  if (eb.casters == 0) return false;
  const Spectrum yb =
      eb.valid ? base.closures->eval(base.wi, eb.wo) * eb.transport : Spectrum(0.0f);
  // The light technique's density of the point in area measure: the actual one for the
  // estimate, area sampling's (the same from every vertex) for the pair weights.
  const float p_actual = light_area_density(ls), p_mis = ls.area_pdf;
  const double tech = light_tech(p_mis, p_actual);
  const bool lit = !is_black(yb);
  if (lit) out.primal += bp.beta * yb / p_actual;
  const Vec3d cb = lit ? mul(bp.fb, Vec3d(yb)) : Vec3d();
  const PathDensities db{bp.pb, p_mis, 0.0};
  Offset* off = scratch.off;
  if (lit) add_merged(off, bp.fb, bp.pb, connected_event(Vec3d(yb), tech, p_mis, 0.0));
  for (unsigned m = open_mask; m != 0; m &= m - 1) {
    Offset& o = off[std::countr_zero(m)];
    Vec3d co;
    PathDensities d_off{0.0, 0.0, 0.0};
    if (o.link != Link::NotConnected) {
      // Recently connected: the base's caustic path seen from the offset's own wi.
      if (eb.valid) co = mul(o.f, Vec3d(o.shared->eval(o.wi_shared, eb.wo) * eb.transport));
      d_off = shift::offset_densities(o.p, 1.0, p_mis, 0.0);
    } else {
      // A pair that cannot shift light samples (a vertex not diffuse) leaves the base alone (its
      // BSDF-sampled copies of the path carry the rest of such pairs' light elsewhere).
      if (!o.nee_on) {
        if (!is_zero(cb)) o.grad = o.grad - cb * shift::mis_weight_over_pdf(db, d_off, tech);
        continue;
      }
      const CausticEvent eo = runs_shadow_caustics(g.ctx, o.v.hit, ls)
                                  ? caustic_event(g, o.v, ls, share, scratch, out.rays)
                                  : CausticEvent{};
      if (eo.casters > 0) {
        if (eo.valid) co = mul(o.f, Vec3d(o.v.closures->eval(o.v.wi, eo.wo) * eo.transport));
        d_off = shift::offset_densities(o.p, 1.0, p_mis, 0.0);
      } else {
        plain_offset(g, o, ls, u_select, u_light, p_mis, scratch, out.rays, co, d_off);
      }
    }
    if (is_zero(cb) && is_zero(co)) continue;
    o.grad = o.grad + (co - cb) * shift::mis_weight_over_pdf(db, d_off, tech);
  }
  return true;
}

}  // namespace gdpt
