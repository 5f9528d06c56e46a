#include "blender_addon/module/render_job.h"

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "reconstruct/reconstruct.h"

namespace gdpt::python {

namespace {

// An image's numpy shape: (height, width) for one channel, else (height, width, channels).
std::vector<py::ssize_t> image_shape(int height, int width, int channels) {
  std::vector<py::ssize_t> shape{height, width};
  if (channels > 1) shape.push_back(channels);
  return shape;
}

// A numpy array that owns a moved-in vector (no second copy).
template <typename Vector>
py::array_t<float> to_numpy(Vector&& v, int height, int width, int channels) {
  auto* owner = new Vector(std::move(v));
  py::capsule free_owner(owner, [](void* p) { delete static_cast<Vector*>(p); });
  return py::array_t<float>(image_shape(height, width, channels), owner->data(), free_owner);
}

// A numpy view of a vector that `owner` keeps alive.
py::array_t<float> view_numpy(const HugePageVector<float>& v, int height, int width, int channels,
                              const py::handle& owner) {
  return py::array_t<float>(image_shape(height, width, channels), v.data(), owner);
}

// Film keys of FilmPasses::feature, in Film::FeaturePass order.
const char* const kFeatureKeys[FilmPasses::kFeatureCount] = {
    "primal_a", "primal_b", "denoising_albedo", "denoising_normal", "denoising_depth"};
const char* const kFeatureVarianceKeys[FilmPasses::kFeatureCount] = {
    "primal_a_variance", "primal_b_variance", "denoising_albedo_variance",
    "denoising_normal_variance", "denoising_depth_variance"};

// Film keys of FilmPasses::half_gradient, and the Film read-out of each.
const char* const kHalfGradientKeys[FilmPasses::kHalfGradientCount] = {
    "gradient_x_a", "gradient_x_b", "gradient_y_a", "gradient_y_b"};

void read_half_gradient(const Film& film, int k, float* out) {
  const Film::SampleHalf half = k % 2 ? Film::SampleHalf::B : Film::SampleHalf::A;
  k < 2 ? film.gradient_x_half_rgb(half, out) : film.gradient_y_half_rgb(half, out);
}

int feature_channels(int k) {
  return Film::feature_channels(Film::FeaturePass(k));
}

// Every pass with its channel count; normal, mist and the feature passes only when the render
// computes them.
template <typename Passes, typename Add>
void for_each_pass(Passes& p, Add&& add) {
  add("primal", p.primal, 3);
  add("gradient_x", p.gradient_x, 3);
  add("gradient_y", p.gradient_y, 3);
  add("emission", p.emission, 3);
  add("variance", p.variance, 3);
  add("shift_failures", p.shift_failures, 1);
  add("sample_count", p.sample_count, 1);
  add("shift_attempts", p.shift_attempts, 1);
  add("gradient_halves", p.gradient_halves, 4);
  add("alpha", p.alpha, 1);
  add("depth", p.depth, 1);
  add("object_index", p.object_index, 1);
  add("material_index", p.material_index, 1);
  if (!p.normal.empty()) add("normal", p.normal, 3);
  if (!p.mist.empty()) add("mist", p.mist, 1);
  for (int k = 0; k < FilmPasses::kFeatureCount; ++k)
    if (!p.feature[k].empty()) {
      add(kFeatureKeys[k], p.feature[k], feature_channels(k));
      add(kFeatureVarianceKeys[k], p.feature_variance[k], feature_channels(k));
    }
  for (int k = 0; k < FilmPasses::kHalfGradientCount; ++k)
    if (!p.half_gradient[k].empty()) add(kHalfGradientKeys[k], p.half_gradient[k], 3);
}

// The dict's size and sample count, before the passes.
py::dict film_dict(const FilmPasses& p) {
  py::dict d;
  d["width"] = p.width;
  d["height"] = p.height;
  d["samples"] = p.samples_done;
  d["half_split"] = p.half_split;
  return d;
}

}  // namespace

void FilmPasses::read(const Film& film, int samples) {
  width = film.width();
  height = film.height();
  samples_done = samples;
  half_split = film.half_split();
  const size_t n = film.pixel_count();
  primal.resize(n * 3);
  gradient_x.resize(n * 3);
  gradient_y.resize(n * 3);
  emission.resize(n * 3);
  variance.resize(n * 3);
  shift_failures.resize(n);
  sample_count.resize(n);
  film.sample_count(sample_count.data());
  shift_attempts.resize(n);
  film.shift_attempts(shift_attempts.data());
  gradient_halves.resize(4 * n);
  film.gradient_halves(gradient_halves.data());
  alpha.resize(n);
  film.alpha(alpha.data());
  depth.resize(n);
  film.depth(depth.data());
  object_index.resize(n);
  film.object_index(object_index.data());
  material_index.resize(n);
  film.material_index(material_index.data());
  normal.resize(film.has_normal() ? n * 3 : 0);
  if (film.has_normal()) film.normal(normal.data());
  mist.resize(film.has_mist() ? n : 0);
  if (film.has_mist()) film.mist(mist.data());
  for (int k = 0; k < kFeatureCount; ++k) {
    const size_t size = film.has_features() ? n * size_t(feature_channels(k)) : 0;
    feature[k].resize(size);
    feature_variance[k].resize(size);
    if (size == 0) continue;
    film.feature(Film::FeaturePass(k), feature[k].data());
    film.feature_variance(Film::FeaturePass(k), feature_variance[k].data());
  }
  for (int k = 0; k < kHalfGradientCount; ++k) {
    half_gradient[k].resize(film.has_half_gradients() ? n * 3 : 0);
    if (film.has_half_gradients()) read_half_gradient(film, k, half_gradient[k].data());
  }
  film.primal_rgb(primal.data());
  film.gradient_x_rgb(gradient_x.data());
  film.gradient_y_rgb(gradient_y.data());
  film.emission_rgb(emission.data());
  film.variance3(variance.data());
  film.shift_failures(shift_failures.data());
}

py::dict FilmPasses::to_python_owning() {
  py::dict d = film_dict(*this);
  for_each_pass(*this, [&](const char* key, HugePageVector<float>& v, int channels) {
    d[key] = to_numpy(std::move(v), height, width, channels);
  });
  return d;
}

py::dict FilmPasses::to_python_views(const py::handle& owner) const {
  py::dict d = film_dict(*this);
  for_each_pass(*this, [&](const char* key, const HugePageVector<float>& v, int channels) {
    d[key] = view_numpy(v, height, width, channels, owner);
  });
  return d;
}

// Shared between the worker (on_pass) and the Python thread (poll loop).
struct RenderJob::State {
  std::mutex mutex;
  std::condition_variable wake;
  RenderProgress progress;
  bool finished = false;  // the worker returned
  bool want_snapshot = false;
  bool snapshot_ready = false;
  bool snapshot_news = false;  // a snapshot was taken since the poll loop last woke
  FilmPasses snapshot;
  std::atomic<bool> cancel{false};
  std::exception_ptr error;
};

RenderJob::RenderJob(SceneBuilder& builder, const RenderSettings& settings)
    : session_(std::make_unique<RenderSession>(builder.take(), settings)),
      state_(std::make_unique<State>()) {}

RenderJob::~RenderJob() = default;

void RenderJob::render(const py::function& poll, double poll_interval) {
  State& st = *state_;
  st.progress.samples_total = session_->settings().samples;

  auto on_pass = [this, &st](const RenderProgress& p) {
    std::lock_guard lock(st.mutex);
    st.progress = p;
    if (st.want_snapshot) {
      // The film is only consistent between passes: copy it now (a few memcpy-sized loops).
      st.snapshot.read(session_->film(), p.samples_done);
      st.want_snapshot = false;
      st.snapshot_ready = true;
      st.snapshot_news = true;
      st.wake.notify_all();
    }
  };

  std::thread worker;
  {
    py::gil_scoped_release no_gil;
    worker = std::thread([this, &st, on_pass] {
      try {
        session_->render(on_pass, st.cancel);
      } catch (...) {
        std::lock_guard lock(st.mutex);
        st.error = std::current_exception();
      }
      std::lock_guard lock(st.mutex);
      st.finished = true;
      st.wake.notify_all();
    });
  }

  const auto interval = std::chrono::duration<double>(std::max(poll_interval, 0.01));
  std::exception_ptr poll_error;
  for (;;) {
    RenderProgress progress;
    bool finished = false, ready = false;
    {
      py::gil_scoped_release no_gil;
      std::unique_lock lock(st.mutex);
      // Woken by the interval, a snapshot or the end, not by every pass: with small passes
      // (1 spp of a small frame takes milliseconds) a wake-up per pass ran the Python callback
      // hundreds of times per second, on one of the cores the render threads use.
      st.wake.wait_for(lock, interval, [&] { return st.finished || st.snapshot_news; });
      st.snapshot_news = false;
      progress = st.progress;
      finished = st.finished;
      ready = st.snapshot_ready;
    }
    if (finished) break;
    if (st.cancel.load()) continue;  // already cancelled: just wait for the worker
    int flags = 0;
    try {
      flags = poll(progress.samples_done, progress.samples_total, progress.elapsed_seconds, ready)
                  .cast<int>();
    } catch (...) {
      poll_error = std::current_exception();
      flags = 1;
    }
    if (flags & 1) st.cancel.store(true);
    if (flags & 2) {
      std::lock_guard lock(st.mutex);
      st.want_snapshot = true;
      st.snapshot_ready = false;
    }
  }
  {
    py::gil_scoped_release no_gil;
    worker.join();
  }
  if (st.error) std::rethrow_exception(st.error);
  if (poll_error) std::rethrow_exception(poll_error);
}

py::dict RenderJob::snapshot(const py::handle& self) {
  {
    std::lock_guard lock(state_->mutex);
    if (!state_->snapshot_ready) throw std::runtime_error("no snapshot has been taken");
    state_->snapshot_ready = false;
    // The worker reads the next snapshot into the buffers the previous views used.
    std::swap(shown_, state_->snapshot);
  }
  return shown_.to_python_views(self);
}

py::dict RenderJob::passes() {
  FilmPasses p;
  {
    py::gil_scoped_release no_gil;
    // The samples the render reached: every pixel's, or with adaptive sampling the most any
    // pixel took (its Sample Count pass has each pixel's).
    p.read(session_->film(), int(session_->film().max_samples()));
  }
  return p.to_python_owning();
}

uint64_t RenderJob::rays_traced() const {
  return session_->rays_traced();
}

std::string RenderJob::features_summary() const {
  return session_->features_summary();
}

py::list RenderJob::warnings() const {
  py::list out;
  for (const std::string& w : session_->warnings()) out.append(w);
  return out;
}

ReconstructionNorm parse_norm(const std::string& norm) {
  if (norm == "L1") return ReconstructionNorm::L1;
  if (norm == "L2") return ReconstructionNorm::L2;
  if (norm == "WEIGHTED") return ReconstructionNorm::Weighted;
  if (norm == "NONE") return ReconstructionNorm::None;
  if (norm == "FEATURE") return ReconstructionNorm::Feature;
  throw std::invalid_argument("unknown reconstruction norm '" + norm + "'");
}

py::array_t<float> reconstruct_arrays(
    const FloatArray& primal, const FloatArray& gradient_x, const FloatArray& gradient_y,
    const std::optional<FloatArray>& variance, const std::optional<FloatArray>& emission,
    const std::string& norm, float alpha, int threads, const std::optional<py::dict>& features,
    const std::optional<FloatArray>& progress, const std::optional<FloatArray>& initial) {
  if (primal.ndim() < 2) throw std::invalid_argument("primal: expected a (height, width, 3) array");
  const int height = int(primal.shape(0)), width = int(primal.shape(1));
  const size_t rgb = size_t(width) * size_t(height) * 3;
  for (const FloatArray* a : {&primal, &gradient_x, &gradient_y})
    if (size_t(a->size()) != rgb) throw std::invalid_argument("passes differ in size");
  if (variance && size_t(variance->size()) != rgb)
    throw std::invalid_argument("variance: expected 3 values per pixel");
  if (emission && size_t(emission->size()) != rgb)
    throw std::invalid_argument("emission: expected 3 values per pixel");
  if (initial && size_t(initial->size()) != rgb)
    throw std::invalid_argument("initial: expected 3 values per pixel (a previous result)");

  ReconstructionSettings settings;
  settings.norm = parse_norm(norm);
  settings.alpha = alpha;
  settings.threads = threads;
  if (progress) {
    if (progress->size() < 1) throw std::invalid_argument("progress: expected at least 1 value");
    // Written from the solving thread without the GIL: one float that the caller polls.
    float* slot = const_cast<float*>(progress->data());
    settings.progress = [slot](float f) { *static_cast<volatile float*>(slot) = f; };
  }

  ReconstructionInput input;
  input.width = width;
  input.height = height;
  input.primal = primal.data();
  input.gradient_x = gradient_x.data();
  input.gradient_y = gradient_y.data();
  input.variance = variance ? variance->data() : nullptr;
  input.emission = emission ? emission->data() : nullptr;
  input.initial = initial ? initial->data() : nullptr;
  // Feature: the arrays stay alive in `features` (the caller's dict) during the solve.
  std::vector<FloatArray> held;
  if (settings.norm == ReconstructionNorm::Feature) {
    if (!features)
      throw std::invalid_argument(
          "FEATURE reconstruction needs the feature passes (render with "
          "the Feature reconstruction)");
    auto pass = [&](const char* key, int channels) -> const float* {
      if (!features->contains(key))
        throw std::invalid_argument(std::string("FEATURE reconstruction: missing pass ") + key);
      held.push_back(py::cast<FloatArray>((*features)[key]));
      if (size_t(held.back().size()) != rgb / 3 * size_t(channels))
        throw std::invalid_argument(std::string(key) + ": wrong size");
      return held.back().data();
    };
    held.reserve(2 * FilmPasses::kFeatureCount + FilmPasses::kHalfGradientCount);
    const float** inputs[FilmPasses::kFeatureCount] = {&input.primal_a, &input.primal_b,
                                                       &input.albedo, &input.normal, &input.depth};
    const float** variances[FilmPasses::kFeatureCount] = {
        &input.variance_a, &input.variance_b, &input.albedo_variance, &input.normal_variance,
        &input.depth_variance};
    for (int k = 0; k < FilmPasses::kFeatureCount; ++k) {
      *inputs[k] = pass(kFeatureKeys[k], feature_channels(k));
      *variances[k] = pass(kFeatureVarianceKeys[k], feature_channels(k));
    }
    // G-PT's gradients over the halves: optional, all four or none.
    int present = 0;
    std::string missing;
    for (const char* key : kHalfGradientKeys)
      if (features->contains(key))
        ++present;
      else
        missing += std::string(missing.empty() ? "" : ", ") + key;
    if (present > 0 && present < FilmPasses::kHalfGradientCount)
      throw std::invalid_argument(
          "FEATURE reconstruction: the gradients over the sample halves (gradient_x_a, "
          "gradient_x_b, gradient_y_a, gradient_y_b) go together; missing " +
          missing);
    const float** halves[FilmPasses::kHalfGradientCount] = {
        &input.gradient_x_a, &input.gradient_x_b, &input.gradient_y_a, &input.gradient_y_b};
    if (present > 0)
      for (int k = 0; k < FilmPasses::kHalfGradientCount; ++k)
        *halves[k] = pass(kHalfGradientKeys[k], 3);
  }

  std::vector<float> image;
  {
    py::gil_scoped_release no_gil;
    image = reconstruct(input, settings);
  }
  return to_numpy(std::move(image), height, width, 3);
}

}  // namespace gdpt::python
