// What a material needs to know about a hit point.
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/transform.h"
#include "core/vec.h"

namespace gdpt {

// Object-space coordinates of a hit, for textures that read Generated or Object coordinates.
struct TexCoords {
  Vec3f generated;  // TexCoordSource::Generated
  Vec3f object;     // TexCoordSource::Object
  Vec3f position;   // TexCoordSource::Position (world space)
  // Columns of the instance's normal matrix (object to world, the inverse transpose), 4 floats
  // each; null: identity. Radial tangents are object-space directions taken to world space so.
  const float (*normal_cols)[4] = nullptr;
  // The mesh's MikkTSpace tangent of its UV map (Mesh::corner_tangents), object space,
  // interpolated; zero where the mesh has none.
  Vec3f uv_tangent{0.0f};
};

// The hit as seen along the incoming ray, for nodes that read the view (Fresnel, Layer Weight,
// Geometry): world space, unit, every normal flipped to the incoming ray's side for back faces
// as Cycles flips sd->N and sd->Ng.
struct ShadingGeometry {
  Vec3f incoming;          // from the hit back along the incoming ray (Cycles' sd->wi, "I")
  Vec3f normal;            // interpolated normal, no normal map / bump (Cycles' sd->N)
  Vec3f perturbed_normal;  // the material's normal map / bump applied (= normal without one)
  Vec3f true_normal;       // the triangle's normal (Cycles' sd->Ng)
};

// The path that reached the hit, for the Light Path node (Cycles' path flags and bounce counts
// when the surface is shaded).
struct PathView {
  uint8_t lobe = 0;  // LobeFlags (closure.h) of the event that spawned the incoming ray; 0: the
                     // camera path (nothing but transparent crossings since the camera)
  // Emission evaluated for a light sample (Cycles' PATH_RAY_EMISSION alone): every Is ... Ray
  // output reads 0.
  bool light_sample = false;
  float ray_length = 0.0f;  // length of the incoming ray segment
  int16_t depth = 0, diffuse_depth = 0, glossy_depth = 0, transmission_depth = 0,
          transparent_depth = 0;
};

// The Geometry node's mesh attributes at a hit (see GeometryOutput).
struct SurfaceAttributes {
  float pointiness = 0.0f;         // Mesh::vertex_pointiness interpolated; 0 without
  float random_per_island = 0.0f;  // Mesh::triangle_island_random of the triangle; 0 without
  Vec2f barycentric;               // (u, v): the hit is (1 - u - v) p0 + u p1 + v p2
};

// The instance a hit lies on, for nodes that read its placement or its triangle (Vector
// Transform's Object space, Wireframe): Cycles' object transform and the mesh's corners.
struct ShadingInstance {
  Transform object_to_world, world_to_object;
  const Vec3f* positions = nullptr;   // the mesh's object-space vertices
  const uint32_t* indices = nullptr;  // 3 per triangle
  // Generated = object * generated_scale + generated_offset (coords_at; hits carry their own).
  Vec3f generated_scale{0.0f}, generated_offset{0.0f};
  // The frequency multiplier of the object's shadow terminator shading offset (1: none;
  // core/shadow_terminator.h), applied by the integrators' shading_closures().
  float terminator_frequency = 1.0f;
  // Corner k of triangle `primitive`, in world space.
  Vec3f corner(uint32_t primitive, int k) const {
    return object_to_world.point(positions[indices[3 * size_t(primitive) + size_t(k)]]);
  }
  // The texture coordinates of world point p on it (a light sample's point).
  TexCoords coords_at(Vec3f p) const {
    const Vec3f object = world_to_object.point(p);
    return {object * generated_scale + generated_offset, object, p};
  }
};

// The render camera as shading nodes see it (Vector Transform's Camera space, Wireframe's pixel
// size).
struct ShadingCamera {
  // Cycles' camera space: Blender's camera with its scale cleared and its z negated (x right,
  // y up, z into the view).
  Transform camera_to_world, world_to_camera;
  // Perspective: one pixel's step on the image plane at unit depth (camera units); orthographic:
  // one pixel's size in world units.
  bool orthographic = false;
  float pixel_x = 0.0f, pixel_y = 0.0f;
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
  // The view of the hit when the caller knows the incoming ray, else null (view nodes then read
  // normal incidence). A material that reads it (Material::reads_view) is evaluated per hit, and
  // each G-PT path (base or offset) evaluates it with its own incoming direction.
  const ShadingGeometry* geometry = nullptr;
  // The path when the caller knows it, else null (a camera ray of length 0). A material that
  // reads it (Material::reads_path) is evaluated per hit; a G-PT offset passes its own length.
  const PathView* path = nullptr;
  // The hit's instance and triangle, else null (object space is world space, no triangle).
  const ShadingInstance* instance = nullptr;
  uint32_t primitive = 0;
  // The hit's mesh attributes when its instance's materials read them, else null (they read 0).
  const SurfaceAttributes* attributes = nullptr;
};

}  // namespace gdpt
