// gdpt-reconstruct end to end: round trip on a generated multilayer EXR, display output, exit
// codes.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <OpenImageIO/imageio.h>

#include "reconstruct/exr_io.h"
#include "reconstruct/reconstruct.h"
#include "testing/feature_scene.h"
#include "testing/test_images.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;

struct CliResult {
  int status = -1;
  std::string out, err;
};

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string slurp(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("gdpt_cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  CliResult run(const std::vector<std::string>& args) const {
    std::string cmd = quote(GDPT_RECONSTRUCT_EXE);
    for (const auto& a : args) {
      cmd += ' ';
      cmd += quote(a);
    }
    cmd += " >";
    cmd += quote(path("stdout.txt"));
    cmd += " 2>";
    cmd += quote(path("stderr.txt"));
    CliResult r;
    const int raw = std::system(cmd.c_str());
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    r.out = slurp(dir_ / "stdout.txt");
    r.err = slurp(dir_ / "stderr.txt");
    return r;
  }

  // A GDPT-style multilayer EXR of a known asymmetric image: exact gradients (bottom-up rows),
  // primal = image + zero-mean noise, a constant emission.
  void write_scene(const std::string& file, std::vector<float>& truth, std::vector<float>& emission,
                   bool with_emission = true) {
    truth = test::make_image(w_, h_);
    std::vector<float> gx, gy;
    test::exact_gradients(truth, w_, h_, gx, gy);
    const auto primal = test::add(truth, test::zero_mean_noise(size_t(w_) * h_, 0.2f, 3));
    emission.assign(truth.size(), 0.25f);
    std::map<std::string, std::vector<float>> passes = {
        {"Primal", primal}, {"Gradient X", gx}, {"Gradient Y", gy}};
    if (with_emission) passes["Emission"] = emission;
    std::vector<float> variance(truth.size(), 0.04f);
    passes["Variance"] = variance;
    write_multilayer_exr(file, w_, h_, "ViewLayer", passes, {"Variance"});
  }

  // Bottom-up RGB of an RGBA EXR written by the CLI.
  std::vector<float> read_rgba(const std::string& file, std::vector<float>* alpha = nullptr) const {
    auto in = OIIO::ImageInput::open(file);
    EXPECT_TRUE(in);
    if (!in) return {};
    EXPECT_EQ(in->spec().nchannels, 4);
    std::vector<float> rgba(size_t(w_) * h_ * 4), rgb(size_t(w_) * h_ * 3);
    EXPECT_TRUE(in->read_image(0, 0, 0, 4, OIIO::TypeDesc::FLOAT, rgba.data()));
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        const size_t src = size_t(h_ - 1 - y) * w_ + x, dst = size_t(y) * w_ + x;
        for (int c = 0; c < 3; ++c) rgb[3 * dst + c] = rgba[4 * src + c];
        if (alpha) alpha->push_back(rgba[4 * src + 3]);
      }
    return rgb;
  }

  fs::path dir_;
  int w_ = 48, h_ = 32;
};

// With alpha -> 0 the result is fixed by the gradients: it only matches the truth when Gradient Y
// is read with Blender's bottom-up rows (a missing or double flip negates dy).
TEST_F(Cli, RoundTripRecoversTheImagePlusEmission) {
  std::vector<float> truth, emission;
  write_scene(path("in.exr"), truth, emission);
  for (const char* norm : {"l2", "l1", "weighted"}) {
    const CliResult r =
        run({path("in.exr"), "-o", path("out.exr"), "--alpha", "1e-3", "--norm", norm});
    ASSERT_EQ(r.status, 0) << norm << ": " << r.err;
    EXPECT_NE(r.out.find("emission added"), std::string::npos) << r.out;
    std::vector<float> alpha;
    const auto out = read_rgba(path("out.exr"), &alpha);
    EXPECT_LT(test::relative_error(out, test::add(truth, emission)), 2e-3) << norm;
    for (float a : alpha) ASSERT_EQ(a, 1.f);
  }
  // Sanity of the oracle: the unreconstructed primal is far from the truth.
  ASSERT_EQ(run({path("in.exr"), "-o", path("none.exr"), "--norm", "none"}).status, 0);
  EXPECT_GT(test::relative_error(read_rgba(path("none.exr")), test::add(truth, emission)), 0.05);
}

