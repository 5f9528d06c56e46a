#include "reconstruct/dct_solver.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <mutex>
#include <tuple>
#include <vector>

#include <fftw3.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/huge_pages.h"
#include "reconstruct/parallel.h"
#include "reconstruct/real_fft_dct.h"

namespace gdpt::detail {

void DctFree::operator()(double* p) const {
  free_huge(p);
}

DctBuffer dct_alloc(size_t count) {
  // 64 bytes is more than any SIMD FFTW uses (large buffers start on a huge page boundary).
  return DctBuffer(static_cast<double*>(allocate_huge(sizeof(double) * count, 64)));
}

namespace {
std::mutex g_buffer_mutex;
DctBuffer g_buffer;
size_t g_buffer_count = 0;
}  // namespace

CachedDctBuffer::CachedDctBuffer(size_t count) : count_(count) {
  {
    std::lock_guard lock(g_buffer_mutex);
    if (g_buffer && g_buffer_count == count) buffer_ = std::move(g_buffer);
  }
  if (!buffer_) buffer_ = dct_alloc(count);
}

CachedDctBuffer::~CachedDctBuffer() {
  DctBuffer old;  // freed outside the lock
  std::lock_guard lock(g_buffer_mutex);
  old = std::move(g_buffer);
  g_buffer = std::move(buffer_);
  g_buffer_count = count_;
}

std::string fftw_wisdom_path() {
  namespace fs = std::filesystem;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
    return (fs::path(xdg) / "gdpt" / "fftw-wisdom").string();
  if (const char* home = std::getenv("HOME"); home && *home)
    return (fs::path(home) / ".cache" / "gdpt" / "fftw-wisdom").string();
  return {};
}

namespace {

struct PlanPair {
  fftw_plan forward = nullptr;  // REDFT10 in both dimensions (DCT-II)
  fftw_plan inverse = nullptr;  // REDFT01 in both dimensions (DCT-III)
};

// The FFTW planner is not thread-safe; executing a plan is. Plans live until the process exits
// (they are tiny next to the images and the add-on solves the same sizes render after render).
std::mutex g_plan_mutex;
std::map<std::tuple<int, int, int, bool>, PlanPair> g_plans;
bool g_threads_initialised = false;
bool g_wisdom_loaded = false;

// Planner set-up shared by both plan caches (caller holds g_plan_mutex): FFTW's threads
// initialised once, wisdom loaded before the first measured plan; returns the planner flags.
unsigned begin_planning(bool measure, int threads) {
  if (!g_threads_initialised) {
    fftw_init_threads();
    g_threads_initialised = true;
  }
  const std::string wisdom = fftw_wisdom_path();
  if (measure && !g_wisdom_loaded && !wisdom.empty()) {
    fftw_import_wisdom_from_filename(wisdom.c_str());  // a missing file is not an error
    g_wisdom_loaded = true;
  }
  fftw_plan_with_nthreads(threads);
  return measure ? FFTW_MEASURE : FFTW_ESTIMATE;
}

// After measured planning: save the wisdom (best effort: a read-only home is fine).
void end_planning(bool measure) {
  const std::string wisdom = fftw_wisdom_path();
  if (!measure || wisdom.empty()) return;
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(wisdom).parent_path(), ec);
  fftw_export_wisdom_to_filename(wisdom.c_str());
}

fftw_plan make_plan(int width, int height, fftw_r2r_kind kind, double* buffer, unsigned flags) {
  const int n[2] = {height, width};
  const fftw_r2r_kind kinds[2] = {kind, kind};
  const int plane = width * height;
  return fftw_plan_many_r2r(2, n, 3, buffer, nullptr, 1, plane, buffer, nullptr, 1, plane, kinds,
                            flags);
}

const PlanPair& plans_for(int width, int height, int threads, bool measure) {
  std::lock_guard lock(g_plan_mutex);
  const auto key = std::make_tuple(width, height, threads, measure);
  if (auto it = g_plans.find(key); it != g_plans.end()) return it->second;

  const unsigned flags = begin_planning(measure, threads);
  // FFTW_MEASURE overwrites the buffer while planning: plan on scratch memory. Execution later
  // uses other fftw_malloc buffers, which have the same alignment.
  DctBuffer scratch = dct_alloc(size_t(3) * width * height);
  PlanPair pair;
  pair.forward = make_plan(width, height, FFTW_REDFT10, scratch.get(), flags);
  pair.inverse = make_plan(width, height, FFTW_REDFT01, scratch.get(), flags);
  if (!pair.forward || !pair.inverse) throw std::runtime_error("FFTW could not create a DCT plan");
  end_planning(measure);
  return g_plans.emplace(key, pair).first->second;
}

}  // namespace

