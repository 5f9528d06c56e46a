#include "reconstruct/exr_io.h"

#include <algorithm>
#include <cstring>

#include <OpenImageIO/imageio.h>

#include "reconstruct/exr_header_check.h"

namespace gdpt {

namespace {

// All channels of all parts of a file, as float, rows top-down as stored.
struct RawExr {
  int width = 0, height = 0;
  std::vector<std::string> names;
  std::vector<std::vector<float>> channels;  // one top-down plane per name
  std::map<std::string, std::string> attributes;
  bool half = false;
};

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

RawExr read_raw(const std::string& path) {
  check_exr_header(path);  // before OpenEXR allocates what a corrupt header claims
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw ExrError("cannot read '" + path + "': " + one_line(OIIO::geterror()));
  RawExr raw;
  for (int sub = 0; in->seek_subimage(sub, 0); ++sub) {
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1)
      throw ExrError("'" + path + "' has an invalid image size");
    if (sub == 0) {
      raw.width = spec.width;
      raw.height = spec.height;
      for (const OIIO::ParamValue& p : spec.extra_attribs)
        if (p.type() == OIIO::TypeDesc::STRING) raw.attributes[p.name().string()] = p.get_string();
    } else if (spec.width != raw.width || spec.height != raw.height) {
      throw ExrError("'" + path + "': parts have different sizes (" + std::to_string(raw.width) +
                     "x" + std::to_string(raw.height) + " and " + std::to_string(spec.width) + "x" +
                     std::to_string(spec.height) + ")");
    }
    const int nc = spec.nchannels;
    const size_t pixels = size_t(spec.width) * spec.height;
    std::vector<float> data(pixels * nc);
    if (!in->read_image(sub, 0, 0, nc, OIIO::TypeDesc::FLOAT, data.data()))
      throw ExrError("cannot read '" + path + "': " + one_line(in->geterror()));
    for (int c = 0; c < nc; ++c) {
      if (spec.channelformat(c) == OIIO::TypeDesc::HALF) raw.half = true;
      raw.names.push_back(spec.channel_name(c));
      std::vector<float> plane(pixels);
      for (size_t i = 0; i < pixels; ++i) plane[i] = data[i * nc + c];
      raw.channels.push_back(std::move(plane));
    }
  }
  if (raw.names.empty()) throw ExrError("'" + path + "' has no image data");
  return raw;
}

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string prefix_of(const std::string& layer) {
  return layer.empty() ? "" : layer + ".";
}

int find_channel(const RawExr& raw, const std::string& name) {
  for (size_t i = 0; i < raw.names.size(); ++i)
    if (raw.names[i] == name) return int(i);
  return -1;
}

std::vector<std::string> layers_with_primal(const RawExr& raw) {
  std::vector<std::string> layers;
  for (const std::string& n : raw.names)
    for (const char* suffix : {"Primal.R", "Primal.X"}) {
      if (!ends_with(n, suffix)) continue;
      const size_t cut = n.size() - std::strlen(suffix);
      if (cut != 0 && n[cut - 1] != '.') continue;  // "XPrimal.R" is another pass
      const std::string layer = cut == 0 ? "" : n.substr(0, cut - 1);
      if (std::find(layers.begin(), layers.end(), layer) == layers.end()) layers.push_back(layer);
    }
  return layers;
}

// The 3 channels of `pass` in `layer`, flipped to bottom-up, or empty when the pass is absent.
std::vector<float> read_pass(const RawExr& raw, const std::string& path, const std::string& layer,
                             const std::string& pass) {
  const std::string base = prefix_of(layer) + pass + ".";
  for (const char* set : {"RGB", "XYZ"}) {
    int idx[3];
    int found = 0;
    for (int c = 0; c < 3; ++c) {
      idx[c] = find_channel(raw, base + set[c]);
      found += idx[c] >= 0;
    }
    if (found == 0) continue;
    if (found != 3) {
      std::string have;
      for (int c = 0; c < 3; ++c)
        if (idx[c] >= 0) have += std::string(have.empty() ? "" : ",") + set[c];
      throw ExrError("'" + path + "': pass '" + pass + "' of layer '" + layer + "' has channels " +
                     have + " but needs " + set[0] + "," + set[1] + "," + set[2]);
    }
    const int W = raw.width, H = raw.height;
    std::vector<float> rgb(size_t(W) * H * 3);
    for (int y = 0; y < H; ++y) {
      const size_t src = size_t(H - 1 - y) * W, dst = size_t(y) * W;  // EXR top-down -> bottom-up
      for (int x = 0; x < W; ++x)
        for (int c = 0; c < 3; ++c) rgb[3 * (dst + x) + c] = raw.channels[idx[c]][src + x];
    }
    return rgb;
  }
  // A pass with the wrong number of components (e.g. a 1-channel ".V" / ".Z" pass).
  for (const std::string& n : raw.names)
    if (n.rfind(base, 0) == 0 && n.find('.', base.size()) == std::string::npos)
      throw ExrError("'" + path + "': pass '" + pass + "' of layer '" + layer +
                     "' is not a 3-channel (R,G,B or X,Y,Z) pass (has channel '" + n + "')");
  return {};
}

// The single channel of 1-channel `pass` in `layer` (Blender: `.Z` for depth, `.V` for values),
// flipped to bottom-up, or empty when the pass is absent.
std::vector<float> read_scalar_pass(const RawExr& raw, const std::string& path,
                                    const std::string& layer, const std::string& pass) {
  const std::string base = prefix_of(layer) + pass + ".";
  std::vector<int> found;
  for (size_t i = 0; i < raw.names.size(); ++i)
    if (raw.names[i].rfind(base, 0) == 0 &&
        raw.names[i].find('.', base.size()) == std::string::npos)
      found.push_back(int(i));
  if (found.empty()) return {};
  if (found.size() != 1)
    throw ExrError("'" + path + "': pass '" + pass + "' of layer '" + layer +
                   "' is not a 1-channel pass (has " + std::to_string(found.size()) + " channels)");
  const int W = raw.width, H = raw.height;
  std::vector<float> v(size_t(W) * H);
  for (int y = 0; y < H; ++y) {
    const size_t src = size_t(H - 1 - y) * W, dst = size_t(y) * W;  // EXR top-down -> bottom-up
    for (int x = 0; x < W; ++x) v[dst + x] = raw.channels[found[0]][src + x];
  }
  return v;
}

void write_image(const std::string& path, const OIIO::ImageSpec& spec, const float* data) {
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw ExrError("cannot write '" + path + "': " + one_line(OIIO::geterror()));
  if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, data) || !out->close())
    throw ExrError("cannot write '" + path + "': " + one_line(out->geterror()));
}

}  // namespace

