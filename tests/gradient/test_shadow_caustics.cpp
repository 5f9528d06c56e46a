// Shadow caustics (manifold next-event estimation, integrators/common/manifold_nee.h) on a glass
// ball above a diffuse floor under a small area lamp (testing/gradient_scenes.h,
// make_caustic_scene). The oracle is path tracing without the flags, which finds the caustic by
// BSDF sampling alone: with the flags the same light must arrive (within the technique's stated
// bias: chains the walk does not reach from the straight seed are missing) with far less noise,
// and the flags must change nothing where they do not apply. G-PT with the flags against PT
// with them: tests/gradient/test_gradient_unbiased.cpp (ShadowCaustics).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "integrators/common/manifold_nee.h"
#include "render/scene_context.h"
#include "testing/gradient_scenes.h"

namespace gdpt {
namespace {

using namespace gradient_test;

struct Sums {
  double total = 0.0, squared_error = 0.0;
};

// The image's summed luminance and its squared error against `ref`.
Sums compare(const Passes& img, const Passes& ref) {
  Sums s;
  for (int y = 0; y < img.h; ++y)
    for (int x = 0; x < img.w; ++x) {
      const double v = img.lum(img.primal, x, y), r = ref.lum(ref.primal, x, y);
      s.total += v;
      s.squared_error += (v - r) * (v - r);
    }
  return s;
}

// A small lamp (0.1 m), whose image through the ball BSDF sampling rarely finds, and a larger
// one (0.3 m), whose image it finds often: at 64 samples (seeds 1-4) manifold NEE weighed against
// BSDF sampling has a fraction of path tracing's squared error (0.20x and 0.22x when written) and
// its light (mean of the seeds) within a few percent of the reference (plain PT at 65536
// samples). Where the refracted light folds (the caustic's bright curves) the generalized
// geometry term is very large and BSDF sampling takes over: manifold NEE alone, every
// BSDF-sampled copy of its paths dropped, had 1.9x path tracing's error with the larger lamp.
TEST(ShadowCaustics, PaysForSmallAndLargerLamps) {
  for (float lamp : {0.1f, 0.3f}) {
    const Passes ref = render(make_caustic_scene(24, false, 1.5f, 1.0f, lamp),
                              settings(RenderSettings::Mode::PT, 65536, 7));
    const double ref_total = compare(ref, ref).total;
    double plain_error = 0.0, mnee_error = 0.0, mnee_light = 0.0;
    for (uint32_t seed = 1; seed <= 4; ++seed) {
      const Passes plain = render(make_caustic_scene(24, false, 1.5f, 1.0f, lamp),
                                  settings(RenderSettings::Mode::PT, 64, seed));
      const Passes mnee = render(make_caustic_scene(24, true, 1.5f, 1.0f, lamp),
                                 settings(RenderSettings::Mode::PT, 64, seed));
      const Sums p = compare(plain, ref), m = compare(mnee, ref);
      plain_error += p.squared_error;
      mnee_error += m.squared_error;
      mnee_light += m.total / ref_total / 4.0;
    }
    std::printf("lamp %.1f m: light %.4f of the reference; squared error %.4g (plain PT %.4g)\n",
                lamp, mnee_light, mnee_error, plain_error);
    EXPECT_NEAR(mnee_light, 1.0, 0.06) << lamp;
    EXPECT_LT(mnee_error, 0.35 * plain_error) << lamp;
  }
}

// Every path counted once: where several refracted paths join a lamp point to a floor point
// (IOR 1.3, the ball's aberration caustic on the floor) the walk from the straight seed finds one
// of them, and BSDF sampling keeps the others (CausticChain): at 1024 samples the light is
// 1.032 of the reference's (0.48 when every such BSDF-sampled path was dropped, as Cycles does);
// with the lamp focused on the floor (IOR 1.5) 0.986. Both estimates are heavy-tailed (the
// geometry term at the caustic's folds): over seeds 1-5, 0.99-1.08 and 0.99-1.03.
TEST(ShadowCaustics, EveryPathCountedOnce) {
  for (float ior : {1.5f, 1.3f}) {
    const Passes ref =
        render(make_caustic_scene(24, false, ior), settings(RenderSettings::Mode::PT, 16384, 7));
    const Passes mnee =
        render(make_caustic_scene(24, true, ior), settings(RenderSettings::Mode::PT, 1024, 1));
    const double ratio = compare(mnee, ref).total / compare(ref, ref).total;
    std::printf("IOR %.1f: light %.4f of the reference\n", ior, ratio);
    EXPECT_NEAR(ratio, 1.0, 0.06) << ior;
  }
}

// Filter Glossy leaves the casters' smooth glass sharp (light_path_filters.h): on this scene,
// whose only glossy surface is the ball, the render with Filter Glossy 1 is the unblurred one,
// its light that of plain PT without blur. (When the casters blurred, BSDF sampling and the
// light samples at the rough glass counted the caustic a second time: 1.40 of the light.)
TEST(ShadowCaustics, FilterGlossyKeepsCastersSharp) {
  const Passes ref =
      render(make_caustic_scene(24, false), settings(RenderSettings::Mode::PT, 16384, 7));
  RenderSettings s = settings(RenderSettings::Mode::PT, 1024, 1);
  s.blur_glossy = 1.0f;
  const Passes mnee = render(make_caustic_scene(24, true), s);
  const double ratio = compare(mnee, ref).total / compare(ref, ref).total;
  std::printf("Filter Glossy 1: light %.4f of the unblurred reference\n", ratio);
  EXPECT_NEAR(ratio, 1.0, 0.06);
}

// Without Refractive Caustics BSDF sampling drops refraction after a diffuse bounce, so manifold
// NEE carries the floor's caustic alone (Cycles' rule, weight 1). Against plain PT with
// refractive caustics the light lacks only what BSDF sampling alone finds (refracted paths the
// walk misses, caustics of indirect light): 0.95 when written. Weighed as when BSDF sampling
// takes its share, that share goes missing too: 0.85.
TEST(ShadowCaustics, WithoutRefractiveCausticsManifoldNeeAlone) {
  const Passes ref =
      render(make_caustic_scene(24, false), settings(RenderSettings::Mode::PT, 16384, 7));
  RenderSettings s = settings(RenderSettings::Mode::PT, 1024, 1);
  s.caustics_refractive = false;
  const Passes mnee = render(make_caustic_scene(24, true), s);
  const double ratio = compare(mnee, ref).total / compare(ref, ref).total;
  std::printf("Refractive Caustics off: light %.4f of the reference\n", ratio);
  EXPECT_GT(ratio, 0.90);
  EXPECT_LT(ratio, 1.02);
}

// Without all three flags (a caster, a receiver and a caustics lamp) nothing changes: the
// renders are bit-identical to the scene without flags, PT and G-PT.
TEST(ShadowCaustics, IncompleteFlagsChangeNothing) {
  const Scene none = make_caustic_scene(12, false);
  for (int missing = 0; missing < 3; ++missing) {
    Scene s = make_caustic_scene(12, true);
    if (missing == 0) s.instances[0].caustics_receiver = false;
    if (missing == 1) s.instances[1].caustics_caster = false;
    if (missing == 2) s.lights[0].caustics_light = false;
    for (auto mode : {RenderSettings::Mode::PT, RenderSettings::Mode::GPT}) {
      const Passes a = render(none, settings(mode, 16, 3)), b = render(s, settings(mode, 16, 3));
      EXPECT_EQ(a.primal, b.primal) << missing;
      EXPECT_EQ(a.dx, b.dx) << missing;
    }
  }
}

// The generalized geometry term against finite differences: moving the light point by small
// steps moves the receiver's direction to the first caster vertex; the solid angle swept per unit
// area of the light is d omega / d A(y), which the transport carries times the lamp's radiance
// and the casters' transmittances (about the same for every point of a weak lens, IOR 1.1: the
// four ratios agree within 0.05% when written; near a focus the finite differences do not).
TEST(ShadowCaustics, GeometryTermMatchesFiniteDifferences) {
  {
    const float ior = 1.1f;
    const Scene scene = make_caustic_scene(8, true, ior, 1.0f);
    RenderSettings rs;
    const SceneContext ctx(scene, rs);
    ClosureSet scratch;
    uint32_t rays = 0;
    std::vector<double> ratios;
    for (Vec3f x : {Vec3f(0.0f, 0.01f, 0.0f), Vec3f(0.03f, 0.01f, 0.0f), Vec3f(0.08f, 0.01f, 0.0f),
                    Vec3f(0.15f, 0.01f, 0.0f)}) {
      auto connect = [&](Vec3f y) {
        LightSample ls;
        ls.position = y;
        ls.normal = Vec3f(0, 0, -1);
        ls.distance = length(y - x);
        ls.direction = (y - x) / ls.distance;
        ls.pdf = 1.0f;
        ls.area_pdf = 1.0f;
        ls.caustics = true;
        ls.valid = true;
        return caustic_connection(ctx, x, Vec3f(0, 0, 1), ls, scratch, rays);
      };
      const Vec3f y(0.02f, -0.03f, 3.0f);
      const float eps = 1e-3f;
      const CausticConnection c0 = connect(y), c1 = connect(y + Vec3f(eps, 0, 0)),
                              c2 = connect(y + Vec3f(0, eps, 0));
      ASSERT_TRUE(c0.valid && c1.valid && c2.valid) << ior << " " << x.x;
      const double solid_angle =
          length(cross(c1.direction - c0.direction, c2.direction - c0.direction)) / (eps * eps);
      ratios.push_back(c0.transport.x / solid_angle);
    }
    // transport / (d omega / d A) = transmittance x radiance: one value for the four points.
    for (double r : ratios) {
      std::printf("IOR %.1f: transport / finite difference %.4f\n", ior, r);
      EXPECT_NEAR(r / ratios[0], 1.0, 0.01) << ior;
    }
  }
}

}  // namespace
}  // namespace gdpt
