// Render settings shared by the add-on (scene.gdpt), the tests and the benchmarks.
#pragma once

#include <cstdint>

namespace gdpt {

// Cycles' pixel filters (Film > Pixel Filter), importance-sampled (render/pixel_filter.h).
enum class PixelFilterType : uint8_t { Box, Gaussian, BlackmanHarris };

struct RenderSettings {
  enum class Mode : uint8_t { PT, GPT } mode = Mode::GPT;
  int samples = 64;         // samples per pixel
  double time_limit = 0.0;  // seconds, 0 = none
  int max_bounces = 8;      // path segments after the camera ray
  // Per-kind limits (Cycles' Diffuse / Glossy / Transmission bounces; bounce_limits.h). The core's
  // defaults leave only max_bounces in force; the add-on passes Blender's settings.
  int max_diffuse_bounces = 1 << 20, max_glossy_bounces = 1 << 20,
      max_transmission_bounces = 1 << 20;
  uint32_t seed = 0;
  // First sample index (Cycles' Sample Offset): the render takes samples sample_offset ..
  // sample_offset + samples - 1 of the seed's sequence, so renders of disjoint ranges are
  // independent parts of one render and merge exactly (reconstruct/pass_merge.h).
  uint32_t sample_offset = 0;
  // The samples of the whole frame when renders of disjoint ranges make it up (a farm's total; 0:
  // sample_offset + samples). The feature passes' halves split the frame's sample sequence at its
  // middle (core/sample_halves.h), so every part of one frame must give the same total.
  uint32_t frame_samples = 0;
  // Film > Pixel Filter, Cycles' meaning of the width (pixel_filter.h). The core's default is the
  // box over the pixel; the add-on passes scene.gdpt's (Cycles' default: Blackman-Harris 1.5).
  PixelFilterType pixel_filter = PixelFilterType::Box;
  float filter_width = 1.0f;
  // Light Paths > Caustics (integrators/common/light_path_filters.h): Filter Glossy (Cycles'
  // blur_glossy; 0 = off, the core's default; Cycles' and the add-on's is 1) and the reflective /
  // refractive caustics toggles.
  float blur_glossy = 0.0f;
  bool caustics_reflective = true, caustics_refractive = true;
  int threads = 0;                           // 0 = all cores
  float clamp = 0.0f;                        // max sample value, 0 = off
  int rr_depth = 3;                          // Russian roulette from this vertex on
  float shift_roughness_threshold = 0.001f;  // G-PT: GGX alpha below this = specular vertex
  // Blender's Film > Transparent: the world seen directly by the camera is left out of the image,
  // and the film's alpha is the fraction of the pixel covered by surfaces (Film::alpha).
  bool transparent_background = false;
  // Blender's Normal and Mist data passes (View Layer > Passes > Data), as Cycles computes them
  // (integrators/common/data_passes.h); off: no cost. Mist: World > Mist Pass start, depth
  // (distances from the camera) and falloff exponent (2 quadratic, 1 linear, 0.5 inverse
  // quadratic).
  bool normal_pass = false;
  bool mist_pass = false;
  float mist_start = 5.0f, mist_depth = 25.0f, mist_falloff = 2.0f;
  // The Feature reconstruction's passes (integrators/common/feature_passes.h): Denoising Albedo /
  // Normal / Depth with their variances, and the primal as two halves (even / odd sample index);
  // off: no cost.
  bool feature_passes = false;
  int samples_per_pass = 1;  // progressive granularity (a pass = this many spp over the image)
  // Adaptive sampling (Cycles' Noise Threshold; integrators/adaptive_sampling.h): after each pass
  // from adaptive_min_samples on, a pixel whose relative noise is below the threshold and whose
  // neighbours' is too stops taking samples. 0 = off (every pixel takes `samples`).
  // adaptive_min_samples 0 = automatic (a quarter of `samples`, 4 to 64).
  float adaptive_threshold = 0.0f;
  int adaptive_min_samples = 0;
  // Debug / benchmark: run the kernel with every feature path on (same image, slower), to measure
  // what the per-scene specialisation buys.
  bool force_all_features = false;
};

}  // namespace gdpt
