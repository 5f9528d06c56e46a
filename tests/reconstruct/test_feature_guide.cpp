// The Feature reconstruction's L1 guide is solved at its own number of reweightings
// (ReconstructionSettings::feature_guide_l1_reweightings), not at the L1 norm's: the filters need
// no fully converged L1, and the cheaper guide must cost no accuracy.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
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

}  // namespace
}  // namespace gdpt
