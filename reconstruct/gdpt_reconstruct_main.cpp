// gdpt-reconstruct: screened Poisson reconstruction of a GDPT multilayer EXR.
//
//   gdpt-reconstruct IN.exr -o OUT.exr [--alpha A] [--norm l1|l2|weighted|feature|none]
//                    [--layer NAME] [--view V] [--threads N]
//
// Reads `<layer>.Primal`, `<layer>.Gradient X`, `<layer>.Gradient Y` (and `Variance` for
// --norm weighted, `Emission` when present), writes Combined = solve(...) + Emission.
// --norm feature reads the passes of kFeaturePasses instead (see the usage text).
// OUT.exr: single-part RGBA float EXR, scene linear. OUT.png / .jpg / .jpeg / .tif: 8-bit through
// the OpenColorIO view transform.
// Exit status: 0 success, 1 unreadable or invalid input (or unwritable output), 2 bad arguments.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <vector>

#include "reconstruct/cli_options.h"
#include "reconstruct/display.h"
#include "reconstruct/exr_io.h"
#include "reconstruct/reconstruct.h"

namespace {

constexpr const char* kUsage =
    "usage: gdpt-reconstruct IN.exr -o OUT.(exr|png|jpg|tif) [options]\n"
    "\n"
    "Reconstructs the final image from the Primal, Gradient X and Gradient Y passes of a\n"
    "multilayer EXR (Blender naming: <ViewLayer>.<Pass>.R/G/B), adds the Emission pass when\n"
    "present, and writes it: EXR as RGBA scene linear, PNG/JPEG/TIFF through OpenColorIO.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE     output image (required)\n"
    "  --alpha A             weight of the primal term, > 0 (default 0.2)\n"
    "  --norm NORM           l1 (default), l2, weighted (needs a Variance pass), feature,\n"
    "                        none\n"
    "                        feature: the L1 solution filtered by feature-guided filters,\n"
    "                        chosen per pixel by an error estimate from the samples' two\n"
    "                        halves; needs Primal A / Primal B, Gradient X / Y, Denoising\n"
    "                        Albedo, Normal and Depth (1 channel); Variance, Primal A / B\n"
    "                        Variance and Denoising Albedo / Normal / Depth Variance used\n"
    "                        when present;\n"
    "                        G-PT's gradients over the halves, Gradient X A / X B / Y A / Y B,\n"
    "                        used when present (all four or none)\n"
    "  --layer NAME          view layer (default: the first layer with a Primal pass)\n"
    "  --view V              OCIO view transform for PNG/JPEG, e.g. Filmic or Standard\n"
    "                        (default: the config's default view; config from $OCIO or\n"
    "                        Blender's bundled config)\n"
    "  --threads N           worker threads (default 0 = all cores)\n"
    "  -h, --help            this help\n"
    "\n"
    "exit status: 0 ok, 1 unreadable or invalid input, 2 bad arguments\n";

// --norm feature: the passes it needs, and those it uses when present.
const std::vector<std::string> kFeaturePasses = {
    "Primal A",         "Primal B",         "Gradient X",     "Gradient Y",
    "Denoising Albedo", "Denoising Normal", "Denoising Depth"};
const std::vector<std::string> kFeatureOptional = {"Primal",
                                                   "Variance",
                                                   "Emission",
                                                   "Primal A Variance",
                                                   "Primal B Variance",
                                                   "Denoising Albedo Variance",
                                                   "Denoising Normal Variance",
                                                   "Denoising Depth Variance",
                                                   "Gradient X A",
                                                   "Gradient X B",
                                                   "Gradient Y A",
                                                   "Gradient Y B"};
const std::vector<std::string> kScalarPasses = {"Denoising Depth", "Denoising Depth Variance"};

struct Options {
  std::string input, output, layer, view;
  gdpt::ReconstructionSettings settings;
  bool display = false;  // output through OCIO
};

const gdpt::cli::Parser kCli{"gdpt-reconstruct"};

[[noreturn]] void bad_arguments(const std::string& message) {
  kCli.bad_arguments(message);
}

std::string lower_extension(const std::string& path) {
  const size_t dot = path.rfind('.');
  if (dot == std::string::npos || path.find('/', dot) != std::string::npos) return {};
  std::string ext = path.substr(dot + 1);
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

Options parse(int argc, char** argv) {
  Options o;
  o.settings.norm = gdpt::ReconstructionNorm::L1;
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.empty()) bad_arguments("no input file");
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) bad_arguments(a + " needs a value");
      return args[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "-o" || a == "--output") {
      o.output = value();
    } else if (a == "--alpha") {
      o.settings.alpha = kCli.alpha(a, value());
    } else if (a == "--norm") {
      o.settings.norm = kCli.norm(value());
    } else if (a == "--layer") {
      o.layer = value();
      if (o.layer.empty()) bad_arguments("--layer needs a name");
    } else if (a == "--view") {
      o.view = value();
    } else if (a == "--threads") {
      o.settings.threads = kCli.threads(a, value());
    } else if (a.size() > 1 && a[0] == '-') {
      bad_arguments("unknown option '" + a + "'");
    } else if (o.input.empty()) {
      o.input = a;
    } else {
      bad_arguments("more than one input file ('" + o.input + "', '" + a + "')");
    }
  }
  if (o.input.empty()) bad_arguments("no input file");
  if (o.output.empty()) bad_arguments("no output file (-o OUT.exr)");
  const std::string ext = lower_extension(o.output);
  if (ext == "exr") {
    o.display = false;
  } else if (ext == "png" || ext == "jpg" || ext == "jpeg" || ext == "tif" || ext == "tiff") {
    o.display = true;
  } else {
    bad_arguments("output must end in .exr, .png, .jpg, .jpeg or .tif, got '" + o.output + "'");
  }
  return o;
}

