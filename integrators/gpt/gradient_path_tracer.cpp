// Gradient-domain path tracer: see gradient_path_tracer.h for the estimator and the film layout,
// docs/gradient.md ("The code and the paper's notation") for its phases' files and names.
//
// Parameters (RenderSettings): max_bounces and the per-kind limits (path_state.h), rr_depth
// (Russian roulette decided by the base path, its probability multiplied into base and offset
// densities alike), shift_roughness_threshold (vertex classification), seed, clamp (applied to
// the primal only, as the path tracer does).
//
// Bookkeeping: each path keeps its throughput f (product of BSDF values, not divided by pdfs) and
// its density p (product of solid-angle densities), both in double; offsets multiply their shift
// Jacobians into both. An emission event of the base path (light sample, BSDF-sampled light hit,
// world) with contribution C = f * segment, and the matching offset contribution C' (Jacobian
// included), adds w (C' - C) to the gradient half of that offset, w = shift::mis_weight_over_pdf.
#include "integrators/gpt/gradient_path_tracer.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>

#include "integrators/common/manifold_nee.h"
#include "integrators/common/path_state.h"
#include "integrators/gpt/camera_rays.h"
#include "integrators/gpt/caustic_pairs.h"
#include "integrators/gpt/emission_events.h"
#include "integrators/gpt/gpt_context.h"
#include "integrators/gpt/nee_pairs.h"
#include "integrators/gpt/offset_path.h"
#include "integrators/gpt/path_scratch.h"
#include "integrators/gpt/path_vertex.h"
#include "render/sampler.h"

namespace gdpt {

namespace {

using shift::Vec3d;
using shift::VertexType;

constexpr float kInf = std::numeric_limits<float>::infinity();

// Adds one half to a gradient accumulator (sum and squared luminance) and, unless null, to the
// sum of its sample's half (Film::half_a_gradients); a non-finite half counts as 0, as a
// non-finite primal does.
void add_half(Vec3d g, double* sum, double& sum2, double* half_sum) {
  if (!(std::isfinite(g.x) && std::isfinite(g.y) && std::isfinite(g.z))) g = Vec3d();
  sum[0] += g.x;
  sum[1] += g.y;
  sum[2] += g.z;
  const double l = 0.2126 * g.x + 0.7152 * g.y + 0.0722 * g.z;
  sum2 += l * l;
  if (half_sum) {
    half_sum[0] += g.x;
    half_sum[1] += g.y;
    half_sum[2] += g.z;
  }
}

// A survived roulette of continuation probability q: the base's throughput is divided by it, and
// it enters every density of the pair.
void divide_by_continuation(float q, BasePath& bp, Offset* off) {
  bp.beta /= q;
  bp.pb *= q;
  for (int k = 0; k < kOffsets; ++k) off[k].p *= q;
}

class GradientPathTracer final : public Integrator {
 public:
  GradientPathTracer(const SceneContext& ctx, const RenderSettings& settings) : g_(ctx, settings) {}

  bool estimates_gradients() const override { return true; }

