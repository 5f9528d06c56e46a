// What a material needs to know about a hit point.
#pragma once

#include "integrator/math/vec.h"

namespace gdpt {

struct ShadingContext {
  Vec2f uv;                  // mesh UV (0 when the mesh has none)
  bool front_facing = true;  // the ray hit the side the geometric normal points to
};

}  // namespace gdpt
