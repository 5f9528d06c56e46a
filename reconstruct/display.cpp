#include "reconstruct/display.h"

#include <cstdlib>
#include <filesystem>
#include <stdexcept>

#include <OpenColorIO/OpenColorIO.h>
#include <OpenImageIO/imageio.h>

#include "reconstruct/exr_io.h"

namespace OCIO = OCIO_NAMESPACE;

namespace gdpt {

namespace {

OCIO::ConstConfigRcPtr load_config(std::string& path) {
  const char* env = std::getenv("OCIO");
  path = env && *env ? env : kBlenderOcioConfig;
  if (!std::filesystem::exists(path))
    throw std::runtime_error("OpenColorIO config '" + path + "' not found (set $OCIO)");
  try {
    return OCIO::Config::CreateFromFile(path.c_str());
  } catch (const OCIO::Exception& e) {
    throw std::runtime_error("cannot load OpenColorIO config '" + path + "': " + e.what());
  }
}

}  // namespace

DisplayTransform resolve_display_transform(const std::string& view) {
  DisplayTransform t;
  const auto config = load_config(t.config_path);
  t.display = config->getDefaultDisplay();
  if (view.empty()) {
    t.view = config->getDefaultView(t.display.c_str());
    return t;
  }
  std::string valid;
  for (int i = 0; i < config->getNumViews(t.display.c_str()); ++i) {
    const std::string v = config->getView(t.display.c_str(), i);
    if (v == view) {
      t.view = v;
      return t;
    }
    valid += (valid.empty() ? "" : ", ") + v;
  }
  throw std::invalid_argument("unknown view '" + view + "' for display '" + t.display +
                              "' (valid: " + valid + ")");
}

void apply_display_transform(const DisplayTransform& t, std::vector<float>& rgb, int width,
                             int height) {
  std::string path;
  const auto config = load_config(path);
  try {
    const auto processor = config->getProcessor(OCIO::ROLE_SCENE_LINEAR, t.display.c_str(),
                                                t.view.c_str(), OCIO::TRANSFORM_DIR_FORWARD);
    OCIO::PackedImageDesc image(rgb.data(), width, height, 3);
    processor->getDefaultCPUProcessor()->apply(image);
  } catch (const OCIO::Exception& e) {
    throw std::runtime_error(std::string("OpenColorIO: ") + e.what());
  }
}

void write_display_image(const std::string& path, const DisplayTransform& t, int width, int height,
                         std::vector<float> rgb) {
  apply_display_transform(t, rgb, width, height);
  std::vector<float> top_down(rgb.size());
  for (int y = 0; y < height; ++y)
    std::copy_n(rgb.data() + size_t(height - 1 - y) * width * 3, size_t(width) * 3,
                top_down.data() + size_t(y) * width * 3);
  auto out = OIIO::ImageOutput::create(path);
  if (!out) throw ExrError("cannot write '" + path + "': " + OIIO::geterror());
  OIIO::ImageSpec spec(width, height, 3, OIIO::TypeDesc::UINT8);
  // OIIO converts float to UINT8 with clamping to [0, 1].
  if (!out->open(path, spec) || !out->write_image(OIIO::TypeDesc::FLOAT, top_down.data()) ||
      !out->close())
    throw ExrError("cannot write '" + path + "': " + out->geterror());
}

}  // namespace gdpt