  void render_tile(const Tile& tile, uint32_t first_sample, uint32_t sample_count,
                   Film& film) const override {
    const int W = film.width(), H = film.height();
    // Raster positions and sampler keys are the frame's (a render region samples as the frame).
    const int rx = g_.ctx.camera().region_x(), ry = g_.ctx.camera().region_y();
    uint64_t rays = 0;
    // This call's working storage, default-initialised (make_unique would zero its kilobytes).
    const std::unique_ptr<PathScratch> scratch(new PathScratch);
    SampleResult r;
    const uint32_t end = first_sample + sample_count;
    if (!g_.has_dof) {
      CameraGrid& grid = scratch->grid;
      bool mask[kOffsets];
      for (uint32_t s = first_sample; s < end; ++s) {
        const uint32_t index = film.sequence_index(s);
        rays += trace_camera_grid(g_, tile, W, H, index, grid);
        for (int y = tile.y0; y < tile.y1; ++y)
          for (int x = tile.x0; x < tile.x1; ++x) {
            // Adaptive sampling: a stopped pixel's camera ray is still its neighbours' offset.
            if (!film.sampling(x, y)) continue;
            Sampler sampler;
            start_sample(g_, sampler, x + rx, y + ry, index);
            offset_mask(W, H, x, y, mask);
            const CameraSample cs = grid_sample(grid, x, y, mask);
            // Depth and index passes: the first sample's camera hit (sample 0, as Cycles).
            if (s == g_.settings.sample_offset && cs.found)
              g_.ctx.record_first_hit(film, x, y, *cs.hit);
            rays += run_path(sampler, cs, x, y, s, *scratch, r, film);
          }
      }
    } else {
      CameraRow& row = scratch->row;
      for (uint32_t s = first_sample; s < end; ++s) {
        const uint32_t index = film.sequence_index(s);
        for (int y = tile.y0; y < tile.y1; ++y)
          for (int x0 = tile.x0; x0 < tile.x1; x0 += kRow) {
            const int n = std::min(kRow, tile.x1 - x0);
            rays += trace_camera_row(g_, W, H, x0, y, n, index, row);
            for (int i = 0; i < n; ++i) {
              if (!film.sampling(x0 + i, y)) continue;
              if (s == g_.settings.sample_offset && row.found[i])  // the first sample's hit
                g_.ctx.record_first_hit(film, x0 + i, y, row.hit[i]);
              rays += run_path(row.sampler[i], row_sample(row, i), x0 + i, y, s, *scratch, r, film);
            }
          }
      }
    }
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x)
        if (film.sampling(x, y)) film.add_sample_count(x, y, sample_count);
    count_rays(rays);
  }

 private:
  // Runs pixel (x, y)'s base path and adds it to the film. Returns its rays past the camera's.
  uint32_t run_path(const Sampler& sampler, const CameraSample& cs, int x, int y, uint32_t s,
                    PathScratch& scratch, SampleResult& r, Film& film) const {
    // The pixel's accumulators (4 cache lines) are read after the path: fetch them now.
    Film::Accumulator& acc = film.pixel(x, y);
    Film::GradientAccumulator& grad = film.gradients(x, y);
    __builtin_prefetch(&acc, 1);
    const char* grad_bytes = reinterpret_cast<const char*>(&grad);
    for (size_t b = 0; b < sizeof(grad); b += 64) __builtin_prefetch(grad_bytes + b, 1);
    trace(sampler, cs, scratch, r);
    // --- Primal, emission and statistics of the pixel's base path ---
    const Spectrum added = acc.add_path(r.primal, r.emission, g_.settings.clamp, r.alpha);
    if (g_.data.active()) film.add_data(x, y, r.data.normal, r.data.mist);
    if (g_.features.active())
      film.add_features(x, y, s, added, r.feature.albedo, r.feature.normal, r.feature.depth);
    grad.shift_attempts += r.attempts;
    grad.shift_failures += r.failures;
    // --- Gradient halves: dx(x) = G_right(x) - G_left(x + 1), likewise dy ---
    // With the feature passes, a half-A sample's halves go to the half-A sums too.
    const bool* mask = cs.mask;
    Film::HalfAGradients* a = film.half_a_gradients(x, y, s);
    if (mask[kRight]) add_half(r.grad[kRight], grad.dx, grad.dx2, a ? a->dx : nullptr);
    if (mask[kUp]) add_half(r.grad[kUp], grad.dy, grad.dy2, a ? a->dy : nullptr);
    if (mask[kLeft]) add_half(r.grad[kLeft], grad.dx_left, grad.dx_left2, a ? a->dx_left : nullptr);
    if (mask[kDown]) add_half(r.grad[kDown], grad.dy_down, grad.dy_down2, a ? a->dy_down : nullptr);
    return r.rays;
  }

