// The progressive render behind the 3D viewport's Rendered mode.
//
// Blender's view_update / view_draw run on its main thread and must never wait on a render or a
// solve, so everything here runs on one worker thread of this job: the BVH build, the passes
// (on the core's own threads), and after a pass the display image (the primal, or a
// reconstruction from the gradients), which is published under a lock. The draw callback takes
// the newest image with latest(); a view change (set_camera) cancels the pass in flight and
// restarts on the same BVH; stop() (and the destructor) cancel and join.
//
// Start resolution: with a divider d > 1 each restart first renders one pass at 1/d of the
// resolution, so an image appears after a fraction of a full pass.
//
// A changed scene (update) goes to the same worker and session: RenderSession::update keeps the
// BVH when only lamps, materials, the world, the camera or settings changed, and builds it again
// otherwise; status() counts both, so tests can tell what a change cost.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>

#include "blender_addon/module/scene_convert.h"
#include "scene/render_settings.h"

namespace gdpt::python {

// How the viewport turns the film into the image it shows.
struct ViewportDisplay {
  std::string norm = "L2";  // reconstruction norm (reconstruct_arrays' names); "NONE" = primal
  float alpha = 0.2f;       // reconstruction alpha
  int start_divider = 1;    // the first pass of a restart at 1/divider of the resolution
  // A solve runs when its cost is at most this share of the time since the last one (and always
  // after the first and the last pass), so it never takes over the render.
  double max_solve_share = 0.25;
};

class ViewportJob {
 public:
  // Takes the builder's scene; `settings.samples` is the viewport's sample count. The worker
  // starts at once (BVH build, then passes); errors are kept for status().
  ViewportJob(SceneBuilder& builder, const RenderSettings& settings,
              const ViewportDisplay& display);
  ~ViewportJob();

  // Restarts the render for this camera dict (scene_convert.h's layout). Returns at once.
  void set_camera(const py::dict& camera);
  // Restarts the render with the builder's scene (its camera included), these settings and this
  // display. Returns at once; the worker updates the session in place or rebuilds it.
  void update(SceneBuilder& builder, const RenderSettings& settings,
              const ViewportDisplay& display);
  // The newest image if its version is above `seen`, else None: {version, width, height,
  // samples, solved (a reconstruction, not the primal), seconds (from the restart), image
  // float32 (height, width, 4), rows bottom-up, alpha from the film, restart (1 for the first
  // camera, +1 for each set_camera the worker took up)}.
  py::object latest(int64_t seen);
  // {version, samples, rendering (passes still to come), finished (the worker has returned),
  // error ("" or the message), bvh_builds (sessions built: the first, and updates that changed
  // the geometry), in_place_updates (updates that kept the BVH), scene_seconds (the last build or
  // update of the scene), first_image_seconds (from the last update or set_camera call to its
  // first published image; -1 before it)}.
  py::dict status();
  // Asks the worker to end and returns at once (a solve in flight is not interrupted): the viewport
  // retires a job this way and drops it once finished, so Blender's thread never waits on it.
  void cancel();
  void stop();  // cancels and joins; idempotent

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace gdpt::python