TEST_F(Cli, DisplayOutputThroughOcio) {
  std::vector<float> truth, emission;
  write_scene(path("in.exr"), truth, emission, false);
  const CliResult r = run({path("in.exr"), "-o", path("out.png"), "--norm", "l2", "--alpha", "1e-3",
                           "--view", "Standard"});
  ASSERT_EQ(r.status, 0) << r.err;
  auto in = OIIO::ImageInput::open(path("out.png"));
  ASSERT_TRUE(in);
  ASSERT_EQ(in->spec().nchannels, 3);
  std::vector<uint8_t> png(size_t(w_) * h_ * 3);
  ASSERT_TRUE(in->read_image(0, 0, 0, 3, OIIO::TypeDesc::UINT8, png.data()));
  // Standard = the sRGB transfer function of the linear value; top-left = memory row h - 1.
  for (int c = 0; c < 3; ++c) {
    const double lin = std::clamp<double>(truth[3 * (size_t(h_ - 1) * w_) + c], 0.0, 1.0);
    const double srgb = lin <= 0.0031308 ? 12.92 * lin : 1.055 * std::pow(lin, 1 / 2.4) - 0.055;
    EXPECT_NEAR(png[c], 255.0 * srgb, 2.0) << c;
  }
  // Filmic differs from Standard.
  ASSERT_EQ(run({path("in.exr"), "-o", path("filmic.png"), "--view", "Filmic"}).status, 0);
  EXPECT_TRUE(fs::exists(path("filmic.png")));
}

TEST_F(Cli, BadArgumentsExit2) {
  std::vector<float> truth, emission;
  write_scene(path("in.exr"), truth, emission);
  const std::string in = path("in.exr"), out = path("out.exr");
  const std::vector<std::vector<std::string>> cases = {
      {},
      {in},
      {in, "-o"},
      {in, "-o", out, "--alpha", "0"},
      {in, "-o", out, "--alpha", "-1"},
      {in, "-o", out, "--alpha", "abc"},
      {in, "-o", out, "--norm", "l3"},
      {in, "-o", out, "--frobnicate"},
      {in, "-o", path("out.bmpx")},
      {in, "-o", path("out.png"), "--view", "NoSuchView"},
      {in, in, "-o", out},
  };
  for (const auto& args : cases) {
    const CliResult r = run(args);
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    EXPECT_EQ(r.status, 2) << joined << r.err;
    EXPECT_FALSE(r.err.empty()) << joined;
  }
  const CliResult help = run({"--help"});
  EXPECT_EQ(help.status, 0);
  EXPECT_NE(help.out.find("usage: gdpt-reconstruct"), std::string::npos);
}

