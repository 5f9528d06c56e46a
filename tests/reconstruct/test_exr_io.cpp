// Multilayer EXR naming and row order (reconstruct/exr_io.h).
#include <gtest/gtest.h>

#include <filesystem>

#include <OpenImageIO/imageio.h>

#include "reconstruct/exr_io.h"
#include "testing/test_images.h"

namespace gdpt {
namespace {

std::string temp_path(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return (std::filesystem::temp_directory_path() /
          ("gdpt_exr_" + std::string(info->name()) + "_" + name))
      .string();
}

// Bottom-up memory: pixel (x, y) with y = 0 the bottom row gets the value 100 y + x + c / 10.
std::vector<float> ramp(int w, int h) {
  std::vector<float> v(size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) v[3 * (size_t(y) * w + x) + c] = 100.f * y + x + 0.1f * c;
  return v;
}

TEST(ExrIo, BlenderNamesAndBottomUpRowsRoundTrip) {
  const int w = 5, h = 3;
  const auto primal = ramp(w, h);
  auto variance = ramp(w, h);
  for (float& v : variance) v += 1000.f;
  const std::string path = temp_path("a.exr");
  write_multilayer_exr(path, w, h, "ViewLayer", {{"Primal", primal}, {"Variance", variance}},
                       {"Variance"});

  // The file holds Blender's channel names, and its first (top) row is memory's last row.
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  const auto& spec = in->spec();
  std::vector<std::string> names(spec.channelnames.begin(), spec.channelnames.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "ViewLayer.Primal.R"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "ViewLayer.Variance.Z"), names.end());
  const int red = int(std::find(names.begin(), names.end(), "ViewLayer.Primal.R") - names.begin());
  std::vector<float> all(size_t(w) * h * spec.nchannels);
  ASSERT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, all.data()));
  EXPECT_EQ(all[red], 100.f * (h - 1));  // file (0, 0) = top-left = memory (0, h - 1)
  in->close();

  const ExrPasses p = read_exr_passes(path, "", {"Primal", "Variance"});
  EXPECT_EQ(p.layer, "ViewLayer");
  EXPECT_EQ(p.width, w);
  EXPECT_EQ(p.height, h);
  EXPECT_EQ(p.passes.at("Primal"), primal);
  EXPECT_EQ(p.passes.at("Variance"), variance);
  std::filesystem::remove(path);
}

TEST(ExrIo, LayerSelectionAndErrors) {
  const int w = 4, h = 4;
  const auto img = ramp(w, h);
  const std::string path = temp_path("b.exr");
  // Two view layers (written as two files' worth of channels in one): use a layer name with a dot.
  OIIO::ImageSpec spec(w, h, 8, OIIO::TypeDesc::FLOAT);
  spec.channelnames = {"Back.001.Primal.R",  "Back.001.Primal.G", "Back.001.Primal.B",
                       "Front.Primal.R",     "Front.Primal.G",    "Front.Primal.B",
                       "Front.Gradient X.R", "Front.Gradient X.G"};
  std::vector<float> data(size_t(w) * h * 8);
  for (size_t i = 0; i < size_t(w) * h; ++i)
    for (int c = 0; c < 8; ++c) data[8 * i + c] = float(c);
  auto out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out && out->open(path, spec) && out->write_image(OIIO::TypeDesc::FLOAT, data.data()));
  out->close();

  EXPECT_EQ(exr_layers_with_primal(path), (std::vector<std::string>{"Back.001", "Front"}));
  EXPECT_EQ(read_exr_passes(path, "", {"Primal"}).layer, "Back.001");
  const auto front = read_exr_passes(path, "Front", {"Primal"}, {"Emission"});
  EXPECT_EQ(front.passes.at("Primal")[0], 3.f);
  EXPECT_EQ(front.passes.count("Emission"), 0u);
  try {
    read_exr_passes(path, "Back.001", {"Primal", "Gradient X"});
    ADD_FAILURE() << "missing pass accepted";
  } catch (const ExrError& e) {
    EXPECT_NE(std::string(e.what()).find("'Gradient X'"), std::string::npos) << e.what();
  }
  try {
    read_exr_passes(path, "Front", {"Primal", "Gradient X"});
    ADD_FAILURE() << "2-channel pass accepted";
  } catch (const ExrError& e) {
    EXPECT_NE(std::string(e.what()).find("has channels R,G"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_exr_passes(path, "Nope", {"Primal"}), ExrError);
  EXPECT_THROW(read_exr_passes(path + ".missing", "", {"Primal"}), ExrError);
  std::filesystem::remove(path);
}

TEST(ExrIo, RgbaOutputIsTopDownWithUnitAlpha) {
  const int w = 3, h = 2;
  const auto img = ramp(w, h);
  const std::string path = temp_path("c.exr");
  write_rgba_exr(path, w, h, img);
  auto in = OIIO::ImageInput::open(path);
  ASSERT_TRUE(in);
  ASSERT_EQ(in->spec().nchannels, 4);
  EXPECT_EQ(in->spec().channelnames[3], "A");
  std::vector<float> rgba(size_t(w) * h * 4);
  ASSERT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, rgba.data()));
  EXPECT_EQ(rgba[0], 100.f);  // top-left = memory row h - 1
  EXPECT_EQ(rgba[3], 1.f);
  EXPECT_EQ(rgba[4 * w + 0], 0.f);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace gdpt
