#include "reconstruct/candidate_selection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

void candidate_error(const FeatureBuffers& fb, const float* fa, const float* fb_half, float* error,
                     const float* weight, float* relative) {
  const int W = fb.width;
  parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i)
      pixel_error(fb, i, fa + 3 * i, fb_half + 3 * i, weight, error, relative);
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
  const size_t n = size_t(fb.width) * fb.height;
  const bool weighted = !choice.weight.empty();
  // Written in full before they are read: no zeroing of image-sized buffers.
  FreshHugeVector<float> error(n), relative(weighted ? n : 0);
  candidate_error(fb, fa, fb_half, error.data(), weighted ? choice.weight.data() : nullptr,
                  relative.data());
  offer_estimates(fb, index, error.data(), std::move(relative), filtered, choice);
}

void offer_estimates(const FeatureBuffers& fb, int index, float* error,
                     FreshHugeVector<float> relative, const float* filtered,
                     CandidateChoice& choice) {
  const int W = fb.width, H = fb.height;
  const size_t n = size_t(W) * H;
  if (size_t(index) != choice.images.size())
    throw std::logic_error("offer_candidate: candidates must be offered in index order");
  // In place: box_filter reads its source in full before it writes.
  box_filter(error, 1, W, H, kErrorSmoothingRadius, error);
  const float* const smooth = error;
  if (choice.weight.empty()) {  // the key is the smoothed absolute estimate itself
    relative.resize(n);
    parallel_rows(H, [&](int y0, int y1) {
      std::copy(error + size_t(y0) * W, error + size_t(y1) * W, relative.begin() + size_t(y0) * W);
    });
  } else {
    box_filter(relative.data(), 1, W, H, kErrorSmoothingRadius, relative.data());
  }
  choice.keys.push_back(std::move(relative));
  const float* const key = choice.keys.back().data();
  choice.images.push_back(filtered);
  const bool first = choice.image.empty();
  if (first) {  // all written below (the image, error and index are handed on as std::vectors)
    resize_huge(choice.image, 3 * n);
    resize_huge(choice.error, n);
    choice.relative.resize(n);
    resize_huge(choice.index, n);
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
  FreshHugeVector<float> sum(3 * n), total(n), chose(n), share(n);
  parallel_rows(H, [&](int y0, int y1) {
    std::fill(sum.begin() + 3 * size_t(y0) * W, sum.begin() + 3 * size_t(y1) * W, 0.f);
    std::fill(total.begin() + size_t(y0) * W, total.begin() + size_t(y1) * W, 0.f);
  });
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
    const float* key = choice.keys[k].data();
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
