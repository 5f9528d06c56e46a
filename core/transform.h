// Affine 3x4 transform, row-major (the top three rows of Blender's matrix_world).
#pragma once

#include "core/vec.h"

namespace gdpt {

struct Transform {
  float m[3][4] = {{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}};

  static Transform from_rows(const float* rows12) {
    Transform t;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) t.m[r][c] = rows12[r * 4 + c];
    return t;
  }
  Vec3f point(Vec3f p) const {
    return {m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
            m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
            m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]};
  }
  Vec3f vector(Vec3f v) const {
    return {m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z,
            m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z,
            m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z};
  }
  Vec3f column(int c) const { return {m[0][c], m[1][c], m[2][c]}; }
  Vec3f translation() const { return column(3); }

  // Inverse of the affine map (general 3x3 inverse; scale and shear allowed).
  Transform inverse() const {
    const float a = m[0][0], b = m[0][1], c = m[0][2];
    const float d = m[1][0], e = m[1][1], f = m[1][2];
    const float g = m[2][0], h = m[2][1], i = m[2][2];
    const float A = e * i - f * h, B = -(d * i - f * g), C = d * h - e * g;
    const float det = a * A + b * B + c * C;
    const float inv_det = 1.0f / det;
    Transform r;
    r.m[0][0] = A * inv_det;
    r.m[0][1] = -(b * i - c * h) * inv_det;
    r.m[0][2] = (b * f - c * e) * inv_det;
    r.m[1][0] = B * inv_det;
    r.m[1][1] = (a * i - c * g) * inv_det;
    r.m[1][2] = -(a * f - c * d) * inv_det;
    r.m[2][0] = C * inv_det;
    r.m[2][1] = -(a * h - b * g) * inv_det;
    r.m[2][2] = (a * e - b * d) * inv_det;
    const Vec3f t = translation();
    for (int row = 0; row < 3; ++row)
      r.m[row][3] = -(r.m[row][0] * t.x + r.m[row][1] * t.y + r.m[row][2] * t.z);
    return r;
  }
  // Normals transform with the inverse transpose: n' = (M^-1)^T n.
  Vec3f normal(Vec3f n) const {
    const Transform inv = inverse();
    return {inv.m[0][0] * n.x + inv.m[1][0] * n.y + inv.m[2][0] * n.z,
            inv.m[0][1] * n.x + inv.m[1][1] * n.y + inv.m[2][1] * n.z,
            inv.m[0][2] * n.x + inv.m[1][2] * n.y + inv.m[2][2] * n.z};
  }
};

}  // namespace gdpt
