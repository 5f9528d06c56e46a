// The render target: every buffer the passes and the reconstruction need, accumulated in double.
// Pixel (x, y) has y = 0 at the BOTTOM row (Blender's convention). Gradients are forward
// differences in those rows: dx(x, y) ~ I(x+1, y) - I(x, y), dy(x, y) ~ I(x, y+1) - I(x, y).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/huge_pages.h"
#include "core/sample_halves.h"
#include "core/vec.h"

namespace gdpt {

// A sample's alpha when its camera path ends uncovered (in a transparent background, or on a
// holdout) with `throughput` left after the transparent surfaces it crossed: what they took.
inline float uncovered_alpha(Spectrum throughput) {
  return 1.0f - std::clamp((throughput.x + throughput.y + throughput.z) / 3.0f, 0.0f, 1.0f);
}

class Film {
 public:
  Film() = default;
  // `gradients_from_primal`: as set_gradients_from_primal(), decided at construction so that a PT
  // film never allocates (and zeroes) the gradient accumulators it would drop: 2 x 300 MB at
  // 1920x1080.
  Film(int width, int height, bool gradients_from_primal = false);

  int width() const { return width_; }
  int height() const { return height_; }
  size_t pixel_count() const { return size_t(width_) * size_t(height_); }

  // Float32 images for passes, interleaved, row 0 at the bottom. Means over the samples done.
  // Gradients: dx(x) = mean dx(x) - mean dx_left(x + 1) (likewise dy), the variance of dx the sum
  // of the two independent halves' variances of the mean.
  void primal_rgb(float* out) const;      // 3 per pixel, without camera-visible emission
  void gradient_x_rgb(float* out) const;  // 3 per pixel
  void gradient_y_rgb(float* out) const;  // 3 per pixel
  void emission_rgb(float* out) const;    // 3 per pixel: camera-visible emission (never shifted)
  // 3 per pixel: variance of the pixel mean of luminance(primal), luminance(dx), luminance(dy).
  void variance3(float* out) const;
  void shift_failures(float* out) const;  // 1 per pixel: fraction of failed shifts
  // What merging renders of disjoint sample ranges needs besides (reconstruct/pass_merge.h), 1
  // per pixel: the samples taken; the shift attempts per sample (Shift Failures' weight; 0 in PT
  // mode).
  void sample_count(float* out) const;
  void shift_attempts(float* out) const;
  // 4 per pixel (0 in PT mode): the luminance means of this pixel's forward gradient halves
  // G_right and G_up and the variances of those means, which Variance's dx and dy entries sum
  // with the neighbours' backward halves: the merge needs the halves apart to pool them exactly.
  void gradient_halves(float* out) const;
  // 1 per pixel: coverage, the mean of the samples' alphas (1 unless the background is
  // transparent: then 0 for a camera ray that reaches the world, 1 - the transparency crossed on
  // the way for one that reaches it through Transparent surfaces).
  void alpha(float* out) const;
  // 1 per pixel, as Cycles fills these passes from the camera ray of the pixel's sample 0: Depth
  // (Z), the view-axis distance of its first hit, 1e10 where it saw no surface; the object's and
  // the material's pass index there (IndexOB, IndexMA), 0 where it saw no surface.
  void depth(float* out) const;
  void object_index(float* out) const;
  void material_index(float* out) const;
  // Normal and Mist passes (enable_data_passes): 3 / 1 per pixel, Cycles' definitions
  // (integrators/common/data_passes.h): the mean over samples of the normal at the first opaque
  // surface (0 without one), and 1 - the mean of the samples' (1 - mist) x surface coverage.
  void normal(float* out) const;
  void mist(float* out) const;
  // Feature passes (enable_feature_passes; integrators/common/feature_passes.h), means over the
  // samples and the variances of those means (unbiased, 0 below two samples), per channel:
  // the primal's halves over the even (A) and odd (B) sample indices, 3 per pixel (their
  // sample-weighted mean is primal_rgb()); Denoising Albedo and Normal 3, Depth 1 per pixel.
  enum class FeaturePass : uint8_t { PrimalA, PrimalB, Albedo, Normal, Depth };
  void feature(FeaturePass pass, float* out) const;
  void feature_variance(FeaturePass pass, float* out) const;
  static int feature_channels(FeaturePass pass) { return pass == FeaturePass::Depth ? 1 : 3; }
  bool has_features() const { return !features_.empty(); }
  // G-PT's gradients over the same halves of the samples, as gradient_x_rgb() / gradient_y_rgb()
  // over each half alone: dx(x) = the mean of pixel x's G_right halves over its half-A (or B)
  // samples - the mean of pixel x + 1's G_left halves over its own; 3 per pixel, 0 where a
  // pixel's half has no samples (all 0 without has_half_gradients()). Kept with the feature
  // passes on in a film that holds gradients (not in PT mode).
  enum class SampleHalf : uint8_t { A, B };
  void gradient_x_half_rgb(SampleHalf half, float* out) const;
  void gradient_y_half_rgb(SampleHalf half, float* out) const;
  bool has_half_gradients() const { return !half_a_grad_.empty(); }
  bool has_normal() const { return !normal_.empty(); }
  bool has_mist() const { return !mist_.empty(); }
  uint32_t samples(int x, int y) const { return samples_[size_t(y) * width_ + x]; }
  uint32_t min_samples() const;
  uint32_t max_samples() const;
  // What adaptive sampling weighs (integrators/adaptive_sampling.h), for pixel i: the luminance
  // of its primal mean, and the variance of that mean plus, with G-PT's gradients, the variances
  // of its own four gradient halves' means (the base paths it traced), all in luminance.
  double pixel_luminance(size_t i) const;
  double pixel_variance(size_t i) const;

