#include "integrators/render_session.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "integrators/adaptive_sampling.h"
#include "integrators/gpt/gradient_path_tracer.h"
#include "integrators/integrator.h"
#include "integrators/pt/path_tracer.h"
#include "render/features.h"
#include "render/scene_context.h"

namespace gdpt {

namespace {
// Tiles are 16 pixels wide (a camera-ray stream, PathTracer::render_tile) and 16 tall; at one
// sample per pixel a tile takes well under a millisecond in typical scenes, so the cancel flag
// (polled between tiles) is seen almost immediately.
constexpr int kTileSize = 16;
// Every pass ends in a barrier, and its idle tail is about half a tile per worker. On small frames
// tiles are therefore 8 or 4 pixels tall, until each worker has at least this many per pass.
// Large frames keep 16x16 tiles, whose per-task overhead is smaller.
constexpr int kTilesPerWorker = 32;
// Pixel-samples per render_tile call (16 spp of a full tile): a few milliseconds of PT or G-PT.
constexpr uint32_t kChunkSamples = 16 * kTileSize * kTileSize;
// Adaptive sampling judges the pixels at least every this many samples (even: the feature
// passes' halves stay equal).
constexpr int kAdaptiveStep = 4;
// Film pairs of other sizes a session keeps: the viewport's start resolutions (divider 16 to 2).
constexpr size_t kMaxSpareFilms = 4;

int tile_height(int w, int h, int workers) {
  const int columns = (w + kTileSize - 1) / kTileSize;
  int height = kTileSize;
  while (height > 4 && columns * ((h + height - 1) / height) < kTilesPerWorker * workers)
    height /= 2;
  return height;
}

// The samples of the whole frame (RenderSettings::frame_samples).
uint64_t frame_total(const RenderSettings& settings) {
  return settings.frame_samples ? uint64_t(settings.frame_samples)
                                : uint64_t(settings.sample_offset) + uint64_t(settings.samples);
}

void check_settings(RenderSettings& settings) {
  if (settings.samples < 0) throw std::invalid_argument("render settings: samples must be >= 0");
  if (settings.max_bounces < 0 || settings.max_diffuse_bounces < 0 ||
      settings.max_glossy_bounces < 0 || settings.max_transmission_bounces < 0)
    throw std::invalid_argument("render settings: bounce limits must be >= 0");
  if (settings.rr_depth < 0)
    throw std::invalid_argument("render settings: the Russian roulette depth must be >= 0");
  if (settings.threads < 0) throw std::invalid_argument("render settings: threads must be >= 0");
  if (uint64_t(settings.sample_offset) + uint64_t(settings.samples) > uint64_t(UINT32_MAX))
    throw std::invalid_argument("render settings: sample_offset + samples must be < 2^32");
  if (settings.frame_samples != 0 &&
      uint64_t(settings.frame_samples) < uint64_t(settings.sample_offset) + settings.samples)
    throw std::invalid_argument(
        "render settings: frame_samples (the frame's samples over all parts) must be at least "
        "sample_offset + samples");
  if (settings.feature_passes && frame_total(settings) >= (uint64_t(1) << 31))
    throw std::invalid_argument(
        "render settings: with the feature passes the frame's samples "
        "must be < 2^31");
  if (!(settings.adaptive_threshold >= 0.0f) || !std::isfinite(settings.adaptive_threshold))
    throw std::invalid_argument("render settings: the noise threshold must be >= 0");
  if (settings.adaptive_min_samples < 0)
    throw std::invalid_argument("render settings: adaptive min samples must be >= 0");
  // Parts of a split frame stop their pixels apart: merged, they would be no render's samples.
  if (settings.adaptive_threshold > 0.0f &&
      (settings.sample_offset != 0 || settings.frame_samples != 0))
    throw std::invalid_argument(
        "render settings: adaptive sampling (noise threshold) renders a whole frame; turn it off "
        "for a render that is one part of a split frame (sample offset / frame samples)");
  if (settings.samples_per_pass < 1) settings.samples_per_pass = 1;
}
}  // namespace

struct RenderSession::Impl {
  Scene scene;
  RenderSettings settings;
  std::unique_ptr<SceneContext> context;
  std::unique_ptr<Integrator> integrator;
  Film film, pass_film;
  // Films of the cameras before (other sizes), the most recent first: the viewport's restarts
  // go through a few start resolutions to the full view, each size's films are kept.
  std::vector<std::pair<Film, Film>> spare_films;
  std::vector<Tile> tiles;
  // Adaptive sampling: the pixels that keep sampling (adaptive_sampling.h), the pass film's mask.
  std::vector<uint8_t> sampling_mask;
  std::vector<std::string> warnings;
  // settings.threads worker slots (0 = all cores): used for the BVH build and every pass.
  std::unique_ptr<tbb::task_arena> arena;
  // Whether the next render() sets the halves' split from its first sample's time.
  bool estimate_split = false;
  // Sets the halves' split from the first sample's time `seconds` (estimate_split).
  void split_from_first_sample(double seconds);
  // The integrator, films and tiles for scene.camera (at construction and on set_camera).
  void setup_for_camera();
  // The arena, the context (BVH included), then setup_for_camera(), for scene and settings.
  void build();
};

RenderSession::RenderSession(Scene scene, RenderSettings settings)
    : impl_(std::make_unique<Impl>()) {
  check_settings(settings);
  Impl& d = *impl_;
  d.scene = std::move(scene);  // owned: the context and the BVH refer to it
  d.settings = settings;
  d.build();
}

void RenderSession::Impl::build() {
  integrator.reset();
  context.reset();  // it refers to the scene, which the caller may have replaced
  const int arena_threads =
      settings.threads > 0 ? settings.threads : int(tbb::task_arena::automatic);
  arena = std::make_unique<tbb::task_arena>(arena_threads);
  // Embree builds with TBB: inside the arena it uses no more threads than the user allowed.
  arena->execute([&] { context = std::make_unique<SceneContext>(scene, settings); });
  warnings = context->warnings();
  setup_for_camera();
}

bool RenderSession::update(Scene scene, RenderSettings settings) {
  check_settings(settings);
  Impl& d = *impl_;
  std::vector<std::string> warnings;
  validate_scene(scene, warnings);  // before anything changes
  if (settings.threads != d.settings.threads || !same_geometry(d.scene, scene)) {
    d.integrator.reset();
    d.context.reset();  // before the meshes its BVH points into go
    d.scene = std::move(scene);
    d.settings = settings;
    d.build();
    return false;
  }
  // The BVH points into the kept meshes; the new scene's equal copies are dropped.
  scene.meshes = std::move(d.scene.meshes);
  d.integrator.reset();
  d.scene = std::move(scene);
  d.settings = settings;
  d.context->update_shading(d.settings);
  d.warnings = d.context->warnings();
  d.context->set_camera(d.scene.camera);
  d.setup_for_camera();
  return true;
}

void RenderSession::Impl::setup_for_camera() {
  // Mode dispatch: G-PT estimates the gradients itself; PT derives them from the primal (Film).
  integrator = settings.mode == RenderSettings::Mode::GPT
                   ? make_gradient_path_tracer(*context, settings)
                   : make_path_tracer(*context, settings);
  const int w = scene.camera.image_width(), h = scene.camera.image_height();
  const bool gradients_from_primal = !integrator->estimates_gradients();
  auto fits = [&](const Film& f) {
    return f.width() == w && f.height() == h &&
           f.gradients_from_primal() == gradients_from_primal &&
           f.has_normal() == settings.normal_pass && f.has_mist() == settings.mist_pass &&
           f.has_features() == settings.feature_passes;
  };
  // A restart clears kept films of its size instead of allocating (and faulting in) new ones.
  if (!fits(film)) {
    auto kept = std::find_if(spare_films.begin(), spare_films.end(),
                             [&](const auto& f) { return fits(f.first); });
    if (kept == spare_films.end() && spare_films.size() < kMaxSpareFilms)
      kept = spare_films.emplace(spare_films.end());
    else if (kept == spare_films.end())
      kept = spare_films.end() - 1;  // the least recent goes
    std::swap(film, kept->first);
    std::swap(pass_film, kept->second);
    std::rotate(spare_films.begin(), kept, kept + 1);  // most recent first
  }
  if (fits(film)) {
    arena->execute(
        [&] { tbb::parallel_invoke([&] { film.clear(); }, [&] { pass_film.clear(); }); });
  } else {
    film = Film(w, h, gradients_from_primal);
    pass_film = Film(w, h, gradients_from_primal);  // the output film's layout (take_rows)
    for (Film* f : {&film, &pass_film}) {
      f->enable_data_passes(settings.normal_pass, settings.mist_pass);
      f->enable_feature_passes(settings.feature_passes);
    }
  }
  // A time-limited render of a whole frame does not know the samples it will reach: its halves
  // are split where the first sample's time predicts (render()); sample 0 is half A's first point
  // at any split.
  estimate_split = settings.feature_passes && settings.time_limit > 0.0 &&
                   settings.frame_samples == 0 && settings.sample_offset == 0;
  const uint32_t split = settings.feature_passes ? half_split(frame_total(settings)) : 0;
  for (Film* f : {&film, &pass_film}) {
    f->set_sample_offset(settings.sample_offset);
    f->set_half_split(split);
  }
  tiles.clear();
  const int th = tile_height(w, h, arena->max_concurrency());
  for (int y = 0; y < h; y += th)
    for (int x = 0; x < w; x += kTileSize)
      tiles.push_back({x, y, std::min(x + kTileSize, w), std::min(y + th, h)});
}

void RenderSession::set_camera(const Camera& camera) {
  Impl& d = *impl_;
  d.context->set_camera(camera);  // validates first: a bad camera leaves the session as it was
  d.scene.camera = camera;
  d.setup_for_camera();
}

void RenderSession::Impl::split_from_first_sample(double seconds) {
  const double left = std::max(0.0, settings.time_limit - seconds);
  const double predicted = 1.0 + std::floor(left / std::max(seconds, 1e-9));
  const uint64_t total = uint64_t(std::min(double(settings.samples), predicted));
  for (Film* f : {&film, &pass_film}) f->set_half_split(half_split(total));
  estimate_split = false;
}

RenderSession::~RenderSession() = default;

void RenderSession::render(const std::function<void(const RenderProgress&)>& on_pass,
                           const std::atomic<bool>& cancel) {
  Impl& d = *impl_;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  tbb::task_arena& arena = *d.arena;
  const int total = d.settings.samples;
  // Adaptive sampling: from adaptive_from samples on, only the pixels of the mask sample.
  const bool adaptive = d.settings.adaptive_threshold > 0.0f;
  const int adaptive_from = adaptive ? adaptive_min_samples(d.settings) : total;
  d.pass_film.set_sampling_mask(nullptr);
  d.sampling_mask.clear();
  int done = int(adaptive ? d.film.max_samples() : d.film.min_samples());
  const int height = d.film.height();
  while (done < total) {
    if (cancel.load(std::memory_order_relaxed)) break;
    if (d.settings.time_limit > 0.0 && elapsed() >= d.settings.time_limit) break;
    // With the feature passes a pixel stops only after an even count: its halves stay equal.
    if (done >= adaptive_from && (done % 2 == 0 || !d.settings.feature_passes)) {
      size_t sampling = 0;
      arena.execute([&] {
        sampling = update_sampling_mask(d.film, d.settings.adaptive_threshold, d.sampling_mask);
      });
      if (sampling == 0) break;  // every pixel is below the noise threshold
      d.pass_film.set_sampling_mask(d.sampling_mask.data());
    }
    const uint32_t first = d.settings.sample_offset + uint32_t(done);
    const bool probe = d.estimate_split && done == 0;
    int per_pass = std::min(d.settings.samples_per_pass, total - done);
    // Adaptive sampling: a pass ends at the minimum samples, and after it every kAdaptiveStep
    // samples at most, where the pixels are judged again.
    if (adaptive)
      per_pass = done < adaptive_from ? std::min(per_pass, adaptive_from - done)
                                      : std::min(per_pass, kAdaptiveStep);
    const uint32_t count = probe ? 1u : uint32_t(per_pass);

    // --- One pass over every tile; a pass interrupted by cancel is discarded, so every pixel
    // always has the same sample count (adaptive sampling: every pixel that still samples) ---
    std::atomic<bool> aborted{false};
    arena.execute([&] {
      tbb::parallel_for(
          tbb::blocked_range<size_t>(0, d.tiles.size(), 1),
          [&](const tbb::blocked_range<size_t>& r) {
            for (size_t t = r.begin(); t != r.end(); ++t) {
              // A tile's samples go in chunks of at most kChunkSamples pixel-samples, with the
              // cancel flag polled between chunks, so a large samples_per_pass does not delay a
              // cancel. Each pixel still receives its samples in index order: the sums, hence the
              // image, do not depend on the chunking.
              const Tile& tile = d.tiles[t];
              const uint32_t pixels = uint32_t((tile.x1 - tile.x0) * (tile.y1 - tile.y0));
              const uint32_t chunk = std::max<uint32_t>(1, kChunkSamples / std::max(pixels, 1u));
              for (uint32_t s = 0; s < count; s += chunk) {
                if (cancel.load(std::memory_order_relaxed)) {
                  aborted.store(true, std::memory_order_relaxed);
                  return;
                }
                d.integrator->render_tile(tile, first + s, std::min(chunk, count - s), d.pass_film);
              }
            }
          },
          tbb::simple_partitioner());
    });
    if (aborted.load()) {
      d.pass_film.clear();
      break;
    }
    // --- Commit the pass ---
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, height, 8),
                        [&](const tbb::blocked_range<int>& r) {
                          d.film.take_rows(d.pass_film, r.begin(), r.end());
                        });
    });
    done += int(count);
    if (probe) d.split_from_first_sample(elapsed());
    if (on_pass) on_pass(RenderProgress{done, total, elapsed()});
  }
  d.pass_film.set_sampling_mask(nullptr);
}

const Film& RenderSession::film() const {
  return impl_->film;
}

const RenderSettings& RenderSession::settings() const {
  return impl_->settings;
}

const std::vector<std::string>& RenderSession::warnings() const {
  return impl_->warnings;
}

uint64_t RenderSession::rays_traced() const {
  return impl_->integrator->rays_traced();
}

std::string RenderSession::features_summary() const {
  const Impl& d = *impl_;
  const SceneContext& c = *d.context;
  std::ostringstream s;
  s << "scene features: " << features_to_string(c.scene_features());
  s << "; kernel: " << features_to_string(path_tracer_specialised_features(c.features()));
  if (d.settings.force_all_features) s << " (forced)";
  s << "; " << c.bvh().triangle_count() << " unique / " << c.bvh().instanced_triangle_count()
    << " instanced triangles, " << d.scene.instances.size() << " instances, "
    << d.scene.lights.size() << " lights";
  return s.str();
}

}  // namespace gdpt
