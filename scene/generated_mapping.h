// Blender's Generated texture coordinates of a mesh as an affine map of its object space:
// (p - location) / (2 size) + 0.5 per axis (Cycles' mesh_texture_space).
#pragma once

#include <limits>

#include "core/vec.h"
#include "scene/scene.h"

namespace gdpt {

struct GeneratedMapping {
  Vec3f scale{0.0f}, offset{0.0f};  // generated = object * scale + offset
};

// The mesh's texture space, or its bounding box (Blender's auto texture space, flat axes of size
// 1) when it has none.
inline GeneratedMapping generated_mapping(const Mesh& mesh) {
  Vec3f location = mesh.texspace_location, size = mesh.texspace_size;
  if (size == Vec3f(0.0f)) {
    constexpr float kInf = std::numeric_limits<float>::infinity();
    Vec3f lo(kInf), hi(-kInf);
    for (const Vec3f& p : mesh.positions) {
      lo = min(lo, p);
      hi = max(hi, p);
    }
    if (mesh.positions.empty()) lo = Vec3f(-1.0f), hi = Vec3f(1.0f);
    location = (lo + hi) * 0.5f;
    size = (hi - lo) * 0.5f;
    for (int k = 0; k < 3; ++k)
      if (size[k] == 0.0f) size[k] = 1.0f;
  }
  GeneratedMapping g;
  for (int k = 0; k < 3; ++k) {
    g.scale[k] = size[k] != 0.0f ? 0.5f / size[k] : 0.0f;
    g.offset[k] = 0.5f - location[k] * g.scale[k];
  }
  return g;
}

}  // namespace gdpt
