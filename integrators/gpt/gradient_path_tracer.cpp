// Gradient-domain path tracer: see gradient_path_tracer.h for the estimator and the film layout,
// shift_mapping.h for the shift mathematics.
//
// Parameters (RenderSettings): max_bounces and the per-kind limits (bounce_limits.h), rr_depth
// (Russian roulette decided by the base path, its probability multiplied into base and offset
// densities alike; after a glossy bounce only past the sampled segment's emission, as in PT),
// shift_roughness_threshold (vertex classification), seed, clamp (applied to the
// primal only, as in PT).
//
// Bookkeeping: each path keeps its throughput f (product of BSDF values, not divided by pdfs) and
// its density p (product of solid-angle densities), both in double; offsets multiply their shift
// Jacobians into both. An emission event of the base path (light sample, BSDF-sampled light hit,
// world) with contribution C = f * segment, and the matching offset contribution C' (Jacobian
// included), adds w (C' - C) to the gradient half of that offset, w = shift::mis_weight_over_pdf.
#include "integrators/gpt/gradient_path_tracer.h"
#include "integrators/common/bounce_limits.h"
#include "integrators/common/bump_shadowing.h"
#include "integrators/common/data_passes.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "core/frame.h"
#include "core/valid_reflection.h"
#include "integrators/common/russian_roulette.h"
#include "integrators/gpt/shift_mapping.h"
#include "integrators/pt/path_tracer.h"
#include "render/features.h"
#include "render/sampler.h"
#include "render/scene_context.h"
#include "shaders/shading_context.h"

