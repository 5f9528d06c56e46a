#include "reconstruct/exr_merge.h"

#include <algorithm>
#include <charconv>

#include "reconstruct/exr_io.h"

namespace gdpt {

namespace {

struct ChannelName {
  std::string layer, pass, channel;
};

// Blender's multilayer naming, `<view layer>.<pass>.<channel>`, split from the right (view layer
// names may hold dots, pass names do not).
bool split_channel(const std::string& name, ChannelName& out) {
  const size_t last = name.rfind('.');
  if (last == std::string::npos || last == 0) return false;
  const size_t middle = name.rfind('.', last - 1);
  if (middle == std::string::npos) return false;
  out = {name.substr(0, middle), name.substr(middle + 1, last - middle - 1), name.substr(last + 1)};
  return !out.layer.empty() && !out.pass.empty() && !out.channel.empty();
}

const std::string& attribute(const ExrChannels& image, const std::string& name,
                             const std::string& key) {
  const auto it = image.attributes.find(key);
  if (it == image.attributes.end())
    throw MergeError("'" + name + "' has no '" + key +
                     "' header attribute: it was not rendered by a Gradient PT that records its "
                     "settings for gdpt-merge");
  return it->second;
}

template <typename T>
T parse_number(const std::string& text, const std::string& what) {
  T value{};
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size())
    throw MergeError(what + " is '" + text + "', not a number");
  return value;
}

// Blender's channel order within a pass (R, G, B, A or X, Y, Z, W), whatever order the file
// lists them in; other names keep the file's order.
int channel_rank(const std::string& channel) {
  static const std::string kOrders[2] = {"RGBA", "XYZW"};
  for (const std::string& order : kOrders)
    if (channel.size() == 1 && order.find(channel[0]) != std::string::npos)
      return int(order.find(channel[0]));
  return 4;
}

// Each pass's channel indices, by (view layer, pass), in Blender's channel order.
using PassChannels = std::map<std::pair<std::string, std::string>, std::vector<size_t>>;
PassChannels pass_channels(const ExrChannels& image, const std::string& name) {
  PassChannels channels;
  std::vector<int> rank(image.names.size());
  for (size_t c = 0; c < image.names.size(); ++c) {
    ChannelName n;
    if (!split_channel(image.names[c], n))
      throw MergeError("'" + name + "': channel '" + image.names[c] +
                       "' is not named <view layer>.<pass>.<channel>: not a multilayer EXR of a "
                       "Blender render");
    channels[{n.layer, n.pass}].push_back(c);
    rank[c] = channel_rank(n.channel);
  }
  for (auto& [key, list] : channels)
    std::stable_sort(list.begin(), list.end(),
                     [&](size_t a, size_t b) { return rank[a] < rank[b]; });
  return channels;
}

// Reads every input; the files must hold the same channels.
void read_inputs(const std::vector<std::string>& inputs, std::vector<ExrChannels>& images,
                 std::vector<std::map<std::string, RenderPart>>& parts) {
  for (const std::string& path : inputs) {
    images.push_back(read_exr_channels(path));
    if (images.back().half)
      throw MergeError("'" + path +
                       "' stores half floats: render with Color Depth Float (Full) for an exact "
                       "merge");
    parts.push_back(parts_from_exr(images.back(), path));
    const ExrChannels& a = images.front();
    const ExrChannels& b = images.back();
    for (const std::string& n : b.names)
      if (std::find(a.names.begin(), a.names.end(), n) == a.names.end())
        throw MergeError("'" + path + "' has a channel '" + n + "' that '" + inputs.front() +
                         "' lacks: merged files need the same passes");
    for (const std::string& n : a.names)
      if (std::find(b.names.begin(), b.names.end(), n) == b.names.end())
        throw MergeError("'" + path + "' has no channel '" + n + "', which '" + inputs.front() +
                         "' has: merged files need the same passes");
  }
}

// `out` (the lowest part's file) with the merged layers' values and records.
void store_merged(ExrChannels& out, const std::vector<RenderPart>& merged_layers, size_t files) {
  const PassChannels channels = pass_channels(out, "merged");
  for (const RenderPart& merged : merged_layers) {
    for (const auto& [name, pass] : merged.passes) {
      const std::vector<size_t>& list = channels.at({merged.name, name});
      for (size_t k = 0; k < list.size(); ++k)
        for (size_t i = 0; i < out.planes[list[k]].size(); ++i)
          out.planes[list[k]][i] = pass.data[i * size_t(pass.channels) + k];
    }
    const auto& counts = merged.passes.at("Sample Count").data;
    out.attributes[record_key(merged.name, "sample_offset")] =
        std::to_string(merged.record.sample_offset);
    out.attributes[record_key(merged.name, "samples")] =
        std::to_string(uint32_t(*std::max_element(counts.begin(), counts.end())));
    out.attributes[record_key(merged.name, "merged_parts")] = std::to_string(files);
    if (merged.record.half_split)
      out.attributes[record_key(merged.name, "half_split")] =
          std::to_string(merged.record.half_split);
  }
}

}  // namespace

