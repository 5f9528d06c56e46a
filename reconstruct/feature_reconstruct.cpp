#include "reconstruct/feature_reconstruct.h"

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include "reconstruct/candidate_selection.h"
#include "reconstruct/parallel.h"

namespace gdpt {

namespace {

double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

void validate_feature(const ReconstructionInput& in, const ReconstructionSettings& s) {
  if (in.width <= 0 || in.height <= 0)
    throw std::invalid_argument("reconstruct: image size must be positive, got " +
                                std::to_string(in.width) + "x" + std::to_string(in.height));
  if (!in.primal_a || !in.primal_b)
    throw std::invalid_argument("reconstruct: the Feature norm needs both primal halves (A and B)");
  if ((in.variance_a == nullptr) != (in.variance_b == nullptr))
    throw std::invalid_argument("reconstruct: give the variances of both halves or of neither");
  if (!(s.feature_guide_alpha > 0.f) || !std::isfinite(s.feature_guide_alpha))
    throw std::invalid_argument("reconstruct: feature_guide_alpha must be > 0");
  const ReconstructionNorm g = s.feature_guide;
  if (g == ReconstructionNorm::Feature)
    throw std::invalid_argument("reconstruct: the Feature guide must be l1, l2, weighted or none");
  if (g != ReconstructionNorm::None && (!in.gradient_x || !in.gradient_y))
    throw std::invalid_argument(
        "reconstruct: the Feature norm's gradient-domain guide needs gradient_x and gradient_y");
}

// The gradient-domain guide, from `primal` or else the halves' mean (non-finite where either is).
std::vector<float> solve_guide(const ReconstructionInput& in, const ReconstructionSettings& s) {
  std::vector<float> mean;
  ReconstructionInput gi = in;
  gi.emission = nullptr;
  if (!gi.primal) {
    mean.resize(size_t(in.width) * in.height * 3);
    for (size_t i = 0; i < mean.size(); ++i) mean[i] = 0.5f * (in.primal_a[i] + in.primal_b[i]);
    gi.primal = mean.data();
  }
  ReconstructionSettings gs = s;
  gs.norm = s.feature_guide;
  gs.alpha = s.feature_guide_alpha;
  gs.compute_objective = false;
  gs.progress = nullptr;
  return reconstruct(gi, gs);
}

}  // namespace

std::vector<detail::CandidateFilter> default_feature_candidates() {
  return {{1, 1.f}, {2, 1.f}};
}

FeatureReconstruction feature_regression(const ReconstructionInput& input, const float* guide,
                                         const std::vector<detail::CandidateFilter>& candidates) {
  if (!input.primal_a || !input.primal_b)
    throw std::invalid_argument("reconstruct: the Feature norm needs both primal halves (A and B)");
  if (candidates.empty() || candidates.size() > 127)
    throw std::invalid_argument("reconstruct: 1 to 127 candidate filters");
  FeatureReconstruction r;
  auto t = std::chrono::steady_clock::now();
  const detail::FeatureBuffers fb = detail::prepare_feature_buffers(input, guide);
  r.features = fb.count;
  r.missing = fb.missing;
  r.prepare_seconds = since(t);

  const size_t n = size_t(input.width) * input.height;
  const int variants = detail::has_guide(fb) ? 2 : 1;
  std::vector<float> fa(variants * 3 * n), fbh(variants * 3 * n);
  float* const out_a[2] = {fa.data(), fa.data() + 3 * n * (variants - 1)};
  float* const out_b[2] = {fbh.data(), fbh.data() + 3 * n * (variants - 1)};
  detail::CandidateChoice choice;
  for (size_t k = 0; k < candidates.size(); ++k) {
    t = std::chrono::steady_clock::now();
    detail::cross_filter_half(fb, fb.a.data(), fb.smooth_b.data(), fb.patch_var_b.data(),
                              candidates[k], out_a);
    detail::cross_filter_half(fb, fb.b.data(), fb.smooth_a.data(), fb.patch_var_a.data(),
                              candidates[k], out_b);
    r.filter_seconds += since(t);
    t = std::chrono::steady_clock::now();
    for (int v = 0; v < variants; ++v)
      detail::offer_candidate(fb, int(k) * variants + v, out_a[v], out_b[v], choice);
    r.select_seconds += since(t);
  }
  r.image = std::move(choice.image);
  r.error = std::move(choice.error);
  r.chosen = std::move(choice.index);
  return r;
}

std::vector<float> reconstruct_feature(const ReconstructionInput& input,
                                       const ReconstructionSettings& settings,
                                       ReconstructionReport* report) {
  const auto start = std::chrono::steady_clock::now();
  validate_feature(input, settings);
  auto progress = [&](float f) {
    if (settings.progress) settings.progress(f);
  };
  progress(0.f);
  std::vector<float> guide;
  if (settings.feature_guide != ReconstructionNorm::None) guide = solve_guide(input, settings);
  const double guide_seconds = since(start);
  progress(0.5f);

  const int threads = settings.threads > 0 ? settings.threads : tbb::info::default_concurrency();
  tbb::task_arena arena(threads);
  FeatureReconstruction fr;
  arena.execute([&] {
    fr = feature_regression(input, guide.empty() ? nullptr : guide.data());
    const int W = input.width;
    detail::parallel_rows(input.height, [&](int y0, int y1) {
      for (size_t i = 3 * size_t(y0) * W; i < 3 * size_t(y1) * W; ++i) {
        float v = fr.image[i];
        if (input.emission && std::isfinite(input.emission[i])) v += input.emission[i];
        fr.image[i] = std::isfinite(v) ? v : 0.f;
      }
    });
  });
  progress(1.f);
  if (report) {
    *report = ReconstructionReport{};
    report->missing_values = fr.missing;
    report->guide_seconds = guide_seconds;
    report->seconds = since(start);
  }
  return std::move(fr.image);
}

}  // namespace gdpt
