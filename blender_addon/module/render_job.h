// A render session driven from Blender's Python thread.
//
// Blender's RenderEngine API (test_break, update_result, update_stats) must be called from the
// thread that runs render(). The core's RenderSession::render() blocks, so it runs on a worker
// thread while the calling thread waits with the GIL released and wakes every `poll_interval`
// seconds (and when a requested snapshot is ready) to call the Python `poll` callback with the GIL
// held; it does not wake per pass, which at small frames would run Python every few milliseconds.
// That keeps Esc responsive (within poll_interval, not one pass) and keeps every Blender call on
// Blender's thread.
//
// Snapshots: the film may only be read between passes, so the worker copies the passes into a
// snapshot inside its on_pass callback when the Python side has asked for one.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>

#include "blender_addon/module/scene_convert.h"
#include "core/huge_pages.h"
#include "integrators/render_session.h"
#include "reconstruct/reconstruct.h"

namespace gdpt::python {

// The film passes as float32 images, row 0 at the bottom, interleaved. In huge pages
// (core/huge_pages.h): at 1920x1080 they are 166 MB, which in fresh 4 KB pages cost the
// benchmark VM 0.4-0.7 s of page faults per read.
struct FilmPasses {
  int width = 0, height = 0, samples_done = 0;
  uint32_t half_split = 0;  // Film::half_split (0 without the feature passes)
  HugePageVector<float> primal, gradient_x, gradient_y, emission, variance, shift_failures, alpha,
      depth, object_index, material_index;
  // What merging renders of disjoint sample ranges needs (Film::sample_count, shift_attempts,
  // gradient_halves: 1, 1 and 4 per pixel).
  HugePageVector<float> sample_count, shift_attempts, gradient_halves;
  HugePageVector<float> normal, mist;  // empty unless the render computes them
  // The feature passes (RenderSettings::feature_passes), empty without them: the primal halves,
  // Denoising Albedo / Normal / Depth, and each one's variance of its pixel mean.
  static constexpr int kFeatureCount = 5;
  HugePageVector<float> feature[kFeatureCount], feature_variance[kFeatureCount];
  // G-PT's gradients over the primal's halves (Film::gradient_x_half_rgb): X A, X B, Y A, Y B;
  // empty unless the film keeps them (feature passes in G-PT mode).
  static constexpr int kHalfGradientCount = 4;
  HugePageVector<float> half_gradient[kHalfGradientCount];
  void read(const Film& film, int samples);
  // numpy arrays that take the vectors over (this object is left empty).
  py::dict to_python_owning();
  // numpy views of the vectors, which keep `owner` alive; valid while this object keeps them.
  py::dict to_python_views(const py::handle& owner) const;
};

class RenderJob {
 public:
  RenderJob(SceneBuilder& builder, const RenderSettings& settings);
  ~RenderJob();

  // Runs the render. poll(samples_done, samples_total, elapsed_seconds, snapshot_ready) returns a
  // bitmask: 1 = cancel, 2 = take a snapshot after the next pass. Exceptions from the core or from
  // poll cancel the render and propagate.
  void render(const py::function& poll, double poll_interval);
  // The last snapshot taken (after poll saw snapshot_ready), as views into this job's memory that
  // the next snapshot() overwrites: copy what must outlive it. `self` is this job's Python object,
  // which the views keep alive. Two buffers take turns, so snapshots after the first two allocate
  // nothing (a preview at 1920x1080 cost 0.7 s of fresh-page faults on the benchmark VM).
  py::dict snapshot(const py::handle& self);
  py::dict passes();  // the film after render() returned, in arrays of its own
  std::string features_summary() const;
  uint64_t rays_traced() const;  // camera, extension and shadow rays so far
  py::list warnings() const;

 private:
  struct State;
  std::unique_ptr<RenderSession> session_;
  std::unique_ptr<State> state_;
  FilmPasses shown_;  // the snapshot Python's views see (snapshot())
};

// A reconstruction norm from its name in the add-on: L1, L2, WEIGHTED, FEATURE or NONE (else
// std::invalid_argument).
ReconstructionNorm parse_norm(const std::string& norm);

// Reconstruction of numpy passes (the same code as the CLI and the engine). FEATURE reads the
// feature passes from `features`, a dict with the film keys of FilmPasses (primal_a, primal_b,
// denoising_albedo, ... and their *_variance), and G-PT's gradients over the halves when it
// holds gradient_x_a, gradient_x_b, gradient_y_a and gradient_y_b (all four or none). `progress`
// (optional, float32): its first value follows the solved fraction, written without the GIL, for
// Python code polling a solve that runs in another thread. `initial` (optional): a previous L1
// result of reconstruct_arrays for the same passes, which L1 warm-starts from
// (ReconstructionInput::initial).
py::array_t<float> reconstruct_arrays(
    const FloatArray& primal, const FloatArray& gradient_x, const FloatArray& gradient_y,
    const std::optional<FloatArray>& variance, const std::optional<FloatArray>& emission,
    const std::string& norm, float alpha, int threads, const std::optional<py::dict>& features,
    const std::optional<FloatArray>& progress, const std::optional<FloatArray>& initial);

}  // namespace gdpt::python
