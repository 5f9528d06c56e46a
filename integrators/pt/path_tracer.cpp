#include "integrators/pt/path_tracer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "core/frame.h"
#include "integrators/common/bump_shadowing.h"
#include "integrators/common/data_passes.h"
#include "integrators/common/feature_passes.h"
#include "integrators/common/light_path_filters.h"
#include "integrators/common/manifold_nee.h"
#include "integrators/common/mis.h"
#include "integrators/common/path_state.h"
#include "integrators/common/shadow_ray.h"
#include "integrators/common/surface_frame.h"
#include "render/features.h"
#include "render/sampler.h"
#include "render/scene_context.h"
#include "render/vertex_number_batch.h"
#include "shaders/shading_context.h"

namespace gdpt {

namespace {

constexpr uint32_t kSpecialised =
    kSceneDoF | kSceneWorld | kSceneAnalyticLights | kSceneEmissiveTriangles | kFeatureTransparent;
constexpr float kInf = std::numeric_limits<float>::infinity();

// Radiance of one camera sample, split as the film stores it.
struct PathResult {
  Spectrum primal{0.0f};
  Spectrum emission{0.0f};  // camera-visible emission
  float alpha = 1.0f;       // Film::alpha()
  uint32_t rays = 0;
  DataSample data;        // Normal / Mist passes (DataPasses)
  FeatureSample feature;  // FeaturePasses
};

template <uint32_t kFeatures>
class PathTracer final : public Integrator {
  static constexpr bool kDoF = (kFeatures & kSceneDoF) != 0;
  static constexpr bool kWorld = (kFeatures & kSceneWorld) != 0;
  static constexpr bool kAnalytic = (kFeatures & kSceneAnalyticLights) != 0;
  static constexpr bool kEmissive = (kFeatures & kSceneEmissiveTriangles) != 0;
  static constexpr bool kTransparentShadows = (kFeatures & kFeatureTransparent) != 0;

 public:
  PathTracer(const SceneContext& ctx, const RenderSettings& settings)
      : ctx_(ctx),
        settings_(settings),
        data_(settings, ctx.camera()),
        features_(settings),
        filters_(settings) {}

  // Camera rays go to Embree a row segment at a time (kStream pixels of one sample index) as one
  // coherent stream, which traverses neighbouring rays together; each path then continues from
  // its camera hit. Every pixel still takes its samples in index order: the image is the same as
  // with one camera ray at a time, bit for bit.
  void render_tile(const Tile& tile, uint32_t first_sample, uint32_t sample_count,
                   Film& film) const override {
    constexpr int kStream = 16;
    uint64_t rays = 0;
    // The segment's Samplers, camera jitters and first vertices' numbers, for one sample index.
    VertexNumberBatch numbers;
    static_assert(VertexNumberBatch::kMaxPixels >= kStream);
    Ray camera_rays[kStream];
    bool valid[kStream], found[kStream];
    SurfaceHit hits[kStream];  // each path's working hit record, starting as its camera hit
    // ~0.5 KB each: initialised once per tile, not per sample.
    ClosureSet closures, scratch, filtered;
    const float clamp = settings_.clamp;
    // Raster positions and sampler keys are the frame's (a render region samples as the frame).
    const int rx = ctx_.camera().region_x(), ry = ctx_.camera().region_y();
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x0 = tile.x0; x0 < tile.x1; x0 += kStream) {
        const int n = std::min(kStream, tile.x1 - x0);
        numbers.prepare(settings_.seed, x0 + rx, y + ry, n, settings_.max_bounces + 1,
                        !ctx_.lights().empty());
        int sampling = 0;  // adaptive sampling: the segment's pixels that take samples
        for (int j = 0; j < n; ++j) sampling += valid[j] = film.sampling(x0 + j, y);
        if (sampling == 0) continue;
        for (uint32_t s = first_sample; s < first_sample + sample_count; ++s) {
          // --- Camera rays of the segment, traced together ---
          numbers.fill(film.sequence_index(s));
          for (int j = 0; j < n; ++j)
            camera_rays[j] = camera_ray(numbers.sampler(j), numbers.camera(j), x0 + j + rx, y + ry);
          ctx_.bvh().intersect_stream(camera_rays, valid, n, found, hits);
          if (s == settings_.sample_offset)  // Depth and index passes: the first sample's hit
            for (int j = 0; j < n; ++j)
              if (found[j]) ctx_.record_first_hit(film, x0 + j, y, hits[j]);
          // --- The paths ---
          for (int j = 0; j < n; ++j) {
            if (!valid[j]) continue;
            const PathResult r =
                trace(numbers, j, camera_rays[j], found[j], closures, scratch, filtered, hits[j]);
            rays += r.rays;
            const Spectrum added =
                film.pixel(x0 + j, y).add_path(r.primal, r.emission, clamp, r.alpha);
            if (data_.active()) film.add_data(x0 + j, y, r.data.normal, r.data.mist);
            if (features_.active())
              film.add_features(x0 + j, y, s, added, r.feature.albedo, r.feature.normal,
                                r.feature.depth);
          }
        }
      }
      for (int x = tile.x0; x < tile.x1; ++x)
        if (film.sampling(x, y)) film.add_sample_count(x, y, sample_count);
    }
    count_rays(rays);
  }

