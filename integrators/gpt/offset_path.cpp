#include "integrators/gpt/offset_path.h"

#include <limits>

#include "integrators/gpt/shadow_rays.h"
#include "shaders/closure.h"

namespace gdpt {

namespace {

using shift::Vec3d;
using shift::VertexType;
constexpr float kInf = std::numeric_limits<float>::infinity();

// Connected or recently connected: the base's own segment, seen from the offset's direction at
// a shared vertex.
void shift_merged(Offset& o, const BaseStep& st) {
  const Vertex& base = *st.base;
  const BsdfSample& bs = *st.bs;
  switch (o.link) {
    case Link::Connected:
      o.shift = Shift::Follow;
      o.seg_value = Vec3d(bs.value);
      o.seg_pdf = bs.pdf;
      return;
    case Link::Recent: {
      // The shared vertex seen from the offset's own incoming direction.
      o.shift = Shift::RecentEval;
      if (bs.is_delta()) {
        o.shift = Shift::Failed;  // a delta lobe cannot map another wi onto the same wo
        return;
      }
      if (o.shared == base.closures && same_side(base, o.wi_shared, base.wi, bs.wo)) {
        // A Lambert sample's value and pdf are eval() and pdf() of wo (bit-identical).
        o.seg_value = Vec3d(bs.value);
        o.seg_pdf = bs.pdf;
      } else {
        float pdf = 0.0f;
        o.seg_value = Vec3d(o.shared->eval_pdf(o.wi_shared, bs.wo, pdf));
        o.seg_pdf = pdf;
      }
      if (!(o.seg_pdf > 0.0)) o.shift = Shift::Failed;
      return;
    }
    case Link::NotConnected:
      break;
  }
}

// Reconnection (x_d, y_d and x_{d+1} all diffuse): y_d connects to the base's x_{d+1}, or to the
// same direction when the base escaped.
void reconnect(const GptContext& g, Offset& o, const BaseStep& st, uint32_t& rays) {
  const Vertex& y = o.v;
  const SurfaceHit& next = *st.next;
  const Vec3f wo_world = st.wo_world;
  const bool found = st.found;
  if (found) {
    const shift::Reconnection r = shift::reconnect(st.target, y.hit.position);
    if (!r.valid) {
      o.shift = Shift::Failed;
      return;
    }
    const Vec3f dir = r.direction.to_float();
    o.seg_dir = dir;
    // The offset must arrive on the same side of x_{d+1} as the base (the closures there
    // depend on the side).
    const bool off_front = dot(y.hit.position - next.position, next.geometric_normal) > 0;
    Vec3f wo;
    if (st.base_front != off_front || !local_dir(y, dir, wo)) {
      o.shift = Shift::Failed;
      return;
    }
    o.shift = Shift::Reconnect;
    o.seg_jacobian = r.jacobian;
    float pdf = 0.0f;
    o.seg_value = Vec3d(y.closures->eval_pdf(y.wi, wo, pdf));
    o.seg_pdf = pdf;
    // Visibility, a single occlusion query (4-ray packets of these cost more).
    o.seg_visible = !occluded(g, shadow_ray_to(y, dir, next.position, st.kind), rays);
  } else {
    // Reconnection at infinity: the same direction, J = 1, visibility from y_d.
    Vec3f wo;
    o.seg_dir = wo_world;
    if (!local_dir(y, wo_world, wo)) {
      o.shift = Shift::Failed;
      return;
    }
    o.shift = Shift::ReconnectEnv;
    float pdf = 0.0f;
    o.seg_value = Vec3d(y.closures->eval_pdf(y.wi, wo, pdf));
    o.seg_pdf = pdf;
    o.seg_visible = !occluded(g, shadow_ray_along(y, wo_world, st.kind), rays);
  }
}

// Half-vector copy in the local frames (x_d or y_d specular, or x_{d+1} specular), then the
// offset's own segment and the kills that keep the shift invertible.
void half_vector_copy(const GptContext& g, Offset& o, const BaseStep& st, VertexType yd_type,
                      uint32_t& rays) {
  const EmbreeScene& bvh = g.ctx.bvh();
  const Vertex& base = *st.base;
  const BsdfSample& bs = *st.bs;
  const Vertex& y = o.v;
  const VertexType xd_type = st.xd_type;
  const bool found = st.found;
  Vec3f wo;
  if (bs.is_delta()) {
    // Delta event: the same discrete event (reflection / transmission) at y_d, J = 1, valued over
    // all of y_d's delta lobes that make it, as sample() sums them at x_d; a lobe re-drawn with
    // the base's lobe number would make the shift depend on that number. An event sending wi two
    // ways names no single path: fail on either side, so that the reverse shift fails alike.
    const uint8_t event = bs.lobe & (kLobeReflection | kLobeTransmission);
    const BsdfSample so = y.closures->delta_event(y.wi, event);
    if (!so.valid || !st.base_delta_unique) {
      o.shift = Shift::Failed;
      return;
    }
    wo = so.wo;
    o.seg_value = Vec3d(so.value);
    o.seg_pdf = so.pdf;
    o.seg_jacobian = 1.0;
  } else {
    const Vec3d wi_b(base.wi), wo_b(bs.wo), wi_o(y.wi);
    const bool transmission = base.wi.z * bs.wo.z < 0.0f;
    const double ior = transmission ? (base.wi.z >= 0.0f ? bs.eta : 1.0 / bs.eta) : 1.0;
    const shift::HalfVectorShift hv = shift::half_vector_shift(wi_b, wo_b, wi_o, ior);
    if (!hv.valid) {
      o.shift = Shift::Failed;
      return;
    }
    wo = hv.wo.to_float();
    float pdf = 0.0f;
    o.seg_value = Vec3d(y.closures->eval_pdf(y.wi, wo, pdf));
    o.seg_pdf = pdf;
    o.seg_jacobian = hv.jacobian;
    if (!(o.seg_pdf > 0.0)) {
      o.shift = Shift::Failed;
      return;
    }
  }
  const Vec3f dir = normalize(y.frame.to_world(wo));
  const float cos_ng = dot(dir, y.ng);
  if (!y.closures->side_ok(wo, cos_ng)) {
    o.shift = Shift::Failed;
    return;
  }
  o.shift = Shift::HalfVector;
  o.seg_dir = dir;
  o.ray.origin = ray_origin(y, cos_ng > 0.0f);
  o.ray.direction = dir;
  o.ray.t_min = 0.0f;
  o.ray.t_max = kInf;
  o.ray.kind = st.kind;
  ++rays;
  o.next_found = bvh.intersect(o.ray, o.next_hit);
  o.holdout_end = o.next_found && st.holdout_ends && g.ctx.is_holdout(o.next_hit);
  if (o.holdout_end) o.next_found = false;  // as an escape into a black world
  // Kill: one path reaches the world (or a holdout) and the other does not.
  if (o.next_found != found) {
    o.killed = true;
    return;
  }
  // Kill: the reverse shift (from the offset as base) would reconnect: x_d, y_d, y_{d+1} all
  // diffuse. Without this the shift is not invertible and the estimator is biased.
  if (xd_type == VertexType::Diffuse && yd_type == VertexType::Diffuse) {
    const VertexType yn_type =
        o.next_found ? g.classify_hit(o.next_hit, *st.state) : VertexType::Diffuse;
    if (yn_type == VertexType::Diffuse) o.killed = true;
  }
}

}  // namespace

void shift_segment(const GptContext& g, Offset& o, const BaseStep& st, uint32_t& rays) {
  o.seg_jacobian = 1.0;
  o.seg_visible = true;
  o.killed = false;
  o.next_found = o.holdout_end = false;
  if (o.link != Link::NotConnected) return shift_merged(o, st);
  const Vertex& y = o.v;
  const VertexType yd_type =
      st.bs->is_delta() && y.closures->has_delta() ? VertexType::Specular : g.classify(y.roughness);
  if (st.xd_type == VertexType::Diffuse && yd_type == VertexType::Diffuse &&
      st.next_type == VertexType::Diffuse)
    return reconnect(g, o, st, rays);
  half_vector_copy(g, o, st, yd_type, rays);
}

void advance(const GptContext& g, Offset& o, bool last, const PathState& state,
             const PathView& path) {
  auto kill = [&] {
    o.alive = false;
    o.failed = true;
  };
  switch (o.shift) {
    case Shift::Follow:
      break;
    case Shift::RecentEval:
      o.link = Link::Connected;
      break;
    case Shift::Reconnect:
      if (!o.seg_visible || !(o.seg_pdf > 0.0)) return kill();
      o.link = Link::Recent;
      o.wi_world = -o.seg_dir;
      break;
    case Shift::ReconnectEnv:
      if (!o.seg_visible || !(o.seg_pdf > 0.0)) return kill();
      o.link = Link::Connected;
      break;
    case Shift::HalfVector:
      if (o.killed) return kill();
      if (o.next_found && !last) {
        PathView own = path;
        own.ray_length = o.next_hit.t;
        setup_vertex(g.ctx, g.sides, g.rules(state), o.next_hit, o.ray.direction, own, o.v);
      }
      break;
    case Shift::Failed:
      return kill();
  }
  o.f = mul(o.f, o.seg_value) * o.seg_jacobian;
  o.p *= o.seg_pdf * o.seg_jacobian;
}

}  // namespace gdpt
