#include "reconstruct/candidate_selection.h"

#include "reconstruct/parallel.h"

namespace gdpt::detail {

void candidate_error(const FeatureBuffers& fb, const float* fa, const float* fb_half,
                     float* error) {
  const int W = fb.width;
  parallel_rows(fb.height, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      if (!(fb.valid[i] & kImagesValid)) {
        error[i] = 0.f;
        continue;
      }
      float e = 0.f;
      for (int c = 0; c < 3; ++c) {
        const size_t k = 3 * i + c;
        const float da = fa[k] - fb.b[k], db = fb_half[k] - fb.a[k], dd = fa[k] - fb_half[k];
        e += 0.5f * (da * da + db * db) - fb.half_var[k] - 0.25f * dd * dd;
      }
      error[i] = e * (1.f / 3.f);
    }
  });
}

void offer_candidate(const FeatureBuffers& fb, int index, const float* fa, const float* fb_half,
                     const float* filtered, CandidateChoice& choice) {
  const int W = fb.width, H = fb.height;
  const size_t n = size_t(W) * H;
  std::vector<float> raw(n), smooth(n);
  candidate_error(fb, fa, fb_half, raw.data());
  box_filter(raw.data(), 1, W, H, kErrorSmoothingRadius, smooth.data());
  const bool first = choice.image.empty();
  if (first) {
    choice.image.resize(3 * n);
    choice.error.resize(n);
    choice.index.resize(n);
  }
  parallel_rows(H, [&](int y0, int y1) {
    for (size_t i = size_t(y0) * W; i < size_t(y1) * W; ++i) {
      if (!first && !(smooth[i] < choice.error[i])) continue;
      choice.error[i] = smooth[i];
      choice.index[i] = uint8_t(index);
      for (int c = 0; c < 3; ++c) choice.image[3 * i + c] = filtered[3 * i + c];
    }
  });
}

}  // namespace gdpt::detail
