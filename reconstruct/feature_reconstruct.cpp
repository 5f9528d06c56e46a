#include "reconstruct/feature_reconstruct.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <string>

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include "reconstruct/candidate_selection.h"
#include "reconstruct/half_outliers.h"
#include "reconstruct/parallel.h"

namespace gdpt {

namespace {

// Relative to the centre's brightness, as the candidates' tolerances.
constexpr float kGuideColourTolerance = 1.f;
// Added to the albedo the images are divided by: keeps black surfaces finite.
constexpr float kDemodulationFloor = 0.02f;

double since(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

int gradient_halves(const ReconstructionInput& in) {
  return (in.gradient_x_a != nullptr) + (in.gradient_x_b != nullptr) +
         (in.gradient_y_a != nullptr) + (in.gradient_y_b != nullptr);
}

void validate_feature(const ReconstructionInput& in, const ReconstructionSettings& s) {
  if (in.width <= 0 || in.height <= 0)
    throw std::invalid_argument("reconstruct: image size must be positive, got " +
                                std::to_string(in.width) + "x" + std::to_string(in.height));
  if (!in.primal_a || !in.primal_b)
    throw std::invalid_argument("reconstruct: the Feature norm needs both primal halves (A and B)");
  if ((in.variance_a == nullptr) != (in.variance_b == nullptr))
    throw std::invalid_argument("reconstruct: give the variances of both halves or of neither");
  if (!(s.alpha > 0.f) || !std::isfinite(s.alpha))
    throw std::invalid_argument("reconstruct: alpha must be > 0");
  const ReconstructionNorm g = s.feature_guide;
  if (g == ReconstructionNorm::Feature)
    throw std::invalid_argument("reconstruct: the Feature guide must be l1, l2, weighted or none");
  if (g != ReconstructionNorm::None && (!in.gradient_x || !in.gradient_y))
    throw std::invalid_argument(
        "reconstruct: the Feature norm's gradient-domain guide needs gradient_x and gradient_y");
  const int halves = gradient_halves(in);
  if (halves != 0 && halves != 4)
    throw std::invalid_argument(
        "reconstruct: give all four gradient halves (x and y of A and B) or none");
}

// The images the filters run on: the two halves and the image of all samples; and the Weighted
// solutions of the same (empty unless settings.feature_weighted_candidate applies).
struct FeatureBase {
  std::vector<float> a, b, all;
  std::vector<float> weighted_a, weighted_b, weighted_all;
  const float *pa = nullptr, *pb = nullptr, *pall = nullptr;
  const float *variance_a = nullptr, *variance_b = nullptr;
  bool primal = true;
};

std::vector<float> solve(const ReconstructionInput& in, const ReconstructionSettings& s,
                         ReconstructionNorm norm, const float* initial = nullptr) {
  ReconstructionInput gi = in;
  gi.emission = nullptr;
  gi.initial = initial;
  ReconstructionSettings gs = s;
  gs.norm = norm;
  gs.compute_objective = false;
  gs.progress = nullptr;
  // The L1 guide keeps the Jacobi schedule (12 -> 3 steps): the multigrid default's 3 -> 1 steps
  // over its 12 reweightings made Feature worse (difficult_light 3-5x; docs/reconstruct.md).
  use_jacobi_l1_schedule(gs);
  gs.l1_reweightings = s.feature_guide_l1_reweightings;
  return reconstruct(gi, gs);
}

// The Weighted candidate's images: each half with the variances of all samples (the weights are
// relative: a half's variances are twice as large everywhere, which does not move the solution),
// started from the half's own solution; all samples' is their mean (the solve is linear in the
// data: a third solve cost about 0.4 s at 1920x1080 and changed the geometric mean by 0.2%).
void weighted_images(const ReconstructionInput& all, const ReconstructionSettings& s,
                     FeatureBase& base) {
  ReconstructionSettings ws = s;
  ws.max_cg_iterations = s.feature_weighted_cg_steps;
  auto half = [&](const float* primal, const float* gx, const float* gy, const float* start) {
    ReconstructionInput h = all;
    h.primal = primal, h.gradient_x = gx, h.gradient_y = gy;
    return solve(h, ws, ReconstructionNorm::Weighted, start);
  };
  base.weighted_a = half(all.primal_a, all.gradient_x_a, all.gradient_y_a, base.a.data());
  base.weighted_b = half(all.primal_b, all.gradient_x_b, all.gradient_y_b, base.b.data());
  base.weighted_all.resize(base.weighted_a.size());
  for (size_t i = 0; i < base.weighted_all.size(); ++i)
    base.weighted_all[i] = 0.5f * (base.weighted_a[i] + base.weighted_b[i]);
}

FeatureBase base_images(const ReconstructionInput& in, const ReconstructionSettings& settings) {
  // The guide's, the halves' and the Weighted candidate's solves share their CG and weight
  // buffers, released before the filters allocate theirs.
  ReconstructionSettings s = settings;
  if (!s.scratch) s.scratch = make_reconstruction_scratch();
  FeatureBase base;
  const size_t n3 = 3 * size_t(in.width) * in.height;
  std::vector<float> mean;
  if (!in.primal) {
    mean.resize(n3);
    for (size_t i = 0; i < n3; ++i) mean[i] = 0.5f * (in.primal_a[i] + in.primal_b[i]);
  }
  const float* primal = in.primal ? in.primal : mean.data();
  if (s.feature_guide == ReconstructionNorm::None || gradient_halves(in) != 4) {
    base.pa = in.primal_a;
    base.pb = in.primal_b;
    base.variance_a = in.variance_a;
    base.variance_b = in.variance_b;
    base.all = std::move(mean);
    base.pall = in.primal ? in.primal : base.all.data();
    return base;
  }
  ReconstructionInput all = in;
  all.primal = primal;
  base.all = solve(all, s, s.feature_guide);
  // Each half's solution, for the error estimates only, by the guide's norm: the filters are
  // judged on images like the one they are applied to (L2 halves judged them on images noisier
  // than an L1 guide, which favoured the Weighted candidate over filters of the guide).
  ReconstructionSettings hs = s;
  hs.feature_guide_l1_reweightings = s.feature_halves_l1_reweightings;
  ReconstructionInput half = in;
  if (s.feature_guide != ReconstructionNorm::Weighted) half.variance = nullptr;
  half.primal = in.primal_a, half.gradient_x = in.gradient_x_a, half.gradient_y = in.gradient_y_a;
  base.a = solve(half, hs, s.feature_guide);
  half.primal = in.primal_b, half.gradient_x = in.gradient_x_b, half.gradient_y = in.gradient_y_b;
  base.b = solve(half, hs, s.feature_guide);
  base.pa = base.a.data(), base.pb = base.b.data(), base.pall = base.all.data();
  base.primal = false;
  if (s.feature_weighted_candidate && in.variance &&
      s.feature_guide != ReconstructionNorm::Weighted)
    weighted_images(all, s, base);
  return base;
}

// The candidate-independent colour the relative errors are taken against: per channel the smaller
// of all samples under the widest window with a loose colour tolerance (a bright spot stays off
// its dark neighbours) and without one (a firefly is spread thin). Wide, so the weights carry
// little of the noise they weigh.
FreshHugeVector<float> relative_error_guide(const detail::FeatureBuffers& fb) {
  const size_t n3 = fb.all.size();
  FreshHugeVector<float> tolerant(n3), plain(n3);  // written in full by the filter
  const float* const all = fb.all.data();
  float* const out[2] = {tolerant.data(), plain.data()};
  const float tolerances[2] = {kGuideColourTolerance, 0.f};
  detail::bilateral_filter(fb, std::end(detail::kWindows)[-1], tolerances, 2, &all, 1, out);
  detail::parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t k = 3 * size_t(y0) * fb.width; k < 3 * size_t(y1) * fb.width; ++k)
      tolerant[k] = std::min(tolerant[k], plain[k]);
  });
  return tolerant;
}