  // Adaptive sampling: the integrators add samples only to pixels whose `mask` entry is non-zero
  // (width x height, row 0 at the bottom; not owned, kept alive by the caller); null, the
  // default: every pixel.
  void set_sampling_mask(const uint8_t* mask) { sampling_mask_ = mask; }
  bool sampling(int x, int y) const {
    return !sampling_mask_ || sampling_mask_[size_t(y) * width_ + x];
  }

  // --- Accumulation (called by the integrators; each pixel is written by one thread at a time) ---
  // What every sample adds: one cache line per pixel (alignas), the whole film in PT mode.
  struct alignas(64) Accumulator {
    double primal[3] = {0, 0, 0}, primal2 = 0;  // sum, sum of squared luminance
    double emission[3] = {0, 0, 0};
    double alpha = 0;  // sum of the samples' alphas

    // One camera sample's primal and camera-visible emission, as every integrator adds them: a
    // non-finite value would poison the pixel forever and is dropped (counted as black); with
    // clamp > 0 the primal is scaled so its largest component is at most clamp. alpha: see
    // Film::alpha().
    // Returns the primal as added.
    Spectrum add_path(Spectrum primal_sample, Spectrum emission_sample, float clamp,
                      float alpha_sample = 1.0f) {
      if (!is_finite(primal_sample)) primal_sample = Spectrum(0.0f);
      if (!is_finite(emission_sample)) emission_sample = Spectrum(0.0f);
      if (clamp > 0.0f) {
        const float m = max_component(primal_sample);
        if (m > clamp) primal_sample *= clamp / m;
      }
      const double lum = luminance(primal_sample);
      for (int c = 0; c < 3; ++c) {
        primal[c] += primal_sample[c];
        emission[c] += emission_sample[c];
      }
      primal2 += lum * lum;
      alpha += std::isfinite(alpha_sample) ? alpha_sample : 1.0f;
      return primal_sample;
    }
  };
  // What G-PT adds besides: gradient halves and shift statistics. Kept apart, and allocated only
  // when the integrator estimates gradients, so that PT's films (the pass film is cleared and
  // merged after every pass) take 64 bytes per pixel instead of 208.
  struct GradientAccumulator {
    double dx[3] = {0, 0, 0}, dx2 = 0;  // sums and sums of squared luminance
    double dy[3] = {0, 0, 0}, dy2 = 0;
    double shift_attempts = 0, shift_failures = 0;
    // This pixel's one-sided halves G_left and G_down, written only by the pixel's own tile and
    // subtracted from the neighbours' dx(x - 1) and dy(y - 1) at read-out, so that no tile has to
    // trace its neighbours' base paths. dx and dy then hold the G_right / G_up halves.
    double dx_left[3] = {0, 0, 0}, dx_left2 = 0;
    double dy_down[3] = {0, 0, 0}, dy_down2 = 0;
  };
  // Half A's share of a GradientAccumulator's four halves: the sums over the samples of even
  // global index (has_half_gradients()); half B's are the totals minus these.
  struct HalfAGradients {
    double dx[3] = {0, 0, 0}, dy[3] = {0, 0, 0};
    double dx_left[3] = {0, 0, 0}, dy_down[3] = {0, 0, 0};
  };
  Accumulator& pixel(int x, int y) { return acc_[size_t(y) * width_ + x]; }
  const Accumulator& pixel(int x, int y) const { return acc_[size_t(y) * width_ + x]; }
  // Only while the film holds gradients (!gradients_from_primal()).
  GradientAccumulator& gradients(int x, int y) { return grad_[size_t(y) * width_ + x]; }
  // Pixel (x, y)'s half-A gradient sums when the sample of global index `sample_index` belongs
  // to half A and the film keeps them, else null: where that sample adds its halves besides.
  HalfAGradients* half_a_gradients(int x, int y, uint32_t sample_index) {
    if (half_a_grad_.empty() || !in_half_a(sample_index)) return nullptr;
    return &half_a_grad_[size_t(y) * width_ + x];
  }
  void add_sample_count(int x, int y, uint32_t n = 1) { samples_[size_t(y) * width_ + x] += n; }
  // Sample 0's camera hit (view-axis distance > 0, pass indices); integrators call it for that
  // sample only.
  void set_first_hit(int x, int y, float depth, float object_index, float material_index) {
    first_hit_[size_t(y) * width_ + x] = {depth, object_index, material_index};
  }
  // One sample's normal-pass and mist-pass values (only for the passes enabled).
  void add_data(int x, int y, Vec3f normal, float mist) {
    const size_t i = size_t(y) * width_ + x;
    if (!normal_.empty())
      for (int c = 0; c < 3; ++c) normal_[3 * i + size_t(c)] += normal[c];
    if (!mist_.empty() && std::isfinite(mist)) mist_[i] += mist;  // as add_path: drop NaN / inf
  }

