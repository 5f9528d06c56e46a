// Directional albedo of one material as GDPT's shaders compute it, for comparison with Cycles
// (cycles_albedo.sh): the integral of eval(wi, .) over the sphere by adaptive quadrature, plus
// the delta lobes' weight by Monte Carlo. Same CASE syntax as cycles_furnace.py; a negative COS
// is a back-face hit (frame oriented towards the ray, front_facing = false, as the integrators).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "shaders/material.h"
#include "testing/chi2.h"  // Integrator2D, Pcg32, direction()

using namespace gdpt;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: shaders_albedo CASE COS\n");
    return 2;
  }
  std::vector<std::string> p;
  std::stringstream ss(argv[1]);
  for (std::string tok; std::getline(ss, tok, '_');) p.push_back(tok);
  const float cos_t = std::stof(argv[2]);
  auto f = [&](size_t i) { return std::stof(p.at(i)); };

  ShaderNode n;
  n.color = ColorInput(Spectrum(1.0f));
  if (p[0] == "glossy" || p[0] == "diffuse") {
    n.kind = p[0] == "glossy" ? ShaderNodeKind::Glossy : ShaderNodeKind::Diffuse;
    n.roughness = FloatInput(f(1));
  } else if (p[0] == "glass") {
    n.kind = ShaderNodeKind::Glass;
    n.roughness = FloatInput(f(1));
    n.ior = FloatInput(f(2));
  } else if (p[0] == "ptrans") {
    n.kind = ShaderNodeKind::Principled;
    n.color = ColorInput(Spectrum(f(1), f(2), f(3)));
    n.specular_tint = FloatInput(f(4));
    n.roughness = FloatInput(f(5));
    n.ior = FloatInput(f(6));
    n.transmission = FloatInput(f(7));
  } else if (p[0] == "principled") {
    n.kind = ShaderNodeKind::Principled;
    n.color = ColorInput(Spectrum(f(1), f(2), f(3)));
    n.metallic = FloatInput(f(4));
    n.specular = FloatInput(f(5));
    n.specular_tint = FloatInput(f(6));
    n.roughness = FloatInput(f(7));
  } else {
    std::fprintf(stderr, "unknown case %s\n", argv[1]);
    return 2;
  }
  MaterialDesc d;
  d.nodes.push_back(n);
  d.root = 0;
  const Material m(d, {});
  ClosureSet cs;
  m.evaluate(ShadingContext{{0.0f, 0.0f}, cos_t > 0.0f}, cs);
  const Vec3f wi(std::sqrt(1.0f - cos_t * cos_t), 0.0f, std::fabs(cos_t));

  for (int ch = 0; ch < 3; ++ch) {
    test::Integrator2D integ([&](double theta, double phi) {
      return double(cs.eval(wi, test::direction(std::cos(theta), phi))[ch]) * std::sin(theta);
    });
    double sum = 0.0;
    for (int h = 0; h < 2; ++h)
      for (int k = 0; k < 8; ++k)
        sum += integ.integrate(h * M_PI / 2, (h + 1) * M_PI / 2, k * M_PI / 4, (k + 1) * M_PI / 4,
                               1e-9, 3, 10);
    if (cs.has_delta()) {
      const int samples = 400000;
      test::Pcg32 rng(1);
      double mc = 0.0;
      for (int i = 0; i < samples; ++i) {
        const BsdfSample s = cs.sample(wi, rng.uniform(), {rng.uniform(), rng.uniform()});
        if (s.valid && s.is_delta()) mc += s.weight()[ch];
      }
      sum += mc / samples;
    }
    std::printf("%.5f%s", sum, ch < 2 ? " " : "\n");
  }
  return 0;
}