  // Traces one base path and its offsets from camera rays render_tile() has traced.
  void trace(const Sampler& sampler, const CameraSample& cs, PathScratch& scratch,
             SampleResult& out) const {
    const EmbreeScene& bvh = g_.ctx.bvh();
    const LightSampler& lights = g_.ctx.lights();
    const RenderSettings& settings = g_.settings;
    const bool has_lights = !lights.empty();
    Offset* off = scratch.off;

    // --- Camera: very direct light, the base's and the offsets' first vertices ---
    if (!start(cs, scratch, out)) return;
    BasePath bp;
    int cur = 0;  // scratch.verts[cur] is the base vertex
    Ray ray;      // the base's segment; a transparent crossing keeps its kind
    // Bounce 0's numbers; later bounces' are drawn before the segment to them is traced, to run
    // alongside it (Sampler::vertex_numbers).
    Sampler::VertexNumbers u = sampler.vertex_numbers(0, has_lights);
    // `bounce` numbers every vertex (sampler dimensions), transparent crossings included.
    for (int bounce = 0;; ++bounce) {
      if (bp.state.bounce > settings.max_bounces) break;
      const Vertex& base = scratch.verts[cur];
      Vertex& next_base = scratch.verts[cur ^ 1];
      // Normal / Mist passes at the surfaces the camera path meets after transparent crossings
      // (the camera hit's are recorded by start()).
      if (bounce > 0 && bp.state.camera_path && g_.data.active())
        g_.data.at_surface(base.hit, *base.closures, bp.beta, out.data);
      if (bounce > 0 && g_.features.active())
        g_.features.at_surface(base.hit, *base.closures, length(base.hit.position - ray.origin),
                               std::fabs(base.wi.z), out.feature);
      if (!base.closures->has_bsdf()) break;
      const VertexType base_type = g_.classify(base.roughness);
      const ClosureSet& bc = *base.closures;
      const unsigned open_mask = open_offsets(base, base_type, bp.state, off);

      // --- Next-event estimation: base and offsets (nee_pairs.h) ---
      if (has_lights) {
        // Dimensions are indexed, not streamed: skipping an unused one changes no other value.
        // Offsets resample with the base's numbers.
        const float u_select =
            lights.needs_selection()
                ? sampler.get1d(Sampler::bounce_dim(bounce, Sampler::kLightSelect))
                : 0.0f;
        const LightSample ls = lights.sample(base.hit.position, u_select, u.light);
        // Shadow caustics take the samples whose segment crosses casters (caustic_pairs.h).
        if (ls.valid && ls.pdf > 0.0f &&
            !(runs_shadow_caustics(g_.ctx, base.hit, ls) &&
              caustic_pairs(g_, base, bp, ls, u_select, u.light, open_mask, scratch, out)))
          nee_pairs(g_, base, bp, ls, u_select, u.light, open_mask, scratch, out);
      }

      // --- BSDF sampling: extend the base ---
      // The lobe number is drawn when the base's closures read it (the offsets never do).
      const float u_lobe = bc.uses_lobe_choice()
                               ? sampler.get1d(Sampler::bounce_dim(bounce, Sampler::kBsdfLobe))
                               : 0.0f;
      const BsdfSample bs = bc.sample(base.wi, u_lobe, u.dir);
      if (!bs.valid || !(bs.pdf > 0.0f) || is_black(bs.value)) break;
      const Vec3f wo_world = base.frame.to_world(bs.wo);
      const float cos_ng = dot(wo_world, base.ng);
      if (!bc.side_ok(bs.wo, cos_ng)) break;
      const bool delta = bs.is_delta();
      bp.beta *= bs.value / bs.pdf;
      const bool crossing = bs.is_straight_crossing();
      ray.kind = crossing ? ray.kind : ray_kind_of_lobe(bs.lobe);
      // Shadow caustics' rule from the path state before this bounce (offsets below share it).
      const CausticShare caustic_share_here =
          g_.ctx.shadow_caustics() ? caustic_share(bp.state, settings) : CausticShare{};
      bp.caustic.scattered(g_.ctx, base.hit, bs, wo_world, caustic_share_here);
      bp.state.count_event(crossing, ray.kind, bs.lobe);
      if (!crossing) bp.state.scattered(bs);

      // --- Russian roulette, decided by the base; q enters every density of the pair ---
      if (!crossing) {
        const float q =
            bp.state.roulette(settings, g_.ctx.scene_features(), bp.beta, bs.lobe, sampler, bounce);
        if (q == 0.0f) break;
        if (q != 1.0f) divide_by_continuation(q, bp, off);
      }

      // --- Trace the base's next segment; its hit goes straight into the next vertex ---
      ray.origin = ray_origin(base, cos_ng > 0.0f);
      ray.direction = normalize(wo_world);
      ray.t_min = 0.0f;
      ray.t_max = kInf;
      const bool camera_path = bp.state.camera_path;
      const bool last = bp.state.last(settings);
      if (!last) u = sampler.vertex_numbers(bounce + 1, has_lights);
      const SurfaceHit& next = next_base.hit;
      // A holdout met by the camera path ends it; the offsets' segments likewise (shift_segment).
      const bool holdout_ends = g_.ctx.has_holdout() && camera_path;
      bool found = distance_only(last, open_mask != 0 || g_.has_emissive || holdout_ends)
                       ? bvh.intersect_distance(ray, next_base.hit.t)
                       : bvh.intersect(ray, next_base.hit);
      ++out.rays;
      const bool base_holdout = found && holdout_ends && g_.ctx.is_holdout(next);
      const float t_hit = found ? next.t : kInf;
      found = found && !base_holdout;
      LightHit lh;
      const bool light_hit = lights.intersect(ray.origin, ray.direction, t_hit, lh);
      // The end point of the last segment is no vertex: the shifts need its classification only.
      VertexType next_type = VertexType::Diffuse;
      if (found && !last) {
        finish_vertex(g_.ctx, g_.sides, g_.rules(bp.state), ray.direction, bp.state.view(next.t),
                      next_base);
        next_type = g_.classify(next_base.roughness);
      } else if (found && open_mask != 0) {
        next_type = g_.classify_hit(next, bp.state);
      }

      // --- Shift every open offset over this segment (offset_path.h) ---
      // Classification of x_d for this step: a sampled delta lobe makes it specular.
      const VertexType xd_type = delta ? VertexType::Specular : base_type;
      if (open_mask != 0) {
        BaseStep& st = scratch.step;
        prepare_step(base, bs, xd_type, next_type, wo_world, found, next, ray.kind, holdout_ends,
                     bp.state, st);
        for (unsigned m = open_mask; m != 0; m &= m - 1)
          shift_segment(g_, off[std::countr_zero(m)], st, out.rays);
      }

      // Shadow caustics' rule follows each offset's own path: a connected offset's is the base's.
      if (g_.ctx.shadow_caustics())
        for (Offset& o : scratch.off) {
          if (!o.active || !o.alive) continue;
          if (o.link == Link::NotConnected)
            o.caustic.scattered(g_.ctx, o.v.hit, bs, o.seg_dir, caustic_share_here);
          else
            o.caustic = bp.caustic;
        }

      // --- Emission events at the end of the segment (emission_events.h) ---
      const Vec3d seg_b = Vec3d(bs.value);
      const SegmentEnd e{
          &base,
          base_type,
          &ray,
          delta,
          seg_b,
          bs.pdf,
          found,
          base_holdout,
          &next,
          camera_path,
          camera_path ? g_.has_camera_world && !settings.transparent_background : g_.has_world,
          light_hit,
          &lh,
          &scratch.shadow_closures};
      Vec3d emit_merged = lamp_events(g_, e, bp, open_mask, off, out);
      end_events(g_, e, bp, open_mask, off, emit_merged, out);
      if (!is_zero(emit_merged)) add_merged(off, bp.fb, bp.pb, emit_merged);
      if (const float q = bp.state.take_deferred_division(); q != 1.0f)
        divide_by_continuation(q, bp, off);

      // --- Advance base and offsets to the segment's end ---
      bp.fb = mul(bp.fb, seg_b);
      bp.pb *= bs.pdf;
      const PathView next_view = bp.state.view(0.0f);
      for (Offset& o : scratch.off) {
        if (!o.active || !o.alive) continue;
        if (o.link == Link::Connected) {  // the base's segment (shift_segment skipped them)
          o.f = mul(o.f, seg_b);
          o.p *= bs.pdf;
        } else {
          advance(g_, o, last, bp.state, next_view);
        }
      }
      if (!found || last) break;  // last: the end point was not set up as a vertex
      cur ^= 1;
    }

    for (int k = 0; k < kOffsets; ++k) {
      out.grad[k] = off[k].grad;
      if (off[k].active && (off[k].failed || !off[k].alive)) ++out.failures;
    }
  }

