// Loading image files for textures: OpenImageIO reads, OpenColorIO converts to scene linear.
#pragma once

#include <string>

#include "scene/material_desc.h"

namespace gdpt {

// Reads `path` and converts from `colorspace` (Blender names: "sRGB", "Non-Color", "Linear", ...,
// resolved in the OCIO config from $OCIO or Blender's bundled config) to scene linear RGBA,
// row 0 at the bottom. Throws std::runtime_error with a clear message on failure.
ImageDesc load_image_file(const std::string& path, const std::string& colorspace);

// Converts pixels already in memory (e.g. Blender's image.pixels) from `colorspace` to scene
// linear.
void convert_to_scene_linear(ImageDesc& image, const std::string& colorspace);

}  // namespace gdpt
