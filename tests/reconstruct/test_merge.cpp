// Renders of disjoint sample ranges (RenderSettings::sample_offset) merged by
// reconstruct/pass_merge.h equal the render of all their samples, every pass; gdpt-merge does the
// same on EXR files and refuses parts that do not belong together.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "integrators/render_session.h"
#include "reconstruct/exr_io.h"
#include "reconstruct/exr_merge.h"
#include "reconstruct/pass_merge.h"
#include "testing/gradient_scenes.h"

namespace gdpt {
namespace {

namespace fs = std::filesystem;
using gradient_test::SceneKind;

// A film's passes as the engine writes them (blender_addon/gdpt/passes.py), Combined included.
RenderPart part_from_film(const Film& f, const RenderSettings& s, const std::string& norm,
                          float alpha) {
  RenderPart p;
  p.name = "offset " + std::to_string(s.sample_offset);
  p.width = f.width();
  p.height = f.height();
  p.record = {s.mode == RenderSettings::Mode::PT ? "PT" : "GPT",
              s.seed,
              s.sample_offset,
              norm,
              alpha,
              f.half_split()};
  const size_t n = f.pixel_count();
  auto add = [&](const std::string& name, int channels, auto&& fill) {
    PassImage& image = p.passes[name];
    image.channels = channels;
    image.data.resize(n * size_t(channels));
    fill(image.data.data());
  };
  add("Primal", 3, [&](float* o) { f.primal_rgb(o); });
  add("Gradient X", 3, [&](float* o) { f.gradient_x_rgb(o); });
  add("Gradient Y", 3, [&](float* o) { f.gradient_y_rgb(o); });
  add("Emission", 3, [&](float* o) { f.emission_rgb(o); });
  add("Variance", 3, [&](float* o) { f.variance3(o); });
  add("Shift Failures", 1, [&](float* o) { f.shift_failures(o); });
  add("Shift Attempts", 1, [&](float* o) { f.shift_attempts(o); });
  add("Gradient Halves", 4, [&](float* o) { f.gradient_halves(o); });
  add("Sample Count", 1, [&](float* o) { f.sample_count(o); });
  add("Depth", 1, [&](float* o) { f.depth(o); });
  add("IndexOB", 1, [&](float* o) { f.object_index(o); });
  if (f.has_normal()) add("Normal", 3, [&](float* o) { f.normal(o); });
  if (f.has_mist()) add("Mist", 1, [&](float* o) { f.mist(o); });
  if (f.has_features()) {
    using FP = Film::FeaturePass;
    const std::pair<FP, std::string> features[] = {{FP::PrimalA, "Primal A"},
                                                   {FP::PrimalB, "Primal B"},
                                                   {FP::Albedo, "Denoising Albedo"},
                                                   {FP::Normal, "Denoising Normal"},
                                                   {FP::Depth, "Denoising Depth"}};
    for (const auto& [pass, name] : features) {
      const int c = Film::feature_channels(pass);
      add(name, c, [&](float* o) { f.feature(pass, o); });
      add(name + " Variance", c, [&](float* o) { f.feature_variance(pass, o); });
    }
  }
  if (f.has_half_gradients()) {
    using H = Film::SampleHalf;
    add("Gradient X A", 3, [&](float* o) { f.gradient_x_half_rgb(H::A, o); });
    add("Gradient X B", 3, [&](float* o) { f.gradient_x_half_rgb(H::B, o); });
    add("Gradient Y A", 3, [&](float* o) { f.gradient_y_half_rgb(H::A, o); });
    add("Gradient Y B", 3, [&](float* o) { f.gradient_y_half_rgb(H::B, o); });
  }
  std::vector<float> alpha_pass(n);
  f.alpha(alpha_pass.data());
  const std::vector<float> rgb = rebuild_combined(p, *norm_from_name(norm), alpha, 2);
  PassImage& combined = p.passes["Combined"];
  combined.channels = 4;
  combined.data.resize(4 * n);
  for (size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) combined.data[4 * i + c] = rgb[3 * i + c];
    combined.data[4 * i + 3] = alpha_pass[i];
  }
  return p;
}

// Samples offset .. offset + samples - 1 of a frame of `frame` samples (frame_samples).
RenderPart render_part(const Scene& scene, RenderSettings s, uint32_t offset, int samples,
                       uint32_t frame = 0, const std::string& norm = "L1", float alpha = 0.2f) {
  s.sample_offset = offset;
  s.samples = samples;
  s.frame_samples = frame;
  s.samples_per_pass = 3;  // pass boundaries that differ from the parts' ranges
  RenderSession session(scene, s);
  std::atomic<bool> cancel{false};
  session.render(nullptr, cancel);
  return part_from_film(session.film(), s, norm, alpha);
}

// The largest difference of each pass against `ref`, relative to the pass's largest magnitude.
std::map<std::string, double> differences(const RenderPart& a, const RenderPart& ref) {
  std::map<std::string, double> out;
  for (const auto& [name, image] : ref.passes) {
    const auto it = a.passes.find(name);
    if (it == a.passes.end() || it->second.data.size() != image.data.size()) {
      out[name] = INFINITY;
      continue;
    }
    double scale = 0.0, diff = 0.0;
    for (size_t j = 0; j < image.data.size(); ++j) {
      scale = std::max(scale, double(std::fabs(image.data[j])));
      diff = std::max(diff, double(std::fabs(it->second.data[j] - image.data[j])));
    }
    out[name] = scale > 0.0 ? diff / scale : diff;
  }
  return out;
}

// Float rounding of the parts' means and variances (measured: at most 1.1e-7 of a pass's largest
// value); Combined: the iterative solves (L1 IRLS, Feature) amplify it (measured 1.5e-6).
double tolerance(const std::string& pass) {
  return pass == "Combined" ? 1e-5 : 1e-6;
}

void expect_equal_passes(const RenderPart& merged, const RenderPart& single) {
  ASSERT_EQ(merged.passes.size(), single.passes.size());
  for (const auto& [name, diff] : differences(merged, single))
    EXPECT_LE(diff, tolerance(name)) << "pass " << name;
}

RenderSettings feature_settings(RenderSettings::Mode mode) {
  RenderSettings s = gradient_test::settings(mode, 1, 11);
  s.feature_passes = s.normal_pass = s.mist_pass = true;
  return s;
}

TEST(Merge, GptPartsEqualTheRenderOfAllSamples) {
  const Scene scene = gradient_test::make_scene(SceneKind::MixedLights, 20);
  const RenderSettings s = feature_settings(RenderSettings::Mode::GPT);
  // An odd first range: the halves' even / odd split follows the global sample index.
  const RenderPart single = render_part(scene, s, 0, 16, 0, "FEATURE");
  const std::vector<RenderPart> parts = {render_part(scene, s, 5, 7, 16, "FEATURE"),
                                         render_part(scene, s, 0, 5, 16, "FEATURE"),
                                         render_part(scene, s, 12, 4, 16, "FEATURE")};
  const RenderPart merged = merge_render_parts(parts, {{}, {}, 2});
  EXPECT_EQ(merged.record.sample_offset, 0u);
  // G-PT's gradients over the halves too, merged by the parts' even / odd sample counts.
  ASSERT_TRUE(single.passes.count("Gradient X A") && single.passes.count("Gradient Y B"));
  expect_equal_passes(merged, single);
  // Not trivially equal: a part differs from the whole.
  EXPECT_GT(differences(parts[0], single)["Primal"], 1e-3);
  EXPECT_GT(differences(parts[0], single)["Gradient X A"], 1e-3);
  EXPECT_GT(differences(parts[0], single)["Variance"], 1e-2);
}

TEST(Merge, PtPartsEqualTheRenderOfAllSamplesWithEveryNorm) {
  const Scene scene = gradient_test::make_scene(SceneKind::CornellDiffuse, 16);
  const RenderSettings s = feature_settings(RenderSettings::Mode::PT);
  const RenderPart single = render_part(scene, s, 0, 10, 0, "WEIGHTED", 0.5f);
  const RenderPart merged = merge_render_parts({render_part(scene, s, 0, 4, 10, "WEIGHTED", 0.5f),
                                                render_part(scene, s, 4, 6, 10, "WEIGHTED", 0.5f)});
  expect_equal_passes(merged, single);
  for (const char* norm : {"L1", "L2", "NONE", "FEATURE"}) {
    const ReconstructionNorm n = *norm_from_name(norm);
    const std::vector<float> a = rebuild_combined(merged, n, 0.5f, 2);
    const std::vector<float> b = rebuild_combined(single, n, 0.5f, 2);
    double scale = 0.0, diff = 0.0;
    for (size_t j = 0; j < a.size(); ++j) {
      scale = std::max(scale, double(std::fabs(b[j])));
      diff = std::max(diff, double(std::fabs(a[j] - b[j])));
    }
    EXPECT_LE(diff, 1e-5 * scale) << norm;
  }
}

TEST(Merge, GptWeightedVarianceMatters) {
  // The G-PT gradients' variances pooled with their halves kept apart equal the whole render's;
  // adding the parts' gradient variances as if they were one half would not.
  const Scene scene = gradient_test::make_scene(SceneKind::CornellGlossy, 16);
  const RenderSettings s = gradient_test::settings(RenderSettings::Mode::GPT, 1, 3);
  const RenderPart single = render_part(scene, s, 0, 12, 0, "WEIGHTED");
  const RenderPart merged = merge_render_parts(
      {render_part(scene, s, 0, 6, 12, "WEIGHTED"), render_part(scene, s, 6, 6, 12, "WEIGHTED")});
  expect_equal_passes(merged, single);
}

std::string merge_error(const std::vector<RenderPart>& parts) {
  try {
    merge_render_parts(parts);
  } catch (const MergeError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Merge, RefusesPartsThatDoNotBelongTogether) {
  const Scene scene = gradient_test::make_scene(SceneKind::CornellDiffuse, 8);
  const RenderSettings s = gradient_test::settings(RenderSettings::Mode::GPT, 1, 1);
  const RenderPart a = render_part(scene, s, 0, 4), b = render_part(scene, s, 4, 4);
  EXPECT_NE(merge_error({a, render_part(scene, s, 3, 4)}).find("sample ranges overlap"),
            std::string::npos);
  RenderPart other_seed = b;
  other_seed.record.seed = 2;
  EXPECT_NE(merge_error({a, other_seed}).find("seed"), std::string::npos);
  RenderPart missing = b;
  missing.passes.erase("Sample Count");
  EXPECT_NE(merge_error({a, missing}).find("Sample Count"), std::string::npos);
  RenderPart no_halves = b, a_no_halves = a;
  no_halves.passes.erase("Gradient Halves");
  a_no_halves.passes.erase("Gradient Halves");
  EXPECT_NE(merge_error({a_no_halves, no_halves}).find("Gradient Halves"), std::string::npos);
  const RenderPart small =
      render_part(gradient_test::make_scene(SceneKind::CornellDiffuse, 6), s, 4, 4);
  EXPECT_NE(merge_error({a, small}).find("6x6"), std::string::npos);
  RenderPart pt = b;
  pt.record.mode = "PT";
  EXPECT_NE(merge_error({a, pt}).find("mode"), std::string::npos);
  RenderPart unknown = b, a_unknown = a;
  unknown.passes["AO"] = a_unknown.passes["AO"] = {1, std::vector<float>(64, 0.0f)};
  EXPECT_NE(merge_error({a_unknown, unknown}).find("'AO'"), std::string::npos);
}

TEST(Merge, RefusesHalvesSplitForAnotherFrame) {
  // Parts that took their ranges without the frame's total split their halves' sequence at
  // different points: their halves are not halves of one render.
  const Scene scene = gradient_test::make_scene(SceneKind::CornellDiffuse, 8);
  const RenderSettings s = feature_settings(RenderSettings::Mode::GPT);
  const RenderPart a = render_part(scene, s, 0, 4), b = render_part(scene, s, 4, 4);
  EXPECT_EQ(a.record.half_split, 2u);
  EXPECT_EQ(b.record.half_split, 4u);
  EXPECT_NE(merge_error({a, b}).find("Frame Samples"), std::string::npos) << merge_error({a, b});
  const RenderPart a8 = render_part(scene, s, 0, 4, 8), b8 = render_part(scene, s, 4, 4, 8);
  EXPECT_EQ(merge_error({a8, b8}), "(no error)");
}

// --- gdpt-merge on files ---

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

struct CliResult {
  int status = -1;
  std::string err;
};

CliResult run_merge(const std::vector<std::string>& args) {
  const fs::path err = fs::temp_directory_path() / ("gdpt_merge_err_" + std::to_string(getpid()));
  std::string cmd = quote(GDPT_MERGE_EXE);
  for (const std::string& a : args) {
    cmd += ' ';
    cmd += quote(a);
  }
  cmd += " >/dev/null 2>";
  cmd += quote(err.string());
  const int raw = std::system(cmd.c_str());
  CliResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream f(err);
  std::stringstream ss;
  ss << f.rdbuf();
  r.err = ss.str();
  return r;
}

// The part as Blender writes it: `ViewLayer.<pass>.<channel>` and the engine's record.
void write_part(const fs::path& path, const RenderPart& p) {
  ExrChannels image;
  image.width = p.width;
  image.height = p.height;
  const size_t n = size_t(p.width) * p.height;
  for (const auto& [name, pass] : p.passes)
    for (int c = 0; c < pass.channels; ++c) {
      image.names.push_back("ViewLayer." + name + "." + std::string(1, "RGBA"[c]));
      std::vector<float> plane(n);
      for (size_t i = 0; i < n; ++i) plane[i] = pass.data[i * size_t(pass.channels) + size_t(c)];
      image.planes.push_back(std::move(plane));
    }
  const RenderRecord& r = p.record;
  image.attributes = {{record_key("ViewLayer", "mode"), r.mode},
                      {record_key("ViewLayer", "seed"), std::to_string(r.seed)},
                      {record_key("ViewLayer", "sample_offset"), std::to_string(r.sample_offset)},
                      {record_key("ViewLayer", "reconstruction"), r.reconstruction},
                      {record_key("ViewLayer", "alpha"), "0.2"}};
  write_exr_channels(path.string(), image);
}

TEST(MergeCli, MergedFileEqualsTheRenderOfAllSamples) {
  const fs::path dir = fs::temp_directory_path() / ("gdpt_merge_" + std::to_string(getpid()));
  fs::create_directories(dir);
  const Scene scene = gradient_test::make_scene(SceneKind::MixedLights, 12);
  const RenderSettings s = gradient_test::settings(RenderSettings::Mode::GPT, 1, 7);
  const RenderPart single = render_part(scene, s, 0, 9);
  write_part(dir / "a.exr", render_part(scene, s, 0, 4));
  write_part(dir / "b.exr", render_part(scene, s, 4, 5));
  write_part(dir / "overlap.exr", render_part(scene, s, 2, 5));
  const std::string out = (dir / "out.exr").string();
  const CliResult ok =
      run_merge({(dir / "b.exr").string(), (dir / "a.exr").string(), "-o", out, "--threads", "2"});
  ASSERT_EQ(ok.status, 0) << ok.err;
  const ExrChannels merged_file = read_exr_channels(out);
  const std::map<std::string, RenderPart> merged = parts_from_exr(merged_file, out);
  expect_equal_passes(merged.at("ViewLayer"), single);
  EXPECT_EQ(merged_file.attributes.at("gdpt.ViewLayer.samples"), "9");
  EXPECT_EQ(merged.at("ViewLayer").record.sample_offset, 0u);

  const CliResult overlap =
      run_merge({(dir / "a.exr").string(), (dir / "overlap.exr").string(), "-o", out});
  EXPECT_EQ(overlap.status, 1);
  EXPECT_NE(overlap.err.find("sample ranges overlap"), std::string::npos) << overlap.err;
  const CliResult missing =
      run_merge({(dir / "a.exr").string(), (dir / "nothing.exr").string(), "-o", out});
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.err.find("nothing.exr"), std::string::npos) << missing.err;
  EXPECT_EQ(run_merge({(dir / "a.exr").string()}).status, 2);  // no -o
  EXPECT_EQ(run_merge({(dir / "a.exr").string(), "-o", out, "--norm", "l3"}).status, 2);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gdpt
