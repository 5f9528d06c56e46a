// Plain-data scene description: everything the integrator needs, with no Blender or Python
// types. The add-on fills it from the depsgraph with flat arrays; tests build it directly.
// Conventions follow Blender/Cycles so a .blend renders as bright as in Cycles.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/transform.h"
#include "core/vec.h"
#include "scene/material_desc.h"

namespace gdpt {

// Triangle mesh in object space. Attributes are per triangle corner (Blender loop triangles),
// except vertex_normals.
struct Mesh {
  std::vector<Vec3f> positions;       // vertices
  std::vector<uint32_t> indices;      // 3 per triangle, into positions
  std::vector<Vec3f> corner_normals;  // 3 per triangle (split normals); empty = flat shading
  std::vector<Vec2f> corner_uvs;      // 3 per triangle; empty = no UVs (uv = 0)
  // 3 per triangle, for Normal Map nodes (NormalMapDesc): the UV map's tangents (Blender's
  // MikkTSpace, object space) and bitangent signs; empty = none (normal maps do nothing).
  std::vector<Vec3f> corner_tangents;
  std::vector<float> corner_tangent_signs;
  // 3 per triangle, for Color Attribute nodes: the attribute's linear RGB; empty = none (the
  // node reads black, as in Cycles).
  std::vector<Vec3f> corner_colors;
  // For the Geometry node, computed only for meshes whose materials read them (both empty =
  // none: they read 0): Pointiness per vertex (in [0, 1], interpolated over the triangle) and
  // Random Per Island per triangle (Cycles' hash of the triangle's island).
  std::vector<float> vertex_pointiness;
  std::vector<float> triangle_island_random;
  std::vector<int32_t> material_slot;  // per triangle; empty = slot 0
  // Per-vertex shading normals, used when corner_normals is empty: what a smooth mesh without
  // split normals has, in a sixth of the memory (a 1M-triangle smooth mesh: 6 MB instead of the
  // 36 MB of corner normals). Both empty = flat shading.
  std::vector<Vec3f> vertex_normals;
  // Texture space (Blender's Mesh.texspace_location / texspace_size): Generated coordinates are
  // (p - location) / (2 size) + 0.5 per axis. A zero size means the bounding box (Blender's auto
  // texture space), with flat axes of size 1 as Blender sets them.
  Vec3f texspace_location{0.0f}, texspace_size{0.0f};
  size_t triangle_count() const { return indices.size() / 3; }
};

// A placement of a mesh. Many instances share one Mesh (Embree two-level instancing).
// Kinds of rays, as Blender's Object > Visibility > Ray Visibility names them (Cycles' path
// flags), one bit each: a ray hits an instance only when the instance's `visibility` has the bit
// of the ray's kind (Embree's ray and geometry masks). A ray continuing straight through a
// Transparent surface keeps its kind; a BSDF-sampled ray is diffuse, glossy or transmission by
// the lobe it came from (ray_kind_of_lobe).
enum RayKind : uint32_t {
  kRayCamera = 1u << 0,
  kRayDiffuse = 1u << 1,
  kRayGlossy = 1u << 2,
  kRayTransmission = 1u << 3,
  kRayShadow = 1u << 4,
  kRayAll = 0xffffffffu,
};

struct Instance {
  uint32_t mesh = 0;
  Transform object_to_world;
  std::vector<int32_t> slot_material;  // slot -> index in Scene::materials (-1 = default)
  float pass_index = 0.0f;        // Blender's Object > Relations > Pass Index (the IndexOB pass)
  uint32_t visibility = kRayAll;  // RayKind bits of the rays that see this instance
  // Blender's Object > Visibility > Mask > Holdout: where the camera path meets it, the path
  // ends with nothing added, and with Film > Transparent the pixel's coverage drops (Cycles).
  bool holdout = false;
  // Object > Shading > Shadow Terminator > Geometry Offset (Cycles' object setting, default 0.1):
  // shadow rays from smooth-shaded triangles near the terminator start from the curved surface
  // (core/shadow_terminator.h); 0 turns it off.
  float terminator_geometry_offset = 0.1f;
  // Object > Shading > Shadow Terminator > Shading Offset (Cycles' object setting, in [0, 1],
  // default 0): the BSDFs' values darken towards the terminator (core/shadow_terminator.h).
  float terminator_shading_offset = 0.0f;
  // obj.cycles.is_caustics_caster (Shadow Caustics): a refractive object whose caustics MNEE finds
  bool caustics_caster = false;
  // obj.cycles.is_caustics_receiver (Shadow Caustics): a surface that receives those caustics
  bool caustics_receiver = false;
};

// Blender camera. Looks down its local -Z with +Y up, like Blender.
struct Camera {
  enum class Projection : uint8_t {
    Perspective,
    Orthographic
  } projection = Projection::Perspective;
  enum class SensorFit : uint8_t { Auto, Horizontal, Vertical } sensor_fit = SensorFit::Auto;
  Transform camera_to_world;
  float focal_length_mm = 50.0f;
  float sensor_width_mm = 36.0f;
  float sensor_height_mm = 24.0f;
  float shift_x = 0.0f, shift_y = 0.0f;  // in units of the larger sensor dimension, as Blender
  float ortho_scale = 6.0f;
  float clip_start = 0.1f, clip_end = 1000.0f;
  float aperture_radius = 0.0f;   // metres; 0 = pinhole (Blender: focal_length / (2 f-stop))
  float focus_distance = 10.0f;   // metres along -Z
  int width = 640, height = 480;  // pixels after resolution percentage (the whole frame)
  float pixel_aspect = 1.0f;      // pixel_aspect_x / pixel_aspect_y
  // Render region (Blender's border): the rendered image is the region_width x region_height
  // block of the frame whose bottom-left pixel is (region_x, region_y); a pixel of it sees and
  // samples exactly what the same pixel of the whole frame does. 0 x 0: the whole frame.
  int region_x = 0, region_y = 0, region_width = 0, region_height = 0;

