// The Feature reconstruction's gradient-domain images: the L1 guide is solved at its own number of
// reweightings (ReconstructionSettings::feature_guide_l1_reweightings), not at the L1 norm's (the
// filters need no fully converged L1, and the cheaper guide must cost no accuracy); with the
// variance buffer the Weighted solution is one more candidate.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <vector>

#include "reconstruct/reconstruct.h"
#include "testing/feature_scene.h"

namespace gdpt {
namespace {

bool same_bits(const std::vector<float>& x, const std::vector<float>& y) {
  return x.size() == y.size() && std::memcmp(x.data(), y.data(), x.size() * sizeof(float)) == 0;
}

TEST(FeatureGuide, SolvesTheL1GuideAtItsOwnReweightings) {
  const test::FeatureScene s = test::make_feature_scene(256, 192, 0.2f, 0.1f, 61);
  ReconstructionSettings settings;
  settings.norm = ReconstructionNorm::Feature;
  ASSERT_LT(settings.feature_guide_l1_reweightings, settings.l1_reweightings);
  const std::vector<float> cheap = reconstruct(s.input(), settings);

  // The L1 norm's own schedule does not reach the guide.
  ReconstructionSettings other_l1 = settings;
  other_l1.l1_reweightings = settings.l1_reweightings / 2;
  EXPECT_TRUE(same_bits(reconstruct(s.input(), other_l1), cheap));

  // A guide at the L1 norm's reweightings is a different image, and no better.
  ReconstructionSettings converged = settings;
  converged.feature_guide_l1_reweightings = settings.l1_reweightings;
  const std::vector<float> full = reconstruct(s.input(), converged);
  EXPECT_FALSE(same_bits(full, cheap));
  const double e_cheap = test::relative_mse(cheap, s.truth);
  const double e_full = test::relative_mse(full, s.truth);
  std::printf("relMSE with the guide at %d reweightings %.5g, at %d %.5g\n",
              settings.feature_guide_l1_reweightings, e_cheap, settings.l1_reweightings, e_full);
  EXPECT_LT(e_cheap, 1.02 * e_full);
}

// The room with bump-like shading: each pixel's light scaled at random by 0.6-1.4, a detail no
// feature shows, so that the filters must keep every pixel as it is; its gradients 10x noisier
// over the left third than elsewhere, and the variance buffer (of the pixel means: primal, dx,
// dy) that says so. `bumpy` false: the plain room, where the filters of the L1 guide win.
struct NoisyGradientRoom {
  static constexpr float kHalf = 0.02f, kGradient = 0.005f, kExtra = 0.1f;  // noise sigmas
  test::FeatureScene s = test::make_feature_scene(256, 192, kHalf, kGradient, 67);
  std::vector<float> variance;

  explicit NoisyGradientRoom(bool bumpy) {
    std::mt19937 rng(68);
    std::uniform_real_distribution<float> bump(0.6f, 1.4f);
    if (bumpy) {
      for (size_t i = 0; i < s.truth.size(); i += 3) {
        const float f = bump(rng);
        for (int c = 0; c < 3; ++c) s.truth[i + c] *= f;
      }
      test::add_noise(s, kHalf, kGradient, 69);
    }
    std::normal_distribution<float> extra(0.f, kExtra * std::sqrt(2.f));  // per half
    variance.resize(s.primal.size());
    for (int y = 0; y < s.h; ++y)
      for (int x = 0; x < s.w; ++x) {
        const size_t i = size_t(y) * s.w + x;
        const bool noisy = 3 * x < s.w;
        for (int c = 0; c < 3; ++c) {
          const size_t k = 3 * i + c;
          if (noisy && x + 1 < s.w) s.gxa[k] += extra(rng), s.gxb[k] += extra(rng);
          if (noisy && y + 1 < s.h) s.gya[k] += extra(rng), s.gyb[k] += extra(rng);
          s.gx[k] = 0.5f * (s.gxa[k] + s.gxb[k]);
          s.gy[k] = 0.5f * (s.gya[k] + s.gyb[k]);
        }
        variance[3 * i] = kHalf * kHalf / 2.f;
        variance[3 * i + 1] = variance[3 * i + 2] =
            kGradient * kGradient + (noisy ? kExtra * kExtra : 0.f);
      }
  }
  ReconstructionInput input() const {
    ReconstructionInput in = s.input();
    in.variance = variance.data();
    return in;
  }
};

// Where the filters cannot average (shading detail no feature shows), the Weighted solution,
// which trusts the primal more where the gradients are noisy, is the better image; in the plain
// room the filters of the L1 guide are, and offering the candidate must not cost them.
TEST(FeatureGuide, WeightedCandidateWinsWhereFiltersCannotAverage) {
  ReconstructionSettings settings;
  settings.norm = ReconstructionNorm::Feature;
  ASSERT_TRUE(settings.feature_weighted_candidate);
  ReconstructionSettings off = settings;
  off.feature_weighted_candidate = false;
  for (bool bumpy : {true, false}) {
    const NoisyGradientRoom room(bumpy);
    const double e_with = test::relative_mse(reconstruct(room.input(), settings), room.s.truth);
    const double e_without = test::relative_mse(reconstruct(room.input(), off), room.s.truth);
    std::printf("%s: relMSE with the Weighted candidate %.5g, without %.5g\n",
                bumpy ? "bump-like shading" : "plain room", e_with, e_without);
    if (bumpy)
      EXPECT_LT(e_with, 0.8 * e_without);
    else
      EXPECT_LT(e_with, 1.03 * e_without);
  }
  // Without the variance buffer there is no such candidate: the same image as with it off.
  const NoisyGradientRoom room(true);
  EXPECT_TRUE(same_bits(reconstruct(room.s.input(), settings), reconstruct(room.s.input(), off)));
}

}  // namespace
}  // namespace gdpt