TEST_F(Cli, InvalidInputExit1WithOneLineReason) {
  std::vector<float> truth, emission;
  write_scene(path("good.exr"), truth, emission);

  // Truncated file.
  const auto size = fs::file_size(path("good.exr"));
  fs::copy_file(path("good.exr"), path("truncated.exr"));
  fs::resize_file(path("truncated.exr"), size / 2);
  // Not an image at all.
  std::ofstream(path("garbage.exr")) << "this is not an EXR file";
  // Wrong channel count: a 2-channel Gradient Y.
  {
    OIIO::ImageSpec spec(4, 4, 8, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"ViewLayer.Primal.R",     "ViewLayer.Primal.G",
                         "ViewLayer.Primal.B",     "ViewLayer.Gradient X.R",
                         "ViewLayer.Gradient X.G", "ViewLayer.Gradient X.B",
                         "ViewLayer.Gradient Y.R", "ViewLayer.Gradient Y.G"};
    std::vector<float> zeros(4 * 4 * 8, 0.f);
    auto o = OIIO::ImageOutput::create(path("channels.exr"));
    ASSERT_TRUE(o && o->open(path("channels.exr"), spec) &&
                o->write_image(OIIO::TypeDesc::FLOAT, zeros.data()));
    o->close();
  }
  // Two parts of different sizes.
  {
    OIIO::ImageSpec specs[2] = {OIIO::ImageSpec(4, 4, 3, OIIO::TypeDesc::FLOAT),
                                OIIO::ImageSpec(5, 4, 3, OIIO::TypeDesc::FLOAT)};
    specs[0].channelnames = {"ViewLayer.Primal.R", "ViewLayer.Primal.G", "ViewLayer.Primal.B"};
    specs[1].channelnames = {"ViewLayer.Gradient X.R", "ViewLayer.Gradient X.G",
                             "ViewLayer.Gradient X.B"};
    specs[0].full_width = 5;  // parts must share the display window; the data windows differ
    specs[0].attribute("name", "a");
    specs[1].attribute("name", "b");
    std::vector<float> zeros(5 * 4 * 3, 0.f);
    auto o = OIIO::ImageOutput::create(path("parts.exr"));
    ASSERT_TRUE(o && o->supports("multiimage"));
    ASSERT_TRUE(o->open(path("parts.exr"), 2, specs)) << o->geterror();
    ASSERT_TRUE(o->write_image(OIIO::TypeDesc::FLOAT, zeros.data()));
    ASSERT_TRUE(o->open(path("parts.exr"), specs[1], OIIO::ImageOutput::AppendSubimage));
    ASSERT_TRUE(o->write_image(OIIO::TypeDesc::FLOAT, zeros.data()));
    o->close();
  }
  // Missing pass.
  write_multilayer_exr(
      path("nogy.exr"), 4, 4, "ViewLayer",
      {{"Primal", std::vector<float>(48, 1.f)}, {"Gradient X", std::vector<float>(48, 0.f)}});

  struct Case {
    std::vector<std::string> args;
    std::string expect;  // in the message
  };
  const std::vector<Case> cases = {
      {{path("missing.exr"), "-o", path("o.exr")}, "missing.exr"},
      {{path("truncated.exr"), "-o", path("o.exr")}, "truncated.exr"},
      {{path("garbage.exr"), "-o", path("o.exr")}, "garbage.exr"},
      {{path("channels.exr"), "-o", path("o.exr")}, "has channels R,G"},
      {{path("nogy.exr"), "-o", path("o.exr")}, "'Gradient Y'"},
      {{path("parts.exr"), "-o", path("o.exr")}, "different sizes"},
      {{path("nogy.exr"), "-o", path("o.exr"), "--norm", "none"}, ""},  // ok: none needs Primal
      {{path("good.exr"), "-o", path("o.exr"), "--layer", "Other"}, "'Other'"},
      {{path("good.exr"), "-o", path("no/such/dir/o.exr")}, "o.exr"},
  };
  for (const Case& c : cases) {
    const CliResult r = run(c.args);
    if (c.expect.empty()) {
      EXPECT_EQ(r.status, 0) << c.args[0] << r.err;
      continue;
    }
    EXPECT_EQ(r.status, 1) << c.args[0] << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << r.err;
    // One line: a single trailing newline.
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  }
}

