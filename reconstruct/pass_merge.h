// Merging renders of one frame that took disjoint sample ranges of the same seed (a render farm's
// split, RenderSettings::sample_offset) into the render of all their samples.
//
// Every pass the engine writes is a per-pixel mean over samples, a variance of such a mean, or
// one sample's value, so parts combine exactly from their means and per-pixel sample counts:
//   - means: weighted by the samples behind them (`Sample Count`; for Primal A / B and G-PT's
//     Gradient X / Y A / B the even / odd global sample indices of each part's range);
//   - variances of means: pooled by Chan et al.'s parallel formula, M2 = sum M2_k + sum n_k
//     (mean_k - mean)^2 with M2_k = V_k n_k (n_k - 1), from the matching mean pass (Variance's
//     primal entry from the luminance of Primal; G-PT's gradient entries from `Gradient Halves`,
//     which keeps each pixel's forward halves apart from the neighbours' backward halves);
//   - Shift Failures: weighted by the shift attempts (`Shift Attempts` per sample);
//   - Depth, IndexOB, IndexMA: the part with the lowest sample offset (sample 0's camera hit);
// then Combined's RGB is rebuilt from the merged passes with the engine's rule and settings
// (Combined = Primal + Emission for None and for PT; else solve(...) + Emission).
// Gradient X / Y are merged per pixel weighted by its own sample count, which is exact when
// neighbours took the same samples (always within one engine render).
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "reconstruct/reconstruct.h"

namespace gdpt {

// Parts that cannot be merged (sizes, passes, seeds, overlapping ranges); what() says why.
struct MergeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// What the engine records of a render (multilayer EXR header `gdpt.<view layer>.<key>`).
struct RenderRecord {
  std::string mode = "GPT";  // "GPT" or "PT"
  uint32_t seed = 0;
  uint32_t sample_offset = 0;  // the first global sample index
  std::string reconstruction;  // "L1", "L2", "WEIGHTED", "FEATURE" or "NONE"
  float alpha = 0.2f;          // the reconstruction's alpha
  // Where the feature passes' halves split the frame's sample sequence (Film::half_split); 0:
  // not recorded (renders without the feature passes, or older renders).
  uint32_t half_split = 0;
};

// One pass: `channels` floats per pixel, interleaved, row 0 at the bottom.
struct PassImage {
  int channels = 0;
  std::vector<float> data;
};

// One render (part) of one view layer: its passes by Blender name ("Combined" is RGBA).
struct RenderPart {
  std::string name;  // where it came from (a file name), for messages
  int width = 0, height = 0;
  RenderRecord record;
  std::map<std::string, PassImage> passes;
};

struct MergeSettings {
  // Override the recorded reconstruction (e.g. to rebuild Combined with another norm).
  std::optional<ReconstructionNorm> norm;
  std::optional<float> alpha;
  int threads = 0;  // 0 = all cores
};

// Parses a recorded reconstruction name; std::nullopt for an unknown one.
std::optional<ReconstructionNorm> norm_from_name(const std::string& name);

// The merged render; its record has the lowest sample offset. Throws MergeError when the parts
// differ in size, seed, mode, reconstruction or passes, when their sample ranges overlap, or when
// a pass the merge needs is missing.
RenderPart merge_render_parts(const std::vector<RenderPart>& parts,
                              const MergeSettings& settings = {});

// Combined's RGB from a render's passes by the engine's rule (see above), `norm` and `alpha`.
std::vector<float> rebuild_combined(const RenderPart& part, ReconstructionNorm norm, float alpha,
                                    int threads);

}  // namespace gdpt
