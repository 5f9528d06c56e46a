// Image loading through OpenImageIO and colour conversion through OpenColorIO (Blender's
// bundled config unless $OCIO is set).
#include <gtest/gtest.h>

#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <string>

#include "shaders/image_io.h"

namespace gdpt {
namespace {

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() /
          ("gdpt_shaders_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

// Writes a w x h image, rows top to bottom as files store them.
void write_image(const std::string& path, int w, int h, int nc, OIIO::TypeDesc type,
                 const std::vector<float>& pixels) {
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  OIIO::ImageSpec spec(w, h, nc, type);
  if (nc == 4) spec.alpha_channel = 3;
  spec.attribute("oiio:UnassociatedAlpha", 1);  // the pixels below are straight alpha
  ASSERT_TRUE(out->open(path, spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::FLOAT, pixels.data()));
  out->close();
}

float srgb_to_linear(float c) {
  return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

TEST(ImageIo, SrgbHalfGreyIsLinear0214) {
  ImageDesc img;
  img.name = "mem";
  img.width = 1;
  img.height = 1;
  img.rgba = {0.5f, 0.5f, 0.5f, 0.5f};
  convert_to_scene_linear(img, "sRGB");
  EXPECT_NEAR(img.rgba[0], 0.2140f, 1e-3f);
  EXPECT_NEAR(img.rgba[1], 0.2140f, 1e-3f);
  EXPECT_NEAR(img.rgba[2], 0.2140f, 1e-3f);
  EXPECT_EQ(img.rgba[3], 0.5f);  // alpha is never colour-converted
}

TEST(ImageIo, DataAndLinearSpacesAreLeftAlone) {
  for (const char* space : {"Non-Color", "Raw", "Linear"}) {
    ImageDesc img;
    img.width = 1;
    img.height = 1;
    img.rgba = {0.5f, 0.25f, 2.0f, 1.0f};
    convert_to_scene_linear(img, space);
    EXPECT_EQ(img.rgba, (std::vector<float>{0.5f, 0.25f, 2.0f, 1.0f})) << space;
  }
}

TEST(ImageIo, Png8BitSrgbIsDecodedAndFlipped) {
  const std::string path = temp_path("srgb.png");
  // 2x2, file rows top to bottom: top row (0, 128/255), bottom row (1, 64/255); alpha 1, 0.5.
  const float v128 = 128.0f / 255.0f, v64 = 64.0f / 255.0f;
  write_image(path, 2, 2, 4, OIIO::TypeDesc::UINT8,
              {0, 0, 0, 1, v128, v128, v128, 1, 1, 1, 1, 1, v64, v64, v64, 128.0f / 255.0f});
  const ImageDesc img = load_image_file(path, "sRGB");
  std::filesystem::remove(path);
  ASSERT_EQ(img.width, 2);
  ASSERT_EQ(img.height, 2);
  // Row 0 of the result is the file's bottom row.
  EXPECT_NEAR(img.rgba[0], 1.0f, 1e-3f);
  EXPECT_NEAR(img.rgba[4], srgb_to_linear(v64), 1e-3f);
  EXPECT_NEAR(img.rgba[7], 128.0f / 255.0f, 1e-3f);  // straight alpha, unconverted
  EXPECT_NEAR(img.rgba[8], 0.0f, 1e-4f);
  EXPECT_NEAR(img.rgba[12], srgb_to_linear(v128), 1e-3f);
  EXPECT_EQ(img.rgba[15], 1.0f);
}

TEST(ImageIo, FloatExrNonColorIsExact) {
  const std::string path = temp_path("data.exr");
  // 1 wide, 2 high, RGB: top (0.1, 0.2, 0.3), bottom (4, 5, 6).
  write_image(path, 1, 2, 3, OIIO::TypeDesc::FLOAT, {0.1f, 0.2f, 0.3f, 4, 5, 6});
  const ImageDesc img = load_image_file(path, "Non-Color");
  std::filesystem::remove(path);
  EXPECT_EQ(img.rgba, (std::vector<float>{4, 5, 6, 1, 0.1f, 0.2f, 0.3f, 1}));
}

TEST(ImageIo, ClearErrors) {
  try {
    load_image_file("/nonexistent/texture.png", "sRGB");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/texture.png"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("does not exist"), std::string::npos);
  }
  ImageDesc img;
  img.name = "mem";
  img.width = 1;
  img.height = 1;
  img.rgba = {0.5f, 0.5f, 0.5f, 1.0f};
  try {
    convert_to_scene_linear(img, "NotAColourSpace");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("NotAColourSpace"), std::string::npos);
  }
}

}  // namespace
}  // namespace gdpt
