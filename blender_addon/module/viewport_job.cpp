#include "blender_addon/module/viewport_job.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "blender_addon/module/render_job.h"
#include "integrators/render_session.h"
#include "reconstruct/reconstruct.h"

namespace gdpt::python {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// `camera` at 1/divider of its resolution (the same view: the aspect is kept up to rounding),
// its region (if any) scaled alike.
Camera reduced(const Camera& camera, int divider) {
  Camera c = camera;
  c.width = std::max(1, camera.width / divider);
  c.height = std::max(1, camera.height / divider);
  if (camera.has_region()) {
    c.region_x = std::min(camera.region_x / divider, c.width - 1);
    c.region_y = std::min(camera.region_y / divider, c.height - 1);
    c.region_width = std::clamp(camera.region_width / divider, 1, c.width - c.region_x);
    c.region_height = std::clamp(camera.region_height / divider, 1, c.height - c.region_y);
  }
  return c;
}

// The reconstruction the display asks for, if the mode estimates gradients.
std::optional<ReconstructionNorm> display_norm(const ViewportDisplay& display,
                                               const RenderSettings& settings) {
  const ReconstructionNorm norm = parse_norm(display.norm);
  if (norm != ReconstructionNorm::None && settings.mode == RenderSettings::Mode::GPT) return norm;
  return std::nullopt;
}

}  // namespace

// A scene for the worker to take up (ViewportJob::update).
struct PendingScene {
  Scene scene;
  RenderSettings settings;
  ViewportDisplay display;
};

struct ViewportJob::State {
  RenderSettings settings;
  ViewportDisplay display;
  std::optional<ReconstructionNorm> norm;  // none: show primal + emission
  Scene scene;                             // until the worker hands it to the session
  std::unique_ptr<RenderSession> session;  // the worker's only
  std::thread worker;

  std::mutex mutex;
  std::condition_variable wake;
  std::optional<Camera> pending;  // a restart asked for by set_camera (or the first start)
  std::optional<PendingScene> pending_scene;   // a scene asked for by update
  Clock::time_point requested = Clock::now();  // of the newest restart
  int bvh_builds = 0, in_place_updates = 0;
  double scene_seconds = 0.0, first_image_seconds = -1.0;
  // Of the published restart: seconds in publish (read-out and solves) and since its start, and
  // the mean fraction of failed shifts at the last solve (-1: none yet).
  double publish_seconds = 0.0, restart_seconds = 0.0, shift_failures = -1.0;
  bool stopping = false;
  bool rendering = true;
  bool finished = false;  // run() returned
  std::atomic<bool> cancel{false};
  std::string error;
  int restart = 0;  // cameras taken by the worker (the first start is 1)
  // The published image.
  int64_t version = 0;
  int image_restart = 0;  // the restart it belongs to
  int width = 0, height = 0, samples = 0;
  bool solved = false;
  double seconds = 0.0;
  std::vector<float> image;  // RGBA

  // The worker's scratch film copies, reused by every publish.
  std::vector<float> primal, gradient_x, gradient_y, emission, alpha, rgb, rgba, failures;

  void run();
  void work();
  void render_view(const Camera& camera);
  void take_scene(PendingScene next, const Camera& camera);
  void set_display(const ViewportDisplay& d);
  void publish(int samples_done, bool solve, Clock::time_point start);
  bool restart_pending() {
    std::lock_guard lock(mutex);
    return pending.has_value() || stopping;
  }
};

void ViewportJob::State::run() {
  work();
  std::lock_guard lock(mutex);
  finished = true;
  rendering = false;
}

void ViewportJob::State::set_display(const ViewportDisplay& d) {
  display = d;
  display.start_divider = std::max(1, d.start_divider);
  norm = display_norm(display, settings);
}

void ViewportJob::State::take_scene(PendingScene next, const Camera& camera) {
  const auto t = Clock::now();
  // The session's films are set up for the first pass's camera, not the full view.
  next.scene.camera = reduced(camera, std::max(1, next.display.start_divider));
  next.settings.time_limit = 0.0;
  const bool kept = session->update(std::move(next.scene), next.settings);
  settings = next.settings;
  set_display(next.display);
  std::lock_guard lock(mutex);
  ++(kept ? in_place_updates : bvh_builds);
  scene_seconds = seconds_since(t);
}

