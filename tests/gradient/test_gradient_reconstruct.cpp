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

// With Cycles' default pixel filter (Blackman-Harris 1.5) on both: the offsets take the base's
// filter sample moved by one pixel, so the gradients are those of the filtered image and the L2
// solve converges to the filtered PT image, not to the box-filtered one (which differs by more).
TEST(GradientReconstruct, L2ConvergesWithBlackmanHarrisFilter) {
  const Scene scene = make_scene(SceneKind::CornellDiffuse, 16);
  auto filtered = [](RenderSettings s) {
    s.pixel_filter = PixelFilterType::BlackmanHarris;
    s.filter_width = 1.5f;
    return s;
  };
  const Passes ref = render(scene, filtered(settings(RenderSettings::Mode::PT, 8192, 21)));
  const Passes box = render(scene, settings(RenderSettings::Mode::PT, 8192, 23));
  const Passes g = render(scene, filtered(settings(RenderSettings::Mode::GPT, 1024, 22)));
  const std::vector<float> img = reconstruct_l2(g);
  const double e_rec = rel_mse(img, ref.primal);
  const double e_primal = rel_mse(g.primal, ref.primal);
  const double e_box = rel_mse(box.primal, ref.primal);
  std::printf("relMSE vs filtered PT: G-PT + L2 %.3g, G-PT primal %.3g, box-filtered PT %.3g\n",
              e_rec, e_primal, e_box);
  EXPECT_LT(e_rec, 1e-3);
  EXPECT_LT(e_rec, e_primal);
  EXPECT_GT(e_box, 3.0 * e_rec);  // the filter is visible at this resolution
}

// Filter Glossy and caustics off (light_path_filters.h), which change the closures after blurry
// or diffuse bounces: the offsets shade by the base's path state, and the L2 solve still
// converges to PT with the same settings (rough and very smooth glossy objects; the images
// differ from the unfiltered PT image by more).
TEST(GradientReconstruct, L2ConvergesWithLightPathFilters) {
  struct Case {
    const char* name;
    float roughness, blur;
    bool caustics;
  };
  const Case cases[] = {{"filter-glossy rough", 0.3f, 1.0f, true},
                        {"filter-glossy smooth", 0.05f, 1.0f, true},
                        {"caustics-off rough", 0.3f, 0.0f, false},
                        {"caustics-off smooth", 0.05f, 0.0f, false}};
  for (const Case& k : cases) {
    const Scene scene = make_scene(SceneKind::CornellGlossy, 16, k.roughness);
    auto with_rules = [&](RenderSettings s) {
      s.blur_glossy = k.blur;
      s.caustics_reflective = s.caustics_refractive = k.caustics;
      return s;
    };
    const Passes ref = render(scene, with_rules(settings(RenderSettings::Mode::PT, 8192, 21)));
    const Passes plain = render(scene, settings(RenderSettings::Mode::PT, 8192, 23));
    const Passes g = render(scene, with_rules(settings(RenderSettings::Mode::GPT, 1024, 22)));
    const std::vector<float> img = reconstruct_l2(g);
    const double e_rec = rel_mse(img, ref.primal);
    const double e_plain = rel_mse(plain.primal, ref.primal);
    std::printf(
        "[%s] relMSE vs PT with the rule: G-PT + L2 %.3g, G-PT primal %.3g, "
        "PT without the rule %.3g\n",
        k.name, e_rec, rel_mse(g.primal, ref.primal), e_plain);
    EXPECT_LT(e_rec, 1e-3) << k.name;
    EXPECT_GT(e_plain, 3.0 * e_rec) << k.name;  // the rule is visible in this scene
  }
}

}  // namespace
}  // namespace gdpt::gradient_test
