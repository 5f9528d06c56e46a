// What a material needs to know about a hit point.
#pragma once

#include "core/vec.h"

namespace gdpt {

// Object-space coordinates of a hit, for textures that read Generated or Object coordinates.
struct TexCoords {
  Vec3f generated;  // TexCoordSource::Generated
  Vec3f object;     // TexCoordSource::Object
  Vec3f position;   // TexCoordSource::Position (world space)
};

struct ShadingContext {
  Vec2f uv;                  // mesh UV (0 when the mesh has none)
  bool front_facing = true;  // the ray hit the side the geometric normal points to
  // The mesh's colour attribute (Mesh::corner_colors) when the hit has one, else null (black).
  // A pointer: most materials never read it, and the context is built at every vertex.
  const Vec3f* color = nullptr;
  // The hit's object-space coordinates when its instance's materials read them, else null
  // (zero coordinates).
  const TexCoords* coords = nullptr;
};

}  // namespace gdpt
