#include "render/film.h"

#include <algorithm>
#include <stdexcept>

namespace gdpt {

namespace {

double lum(const double c[3]) {
  return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

// Variance of the mean of n samples from their sum and sum of squares (unbiased sample variance
// divided by n); 0 with fewer than two samples.
double variance_of_mean(double sum, double sum2, uint32_t n) {
  if (n < 2) return 0.0;
  const double mean = sum / n;
  const double var = std::max(0.0, (sum2 - mean * sum) / (n - 1));
  return var / n;
}

// to += from for a struct of double sums, field by field.
template <class T>
void add_sums(T& to, const T& from) {
  static_assert(sizeof(T) % sizeof(double) == 0);
  double* a = reinterpret_cast<double*>(&to);
  const double* b = reinterpret_cast<const double*>(&from);
  for (size_t k = 0; k < sizeof(T) / sizeof(double); ++k) a[k] += b[k];
}

// G-PT gradients along one axis from per-pixel sums of the one-sided halves, sum(i, backward, c),
// and the samples behind them, inv(i) = 1 / count (0 for none): this pixel's forward half minus
// the neighbour's (i + step) backward half, the neighbour's term only inside the image.
template <class Sum, class Inv>
void one_sided_differences(float* out, int width, int height, bool along_x, const Sum& sum,
                           const Inv& inv) {
  const size_t step = along_x ? 1 : size_t(width);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const size_t i = size_t(y) * width + x;
      const bool inside = along_x ? x + 1 < width : y + 1 < height;
      const double inv_here = inv(i), inv_next = inside ? inv(i + step) : 0.0;
      for (int c = 0; c < 3; ++c) {
        double v = sum(i, false, c) * inv_here;
        if (inside) v -= sum(i + step, true, c) * inv_next;
        out[3 * i + c] = float(v);
      }
    }
}

}  // namespace

Film::Film(int width, int height, bool gradients_from_primal)
    : width_(std::max(width, 0)),
      height_(std::max(height, 0)),
      acc_(size_t(width_) * size_t(height_)),
      grad_(gradients_from_primal ? 0 : size_t(width_) * size_t(height_)),
      samples_(size_t(width_) * size_t(height_), 0u),
      first_hit_(size_t(width_) * size_t(height_)),
      gradients_from_primal_(gradients_from_primal) {}

void Film::set_gradients_from_primal(bool on) {
  gradients_from_primal_ = on;
  if (on)
    HugePageVector<GradientAccumulator>().swap(grad_);
  else
    grad_.assign(pixel_count(), GradientAccumulator{});
  allocate_half_gradients();
}

void Film::allocate_half_gradients() {
  const bool on = !features_.empty() && !grad_.empty();
  if (on)
    half_a_grad_.assign(pixel_count(), HalfAGradients{});
  else
    HugePageVector<HalfAGradients>().swap(half_a_grad_);
}

void Film::enable_data_passes(bool normal, bool mist) {
  normal_.assign(normal ? 3 * pixel_count() : 0, 0.0);
  mist_.assign(mist ? pixel_count() : 0, 0.0);
}

void Film::enable_feature_passes(bool on) {
  features_.assign(on ? pixel_count() : 0, FeatureAccumulator{});
  allocate_half_gradients();
}

void Film::clear() {
  std::fill(features_.begin(), features_.end(), FeatureAccumulator{});
  std::fill(half_a_grad_.begin(), half_a_grad_.end(), HalfAGradients{});
  std::fill(normal_.begin(), normal_.end(), 0.0);
  std::fill(mist_.begin(), mist_.end(), 0.0);
  std::fill(acc_.begin(), acc_.end(), Accumulator{});
  std::fill(grad_.begin(), grad_.end(), GradientAccumulator{});
  std::fill(samples_.begin(), samples_.end(), 0u);
  std::fill(first_hit_.begin(), first_hit_.end(), FirstHit{});
}

void Film::take_rows(Film& pass, int y0, int y1) {
  if (pass.acc_.size() != acc_.size() || pass.grad_.size() != grad_.size() ||
      pass.half_a_grad_.size() != half_a_grad_.size())
    throw std::logic_error("Film::take_rows: the pass film has another size or gradient layout");
  for (size_t i = size_t(y0) * width_, end = size_t(y1) * width_; i < end; ++i) {
    Accumulator& a = acc_[i];
    Accumulator& b = pass.acc_[i];
    for (int c = 0; c < 3; ++c) {
      a.primal[c] += b.primal[c];
      a.emission[c] += b.emission[c];
    }
    a.primal2 += b.primal2;
    a.alpha += b.alpha;
    b = Accumulator{};
    if (!grad_.empty()) {
      GradientAccumulator& ga = grad_[i];
      GradientAccumulator& gb = pass.grad_[i];
      for (int c = 0; c < 3; ++c) {
        ga.dx[c] += gb.dx[c];
        ga.dy[c] += gb.dy[c];
        ga.dx_left[c] += gb.dx_left[c];
        ga.dy_down[c] += gb.dy_down[c];
      }
      ga.dx2 += gb.dx2;
      ga.dy2 += gb.dy2;
      ga.dx_left2 += gb.dx_left2;
      ga.dy_down2 += gb.dy_down2;
      ga.shift_attempts += gb.shift_attempts;
      ga.shift_failures += gb.shift_failures;
      gb = GradientAccumulator{};
    }
    samples_[i] += pass.samples_[i];
    if (!normal_.empty())
      for (size_t c = 3 * i; c < 3 * i + 3; ++c) {
        normal_[c] += pass.normal_[c];
        pass.normal_[c] = 0.0;
      }
    if (!features_.empty()) {
      add_sums(features_[i], pass.features_[i]);
      pass.features_[i] = FeatureAccumulator{};
    }
    if (!half_a_grad_.empty()) {
      add_sums(half_a_grad_[i], pass.half_a_grad_[i]);
      pass.half_a_grad_[i] = HalfAGradients{};
    }
    if (!mist_.empty()) {
      mist_[i] += pass.mist_[i];
      pass.mist_[i] = 0.0;
    }
    // Sample 0 was in this pass and hit a surface.
    if (pass.first_hit_[i].depth != 0.0f) first_hit_[i] = pass.first_hit_[i];
    pass.first_hit_[i] = FirstHit{};
    pass.samples_[i] = 0;
  }
}

uint32_t Film::min_samples() const {
  if (samples_.empty()) return 0;
  return *std::min_element(samples_.begin(), samples_.end());
}

uint32_t Film::max_samples() const {
  if (samples_.empty()) return 0;
  return *std::max_element(samples_.begin(), samples_.end());
}

double Film::pixel_luminance(size_t i) const {
  return samples_[i] ? lum(acc_[i].primal) / samples_[i] : 0.0;
}

double Film::pixel_variance(size_t i) const {
  const uint32_t n = samples_[i];
  double v = variance_of_mean(lum(acc_[i].primal), acc_[i].primal2, n);
  if (!gradients_from_primal_) {
    const GradientAccumulator& g = grad_[i];
    v += variance_of_mean(lum(g.dx), g.dx2, n) + variance_of_mean(lum(g.dy), g.dy2, n) +
         variance_of_mean(lum(g.dx_left), g.dx_left2, n) +
         variance_of_mean(lum(g.dy_down), g.dy_down2, n);
  }
  return v;
}

void Film::primal_rgb(float* out) const {
  for (size_t i = 0; i < acc_.size(); ++i) {
    const double inv = samples_[i] ? 1.0 / samples_[i] : 0.0;
    for (int c = 0; c < 3; ++c) out[3 * i + c] = float(acc_[i].primal[c] * inv);
  }
}

void Film::alpha(float* out) const {
  for (size_t i = 0; i < acc_.size(); ++i)
    out[i] = samples_[i] ? float(acc_[i].alpha / samples_[i]) : 0.0f;
}

void Film::depth(float* out) const {
  for (size_t i = 0; i < first_hit_.size(); ++i)
    out[i] = first_hit_[i].depth > 0.0f ? first_hit_[i].depth : 1e10f;
}

void Film::object_index(float* out) const {
  for (size_t i = 0; i < first_hit_.size(); ++i) out[i] = first_hit_[i].object_index;
}

void Film::material_index(float* out) const {
  for (size_t i = 0; i < first_hit_.size(); ++i) out[i] = first_hit_[i].material_index;
}

void Film::normal(float* out) const {
  for (size_t i = 0; i < pixel_count(); ++i) {
    const double inv = samples_[i] ? 1.0 / samples_[i] : 0.0;
    for (size_t c = 0; c < 3; ++c)
      out[3 * i + c] = normal_.empty() ? 0.0f : float(normal_[3 * i + c] * inv);
  }
}

void Film::mist(float* out) const {
  // Cycles accumulates 1 - mist weighted by coverage and outputs 1 - the mean: the background
  // (no surface) reads 1, fully misted.
  for (size_t i = 0; i < pixel_count(); ++i) {
    const double inv = samples_[i] ? 1.0 / samples_[i] : 0.0;
    out[i] = mist_.empty() ? 0.0f : std::clamp(float(1.0 - mist_[i] * inv), 0.0f, 1.0f);
  }
}

void Film::emission_rgb(float* out) const {
  for (size_t i = 0; i < acc_.size(); ++i) {
    const double inv = samples_[i] ? 1.0 / samples_[i] : 0.0;
    for (int c = 0; c < 3; ++c) out[3 * i + c] = float(acc_[i].emission[c] * inv);
  }
}

// One routine for both axes: the neighbour of pixel i along the axis is i + step. G-PT gradients
// combine this pixel's forward half with the neighbour's backward half, PT ones are forward
// differences of the primal means. The last column / row is 0 (Neumann).
void Film::gradient_rgb(float* out, bool along_x, double (GradientAccumulator::*forward)[3],
                        double (GradientAccumulator::*backward)[3]) const {
  const auto inv_samples = [&](size_t i) { return samples_[i] ? 1.0 / samples_[i] : 0.0; };
  if (!gradients_from_primal_) {
    const auto sum = [&](size_t i, bool back, int c) {
      return (grad_[i].*(back ? backward : forward))[c];
    };
    one_sided_differences(out, width_, height_, along_x, sum, inv_samples);
    return;
  }
  const size_t step = along_x ? 1 : size_t(width_);
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const size_t i = size_t(y) * width_ + x;
      const bool inside = along_x ? x + 1 < width_ : y + 1 < height_;
      const double inv = inv_samples(i), inv_next = inside ? inv_samples(i + step) : 0.0;
      for (int c = 0; c < 3; ++c)
        out[3 * i + c] =
            inside ? float(acc_[i + step].primal[c] * inv_next - acc_[i].primal[c] * inv) : 0.0f;
    }
}

