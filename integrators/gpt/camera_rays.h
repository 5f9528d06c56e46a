// The camera rays of G-PT's base paths and of their offsets through the four neighbouring pixels
// (same jitter, same lens sample), traced in coherent Embree streams before the paths.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "integrators/gpt/gpt_context.h"
#include "integrators/integrator.h"
#include "render/sampler.h"

namespace gdpt {

// Every offset whose target pixel is inside the W x H image: the pixel's own halves of dx(x),
// dy(x), dx(x - 1) and dy(y - 1) (the latter two combined at read-out).
inline void offset_mask(int W, int H, int x, int y, bool* mask) {
  mask[kRight] = x + 1 < W;
  mask[kUp] = y + 1 < H;
  mask[kLeft] = x >= 1;
  mask[kDown] = y >= 1;
}

// What trace() needs of one base path's camera rays, wherever they were traced.
struct CameraSample {
  const Ray* ray;
  const SurfaceHit* hit;
  bool found;
  const bool* mask;  // offsets whose target pixel is inside the image
  const Ray* off_ray[kOffsets];
  const SurfaceHit* off_hit[kOffsets];
  bool off_found[kOffsets];
};

// Camera rays of a tile without depth of field: one jitter per sample index for the whole image,
// so the offset of pixel p towards a neighbour q (same jitter, q's pixel) is exactly q's base
// camera ray. The tile's rays and a one-pixel halo around it (the neighbours of its border pixels,
// clipped to the image; the halo's corners are no one's neighbour) are traced once per sample and
// every offset reads its neighbour's hit: about 1.3 camera rays per base path instead of 5.
struct CameraGrid {
  int x0 = 0, y0 = 0, w = 0, h = 0;  // the traced rectangle
  std::vector<Ray> ray;
  std::vector<SurfaceHit> hit;
  std::unique_ptr<bool[]> valid, found;  // not vector<bool>: intersect_stream takes bool arrays
  void reserve(size_t n) {               // grows only: one allocation per tile size
    if (n <= ray.size()) return;
    ray.resize(n);
    hit.resize(n);
    valid.reset(new bool[n]);
    found.reset(new bool[n]);
  }
  int index(int x, int y) const { return (y - y0) * w + (x - x0); }
};

// Traces the tile's camera rays and its halo for the sample of sequence index `index`
// (Film::sequence_index) of a W x H image, with the image-wide jitter of that sample. Returns the
// number of rays.
uint64_t trace_camera_grid(const GptContext& g, const Tile& tile, int W, int H, uint32_t index,
                           CameraGrid& grid);

// Pixel (x, y)'s camera sample from a traced grid; `mask` from offset_mask().
CameraSample grid_sample(const CameraGrid& grid, int x, int y, const bool* mask);

// Depth of field: every pixel keeps its own jitter and lens sample, so each offset traces its own
// camera ray (through the neighbour, with the base's jitter and lens sample). A row segment of up
// to kRow pixels is traced at once: the base rays in one Embree stream, then the offsets' rays,
// offset-major (the rays of one offset direction are as coherent as the base rays), in another.
inline constexpr int kRow = 16;

struct CameraRow {
  Sampler sampler[kRow];
  Vec2f raster[kRow], lens[kRow];
  bool mask[kRow][kOffsets];
  Ray ray[kRow];
  bool valid[kRow], found[kRow];
  SurfaceHit hit[kRow];
  // Offset k of pixel i at k * kRow + i, traced when the pixel's base ray found a surface.
  Ray cam[kOffsets * kRow];
  Ray cam_pixel[kOffsets];  // generate_offset_rays()'s output for one pixel
  bool cam_valid[kOffsets * kRow], cam_found[kOffsets * kRow];
  SurfaceHit cam_hit[kOffsets * kRow];
};

// Traces the n <= kRow pixels from (x0, y) on for the sample of sequence index `index`. Returns the
// number of rays.
uint64_t trace_camera_row(const GptContext& g, int W, int H, int x0, int y, int n, uint32_t index,
                          CameraRow& row);

// Pixel i's camera sample from a traced row.
CameraSample row_sample(const CameraRow& row, int i);

}  // namespace gdpt
