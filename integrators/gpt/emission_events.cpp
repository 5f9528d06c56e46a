#include "integrators/gpt/emission_events.h"

#include <bit>
#include <cmath>
#include <limits>

#include "integrators/common/mis.h"
#include "integrators/gpt/mis_weights.h"
#include "integrators/gpt/nee_pairs.h"
#include "integrators/gpt/shadow_rays.h"

namespace gdpt {

namespace {

using shift::PathDensities;
using shift::Vec3d;
using shift::VertexType;
constexpr float kInf = std::numeric_limits<float>::infinity();

// (a) for a not-connected pair with x_d, y_d diffuse: the offset reconnects to the point the
// base's ray found on an analytic light.
void reconnect_to_light(const GptContext& g, Offset& o, const Vertex& base, Vec3f base_dir,
                        uint32_t kind, const LightHit& lh, float pl_pair, Vec3d& co,
                        PathDensities& d_off, uint32_t& rays) {
  const Vertex& y = o.v;
  if (!std::isfinite(lh.distance)) {
    // A sun disc: reconnection at infinity, the same direction and radiance, J = 1.
    Vec3f wo;
    if (!local_dir(y, base_dir, wo)) return;
    float pdf_o = 0.0f;
    const Spectrum fo = y.closures->eval_pdf(y.wi, wo, pdf_o);
    const bool vis = !occluded(g, shadow_ray_along(y, base_dir, kind), rays);
    co = vis ? mul(mul(o.f, fo), lh.radiance) : Vec3d();
    d_off = shift::offset_densities(o.p, 1.0, pl_pair, vis ? pdf_o : 0.0f);
    return;
  }
  const shift::Reconnection r =
      shift::reconnect(base.hit.position, y.hit.position, lh.position, lh.normal);
  if (!r.valid) return;  // degenerate: density 0 (failed)
  const Vec3f dir = r.direction.to_float();
  Vec3f wo;
  if (!local_dir(y, dir, wo)) return;
  LightHit lo;
  const float d = float(r.distance);
  // The base's light point itself (same surface normal): y's own receiver-facing disc of a
  // point/spot light with a radius passes near it but is another surface (see offset_light).
  const bool reaches = g.ctx.lights().intersect(y.hit.position, dir, d * (1.0f + 1e-3f), lo) &&
                       std::fabs(lo.distance - d) < 1e-3f * d &&
                       length_squared(lo.normal - lh.normal) <= kSameNormal2;
  float pdf_o = 0.0f;
  const Spectrum fo = y.closures->eval_pdf(y.wi, wo, pdf_o);
  const bool vis = reaches && !occluded(g, shadow_ray_to(y, dir, lh.position, kind), rays);
  co = vis ? mul(mul(o.f, fo), lo.radiance) * r.jacobian : Vec3d();
  // Light sampling from y produces this point only where the light emits towards y (a spot's
  // cone), as the base's pl is counted only for a lit hit.
  d_off = shift::offset_densities(
      o.p, r.jacobian,
      pl_pair > 0.0f && reaches && !is_black(lo.radiance)
          ? mis_light_pdf(lo.area_pdf, lo.pdf, lo.distance, -dot(dir, lo.normal))
          : 0.0f,
      vis ? pdf_o : 0.0f);
}

// (b)/(c): the offset's contribution and densities for the emission at the end of the segment
// (world when !found, emissive triangle `next` otherwise). `nee_on`: the pair shifts light
// sampling here, so the offset's own light density counts.
// `world_seen`: the world emits into this segment (not with a transparent background on the
// camera path); `camera_path`: the segment is still a camera ray's (it sees the camera view).
// `path`: the path state at the end point (Light Path in an emitter's material).
void end_event(const GptContext& g, const Offset& o, bool found, bool world_seen, bool camera_path,
               const SurfaceHit& next, Spectrum le, float pl_pair, bool nee_on,
               const PathView& path, Vec3d& co, PathDensities& d_off) {
  const LightSampler& lights = g.ctx.lights();
  switch (o.shift) {
    case Shift::Follow:
    case Shift::RecentEval:
      // Same end point reached from the same vertex x_d.
      co = mul(mul(o.f, o.seg_value), le);
      d_off = shift::offset_densities(o.p, 1.0, pl_pair, o.seg_pdf);
      return;
    case Shift::Reconnect: {
      // Same end point, reached from y_d. Occlusion zeroes the contribution and the BSDF
      // density, but light sampling from y_d could still have produced the path.
      const Spectrum le_o = g.triangle_le(next, o.v.hit.position, path);
      const float pl_o = pl_pair > 0.0f
                             ? lights.pdf_triangle(next.instance, next.primitive, o.v.hit.position,
                                                   next.position, next.geometric_normal)
                             : 0.0f;
      co = o.seg_visible ? mul(mul(o.f, o.seg_value), le_o) * o.seg_jacobian : Vec3d();
      d_off = shift::offset_densities(o.p, o.seg_jacobian, pl_o, o.seg_visible ? o.seg_pdf : 0.0);
      return;
    }
    case Shift::ReconnectEnv: {
      co = o.seg_visible ? mul(mul(o.f, o.seg_value), le) : Vec3d();
      d_off = shift::offset_densities(o.p, 1.0, pl_pair, o.seg_visible ? o.seg_pdf : 0.0);
      return;
    }
    case Shift::HalfVector: {
      if (o.killed) return;  // density 0: failed
      Spectrum le_o(0.0f);
      float pl_o = 0.0f;
      if (!found) {
        if (world_seen && !o.holdout_end)
          le_o = camera_path ? lights.camera_environment(o.ray.direction)
                             : lights.environment(o.ray.direction);
        if (nee_on && !is_black(le_o)) pl_o = lights.pdf_environment(o.ray.direction);
      } else {
        le_o = g.triangle_le(o.next_hit, o.v.hit.position, path);
        if (nee_on && !is_black(le_o))
          pl_o = lights.pdf_triangle(o.next_hit.instance, o.next_hit.primitive, o.v.hit.position,
                                     o.next_hit.position, o.next_hit.geometric_normal);
      }
      co = mul(mul(o.f, o.seg_value), le_o) * o.seg_jacobian;
      d_off = shift::offset_densities(o.p, o.seg_jacobian, pl_o, o.seg_pdf);
      return;
    }
    case Shift::Failed:
      return;
  }
}

}  // namespace

Vec3d lamp_events(const GptContext& g, const SegmentEnd& e, const BasePath& bp, unsigned open_mask,
                  Offset* off, SampleResult& out) {
  const LightSampler& lights = g.ctx.lights();
  const Vertex& base = *e.base;
  const VertexType base_type = e.base_type;
  const Ray& ray = *e.ray;
  const bool delta = e.delta, light_hit = e.light_hit;
  const LightHit& lh = *e.lh;
  const Vec3d seg_b = e.seg_b;
  const float pdf_b = e.pdf_b;
  const Spectrum beta = bp.beta;
  const Vec3d fb = bp.fb;
  const double pb = bp.pb;
  Vec3d emit_merged;
  // A caustics lamp behind caster refractions from a receiver may be shared with manifold NEE
  // (CausticChain): weighed for the base and each offset by its own path.
  const bool base_hit = light_hit && !is_black(lh.radiance);
  const float caustic_w = base_hit ? bp.caustic.weight(g.ctx, lh, *e.scratch, out.rays) : 0.0f;
  const bool base_lit = caustic_w > 0.0f;
  const Spectrum le = lh.radiance * caustic_w;
  const float pl = (base_lit && !delta) ? lh.pdf : 0.0f;
  if (base_lit) out.primal += beta * le * (delta ? 1.0f : power_heuristic(pdf_b, pl));
  // The pair weights' light density (mis_light_pdf); the primal keeps PT's.
  const float pl_mis =
      pl > 0.0f && std::isfinite(lh.distance)
          ? mis_light_pdf(lh.area_pdf, pl, lh.distance, -dot(ray.direction, lh.normal))
          : pl;
  const Vec3d cb = base_lit ? mul(mul(fb, seg_b), le) : Vec3d();
  if (base_lit) emit_merged = connected_event(mul(seg_b, le), pdf_b, pl_mis, pdf_b);
  for (unsigned m = open_mask; m != 0; m &= m - 1) {
    Offset& o = off[std::countr_zero(m)];
    // Without a lamp at the base's end only a half-vector offset's own ray can find a light.
    if (!base_hit && o.shift != Shift::HalfVector) continue;
    Vec3d co;
    PathDensities d_off{0.0, 0.0, 0.0};
    const float pl_pair = o.nee_on ? pl_mis : 0.0f;
    const bool reconnectable = o.link == Link::NotConnected && !delta &&
                               base_type == VertexType::Diffuse &&
                               g.classify(o.v.roughness) == VertexType::Diffuse;
    if (o.alive) {
      if (o.shift == Shift::Follow || o.shift == Shift::RecentEval) {
        if (base_hit) {
          co = mul(mul(o.f, o.seg_value), lh.radiance) *
               double(o.caustic.weight(g.ctx, lh, *e.scratch, out.rays));
          d_off = shift::offset_densities(o.p, 1.0, pl_pair, o.seg_pdf);
        }
      } else if (reconnectable) {
        // The light point is a diffuse end vertex: reconnect y_d to it. (A light that only
        // the offset's own direction finds belongs to the reverse reconnection: not here.)
        if (base_lit)
          reconnect_to_light(g, o, base, ray.direction, ray.kind, lh, pl_pair, co, d_off, out.rays);
      } else if (o.shift == Shift::HalfVector) {
        // The offset's own direction: does its ray cross a light before its surface?
        LightHit lo;
        const float t_o = o.next_found || o.holdout_end ? o.next_hit.t : kInf;
        if (lights.intersect(o.ray.origin, o.ray.direction, t_o, lo))
          co = mul(mul(o.f, o.seg_value), lo.radiance) *
               (o.seg_jacobian * o.caustic.weight(g.ctx, lo, *e.scratch, out.rays));
        d_off = shift::offset_densities(o.p, o.seg_jacobian, 0.0, o.seg_pdf);
      }
    }
    if (is_zero(cb) && is_zero(co)) continue;
    const double w = shift::mis_weight_over_pdf(PathDensities{pb, pl_pair, pdf_b}, d_off, pdf_b);
    o.grad = o.grad + (co - cb) * w;
  }
  return emit_merged;
}

void end_events(const GptContext& g, const SegmentEnd& e, const BasePath& bp, unsigned open_mask,
                Offset* off, Vec3d& emit_merged, SampleResult& out) {
  const LightSampler& lights = g.ctx.lights();
  const Vertex& base = *e.base;
  const Ray& ray = *e.ray;
  const SurfaceHit& next = *e.next;
  const bool delta = e.delta, found = e.found, base_holdout = e.base_holdout;
  const bool camera_path = e.camera_path, world_seen = e.world_seen;
  const Vec3d seg_b = e.seg_b;
  const float pdf_b = e.pdf_b;
  const Spectrum beta = bp.beta;
  const Vec3d fb = bp.fb;
  const double pb = bp.pb;
  Spectrum le(0.0f);
  float pl = 0.0f;
  const PathView path = bp.state.view(0.0f);  // the state at the end point (counted already)
  if (!found) {
    bp.state.set_alpha(g.settings, beta, out.alpha);
    if (world_seen && !base_holdout) {
      le = camera_path ? lights.camera_environment(ray.direction)
                       : lights.environment(ray.direction);
      if (!delta && !camera_path && !is_black(le)) pl = lights.pdf_environment(ray.direction);
    }
  } else {
    le = g.triangle_le(next, base.hit.position, path);
    if (!delta && !is_black(le))
      pl = lights.pdf_triangle(next.instance, next.primitive, base.hit.position, next.position,
                               next.geometric_normal);
  }
  const bool base_emits = !is_black(le);
  if (base_emits) out.primal += beta * le * (delta ? 1.0f : power_heuristic(pdf_b, pl));
  const Vec3d cb = mul(mul(fb, seg_b), le);
  if (base_emits) emit_merged = emit_merged + connected_event(mul(seg_b, le), pdf_b, pl, pdf_b);
  for (unsigned m = open_mask; m != 0; m &= m - 1) {
    Offset& o = off[std::countr_zero(m)];
    // Without emission at the base's end point only a half-vector offset's own end point
    // can have some (the other shifts end at the same point, seen from the same side).
    if (!base_emits && o.shift != Shift::HalfVector) continue;
    Vec3d co;
    PathDensities d_off{0.0, 0.0, 0.0};
    const float pl_pair = o.nee_on ? pl : 0.0f;
    if (o.alive)
      end_event(g, o, found, world_seen, camera_path, next, le, pl_pair, !delta && o.nee_on, path,
                co, d_off);
    if (is_zero(cb) && is_zero(co)) continue;
    const double w = shift::mis_weight_over_pdf(PathDensities{pb, pl_pair, pdf_b}, d_off, pdf_b);
    o.grad = o.grad + (co - cb) * w;
  }
}

}  // namespace gdpt