void dct_round_trip(int width, int height, double* planes, int threads, bool measure) {
  const PlanPair& p = plans_for(width, height, threads, measure);
  fftw_execute_r2r(p.forward, planes, planes);
  fftw_execute_r2r(p.inverse, planes, planes);
}

namespace {

// 1 when v is NaN or +-Inf (exponent all ones); integer compares, so the loops vectorise.
inline uint32_t not_finite(float v) {
  uint32_t u;
  std::memcpy(&u, &v, sizeof u);
  return uint32_t(int32_t(u & 0x7fffffffu) > 0x7f7fffff);
}

// b = alpha^2 primal + Dx^T dx + Dy^T dy of one row, interleaved RGB in `b` (3 * width values).
// (Dx^T g)(x) = g(x - 1) - g(x), where g(-1) and g(W - 1) are not part of the objective (zero);
// the same for rows: kBelow says row y - 1 exists (its dy enters with +), kAbove that row y + 1
// does (this row's dy enters with -). The boundary columns are peeled off, so the middle loop is
// branch-free over contiguous values; the operations are in the same order for every value.
template <bool kBelow, bool kAbove>
void rhs_row(int width, double alpha2, const float* p, const float* gx, const float* gy,
             const float* gy_below, double* b) {
  auto value = [&](int k, bool left, bool right) {
    double v = alpha2 * p[k];
    if (right) v -= gx[k];
    if (left) v += gx[k - 3];
    if constexpr (kAbove) v -= gy[k];
    if constexpr (kBelow) v += gy_below[k];
    return v;
  };
  const int n = 3 * width;
  if (width == 1) {
    for (int k = 0; k < 3; ++k) b[k] = value(k, false, false);
    return;
  }
  for (int k = 0; k < 3; ++k) b[k] = value(k, false, true);
  for (int k = 3; k < n - 3; ++k) b[k] = value(k, true, true);
  for (int k = n - 3; k < n; ++k) b[k] = value(k, true, false);
}

}  // namespace

namespace {

// One-line 1-D plans (single-threaded; the passes run them in parallel from TBB): rows of
// `width`, and blocks of kColumnBlock contiguous columns of `height`.
constexpr int kColumnBlock = 8;

// Row and column-block DCTs through real FFTs (real_fft_dct.h): about half the time of FFTW's
// REDFT10 / REDFT01 plans of the same lines.
struct LinePlans {
  RealFftDct row, column;
  LinePlans(int width, int height, unsigned flags)
      : row(width, 1, flags), column(height, kColumnBlock, flags) {}
};

std::map<std::tuple<int, int, bool>, LinePlans> g_line_plans;

const LinePlans& line_plans_for(int width, int height, bool measure) {
  std::lock_guard lock(g_plan_mutex);
  const auto key = std::make_tuple(width, height, measure);
  if (auto it = g_line_plans.find(key); it != g_line_plans.end()) return it->second;
  const unsigned flags = begin_planning(measure, 1);
  const LinePlans& p = g_line_plans.try_emplace(key, width, height, flags).first->second;
  end_planning(measure);
  return p;
}

}  // namespace

