#include "reconstruct/candidate_selection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

void candidate_error(const FeatureBuffers& fb, const float* fa, const float* fb_half, float* error,
                     const float* weight, float* relative) {
  const int W = fb.width;
  parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      float e = 0.f, r = 0.f;
      if (fb.valid[i] & kImagesValid) {
        for (int c = 0; c < 3; ++c) {
          const size_t k = 3 * i + c;
          const float da = fa[k] - fb.b[k], db = fb_half[k] - fb.a[k], dd = fa[k] - fb_half[k];
          const float ec = 0.5f * (da * da + db * db) - fb.half_var[k] - 0.25f * dd * dd;
          e += ec;
          if (weight) r += weight[k] * ec;
        }
      }
      error[i] = e * (1.f / 3.f);
      if (relative) relative[i] = r * (1.f / 3.f);
    }
  });
}

void set_relative_weights(const FeatureBuffers& fb, const float* guide, CandidateChoice& choice) {
  const int W = fb.width;
  choice.weight.resize(3 * size_t(W) * fb.height);
  parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t k = 3 * size_t(y0) * W; k < 3 * size_t(y1) * W; ++k)
      choice.weight[k] = 1.f / (guide[k] * guide[k] + kRelativeErrorEpsilon);
  });
}

void offer_candidate(const FeatureBuffers& fb, int index, const float* fa, const float* fb_half,
                     const float* filtered, CandidateChoice& choice) {
  const int W = fb.width, H = fb.height;
  const size_t n = size_t(W) * H;
  const bool weighted = !choice.weight.empty();
  if (size_t(index) != choice.images.size())
    throw std::logic_error("offer_candidate: candidates must be offered in index order");
  // Scratch and keys are written in full before they are read: no zeroing of image-sized buffers.
  if (!choice.scratch) choice.scratch.reset(new float[3 * n]);
  float* const raw = choice.scratch.get();
  choice.keys.emplace_back(new float[n]);
  float* const key = choice.keys.back().get();
  candidate_error(fb, fa, fb_half, raw, weighted ? choice.weight.data() : nullptr, raw + n);
  // Without weights the key is the smoothed absolute estimate itself.
  float* const smooth = weighted ? raw + 2 * n : key;
  box_filter(raw, 1, W, H, kErrorSmoothingRadius, smooth);
  if (weighted) box_filter(raw + n, 1, W, H, kErrorSmoothingRadius, key);
  choice.images.push_back(filtered);
  const bool first = choice.image.empty();
  if (first) {
    choice.image.resize(3 * n);
    choice.error.resize(n);
    choice.relative.resize(n);
    choice.index.resize(n);
  }
  parallel_rows(H, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      if (!first && !(key[i] < choice.relative[i])) continue;
      choice.error[i] = smooth[i];
      choice.relative[i] = key[i];
      choice.index[i] = uint8_t(index);
      for (int c = 0; c < 3; ++c) choice.image[3 * i + c] = filtered[3 * i + c];
    }
  });
}

void blend_choices(const FeatureBuffers& fb, CandidateChoice& choice) {
  const int W = fb.width, H = fb.height;
  const size_t n = size_t(W) * H;
  std::vector<float> sum(3 * n, 0.f), total(n, 0.f), chose(n), share(n);
  std::vector<size_t> pixels_chose(choice.images.size(), 0);
  for (uint8_t k : choice.index) ++pixels_chose[k];
  for (size_t k = 0; k < choice.images.size(); ++k) {
    // A candidate no pixel chose has a zero share everywhere: it adds nothing.
    if (pixels_chose[k] == 0) continue;
    parallel_rows(H, [&](int y0, int y1) {
      for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i)
        chose[i] = choice.index[i] == k ? 1.f : 0.f;
    });
    box_filter(chose.data(), 1, W, H, kErrorSmoothingRadius, share.data());
    const float* key = choice.keys[k].get();
    const float* image = choice.images[k];
    parallel_rows(H, [&](int y0, int y1) {
      for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
        const float best = choice.relative[i];
        if (!(share[i] > 0.f) || !(key[i] <= best + kBlendTolerance * std::fabs(best))) continue;
        total[i] += share[i];
        for (int c = 0; c < 3; ++c) sum[3 * i + c] += share[i] * image[3 * i + c];
      }
    });
  }
  // The chosen candidate always takes part (its share at its own pixel is positive).
  parallel_rows(H, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i)
      for (int c = 0; c < 3; ++c) choice.image[3 * i + c] = sum[3 * i + c] / total[i];
  });
  choice.images.clear();
  choice.keys.clear();
}

}  // namespace gdpt::detail