 private:
  // Fraction of light passing along the shadow ray (SceneContext::transmittance); opaque-only
  // scenes use one occlusion query.
  Spectrum transmittance(const Ray& ray, ClosureSet& scratch, uint32_t& rays) const {
    if (!kTransparentShadows) {
      ++rays;
      return ctx_.bvh().occluded(ray) ? Spectrum(0.0f) : Spectrum(1.0f);
    }
    return ctx_.transmittance(ray, scratch, rays);
  }

  // The camera ray of pixel (px, py) of the frame, through the filter's sample for `jitter`.
  Ray camera_ray(const Sampler& sampler, Vec2f jitter, int px, int py) const {
    const Vec2f lens = kDoF ? sampler.get2d(Sampler::kDimLens) : Vec2f(0.5f, 0.5f);
    return ctx_.camera().generate_ray(ctx_.pixel_filter().raster(px, py, jitter), lens);
  }

  // The path's state between vertices.
  struct Path {
    PathState state;
    Spectrum beta{1.0f};                // path throughput f / p
    float prev_pdf = 0.0f;              // solid-angle pdf of the BSDF sample that spawned the ray
    bool prev_delta = true;             // no MIS for camera rays and delta lobes
    Vec3f prev_position;                // the last scattering vertex (NEE ran from there)
    bool crossed_since_vertex = false;  // transparent crossings since prev_position
    CausticChain caustic;               // lamps whose light manifold NEE counted
  };

  // A light sample whose shadow ray is traced after the BSDF sample, which does not depend on
  // it: the sampling and the next ray's set-up then run while Embree traverses the shadow ray.
  struct PendingShadow {
    Ray ray;
    bool pending = false, cast = false;
    Spectrum beta_f, radiance;  // beta f before this vertex's sample updates beta
    float scale = 0.0f;         // MIS weight / light pdf
  };

