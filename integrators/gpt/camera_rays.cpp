#include "integrators/gpt/camera_rays.h"

#include <algorithm>

namespace gdpt {

namespace {

constexpr int kStepX[kOffsets] = {1, 0, -1, 0}, kStepY[kOffsets] = {0, 1, 0, -1};
static_assert(kRight == 0 && kUp == 1 && kLeft == 2 && kDown == 3);

}  // namespace

uint64_t trace_camera_grid(const GptContext& g, const Tile& tile, int W, int H, uint32_t index,
                           CameraGrid& grid) {
  // The image-wide jitter: a sampler keyed to no pixel, (-1, -1). Every pixel takes the same
  // filter sample, so a neighbour's base ray is this pixel's offset ray.
  Sampler image_wide;
  start_sample(g, image_wide, -1, -1, index);
  const Vec2f jitter = image_wide.get2d(Sampler::kDimCamera);
  const PixelFilter& filter = g.ctx.pixel_filter();
  grid.x0 = std::max(tile.x0 - 1, 0);
  grid.y0 = std::max(tile.y0 - 1, 0);
  const int x1 = std::min(tile.x1 + 1, W), y1 = std::min(tile.y1 + 1, H);
  grid.w = x1 - grid.x0;
  grid.h = y1 - grid.y0;
  grid.reserve(size_t(grid.w) * size_t(grid.h));
  const CameraModel& camera = g.ctx.camera();
  const int rx = camera.region_x(), ry = camera.region_y();  // frame raster
  uint64_t n = 0;
  for (int y = grid.y0; y < y1; ++y) {
    const bool row_inside = y >= tile.y0 && y < tile.y1;
    for (int x = grid.x0; x < x1; ++x) {
      const int c = grid.index(x, y);
      // The halo's corners are no tile pixel's neighbour.
      grid.valid[c] = row_inside || (x >= tile.x0 && x < tile.x1);
      if (!grid.valid[c]) continue;
      grid.ray[c] = camera.generate_ray(filter.raster(x + rx, y + ry, jitter), Vec2f(0.5f, 0.5f));
      ++n;
    }
  }
  g.ctx.bvh().intersect_stream(grid.ray.data(), grid.valid.get(), grid.w * grid.h, grid.found.get(),
                               grid.hit.data());
  return n;
}

CameraSample grid_sample(const CameraGrid& grid, int x, int y, const bool* mask) {
  CameraSample cs;
  const int c = grid.index(x, y);
  cs.mask = mask;
  cs.ray = &grid.ray[c];
  cs.hit = &grid.hit[c];
  cs.found = grid.found[c];
  for (int k = 0; k < kOffsets; ++k) {
    if (!mask[k]) continue;
    const int n = grid.index(x + kStepX[k], y + kStepY[k]);
    cs.off_ray[k] = &grid.ray[n];
    cs.off_hit[k] = &grid.hit[n];
    cs.off_found[k] = grid.found[n];
  }
  return cs;
}

uint64_t trace_camera_row(const GptContext& g, int W, int H, int x0, int y, int n, uint32_t index,
                          CameraRow& row) {
  const CameraModel& camera = g.ctx.camera();
  const int rx = camera.region_x(), ry = camera.region_y();  // frame raster
  for (int i = 0; i < kRow; ++i) {
    row.valid[i] = i < n;
    if (!row.valid[i]) continue;
    const int x = x0 + i;
    start_sample(g, row.sampler[i], x + rx, y + ry, index);
    const Vec2f jitter = row.sampler[i].get2d(Sampler::kDimCamera);
    row.lens[i] = row.sampler[i].get2d(Sampler::kDimLens);
    row.raster[i] = g.ctx.pixel_filter().raster(x + rx, y + ry, jitter);
    row.ray[i] = camera.generate_ray(row.raster[i], row.lens[i]);
  }
  g.ctx.bvh().intersect_stream(row.ray, row.valid, kRow, row.found, row.hit);
  uint64_t rays = uint64_t(n);
  for (int i = 0; i < kRow; ++i) {
    bool* mask = row.mask[i];
    offset_mask(W, H, x0 + i, y, mask);
    const bool traced = row.valid[i] && row.found[i];
    Ray* cam = row.cam_pixel;
    if (traced) camera.generate_offset_rays(row.raster[i], row.lens[i], mask, cam);
    for (int k = 0; k < kOffsets; ++k) {
      row.cam_valid[k * kRow + i] = traced && mask[k];
      if (row.cam_valid[k * kRow + i]) row.cam[k * kRow + i] = cam[k];
      rays += row.cam_valid[k * kRow + i];
    }
  }
  g.ctx.bvh().intersect_stream(row.cam, row.cam_valid, kOffsets * kRow, row.cam_found, row.cam_hit);
  return rays;
}

CameraSample row_sample(const CameraRow& row, int i) {
  CameraSample cs;
  cs.mask = row.mask[i];
  cs.ray = &row.ray[i];
  cs.hit = &row.hit[i];
  cs.found = row.found[i];
  for (int k = 0; k < kOffsets; ++k) {
    cs.off_ray[k] = &row.cam[k * kRow + i];
    cs.off_hit[k] = &row.cam_hit[k * kRow + i];
    cs.off_found[k] = row.cam_found[k * kRow + i];
  }
  return cs;
}

}  // namespace gdpt