void ViewportJob::State::work() {
  try {
    const auto t = Clock::now();
    scene.camera = reduced(scene.camera, display.start_divider);  // the first pass's films
    session = std::make_unique<RenderSession>(std::move(scene), settings);
    std::lock_guard lock(mutex);
    ++bvh_builds;
    scene_seconds = seconds_since(t);
  } catch (const std::exception& e) {
    std::lock_guard lock(mutex);
    error = e.what();
    rendering = false;
    return;
  }
  for (;;) {
    Camera camera;
    std::optional<PendingScene> next;
    {
      std::unique_lock lock(mutex);
      wake.wait(lock, [&] { return stopping || pending.has_value(); });
      if (stopping) return;
      camera = *pending;
      pending.reset();
      next.swap(pending_scene);
      ++restart;
      cancel.store(false);
      rendering = true;
    }
    try {
      if (next) take_scene(std::move(*next), camera);
      render_view(camera);
    } catch (const std::exception& e) {
      std::lock_guard lock(mutex);
      error = e.what();
    }
    std::lock_guard lock(mutex);
    rendering = pending.has_value();
  }
}

void ViewportJob::State::render_view(const Camera& camera) {
  const auto start = Clock::now();
  // One pass at 1/divider of the resolution, then at twice that, ..., then the full view (as
  // Cycles' start resolution): on_pass cancels the rest of each. Their images are primals: a solve
  // at other sizes would plan FFTs and map solver buffers for them on every restart, for 1-sample
  // previews that a reconstruction barely improves.
  for (int divider = display.start_divider; divider > 1; divider /= 2) {
    session->set_camera(reduced(camera, divider));
    session->render(
        [&](const RenderProgress& p) {
          publish(p.samples_done, false, start);
          cancel.store(true);
        },
        cancel);
    std::lock_guard lock(mutex);
    if (pending || stopping) return;
    cancel.store(false);
  }
  session->set_camera(camera);
  const int total = settings.samples;
  double solve_cost = 0.0;
  auto last_solve = start;
  bool first = true;
  session->render(
      [&](const RenderProgress& p) {
        const bool due = seconds_since(last_solve) * display.max_solve_share >= solve_cost;
        if (!(first || p.samples_done >= total || due || !norm)) return;
        const auto t = Clock::now();
        publish(p.samples_done, true, start);
        last_solve = Clock::now();
        solve_cost = std::chrono::duration<double>(last_solve - t).count();
        first = false;
      },
      cancel);
}

void ViewportJob::State::publish(int samples_done, bool solve, Clock::time_point start) {
  const auto t = Clock::now();
  const Film& film = session->film();
  const size_t n = film.pixel_count();
  primal.resize(3 * n);
  emission.resize(3 * n);
  alpha.resize(n);
  film.primal_rgb(primal.data());
  film.emission_rgb(emission.data());
  film.alpha(alpha.data());
  const bool solved_now = solve && norm.has_value();
  double failure_rate = -1.0;
  if (solved_now) {
    gradient_x.resize(3 * n);
    gradient_y.resize(3 * n);
    film.gradient_x_rgb(gradient_x.data());
    film.gradient_y_rgb(gradient_y.data());
    ReconstructionInput input;
    input.width = film.width();
    input.height = film.height();
    input.primal = primal.data();
    input.gradient_x = gradient_x.data();
    input.gradient_y = gradient_y.data();
    input.emission = emission.data();
    ReconstructionSettings rs;
    rs.norm = *norm;
    rs.alpha = display.alpha;
    rs.threads = settings.threads;
    rgb = reconstruct(input, rs);
    failures.resize(n);
    film.shift_failures(failures.data());
    double sum = 0.0;
    for (float f : failures) sum += f;
    failure_rate = n ? sum / double(n) : 0.0;
  } else {
    rgb.resize(3 * n);
    for (size_t i = 0; i < 3 * n; ++i) rgb[i] = primal[i] + emission[i];
  }
  rgba.resize(4 * n);
  for (size_t i = 0; i < n; ++i) {
    std::memcpy(&rgba[4 * i], &rgb[3 * i], 3 * sizeof(float));
    rgba[4 * i + 3] = alpha[i];
  }
  std::lock_guard lock(mutex);
  std::swap(image, rgba);
  width = film.width();
  height = film.height();
  samples = samples_done;
  if (image_restart != restart) {
    first_image_seconds = seconds_since(requested);
    publish_seconds = 0.0;
    shift_failures = -1.0;
  }
  publish_seconds += seconds_since(t);
  restart_seconds = seconds_since(start);
  if (failure_rate >= 0.0) shift_failures = failure_rate;
  image_restart = restart;
  solved = solved_now;
  seconds = seconds_since(start);
  ++version;
}

