// FNV-1a over the bits of a film's primal and gradient images: equal checksums mean
// bit-identical renders (for checking that a speed change leaves the image alone).
#pragma once

#include <cstdint>
#include <cstring>
#include <vector>

#include "render/film.h"

namespace gdpt::bench {

inline uint64_t film_checksum(const Film& film) {
  uint64_t h = 1469598103934665603ull;
  std::vector<float> image(3 * film.pixel_count());
  for (void (Film::*read)(float*) const :
       {&Film::primal_rgb, &Film::gradient_x_rgb, &Film::gradient_y_rgb}) {
    (film.*read)(image.data());
    for (float v : image) {
      uint32_t b;
      std::memcpy(&b, &v, sizeof b);
      h = (h ^ b) * 1099511628211ull;
    }
  }
  return h;
}

}  // namespace gdpt::bench
