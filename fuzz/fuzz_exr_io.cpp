// libFuzzer target: gdpt-reconstruct's EXR reading path (reconstruct/exr_io.h) on arbitrary file
// contents. Any input either throws ExrError or yields passes of width x height x 3 floats.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "reconstruct/exr_io.h"

namespace {

// OpenImageIO reads files, so each input goes through one file per fuzzing process (in /dev/shm
// when it exists: no disk writes).
const std::string& input_path() {
  static const std::string path = [] {
    const char* dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return std::string(dir) + "/gdpt-fuzz-exr-" + std::to_string(getpid()) + ".exr";
  }();
  return path;
}

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string& path = input_path();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) std::abort();
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    (void)gdpt::exr_layers_with_primal(path);
    // As gdpt-reconstruct reads its input (gdpt_reconstruct_main.cpp).
    const gdpt::ExrPasses in = gdpt::read_exr_passes(
        path, "", {"Primal", "Gradient X", "Gradient Y", "Variance"}, {"Emission"});
    const size_t floats = size_t(in.width) * size_t(in.height) * 3;
    require(in.width > 0 && in.height > 0);
    for (const auto& [name, rgb] : in.passes) require(rgb.size() == floats);
  } catch (const gdpt::ExrError&) {
    // Rejected with a message: what bad input must do.
  }
  return 0;
}
