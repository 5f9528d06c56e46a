#include "reconstruct/pass_merge.h"

#include <algorithm>
#include <set>

#include "core/sample_halves.h"

namespace gdpt {

namespace {

constexpr double kLuminance[3] = {0.2126, 0.7152, 0.0722};  // as the Film's variances

// Per-pixel means over samples, merged by sample weight (Combined's alpha too).
const std::set<std::string> kMeanPasses = {
    "Primal", "Emission",         "Gradient X",       "Gradient Y",      "Normal",
    "Mist",   "Denoising Albedo", "Denoising Normal", "Denoising Depth", "Shift Attempts"};
// The first sample's values (depth and indices of its camera hit).
const std::set<std::string> kFirstSamplePasses = {"Depth", "IndexOB", "IndexMA"};
// Per-channel variances of a mean pass's pixel means.
const std::map<std::string, std::string> kChannelVariances = {
    {"Primal A Variance", "Primal A"},
    {"Primal B Variance", "Primal B"},
    {"Denoising Albedo Variance", "Denoising Albedo"},
    {"Denoising Normal Variance", "Denoising Normal"},
    {"Denoising Depth Variance", "Denoising Depth"}};
// Means over one half of the samples (true: the even global sample indices, A; false: the odd
// ones, B): the primal's and G-PT's gradients'.
const std::map<std::string, bool> kHalfMeanPasses = {
    {"Primal A", true},      {"Primal B", false},    {"Gradient X A", true},
    {"Gradient X B", false}, {"Gradient Y A", true}, {"Gradient Y B", false}};
const std::set<std::string> kOtherPasses = {"Combined", "Sample Count", "Variance",
                                            "Gradient Halves", "Shift Failures"};

std::string range_text(uint32_t first, double count) {
  return std::to_string(first) + ".." + std::to_string(uint64_t(first) + uint64_t(count) - 1);
}

// The variance of the pooled mean of parts with n[k] samples, means m[k] and variances of their
// means v[k] (Chan et al.'s parallel formula, as a sum over parts).
double pooled_variance(size_t parts, const double* n, const double* m, const double* v) {
  double total = 0.0, sum = 0.0;
  for (size_t k = 0; k < parts; ++k) total += n[k], sum += n[k] * m[k];
  if (total < 2.0) return 0.0;
  const double mean = sum / total;
  double m2 = 0.0;
  for (size_t k = 0; k < parts; ++k) {
    if (n[k] <= 0.0) continue;
    m2 += std::max(0.0, v[k]) * n[k] * (n[k] - 1.0) + n[k] * (m[k] - mean) * (m[k] - mean);
  }
  return m2 / (total - 1.0) / total;
}

class Merger {
 public:
  Merger(const std::vector<RenderPart>& parts, const MergeSettings& settings)
      : parts_(parts), settings_(settings), first_(parts.front()) {}

  RenderPart run();

 private:
  const std::vector<RenderPart>& parts_;
  const MergeSettings& settings_;
  const RenderPart& first_;
  size_t pixels_ = 0;
  size_t lowest_ = 0;                        // the part with the lowest sample offset
  std::vector<std::vector<double>> n_;       // [part][pixel] samples
  std::vector<std::vector<double>> even_n_;  // [part][pixel] samples of even index
  ReconstructionNorm norm_ = ReconstructionNorm::L1;
  float alpha_ = 0.2f;

