// gdpt-merge: merges multilayer EXRs of one frame rendered over disjoint sample ranges of one
// seed (scene.gdpt.sample_offset; a render farm's split) into the EXR of all their samples.
//
//   gdpt-merge A.exr B.exr ... -o OUT.exr [--norm l1|l2|weighted|feature|none] [--alpha A]
//              [--threads N]
//
// Every pass is combined by its per-pixel sample counts (reconstruct/pass_merge.h); Combined is
// rebuilt with the reconstruction and alpha the engine recorded in the EXR header (or those
// given). Exit status: 0 success, 1 unreadable, invalid or unmergeable input (or unwritable
// output), 2 bad arguments.
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "reconstruct/cli_options.h"
#include "reconstruct/exr_io.h"
#include "reconstruct/exr_merge.h"

namespace {

constexpr const char* kUsage =
    "usage: gdpt-merge A.exr B.exr ... -o OUT.exr [options]\n"
    "\n"
    "Merges multilayer EXRs that Gradient PT rendered of one frame with the same seed over\n"
    "disjoint sample ranges (scene.gdpt.sample_offset) into the render of all their samples:\n"
    "every pass weighted by the per-pixel 'Sample Count' pass, variances pooled exactly, and\n"
    "Combined rebuilt with the reconstruction the engine recorded in the EXR header.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE     merged multilayer EXR (required)\n"
    "  --norm NORM           rebuild Combined with l1, l2, weighted, feature or none instead\n"
    "  --alpha A             and with this alpha (> 0) instead\n"
    "  --threads N           worker threads (default 0 = all cores)\n"
    "  -h, --help            this help\n"
    "\n"
    "exit status: 0 ok, 1 unreadable, invalid or unmergeable input, 2 bad arguments\n";

const gdpt::cli::Parser kCli{"gdpt-merge"};

[[noreturn]] void bad_arguments(const std::string& message) {
  kCli.bad_arguments(message);
}

const char* norm_name(gdpt::ReconstructionNorm n) {
  switch (n) {
    case gdpt::ReconstructionNorm::L1:
      return "L1";
    case gdpt::ReconstructionNorm::L2:
      return "L2";
    case gdpt::ReconstructionNorm::Weighted:
      return "WEIGHTED";
    case gdpt::ReconstructionNorm::Feature:
      return "FEATURE";
    case gdpt::ReconstructionNorm::None:
      return "NONE";
  }
  return "?";
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> inputs;
  std::string output;
  gdpt::MergeSettings settings;
  std::vector<std::string> args(argv + 1, argv + argc);
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) bad_arguments(a + " needs a value");
      return args[++i];
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      return 0;
    } else if (a == "-o" || a == "--output") {
      output = value();
    } else if (a == "--norm") {
      settings.norm = kCli.norm(value());
    } else if (a == "--alpha") {
      settings.alpha = kCli.alpha(a, value());
    } else if (a == "--threads") {
      settings.threads = kCli.threads(a, value());
    } else if (a.size() > 1 && a[0] == '-') {
      bad_arguments("unknown option '" + a + "'");
    } else {
      inputs.push_back(a);
    }
  }
  if (inputs.empty()) bad_arguments("no input files");
  if (output.empty()) bad_arguments("no output file (-o OUT.exr)");
  for (const std::string& in : inputs)
    if (in == output) bad_arguments("the output '" + output + "' is also an input");
  try {
    const gdpt::ExrMergeSummary s = gdpt::merge_exr_files(inputs, output, settings);
    std::string layers;
    for (const std::string& l : s.layers) layers += (layers.empty() ? "'" : ", '") + l + "'";
    std::printf("gdpt-merge: %zu files, view layer%s %s: samples from %u, %u", inputs.size(),
                s.layers.size() > 1 ? "s" : "", layers.c_str(), s.first_sample, s.min_samples);
    if (s.max_samples != s.min_samples) std::printf("-%u", s.max_samples);
    std::printf(" per pixel; Combined rebuilt with %s, alpha %g -> %s\n", norm_name(s.norm),
                double(s.alpha), output.c_str());
  } catch (const gdpt::MergeError& e) {
    std::fprintf(stderr, "gdpt-merge: %s\n", e.what());
    return 1;
  } catch (const gdpt::ExrError& e) {
    std::fprintf(stderr, "gdpt-merge: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gdpt-merge: %s\n", e.what());
    return 1;
  }
  return 0;
}