uint32_t Film::half_samples(SampleHalf half, size_t i) const {
  const uint32_t even = even_sample_count(sample_offset_, samples_[i]);
  return half == SampleHalf::A ? even : samples_[i] - even;
}

// Half A from its own sums, half B as the totals minus half A's.
void Film::gradient_half_rgb(SampleHalf half, bool along_x, float* out) const {
  if (half_a_grad_.empty()) {
    std::fill(out, out + 3 * pixel_count(), 0.0f);
    return;
  }
  using G = GradientAccumulator;
  using A = HalfAGradients;
  const auto forward = along_x ? &G::dx : &G::dy, backward = along_x ? &G::dx_left : &G::dy_down;
  const auto forward_a = along_x ? &A::dx : &A::dy,
             backward_a = along_x ? &A::dx_left : &A::dy_down;
  const bool b = half == SampleHalf::B;
  const auto sum = [&](size_t i, bool back, int c) {
    const double a = (half_a_grad_[i].*(back ? backward_a : forward_a))[c];
    return b ? (grad_[i].*(back ? backward : forward))[c] - a : a;
  };
  const auto inv = [&](size_t i) {
    const uint32_t n = half_samples(half, i);
    return n ? 1.0 / n : 0.0;
  };
  one_sided_differences(out, width_, height_, along_x, sum, inv);
}