// Progress on stderr, only once a run has taken more than a second, at most twice a second.
class Progress {
 public:
  void stage(const char* name, float fraction) {
    const double t = elapsed();
    if (t < 1.0 || (t - last_ < 0.5 && fraction < 1.f)) return;
    last_ = t;
    std::fprintf(stderr, "gdpt-reconstruct: %s %3d%% (%.1f s)\n", name,
                 int(fraction * 100.f + 0.5f), t);
  }
  double elapsed() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  double last_ = -1.0;
};

gdpt::ExrPasses read_passes(const Options& o) {
  std::vector<std::string> required = {"Primal"};
  if (o.settings.norm != gdpt::ReconstructionNorm::None) {
    required.push_back("Gradient X");
    required.push_back("Gradient Y");
  }
  if (o.settings.norm == gdpt::ReconstructionNorm::Weighted) required.push_back("Variance");
  return gdpt::read_exr_passes(o.input, o.layer, required, {"Emission"});
}

void set_input(const Options& o, const gdpt::ExrPasses& in, gdpt::ReconstructionInput& input) {
  input.width = in.width;
  input.height = in.height;
  input.primal = in.passes.at("Primal").data();
  if (o.settings.norm != gdpt::ReconstructionNorm::None) {
    input.gradient_x = in.passes.at("Gradient X").data();
    input.gradient_y = in.passes.at("Gradient Y").data();
  }
  if (o.settings.norm == gdpt::ReconstructionNorm::Weighted)
    input.variance = in.passes.at("Variance").data();
  if (auto it = in.passes.find("Emission"); it != in.passes.end())
    input.emission = it->second.data();
}

// A missing pass is named, with the list of what --norm feature reads.
gdpt::ExrPasses read_feature_passes(const Options& o) {
  try {
    return gdpt::read_exr_passes(o.input, o.layer, kFeaturePasses, kFeatureOptional, kScalarPasses);
  } catch (const gdpt::ExrError& e) {
    std::string needs;
    for (const auto& p : kFeaturePasses) needs += (needs.empty() ? "" : ", ") + p;
    throw gdpt::ExrError(std::string(e.what()) + " (--norm feature needs " + needs + ")");
  }
}

