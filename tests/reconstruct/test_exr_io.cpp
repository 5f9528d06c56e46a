// Multilayer EXR naming and row order (reconstruct/exr_io.h).
#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <OpenImageIO/imageio.h>

#include "reconstruct/exr_header_check.h"
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

// A scanline OpenEXR header written byte by byte (the layout of the OpenEXR file format
// document): magic, version, attributes (name, type, size, value), a terminating NUL.
struct ExrBytes {
  std::string b;
  template <typename T>
  void put(T v) {
    b.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void attr(const std::string& name, const std::string& type, const std::string& value,
            int32_t claimed = -1) {
    b += name + '\0' + type + '\0';
    put<int32_t>(claimed >= 0 ? claimed : int32_t(value.size()));
    b += value;
  }
  static std::string box(int32_t x0, int32_t y0, int32_t x1, int32_t y1) {
    ExrBytes v;
    for (int32_t i : {x0, y0, x1, y1}) v.put(i);
    return v.b;
  }
  // Magic, version 2, and the required attributes of a w x h RGB float image (no NUL yet).
  ExrBytes(int32_t w, int32_t h) {
    put<uint32_t>(20000630);
    put<int32_t>(2);
    std::string channels;
    for (const char* c : {"B", "G", "R"}) {
      ExrBytes ch;
      ch.b = std::string(c) + '\0';
      ch.put<int32_t>(2);  // FLOAT
      ch.put<int32_t>(0);  // pLinear, reserved
      ch.put<int32_t>(1);
      ch.put<int32_t>(1);
      channels += ch.b;
    }
    attr("channels", "chlist", channels + '\0');
    attr("compression", "compression", std::string(1, '\0'));
    attr("dataWindow", "box2i", box(0, 0, w - 1, h - 1));
    attr("displayWindow", "box2i", box(0, 0, w - 1, h - 1));
    attr("lineOrder", "lineOrder", std::string(1, '\0'));
    ExrBytes f;
    f.put<float>(1.0f);
    attr("pixelAspectRatio", "float", f.b);
    attr("screenWindowCenter", "v2f", std::string(8, '\0'));
    attr("screenWindowWidth", "float", f.b);
  }
  ExrBytes() = default;
  void write(const std::string& path) const { std::ofstream(path, std::ios::binary) << b; }
};

long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

void expect_rejected(const std::string& path, const std::string& reason) {
  try {
    read_exr_passes(path, "", {"Primal"});
    ADD_FAILURE() << "accepted: " << path;
  } catch (const ExrError& e) {
    EXPECT_NE(std::string(e.what()).find(reason), std::string::npos) << e.what();
  }
}

// Found by fuzz_exr_io: a truncated header whose string attribute claims 1.7 GB made OpenEXR
// allocate it (1.79 GB peak, 45 s) before failing. The sizes are now checked against the file
// first: a clear error, no allocation.
TEST(ExrIo, HeaderClaimingMoreThanTheFileHoldsIsRejectedBeforeReading) {
  const std::string path = temp_path("claims.exr");
  const long rss_before = peak_rss_kib();
  ExrBytes huge_string(4, 4);
  huge_string.attr("owner", "string", "", 1700000000);  // and the file ends
  huge_string.write(path);
  expect_rejected(path, "attribute 'owner' claims 1700000000 bytes");
  EXPECT_LT(peak_rss_kib() - rss_before, 100 * 1024) << "peak memory grew by more than 100 MiB";

  // A complete header whose data window needs more chunks than the file can hold.
  for (const int32_t h : {200000000, 300}) {
    ExrBytes tall(4, h);
    tall.b += '\0';
    tall.write(path);
    expect_rejected(path, "chunks, at least");
  }
  ExrBytes wide(40000, 40000);  // above kMaxExrPixels
  wide.b += '\0';
  wide.write(path);
  expect_rejected(path, "pixels");
  ExrBytes inverted(4, 4);
  inverted.attr("dataWindow", "box2i", ExrBytes::box(3, 3, 0, 0));
  inverted.b += '\0';
  inverted.write(path);
  expect_rejected(path, "is empty");
  std::filesystem::remove(path);
}

// A file Blender could write, cut at every length up to past its header: always an ExrError,
// and the uncut file still reads.
TEST(ExrIo, TruncatedFilesGiveAnErrorAtEveryLength) {
  const int w = 5, h = 3;
  const std::string path = temp_path("whole.exr"), cut = temp_path("cut.exr");
  write_multilayer_exr(path, w, h, "ViewLayer", {{"Primal", ramp(w, h)}}, {});
  std::ifstream in(path, std::ios::binary);
  const std::string whole((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NO_THROW(check_exr_header(path));
  for (size_t n = 0; n + 1 < whole.size(); n += 7) {
    std::ofstream(cut, std::ios::binary) << whole.substr(0, n);
    EXPECT_THROW(read_exr_passes(cut, "", {"Primal"}), ExrError) << n << " bytes";
  }
  EXPECT_EQ(read_exr_passes(path, "", {"Primal"}).width, w);
  std::filesystem::remove(path);
  std::filesystem::remove(cut);
}

}  // namespace
}  // namespace gdpt