std::vector<std::string> exr_layers_with_primal(const std::string& path) {
  return layers_with_primal(read_raw(path));
}

ExrPasses read_exr_passes(const std::string& path, const std::string& layer,
                          const std::vector<std::string>& required,
                          const std::vector<std::string>& optional,
                          const std::vector<std::string>& scalar) {
  const RawExr raw = read_raw(path);
  ExrPasses result;
  result.width = raw.width;
  result.height = raw.height;
  if (layer.empty()) {
    const auto layers = layers_with_primal(raw);
    if (layers.empty()) throw ExrError("'" + path + "' has no view layer with a Primal pass");
    result.layer = layers.front();
  } else {
    result.layer = layer;
    const std::string prefix = layer + ".";
    const bool exists = std::any_of(raw.names.begin(), raw.names.end(),
                                    [&](const std::string& n) { return n.rfind(prefix, 0) == 0; });
    if (!exists) throw ExrError("'" + path + "' has no view layer '" + layer + "'");
  }
  auto read = [&](const std::string& pass) {
    return std::find(scalar.begin(), scalar.end(), pass) != scalar.end()
               ? read_scalar_pass(raw, path, result.layer, pass)
               : read_pass(raw, path, result.layer, pass);
  };
  for (const std::string& pass : required) {
    auto rgb = read(pass);
    if (rgb.empty())
      throw ExrError("'" + path + "' has no pass '" + pass + "' in layer '" + result.layer + "'");
    result.passes[pass] = std::move(rgb);
  }
  for (const std::string& pass : optional) {
    auto rgb = read(pass);
    if (!rgb.empty()) result.passes[pass] = std::move(rgb);
  }
  return result;
}