  void check_compatible();
  void check_ranges();
  void require(const std::string& pass, const std::string& why) const;
  const PassImage& pass(size_t k, const std::string& name) const {
    return parts_[k].passes.at(name);
  }
  // Merged pass by rule.
  PassImage weighted_mean(const std::string& name, bool even_half, bool odd_half) const;
  PassImage channel_variance(const std::string& name, const std::string& mean) const;
  PassImage variance3(const RenderPart& merged) const;
  PassImage gradient_halves() const;
  PassImage shift_failures() const;
  PassImage sample_count() const;
  double count(size_t k, size_t i, bool even_half, bool odd_half) const {
    if (even_half) return even_n_[k][i];
    if (odd_half) return n_[k][i] - even_n_[k][i];
    return n_[k][i];
  }
  double luminance(size_t k, const std::string& name, size_t i) const {
    const float* c = &pass(k, name).data[3 * i];
    return kLuminance[0] * c[0] + kLuminance[1] * c[1] + kLuminance[2] * c[2];
  }
};

void Merger::require(const std::string& name, const std::string& why) const {
  if (!first_.passes.count(name))
    throw MergeError("'" + first_.name + "' has no '" + name + "' pass, which " + why);
}

void Merger::check_compatible() {
  for (const RenderPart& p : parts_) {
    if (p.width != first_.width || p.height != first_.height)
      throw MergeError("'" + p.name + "' is " + std::to_string(p.width) + "x" +
                       std::to_string(p.height) + ", '" + first_.name + "' " +
                       std::to_string(first_.width) + "x" + std::to_string(first_.height));
    if (p.record.seed != first_.record.seed)
      throw MergeError("'" + p.name + "' was rendered with seed " + std::to_string(p.record.seed) +
                       ", '" + first_.name + "' with seed " + std::to_string(first_.record.seed) +
                       ": only sample ranges of one seed merge into one render");
    if (p.record.half_split != first_.record.half_split && first_.passes.count("Primal A"))
      throw MergeError("'" + p.name + "' split its halves' samples at " +
                       std::to_string(p.record.half_split) + " pairs, '" + first_.name + "' at " +
                       std::to_string(first_.record.half_split) +
                       ": the parts of one frame need the same Frame Samples "
                       "(scene.gdpt.frame_samples, the frame's samples over all parts)");
    if (p.record.mode != first_.record.mode)
      throw MergeError("'" + p.name + "' was rendered in " + p.record.mode + " mode, '" +
                       first_.name + "' in " + first_.record.mode + " mode");
    if (!settings_.norm && p.record.reconstruction != first_.record.reconstruction)
      throw MergeError("'" + p.name + "' records reconstruction " + p.record.reconstruction +
                       ", '" + first_.name + "' " + first_.record.reconstruction +
                       " (choose one with --norm)");
    if (!settings_.alpha && p.record.alpha != first_.record.alpha)
      throw MergeError("'" + p.name + "' records alpha " + std::to_string(p.record.alpha) + ", '" +
                       first_.name + "' " + std::to_string(first_.record.alpha) +
                       " (choose one with --alpha)");
    for (const auto& [name, image] : p.passes) {
      const auto other = first_.passes.find(name);
      if (other == first_.passes.end())
        throw MergeError("'" + p.name + "' has a '" + name + "' pass that '" + first_.name +
                         "' lacks: merged parts need the same passes");
      if (other->second.channels != image.channels)
        throw MergeError("pass '" + name + "' has " + std::to_string(image.channels) +
                         " channels in '" + p.name + "', " +
                         std::to_string(other->second.channels) + " in '" + first_.name + "'");
      if (image.channels <= 0 || image.data.size() != pixels_ * size_t(image.channels))
        throw MergeError("pass '" + name + "' of '" + p.name + "' has the wrong size");
      if (!kMeanPasses.count(name) && !kFirstSamplePasses.count(name) &&
          !kChannelVariances.count(name) && !kHalfMeanPasses.count(name) &&
          !kOtherPasses.count(name))
        throw MergeError("'" + p.name + "' has a pass '" + name +
                         "' that GDPT does not write: the merge does not know how to combine it");
    }
    if (p.passes.size() != first_.passes.size())
      for (const auto& [name, image] : first_.passes)
        if (!p.passes.count(name))
          throw MergeError("'" + p.name + "' has no '" + name + "' pass, which '" + first_.name +
                           "' has: merged parts need the same passes");
  }
}

void Merger::check_ranges() {
  require("Sample Count", "the merge weighs every pass by (render with sample counts)");
  struct Range {
    uint32_t first;
    double count;
    size_t part;
  };
  std::vector<Range> ranges;
  n_.assign(parts_.size(), {});
  even_n_.assign(parts_.size(), {});
  for (size_t k = 0; k < parts_.size(); ++k) {
    const std::vector<float>& counts = pass(k, "Sample Count").data;
    if (pass(k, "Sample Count").channels != 1)
      throw MergeError("'" + parts_[k].name + "': 'Sample Count' must have 1 channel");
    double most = 0.0;
    n_[k].resize(pixels_);
    even_n_[k].resize(pixels_);
    for (size_t i = 0; i < pixels_; ++i) {
      const float c = counts[i];
      if (!(c >= 0.0f) || c != float(uint32_t(c)))
        throw MergeError("'" + parts_[k].name + "': 'Sample Count' holds " + std::to_string(c) +
                         ", not a sample count");
      n_[k][i] = c;
      even_n_[k][i] = even_sample_count(parts_[k].record.sample_offset, uint32_t(c));
      most = std::max(most, double(c));
    }
    if (most > 0.0) ranges.push_back({parts_[k].record.sample_offset, most, k});
  }
  std::sort(ranges.begin(), ranges.end(),
            [](const Range& a, const Range& b) { return a.first < b.first; });
  for (size_t r = 1; r < ranges.size(); ++r) {
    const Range &a = ranges[r - 1], &b = ranges[r];
    if (double(a.first) + a.count > double(b.first))
      throw MergeError("sample ranges overlap: '" + parts_[a.part].name + "' took samples " +
                       range_text(a.first, a.count) + ", '" + parts_[b.part].name + "' " +
                       range_text(b.first, b.count) +
                       " (each part needs its own scene.gdpt.sample_offset)");
  }
  lowest_ = ranges.empty() ? 0 : ranges.front().part;
}

PassImage Merger::sample_count() const {
  PassImage out{1, std::vector<float>(pixels_, 0.0f)};
  for (size_t i = 0; i < pixels_; ++i) {
    double n = 0.0;
    for (size_t k = 0; k < parts_.size(); ++k) n += n_[k][i];
    out.data[i] = float(n);
  }
  return out;
}

PassImage Merger::weighted_mean(const std::string& name, bool even_half, bool odd_half) const {
  const int channels = pass(0, name).channels;
  PassImage out{channels, std::vector<float>(pixels_ * size_t(channels), 0.0f)};
  for (size_t i = 0; i < pixels_; ++i) {
    double total = 0.0;
    for (size_t k = 0; k < parts_.size(); ++k) total += count(k, i, even_half, odd_half);
    if (total <= 0.0) continue;
    for (int c = 0; c < channels; ++c) {
      double sum = 0.0;
      for (size_t k = 0; k < parts_.size(); ++k) {
        const double n = count(k, i, even_half, odd_half);
        if (n > 0.0) sum += n * pass(k, name).data[i * size_t(channels) + size_t(c)];
      }
      out.data[i * size_t(channels) + size_t(c)] = float(sum / total);
    }
  }
  return out;
}

PassImage Merger::channel_variance(const std::string& name, const std::string& mean) const {
  require(mean, "'" + name + "' is merged with");
  const auto half = kHalfMeanPasses.find(mean);
  const bool even = half != kHalfMeanPasses.end() && half->second;
  const bool odd = half != kHalfMeanPasses.end() && !half->second;
  const int channels = pass(0, name).channels;
  if (pass(0, mean).channels != channels)
    throw MergeError("'" + name + "' and '" + mean + "' have different channel counts");
  PassImage out{channels, std::vector<float>(pixels_ * size_t(channels), 0.0f)};
  const size_t K = parts_.size();
  std::vector<double> n(K), m(K), v(K);
  for (size_t i = 0; i < pixels_; ++i)
    for (int c = 0; c < channels; ++c) {
      const size_t j = i * size_t(channels) + size_t(c);
      for (size_t k = 0; k < K; ++k) {
        n[k] = count(k, i, even, odd);
        m[k] = pass(k, mean).data[j];
        v[k] = pass(k, name).data[j];
      }
      out.data[j] = float(pooled_variance(K, n.data(), m.data(), v.data()));
    }
  return out;
}

PassImage Merger::gradient_halves() const {
  PassImage out = weighted_mean("Gradient Halves", false, false);
  const size_t K = parts_.size();
  std::vector<double> n(K), m(K), v(K);
  for (size_t i = 0; i < pixels_; ++i)
    for (int c = 0; c < 2; ++c) {
      for (size_t k = 0; k < K; ++k) {
        const float* h = &pass(k, "Gradient Halves").data[4 * i];
        n[k] = n_[k][i], m[k] = h[c], v[k] = h[2 + c];
      }
      out.data[4 * i + 2 + size_t(c)] = float(pooled_variance(K, n.data(), m.data(), v.data()));
    }
  return out;
}

// Variance: the primal's entry pooled with Primal's luminance; the gradients' entries rebuilt
// from the pooled primal variances (PT: independent pixel means) or from the pooled forward
// halves and the backward halves they imply (G-PT: dx(i) = F(i) - B(i + 1)).
PassImage Merger::variance3(const RenderPart& merged) const {
  require("Primal", "Variance is merged with");
  const bool gpt = first_.record.mode != "PT";
  if (gpt) {
    require("Gradient Halves", "a G-PT Variance pass is merged with");
    require("Gradient X", "a G-PT Variance pass is merged with");
    require("Gradient Y", "a G-PT Variance pass is merged with");
  }
  const int W = first_.width, H = first_.height;
  const size_t K = parts_.size();
  PassImage out{3, std::vector<float>(pixels_ * 3, 0.0f)};
  std::vector<double> n(K), m(K), v(K);
  std::vector<double> primal(pixels_);
  for (size_t i = 0; i < pixels_; ++i) {
    for (size_t k = 0; k < K; ++k)
      n[k] = n_[k][i], m[k] = luminance(k, "Primal", i), v[k] = pass(k, "Variance").data[3 * i];
    primal[i] = pooled_variance(K, n.data(), m.data(), v.data());
  }
  const PassImage* halves = gpt ? &merged.passes.at("Gradient Halves") : nullptr;
  // The pooled backward half of pixel j = i + step, from the parts' gradient at i.
  auto backward = [&](size_t i, size_t j, int axis) {
    const char* gradient = axis == 0 ? "Gradient X" : "Gradient Y";
    for (size_t k = 0; k < K; ++k) {
      const float* h = &pass(k, "Gradient Halves").data[4 * i];
      n[k] = n_[k][j];
      m[k] = h[axis] - luminance(k, gradient, i);
      v[k] = double(pass(k, "Variance").data[3 * i + 1 + size_t(axis)]) - h[2 + axis];
    }
    return pooled_variance(K, n.data(), m.data(), v.data());
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const size_t i = size_t(y) * W + x;
      const bool inside[2] = {x + 1 < W, y + 1 < H};
      const size_t next[2] = {i + 1, i + size_t(W)};
      out.data[3 * i] = float(primal[i]);
      for (int axis = 0; axis < 2; ++axis) {
        double var;
        if (!gpt)
          var = inside[axis] ? primal[i] + primal[next[axis]] : 0.0;
        else
          var = double(halves->data[4 * i + 2 + size_t(axis)]) +
                (inside[axis] ? backward(i, next[axis], axis) : 0.0);
        out.data[3 * i + 1 + size_t(axis)] = float(var);
      }
    }
  return out;
}

PassImage Merger::shift_failures() const {
  require("Shift Attempts", "Shift Failures is weighted by");
  PassImage out{1, std::vector<float>(pixels_, 0.0f)};
  for (size_t i = 0; i < pixels_; ++i) {
    double attempts = 0.0, failures = 0.0;
    for (size_t k = 0; k < parts_.size(); ++k) {
      const double a = n_[k][i] * pass(k, "Shift Attempts").data[i];
      attempts += a;
      failures += a * pass(k, "Shift Failures").data[i];
    }
    out.data[i] = attempts > 0.0 ? float(failures / attempts) : 0.0f;
  }
  return out;
}

RenderPart Merger::run() {
  pixels_ = size_t(std::max(first_.width, 0)) * size_t(std::max(first_.height, 0));
  check_compatible();
  check_ranges();
  norm_ = settings_.norm ? *settings_.norm : [&] {
    const auto n = norm_from_name(first_.record.reconstruction);
    if (!n)
      throw MergeError("'" + first_.name + "' records an unknown reconstruction '" +
                       first_.record.reconstruction + "' (choose one with --norm)");
    return *n;
  }();
  alpha_ = settings_.alpha ? *settings_.alpha : first_.record.alpha;

  RenderPart merged;
  merged.name = "merged";
  merged.width = first_.width;
  merged.height = first_.height;
  merged.record = parts_[lowest_].record;
  for (const auto& [name, image] : first_.passes) {
    PassImage out;
    if (name == "Sample Count")
      out = sample_count();
    else if (kMeanPasses.count(name) || name == "Combined")
      out = weighted_mean(name, false, false);
    else if (kHalfMeanPasses.count(name))
      out = weighted_mean(name, kHalfMeanPasses.at(name), !kHalfMeanPasses.at(name));
    else if (kFirstSamplePasses.count(name))
      out = parts_[lowest_].passes.at(name);
    else if (kChannelVariances.count(name))
      out = channel_variance(name, kChannelVariances.at(name));
    else if (name == "Gradient Halves")
      out = gradient_halves();
    else if (name == "Shift Failures")
      out = shift_failures();
    else
      continue;  // Variance, below: it reads the merged Gradient Halves
    merged.passes[name] = std::move(out);
  }
  if (first_.passes.count("Variance")) merged.passes["Variance"] = variance3(merged);

  require("Primal", "Combined is rebuilt from");
  require("Emission", "Combined is rebuilt from");
  const std::vector<float> rgb = rebuild_combined(merged, norm_, alpha_, settings_.threads);
  PassImage& combined = merged.passes["Combined"];
  if (combined.channels == 0) combined = {4, std::vector<float>(pixels_ * 4, 1.0f)};
  for (size_t i = 0; i < pixels_; ++i)
    for (int c = 0; c < 3; ++c)
      combined.data[i * size_t(combined.channels) + size_t(c)] = rgb[3 * i + size_t(c)];
  return merged;
}

const float* pass_data(const RenderPart& part, const std::string& name, int channels,
                       const char* why) {
  const auto it = part.passes.find(name);
  if (it == part.passes.end())
    throw MergeError("'" + part.name + "' has no '" + name + "' pass, which " + why);
  if (it->second.channels != channels)
    throw MergeError("'" + part.name + "': '" + name + "' has " +
                     std::to_string(it->second.channels) + " channels, not " +
                     std::to_string(channels));
  return it->second.data.data();
}

// G-PT's gradients over the halves into `in` when the part has them: all four or none.
void half_gradients(const RenderPart& part, ReconstructionInput& in) {
  const char* names[4] = {"Gradient X A", "Gradient X B", "Gradient Y A", "Gradient Y B"};
  const float** fields[4] = {&in.gradient_x_a, &in.gradient_x_b, &in.gradient_y_a,
                             &in.gradient_y_b};
  int present = 0;
  for (const char* name : names) present += int(part.passes.count(name));
  if (present == 0) return;
  const char* why = "the Feature reconstruction needs with the other half gradients";
  for (int k = 0; k < 4; ++k) *fields[k] = pass_data(part, names[k], 3, why);
}

}  // namespace

std::optional<ReconstructionNorm> norm_from_name(const std::string& name) {
  if (name == "L1") return ReconstructionNorm::L1;
  if (name == "L2") return ReconstructionNorm::L2;
  if (name == "WEIGHTED") return ReconstructionNorm::Weighted;
  if (name == "FEATURE") return ReconstructionNorm::Feature;
  if (name == "NONE") return ReconstructionNorm::None;
  return std::nullopt;
}

std::vector<float> rebuild_combined(const RenderPart& part, ReconstructionNorm norm, float alpha,
                                    int threads) {
  const size_t rgb = size_t(part.width) * size_t(part.height) * 3;
  const char* why = "Combined is rebuilt from";
  const float* primal = pass_data(part, "Primal", 3, why);
  const float* emission = pass_data(part, "Emission", 3, why);
  if (norm == ReconstructionNorm::None ||
      (part.record.mode == "PT" && norm != ReconstructionNorm::Feature)) {
    std::vector<float> out(rgb);
    for (size_t j = 0; j < rgb; ++j) out[j] = primal[j] + emission[j];
    return out;
  }
  ReconstructionInput in;
  in.width = part.width;
  in.height = part.height;
  in.primal = primal;
  in.emission = emission;
  in.gradient_x = pass_data(part, "Gradient X", 3, why);
  in.gradient_y = pass_data(part, "Gradient Y", 3, why);
  if (part.passes.count("Variance")) in.variance = pass_data(part, "Variance", 3, why);
  if (norm == ReconstructionNorm::Feature) {
    const char* feature = "the Feature reconstruction needs";
    in.primal_a = pass_data(part, "Primal A", 3, feature);
    in.primal_b = pass_data(part, "Primal B", 3, feature);
    in.variance_a = pass_data(part, "Primal A Variance", 3, feature);
    in.variance_b = pass_data(part, "Primal B Variance", 3, feature);
    in.albedo = pass_data(part, "Denoising Albedo", 3, feature);
    in.albedo_variance = pass_data(part, "Denoising Albedo Variance", 3, feature);
    in.normal = pass_data(part, "Denoising Normal", 3, feature);
    in.normal_variance = pass_data(part, "Denoising Normal Variance", 3, feature);
    in.depth = pass_data(part, "Denoising Depth", 1, feature);
    in.depth_variance = pass_data(part, "Denoising Depth Variance", 1, feature);
    half_gradients(part, in);
  }
  ReconstructionSettings settings;
  settings.norm = norm;
  settings.alpha = alpha;
  settings.threads = threads;
  try {
    return reconstruct(in, settings);
  } catch (const std::invalid_argument& e) {
    throw MergeError(std::string("rebuilding Combined: ") + e.what());
  }
}

RenderPart merge_render_parts(const std::vector<RenderPart>& parts, const MergeSettings& settings) {
  if (parts.empty()) throw MergeError("nothing to merge");
  return Merger(parts, settings).run();
}

}  // namespace gdpt