  // The path of one camera sample, from its camera ray already traced (`camera_found`, and `hit`
  // holding the hit when found); `hit` is the path's working hit record from there on.
  // `numbers` holds the pixel's Sampler and first vertices' numbers in lane `lane`. `filtered`
  // holds the closures the light-path rules rewrote (light_path_filters.h).
  PathResult trace(const VertexNumberBatch& numbers, int lane, Ray ray, bool camera_found,
                   ClosureSet& closure_scratch, ClosureSet& scratch, ClosureSet& filtered,
                   SurfaceHit& hit) const {
    const Sampler& sampler = numbers.sampler(lane);
    const EmbreeScene& bvh = ctx_.bvh();
    PathResult out;
    Path path;
    path.prev_position = ray.origin;
    // The view and the path state of a vertex, for materials that read them.
    ShadingGeometry view;
    PathView path_view;
    // `vertex` numbers every surface interaction (sampler dimensions); state.bounce follows Cycles.
    for (int vertex = 0;; ++vertex) {
      const bool last = path.state.last(settings_);
      // Drawn before the ray is traced, to run alongside it (Sampler::vertex_numbers).
      Sampler::VertexNumbers u;
      if (!last) u = numbers.vertex_numbers(lane, vertex);
      const bool found = vertex == 0                      ? camera_found
                         : distance_only(last, kEmissive) ? bvh.intersect_distance(ray, hit.t)
                                                          : bvh.intersect(ray, hit);
      ++out.rays;
      if constexpr (kAnalytic) lamps_before(path, ray, found ? hit.t : ray.t_max, scratch, out);
      if (!found) {
        escape(path, ray, out);
        break;
      }
      if (distance_only(last, kEmissive)) break;
      if (holdout_ends_path(ctx_, path.state.camera_path, hit)) {
        // Nothing added; the coverage is what the transparent surfaces crossed so far took.
        path.state.set_alpha(settings_, path.beta, out.alpha);
        break;
      }

      // --- Shading point ---
      ShadingContext sc = shading_context_of(hit);
      const Material& material = ctx_.materials()[size_t(hit.material)];
      if (material.reads_view()) [[unlikely]] {
        view = shading_geometry(hit, -ray.direction);
        sc.geometry = &view;
      }
      if (material.reads_path()) [[unlikely]] {
        // Measured from the ray's start: camera rays start at the near clip, as in Cycles.
        path_view = path.state.view(hit.t - ray.t_min);
        sc.path = &path_view;
      }
      if constexpr (kEmissive)
        if (material.is_emissive()) emitter_hit(path, hit, material.emission(sc), out);
      if (last) break;
      if (const float q = path.state.take_deferred_division(); q != 1.0f) [[unlikely]]
        path.beta /= q;
      const ClosureSet* evaluated = &material.closures(sc, closure_scratch);
      if (filters_.enabled() && filters_.active(path.state)) {
        filtered.assign(*evaluated);
        filters_.apply(path.state, filtered, ctx_.is_sharp_caster(hit));
        evaluated = &filtered;
      }
      const ClosureSet& material_closures = *evaluated;
      if (path.state.camera_path && data_.active())
        data_.at_surface(hit, material_closures, path.beta, out.data);
      if (features_.active())
        features_.at_surface(hit, material_closures, length(hit.position - ray.origin),
                             std::fabs(dot(ray.direction, hit.shading_normal)), out.feature);
      if (!material_closures.has_bsdf()) break;
      const Vec3f wi_world = -ray.direction;
      const SurfaceFrame sf = facing_frame(hit, wi_world);
      const Frame frame = shading_frame(sf.ns, material_closures);
      const Vec3f wi = frame.to_local(wi_world);
      // With bump shadowing where the normal is not the interpolated one (bump_shadowing.h).
      const ClosureSet& closures = shading_closures(material_closures, closure_scratch, hit, frame,
                                                    sf.ng, wi_world, sf.rotated);

      const PendingShadow nee =
          sample_light(path, hit, frame, sf.ng, wi, closures, sampler, u, vertex, scratch, out);
      const bool continues = extend(path, hit, frame, sf.ng, wi, closures, sampler, u, vertex, ray);
      if (nee.pending) {
        const Spectrum tr = nee.cast ? transmittance(nee.ray, scratch, out.rays) : Spectrum(1.0f);
        if (!is_black(tr)) out.primal += nee.beta_f * tr * nee.radiance * nee.scale;
      }
      if (!continues) break;
    }
    return out;
  }

  // Analytic lights the ray crosses before `t_hit`. Camera rays see a lamp only when its object
  // is visible to the camera (Blender's Object.visible_camera, off by default as in Cycles).
  // `scratch`: closures for the walk of shadow caustics' rule (CausticChain::weight).
  void lamps_before(const Path& path, const Ray& ray, float t_hit, ClosureSet& scratch,
                    PathResult& out) const {
    const LightSampler& lights = ctx_.lights();
    LightHit lh;
    if (!lights.intersect(ray.origin, ray.direction, t_hit, lh)) return;
    if (path.state.camera_path) {
      if (lh.camera_visible) out.emission += path.beta * lh.radiance;
      return;
    }
    const float caustic_w = path.caustic.weight(ctx_, lh, scratch, out.rays);
    if (caustic_w == 0.0f) return;
    float light_pdf = lh.pdf;
    if (!path.prev_delta && path.crossed_since_vertex) {
      // NEE ran from prev_position, behind the transparent surfaces just crossed: its density
      // for this light is the one seen from there along the same line.
      LightHit from_vertex;
      if (lights.intersect(path.prev_position, ray.direction, kInf, from_vertex) &&
          std::fabs(from_vertex.distance - length(lh.position - path.prev_position)) <=
              1e-3f * from_vertex.distance)
        light_pdf = from_vertex.pdf;
    }
    const float w = path.prev_delta ? 1.0f : power_heuristic(path.prev_pdf, light_pdf);
    out.primal += path.beta * lh.radiance * (w * caustic_w);
  }

