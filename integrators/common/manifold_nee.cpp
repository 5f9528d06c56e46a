#include "integrators/common/manifold_nee.h"

#include <algorithm>
#include <cmath>

#include "core/frame.h"
#include "core/shadow_terminator.h"
#include "integrators/common/mis.h"
#include "integrators/common/shadow_ray.h"
#include "shaders/bsdf_ggx_dielectric.h"
#include "shaders/fresnel.h"
#include "shaders/microfacet.h"
#include "shaders/shading_context.h"

namespace gdpt {

namespace {

constexpr int kMaxSeedHits = 10;  // surfaces the seed and projection rays may pass
// Converged when every vertex's half vector is this close to its normal (the sine of the angle).
constexpr float kConstraintTolerance = 1e-4f;
constexpr float kMinStep = 1e-4f;   // the Newton step's fraction below which the walk gives up
constexpr int kMaxIterations = 64;  // chain projections per walk

// A row-major 2x2 matrix: the constraint derivatives of one vertex w.r.t. one vertex's tangent
// coordinates.
struct Mat2 {
  float a = 0.0f, b = 0.0f, c = 0.0f, d = 0.0f;
};
Mat2 operator*(const Mat2& m, const Mat2& n) {
  return {m.a * n.a + m.b * n.c, m.a * n.b + m.b * n.d, m.c * n.a + m.d * n.c,
          m.c * n.b + m.d * n.d};
}
Mat2 operator-(const Mat2& m, const Mat2& n) {
  return {m.a - n.a, m.b - n.b, m.c - n.c, m.d - n.d};
}
Vec2f operator*(const Mat2& m, Vec2f v) {
  return {m.a * v.x + m.b * v.y, m.c * v.x + m.d * v.y};
}
float det(const Mat2& m) {
  return m.a * m.d - m.b * m.c;
}
bool invert(const Mat2& m, Mat2& inv) {
  const float dt = det(m);
  if (!(std::fabs(dt) > 1e-12f)) return false;
  inv = {m.d / dt, -m.b / dt, -m.c / dt, m.a / dt};
  return true;
}

// A caster vertex: its point, the triangle's local differential geometry in an orthonormal
// tangent frame of the geometric normal, and the constraint (the tangential part of the
// generalized half vector in the shading frame) with its derivatives.
struct ManifoldVertex {
  SurfaceHit hit;
  Vec3f p, ng, n;
  Vec3f dp_du, dp_dv;  // orthonormal tangents of the triangle's plane
  Vec3f dn_du, dn_dv;  // the interpolated normal's derivatives along them
  float ior = 1.0f;    // relative IOR entering through the side ng points to
  Vec2f constraint;
  Mat2 a, b, c;  // d constraint / d (previous, this, next vertex)
};

void setup_vertex(const EmbreeScene& bvh, const SurfaceHit& hit, float ior, ManifoldVertex& v) {
  SmoothTriangle tri;
  bvh.world_triangle(hit, tri);
  const float b1 = hit.bary.x, b2 = hit.bary.y, b0 = 1.0f - b1 - b2;
  v.hit = hit;
  v.ior = ior;
  v.p = tri.p[0] * b0 + tri.p[1] * b1 + tri.p[2] * b2;
  v.ng = hit.geometric_normal;
  const Vec3f n = tri.n[0] * b0 + tri.n[1] * b1 + tri.n[2] * b2;
  const float n_len = std::max(length(n), 1e-12f);
  v.n = n / n_len;
  // d(n / |n|) = dn / |n| minus its part along n, per unit barycentric step.
  Vec3f dpu = tri.p[1] - tri.p[0], dpv = tri.p[2] - tri.p[0];
  Vec3f dnu = (tri.n[1] - tri.n[0]) / n_len, dnv = (tri.n[2] - tri.n[0]) / n_len;
  dnu = dnu - v.n * dot(v.n, dnu);
  dnv = dnv - v.n * dot(v.n, dnv);
  // Gram-Schmidt on the edges, the same linear map on the normal's derivatives.
  const float lu = std::max(length(dpu), 1e-20f);
  dpu = dpu / lu;
  dnu = dnu / lu;
  const float k = dot(dpu, dpv);
  dpv = dpv - dpu * k;
  dnv = dnv - dnu * k;
  const float lv = std::max(length(dpv), 1e-20f);
  dpv = dpv / lv;
  dnv = dnv / lv;
  // The frame of ng, the same wherever the walk moves on one plane.
  const Frame f(v.ng);
  v.dp_du = f.s;
  v.dp_dv = f.t;
  v.dn_du = dnu * dot(f.s, dpu) + dnv * dot(f.s, dpv);
  v.dn_dv = dnu * dot(f.t, dpu) + dnv * dot(f.t, dpv);
}

// The derivative of the unit half vector H = h / |h| for a change dh of h, |h| already divided.
Vec3f unit_change(Vec3f dh, Vec3f H) {
  return dh - H * dot(dh, H);
}

Mat2 tangent_block(Vec3f du, Vec3f dv, Vec3f s, Vec3f t) {
  return {dot(du, s), dot(dv, s), dot(du, t), dot(dv, t)};
}

// Constraints and their derivatives along the chain x -> v[0] .. v[k-1] -> y; `d_light` gets the
// last vertex's derivative w.r.t. the light point along (lu, lv). False for a degenerate chain.
bool constraints(ManifoldVertex* v, int k, Vec3f x, Vec3f y, Vec3f lu, Vec3f lv, Mat2* d_light) {
  for (int i = 0; i < k; ++i) {
    ManifoldVertex& m = v[i];
    Vec3f wi = (i == 0 ? x : v[i - 1].p) - m.p;
    Vec3f wo = (i == k - 1 ? y : v[i + 1].p) - m.p;
    const float li = length(wi), lo = length(wo);
    if (!(li > 1e-7f && lo > 1e-7f)) return false;
    wi = wi / li;
    wo = wo / lo;
    const float eta = dot(wi, m.ng) > 0.0f ? m.ior : 1.0f / m.ior;
    // Snell's law holds when the tangential parts of wi and eta wo cancel: the generalized half
    // vector lies along the normal.
    const Vec3f h = -(wi + wo * eta);
    const float lh = length(h);
    if (!(lh > 1e-7f)) return false;
    const Vec3f H = h / lh;
    const float ki = 1.0f / (li * lh), ko = eta / (lo * lh);
    const float dpn = dot(m.dp_du, m.n);
    const Vec3f s_raw = m.dp_du - m.n * dpn;
    const float ls = length(s_raw);
    if (!(ls > 1e-7f)) return false;
    const Vec3f s = s_raw / ls, t = cross(m.n, s);
    if (i > 0) {
      const Vec3f pu = v[i - 1].dp_du, pv = v[i - 1].dp_dv;
      m.a = tangent_block(unit_change(-(pu - wi * dot(wi, pu)) * ki, H),
                          unit_change(-(pv - wi * dot(wi, pv)) * ki, H), s, t);
    }
    // This vertex moves both directions, and the frame turns with the normal.
    const Vec3f pu = m.dp_du, pv = m.dp_dv;
    const Vec3f dHu =
        unit_change(pu * (ki + ko) - wi * (dot(wi, pu) * ki) - wo * (dot(wo, pu) * ko), H);
    const Vec3f dHv =
        unit_change(pv * (ki + ko) - wi * (dot(wi, pv) * ki) - wo * (dot(wo, pv) * ko), H);
    Vec3f ds_u = -(m.n * dot(m.dp_du, m.dn_du) + m.dn_du * dpn) / ls;
    Vec3f ds_v = -(m.n * dot(m.dp_du, m.dn_dv) + m.dn_dv * dpn) / ls;
    ds_u = ds_u - s * dot(s, ds_u);
    ds_v = ds_v - s * dot(s, ds_v);
    const Vec3f dt_u = cross(m.dn_du, s) + cross(m.n, ds_u);
    const Vec3f dt_v = cross(m.dn_dv, s) + cross(m.n, ds_v);
    m.b = {dot(dHu, s) + dot(H, ds_u), dot(dHv, s) + dot(H, ds_v), dot(dHu, t) + dot(H, dt_u),
           dot(dHv, t) + dot(H, dt_v)};
    const bool last = i == k - 1;
    const Vec3f nu = last ? lu : v[i + 1].dp_du, nv = last ? lv : v[i + 1].dp_dv;
    const Mat2 next = tangent_block(unit_change(-(nu - wo * dot(wo, nu)) * ko, H),
                                    unit_change(-(nv - wo * dot(wo, nv)) * ko, H), s, t);
    if (last)
      *d_light = next;
    else
      m.c = next;
    m.constraint = Vec2f(dot(s, H), dot(t, H));
  }
  return true;
}

// Solves the block-tridiagonal system J dx = rhs (rows: a dx[i-1] + b dx[i] + c dx[i+1]).
bool solve_blocks(const ManifoldVertex* v, int k, const Vec2f* rhs, Vec2f* dx) {
  Mat2 inv[kMaxCausticCasters];
  Vec2f r[kMaxCausticCasters];
  if (!invert(v[0].b, inv[0])) return false;
  r[0] = rhs[0];
  for (int i = 1; i < k; ++i) {
    const Mat2 f = v[i].a * inv[i - 1];
    if (!invert(v[i].b - f * v[i - 1].c, inv[i])) return false;
    r[i] = rhs[i] - f * r[i - 1];
  }
  dx[k - 1] = inv[k - 1] * r[k - 1];
  for (int i = k - 2; i >= 0; --i) dx[i] = inv[i] * (r[i] - v[i].c * dx[i + 1]);
  return true;
}

// The next surface along `ray` from its origin; the ray then continues past it.
bool next_hit(const EmbreeScene& bvh, Ray& ray, SurfaceHit& hit, uint32_t& rays) {
  ++rays;
  if (!bvh.intersect(ray, hit)) return false;
  const Vec3f side = dot(ray.direction, hit.geometric_normal) > 0.0f ? hit.geometric_normal
                                                                     : -hit.geometric_normal;
  ray.origin = offset_ray_origin(hit.position, side, bvh.offset_scale());
  ray.t_max -= hit.t;
  return true;
}

Ray ray_towards(const EmbreeScene& bvh, Vec3f from, Vec3f from_ng, Vec3f to, float reach) {
  Ray r;
  const Vec3f d = to - from;
  const float len = length(d);
  r.direction = d / len;
  r.origin = offset_ray_origin(from, dot(r.direction, from_ng) > 0.0f ? from_ng : -from_ng,
                               bvh.offset_scale());
  r.t_min = 0.0f;
  r.t_max = len * reach;
  r.kind = kRayTransmission;
  return r;
}

// The caster's smooth refraction lobe at `hit` (seen from the ray that found it): its relative
// IOR for that ray and its weight; false when the material is not one smooth dielectric lobe.
bool smooth_refraction(const SceneContext& ctx, const SurfaceHit& hit, ClosureSet& scratch,
                       Closure& lobe) {
  const Material& material = ctx.materials()[size_t(hit.material)];
  const ClosureSet& set = material.closures(shading_context_of(hit), scratch);
  if (set.count() != 1) return false;
  lobe = set[0];
  return lobe.type == ClosureType::GGXDielectric && is_delta_alpha(lobe.alpha) &&
         !lobe.drop_refraction && lobe.ior > 0.0f;
}

// The seed: the casters the straight segment x -> y crosses (other surfaces are passed: the
// refracted path may avoid them). Returns their count, 0 when there are none or any is unusable.
int seed_chain(const SceneContext& ctx, Vec3f x, Vec3f ng_x, Vec3f y, ManifoldVertex* v,
               ClosureSet& scratch, uint32_t& rays) {
  const EmbreeScene& bvh = ctx.bvh();
  Ray ray = ray_towards(bvh, x, ng_x, y, 1.0f);
  int k = 0;
  SurfaceHit hit;
  for (int n = 0; n < kMaxSeedHits && next_hit(bvh, ray, hit, rays); ++n) {
    if (!ctx.is_caustics_caster(hit)) continue;
    Closure lobe;
    if (k == kMaxCausticCasters || !smooth_refraction(ctx, hit, scratch, lobe)) return 0;
    // The material gives the IOR for the side the ray came from.
    setup_vertex(bvh, hit, hit.front_facing ? lobe.ior : 1.0f / lobe.ior, v[k++]);
  }
  return k;
}

// Moves `from`'s tentative point back onto its instance's surface along the ray from the
// previous vertex; false when that ray does not reach it.
bool project(const SceneContext& ctx, Vec3f origin, Vec3f origin_ng, Vec3f target,
             const ManifoldVertex& from, ManifoldVertex& to, uint32_t& rays) {
  const EmbreeScene& bvh = ctx.bvh();
  Ray ray = ray_towards(bvh, origin, origin_ng, target, 2.0f);
  SurfaceHit hit;
  for (int n = 0; n < kMaxSeedHits && next_hit(bvh, ray, hit, rays); ++n) {
    if (hit.instance != from.hit.instance) continue;
    setup_vertex(bvh, hit, from.ior, to);
    return true;
  }
  return false;
}

// The largest squared constraint of the chain.
float constraint_norm(const ManifoldVertex* v, int k) {
  float norm = 0.0f;
  for (int i = 0; i < k; ++i)
    norm = std::max(norm,
                    v[i].constraint.x * v[i].constraint.x + v[i].constraint.y * v[i].constraint.y);
  return norm;
}

// The chain moved by `beta` times the Newton step `dx` and projected back onto the casters;
// false when a vertex leaves its caster or stops refracting.
bool step_chain(const SceneContext& ctx, Vec3f x, Vec3f ng_x, Vec3f y, const ManifoldVertex* v,
                int k, const Vec2f* dx, float beta, ManifoldVertex* out, uint32_t& rays) {
  for (int i = 0; i < k; ++i) {
    const Vec3f step = (v[i].dp_du * dx[i].x + v[i].dp_dv * dx[i].y) * beta;
    Vec3f target = v[i].p - step;
    // A first vertex stepped below the receiver: try the other way (as Cycles does).
    if (i == 0 && dot(ng_x, target - x) <= 0.0f) target = v[i].p + step;
    const Vec3f origin = i == 0 ? x : v[i - 1].p;
    const Vec3f origin_ng = i == 0 ? ng_x : v[i - 1].ng;
    if (!project(ctx, origin, origin_ng, target, v[i], out[i], rays)) return false;
  }
  // Every vertex must still refract (its neighbours on both sides of its normal).
  for (int i = 0; i < k; ++i) {
    const Vec3f wi = (i == 0 ? x : out[i - 1].p) - out[i].p;
    const Vec3f wo = (i == k - 1 ? y : out[i + 1].p) - out[i].p;
    if (!(dot(out[i].n, wi) * dot(out[i].n, wo) < 0.0f)) return false;
  }
  return true;
}

// Newton's method on the specular manifold from the seed in v (Cycles' scheme): a step that
// leaves the casters or stops refracting is halved, an accepted one doubles the next (up to a
// full step). True when it converged; the constraints and their derivatives are then those of
// the solution.
bool walk(const SceneContext& ctx, Vec3f x, Vec3f ng_x, Vec3f y, Vec3f lu, Vec3f lv,
          ManifoldVertex* v, int k, uint32_t& rays) {
  ManifoldVertex tentative[kMaxCausticCasters];
  Vec2f dx[kMaxCausticCasters], rhs[kMaxCausticCasters];
  Mat2 d_light;
  // Start gently: far from the solution the linearised normals mislead a full step.
  float beta = 0.1f;
  bool fresh = false;  // dx belongs to the current vertices
  for (int it = 0; it < kMaxIterations; ++it) {
    if (!fresh) {
      if (!constraints(v, k, x, y, lu, lv, &d_light)) return false;
      if (constraint_norm(v, k) < kConstraintTolerance * kConstraintTolerance) return true;
      for (int i = 0; i < k; ++i) rhs[i] = v[i].constraint;
      if (!solve_blocks(v, k, rhs, dx)) return false;
      fresh = true;
    }
    if (!step_chain(ctx, x, ng_x, y, v, k, dx, beta, tentative, rays)) {
      beta *= 0.5f;
      if (beta < kMinStep) return false;
      continue;
    }
    for (int i = 0; i < k; ++i) v[i] = tentative[i];
    fresh = false;
    beta = std::min(1.0f, 2.0f * beta);
  }
  return false;
}

// |det d x1 / d y|: how the first caster vertex moves with the light point, both in their
// tangent frames' area measure (the implicit function theorem on the constraints).
float transfer_determinant(const ManifoldVertex* v, int k, const Mat2& d_light) {
  Vec2f rhs[kMaxCausticCasters], du[kMaxCausticCasters], dv[kMaxCausticCasters];
  for (int i = 0; i < k; ++i) rhs[i] = Vec2f();
  rhs[k - 1] = Vec2f(d_light.a, d_light.c);
  if (!solve_blocks(v, k, rhs, du)) return 0.0f;
  rhs[k - 1] = Vec2f(d_light.b, d_light.d);
  if (!solve_blocks(v, k, rhs, dv)) return 0.0f;
  return std::fabs(du[0].x * dv[0].y - dv[0].x * du[0].y);
}

}  // namespace

CausticConnection caustic_connection(const SceneContext& ctx, Vec3f x, Vec3f ng_x,
                                     const LightSample& ls, ClosureSet& scratch, uint32_t& rays) {
  CausticConnection out;
  const EmbreeScene& bvh = ctx.bvh();
  const Vec3f y = ls.position;
  ManifoldVertex v[kMaxCausticCasters];
  const int k = seed_chain(ctx, x, ng_x, y, v, scratch, rays);
  out.casters = k;
  if (k == 0) return out;
  const Frame light_frame(ls.normal);
  if (!walk(ctx, x, ng_x, y, light_frame.s, light_frame.t, v, k, rays)) return out;
  Mat2 d_light;
  if (!constraints(v, k, x, y, light_frame.s, light_frame.t, &d_light)) return out;
  const float transfer = transfer_determinant(v, k, d_light);

  // --- The path found: unoccluded, each vertex a smooth refraction ---
  Spectrum throughput(1.0f);
  Vec3f from = x, from_ng = ng_x;
  for (int i = 0; i < k; ++i) {
    const float d = length(v[i].p - from);
    Ray ray = ray_towards(bvh, from, from_ng, v[i].p, 1.0f + 1e-3f);
    SurfaceHit hit;
    ++rays;
    if (!bvh.intersect(ray, hit) || hit.instance != v[i].hit.instance ||
        std::fabs(hit.t - d) > 1e-3f * d)
      return out;
    Closure lobe;
    if (!smooth_refraction(ctx, hit, scratch, lobe)) return out;
    const Vec3f wi = normalize(from - v[i].p);
    const float cos_n = dot(wi, hit.shading_normal), cos_i = std::fabs(cos_n);
    const float fresnel =
        lobe.fresnel == FresnelMode::RefractionOnly ? 0.0f : fresnel_dielectric(cos_i, lobe.ior);
    throughput = throughput * lobe.weight * lobe.transmission_tint * (1.0f - fresnel);
    // The glass lobe's own choice between reflection and refraction (ggx_dielectric::sample).
    const float eta = cos_n > 0.0f ? lobe.ior : 1.0f / lobe.ior;
    out.refraction_pdf *= 1.0f - ggx_dielectric::split(lobe, eta, cos_i).p_reflect;
    from = v[i].p;
    from_ng = v[i].ng;
  }
  const Vec3f to_light = y - from;
  const float d_light_len = length(to_light);
  const Vec3f origin = offset_ray_origin(from, dot(to_light, from_ng) > 0.0f ? from_ng : -from_ng,
                                         bvh.offset_scale());
  ++rays;
  if (ls.cast_shadow && bvh.occluded(shadow_ray_to_point(origin, y, kRayShadow))) return out;
  LightHit lh;
  if (!ctx.lights().intersect(from, to_light / d_light_len, d_light_len * (1.0f + 1e-3f), lh) ||
      length(lh.position - y) > 1e-3f * d_light_len)
    return out;

  // --- Its transport: lamp radiance x d omega_x / d A(y) ---
  const Vec3f wo_x = v[0].p - x;
  const float d0 = length(wo_x);
  const float g = std::fabs(dot(wo_x / d0, v[0].ng)) / (d0 * d0) * transfer;
  if (!(g > 0.0f) || !std::isfinite(g)) return out;
  out.transport = throughput * lh.radiance * g;
  out.solid_angle_per_area = g;
  out.direction = wo_x / d0;
  out.valid = !is_black(out.transport);
  return out;
}

CausticShare caustic_share(const PathState& before, const RenderSettings& s) {
  CausticShare share;
  share.mis = s.caustics_refractive;
  const BounceCounts& n = before.kinds;
  if (n.diffuse + 1 > s.max_diffuse_bounces || n.glossy + 1 > s.max_glossy_bounces) return share;
  // The lamp counts when the last caster still scatters: its bounce and transmission counts
  // within the limits (the receiver's bounce counted as a transmission too).
  share.reach = std::max(
      0, std::min(s.max_bounces - before.bounce, s.max_transmission_bounces - n.transmission));
  return share;
}

float manifold_nee_weight(const CausticConnection& c, const CausticShare& share, float area_pdf,
                          Vec3f ng_x) {
  if (!share.mis || c.casters > share.reach) return 1.0f;
  const float bsdf_pdf =
      std::fabs(dot(c.direction, ng_x)) * kInvPi * c.refraction_pdf * c.solid_angle_per_area;
  return power_heuristic(area_pdf, bsdf_pdf);
}

float CausticChain::weight(const SceneContext& ctx, const LightHit& lh, ClosureSet& scratch,
                           uint32_t& rays) const {
  if (state != 2 || !lh.caustics || !(lh.area_pdf > 0.0f)) return 1.0f;
  if (!share.mis) return 0.0f;  // Cycles' rule: manifold NEE alone
  LightSample ls;
  ls.position = lh.position;
  ls.normal = lh.normal;
  const CausticConnection c = caustic_connection(ctx, receiver, receiver_ng, ls, scratch, rays);
  // The walk stops within 1e-4 of Snell's law; near the caustic's folds the same path's first
  // direction still differs by up to half a degree (measured with the paths dropped, before the
  // weighing: at 1 - 1e-6 too few were, 1.047 of the light at IOR 1.3 against 1.032 here),
  // distinct paths by more.
  if (!(c.valid && dot(c.direction, direction) > 1.0f - 5e-5f)) return 1.0f;
  return 1.0f - manifold_nee_weight(c, share, lh.area_pdf, receiver_ng);
}

}  // namespace gdpt