void write_rgba_exr(const std::string& path, int width, int height, const std::vector<float>& rgb) {
  if (rgb.size() != size_t(width) * height * 3)
    throw ExrError("write_rgba_exr: buffer size does not match " + std::to_string(width) + "x" +
                   std::to_string(height));
  OIIO::ImageSpec spec(width, height, 4, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"R", "G", "B", "A"};
  spec.attribute("compression", "zip");
  std::vector<float> rgba(size_t(width) * height * 4);
  for (int y = 0; y < height; ++y) {
    const size_t src = size_t(height - 1 - y) * width, dst = size_t(y) * width;  // -> top-down
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) rgba[4 * (dst + x) + c] = rgb[3 * (src + x) + c];
      rgba[4 * (dst + x) + 3] = 1.f;
    }
  }
  write_image(path, spec, rgba.data());
}

void write_multilayer_exr(const std::string& path, int width, int height, const std::string& layer,
                          const std::map<std::string, std::vector<float>>& passes,
                          const std::vector<std::string>& xyz_passes) {
  const size_t pixels = size_t(width) * height;
  int nc = 0;
  for (const auto& [name, values] : passes) {
    if (values.size() != pixels && values.size() != 3 * pixels)
      throw ExrError("write_multilayer_exr: pass '" + name + "' has the wrong size");
    nc += int(values.size() / pixels);
  }
  OIIO::ImageSpec spec(width, height, nc, OIIO::TypeDesc::FLOAT);
  spec.channelnames.clear();
  std::vector<float> data(pixels * nc);
  int first = 0;
  for (const auto& [name, values] : passes) {
    const int n = int(values.size() / pixels);
    const bool xyz = std::find(xyz_passes.begin(), xyz_passes.end(), name) != xyz_passes.end();
    const char* set = n == 1 ? "Z" : xyz ? "XYZ" : "RGB";
    for (int c = 0; c < n; ++c) spec.channelnames.push_back(prefix_of(layer) + name + "." + set[c]);
    for (int y = 0; y < height; ++y) {
      const size_t src = size_t(height - 1 - y) * width, dst = size_t(y) * width;
      for (int x = 0; x < width; ++x)
        for (int c = 0; c < n; ++c) data[(dst + x) * nc + first + c] = values[n * (src + x) + c];
    }
    first += n;
  }
  spec.attribute("compression", "zip");
  write_image(path, spec, data.data());
}

ExrChannels read_exr_channels(const std::string& path) {
  RawExr raw = read_raw(path);
  ExrChannels image;
  image.width = raw.width;
  image.height = raw.height;
  image.names = std::move(raw.names);
  image.attributes = std::move(raw.attributes);
  image.half = raw.half;
  const size_t W = size_t(raw.width), H = size_t(raw.height);
  for (std::vector<float>& plane : raw.channels) {
    std::vector<float> flipped(plane.size());
    for (size_t y = 0; y < H; ++y)  // EXR top-down -> bottom-up
      std::copy_n(&plane[(H - 1 - y) * W], W, &flipped[y * W]);
    image.planes.push_back(std::move(flipped));
  }
  return image;
}

void write_exr_channels(const std::string& path, const ExrChannels& image) {
  const size_t W = size_t(image.width), H = size_t(image.height), nc = image.names.size();
  if (nc == 0 || image.planes.size() != nc)
    throw ExrError("write_exr_channels: " + std::to_string(nc) + " names for " +
                   std::to_string(image.planes.size()) + " planes");
  OIIO::ImageSpec spec(image.width, image.height, int(nc), OIIO::TypeDesc::FLOAT);
  spec.channelnames = image.names;
  for (const auto& [name, value] : image.attributes) spec.attribute(name, value);
  spec.attribute("compression", "zip");
  std::vector<float> data(W * H * nc);
  for (size_t c = 0; c < nc; ++c) {
    if (image.planes[c].size() != W * H)
      throw ExrError("write_exr_channels: channel '" + image.names[c] + "' has the wrong size");
    for (size_t y = 0; y < H; ++y)  // bottom-up -> EXR top-down
      for (size_t x = 0; x < W; ++x)
        data[(y * W + x) * nc + c] = image.planes[c][(H - 1 - y) * W + x];
  }
  write_image(path, spec, data.data());
}

}  // namespace gdpt