  // The ray left the scene: the world (with a transparent background a camera path leaves it
  // out and reports the transparency it crossed).
  void escape(const Path& path, const Ray& ray, PathResult& out) const {
    path.state.set_alpha(settings_, path.beta, out.alpha);
    if constexpr (kWorld) {
      const LightSampler& lights = ctx_.lights();
      if (path.state.camera_path) {  // the world as camera rays see it (World::camera_view)
        if (!settings_.transparent_background)
          out.emission += path.beta * lights.camera_environment(ray.direction);
      } else if (const Spectrum le = lights.environment(ray.direction); !is_black(le)) {
        const float w = path.prev_delta
                            ? 1.0f
                            : power_heuristic(path.prev_pdf, lights.pdf_environment(ray.direction));
        out.primal += path.beta * le * w;
      }
    }
  }

  // Emission `le` of an emissive triangle the ray hit.
  void emitter_hit(const Path& path, const SurfaceHit& hit, Spectrum le, PathResult& out) const {
    if (path.state.camera_path) {
      out.emission += path.beta * le;
    } else if (!is_black(le)) {
      float w = 1.0f;
      if (!path.prev_delta)
        w = power_heuristic(path.prev_pdf, ctx_.lights().pdf_triangle(
                                               hit.instance, hit.primitive, path.prev_position,
                                               hit.position, hit.geometric_normal));
      out.primal += path.beta * le * w;
    }
  }

  // Next-event estimation: the light sample and its BSDF value; the shadow ray is the caller's.
  // A sample whose segment crosses caustics casters is manifold NEE's, added here to `out`.
  PendingShadow sample_light(const Path& path, const SurfaceHit& hit, const Frame& frame, Vec3f ng,
                             Vec3f wi, const ClosureSet& closures, const Sampler& sampler,
                             const Sampler::VertexNumbers& u, int vertex, ClosureSet& scratch,
                             PathResult& out) const {
    PendingShadow nee;
    const LightSampler& lights = ctx_.lights();
    if (lights.empty()) return nee;
    // Dimensions are indexed, not streamed: skipping an unused one changes no other value.
    const float u_select = lights.needs_selection()
                               ? sampler.get1d(Sampler::bounce_dim(vertex, Sampler::kLightSelect))
                               : 0.0f;
    const LightSample ls = lights.sample(hit.position, u_select, u.light);
    if (!ls.valid || !(ls.pdf > 0.0f) || is_black(ls.radiance)) return nee;
    if (runs_shadow_caustics(ctx_, hit, ls)) [[unlikely]]
      if (caustic_nee(path, hit, frame, ng, wi, closures, ls, scratch, out)) return nee;
    const Vec3f wo = frame.to_local(ls.direction);
    const float cos_ng = dot(ls.direction, ng);
    // The geometric and shading hemispheres must agree, or light leaks through the surface.
    if (!light_side_ok(ctx_.bvh(), hit, closures, wo, cos_ng)) return nee;
    float bsdf_pdf;
    const Spectrum f = closures.eval_pdf(wi, wo, bsdf_pdf);
    if (is_black(f)) return nee;
    const EmbreeScene& bvh = ctx_.bvh();
    const Vec3f plain =
        offset_ray_origin(hit.position, cos_ng > 0.0f ? ng : -ng, bvh.offset_scale());
    const Vec3f origin = light_ray_origin(bvh, hit, ng, ls.direction, plain);
    nee.ray = ls.is_infinite ? shadow_ray_to_infinity(origin, ls.direction, kRayShadow)
                             : shadow_ray_to_point(origin, ls.position, kRayShadow);
    nee.pending = true;
    nee.cast = ls.cast_shadow;
    nee.beta_f = path.beta * f;
    nee.radiance = ls.radiance;
    nee.scale = (ls.is_delta ? 1.0f : power_heuristic(ls.pdf, bsdf_pdf)) / ls.pdf;
    return nee;
  }

  // Manifold NEE of the light sample `ls` (manifold_nee.h); false when no caster stands on its
  // segment (the plain light sample then stands), true when casters do: they would block the
  // plain shadow ray, and the refracted path through them, if found, is added to `out`.
  bool caustic_nee(const Path& path, const SurfaceHit& hit, const Frame& frame, Vec3f ng, Vec3f wi,
                   const ClosureSet& closures, const LightSample& ls, ClosureSet& scratch,
                   PathResult& out) const {
    const Vec3f ng_light = dot(ls.direction, ng) > 0.0f ? ng : -ng;
    const CausticConnection cc =
        caustic_connection(ctx_, hit.position, ng_light, ls, scratch, out.rays);
    if (cc.casters == 0) return false;
    if (!cc.valid) return true;
    const Vec3f wo = frame.to_local(cc.direction);
    if (light_side_ok(ctx_.bvh(), hit, closures, wo, dot(cc.direction, ng))) {
      const float w =
          manifold_nee_weight(cc, caustic_share(path.state, settings_), ls.area_pdf, ng_light);
      out.primal += path.beta * closures.eval(wi, wo) * cc.transport * (w / light_area_density(ls));
    }
    return true;
  }