void Film::gradient_x_half_rgb(SampleHalf half, float* out) const {
  gradient_half_rgb(half, true, out);
}

void Film::gradient_y_half_rgb(SampleHalf half, float* out) const {
  gradient_half_rgb(half, false, out);
}

void Film::gradient_x_rgb(float* out) const {
  gradient_rgb(out, true, &GradientAccumulator::dx, &GradientAccumulator::dx_left);
}

void Film::gradient_y_rgb(float* out) const {
  gradient_rgb(out, false, &GradientAccumulator::dy, &GradientAccumulator::dy_down);
}

void Film::variance3(float* out) const {
  auto primal_var = [&](size_t i) {
    return variance_of_mean(lum(acc_[i].primal), acc_[i].primal2, samples_[i]);
  };
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) {
      const size_t i = size_t(y) * width_ + x;
      const double vp = primal_var(i);
      double vdx, vdy;
      if (gradients_from_primal_) {
        // Independent pixel means: the variance of a difference is the sum of the variances.
        vdx = x + 1 < width_ ? vp + primal_var(i + 1) : 0.0;
        vdy = y + 1 < height_ ? vp + primal_var(i + width_) : 0.0;
      } else {
        // G-PT: the two halves come from different pixels' base paths (independent).
        const GradientAccumulator& a = grad_[i];
        vdx = variance_of_mean(lum(a.dx), a.dx2, samples_[i]);
        vdy = variance_of_mean(lum(a.dy), a.dy2, samples_[i]);
        if (x + 1 < width_) {
          const GradientAccumulator& b = grad_[i + 1];
          vdx += variance_of_mean(lum(b.dx_left), b.dx_left2, samples_[i + 1]);
        }
        if (y + 1 < height_) {
          const GradientAccumulator& b = grad_[i + width_];
          vdy += variance_of_mean(lum(b.dy_down), b.dy_down2, samples_[i + width_]);
        }
      }
      out[3 * i + 0] = float(vp);
      out[3 * i + 1] = float(vdx);
      out[3 * i + 2] = float(vdy);
    }
}