namespace gdpt {

namespace {

using shift::PathDensities;
using shift::Vec3d;
using shift::VertexType;

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kOffsets = 4;
// Offset order: +x (right), +y (up), -x (left), -y (down), as CameraModel::generate_offset_rays.
enum : int { kRight = 0, kUp = 1, kLeft = 2, kDown = 3 };

inline Vec3d mul(Vec3d a, Vec3d b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
inline Vec3d mul(Vec3d a, Spectrum b) {
  return {a.x * b.x, a.y * b.y, a.z * b.z};
}
inline bool is_zero(Vec3d a) {
  return a.x == 0.0 && a.y == 0.0 && a.z == 0.0;
}

// Event part of the pair weight for a merged offset (see add_merged): Y p_tech /
// (p_L^2 + p_B^2), 0 when both densities are 0 (mis_weight_over_pdf's zero denominator).
inline Vec3d connected_event(Vec3d y, double p_tech, double p_light, double p_bsdf) {
  const double d = p_light * p_light + p_bsdf * p_bsdf;
  return d > 0.0 ? y * (p_tech / d) : Vec3d();
}

// Light-technique density of a light point in the pair weights: for an area light the density
// of uniform area sampling, area_pdf d^2 / cos_l (d the distance from the vertex, cos_l the
// cosine at the light), whichever way sample() picks the point from that vertex (the spherical
// rectangle where the light subtends more than 0.1 sr); the sampling density `pdf` for every
// other light. The power heuristic's weights of a path pair's four techniques sum to one for
// any such density function of the pair's vertices, as long as all four use the same one: the
// base's light technique is then weighted by p_mis^2 / pdf instead of p_mis (light_tech()).
// Its use: the offsets' light densities need neither an intersection with the light nor the
// spherical rectangle's solid angle from their own vertex (4-5% of G-PT's time).
inline float mis_light_pdf(float area_pdf, float pdf, float d, float cos_l) {
  return area_pdf > 0.0f ? area_pdf * (d * d) / cos_l : pdf;
}
// The technique term of a light sample drawn with density `pdf` and weighted with `p_mis`:
// mis_weight_over_pdf(..., light_tech(...)) = w / (p pdf) with w the heuristic of p_mis.
inline double light_tech(float p_mis, float pdf) {
  return p_mis == pdf ? double(pdf) : double(p_mis) * double(p_mis) / double(pdf);
}

// A shading point of a path: the hit, the frame facing the incoming ray, the closures.
struct Vertex {
  SurfaceHit hit;
  Frame frame;
  Vec3f ng;  // geometric normal on the side of the incoming ray
  Vec3f wi;  // local incoming direction
  // The closures: a constant material's own set (no copy), else `own` filled by evaluate().
  // A Vertex is never copied or moved (it lives in PathScratch), so `closures` may point into it.
  const ClosureSet* closures = nullptr;
  ClosureSet own;
  float roughness = 1.0f;  // ClosureSet::roughness(), 1 for a vertex without BSDF
  // A single Lambert lobe: eval() and pdf() depend on wi only through the sign of wi.z * wo.z,
  // so an offset sharing this vertex with another wi reuses the base's values (same_side()).
  bool lambert = false;
  // offset_ray_origin() on the side of ng, computed on first use (ray_origin()): light samples,
  // the extension ray and reconnection rays of a vertex mostly leave on that side.
  mutable bool origin_set = false;
  mutable Vec3f origin;
};

// Origin of a ray leaving `v` on the side of ng (`front`) or the other side.
inline Vec3f ray_origin(const Vertex& v, bool front) {
  if (!front) return offset_ray_origin(v.hit.position, -v.ng);
  if (!v.origin_set) {
    v.origin = offset_ray_origin(v.hit.position, v.ng);
    v.origin_set = true;
  }
  return v.origin;
}

// Whether a single-Lambert vertex gives wi_a and wi_b the same eval() and pdf() for wo: the
// lobe's only use of wi is the test wi.z * wo.z > 0 (shaders/bsdf_lambert.h), so equal test
// outcomes mean bit-identical values.
inline bool same_side(const Vertex& v, Vec3f wi_a, Vec3f wi_b, Vec3f wo) {
  return v.lambert && (wi_a.z * wo.z > 0.0f) == (wi_b.z * wo.z > 0.0f);
}

// What setup_vertex() needs of a material side whose closures do not vary over the surface
// (Material::closures returns its cached set): the set itself, its roughness and whether it is a
// single Lambert lobe, computed once per material and side. `set` is null for a material that
// is evaluated per hit (textures).
struct MaterialSide {
  const ClosureSet* set = nullptr;
  float roughness = 1.0f;
  bool lambert = false;
};

float vertex_roughness(const ClosureSet& cs) {
  return cs.has_bsdf() ? cs.roughness() : 1.0f;
}
bool single_lambert(const ClosureSet& cs) {
  return cs.count() == 1 && cs[0].type == ClosureType::Lambert;
}

// Indexed by 2 * material + front_facing.
std::vector<MaterialSide> material_sides(const SceneContext& ctx) {
  std::vector<MaterialSide> sides(2 * ctx.materials().size());
  ClosureSet scratch;
  for (size_t m = 0; m < ctx.materials().size(); ++m)
    for (int front = 0; front < 2; ++front) {
      const ClosureSet& cs = ctx.materials()[m].closures(ShadingContext{{}, front == 1}, scratch);
      if (&cs == &scratch) continue;  // evaluated per hit
      sides[2 * m + size_t(front)] = {&cs, vertex_roughness(cs), single_lambert(cs)};
    }
  return sides;
}

// Sets up `v` at its hit v.hit reached along `dir` (world, unit), as the path tracer does:
// Cycles-style flipped normals for back faces, geometric-normal fallback for a shading normal
// that puts the incoming direction below its horizon. (The base's next hit is traced into v.hit
// directly: no copy.)
void finish_vertex(const SceneContext& ctx, std::span<const MaterialSide> sides, const Vec3f& dir,
                   Vertex& v) {
  const SurfaceHit& hit = v.hit;
  const MaterialSide& side = sides[2 * size_t(hit.material) + (hit.front_facing ? 1 : 0)];
  if (side.set) {
    v.closures = side.set;
    v.roughness = side.roughness;
    v.lambert = side.lambert;
  } else {
    v.own.clear();
    ctx.materials()[size_t(hit.material)].evaluate(shading_context_of(hit), v.own);
    v.closures = &v.own;
    v.roughness = vertex_roughness(v.own);
    v.lambert = single_lambert(v.own);
  }
  const Vec3f wi_world = -dir;
  v.ng = hit.front_facing ? hit.geometric_normal : -hit.geometric_normal;
  // The shading normal as Cycles sets it (valid_reflection_normal), as in PT.
  bool rotated;
  Vec3f ns = valid_reflection_normal(hit.front_facing ? hit.shading_normal : -hit.shading_normal,
                                     v.ng, wi_world, rotated);
  v.frame = Frame(ns);
  v.wi = v.frame.to_local(wi_world);
  // With bump shadowing where the normal is not the interpolated one, as in PT.
  v.closures = &shading_closures(*v.closures, v.own, hit, v.frame, v.ng, wi_world, rotated);
  // A lobe about its own normal reads more of wi than the side (same_side()).
  if (v.closures->has_own_frames()) v.lambert = false;
  v.origin_set = false;
}

// The same at a copy of `hit`.
void setup_vertex(const SceneContext& ctx, std::span<const MaterialSide> sides,
                  const SurfaceHit& hit, const Vec3f& dir, Vertex& v) {
  v.hit = hit;
  finish_vertex(ctx, sides, dir, v);
}

// Emitted radiance of an emissive triangle at `hit` towards the point `from`.
Spectrum triangle_emission(const SceneContext& ctx, const SurfaceHit& hit, Vec3f from) {
  const Material& m = ctx.materials()[size_t(hit.material)];
  if (!m.is_emissive()) return Spectrum(0.0f);
  ShadingContext sc = shading_context_of(hit);
  sc.front_facing = dot(from - hit.position, hit.geometric_normal) > 0.0f;
  return m.emission(sc);
}

enum class Link : uint8_t { NotConnected, Recent, Connected };

// How the offset follows the base over one segment.
enum class Shift : uint8_t { Follow, RecentEval, Reconnect, ReconnectEnv, HalfVector, Failed };

struct Offset {
  bool active = false;  // traced for this sample (target pixel inside the image, needed)
  bool alive = false;
  bool failed = false;  // died at some point (statistics)
  Link link = Link::NotConnected;
  Vertex v;            // own vertex while NotConnected
  Vec3f wi_world;      // Recent: direction towards the previous offset vertex, world
  Vec3f wi_shared;     // Recent: the same in the base vertex's local frame
  Vec3d f;             // throughput up to the current vertex, Jacobians included
  double p = 0.0;      // density up to the current vertex, Jacobians included
  Vec3d grad;          // sum of w (C' - C)
  bool nee_on = true;  // next-event estimation shifted for this pair at the current vertex
  // Segment from the current vertex (set per bounce).
  Shift shift = Shift::Failed;
  Vec3d seg_value;
  double seg_pdf = 0.0, seg_jacobian = 1.0;
  bool seg_visible = true;  // Reconnect*: the offset vertex sees the target
  Vec3f seg_dir;            // world direction of the offset's segment
  // HalfVector: the offset's own next vertex.
  Ray ray;
  bool next_found = false;
  bool holdout_end = false;  // next_found is false because the segment met a holdout
  SurfaceHit next_hit;
  bool killed = false;  // the continuing path is not invertible / mismatched
};

// Filled completely by trace() (reused across pixels: zeroing it per pixel took a `rep stos`).
struct SampleResult {
  Spectrum primal;
  Spectrum emission;
  Vec3d grad[kOffsets];
  float alpha;  // Film::alpha(): 0 for a camera ray that reaches a transparent background
  uint8_t attempts, failures;
  uint32_t rays;
  DataSample data;  // Normal / Mist passes (DataPasses)
};

// The base's segment x_d -> x_{d+1} as the offsets' shift_segment() calls see it.
struct BaseStep {
  const Vertex* base;
  const BsdfSample* bs;
  VertexType xd_type, next_type;
  Vec3f wo_world;
  bool found;
  const SurfaceHit* next;
  float u_lobe;
  Vec2f u_dir;
  uint32_t kind;      // RayKind of the base's segment: the offsets' segments see what it sees
  bool holdout_ends;  // a holdout at the segment's end ends the path (the camera path's)
  // Reconnection target x_{d+1} (when found): its base side, and the side the base arrives on.
  shift::ReconnectionBase target;
  bool base_front;
};

// Per-thread working storage of trace(), reused across samples: no allocation or large
// initialisation per sample (a ClosureSet holds kMaxClosures lobes). The per-offset arrays of
// next-event estimation live here too: as locals their default member initialisers ran on every
// bounce.
// Camera rays are traced for a row of up to kRow pixels at once (render_tile): the base rays of
// the row in one Embree stream, then the offsets' rays, offset-major (the kRow rays of one offset
// direction are as coherent as the base rays), in another; Embree packs them into its own
// packets. Per-pixel rays as packets of four cost about twice as much time.
constexpr int kRow = 16;

struct CameraRow {
  Sampler sampler[kRow];
  Vec2f raster[kRow], lens[kRow];
  bool mask[kRow][kOffsets];
  Ray ray[kRow];
  bool valid[kRow], found[kRow];
  SurfaceHit hit[kRow];
  // Offset k of pixel i at k * kRow + i, traced when the pixel's base ray found a surface.
  Ray cam[kOffsets * kRow];
  Ray cam_pixel[kOffsets];  // generate_offset_rays()'s output for one pixel
  bool cam_valid[kOffsets * kRow], cam_found[kOffsets * kRow];
  SurfaceHit cam_hit[kOffsets * kRow];
};

// Camera rays of a tile without depth of field: one jitter per sample index for the whole image,
// so the offset of pixel p towards a neighbour q (same jitter, q's pixel) is exactly q's base
// camera ray. The tile's rays and a one-pixel halo around it (the neighbours of its border pixels,
// clipped to the image; the halo's corners are no one's neighbour) are traced once per sample and
// every offset reads its neighbour's hit: ~1.3 camera rays per base path instead of 5.
struct CameraGrid {
  int x0 = 0, y0 = 0, w = 0, h = 0;  // the traced rectangle
  std::vector<Ray> ray;
  std::vector<SurfaceHit> hit;
  std::unique_ptr<bool[]> valid, found;  // not vector<bool>: intersect_stream takes bool arrays
  void reserve(size_t n) {  // grows only: no allocation once the first tile has been seen
    if (n <= ray.size()) return;
    ray.resize(n);
    hit.resize(n);
    valid.reset(new bool[n]);
    found.reset(new bool[n]);
  }
  int index(int x, int y) const { return (y - y0) * w + (x - x0); }
};

// What trace() needs of one base path's camera rays, wherever render_tile() traced them.
struct CameraSample {
  const Ray* ray;
  const SurfaceHit* hit;
  bool found;
  const bool* mask;  // offsets whose target pixel is inside the image
  const Ray* off_ray[kOffsets];
  const SurfaceHit* off_hit[kOffsets];
  bool off_found[kOffsets];
};

struct PathScratch {
  Offset off[kOffsets];
  Vertex verts[2];  // base vertex and the next one, swapped per bounce
  CameraRow row;
  CameraGrid grid;
  LightSample lo[kOffsets];
  Vec3f wo_o[kOffsets];
  Spectrum fo[kOffsets];
  // Per bounce, here rather than locals: their ReconnectionBase members' default initialisers
  // (eight doubles each) ran on every bounce. Each is read only after trace() has set it.
  BaseStep step;
  shift::ReconnectionBase light_base;
  ClosureSet shadow_closures;  // surfaces a transparent shadow ray crosses
};

class GradientPathTracer final : public Integrator {
 public:
  GradientPathTracer(const SceneContext& ctx, const RenderSettings& settings)
      : ctx_(ctx),
        settings_(settings),
        has_world_(ctx.lights().has_environment()),
        has_camera_world_(ctx.lights().has_camera_environment()),
        has_visible_lamps_(ctx.lights().has_camera_visible_lights()),
        has_dof_(ctx.camera().has_dof()),
        has_emissive_((ctx.features() & kSceneEmissiveTriangles) != 0),
        sides_(material_sides(ctx)),
        data_(settings, ctx.camera()),
        transparent_shadows_((ctx.features() & kFeatureTransparent) != 0) {}

  bool estimates_gradients() const override { return true; }

  void render_tile(const Tile& tile, uint32_t first_sample, uint32_t sample_count,
                   Film& film) const override {
    const int W = film.width(), H = film.height();
    // Raster positions and sampler keys are the frame's (a render region samples as the frame).
    const int rx = ctx_.camera().region_x(), ry = ctx_.camera().region_y();
    uint64_t rays = 0;
    thread_local PathScratch scratch;
    const float clamp = settings_.clamp;
    // Adds one half to a gradient accumulator (sum and squared luminance); a non-finite half
    // counts as 0, as a non-finite primal does.
    auto add_half = [](Vec3d g, double* sum, double& sum2) {
      if (!(std::isfinite(g.x) && std::isfinite(g.y) && std::isfinite(g.z))) g = Vec3d();
      sum[0] += g.x;
      sum[1] += g.y;
      sum[2] += g.z;
      const double l = 0.2126 * g.x + 0.7152 * g.y + 0.0722 * g.z;
      sum2 += l * l;
    };
    SampleResult r;
    // Runs pixel (x, y)'s base path and adds it to the film.
    auto run_path = [&](const Sampler& sampler, const CameraSample& cs, int x, int y) {
      // The pixel's accumulators (4 cache lines) are read after the path: fetch them now.
      Film::Accumulator& acc = film.pixel(x, y);
      Film::GradientAccumulator& grad = film.gradients(x, y);
      __builtin_prefetch(&acc, 1);
      const char* grad_bytes = reinterpret_cast<const char*>(&grad);
      for (size_t b = 0; b < sizeof(grad); b += 64) __builtin_prefetch(grad_bytes + b, 1);
      trace(sampler, cs, scratch, r);
      rays += r.rays;
      // --- Primal, emission and statistics of the pixel's base path ---
      acc.add_path(r.primal, r.emission, clamp, r.alpha);
      if (data_.active()) film.add_data(x, y, r.data.normal, r.data.mist);
      grad.shift_attempts += r.attempts;
      grad.shift_failures += r.failures;
      // --- Gradient halves: dx(x) = G_right(x) - G_left(x + 1), likewise dy ---
      const bool* mask = cs.mask;
      if (mask[kRight]) add_half(r.grad[kRight], grad.dx, grad.dx2);
      if (mask[kUp]) add_half(r.grad[kUp], grad.dy, grad.dy2);
      if (mask[kLeft]) add_half(r.grad[kLeft], grad.dx_left, grad.dx_left2);
      if (mask[kDown]) add_half(r.grad[kDown], grad.dy_down, grad.dy_down2);
    };
    // Every offset whose target pixel is inside the image: the pixel's own halves of dx(x),
    // dy(x), dx(x - 1) and dy(y - 1) (the latter two combined at read-out).
    auto offset_mask = [W, H](int x, int y, bool* mask) {
      mask[kRight] = x + 1 < W;
      mask[kUp] = y + 1 < H;
      mask[kLeft] = x >= 1;
      mask[kDown] = y >= 1;
    };
    constexpr int kStepX[kOffsets] = {1, 0, -1, 0}, kStepY[kOffsets] = {0, 1, 0, -1};
    static_assert(kRight == 0 && kUp == 1 && kLeft == 2 && kDown == 3);
    CameraSample cs;
    if (!has_dof_) {
      CameraGrid& g = scratch.grid;
      for (uint32_t s = first_sample; s < first_sample + sample_count; ++s) {
        rays += trace_camera_grid(tile, W, H, s, g);
        bool mask[kOffsets];
        cs.mask = mask;
        for (int y = tile.y0; y < tile.y1; ++y)
          for (int x = tile.x0; x < tile.x1; ++x) {
            Sampler sampler;
            sampler.start(settings_.seed, x + rx, y + ry, s);
            offset_mask(x, y, mask);
            const int c = g.index(x, y);
            if (s == 0 && g.found[c])  // Depth and index passes: sample 0's camera hit, as Cycles
              ctx_.record_first_hit(film, x, y, g.hit[c]);
            cs.ray = &g.ray[c];
            cs.hit = &g.hit[c];
            cs.found = g.found[c];
            for (int k = 0; k < kOffsets; ++k) {
              if (!mask[k]) continue;
              const int n = g.index(x + kStepX[k], y + kStepY[k]);
              cs.off_ray[k] = &g.ray[n];
              cs.off_hit[k] = &g.hit[n];
              cs.off_found[k] = g.found[n];
            }
            run_path(sampler, cs, x, y);
          }
      }
    } else {
      // Depth of field: every pixel keeps its own jitter and lens sample, so each offset traces
      // its own camera ray (through the neighbour, with the base's jitter and lens sample).
      CameraRow& row = scratch.row;
      for (uint32_t s = first_sample; s < first_sample + sample_count; ++s)
        for (int y = tile.y0; y < tile.y1; ++y)
          for (int x0 = tile.x0; x0 < tile.x1; x0 += kRow) {
            const int n = std::min(kRow, tile.x1 - x0);
            // --- Camera rays of the row: same jitter and lens sample for a base and its offsets
            for (int i = 0; i < kRow; ++i) {
              row.valid[i] = i < n;
              if (!row.valid[i]) continue;
              const int x = x0 + i;
              row.sampler[i].start(settings_.seed, x + rx, y + ry, s);
              const Vec2f jitter = row.sampler[i].get2d(Sampler::kDimCamera);
              row.lens[i] = row.sampler[i].get2d(Sampler::kDimLens);
              row.raster[i] = Vec2f(float(x + rx) + jitter.x, float(y + ry) + jitter.y);
              row.ray[i] = ctx_.camera().generate_ray(row.raster[i], row.lens[i]);
            }
            ctx_.bvh().intersect_stream(row.ray, row.valid, kRow, row.found, row.hit);
            if (s == 0)  // Depth and index passes: sample 0's camera hit, as Cycles
              for (int i = 0; i < n; ++i)
                if (row.found[i]) ctx_.record_first_hit(film, x0 + i, y, row.hit[i]);
            for (int i = 0; i < kRow; ++i) {
              bool* mask = row.mask[i];
              offset_mask(x0 + i, y, mask);
              const bool traced = row.valid[i] && row.found[i];
              Ray* cam = row.cam_pixel;
              if (traced) ctx_.camera().generate_offset_rays(row.raster[i], row.lens[i], mask, cam);
              for (int k = 0; k < kOffsets; ++k) {
                row.cam_valid[k * kRow + i] = traced && mask[k];
                if (row.cam_valid[k * kRow + i]) row.cam[k * kRow + i] = cam[k];
              }
            }
            ctx_.bvh().intersect_stream(row.cam, row.cam_valid, kOffsets * kRow, row.cam_found,
                                        row.cam_hit);
            for (int i = 0; i < n; ++i) {
              rays += 1;  // the base camera ray
              cs.mask = row.mask[i];
              cs.ray = &row.ray[i];
              cs.hit = &row.hit[i];
              cs.found = row.found[i];
              for (int k = 0; k < kOffsets; ++k) {
                cs.off_ray[k] = &row.cam[k * kRow + i];
                cs.off_hit[k] = &row.cam_hit[k * kRow + i];
                cs.off_found[k] = row.cam_found[k * kRow + i];
                rays += row.cam_valid[k * kRow + i];
              }
              run_path(row.sampler[i], cs, x0 + i, y);
            }
          }
    }
    for (int y = tile.y0; y < tile.y1; ++y)
      for (int x = tile.x0; x < tile.x1; ++x) film.add_sample_count(x, y, sample_count);
    count_rays(rays);
  }

 private:
  VertexType classify(float roughness) const {
    return shift::classify_vertex(roughness, settings_.shift_roughness_threshold);
  }

  // The segment from vertex `v` along `dir` up to t_max, leaving the surface on the side of
  // `dir`: an occlusion query only (EmbreeScene::occluded).
  static Ray shadow_ray(const Vertex& v, const Vec3f& dir, float t_max, uint32_t kind) {
    const Vec3f from = v.hit.position;
    Ray shadow;
    shadow.kind = kind;
    shadow.origin = ray_origin(v, dot(dir, v.ng) > 0.0f);
    shadow.direction = dir;
    shadow.t_min = 0.0f;
    shadow.t_max = t_max;
    if (std::isfinite(t_max)) {
      // Aim at the same end point from the offset origin: the offset shortens the path to a
      // light surface by up to offset / cos, which at grazing angles exceeded the caller's
      // 1e-4 margin and made an emitter occlude itself. The direction is that segment itself,
      // not a unit vector, and t runs over [0, 1]: Embree accepts any direction length (t is
      // measured in it), and an occlusion query needs no unit direction, which saves a square
      // root and three divisions per ray.
      const Vec3f to = from + dir * t_max - shadow.origin;
      if (length_squared(to) > 0.0f) {
        shadow.direction = to;
        shadow.t_max = 1.0f;
      }
    }
    return shadow;
  }

  // `kind`: kRayShadow for light samples; a reconnected segment is the kind of the base's
  // segment it replaces (RayKind, Instance::visibility).
  bool occluded(const Vertex& v, const Vec3f& dir, float t_max, uint32_t kind,
                uint32_t& rays) const {
    ++rays;
    return ctx_.bvh().occluded(shadow_ray(v, dir, t_max, kind));
  }

  // Whether a light sample of lamp `ls` (its cast_shadow and is_delta) taken from `v` towards
  // `dir`, `distance` away (infinite lamps: any distance), is unblocked. Delta lamps see through
  // Transparent surfaces as in PT (Cycles' transparent shadows: `le` is multiplied by the
  // transmittance), because no BSDF sample can reach them; the light of other lamps through such
  // surfaces arrives by BSDF sampling (a crossing is a delta event of the path), so their shadow
  // rays stay opaque and nothing is counted twice.
  bool lamp_visible(const Vertex& v, const LightSample& ls, const Vec3f& dir, float distance,
                    bool infinite, ClosureSet& scratch, Spectrum& le, uint32_t& rays) const {
    if (!ls.cast_shadow) return true;  // Light::cast_shadow off: no shadow ray
    const float t_max = infinite ? kInf : distance * (1.0f - 1e-4f);
    if (ls.is_delta && transparent_shadows_) {
      const Spectrum tr = ctx_.transmittance(shadow_ray(v, dir, t_max, kRayShadow), scratch, rays);
      le *= tr;
      return !is_black(tr);
    }
    return !occluded(v, dir, t_max, kRayShadow, rays);
  }

  // Local outgoing direction at `v` for world `dir`; false when the geometric and shading
  // hemispheres disagree (the path tracer's leak test).
  static bool local_dir(const Vertex& v, Vec3f dir, Vec3f& wo) {
    wo = v.frame.to_local(dir);
    return v.closures->side_ok(wo, dot(dir, v.ng));
  }

  // Squared distance of two unit normals of the same surface point evaluated from two
  // reference points (rounding only); receiver-facing discs differ by the angle between the
  // two receivers seen from the light, far above this.
  static constexpr float kSameNormal2 = 1e-8f;

  // The offset's light sample for a not-connected pair: the same point on the light (same
  // direction for infinite lights) as the base's sample `ls`, seen from y. Resampling with the
  // same random numbers gives that point for area-sampled lights, the world and the sun;
  // solid-angle-sampled spheres are evaluated by intersecting the light towards the point.
  bool offset_light(Vec3f y, float u_select, Vec2f u_light, const LightSample& ls,
                    LightSample& out) const {
    const LightSampler& lights = ctx_.lights();
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

  // Traces the tile's camera rays and a one-pixel halo around it for sample `s` (CameraGrid),
  // with the image-wide jitter of that sample: a sampler keyed to no pixel, (-1, -1). Returns
  // the number of rays.
  uint64_t trace_camera_grid(const Tile& tile, int W, int H, uint32_t s, CameraGrid& g) const {
    Sampler image_wide;
    image_wide.start(settings_.seed, -1, -1, s);
    const Vec2f jitter = image_wide.get2d(Sampler::kDimCamera);
    g.x0 = std::max(tile.x0 - 1, 0);
    g.y0 = std::max(tile.y0 - 1, 0);
    const int x1 = std::min(tile.x1 + 1, W), y1 = std::min(tile.y1 + 1, H);
    g.w = x1 - g.x0;
    g.h = y1 - g.y0;
    g.reserve(size_t(g.w) * size_t(g.h));
    const int rx = ctx_.camera().region_x(), ry = ctx_.camera().region_y();  // frame raster
    uint64_t n = 0;
    for (int y = g.y0; y < y1; ++y) {
      const bool row_inside = y >= tile.y0 && y < tile.y1;
      for (int x = g.x0; x < x1; ++x) {
        const int c = g.index(x, y);
        // The halo's corners are no tile pixel's neighbour.
        g.valid[c] = row_inside || (x >= tile.x0 && x < tile.x1);
        if (!g.valid[c]) continue;
        g.ray[c] = ctx_.camera().generate_ray(
            Vec2f(float(x + rx) + jitter.x, float(y + ry) + jitter.y), Vec2f(0.5f, 0.5f));
        ++n;
      }
    }
    ctx_.bvh().intersect_stream(g.ray.data(), g.valid.get(), g.w * g.h, g.found.get(),
                                g.hit.data());
    return n;
  }

  // Traces one base path and its offsets from camera rays render_tile() has traced.
  void trace(const Sampler& sampler, const CameraSample& cs, PathScratch& scratch,
             SampleResult& out) const {
    const EmbreeScene& bvh = ctx_.bvh();
    const LightSampler& lights = ctx_.lights();
    const int max_bounces = settings_.max_bounces;
    const bool has_lights = !lights.empty();
    const bool needs_selection = lights.needs_selection();
    const bool* mask = cs.mask;

    out.primal = Spectrum(0.0f);
    out.emission = Spectrum(0.0f);
    out.alpha = 1.0f;
    out.attempts = out.failures = 0;
    out.rays = 0;  // camera rays are counted by render_tile()
    out.data = DataSample{};

    // --- Camera rays (traced by render_tile) ---
    const Ray& cam_ray = *cs.ray;
    const SurfaceHit& hit = *cs.hit;
    // A holdout at the camera hit ends the path as an escape to a black world would (Cycles:
    // nothing added; with a transparent background coverage 0); offsets meeting one are dead.
    const bool holdouts = ctx_.has_holdout();
    const bool holdout = cs.found && holdouts && ctx_.is_holdout(*cs.hit);
    const bool camera_found = cs.found && !holdout;
    // Very direct light, never shifted: lamps visible to the camera, and the world.
    if (has_visible_lamps_) {
      LightHit lh;
      if (lights.intersect(cam_ray.origin, cam_ray.direction, cs.found ? hit.t : cam_ray.t_max,
                           lh) &&
          lh.camera_visible)
        out.emission += lh.radiance;
    }
    if (!camera_found) {
      if (settings_.transparent_background)
        out.alpha = 0.0f;
      else if (has_camera_world_ && !holdout)
        out.emission += lights.camera_environment(cam_ray.direction);
      for (Vec3d& g : out.grad) g = Vec3d();
      return;
    }

    Offset* off = scratch.off;
    for (int k = 0; k < kOffsets; ++k) {
      Offset& o = off[k];
      o.active = mask[k];
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
      o.alive = cs.off_found[k] && !(holdouts && ctx_.is_holdout(*cs.off_hit[k]));
      if (o.alive) setup_vertex(ctx_, sides_, *cs.off_hit[k], cs.off_ray[k]->direction, o.v);
    }

    int cur = 0;  // scratch.verts[cur] is the base vertex
    setup_vertex(ctx_, sides_, hit, cam_ray.direction, scratch.verts[cur]);
    if (data_.active())
      data_.at_surface(hit, *scratch.verts[cur].closures, Spectrum(1.0f), out.data);
    // Very direct light: emission seen by the camera, never shifted.
    out.emission += triangle_le(hit, cam_ray.origin);
    Ray ray;  // the base's current segment

    Spectrum beta(1.0f);  // f / p of the base, for the primal (PT estimator)
    // Nothing but straight transparent crossings since the camera (the offsets, which copy
    // delta events, cross with the base). With Film > Transparent such a path leaves the world
    // out and the pixel's coverage is what it crossed (Cycles' rule, as PT).
    bool camera_path = true;
    BounceCounts kinds;  // the base's scattering events by kind (per-kind limits)
    // Cycles' bounce counts, as PT's: scattering events (`bounce` below numbers every vertex,
    // straight transparent crossings included, for the sampler's dimensions) and crossings.
    int scatterings = 0, crossings = 0;
    Vec3d fb(1.0, 1.0, 1.0);
    double pb = 1.0;
    bool rr_stop = false;  // the roulette stopped the base: the current segment is its last
    float rr_q = 1.0f;     // a survived roulette whose division waits for the segment's emission

    // Bounce 0's numbers; later bounces' are drawn before the segment to them is traced, to run
    // alongside it (Sampler::vertex_numbers).
    Sampler::VertexNumbers u = sampler.vertex_numbers(0, has_lights);
    for (int bounce = 0;; ++bounce) {
      if (scatterings > max_bounces) break;
      const Vertex& base = scratch.verts[cur];
      Vertex& next_base = scratch.verts[cur ^ 1];
      // Normal / Mist passes at the surfaces the camera path meets after transparent crossings
      // (the camera hit's are recorded above).
      if (bounce > 0 && camera_path && data_.active())
        data_.at_surface(base.hit, *base.closures, beta, out.data);
      if (!base.closures->has_bsdf()) break;

      const VertexType base_type = classify(base.roughness);
      const ClosureSet& bc = *base.closures;

      // Offsets arriving at a shared vertex see it from their own direction. `open` counts the
      // offsets with work of their own at this bounce (alive, not connected); connected and dead
      // ones are "merged" (add_merged) and once all are, the bounce skips every offset loop.
      //
      // Per-pair NEE rule, shared by light sampling here and BSDF-sampled light hits at the next
      // vertex: a not-connected pair shifts light samples only when both vertices are diffuse.
      // A dead offset leaves the base alone with both of its techniques: light sampling stays on
      // (nee_on, as for connected offsets).
      int open = 0;
      unsigned open_mask = 0;  // bit k: offset k is open (the loops below visit only these)
      for (Offset& o : std::span(off, kOffsets)) {
        o.nee_on = true;
        if (!o.active || !o.alive || o.link == Link::Connected) continue;
        if (o.link == Link::Recent) {
          o.wi_shared = base.frame.to_local(o.wi_world);
        } else if (!o.v.closures->has_bsdf()) {
          o.alive = false;  // the offset ends on a surface without BSDF: it cannot follow
          continue;
        } else {
          o.nee_on =
              base_type == VertexType::Diffuse && classify(o.v.roughness) == VertexType::Diffuse;
        }
        ++open;
        open_mask |= 1u << (&o - off);
      }
      if (has_lights) {
        // Dimensions are indexed, not streamed: skipping an unused one changes no other value
        // (as in the path tracer). Offsets resample with the base's numbers.
        const float u_select =
            needs_selection ? sampler.get1d(Sampler::bounce_dim(bounce, Sampler::kLightSelect))
                            : 0.0f;
        const Vec2f u_light = u.light;
        const LightSample ls = lights.sample(base.hit.position, u_select, u_light);
        if (ls.valid && ls.pdf > 0.0f) {
          // --- Base ---
          Vec3f wo;
          Spectrum fs(0.0f);
          float pdf_fs = 0.0f;
          bool visible = false;
          Spectrum le = ls.radiance;  // arriving: times the transmittance of delta lamps' rays
          if (local_dir(base, ls.direction, wo)) {
            fs = bc.eval_pdf(base.wi, wo, pdf_fs);
            if (!is_black(fs) && !is_black(ls.radiance))
              visible = lamp_visible(base, ls, ls.direction, ls.distance, ls.is_infinite,
                                     scratch.shadow_closures, le, out.rays);
          }
          const float pdf_bsdf = (!ls.is_delta && visible) ? pdf_fs : 0.0f;
          if (visible) {
            const float w = ls.is_delta ? 1.0f : power_heuristic(ls.pdf, pdf_bsdf);
            out.primal += beta * fs * le * (w / ls.pdf);
          }
          const Vec3d cb = visible ? mul(mul(fb, fs), le) : Vec3d();
          // The pair weights see the light technique through mis_light_pdf().
          const float pl_mis = ls.is_infinite ? ls.pdf
                                              : mis_light_pdf(ls.area_pdf, ls.pdf, ls.distance,
                                                              -dot(ls.direction, ls.normal));
          const double tech_l = light_tech(pl_mis, ls.pdf);
          const PathDensities db{pb, pl_mis, pdf_bsdf};

          // --- Merged offsets (connected or dead) ---
          if (visible)
            add_merged(off, fb, pb, connected_event(mul(Vec3d(fs), le), tech_l, pl_mis, pdf_bsdf));

          // --- Open offsets ---
          // First pass: the offsets' light samples and the shadow rays of the not-connected
          // ones. Each is its own occlusion query: Embree's 4-ray packets (rtcOccluded4) of these
          // rays from neighbouring points towards the same light point cost 3-4% more time.
          enum class NeeCase : uint8_t { Skip, Shared, NoLight, Shifted };
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
            if (!offset_light(o.v.hit.position, u_select, u_light, ls, lo[k])) {
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
            fo[k] = Spectrum(0.0f);
            if (local_dir(o.v, lo[k].direction, wo_o[k])) {
              fo[k] = o.v.closures->eval_pdf(o.v.wi, wo_o[k], pdf_fo[k]);
              if (!is_black(fo[k]) && !is_black(lo[k].radiance)) {
                test[k] = true;
                // The same lamp as the base's sample (its cast_shadow and is_delta).
                blocked[k] =
                    !lamp_visible(o.v, ls, lo[k].direction, lo[k].distance, lo[k].is_infinite,
                                  scratch.shadow_closures, lo[k].radiance, out.rays);
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
                  if (same_side(base, o.wi_shared, base.wi, wo)) {
                    f_r = fs;
                    pdf_o = pdf_fs;
                  } else {
                    f_r = bc.eval_pdf(o.wi_shared, wo, pdf_o);
                  }
                  if (ls.is_delta) pdf_o = 0.0f;
                }
                co = mul(mul(o.f, f_r), le);
                d_off = shift::offset_densities(o.p, 1.0, pl_mis, pdf_o);
                break;
              }
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
      }

      // ==================== BSDF sampling: extend the base ====================
      // The lobe number is drawn when the base's closures read it, or below when a delta shift
      // samples an offset's closures that do.
      bool lobe_drawn = bc.uses_lobe_choice();
      const float u_lobe =
          lobe_drawn ? sampler.get1d(Sampler::bounce_dim(bounce, Sampler::kBsdfLobe)) : 0.0f;
      const Vec2f u_dir = u.dir;
      const BsdfSample bs = bc.sample(base.wi, u_lobe, u_dir);
      if (!bs.valid || !(bs.pdf > 0.0f) || is_black(bs.value)) break;
      const Vec3f wo_world = base.frame.to_world(bs.wo);
      const float cos_ng = dot(wo_world, base.ng);
      if (!bc.side_ok(bs.wo, cos_ng)) break;
      const bool delta = bs.is_delta();
      // Classification of x_d for the BSDF step: a sampled delta lobe makes it specular.
      const VertexType xd_type = delta ? VertexType::Specular : base_type;

      beta *= bs.value / bs.pdf;
      // A straight transparent crossing is no bounce (Cycles' transparent bounce): it counts for
      // no limit and no roulette, and keeps the ray's kind.
      const bool crossing = bs.is_straight_crossing();
      // --- Russian roulette, decided by the base; q enters every density of the pair ---
      // After a glossy or specular bounce it takes effect past the segment's emission events
      // (roulette_past_next_hit): the segment is traced either way (a stopped path's last).
      if (!crossing && scatterings >= settings_.rr_depth) {
        const float q = roulette_continuation(beta);
        if (q < 1.0f) {
          const bool last_ray = roulette_past_next_hit(bs.lobe, ctx_.scene_features());
          const bool survive = sampler.get1d(Sampler::bounce_dim(bounce, Sampler::kRoulette)) < q;
          if (survive && last_ray) {
            rr_q = q;
          } else if (survive) {
            divide_by_continuation(q, beta, pb, off);
          } else if (last_ray) {
            rr_stop = true;
          } else {
            break;
          }
        }
      }

      // --- Trace the base's next segment ---
      ray.origin = ray_origin(base, cos_ng > 0.0f);
      ray.direction = normalize(wo_world);
      ray.t_min = 0.0f;
      ray.t_max = kInf;
      if (crossing) {
        ++crossings;
      } else {
        ++scatterings;
        ray.kind = ray_kind_of_lobe(bs.lobe);
        kinds.add(ray.kind);
      }
      camera_path = camera_path && crossing;
      // A camera path (transparent crossings only) sees the world as camera rays do.
      const bool world_seen =
          camera_path ? has_camera_world_ && !settings_.transparent_background : has_world_;
      // The hit goes straight into the next vertex. Its end point only ends the path at the last
      // bounce: no vertex set-up there (the offsets' shifts need its classification alone), and
      // no hit record either when no offset shifts and no triangle emits (as PT).
      const bool last = rr_stop || scatterings > max_bounces ||
                        crossings > kMaxTransparentBounces || kinds.over(settings_);
      if (!last) u = sampler.vertex_numbers(bounce + 1, has_lights);
      const SurfaceHit& next = next_base.hit;
      // A holdout met by the camera path (only transparent crossings so far) ends it as an escape
      // into a black world would (Cycles); the offsets' segments likewise (shift_segment).
      const bool holdout_ends = holdouts && camera_path;
      bool found = last && open == 0 && !has_emissive_ && !holdout_ends
                       ? bvh.intersect_distance(ray, next_base.hit.t)
                       : bvh.intersect(ray, next_base.hit);
      ++out.rays;
      const bool base_holdout = found && holdout_ends && ctx_.is_holdout(next);
      const float t_hit = found ? next.t : kInf;
      found = found && !base_holdout;
      LightHit lh;
      const bool light_hit = lights.intersect(ray.origin, ray.direction, t_hit, lh);
      VertexType next_type = VertexType::Diffuse;
      if (found && !last) {
        finish_vertex(ctx_, sides_, ray.direction, next_base);
        next_type = classify(next_base.roughness);
      } else if (found && open > 0) {
        next_type = classify(next_vertex_roughness(next));
      }

      // --- Shift every offset over this segment ---
      const Vec3d seg_b = Vec3d(bs.value);
      const float pdf_b = bs.pdf;
      // Filled member by member: an aggregate assignment built a temporary with narrow stores and
      // copied it with 16-byte loads across them (failed store-to-load forwarding; perf annotate
      // put ~1% of the samples there).
      BaseStep& st = scratch.step;
      if (open > 0) {
        st.base = &base;
        st.bs = &bs;
        st.xd_type = xd_type;
        st.next_type = next_type;
        st.wo_world = wo_world;
        st.found = found;
        st.next = &next;
        st.u_lobe = u_lobe;
        st.u_dir = u_dir;
        st.kind = ray.kind;
        st.holdout_ends = holdout_ends;
        st.base_front = false;
        // The reconnection target (a double square root and division) only where shift_segment()
        // may reconnect: x_d and x_{d+1} diffuse.
        if (found && xd_type == VertexType::Diffuse && next_type == VertexType::Diffuse) {
          st.target =
              shift::reconnection_base(base.hit.position, next.position, next.geometric_normal);
          st.base_front = dot(base.hit.position - next.position, next.geometric_normal) > 0;
        }
      }
      for (unsigned m = open_mask; m != 0; m &= m - 1) {
        Offset& o = off[std::countr_zero(m)];
        if (!lobe_drawn && delta && o.link == Link::NotConnected &&
            o.v.closures->uses_lobe_choice()) {
          st.u_lobe = sampler.get1d(Sampler::bounce_dim(bounce, Sampler::kBsdfLobe));
          lobe_drawn = true;
        }
        shift_segment(o, st, out.rays);
      }

      // ==================== Emission events at the end of the segment ====================
      // Emission events are processed per pair whenever the base OR the offset finds emission:
      // a half-vector offset has its own end vertex and can reach a light the base misses.

      // Merged offsets: the events' common part, applied once after (a)-(c).
      Vec3d emit_merged;

      // (a) analytic lights crossed by the rays (before their surfaces).
      {
        const bool base_lit = light_hit && !is_black(lh.radiance);
        const float pl = (base_lit && !delta) ? lh.pdf : 0.0f;
        if (base_lit)
          out.primal += beta * lh.radiance * (delta ? 1.0f : power_heuristic(pdf_b, pl));
        // The pair weights' light density (mis_light_pdf); the primal keeps PT's.
        const float pl_mis =
            pl > 0.0f && std::isfinite(lh.distance)
                ? mis_light_pdf(lh.area_pdf, pl, lh.distance, -dot(ray.direction, lh.normal))
                : pl;
        const Vec3d cb = base_lit ? mul(mul(fb, seg_b), lh.radiance) : Vec3d();
        if (base_lit) emit_merged = connected_event(mul(seg_b, lh.radiance), pdf_b, pl_mis, pdf_b);
        for (unsigned m = open_mask; m != 0; m &= m - 1) {
          Offset& o = off[std::countr_zero(m)];
          // Without a lit base only a half-vector offset's own ray can find a light.
          if (!base_lit && o.shift != Shift::HalfVector) continue;
          Vec3d co;
          PathDensities d_off{0.0, 0.0, 0.0};
          const float pl_pair = o.nee_on ? pl_mis : 0.0f;
          const bool reconnectable = o.link == Link::NotConnected && !delta &&
                                     base_type == VertexType::Diffuse &&
                                     classify(o.v.roughness) == VertexType::Diffuse;
          if (o.alive) {
            if (o.shift == Shift::Follow || o.shift == Shift::RecentEval) {
              if (base_lit) {
                co = mul(mul(o.f, o.seg_value), lh.radiance);
                d_off = shift::offset_densities(o.p, 1.0, pl_pair, o.seg_pdf);
              }
            } else if (reconnectable) {
              // The light point is a diffuse end vertex: reconnect y_d to it. (A light that only
              // the offset's own direction finds belongs to the reverse reconnection: not here.)
              if (base_lit)
                reconnect_to_light(o, base, ray.direction, ray.kind, lh, pl_pair, co, d_off,
                                   out.rays);
            } else if (o.shift == Shift::HalfVector) {
              // The offset's own direction: does its ray cross a light before its surface?
              LightHit lo;
              const float t_o = o.next_found || o.holdout_end ? o.next_hit.t : kInf;
              if (lights.intersect(o.ray.origin, o.ray.direction, t_o, lo))
                co = mul(mul(o.f, o.seg_value), lo.radiance) * o.seg_jacobian;
              d_off = shift::offset_densities(o.p, o.seg_jacobian, 0.0, o.seg_pdf);
            }
          }
          if (is_zero(cb) && is_zero(co)) continue;
          const double w =
              shift::mis_weight_over_pdf(PathDensities{pb, pl_pair, pdf_b}, d_off, pdf_b);
          o.grad = o.grad + (co - cb) * w;
        }
      }

      // (b) the world, (c) an emissive triangle at the end of the segment.
      {
        Spectrum le(0.0f);
        float pl = 0.0f;
        if (!found) {
          if (camera_path && settings_.transparent_background) out.alpha = uncovered_alpha(beta);
          if (world_seen && !base_holdout) {
            le = camera_path ? lights.camera_environment(ray.direction)
                             : lights.environment(ray.direction);
            if (!delta && !camera_path && !is_black(le)) pl = lights.pdf_environment(ray.direction);
          }
        } else {
          le = triangle_le(next, base.hit.position);
          if (!delta && !is_black(le))
            pl = lights.pdf_triangle(next.instance, next.primitive, base.hit.position,
                                     next.position, next.geometric_normal);
        }
        const bool base_emits = !is_black(le);
        if (base_emits) out.primal += beta * le * (delta ? 1.0f : power_heuristic(pdf_b, pl));
        const Vec3d cb = mul(mul(fb, seg_b), le);
        if (base_emits)
          emit_merged = emit_merged + connected_event(mul(seg_b, le), pdf_b, pl, pdf_b);
        for (unsigned m = open_mask; m != 0; m &= m - 1) {
          Offset& o = off[std::countr_zero(m)];
          // Without emission at the base's end point only a half-vector offset's own end point
          // can have some (the other shifts end at the same point, seen from the same side).
          if (!base_emits && o.shift != Shift::HalfVector) continue;
          Vec3d co;
          PathDensities d_off{0.0, 0.0, 0.0};
          const float pl_pair = o.nee_on ? pl : 0.0f;
          if (o.alive)
            end_event(o, found, world_seen, camera_path, next, le, pl_pair, !delta && o.nee_on, co,
                      d_off);
          if (is_zero(cb) && is_zero(co)) continue;
          const double w =
              shift::mis_weight_over_pdf(PathDensities{pb, pl_pair, pdf_b}, d_off, pdf_b);
          o.grad = o.grad + (co - cb) * w;
        }
      }

      if (!is_zero(emit_merged)) add_merged(off, fb, pb, emit_merged);
      if (rr_q != 1.0f) {  // survived a deferred roulette: what follows is divided
        divide_by_continuation(rr_q, beta, pb, off);
        rr_q = 1.0f;
      }

      // ==================== Advance ====================
      fb = mul(fb, seg_b);
      pb *= pdf_b;
      for (Offset& o : std::span(off, kOffsets)) {
        if (!o.active || !o.alive) continue;
        if (o.link == Link::Connected) {  // the base's segment (shift_segment skipped them)
          o.f = mul(o.f, seg_b);
          o.p *= pdf_b;
        } else {
          advance(o, last);
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

  // Merged offsets: a connected offset shares the rest of the base path, so for an emission
  // event with base contribution C = fb Y its contribution is C' = f' Y with the same technique
  // densities, and the pair weight of shift::mis_weight_over_pdf factors into
  // [p / (p^2 + p'^2)] [p_tech / (p_L^2 + p_B^2)]: w (C' - C) = (f' - fb) p / (p^2 + p'^2) E with
  // the event part E = connected_event(Y, ...) common to all offsets. A dead offset is the same
  // with f' = 0 and p' = 0 (it adds -w C, the base keeping both of its techniques). Equal up to
  // rounding to the per-pair evaluation, which the open offsets still use.
  // A survived roulette of continuation probability q: the base's throughput is divided by it,
  // and it enters every density of the pair.
  static void divide_by_continuation(float q, Spectrum& beta, double& pb, Offset* off) {
    beta /= q;
    pb *= q;
    for (Offset& o : std::span(off, kOffsets)) o.p *= q;
  }

  static void add_merged(Offset* off, Vec3d fb, double pb, Vec3d event) {
    for (Offset& o : std::span(off, kOffsets)) {
      if (!o.active || (o.alive && o.link != Link::Connected)) continue;
      const Vec3d f = o.alive ? o.f : Vec3d();
      const double p = o.alive ? o.p : 0.0;
      const double d = pb * pb + p * p;
      if (d > 0.0) o.grad = o.grad + mul(f - fb, event) * (pb / d);
    }
  }

  // Decides and evaluates the offset's version of the base segment x_d -> x_{d+1}.
  void shift_segment(Offset& o, const BaseStep& st, uint32_t& rays) const {
    const EmbreeScene& bvh = ctx_.bvh();
    const Vertex& base = *st.base;
    const BsdfSample& bs = *st.bs;
    const VertexType xd_type = st.xd_type, next_type = st.next_type;
    const Vec3f wo_world = st.wo_world;
    const bool found = st.found;
    const SurfaceHit& next = *st.next;
    const float u_lobe = st.u_lobe;
    const Vec2f u_dir = st.u_dir;
    o.seg_jacobian = 1.0;
    o.seg_visible = true;
    o.killed = false;
    o.next_found = o.holdout_end = false;
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
        if (same_side(base, o.wi_shared, base.wi, bs.wo)) {
          // A Lambert sample's value and pdf are eval() and pdf() of wo (bit-identical).
          o.seg_value = Vec3d(bs.value);
          o.seg_pdf = bs.pdf;
        } else {
          float pdf = 0.0f;
          o.seg_value = Vec3d(base.closures->eval_pdf(o.wi_shared, bs.wo, pdf));
          o.seg_pdf = pdf;
        }
        if (!(o.seg_pdf > 0.0)) o.shift = Shift::Failed;
        return;
      }
      case Link::NotConnected:
        break;
    }

    const Vertex& y = o.v;
    const VertexType yd_type =
        bs.is_delta() && y.closures->has_delta() ? VertexType::Specular : classify(y.roughness);

    // --- Reconnection: x_d, y_d and x_{d+1} all diffuse ---
    if (xd_type == VertexType::Diffuse && yd_type == VertexType::Diffuse &&
        next_type == VertexType::Diffuse) {
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
        // Visibility, a single occlusion query (4-ray packets cost more, see trace()).
        o.seg_visible = !occluded(y, dir, float(r.distance) * (1.0f - 1e-4f), st.kind, rays);
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
        o.seg_visible = !occluded(y, wo_world, kInf, st.kind, rays);
      }
      return;
    }

    // --- Half-vector copy in the local frames ---
    Vec3f wo;
    if (bs.is_delta()) {
      // Delta lobe: the same discrete event (reflection / transmission) at y_d, J = 1. The
      // offset samples its own closures; when its random choice differs, the choice is forced
      // for a single-lobe closure set (the lobe's event is driven by u_lobe alone).
      const uint8_t want = bs.lobe & (kLobeReflection | kLobeTransmission);
      BsdfSample so = y.closures->sample(y.wi, u_lobe, u_dir);
      if (so.valid && (!so.is_delta() || (so.lobe & want) == 0) && y.closures->count() == 1)
        so = y.closures->sample(y.wi, (want & kLobeReflection) ? 0.0f : 0.99999994f, u_dir);
      if (!so.valid || !so.is_delta() || (so.lobe & want) == 0 || !(so.pdf > 0.0f)) {
        o.shift = Shift::Failed;
        return;
      }
      wo = so.wo;
      o.seg_value = Vec3d(so.value);
      o.seg_pdf = so.pdf;
      o.seg_jacobian = 1.0;
    } else {
      const shift::Vec3d wi_b(base.wi), wo_b(bs.wo), wi_o(y.wi);
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
    o.holdout_end = o.next_found && st.holdout_ends && ctx_.is_holdout(o.next_hit);
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
          o.next_found ? classify(next_vertex_roughness(o.next_hit)) : VertexType::Diffuse;
      if (yn_type == VertexType::Diffuse) o.killed = true;
    }
  }

  // Emission of an emissive triangle at `hit` towards `from`; none without emissive triangles.
  Spectrum triangle_le(const SurfaceHit& hit, Vec3f from) const {
    return has_emissive_ ? triangle_emission(ctx_, hit, from) : Spectrum(0.0f);
  }

  float next_vertex_roughness(const SurfaceHit& h) const {
    const MaterialSide& side = sides_[2 * size_t(h.material) + (h.front_facing ? 1 : 0)];
    if (side.set) return side.roughness;
    ClosureSet cs;
    ctx_.materials()[size_t(h.material)].evaluate(shading_context_of(h), cs);
    return vertex_roughness(cs);
  }

  // (a) for a not-connected pair with x_d, y_d diffuse: the offset reconnects to the point the
  // base's ray found on an analytic light.
  void reconnect_to_light(Offset& o, const Vertex& base, Vec3f base_dir, uint32_t kind,
                          const LightHit& lh, float pl_pair, Vec3d& co, PathDensities& d_off,
                          uint32_t& rays) const {
    const Vertex& y = o.v;
    if (!std::isfinite(lh.distance)) {
      // A sun disc: reconnection at infinity, the same direction and radiance, J = 1.
      Vec3f wo;
      if (!local_dir(y, base_dir, wo)) return;
      float pdf_o = 0.0f;
      const Spectrum fo = y.closures->eval_pdf(y.wi, wo, pdf_o);
      const bool vis = !occluded(y, base_dir, kInf, kind, rays);
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
    const bool reaches = ctx_.lights().intersect(y.hit.position, dir, d * (1.0f + 1e-3f), lo) &&
                         std::fabs(lo.distance - d) < 1e-3f * d &&
                         length_squared(lo.normal - lh.normal) <= kSameNormal2;
    float pdf_o = 0.0f;
    const Spectrum fo = y.closures->eval_pdf(y.wi, wo, pdf_o);
    const bool vis = reaches && !occluded(y, dir, d * (1.0f - 1e-4f), kind, rays);
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
  void end_event(const Offset& o, bool found, bool world_seen, bool camera_path,
                 const SurfaceHit& next, Spectrum le, float pl_pair, bool nee_on, Vec3d& co,
                 PathDensities& d_off) const {
    const LightSampler& lights = ctx_.lights();
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
        const Spectrum le_o = triangle_le(next, o.v.hit.position);
        const float pl_o =
            pl_pair > 0.0f ? lights.pdf_triangle(next.instance, next.primitive, o.v.hit.position,
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
          le_o = triangle_le(o.next_hit, o.v.hit.position);
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

  // Moves the offset to the end of the segment (`last`: the path ends there, no vertex needed).
  void advance(Offset& o, bool last) const {
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
        if (o.next_found && !last) setup_vertex(ctx_, sides_, o.next_hit, o.ray.direction, o.v);
        break;
      case Shift::Failed:
        return kill();
    }
    o.f = mul(o.f, o.seg_value) * o.seg_jacobian;
    o.p *= o.seg_pdf * o.seg_jacobian;
  }

  const SceneContext& ctx_;
  RenderSettings settings_;
  bool has_world_ = false;
  bool has_camera_world_ = false;  // LightSampler::has_camera_environment
  bool has_visible_lamps_ = false;
  bool has_dof_ = false;
  bool has_emissive_ = false;
  std::vector<MaterialSide> sides_;
  DataPasses data_;
  bool transparent_shadows_ = false;  // some material has a Transparent closure
};

}  // namespace

std::unique_ptr<Integrator> make_gradient_path_tracer(const SceneContext& ctx,
                                                      const RenderSettings& settings) {
  return std::make_unique<GradientPathTracer>(ctx, settings);
}

}  // namespace gdpt