// --norm feature reads the halves, the gradients and the Denoising passes (depth as one `.Z`
// channel), gives what reconstruct() gives for them, and names a missing pass.
TEST_F(Cli, FeatureNormReadsTheDenoisingPasses) {
  const test::FeatureScene sc = test::make_feature_scene(w_, h_, 0.1f, 0.05f, 9);
  std::map<std::string, std::vector<float>> passes = {{"Primal", sc.primal},
                                                      {"Primal A", sc.a},
                                                      {"Primal B", sc.b},
                                                      {"Gradient X", sc.gx},
                                                      {"Gradient Y", sc.gy},
                                                      {"Denoising Albedo", sc.albedo},
                                                      {"Denoising Normal", sc.normal},
                                                      {"Denoising Depth", sc.depth}};
  write_multilayer_exr(path("in.exr"), w_, h_, "ViewLayer", passes, {"Denoising Normal"});
  const CliResult r = run({path("in.exr"), "-o", path("out.exr"), "--norm", "feature"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("norm feature"), std::string::npos) << r.out;
  const auto out = read_rgba(path("out.exr"));

  ReconstructionSettings settings;
  settings.norm = ReconstructionNorm::Feature;
  ReconstructionInput in = sc.input();  // the file has no gradient halves
  in.gradient_x_a = in.gradient_x_b = in.gradient_y_a = in.gradient_y_b = nullptr;
  const auto expected = reconstruct(in, settings);
  EXPECT_LT(test::rms_error(out, expected), 1e-6);
  EXPECT_LT(test::relative_mse(out, sc.truth), 0.5 * test::relative_mse(sc.primal, sc.truth));

  passes.erase("Denoising Normal");
  write_multilayer_exr(path("no_normal.exr"), w_, h_, "ViewLayer", passes);
  const CliResult missing = run({path("no_normal.exr"), "-o", path("x.exr"), "--norm", "feature"});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("no pass 'Denoising Normal'"), std::string::npos) << missing.err;
  EXPECT_NE(missing.err.find("--norm feature needs"), std::string::npos) << missing.err;
  EXPECT_EQ(std::count(missing.err.begin(), missing.err.end(), '\n'), 1) << missing.err;
  EXPECT_FALSE(fs::exists(path("x.exr")));

  const CliResult bad = run({path("in.exr"), "-o", path("x.exr"), "--norm", "nfor"});
  EXPECT_EQ(bad.status, 2);
  EXPECT_NE(bad.err.find("feature"), std::string::npos) << bad.err;
}

// --norm feature reads G-PT's gradients over the halves when all four are present (the output is
// reconstruct() with them) and refuses a layer that has only some of them.
TEST_F(Cli, FeatureNormReadsTheHalfGradients) {
  const test::FeatureScene sc = test::make_feature_scene(w_, h_, 0.1f, 0.05f, 9);
  // Halves that differ from each other and average to the scene's gradients.
  std::vector<float> gxa = sc.gx, gxb = sc.gx, gya = sc.gy, gyb = sc.gy;
  for (size_t j = 0; j < gxa.size(); ++j) {
    const float d = 0.02f * float(int(j * 7919 % 13) - 6);
    gxa[j] += d, gxb[j] -= d, gya[j] -= d, gyb[j] += d;
  }
  std::map<std::string, std::vector<float>> passes = {{"Primal", sc.primal},
                                                      {"Primal A", sc.a},
                                                      {"Primal B", sc.b},
                                                      {"Gradient X", sc.gx},
                                                      {"Gradient Y", sc.gy},
                                                      {"Denoising Albedo", sc.albedo},
                                                      {"Denoising Normal", sc.normal},
                                                      {"Denoising Depth", sc.depth},
                                                      {"Gradient X A", gxa},
                                                      {"Gradient X B", gxb},
                                                      {"Gradient Y A", gya},
                                                      {"Gradient Y B", gyb}};
  write_multilayer_exr(path("halves.exr"), w_, h_, "ViewLayer", passes, {"Denoising Normal"});
  const CliResult r = run({path("halves.exr"), "-o", path("out.exr"), "--norm", "feature"});
  ASSERT_EQ(r.status, 0) << r.err;
  ReconstructionInput in = sc.input();
  in.gradient_x_a = gxa.data(), in.gradient_x_b = gxb.data();
  in.gradient_y_a = gya.data(), in.gradient_y_b = gyb.data();
  ReconstructionSettings settings;
  settings.norm = ReconstructionNorm::Feature;
  EXPECT_LT(test::rms_error(read_rgba(path("out.exr")), reconstruct(in, settings)), 1e-6);

  passes.erase("Gradient Y B");
  write_multilayer_exr(path("three.exr"), w_, h_, "ViewLayer", passes, {"Denoising Normal"});
  const CliResult some = run({path("three.exr"), "-o", path("y.exr"), "--norm", "feature"});
  EXPECT_EQ(some.status, 1);
  EXPECT_NE(some.err.find("go together (missing Gradient Y B)"), std::string::npos) << some.err;
  EXPECT_EQ(std::count(some.err.begin(), some.err.end(), '\n'), 1) << some.err;
  EXPECT_FALSE(fs::exists(path("y.exr")));
}

}  // namespace
}  // namespace gdpt
