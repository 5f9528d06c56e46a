// Image files for textures: OpenImageIO reads any format it knows, OpenColorIO converts the
// pixels from the image's colour space (Blender's names) to the config's scene_linear role.
//
// OCIO config: $OCIO when set, else Blender's bundled config (kBlenderOcioConfig). The config is
// loaded once and cached. Data colour spaces ("Non-Color", "Raw", any isdata space) are never
// converted. Alpha is read unassociated (straight), as Blender's image.pixels, and is never
// colour-converted. Rows are flipped so that row 0 is the bottom row, as Blender stores images.
#include "shaders/image_io.h"

#include <OpenColorIO/OpenColorIO.h>

#include <OpenImageIO/imageio.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>

namespace OCIO = OCIO_NAMESPACE;

namespace gdpt {

namespace {

constexpr const char* kBlenderOcioConfig =
    "/usr/share/blender/datafiles/colormanagement/config.ocio";

OCIO::ConstConfigRcPtr ocio_config() {
  static std::mutex mutex;
  static OCIO::ConstConfigRcPtr config;
  std::lock_guard<std::mutex> lock(mutex);
  if (config) return config;
  const char* env = std::getenv("OCIO");
  try {
    if (env && *env) {
      config = OCIO::Config::CreateFromFile(env);
    } else if (std::filesystem::exists(kBlenderOcioConfig)) {
      config = OCIO::Config::CreateFromFile(kBlenderOcioConfig);
    } else {
      throw std::runtime_error(std::string("no OpenColorIO config: $OCIO is not set and ") +
                               kBlenderOcioConfig + " does not exist (install blender)");
    }
  } catch (const OCIO::Exception& e) {
    throw std::runtime_error(std::string("cannot load OpenColorIO config ") +
                             (env && *env ? env : kBlenderOcioConfig) + ": " + e.what());
  }
  return config;
}

bool is_data_name(const std::string& name) {
  return name == "Non-Color" || name == "Raw";
}

}  // namespace

void convert_to_scene_linear(ImageDesc& image, const std::string& colorspace) {
  if (is_data_name(colorspace)) return;
  const OCIO::ConstConfigRcPtr config = ocio_config();
  const OCIO::ConstColorSpaceRcPtr space = config->getColorSpace(colorspace.c_str());
  if (!space)
    throw std::runtime_error("image '" + image.name + "': unknown colour space '" + colorspace +
                             "' (not in the OpenColorIO config)");
  if (space->isData()) return;
  const OCIO::ConstColorSpaceRcPtr linear = config->getColorSpace(OCIO::ROLE_SCENE_LINEAR);
  if (linear && std::string(linear->getName()) == space->getName()) return;
  if (image.width <= 0 || image.height <= 0) return;
  if (image.rgba.size() != size_t(image.width) * size_t(image.height) * 4)
    throw std::runtime_error("image '" + image.name + "': pixel buffer size does not match " +
                             std::to_string(image.width) + "x" + std::to_string(image.height) +
                             " RGBA");
  try {
    const OCIO::ConstProcessorRcPtr processor =
        config->getProcessor(colorspace.c_str(), OCIO::ROLE_SCENE_LINEAR);
    const OCIO::ConstCPUProcessorRcPtr cpu = processor->getDefaultCPUProcessor();
    OCIO::PackedImageDesc desc(image.rgba.data(), image.width, image.height, 4);
    cpu->apply(desc);  // RGBA: OCIO converts RGB and passes alpha through
  } catch (const OCIO::Exception& e) {
    throw std::runtime_error("image '" + image.name + "': OpenColorIO conversion from '" +
                             colorspace + "' failed: " + e.what());
  }
}

ImageDesc load_image_file(const std::string& path, const std::string& colorspace) {
  if (!std::filesystem::exists(path))
    throw std::runtime_error("image file '" + path + "' does not exist");
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) throw std::runtime_error("cannot read image '" + path + "': " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  const int w = spec.width, h = spec.height, nc = spec.nchannels;
  if (w <= 0 || h <= 0 || nc <= 0) throw std::runtime_error("image '" + path + "' has no pixels");
  std::vector<float> pixels(size_t(w) * size_t(h) * size_t(nc));
  if (!in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, pixels.data()))
    throw std::runtime_error("cannot read pixels of '" + path + "': " + in->geterror());
  in->close();

  ImageDesc image;
  image.name = std::filesystem::path(path).filename().string();
  image.width = w;
  image.height = h;
  image.rgba.resize(size_t(w) * size_t(h) * 4);
  // Alpha channel: the spec's alpha channel if any, else the 2nd of grey+alpha or the 4th.
  const int alpha =
      spec.alpha_channel >= 0 ? spec.alpha_channel : (nc == 2 ? 1 : (nc >= 4 ? 3 : -1));
  for (int y = 0; y < h; ++y) {
    const float* src = pixels.data() + size_t(h - 1 - y) * size_t(w) * size_t(nc);  // flip rows
    float* dst = image.rgba.data() + size_t(y) * size_t(w) * 4;
    for (int x = 0; x < w; ++x, src += nc, dst += 4) {
      if (nc < 3) {  // grey (+ alpha)
        dst[0] = dst[1] = dst[2] = src[0];
      } else {
        dst[0] = src[0];
        dst[1] = src[1];
        dst[2] = src[2];
      }
      dst[3] = alpha >= 0 ? src[alpha] : 1.0f;
    }
  }
  convert_to_scene_linear(image, colorspace);
  return image;
}

}  // namespace gdpt
