// Gradient-domain path tracer (Kettunen et al. 2015, "Gradient-Domain Path Tracing").
//
// For every pixel sample a base path through p + u (u = jitter, same lens sample) and up to four
// offset paths through p + u + (+-1, 0), (0, +-1) are traced with the same random numbers. The
// offsets follow the base vertex by vertex (integrators/gpt/shift_mapping.h): reconnection where
// the base vertex, its successor and the offset vertex are all rough enough, half-vector copy
// through specular vertices, kills where the shift would not be invertible. Each base/offset pair
// is a two-pixel MIS estimator (power heuristic over {base, offset} x {light, BSDF sample}) of the
// pixel difference, so
//   dx(x, y) = G_right(x, y) - G_left(x + 1, y),   dy(x, y) = G_up(x, y) - G_down(x, y + 1),
// where G_k(p) = sum over the path's emission events of w (f'J - f) for the offset shifted by k
// from the base at p. The two one-sided halves are the two MIS techniques of one estimator: they
// are summed, not averaged (their weights sum to one per path pair).
//
// Film outputs (render/film.h): primal = the base path's ordinary PT estimate (NEE + BSDF
// sampling, power heuristic), emission = camera-visible emission (never shifted), dx/dy as above
// (each half with its own sum of squared luminance; the halves come from different pixels' base
// paths, so their variances add), shift attempts / failures of the pixel's own offsets. The last
// column has dx = 0 and the last row dy = 0 (the Neumann rows of the reconstruction).
//
// Threads: render_tile() writes only the pixels of its tile. Each pixel stores its own four
// halves (G_right and G_up in Film::GradientAccumulator::dx/dy, G_left and G_down in
// dx_left/dy_down); the film combines them with the neighbours' at read-out, so no tile traces
// another tile's base paths. Sample values depend only on (seed, pixel, sample index), so the
// result is bit-identical for any tile order or thread count.
#pragma once

#include <memory>

#include "integrators/integrator.h"

namespace gdpt {

std::unique_ptr<Integrator> make_gradient_path_tracer(const SceneContext& ctx,
                                                      const RenderSettings& settings);

}  // namespace gdpt
