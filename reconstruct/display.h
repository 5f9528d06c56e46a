// Display-referred output (PNG, JPEG, TIFF 8-bit) through OpenColorIO.
//
// Config: $OCIO when set, else Blender's bundled config
// (/usr/share/blender/datafiles/colormanagement/config.ocio). The image goes from the config's
// scene_linear role to its default display with the chosen view transform (empty: the display's
// default view). EXR output never goes through here: it stays scene linear.
#pragma once

#include <string>
#include <vector>

namespace gdpt {

inline constexpr const char* kBlenderOcioConfig =
    "/usr/share/blender/datafiles/colormanagement/config.ocio";

struct DisplayTransform {
  std::string config_path;  // the config actually used
  std::string display;      // the config's default display
  std::string view;         // the view transform used
};

// Loads the config and resolves the view. Throws std::invalid_argument when `view` is not a view
// of the default display (the message lists the valid ones) and std::runtime_error when no
// config can be loaded.
DisplayTransform resolve_display_transform(const std::string& view);

// Applies the transform to bottom-up RGB in place (values are display-referred, [0, 1] afterwards
// up to the view's own range).
void apply_display_transform(const DisplayTransform& transform, std::vector<float>& rgb, int width,
                             int height);

// Transforms bottom-up scene-linear RGB and writes it as an 8-bit image (format from the file
// extension), flipping rows to the file's top-down order. Throws ExrError on write failure.
void write_display_image(const std::string& path, const DisplayTransform& transform, int width,
                         int height, std::vector<float> rgb);

}  // namespace gdpt
