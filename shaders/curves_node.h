// Blender's curve nodes (RGB Curves, Vector Curves, Float Curve) over a baked table, and the
// Blackbody node, with Cycles' formulas (kernel/svm/ramp.h, curves.h, math_util.h).
#pragma once

#include <algorithm>
#include <span>

#include "core/vec.h"

namespace gdpt {

// Column `channel` of a table of RGBA entries (4 floats each, at least 2) read at f in [0, 1]:
// interpolated linearly, and extrapolated along the end segments outside [0, 1]
// (rgb_ramp_lookup with interpolation and extrapolation).
inline float curve_table_lookup(std::span<const float> table, float f, int channel) {
  const int size = int(table.size() / 4);
  auto at = [&](int i) { return table[4 * size_t(i) + size_t(channel)]; };
  if (f < 0.0f) return at(0) + (at(0) - at(1)) * (-f) * float(size - 1);
  if (f > 1.0f) return at(size - 1) + (at(size - 1) - at(size - 2)) * (f - 1.0f) * float(size - 1);
  const float x = f * float(size - 1);
  const int i = std::clamp(int(x), 0, size - 1);
  const float t = x - float(i);
  return t > 0.0f ? (1.0f - t) * at(i) + t * at(i + 1) : at(i);
}

// A curve node: each of the `channels` components of v looked up in its own column, with the
// table spanning [min_x, max_x] of the curves' input, mixed with v by fac.
inline Vec3f curves_node(std::span<const float> table, float min_x, float max_x, Vec3f v, float fac,
                         int channels) {
  const float range = max_x - min_x;
  Vec3f r = v;
  for (int k = 0; k < channels; ++k) {
    const float mapped = curve_table_lookup(table, (v[k] - min_x) / range, k);
    r[k] = (1.0f - fac) * v[k] + fac * mapped;
  }
  return r;
}

// Cycles' fit of the Rec.709 colour of a black body at temperature t (kelvin): a / t + b t + c
// for red and green, a cubic in t for blue, over seven ranges; constants outside 800 .. 12000 K.
// Negative components (outside the Rec.709 gamut) are clamped to zero, as the node does.
inline Vec3f blackbody_color(float t) {
  static constexpr float kR[7][3] = {{1.61919106e+03f, -2.05010916e-03f, 5.02995757e+00f},
                                     {2.48845471e+03f, -1.11330907e-03f, 3.22621544e+00f},
                                     {3.34143193e+03f, -4.86551192e-04f, 1.76486769e+00f},
                                     {4.09461742e+03f, -1.27446582e-04f, 7.25731635e-01f},
                                     {4.67028036e+03f, 2.91258199e-05f, 1.26703442e-01f},
                                     {4.59509185e+03f, 2.87495649e-05f, 1.50345020e-01f},
                                     {3.78717450e+03f, 9.35907826e-06f, 3.99075871e-01f}};
  static constexpr float kG[7][3] = {{-4.88999748e+02f, 6.04330754e-04f, -7.55807526e-02f},
                                     {-7.55994277e+02f, 3.16730098e-04f, 4.78306139e-01f},
                                     {-1.02363977e+03f, 1.20223470e-04f, 9.36662319e-01f},
                                     {-1.26571316e+03f, 4.87340896e-06f, 1.27054498e+00f},
                                     {-1.42529332e+03f, -4.01150431e-05f, 1.43972784e+00f},
                                     {-1.17554822e+03f, -2.16378048e-05f, 1.30408023e+00f},
                                     {-5.00799571e+02f, -4.59832026e-06f, 1.09098763e+00f}};
  static constexpr float kB[7][4] = {
      {5.96945309e-11f, -4.85742887e-08f, -9.70622247e-05f, -4.07936148e-03f},
      {2.40430366e-11f, 5.55021075e-08f, -1.98503712e-04f, 2.89312858e-02f},
      {-1.40949732e-11f, 1.89878968e-07f, -3.56632824e-04f, 9.10767778e-02f},
      {-3.61460868e-11f, 2.84822009e-07f, -4.93211319e-04f, 1.56723440e-01f},
      {-1.97075738e-11f, 1.75359352e-07f, -2.50542825e-04f, -2.22783266e-02f},
      {-1.61997957e-13f, -1.64216008e-08f, 3.86216271e-04f, -7.38077418e-01f},
      {6.72650283e-13f, -2.73078809e-08f, 4.24098264e-04f, -7.52335691e-01f}};
  Vec3f c;
  if (t >= 12000.0f) {
    c = Vec3f(0.8262954810464208f, 0.9945080501520986f, 1.566307710274283f);
  } else if (!(t >= 800.0f)) {  // also NaN
    c = Vec3f(5.413294490189271f, -0.20319390035873933f, -0.0822535242887164f);
  } else {
    const int i = t >= 6365.0f   ? 6
                  : t >= 3315.0f ? 5
                  : t >= 1902.0f ? 4
                  : t >= 1449.0f ? 3
                  : t >= 1167.0f ? 2
                  : t >= 965.0f  ? 1
                                 : 0;
    const float inv = 1.0f / t;
    c = Vec3f(kR[i][0] * inv + kR[i][1] * t + kR[i][2], kG[i][0] * inv + kG[i][1] * t + kG[i][2],
              ((kB[i][0] * t + kB[i][1]) * t + kB[i][2]) * t + kB[i][3]);
  }
  return Vec3f(std::max(c.x, 0.0f), std::max(c.y, 0.0f), std::max(c.z, 0.0f));
}

}  // namespace gdpt
