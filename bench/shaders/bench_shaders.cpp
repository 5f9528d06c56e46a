// Cost of the shading hot path: Material::evaluate into a ClosureSet, then the BSDF queries a
// path vertex makes (one sample, one eval + pdf for next-event estimation), for a diffuse, a
// Principled (diffuse + specular) and a glass material; and an image texture's bilinear lookup at
// random coordinates (what a textured surface costs per hit). Prints ns per operation.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "shaders/material.h"
#include "shaders/texture.h"

namespace gdpt {
namespace {

// Cheap reproducible numbers in [0, 1).
struct Lcg {
  uint32_t s = 12345u;
  float next() {
    s = s * 1664525u + 1013904223u;
    return float(s >> 8) * (1.0f / 16777216.0f);
  }
};

MaterialDesc single(ShaderNode n) {
  MaterialDesc d;
  d.nodes.push_back(n);
  d.root = 0;
  return d;
}

Material make(int which) {
  ShaderNode n;
  switch (which) {
    case 0:
      n.kind = ShaderNodeKind::Diffuse;
      n.roughness = FloatInput(0.0f);
      break;
    case 1:
      n.kind = ShaderNodeKind::Principled;
      n.roughness = FloatInput(0.4f);
      break;
    default:
      n.kind = ShaderNodeKind::Glass;
      n.roughness = FloatInput(0.2f);
      n.ior = FloatInput(1.5f);
      break;
  }
  return Material(single(n), {});
}

const char* kNames[] = {"Diffuse", "Principled", "RoughGlass"};

void BM_Evaluate(benchmark::State& state) {
  const Material m = make(int(state.range(0)));
  ClosureSet cs;
  for (auto _ : state) {
    m.evaluate(ShadingContext{{0.3f, 0.6f}, true}, cs);
    benchmark::DoNotOptimize(cs);
  }
  state.SetLabel(kNames[state.range(0)]);
}

// One path vertex: sample a continuation and evaluate eval + pdf towards a light direction.
void BM_Vertex(benchmark::State& state) {
  const Material m = make(int(state.range(0)));
  ClosureSet cs;
  m.evaluate(ShadingContext{{0.3f, 0.6f}, true}, cs);
  Lcg rng;
  const Vec3f wi = normalize(Vec3f(0.3f, 0.2f, 0.9f));
  for (auto _ : state) {
    const BsdfSample s = cs.sample(wi, rng.next(), Vec2f(rng.next(), rng.next()));
    const Vec3f wl = normalize(Vec3f(rng.next() - 0.5f, rng.next() - 0.5f, 0.5f));
    const Spectrum f = cs.eval(wi, wl);
    const float p = cs.pdf(wi, wl);
    benchmark::DoNotOptimize(s);
    benchmark::DoNotOptimize(f);
    benchmark::DoNotOptimize(p);
  }
  state.SetLabel(kNames[state.range(0)]);
}

// A 256x256 sRGB image of random 8-bit values (kept as 8-bit codes, texture.h) or, with range 1,
// of random floats (kept as float RGBA): bilinear Repeat lookups at random coordinates, so that
// the texels come from the caches as they do along incoherent paths.
void BM_TextureLookup(benchmark::State& state) {
  const bool coded = state.range(0) == 0;
  ImageDesc img;
  img.name = "bench";
  img.width = img.height = 256;
  img.srgb_encoded = coded;
  img.rgba.resize(size_t(img.width) * size_t(img.height) * 4);
  Lcg rng;
  for (size_t i = 0; i < img.rgba.size(); ++i)
    img.rgba[i] = coded ? float(uint32_t(rng.next() * 256.0f)) / 255.0f : rng.next();
  const Texture tex(img);
  std::vector<Vec2f> uv(4096);
  for (Vec2f& p : uv) p = {rng.next() * 3.0f - 1.0f, rng.next() * 3.0f - 1.0f};
  size_t i = 0;
  for (auto _ : state) {
    const Rgba c = tex.lookup(uv[i++ & 4095], TextureLookup::Interpolation::Linear,
                              TextureLookup::Extension::Repeat);
    benchmark::DoNotOptimize(c);
  }
  state.SetLabel(tex.coded() ? "8-bit sRGB" : "float");
}

BENCHMARK(BM_Evaluate)->DenseRange(0, 2);
BENCHMARK(BM_TextureLookup)->DenseRange(0, 1);
BENCHMARK(BM_Vertex)->DenseRange(0, 2);

}  // namespace
}  // namespace gdpt

BENCHMARK_MAIN();