  // One sample's feature values (only with the feature passes on): `primal` as add_path()
  // returned it, `sample_index` picking its half; albedo, normal (3 each) and depth.
  void add_features(int x, int y, uint32_t sample_index, Spectrum primal, Spectrum albedo,
                    Vec3f normal, float depth) {
    FeatureAccumulator& f = features_[size_t(y) * width_ + x];
    double* half = in_half_a(sample_index) ? f.half_a : f.half_b;
    double* half2 = in_half_a(sample_index) ? f.half_a2 : f.half_b2;
    if (!is_finite(albedo)) albedo = Spectrum(0.0f);
    if (!is_finite(normal)) normal = Vec3f();
    if (!std::isfinite(depth)) depth = 0.0f;
    for (int c = 0; c < 3; ++c) {
      half[c] += primal[c];
      half2[c] += double(primal[c]) * primal[c];
      f.albedo[c] += albedo[c];
      f.albedo2[c] += double(albedo[c]) * albedo[c];
      f.normal[c] += normal[c];
      f.normal2[c] += double(normal[c]) * normal[c];
    }
    f.depth += depth;
    f.depth2 += double(depth) * depth;
  }

  // --- Bookkeeping (RenderSession) ---
  // PT mode: the integrator does not estimate gradients; gradient_x/y_rgb() then return forward
  // differences of the primal pixel means (0 at the last column / row, the Neumann rows of the
  // reconstruction) and variance3() the matching sum of the two pixels' variances, so that
  // reconstructing PT passes returns the PT image.
  // On, the film drops its gradient accumulators (GradientAccumulator); off (the default), it
  // has them, zeroed.
  void set_gradients_from_primal(bool on);
  bool gradients_from_primal() const { return gradients_from_primal_; }
  void clear();  // zero every accumulator and sample count
  // Allocates the Normal / Mist sums (none by default: films without them cost nothing).
  void enable_data_passes(bool normal, bool mist);
  // Allocates the feature passes' sums (none by default), and the half-A gradient sums when the
  // film holds gradients.
  void enable_feature_passes(bool on);
  // The index of the render's first sample (RenderSettings::sample_offset): the feature passes'
  // halves are the even and odd global sample indices.
  void set_sample_offset(uint32_t offset) { sample_offset_ = offset; }
  uint32_t sample_offset() const { return sample_offset_; }
  // The feature passes' halves split the sample sequence at `pairs` (core/sample_halves.h); 0
  // without the feature passes, where sample s draws from sequence index s.
  void set_half_split(uint32_t pairs) { half_split_ = pairs; }
  uint32_t half_split() const { return half_split_; }
  // The sequence index global sample `s` draws its numbers from.
  uint32_t sequence_index(uint32_t s) const {
    return half_split_ ? half_sequence_index(s, half_split_) : s;
  }
  // Adds rows [y0, y1) of `pass` (same size) into this film and zeroes them in `pass`: how a
  // completed pass is committed.
  void take_rows(Film& pass, int y0, int y1);

