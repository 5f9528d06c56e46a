// G-PT + L2 screened-Poisson reconstruction (reconstruct/reconstruct.h) converges to the PT
// reference: the L2 solve is unbiased, so at high sample counts the relative MSE of the
// reconstruction against a converged PT image is small, and smaller than that of the G-PT primal
// alone (the gradients carry information).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "reconstruct/reconstruct.h"
#include "testing/gradient_scenes.h"

namespace gdpt::gradient_test {
namespace {

TEST(GradientReconstruct, L2ConvergesToPathTracedReference) {
  const Scene scene = make_scene(SceneKind::CornellDiffuse, 16);
  const Passes ref = render(scene, settings(RenderSettings::Mode::PT, 8192, 21));
  const Passes g = render(scene, settings(RenderSettings::Mode::GPT, 1024, 22));
  const std::vector<float> img = reconstruct_l2(g);
  const double e_rec = rel_mse(img, ref.primal);
  const double e_primal = rel_mse(g.primal, ref.primal);
  std::printf("relMSE vs PT reference: G-PT + L2 %.3g, G-PT primal alone %.3g\n", e_rec, e_primal);
  EXPECT_LT(e_rec, 1e-3);
  EXPECT_LT(e_rec, e_primal);
}

}  // namespace
}  // namespace gdpt::gradient_test