  bool has_region() const { return region_width > 0 && region_height > 0; }
  // Size of the rendered image (film, passes): the region, or the whole frame.
  int image_width() const { return has_region() ? region_width : width; }
  int image_height() const { return has_region() ? region_height : height; }
};

// Blender light object. Emission direction is the light's local -Z (spot, sun, area).
struct Light {
  enum class Type : uint8_t { Point, Spot, Sun, Area } type = Type::Point;
  enum class Shape : uint8_t { Square, Rectangle, Disk, Ellipse } shape = Shape::Square;
  Transform light_to_world;
  Spectrum color{1.0f, 1.0f, 1.0f};
  float power = 10.0f;       // W for point/spot/area, W/m^2 irradiance for sun
  float radius = 0.0f;       // point/spot soft size (sphere radius), metres
  float spot_size = 0.785f;  // full cone angle, radians
  float spot_blend = 0.15f;
  float sun_angle = 0.0f;              // angular diameter, radians
  float size_x = 1.0f, size_y = 1.0f;  // area light extent, metres (before object scale)
  // Blender's Object.visible_camera: camera rays see the lamp itself (default False in 3.4).
  bool camera_visible = false;
  // Cycles' Light > Cast Shadow (light.cycles.cast_shadow): off, light samples of this lamp skip
  // the shadow ray (nothing occludes it); rays that hit it by BSDF sampling are still blocked.
  bool cast_shadow = true;
  // light.cycles.is_caustics_light (Cycles' Shadow Caustics): the lamp lights shadow caustics
  bool caustics_light = false;
};

// A world background: a constant colour, or an equirectangular image, times strength.
struct Background {
  Spectrum color{0.05f, 0.05f, 0.05f};  // Blender's default world grey
  float strength = 1.0f;
  int32_t image = -1;  // equirectangular environment in Scene::images; -1 = constant colour
  Transform rotation;  // world direction -> environment lookup direction (Mapping node rotation)
};

// The background that lights the scene, and what camera rays see of the world instead when its
// node tree gives them their own (a Mix Shader by Light Path's Is Camera Ray).
struct World : Background {
  std::optional<Background> camera_view;
};

struct Scene {
  std::vector<Mesh> meshes;
  std::vector<Instance> instances;
  std::vector<MaterialDesc> materials;
  std::vector<ImageDesc> images;
  std::vector<Light> lights;
  Camera camera;
  World world;
};

}  // namespace gdpt
