#include "integrators/pt/path_tracer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <utility>

#include "core/frame.h"
#include "core/valid_reflection.h"
#include "integrators/common/bounce_limits.h"
#include "integrators/common/bump_shadowing.h"
#include "integrators/common/data_passes.h"
#include "integrators/common/russian_roulette.h"
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
  DataSample data;  // Normal / Mist passes (DataPasses)
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
      : ctx_(ctx), settings_(settings), data_(settings, ctx.camera()) {}

  // Camera rays go to Embree a row segment at a time (kStream pixels of one sample index) as one
  // coherent stream, which traverses neighbouring rays together; each path then continues from
  // its camera hit. Every pixel still takes its samples in index order: the image is the same as
  // with one camera ray at a time, bit for bit.
  void render_tile(const Tile& tile, uint32_t first_sample, uint32_t sample_count,
                   Film& film) const override {
    constexpr int kStream = 16;
    uint64_t rays = 0;
    VertexNumberBatch numbers;  // the segment's Samplers, camera jitters, first vertices' numbers
    static_assert(VertexNumberBatch::kMaxPixels >= kStream);
    Ray camera_rays[kStream];
    bool valid[kStream], found[kStream];
    SurfaceHit hits[kStream];      // each path's working hit record, starting as its camera hit
    ClosureSet closures, scratch;  // ~0.5 KB each: initialised once per tile, not per sample
    const float clamp = settings_.clamp;
    // Raster positions and sampler keys are the frame's (a render region samples as the frame).
    const int rx = ctx_.camera().region_x(), ry = ctx_.camera().region_y();
    std::fill(valid, valid + kStream, true);
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x0 = tile.x0; x0 < tile.x1; x0 += kStream) {
        const int n = std::min(kStream, tile.x1 - x0);
        numbers.prepare(settings_.seed, x0 + rx, y + ry, n, settings_.max_bounces + 1,
                        !ctx_.lights().empty());
        for (uint32_t s = first_sample; s < first_sample + sample_count; ++s) {
          // --- Camera rays of the segment, traced together ---
          numbers.fill(s);
          for (int j = 0; j < n; ++j)
            camera_rays[j] = camera_ray(numbers.sampler(j), numbers.camera(j), x0 + j + rx, y + ry);
          ctx_.bvh().intersect_stream(camera_rays, valid, n, found, hits);
          if (s == 0)  // Depth and index passes: sample 0's camera hit, as Cycles
            for (int j = 0; j < n; ++j)
              if (found[j]) ctx_.record_first_hit(film, x0 + j, y, hits[j]);
          // --- The paths ---
          for (int j = 0; j < n; ++j) {
            const PathResult r =
                trace(numbers, j, camera_rays[j], found[j], closures, scratch, hits[j]);
            rays += r.rays;
            film.pixel(x0 + j, y).add_path(r.primal, r.emission, clamp, r.alpha);
            if (data_.active()) film.add_data(x0 + j, y, r.data.normal, r.data.mist);
          }
        }
      }
      for (int x = tile.x0; x < tile.x1; ++x) film.add_sample_count(x, y, sample_count);
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

  // The camera ray of pixel (px, py) of the frame.
  Ray camera_ray(const Sampler& sampler, Vec2f jitter, int px, int py) const {
    const Vec2f lens = kDoF ? sampler.get2d(Sampler::kDimLens) : Vec2f(0.5f, 0.5f);
    return ctx_.camera().generate_ray({float(px) + jitter.x, float(py) + jitter.y}, lens);
  }

  // The path of one camera sample, from its camera ray already traced (`camera_found`, and `hit`
  // holding the hit when found); `hit` is the path's working hit record from there on.
  // `numbers` holds the pixel's Sampler and first vertices' numbers in lane `lane`.
  PathResult trace(const VertexNumberBatch& numbers, int lane, Ray ray, bool camera_found,
                   ClosureSet& closure_scratch, ClosureSet& scratch, SurfaceHit& hit) const {
    const Sampler& sampler = numbers.sampler(lane);
    const EmbreeScene& bvh = ctx_.bvh();
    const LightSampler& lights = ctx_.lights();
    const auto& materials = ctx_.materials();
    const int max_bounces = settings_.max_bounces;
    const bool has_lights = !lights.empty();
    const bool needs_selection = lights.needs_selection();

    PathResult out;
    Spectrum beta(1.0f);     // path throughput f / p
    float prev_pdf = 0.0f;   // solid-angle pdf of the BSDF sample that spawned `ray`
    bool prev_delta = true;  // no MIS for camera rays and delta lobes
    Vec3f prev_position = ray.origin;

    int bounce = 0;           // Cycles' bounce count: scattering events, transparent ones excluded
    int transparent = 0;      // transparent crossings (Cycles' transparent bounces)
    BounceCounts kinds;       // scattering events by kind, for the per-kind limits
    bool camera_path = true;  // nothing but transparent crossings since the camera
    bool crossed_since_vertex = false;  // transparent crossings since prev_position
    // A roulette that takes effect past the next hit (roulette_past_next_hit): stopped, that hit
    // is the path's last, traced like the one past the bounce limit; survived, what follows the
    // hit's emission is divided by the continuation probability.
    bool rr_stop = false;
    float rr_divide = 1.0f;

    // `vertex` numbers every surface interaction (sampler dimensions); `bounce` follows Cycles.
    for (int vertex = 0;; ++vertex) {
      // Past the bounce limits a vertex only ends the path: without emissive triangles its hit
      // needs no record, only the distance (analytic lights in front of it, the world behind).
      const bool last = rr_stop || bounce > max_bounces || transparent > kMaxTransparentBounces ||
                        kinds.over(settings_);
      // Drawn before the ray is traced, to run alongside it (Sampler::vertex_numbers).
      Sampler::VertexNumbers u;
      if (!last) u = numbers.vertex_numbers(lane, vertex);
      const bool found = vertex == 0          ? camera_found
                         : !kEmissive && last ? bvh.intersect_distance(ray, hit.t)
                                              : bvh.intersect(ray, hit);
      ++out.rays;
      const float t_hit = found ? hit.t : ray.t_max;

      // --- Analytic lights in front of the surface (camera rays see a lamp only when its object
      // is visible to the camera, Blender's Object.visible_camera, off by default as in Cycles) ---
      if constexpr (kAnalytic) {
        LightHit lh;
        if (lights.intersect(ray.origin, ray.direction, t_hit, lh)) {
          if (camera_path) {
            if (lh.camera_visible) out.emission += beta * lh.radiance;
          } else {
            float light_pdf = lh.pdf;
            if (!prev_delta && crossed_since_vertex) {
              // NEE ran from prev_position, behind the transparent surfaces just crossed: its
              // density for this light is the one seen from there along the same line.
              LightHit from_vertex;
              if (lights.intersect(prev_position, ray.direction, kInf, from_vertex) &&
                  std::fabs(from_vertex.distance - length(lh.position - prev_position)) <=
                      1e-3f * from_vertex.distance)
                light_pdf = from_vertex.pdf;
            }
            const float w = prev_delta ? 1.0f : power_heuristic(prev_pdf, light_pdf);
            out.primal += beta * lh.radiance * w;
          }
        }
      }

      // --- Escape: the world (with a transparent background, a camera path that gets here
      // leaves it out and reports the transparency it crossed: Cycles' alpha) ---
      if (!found) {
        if (camera_path && settings_.transparent_background) out.alpha = uncovered_alpha(beta);
        if constexpr (kWorld) {
          if (camera_path) {  // the world as camera rays see it (World::camera_view)
            if (!settings_.transparent_background)
              out.emission += beta * lights.camera_environment(ray.direction);
          } else if (const Spectrum le = lights.environment(ray.direction); !is_black(le)) {
            const float w = prev_delta
                                ? 1.0f
                                : power_heuristic(prev_pdf, lights.pdf_environment(ray.direction));
            out.primal += beta * le * w;
          }
        }
        break;
      }

      if (!kEmissive && last) break;

      // --- Holdout: the camera path ends here with nothing added; with a transparent
      // background the coverage is what the transparent surfaces crossed so far took (Cycles) ---
      if (camera_path && ctx_.has_holdout() && ctx_.is_holdout(hit)) {
        if (settings_.transparent_background) out.alpha = uncovered_alpha(beta);
        break;
      }

      // --- Shading point ---
      const ShadingContext sc = shading_context_of(hit);
      const Material& material = materials[size_t(hit.material)];
      if constexpr (kEmissive) {
        if (material.is_emissive()) {
          const Spectrum le = material.emission(sc);
          if (camera_path) {
            out.emission += beta * le;
          } else if (!is_black(le)) {
            float w = 1.0f;
            if (!prev_delta)
              w = power_heuristic(prev_pdf,
                                  lights.pdf_triangle(hit.instance, hit.primitive, prev_position,
                                                      hit.position, hit.geometric_normal));
            out.primal += beta * le * w;
          }
        }
      }
      if (last) break;
      if (rr_divide != 1.0f) [[unlikely]] {  // survived the roulette: what follows is divided
        beta /= rr_divide;
        rr_divide = 1.0f;
      }
      const ClosureSet& material_closures = material.closures(sc, closure_scratch);
      if (camera_path && data_.active()) data_.at_surface(hit, material_closures, beta, out.data);
      if (!material_closures.has_bsdf()) break;

      // Frame facing the incoming ray (Cycles flips N and Ng for back faces; materials learn the
      // side from ShadingContext::front_facing). A shading normal that would mirror wi below the
      // surface is rotated towards ng as Cycles does (valid_reflection_normal), which keeps
      // smooth shading continuous at silhouettes, instead of snapping to the flat normal.
      const Vec3f wi_world = -ray.direction;
      const Vec3f ng = hit.front_facing ? hit.geometric_normal : -hit.geometric_normal;
      bool rotated;
      const Vec3f ns = valid_reflection_normal(
          hit.front_facing ? hit.shading_normal : -hit.shading_normal, ng, wi_world, rotated);
      const Frame frame(ns);
      const Vec3f wi = frame.to_local(wi_world);
      // With bump shadowing where the normal is not the interpolated one (bump_shadowing.h).
      const ClosureSet& closures =
          shading_closures(material_closures, closure_scratch, hit, frame, ng, wi_world, rotated);

      // --- Next-event estimation: the light sample and its BSDF value. Its shadow ray is traced
      // after the BSDF sample below, which does not depend on it: the sampling and the next
      // ray's set-up then run while Embree traverses the shadow ray, instead of delaying the
      // next traversal.
      Ray shadow;
      bool shadow_pending = false;
      bool shadow_cast = false;
      Spectrum nee_beta_f, nee_radiance;  // beta f before this vertex's sample updates beta
      float nee_scale = 0.0f;             // MIS weight / light pdf
      if (has_lights) {
        // Dimensions are indexed, not streamed: skipping an unused one changes no other value.
        const float u_select =
            needs_selection ? sampler.get1d(Sampler::bounce_dim(vertex, Sampler::kLightSelect))
                            : 0.0f;
        const LightSample ls = lights.sample(hit.position, u_select, u.light);
        if (ls.valid && ls.pdf > 0.0f && !is_black(ls.radiance)) {
          const Vec3f wo = frame.to_local(ls.direction);
          const float cos_ng = dot(ls.direction, ng);
          // The geometric and shading hemispheres must agree, or light leaks through the surface.
          if (closures.side_ok(wo, cos_ng)) {
            float bsdf_pdf;
            const Spectrum f = closures.eval_pdf(wi, wo, bsdf_pdf);
            if (!is_black(f)) {
              shadow.origin = offset_ray_origin(hit.position, cos_ng > 0.0f ? ng : -ng);
              shadow.direction = ls.direction;
              shadow.t_min = 0.0f;
              shadow.kind = kRayShadow;
              // Stop short of the light's own surface (emissive triangles are geometry too),
              // aiming from the offset origin: the offset shortens the path to a light surface
              // by up to offset / cos, which at grazing angles (a ceiling just above a panel)
              // exceeded the 1e-4 margin and made the emitter occlude itself.
              // A finite light point is aimed at with the segment itself as the direction, t in
              // [0, 1): no normalisation for an occlusion query.
              shadow.t_max = kInf;
              if (!ls.is_infinite) {
                shadow.direction = ls.position - shadow.origin;
                shadow.t_max = 1.0f - 1e-4f;
              }
              shadow_pending = true;
              shadow_cast = ls.cast_shadow;
              nee_beta_f = beta * f;
              nee_radiance = ls.radiance;
              nee_scale = (ls.is_delta ? 1.0f : power_heuristic(ls.pdf, bsdf_pdf)) / ls.pdf;
            }
          }
        }
      }

      // --- BSDF sampling: the direction the path continues in ---
      const float u_lobe = closures.uses_lobe_choice()
                               ? sampler.get1d(Sampler::bounce_dim(vertex, Sampler::kBsdfLobe))
                               : 0.0f;
      const BsdfSample bs = closures.sample(wi, u_lobe, u.dir);
      bool continues = bs.valid && bs.pdf > 0.0f && !is_black(bs.value);
      const Vec3f wo_world = frame.to_world(bs.wo);
      const float cos_wo_ng = dot(wo_world, ng);
      continues = continues && closures.side_ok(bs.wo, cos_wo_ng);
      if (continues) {
        beta *= bs.value / bs.pdf;
        // A transparent crossing (straight through, eta 1) is not a bounce, keeps the
        // camera-path status and keeps the MIS state of the last real scattering vertex: shadow
        // rays see through transparent surfaces too (transmittance()), so the NEE density from
        // that vertex is still the competing technique.
        const bool crossing = bs.is_straight_crossing();
        if (crossing) {
          ++transparent;
          crossed_since_vertex = true;
        } else {
          crossed_since_vertex = false;
          prev_delta = bs.is_delta();
          prev_pdf = bs.pdf;
          prev_position = hit.position;
          camera_path = false;
          ++bounce;
        }

        // --- Russian roulette (real bounces only) ---
        if (!crossing && bounce - 1 >= settings_.rr_depth) {
          const float q = roulette_continuation(beta);
          if (q < 1.0f) {
            // Either order is unbiased, as long as the survivors match the stopped paths.
            const bool last_ray = roulette_past_next_hit(bs.lobe, ctx_.scene_features());
            const bool survive = sampler.get1d(Sampler::bounce_dim(vertex, Sampler::kRoulette)) < q;
            if (survive && last_ray)
              rr_divide = q;  // from after the next hit's emission on
            else if (survive)
              beta /= q;
            else if (last_ray)
              rr_stop = true;  // the last ray, for the lamp, emitter or world it may find
            else
              continues = false;
          }
        }

        ray.origin = offset_ray_origin(hit.position, cos_wo_ng > 0.0f ? ng : -ng);
        ray.direction = normalize(wo_world);
        ray.t_min = 0.0f;
        ray.t_max = kInf;
        if (!crossing) {  // a crossing keeps the kind and counts for no limit
          ray.kind = ray_kind_of_lobe(bs.lobe);
          kinds.add(ray.kind);
        }
      }

      // --- The NEE's shadow ray ---
      if (shadow_pending) {
        const Spectrum tr = shadow_cast ? transmittance(shadow, scratch, out.rays) : Spectrum(1.0f);
        if (!is_black(tr)) out.primal += nee_beta_f * tr * nee_radiance * nee_scale;
      }
      if (!continues) break;
    }
    return out;
  }

  const SceneContext& ctx_;
  RenderSettings settings_;
  DataPasses data_;
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
