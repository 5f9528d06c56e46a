// Progressive render of one Scene: builds the BVH, lights and materials once, then renders
// sample passes over the whole image until the sample count, the time limit or a cancel.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/film.h"
#include "scene/render_settings.h"
#include "scene/scene.h"

namespace gdpt {

struct RenderProgress {
  int samples_done = 0;  // completed samples per pixel
  int samples_total = 0;
  double elapsed_seconds = 0.0;
};

class RenderSession {
 public:
  // Throws std::invalid_argument with a clear message for an unusable scene (e.g. zero resolution).
  RenderSession(Scene scene, RenderSettings settings);
  ~RenderSession();

  // Renders until done. `on_pass` runs on the calling thread after each completed pass; it may
  // read the film. `cancel` is polled at least every 100 ms; finished passes are kept.
  void render(const std::function<void(const RenderProgress&)>& on_pass,
              const std::atomic<bool>& cancel);

  // Replaces the camera (its resolution may differ) and clears the film, keeping the BVH, lights
  // and materials: the viewport restarts this way when only the view moved. Not during render().
  void set_camera(const Camera& camera);
  // Replaces the scene and the settings and clears the film. When the new scene's geometry is the
  // old one's (same_geometry: a lamp, a material, the world, the camera or a setting changed)
  // the BVH is kept and only textures, materials and lights are rebuilt; otherwise (or with
  // another thread count) everything is built again. Returns true when the BVH was kept. The scene
  // and settings are checked first: std::invalid_argument for unusable ones leaves the session as
  // it was. Not during render().
  bool update(Scene scene, RenderSettings settings);

  const Film& film() const;
  const RenderSettings& settings() const;
  // Human-readable list of what the scene uses (for logs and the feature benchmark).
  std::string features_summary() const;
  // Non-fatal problems found while preparing the scene (e.g. degenerate lights).
  const std::vector<std::string>& warnings() const;
  // Rays traced so far (camera, extension and shadow rays), for the benchmarks.
  uint64_t rays_traced() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gdpt
