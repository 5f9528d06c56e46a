#include "reconstruct/dct_solver.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <mutex>
#include <tuple>
#include <vector>

#include <fftw3.h>

#include "reconstruct/parallel.h"

namespace gdpt::detail {

void FftwFree::operator()(double* p) const {
  fftw_free(p);
}

DctBuffer dct_alloc(size_t count) {
  auto* p = static_cast<double*>(fftw_malloc(sizeof(double) * std::max<size_t>(count, 1)));
  if (!p) throw std::bad_alloc();
  return DctBuffer(p);
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
  // FFTW_MEASURE overwrites the buffer while planning: plan on scratch memory. Execution later
  // uses other fftw_malloc buffers, which have the same alignment.
  DctBuffer scratch = dct_alloc(size_t(3) * width * height);
  const unsigned flags = measure ? FFTW_MEASURE : FFTW_ESTIMATE;
  PlanPair pair;
  pair.forward = make_plan(width, height, FFTW_REDFT10, scratch.get(), flags);
  pair.inverse = make_plan(width, height, FFTW_REDFT01, scratch.get(), flags);
  if (!pair.forward || !pair.inverse) throw std::runtime_error("FFTW could not create a DCT plan");
  if (measure && !wisdom.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(std::filesystem::path(wisdom).parent_path(), ec);
    fftw_export_wisdom_to_filename(wisdom.c_str());  // best effort: a read-only home is fine
  }
  return g_plans.emplace(key, pair).first->second;
}

}  // namespace

void dct_round_trip(int width, int height, double* planes, int threads, bool measure) {
  const PlanPair& p = plans_for(width, height, threads, measure);
  fftw_execute_r2r(p.forward, planes, planes);
  fftw_execute_r2r(p.inverse, planes, planes);
}

void solve_l2_dct(int width, int height, double alpha, const float* primal, const float* gradient_x,
                  const float* gradient_y, double* planes, int threads, bool measure) {
  const PlanPair& plans = plans_for(width, height, threads, measure);
  const size_t plane = size_t(width) * height;
  const double alpha2 = alpha * alpha;

  // --- Right-hand side b = alpha^2 primal + Dx^T dx + Dy^T dy, deinterleaved into planes.
  // (Dx^T g)(x) = g(x - 1) - g(x), where g(-1) and g(W - 1) are not part of the objective (zero).
  parallel_rows(height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const size_t row = size_t(y) * width;
      for (int x = 0; x < width; ++x) {
        const size_t i = row + x;
        for (int c = 0; c < 3; ++c) {
          double b = alpha2 * primal[3 * i + c];
          if (x < width - 1) b -= gradient_x[3 * i + c];
          if (x > 0) b += gradient_x[3 * (i - 1) + c];
          if (y < height - 1) b -= gradient_y[3 * i + c];
          if (y > 0) b += gradient_y[3 * (i - width) + c];
          planes[c * plane + i] = b;
        }
      }
    }
  });

  fftw_execute_r2r(plans.forward, planes, planes);

  // --- Divide by the eigenvalues; 1 / (4 W H) undoes the unnormalised REDFT10 -> REDFT01 pair.
  std::vector<double> lambda_x(width);
  for (int k = 0; k < width; ++k) lambda_x[k] = 2.0 - 2.0 * std::cos(M_PI * k / width);
  const double norm = 1.0 / (4.0 * double(width) * double(height));
  parallel_rows(height, [&](int y0, int y1) {
    for (int y = y0; y < y1; ++y) {
      const double lambda_y = 2.0 - 2.0 * std::cos(M_PI * y / height) + alpha2;
      for (int c = 0; c < 3; ++c) {
        double* row = planes + c * plane + size_t(y) * width;
        for (int x = 0; x < width; ++x) row[x] *= norm / (lambda_x[x] + lambda_y);
      }
    }
  });

  fftw_execute_r2r(plans.inverse, planes, planes);
}

}  // namespace gdpt::detail
