// The per-tile render entry point shared by every integrator (PT, G-PT).
//
// RenderSession owns a SceneContext (BVH, camera, lights, materials, textures, feature mask) and
// one Integrator. For each pass it calls render_tile() on disjoint tiles from several threads;
// an integrator must therefore be const/thread-safe and write only the pixels of its tile.
//
// Sample indices: pass `p` covers samples [K + p * spp, K + (p + 1) * spp) of every pixel (K =
// RenderSettings::sample_offset), so the value a pixel receives depends only on (seed, pixel,
// sample index), never on threads or tile order. The depth and index passes come from the
// render's first sample K (sample 0 unless the render is one part of a farm's split).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>

#include "render/film.h"
#include "scene/render_settings.h"

namespace gdpt {

class SceneContext;

// Half-open pixel rectangle [x0, x1) x [y0, y1), y = 0 at the bottom row.
struct Tile {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  // Adds samples [first_sample, first_sample + sample_count) of every pixel of `tile` to `film`
  // (accumulators and sample counts). Called concurrently for disjoint tiles.
  virtual void render_tile(const Tile& tile, uint32_t first_sample, uint32_t sample_count,
                           Film& film) const = 0;
  // True when render_tile() fills Film::GradientAccumulator::dx/dy (G-PT). Otherwise the film
  // derives the gradient passes from the primal means (Film::set_gradients_from_primal).
  virtual bool estimates_gradients() const { return false; }
  // Rays traced so far (camera, extension and shadow rays), for the benchmarks.
  uint64_t rays_traced() const { return rays_.load(std::memory_order_relaxed); }

 protected:
  void count_rays(uint64_t n) const { rays_.fetch_add(n, std::memory_order_relaxed); }

 private:
  mutable std::atomic<uint64_t> rays_{0};
};

// The unidirectional path tracer (integrators/pt/path_tracer.cpp), specialised for ctx.features().
std::unique_ptr<Integrator> make_path_tracer(const SceneContext& ctx,
                                             const RenderSettings& settings);

}  // namespace gdpt