  // BSDF sampling, the roulette and the next ray. False when the path ends here.
  bool extend(Path& path, const SurfaceHit& hit, const Frame& frame, Vec3f ng, Vec3f wi,
              const ClosureSet& closures, const Sampler& sampler, const Sampler::VertexNumbers& u,
              int vertex, Ray& ray) const {
    const float u_lobe = closures.uses_lobe_choice()
                             ? sampler.get1d(Sampler::bounce_dim(vertex, Sampler::kBsdfLobe))
                             : 0.0f;
    const BsdfSample bs = closures.sample(wi, u_lobe, u.dir);
    const Vec3f wo_world = frame.to_world(bs.wo);
    const float cos_wo_ng = dot(wo_world, ng);
    if (!(bs.valid && bs.pdf > 0.0f && !is_black(bs.value)) || !closures.side_ok(bs.wo, cos_wo_ng))
      return false;
    path.beta *= bs.value / bs.pdf;
    // A transparent crossing keeps the MIS state of the last real scattering vertex: shadow rays
    // see through transparent surfaces too (transmittance()), so the NEE density from that
    // vertex is still the competing technique.
    const bool crossing = bs.is_straight_crossing();
    const uint32_t kind = crossing ? ray.kind : ray_kind_of_lobe(bs.lobe);
    if (ctx_.shadow_caustics())
      path.caustic.scattered(ctx_, hit, bs, wo_world, caustic_share(path.state, settings_));
    path.state.count_event(crossing, kind, bs.lobe);
    if (!crossing) path.state.scattered(bs);
    path.crossed_since_vertex = crossing;
    bool continues = true;
    if (!crossing) {
      path.prev_delta = bs.is_delta();
      path.prev_pdf = bs.pdf;
      path.prev_position = hit.position;
      const float q = path.state.roulette(settings_, ctx_.scene_features(), path.beta, bs.lobe,
                                          sampler, vertex);
      if (q == 0.0f)
        continues = false;
      else if (q != 1.0f)
        path.beta /= q;
    }
    ray.origin =
        offset_ray_origin(hit.position, cos_wo_ng > 0.0f ? ng : -ng, ctx_.bvh().offset_scale());
    ray.direction = normalize(wo_world);
    ray.t_min = 0.0f;
    ray.t_max = kInf;
    ray.kind = kind;  // a crossing keeps the kind
    return continues;
  }

  const SceneContext& ctx_;
  RenderSettings settings_;
  DataPasses data_;
  FeaturePasses features_;
  LightPathFilters filters_;
};

// --- Dispatch: one instantiation per subset of kSpecialised, picked once per session ---

template <uint32_t kMask>
std::unique_ptr<Integrator> make_kernel(const SceneContext& ctx, const RenderSettings& s) {
  return std::make_unique<PathTracer<kMask>>(ctx, s);
}

constexpr std::array<uint32_t, 5> kBits = {kSceneDoF, kSceneWorld, kSceneAnalyticLights,
                                           kSceneEmissiveTriangles, kFeatureTransparent};

constexpr uint32_t mask_of_index(size_t i) {
  uint32_t m = 0;
  for (size_t b = 0; b < kBits.size(); ++b)
    if (i & (size_t(1) << b)) m |= kBits[b];
  return m;
}

template <size_t... I>
auto make_table(std::index_sequence<I...>) {
  using Factory = std::unique_ptr<Integrator> (*)(const SceneContext&, const RenderSettings&);
  return std::array<Factory, sizeof...(I)>{&make_kernel<mask_of_index(I)>...};
}

}  // namespace

uint32_t path_tracer_specialised_features(uint32_t scene_features) {
  return scene_features & kSpecialised;
}

std::unique_ptr<Integrator> make_path_tracer(const SceneContext& ctx,
                                             const RenderSettings& settings) {
  static const auto table = make_table(std::make_index_sequence<size_t(1) << kBits.size()>{});
  const uint32_t f = ctx.features();
  size_t index = 0;
  for (size_t b = 0; b < kBits.size(); ++b)
    if (f & kBits[b]) index |= size_t(1) << b;
  return table[index](ctx, settings);
}

}  // namespace gdpt
