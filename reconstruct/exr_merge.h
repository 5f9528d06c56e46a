// gdpt-merge's file level: multilayer EXRs of disjoint sample ranges (the engine's output, with
// its `gdpt.<view layer>.*` header attributes) -> one EXR of all their samples
// (reconstruct/pass_merge.h merges each view layer).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "reconstruct/pass_merge.h"

namespace gdpt {

struct ExrMergeSummary {
  std::vector<std::string> layers;            // the view layers merged
  uint32_t first_sample = 0;                  // the merged record's sample offset
  uint32_t min_samples = 0, max_samples = 0;  // merged per-pixel sample counts (first layer)
  ReconstructionNorm norm = ReconstructionNorm::L1;
  float alpha = 0.2f;
};

// Header attribute keys the engine writes per view layer (blender_addon/gdpt/engine.py).
std::string record_key(const std::string& layer, const std::string& key);

// The view layers of `image` as render parts, by view layer name (`name`, the file, for
// messages). Throws MergeError for a file that is not a Blender multilayer EXR, or whose GDPT
// layers (those with a `Sample Count` pass) lack their record.
struct ExrChannels;
std::map<std::string, RenderPart> parts_from_exr(const ExrChannels& image, const std::string& name);

// Merges `inputs` into `output`. Throws ExrError (files) or MergeError (contents).
ExrMergeSummary merge_exr_files(const std::vector<std::string>& inputs, const std::string& output,
                                const MergeSettings& settings);

}  // namespace gdpt