  // The camera's part of a sample: very direct light (lamps visible to the camera, the world,
  // emissive triangles seen directly: never shifted), the base's first vertex and the offsets'.
  // False when the camera ray escaped or met a holdout (the sample is complete).
  bool start(const CameraSample& cs, PathScratch& scratch, SampleResult& out) const {
    const LightSampler& lights = g_.ctx.lights();
    const PathState camera_state;  // the camera hits: no light-path rule applies yet
    out.primal = Spectrum(0.0f);
    out.emission = Spectrum(0.0f);
    out.alpha = 1.0f;
    out.attempts = out.failures = 0;
    out.rays = 0;  // camera rays are counted by render_tile()
    out.data = DataSample{};
    out.feature = FeatureSample{};
    const Ray& cam_ray = *cs.ray;
    const SurfaceHit& hit = *cs.hit;
    // A holdout at the camera hit ends the path as an escape to a black world would (Cycles:
    // nothing added; with a transparent background coverage 0); offsets meeting one are dead.
    const bool holdout = cs.found && holdout_ends_path(g_.ctx, true, hit);
    const bool camera_found = cs.found && !holdout;
    if (g_.has_visible_lamps) {
      LightHit lh;
      if (lights.intersect(cam_ray.origin, cam_ray.direction, cs.found ? hit.t : cam_ray.t_max,
                           lh) &&
          lh.camera_visible)
        out.emission += lh.radiance;
    }
    if (!camera_found) {
      if (g_.settings.transparent_background)
        out.alpha = 0.0f;
      else if (g_.has_camera_world && !holdout)
        out.emission += lights.camera_environment(cam_ray.direction);
      for (Vec3d& grad : out.grad) grad = Vec3d();
      return false;
    }
    for (int k = 0; k < kOffsets; ++k) {
      Offset& o = scratch.off[k];
      o.active = cs.mask[k];
      o.alive = false;
      if (!o.active) continue;
      ++out.attempts;
      o.failed = false;
      o.link = Link::NotConnected;
      o.nee_on = true;
      o.f = Vec3d(1.0, 1.0, 1.0);
      o.p = 1.0;
      o.grad = Vec3d();
      // Base hits a surface, the offset the world: no shift.
      o.alive = cs.off_found[k] && !holdout_ends_path(g_.ctx, true, *cs.off_hit[k]);
      if (o.alive) {
        PathView camera;
        camera.ray_length = cs.off_hit[k]->t - cs.off_ray[k]->t_min;  // from the near clip
        setup_vertex(g_.ctx, g_.sides, g_.rules(camera_state), *cs.off_hit[k],
                     cs.off_ray[k]->direction, camera, o.v);
      }
    }
    Vertex& base = scratch.verts[0];
    PathView camera;
    camera.ray_length = hit.t - cam_ray.t_min;
    setup_vertex(g_.ctx, g_.sides, g_.rules(camera_state), hit, cam_ray.direction, camera, base);
    if (g_.data.active()) g_.data.at_surface(hit, *base.closures, Spectrum(1.0f), out.data);
    if (g_.features.active())
      g_.features.at_surface(hit, *base.closures, length(hit.position - cam_ray.origin),
                             std::fabs(base.wi.z), out.feature);
    // Seen from the near clip (the ray length of a camera ray, as Cycles starts it there).
    out.emission += g_.triangle_le(hit, cam_ray.origin + cam_ray.direction * cam_ray.t_min, camera);
    return true;
  }