// Per pixel and channel, the albedo the filters' images are divided by and their outputs
// multiplied by: filtering the illumination instead of the colour, textures stay sharp and the
// colour tolerances compare light, not paint. Empty without an albedo feature; 1 where a pixel has
// no valid features.
FreshHugeVector<float> demodulation(const ReconstructionInput& in,
                                    const detail::FeatureBuffers& fb) {
  if (!in.albedo) return {};
  const size_t n = size_t(fb.width) * fb.height;
  FreshHugeVector<float> d(3 * n);
  detail::parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * fb.width; i < size_t(y1) * fb.width; ++i)
      for (int c = 0; c < 3; ++c)
        d[3 * i + c] = (fb.valid[i] & detail::kFeaturesValid)
                           ? std::max(0.f, fb.feature[size_t(c) * n + i]) + kDemodulationFloor
                           : 1.f;
  });
  return d;
}

// out = image / factor (RGB, width x height).
void divide_image(const float* factor, int width, int height, const float* image, float* out) {
  detail::parallel_rows(height, [&](int y0, int y1) {
    for (size_t i = 3 * size_t(y0) * width; i < 3 * size_t(y1) * width; ++i)
      out[i] = image[i] / factor[i];
  });
}

// Per image (half A, half B, all samples): each pixel's variance summed over RGB, divided by the
// albedo squared as the images are; all samples' is (Var A + Var B) / 4. Empty without variances.
std::vector<FreshHugeVector<float>> pixel_noise(const detail::FeatureBuffers& fb,
                                                const float* variance_a, const float* variance_b,
                                                const FreshHugeVector<float>& albedo) {
  std::vector<FreshHugeVector<float>> noise;
  if (!variance_a || !variance_b) return noise;
  noise.resize(3);
  const size_t n = size_t(fb.width) * fb.height;
  for (auto& v : noise) v.resize(n);  // written in full below
  detail::parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * fb.width; i < size_t(y1) * fb.width; ++i) {
      float va = 0.f, vb = 0.f;
      for (int c = 0; c < 3; ++c) {
        const float d = albedo.empty() ? 1.f : albedo[3 * i + c];
        const float a = variance_a[3 * i + c], b = variance_b[3 * i + c];
        va += std::isfinite(a) ? std::max(0.f, a) / (d * d) : 0.f;
        vb += std::isfinite(b) ? std::max(0.f, b) / (d * d) : 0.f;
      }
      const bool valid = fb.valid[i] & detail::kImagesValid;
      noise[0][i] = valid ? va : 0.f, noise[1][i] = valid ? vb : 0.f;
      noise[2][i] = valid ? 0.25f * (va + vb) : 0.f;
    }
  });
  return noise;
}

}  // namespace