void set_feature_input(const gdpt::ExrPasses& in, gdpt::ReconstructionInput& input) {
  auto pass = [&](const char* name) -> const float* {
    const auto it = in.passes.find(name);
    return it == in.passes.end() ? nullptr : it->second.data();
  };
  input.width = in.width;
  input.height = in.height;
  input.primal = pass("Primal");
  input.emission = pass("Emission");
  input.gradient_x = pass("Gradient X");
  input.gradient_y = pass("Gradient Y");
  input.primal_a = pass("Primal A");
  input.primal_b = pass("Primal B");
  input.variance = pass("Variance");  // the Weighted candidate's, when present
  input.variance_a = pass("Primal A Variance");
  input.variance_b = pass("Primal B Variance");
  input.albedo = pass("Denoising Albedo");
  input.albedo_variance = pass("Denoising Albedo Variance");
  input.normal = pass("Denoising Normal");
  input.normal_variance = pass("Denoising Normal Variance");
  input.depth = pass("Denoising Depth");
  input.depth_variance = pass("Denoising Depth Variance");
  // G-PT's gradients over the halves: all four or none.
  const char* halves[4] = {"Gradient X A", "Gradient X B", "Gradient Y A", "Gradient Y B"};
  const float** fields[4] = {&input.gradient_x_a, &input.gradient_x_b, &input.gradient_y_a,
                             &input.gradient_y_b};
  int present = 0;
  std::string missing;
  for (int k = 0; k < 4; ++k) {
    *fields[k] = pass(halves[k]);
    if (*fields[k])
      ++present;
    else
      missing += std::string(missing.empty() ? "" : ", ") + halves[k];
  }
  if (present > 0 && present < 4)
    throw gdpt::ExrError("layer '" + in.layer +
                         "' has only some of Gradient X A, Gradient X B, Gradient Y A and "
                         "Gradient Y B, which go together (missing " +
                         missing + ")");
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  Progress progress;

  // The view is an argument: check it before the (possibly long) solve.
  std::optional<gdpt::DisplayTransform> display;
  if (o.display || !o.view.empty()) {
    try {
      display = gdpt::resolve_display_transform(o.view);
    } catch (const std::invalid_argument& e) {
      bad_arguments(e.what());
    } catch (const std::exception& e) {
      std::fprintf(stderr, "gdpt-reconstruct: %s\n", e.what());
      return 1;
    }
  }

  try {
    const bool feature = o.settings.norm == gdpt::ReconstructionNorm::Feature;
    gdpt::ExrPasses in;
    gdpt::ReconstructionInput input;
    if (feature) {
      in = read_feature_passes(o);
      set_feature_input(in, input);
    } else {
      in = read_passes(o);
      set_input(o, in, input);
    }
    progress.stage("read", 1.f);

    gdpt::ReconstructionSettings settings = o.settings;
    settings.progress = [&](float f) { progress.stage("solve", f); };
    settings.compute_objective = !feature;  // printed in the summary line
    gdpt::ReconstructionReport report;
    const std::vector<float> image = gdpt::reconstruct(input, settings, &report);

    if (o.display)
      gdpt::write_display_image(o.output, *display, in.width, in.height, image);
    else
      gdpt::write_rgba_exr(o.output, in.width, in.height, image);

    static const char* kNames[] = {"l2", "l1", "weighted", "none", "feature"};
    std::printf(
        "gdpt-reconstruct: %s layer '%s' %dx%d norm %s alpha %g: %d iterations, "
        "objective %.6g, %.2f s solve, %.2f s total%s%s\n",
        o.output.c_str(), in.layer.c_str(), in.width, in.height, kNames[int(o.settings.norm)],
        double(o.settings.alpha), report.iterations, report.objective, report.seconds,
        progress.elapsed(), input.emission ? ", emission added" : "",
        o.display ? (", view '" + display->view + "'").c_str() : "");
    if (report.missing_values > 0)
      std::fprintf(stderr,
                   "gdpt-reconstruct: warning: %d non-finite input values treated as missing\n",
                   report.missing_values);
    return 0;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "gdpt-reconstruct: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gdpt-reconstruct: %s\n", e.what());
    return 1;
  }
}