  // The offsets with work of their own at this base vertex (bit k: offset k alive and not
  // connected); connected and dead ones are merged (add_merged). Offsets arriving at a shared
  // vertex see it from their own direction. Per-pair NEE rule, shared by light sampling and the
  // BSDF-sampled light hits at the next vertex: a not-connected pair shifts light samples only
  // when both vertices are diffuse. A dead offset leaves the base alone with both of its
  // techniques: light sampling stays on (nee_on, as for connected offsets).
  unsigned open_offsets(const Vertex& base, VertexType base_type, const PathState& state,
                        Offset* off) const {
    unsigned open_mask = 0;
    for (int k = 0; k < kOffsets; ++k) {
      Offset& o = off[k];
      o.nee_on = true;
      if (!o.active || !o.alive || o.link == Link::Connected) continue;
      if (o.link == Link::Recent) {
        o.wi_shared = base.frame.to_local(o.wi_world);
        // Its own segment from y_d (still in o.v) to the shared vertex.
        o.shared =
            &shared_closures(g_.ctx, g_.rules(state), base, o.wi_world,
                             state.view(length(base.hit.position - o.v.hit.position)), o.v.own);
      } else if (!o.v.closures->has_bsdf()) {
        o.alive = false;  // the offset ends on a surface without BSDF: it cannot follow
        continue;
      } else {
        o.nee_on =
            base_type == VertexType::Diffuse && g_.classify(o.v.roughness) == VertexType::Diffuse;
      }
      open_mask |= 1u << k;
    }
    return open_mask;
  }