bool solve_l2_dct_rows(int width, int height, double alpha, const float* primal,
                       const float* gradient_x, const float* gradient_y, double* planes,
                       bool measure, const RowSink& sink) {
  const LinePlans& plans = line_plans_for(width, height, measure);
  const size_t plane = size_t(width) * height;
  const double alpha2 = alpha * alpha;
  const int n = 3 * width;

  // --- Pass 1, per row: the right-hand side b, the finiteness check of every input, and the
  // forward DCT along the row, into the planes.
  const auto bad = parallel_rows_sum<1>(height, [&](int y0, int y1, std::array<double, 1>& s) {
    std::vector<double> b(static_cast<size_t>(n)), line(static_cast<size_t>(width));
    RealFftDct::Work work(plans.row);
    uint32_t flags = 0;
    for (int y = y0; y < y1; ++y) {
      const size_t row = size_t(y) * width;
      const float *p = primal + 3 * row, *gx = gradient_x + 3 * row, *gy = gradient_y + 3 * row;
      for (int k = 0; k < n; ++k) flags |= not_finite(p[k]) | not_finite(gx[k]) | not_finite(gy[k]);
      const float* below = y > 0 ? gy - n : nullptr;
      if (y > 0 && y < height - 1)
        rhs_row<true, true>(width, alpha2, p, gx, gy, below, b.data());
      else if (y > 0)
        rhs_row<true, false>(width, alpha2, p, gx, gy, below, b.data());
      else if (y < height - 1)
        rhs_row<false, true>(width, alpha2, p, gx, gy, below, b.data());
      else
        rhs_row<false, false>(width, alpha2, p, gx, gy, below, b.data());
      for (int c = 0; c < 3; ++c) {
        for (int x = 0; x < width; ++x) line[size_t(x)] = b[3 * x + c];
        plans.row.forward(line.data(), work);
        std::memcpy(planes + c * plane + row, line.data(), sizeof(double) * width);
      }
    }
    s[0] += flags;
  });
  if (bad[0] != 0) return false;

  // --- Pass 2, per block of kColumnBlock columns: forward DCT along the columns, division by the
  // eigenvalues (and by 4 W H, which undoes the unnormalised REDFT10 -> REDFT01 pair), inverse
  // DCT along the columns. The factor is shared by the 3 planes.
  std::vector<double> lambda_x(width), lambda_y(height);
  for (int k = 0; k < width; ++k) lambda_x[k] = 2.0 - 2.0 * std::cos(M_PI * k / width);
  for (int k = 0; k < height; ++k) lambda_y[k] = 2.0 - 2.0 * std::cos(M_PI * k / height) + alpha2;
  const double norm = 1.0 / (4.0 * double(width) * double(height));
  const int blocks = (width + kColumnBlock - 1) / kColumnBlock;
  const size_t block_values = size_t(kColumnBlock) * height;
  tbb::parallel_for(tbb::blocked_range<int>(0, blocks, 1), [&](const tbb::blocked_range<int>& r) {
    const FlushDenormals ftz;
    std::vector<double> cols(3 * block_values);
    RealFftDct::Work work(plans.column);
    for (int blk = r.begin(); blk != r.end(); ++blk) {
      const int x0 = blk * kColumnBlock, m = std::min(kColumnBlock, width - x0);
      for (int c = 0; c < 3; ++c) {
        double* col = cols.data() + c * block_values;
        for (int y = 0; y < height; ++y) {
          const double* src = planes + c * plane + size_t(y) * width + x0;
          for (int j = 0; j < m; ++j) col[j * height + y] = src[j];
        }
        for (int j = m; j < kColumnBlock; ++j) std::fill_n(col + j * height, height, 0.0);
        plans.column.forward(col, work);
      }
      for (int j = 0; j < m; ++j) {
        double* c0 = cols.data() + j * height;
        double* c1 = c0 + block_values;
        double* c2 = c1 + block_values;
        const double lx = lambda_x[x0 + j];
        for (int k = 0; k < height; ++k) {
          const double f = norm / (lx + lambda_y[k]);
          c0[k] *= f;
          c1[k] *= f;
          c2[k] *= f;
        }
      }
      for (int c = 0; c < 3; ++c) {
        double* col = cols.data() + c * block_values;
        plans.column.inverse(col, work);
        for (int y = 0; y < height; ++y) {
          double* dst = planes + c * plane + size_t(y) * width + x0;
          for (int j = 0; j < m; ++j) dst[j] = col[j * height + y];
        }
      }
    }
  });

  // --- Pass 3, per row: inverse DCT along the row, handed to the sink.
  parallel_rows(height, [&](int y0, int y1) {
    std::vector<double> lines(3 * size_t(width));
    RealFftDct::Work work(plans.row);
    const double* rows[3] = {lines.data(), lines.data() + width, lines.data() + 2 * width};
    for (int y = y0; y < y1; ++y) {
      for (int c = 0; c < 3; ++c) {
        double* line = lines.data() + c * width;
        std::memcpy(line, planes + c * plane + size_t(y) * width, sizeof(double) * width);
        plans.row.inverse(line, work);
      }
      sink(y, rows);
    }
  });
  return true;
}

bool solve_l2_dct(int width, int height, double alpha, const float* primal, const float* gradient_x,
                  const float* gradient_y, double* planes, bool measure) {
  const size_t plane = size_t(width) * height;
  return solve_l2_dct_rows(width, height, alpha, primal, gradient_x, gradient_y, planes, measure,
                           [&](int y, const double* const* rows) {
                             for (int c = 0; c < 3; ++c)
                               std::memcpy(planes + c * plane + size_t(y) * width, rows[c],
                                           sizeof(double) * width);
                           });
}

}  // namespace gdpt::detail
