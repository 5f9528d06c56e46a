// Compares a Cycles render of cycles_texture.py with Texture::lookup at the same uv points and
// prints the largest difference. Usage: shaders_texture_check Linear|Closest REPEAT|EXTEND|CLIP
// RENDER.exr
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "shaders/texture.h"

using namespace gdpt;

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: shaders_texture_check INTERP EXT RENDER.exr\n");
    return 2;
  }
  // The same 4x2 image as cycles_texture.py, row 0 at the bottom.
  ImageDesc img;
  img.width = 4;
  img.height = 2;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 4; ++i)
      img.rgba.insert(img.rgba.end(), {i * 0.25f + 0.1f, j * 0.5f + 0.2f, (i + j) * 0.1f, 1.0f});
  const Texture tex(img);
  const std::string interp_name = argv[1], ext_name = argv[2];
  const auto interp = interp_name == "Closest" ? TextureLookup::Interpolation::Closest
                                               : TextureLookup::Interpolation::Linear;
  const auto ext = ext_name == "REPEAT"   ? TextureLookup::Extension::Repeat
                   : ext_name == "EXTEND" ? TextureLookup::Extension::Extend
                                          : TextureLookup::Extension::Clip;
  auto in = OIIO::ImageInput::open(argv[3]);
  if (!in) {
    std::fprintf(stderr, "%s\n", OIIO::geterror().c_str());
    return 1;
  }
  const int w = in->spec().width, h = in->spec().height;
  std::vector<float> px(size_t(w) * size_t(h) * 4);
  in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, px.data());
  double max_diff = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // File row 0 is the top; the plane's uv spans the frame, then the Mapping node.
      const float u = (x + 0.5f) / w, v = 1.0f - (y + 0.5f) / h;
      const Rgba r = tex.lookup({u * 1.5f - 0.25f, v * 1.5f - 0.25f}, interp, ext);
      for (int c = 0; c < 3; ++c)
        max_diff =
            std::max(max_diff, double(std::fabs(r.rgb[c] - px[(size_t(y) * w + x) * 4 + c])));
    }
  std::printf("%-8s %-7s max |cycles - gdpt| = %.5f\n", argv[1], argv[2], max_diff);
  return 0;
}