  // The base's segment as the offsets' shift_segment() sees it. Filled member by member: an
  // aggregate assignment built a temporary with narrow stores and copied it with wide loads
  // across them (failed store-to-load forwarding).
  static void prepare_step(const Vertex& base, const BsdfSample& bs, VertexType xd_type,
                           VertexType next_type, Vec3f wo_world, bool found, const SurfaceHit& next,
                           uint32_t kind, bool holdout_ends, const PathState& state, BaseStep& st) {
    st.base = &base;
    st.bs = &bs;
    st.xd_type = xd_type;
    st.next_type = next_type;
    st.wo_world = wo_world;
    st.found = found;
    st.next = &next;
    st.base_delta_unique = delta_event_unique(base, bs);
    st.kind = kind;
    st.holdout_ends = holdout_ends;
    st.state = &state;
    st.base_front = false;
    // The reconnection target (a double square root and division) only where shift_segment()
    // may reconnect: x_d and x_{d+1} diffuse.
    if (found && xd_type == VertexType::Diffuse && next_type == VertexType::Diffuse) {
      st.target = shift::reconnection_base(base.hit.position, next.position, next.geometric_normal);
      st.base_front = dot(base.hit.position - next.position, next.geometric_normal) > 0;
    }
  }

  GptContext g_;
};

}  // namespace

std::unique_ptr<Integrator> make_gradient_path_tracer(const SceneContext& ctx,
                                                      const RenderSettings& settings) {
  return std::make_unique<GradientPathTracer>(ctx, settings);
}

}  // namespace gdpt