FeatureReconstruction feature_filter(const ReconstructionInput& input, const float* a,
                                     const float* b, const float* all, const float* variance_a,
                                     const float* variance_b, const IdentityCandidate* extra) {
  FeatureReconstruction r;
  auto t = std::chrono::steady_clock::now();
  const size_t n3 = 3 * size_t(input.width) * input.height;
  FreshHugeVector<float> la(n3), lb(n3), lall(n3);
  detail::parallel_rows(input.height, [&](int y0, int y1) {
    const size_t k0 = 3 * size_t(y0) * input.width, k1 = 3 * size_t(y1) * input.width;
    std::copy(a + k0, a + k1, la.begin() + k0);
    std::copy(b + k0, b + k1, lb.begin() + k0);
    std::copy(all + k0, all + k1, lall.begin() + k0);
  });
  r.limited =
      detail::limit_half_outliers(input.width, input.height, input.primal_a ? input.primal_a : a,
                                  input.primal_b ? input.primal_b : b, la.data(), lb.data(),
                                  lall.data(), input.primal_a ? input.variance_a : variance_a,
                                  input.primal_b ? input.variance_b : variance_b);
  const detail::FeatureBuffers fb = detail::prepare_feature_buffers(
      input, la.data(), lb.data(), lall.data(), variance_a, variance_b);
  FreshHugeVector<float>().swap(la), FreshHugeVector<float>().swap(lb);
  FreshHugeVector<float>().swap(lall);
  r.features = fb.features;
  r.missing = fb.missing;
  r.prepare_seconds = since(t);

  // Every candidate's image of all samples, kept for the blend (written in full by the filters).
  constexpr int kTol = detail::kColourToleranceCount;
  constexpr int kWindowed = int(std::size(detail::kWindows)) * kTol;
  FreshHugeVector<float> candidates[1 + kWindowed];
  for (auto& c : candidates) c.resize(n3);
  detail::CandidateChoice choice;
  t = std::chrono::steady_clock::now();
  detail::set_relative_weights(fb, relative_error_guide(fb).data(), choice);
  const FreshHugeVector<float> albedo = demodulation(input, fb);
  FreshHugeVector<float> illumination[3];
  const float* images[3] = {fb.a.data(), fb.b.data(), fb.all.data()};
  if (!albedo.empty()) {
    for (int k = 0; k < 3; ++k) {
      illumination[k].resize(n3);
      divide_image(albedo.data(), input.width, input.height, images[k], illumination[k].data());
      images[k] = illumination[k].data();
    }
  }
  // The filters' outputs, multiplied back by the albedo as they are written.
  const float* const remodulate = albedo.empty() ? nullptr : albedo.data();
  {  // The identity, through its filtered halves.
    FreshHugeVector<float> halves(2 * n3);
    float* const out[3] = {halves.data(), halves.data() + n3, candidates[0].data()};
    const float none = 0.f;
    detail::bilateral_filter(fb, detail::BilateralWindow{0, 1}, &none, 1, images, 3, out,
                             remodulate);
    r.filter_seconds += since(t);
    t = std::chrono::steady_clock::now();
    detail::offer_candidate(fb, 0, out[0], out[1], out[2], choice);
    r.select_seconds += since(t);
  }
  // The windows in one pass, which writes the halves' error estimates instead of the halves.
  t = std::chrono::steady_clock::now();
  const bool weighted = !choice.weight.empty();
  const size_t n = size_t(input.width) * input.height;
  FreshHugeVector<float> errors(size_t(kWindowed) * n), keys[kWindowed];
  detail::CandidateEstimates estimates[kWindowed];
  float* out[kWindowed];
  for (int c = 0; c < kWindowed; ++c) {
    if (weighted) keys[c].resize(n);
    estimates[c] = {errors.data() + size_t(c) * n, weighted ? keys[c].data() : nullptr};
    out[c] = candidates[1 + c].data();
  }
  // The primal halves' variances, also where the halves are gradient-domain solutions.
  const auto noise = pixel_noise(fb, variance_a ? variance_a : input.variance_a,
                                 variance_b ? variance_b : input.variance_b, albedo);
  const float* noise_planes[3] = {};
  for (size_t k = 0; k < noise.size(); ++k) noise_planes[k] = noise[k].data();
  detail::bilateral_candidates(fb, detail::kWindows, int(std::size(detail::kWindows)),
                               detail::kColourTolerances, kTol, images, out, estimates,
                               weighted ? choice.weight.data() : nullptr, remodulate,
                               noise.empty() ? nullptr : noise_planes);
  r.filter_seconds += since(t);
  t = std::chrono::steady_clock::now();
  for (int c = 0; c < kWindowed; ++c)
    detail::offer_estimates(fb, 1 + c, estimates[c].error, std::move(keys[c]), out[c], choice);
  FreshHugeVector<float>().swap(errors);  // released before the blend's scratch
  for (auto& image : illumination) FreshHugeVector<float>().swap(image);
  r.select_seconds += since(t);
  if (extra) {  // after the windows: their raw estimates are released, the peak stays theirs
    t = std::chrono::steady_clock::now();
    detail::offer_candidate(fb, 1 + kWindowed, extra->a, extra->b, extra->all, choice);
    r.select_seconds += since(t);
  }
  t = std::chrono::steady_clock::now();
  detail::blend_choices(fb, choice);
  r.blend_seconds = since(t);
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
  const FeatureBase base = base_images(input, settings);
  const double guide_seconds = since(start);
  progress(0.5f);

  const int threads = settings.threads > 0 ? settings.threads : tbb::info::default_concurrency();
  tbb::task_arena arena(threads);
  FeatureReconstruction fr;
  arena.execute([&] {
    const IdentityCandidate weighted{base.weighted_a.data(), base.weighted_b.data(),
                                     base.weighted_all.data()};
    fr = feature_filter(input, base.pa, base.pb, base.pall, base.variance_a, base.variance_b,
                        base.weighted_all.empty() ? nullptr : &weighted);
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
    report->feature_filtered_primal = base.primal;
    report->seconds = since(start);
  }
  return std::move(fr.image);
}

}  // namespace gdpt