 private:
  void gradient_rgb(float* out, bool along_x, double (GradientAccumulator::*forward)[3],
                    double (GradientAccumulator::*backward)[3]) const;
  void gradient_half_rgb(SampleHalf half, bool along_x, float* out) const;
  // Pixel i's samples in `half` (by the global sample index, sample_offset_ included).
  uint32_t half_samples(SampleHalf half, size_t i) const;
  // Half-A gradient sums exactly when there are feature passes and gradients.
  void allocate_half_gradients();

  int width_ = 0, height_ = 0;
  // Per-pixel arrays in huge pages: a 1920x1080 film is 170-470 MB (huge_pages.h).
  HugePageVector<Accumulator> acc_;
  HugePageVector<GradientAccumulator> grad_;  // empty when gradients_from_primal_
  HugePageVector<uint32_t> samples_;
  struct FirstHit {
    float depth = 0.0f;  // 0: no surface (yet)
    float object_index = 0.0f, material_index = 0.0f;
  };
  HugePageVector<FirstHit> first_hit_;
  HugePageVector<double> normal_, mist_;  // sums; empty when the pass is off
  // Sums and sums of squares per channel (the halves: per half).
  struct FeatureAccumulator {
    double half_a[3] = {0, 0, 0}, half_a2[3] = {0, 0, 0};
    double half_b[3] = {0, 0, 0}, half_b2[3] = {0, 0, 0};
    double albedo[3] = {0, 0, 0}, albedo2[3] = {0, 0, 0};
    double normal[3] = {0, 0, 0}, normal2[3] = {0, 0, 0};
    double depth = 0, depth2 = 0;
  };
  // The sums of `pass` in pixel i and its sample count.
  void feature_sums(FeaturePass pass, size_t i, const double*& sum, const double*& sum2,
                    uint32_t& n) const;
  HugePageVector<FeatureAccumulator> features_;  // empty when the feature passes are off
  HugePageVector<HalfAGradients> half_a_grad_;   // empty unless features_ and grad_ are not
  bool gradients_from_primal_ = false;
  const uint8_t* sampling_mask_ = nullptr;
  uint32_t sample_offset_ = 0;
  uint32_t half_split_ = 0;
};

}  // namespace gdpt