ViewportJob::ViewportJob(SceneBuilder& builder, const RenderSettings& settings,
                         const ViewportDisplay& display)
    : state_(std::make_unique<State>()) {
  State& st = *state_;
  st.settings = settings;
  st.settings.time_limit = 0.0;
  st.set_display(display);
  st.scene = builder.take();
  st.pending = st.scene.camera;
  st.worker = std::thread([&st] { st.run(); });
}

ViewportJob::~ViewportJob() {
  stop();
}

void ViewportJob::set_camera(const py::dict& camera) {
  SceneBuilder b;
  b.set_camera(camera);  // validates the dict's layout
  std::lock_guard lock(state_->mutex);
  state_->pending = b.scene().camera;
  state_->requested = Clock::now();
  state_->rendering = true;
  state_->cancel.store(true);
  state_->wake.notify_all();
}

void ViewportJob::update(SceneBuilder& builder, const RenderSettings& settings,
                         const ViewportDisplay& display) {
  parse_norm(display.norm);  // a bad name fails here, not on the worker
  PendingScene next{builder.take(), settings, display};
  State& st = *state_;
  std::lock_guard lock(st.mutex);
  st.pending = next.scene.camera;
  st.pending_scene = std::move(next);
  st.requested = Clock::now();
  st.rendering = true;
  st.cancel.store(true);
  st.wake.notify_all();
}

py::object ViewportJob::latest(int64_t seen) {
  State& st = *state_;
  std::lock_guard lock(st.mutex);
  if (st.version <= seen || st.image.empty()) return py::none();
  py::array_t<float> image({py::ssize_t(st.height), py::ssize_t(st.width), py::ssize_t(4)});
  std::memcpy(image.mutable_data(), st.image.data(), st.image.size() * sizeof(float));
  py::dict d;
  d["version"] = st.version;
  d["width"] = st.width;
  d["height"] = st.height;
  d["samples"] = st.samples;
  d["restart"] = st.image_restart;
  d["solved"] = st.solved;
  d["seconds"] = st.seconds;
  d["image"] = std::move(image);
  return d;
}

py::dict ViewportJob::status() {
  State& st = *state_;
  std::lock_guard lock(st.mutex);
  py::dict d;
  d["version"] = st.version;
  d["samples"] = st.samples;
  d["rendering"] = st.rendering && st.error.empty();
  d["finished"] = st.finished;
  d["error"] = st.error;
  d["bvh_builds"] = st.bvh_builds;
  d["in_place_updates"] = st.in_place_updates;
  d["scene_seconds"] = st.scene_seconds;
  d["first_image_seconds"] = st.first_image_seconds;
  d["publish_seconds"] = st.publish_seconds;
  d["restart_seconds"] = st.restart_seconds;
  d["shift_failures"] = st.shift_failures;
  return d;
}

void ViewportJob::cancel() {
  State& st = *state_;
  std::lock_guard lock(st.mutex);
  st.stopping = true;
  st.cancel.store(true);
  st.wake.notify_all();
}

void ViewportJob::stop() {
  State& st = *state_;
  cancel();
  if (st.worker.joinable()) {
    py::gil_scoped_release no_gil;
    st.worker.join();
  }
}

}  // namespace gdpt::python