std::string record_key(const std::string& layer, const std::string& key) {
  return "gdpt." + layer + "." + key;
}

std::map<std::string, RenderPart> parts_from_exr(const ExrChannels& image,
                                                 const std::string& name) {
  const size_t pixels = size_t(image.width) * size_t(image.height);
  const auto channels = pass_channels(image, name);
  std::map<std::string, RenderPart> parts;
  for (const auto& [key, list] : channels) {
    RenderPart& part = parts[key.first];
    part.width = image.width;
    part.height = image.height;
    PassImage& out = part.passes[key.second];
    out.channels = int(list.size());
    out.data.resize(pixels * list.size());
    for (size_t c = 0; c < list.size(); ++c)
      for (size_t i = 0; i < pixels; ++i) out.data[i * list.size() + c] = image.planes[list[c]][i];
  }
  for (auto& [layer, part] : parts) {
    part.name = name + "' view layer '" + layer;
    if (!part.passes.count("Sample Count")) continue;  // not rendered by GDPT
    RenderRecord& r = part.record;
    r.mode = attribute(image, name, record_key(layer, "mode"));
    r.seed = parse_number<uint32_t>(attribute(image, name, record_key(layer, "seed")),
                                    "'" + name + "': the seed");
    r.sample_offset =
        parse_number<uint32_t>(attribute(image, name, record_key(layer, "sample_offset")),
                               "'" + name + "': the sample offset");
    r.reconstruction = attribute(image, name, record_key(layer, "reconstruction"));
    r.alpha = parse_number<float>(attribute(image, name, record_key(layer, "alpha")),
                                  "'" + name + "': alpha");
    // Recorded since the halves share one sequence; older renders lack it (compared as 0).
    const auto split = image.attributes.find(record_key(layer, "half_split"));
    if (split != image.attributes.end())
      r.half_split = parse_number<uint32_t>(split->second, "'" + name + "': the halves' split");
  }
  return parts;
}

ExrMergeSummary merge_exr_files(const std::vector<std::string>& inputs, const std::string& output,
                                const MergeSettings& settings) {
  if (inputs.empty()) throw MergeError("no input files");
  std::vector<ExrChannels> images;
  std::vector<std::map<std::string, RenderPart>> parts;  // [file][view layer]
  read_inputs(inputs, images, parts);
  ExrMergeSummary summary;
  size_t lowest_file = 0;
  std::vector<RenderPart> merged_layers;
  for (const auto& [layer, first] : parts.front()) {
    if (!first.passes.count("Sample Count")) continue;  // not a GDPT layer
    std::vector<RenderPart> layer_parts;
    for (auto& file_parts : parts) layer_parts.push_back(std::move(file_parts.at(layer)));
    RenderPart merged = merge_render_parts(layer_parts, settings);
    if (summary.layers.empty()) {
      for (size_t f = 0; f < layer_parts.size(); ++f)
        if (layer_parts[f].record.sample_offset == merged.record.sample_offset) lowest_file = f;
      summary.first_sample = merged.record.sample_offset;
      const auto& counts = merged.passes.at("Sample Count").data;
      summary.min_samples = uint32_t(*std::min_element(counts.begin(), counts.end()));
      summary.max_samples = uint32_t(*std::max_element(counts.begin(), counts.end()));
      summary.norm =
          settings.norm ? *settings.norm : norm_from_name(merged.record.reconstruction).value();
      summary.alpha = settings.alpha ? *settings.alpha : merged.record.alpha;
    }
    summary.layers.push_back(layer);
    merged.name = layer;
    merged_layers.push_back(std::move(merged));
  }
  if (summary.layers.empty())
    throw MergeError("'" + inputs.front() +
                     "' has no view layer with a 'Sample Count' pass: not a Gradient PT render");

  // The output: the lowest part's channels and header, with the merged values and record.
  ExrChannels out = std::move(images[lowest_file]);
  store_merged(out, merged_layers, inputs.size());
  write_exr_channels(output, out);
  return summary;
}

}  // namespace gdpt