void Film::feature_sums(FeaturePass pass, size_t i, const double*& sum, const double*& sum2,
                        uint32_t& n) const {
  const FeatureAccumulator& f = features_[i];
  n = samples_[i];
  switch (pass) {
    case FeaturePass::PrimalA:
      sum = f.half_a, sum2 = f.half_a2, n = half_samples(SampleHalf::A, i);
      break;
    case FeaturePass::PrimalB:
      sum = f.half_b, sum2 = f.half_b2, n = half_samples(SampleHalf::B, i);
      break;
    case FeaturePass::Albedo:
      sum = f.albedo, sum2 = f.albedo2;
      break;
    case FeaturePass::Normal:
      sum = f.normal, sum2 = f.normal2;
      break;
    case FeaturePass::Depth:
      sum = &f.depth, sum2 = &f.depth2;
      break;
  }
}

void Film::feature(FeaturePass pass, float* out) const {
  const int channels = feature_channels(pass);
  for (size_t i = 0; i < pixel_count(); ++i) {
    const double *sum = nullptr, *sum2 = nullptr;
    uint32_t n = 0;
    if (!features_.empty()) feature_sums(pass, i, sum, sum2, n);
    for (int c = 0; c < channels; ++c) out[size_t(channels) * i + c] = n ? float(sum[c] / n) : 0.0f;
  }
}

void Film::feature_variance(FeaturePass pass, float* out) const {
  const int channels = feature_channels(pass);
  for (size_t i = 0; i < pixel_count(); ++i) {
    const double *sum = nullptr, *sum2 = nullptr;
    uint32_t n = 0;
    if (!features_.empty()) feature_sums(pass, i, sum, sum2, n);
    for (int c = 0; c < channels; ++c)
      out[size_t(channels) * i + c] = n ? float(variance_of_mean(sum[c], sum2[c], n)) : 0.0f;
  }
}

void Film::sample_count(float* out) const {
  for (size_t i = 0; i < samples_.size(); ++i) out[i] = float(samples_[i]);
}

void Film::shift_attempts(float* out) const {
  for (size_t i = 0; i < grad_.size(); ++i)
    out[i] = samples_[i] ? float(grad_[i].shift_attempts / samples_[i]) : 0.0f;
  if (grad_.empty()) std::fill(out, out + pixel_count(), 0.0f);
}

void Film::gradient_halves(float* out) const {
  if (grad_.empty()) {
    std::fill(out, out + 4 * pixel_count(), 0.0f);
    return;
  }
  for (size_t i = 0; i < grad_.size(); ++i) {
    const GradientAccumulator& a = grad_[i];
    const uint32_t n = samples_[i];
    const double inv = n ? 1.0 / n : 0.0;
    out[4 * i + 0] = float(lum(a.dx) * inv);
    out[4 * i + 1] = float(lum(a.dy) * inv);
    out[4 * i + 2] = float(variance_of_mean(lum(a.dx), a.dx2, n));
    out[4 * i + 3] = float(variance_of_mean(lum(a.dy), a.dy2, n));
  }
}

void Film::shift_failures(float* out) const {
  for (size_t i = 0; i < grad_.size(); ++i) {
    const GradientAccumulator& a = grad_[i];
    out[i] = a.shift_attempts > 0.0 ? float(a.shift_failures / a.shift_attempts) : 0.0f;
  }
  if (grad_.empty()) std::fill(out, out + pixel_count(), 0.0f);
}

}  // namespace gdpt
