// Multilayer OpenEXR input / output with Blender's naming, through OpenImageIO.
//
// Blender writes a pass of a view layer as channels `<ViewLayer>.<Pass>.<Channel>`, e.g.
// `ViewLayer.Primal.R` or `ViewLayer.Normal.X`: colour passes use R, G, B (A), other 3-channel
// passes X, Y, Z. Both spellings are accepted for every 3-channel pass.
//
// Row order: OpenEXR (and OpenImageIO) store row 0 at the TOP of the image; Blender's buffers and
// GDPT's gradient convention (dy(x, y) = I(x, y + 1) - I(x, y)) have row 0 at the BOTTOM. This file
// is the one place that flips: images in memory are always bottom-up.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace gdpt {

// Unreadable or invalid EXR input / unwritable output; what() is a one-line reason.
struct ExrError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct ExrPasses {
  int width = 0, height = 0;
  std::string layer;                                 // the view layer that was read
  std::map<std::string, std::vector<float>> passes;  // pass name -> 3 (or 1) floats per pixel
};

// View layers of the file that have a `Primal` pass, in channel order ("" for un-prefixed
// `Primal.R` channels).
std::vector<std::string> exr_layers_with_primal(const std::string& path);

// Reads the passes `required` (an ExrError names the first one missing) and those of `optional`
// that exist, from view layer `layer` (empty: the first layer that has a Primal pass). Passes
// named in `scalar` are 1-channel (e.g. `Denoising Depth.Z`, 1 float per pixel), the others
// 3-channel.
ExrPasses read_exr_passes(const std::string& path, const std::string& layer,
                          const std::vector<std::string>& required,
                          const std::vector<std::string>& optional = {},
                          const std::vector<std::string>& scalar = {});

// Writes a single-part RGBA float EXR with channels R, G, B, A (A = 1) from bottom-up RGB.
void write_rgba_exr(const std::string& path, int width, int height, const std::vector<float>& rgb);

// Writes bottom-up passes as Blender names them (`<layer>.<pass>.R/G/B`, or X/Y/Z for the passes
// listed in `xyz_passes`, or `.Z` for a pass of 1 float per pixel), all in one part, as float.
// Used by tests and tools.
void write_multilayer_exr(const std::string& path, int width, int height, const std::string& layer,
                          const std::map<std::string, std::vector<float>>& passes,
                          const std::vector<std::string>& xyz_passes = {});

// Every channel of a file as stored, with the header's string attributes: what gdpt-merge reads
// and writes back (channel names and attributes kept).
struct ExrChannels {
  int width = 0, height = 0;
  std::vector<std::string> names;                 // channel names, in file order
  std::vector<std::vector<float>> planes;         // one bottom-up plane per name
  std::map<std::string, std::string> attributes;  // string attributes of the (first) header
  bool half = false;                              // some channel is stored as half float
};
ExrChannels read_exr_channels(const std::string& path);
// One part, every channel as 32-bit float, zip compression, the string attributes in the header.
void write_exr_channels(const std::string& path, const ExrChannels& image);

}  // namespace gdpt
