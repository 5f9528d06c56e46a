// Conversion of the add-on's flat numpy arrays and small dicts into the plain-data gdpt::Scene.
//
// The Python side (blender_addon/gdpt/export_*.py) owns every Blender concept; this layer only
// checks shapes and copies contiguous float32/int32 buffers into the Scene's vectors (one memcpy
// per array: the arrays are taken with noconvert, so a wrong dtype is an error, not a silent copy).
//
// Dict layouts (keys are the Scene field names):
//   camera:   projection 'PERSP'|'ORTHO', sensor_fit 'AUTO'|'HORIZONTAL'|'VERTICAL', matrix (12
//             floats, row-major 3x4), focal_length_mm, sensor_width_mm, sensor_height_mm, shift_x,
//             shift_y, ortho_scale, clip_start, clip_end, aperture_radius, focus_distance, width,
//             height, pixel_aspect
//   light:    type 'POINT'|'SPOT'|'SUN'|'AREA', shape 'SQUARE'|'RECTANGLE'|'DISK'|'ELLIPSE',
//             matrix, color (3), power, radius, spot_size, spot_blend, sun_angle, size_x, size_y,
//             camera_visible, cast_shadow, caustics_light
//   world:    color (3), strength, image (int), rotation (12 floats)
//   material: name, root, nodes: list of dicts {kind: 'DIFFUSE'|'GLOSSY'|'GLASS'|'PRINCIPLED'|
//             'EMISSION'|'TRANSPARENT'|'MIX'|'ADD', a, b, distribution 'GGX'|'BECKMANN' (Glossy,
//             Glass, Refraction, Anisotropic)|'ASHIKHMIN_SHIRLEY' (Glossy, Anisotropic)|
//             'MULTI_GGX' (Glossy, Glass, Anisotropic, Principled), and inputs color, roughness,
//             ior, strength, fac, metallic, specular, specular_tint, transmission, alpha, emission,
//             emission_strength, subsurface, subsurface_color}; a colour input is {value: (3),
//             image, mapping (12), coordinates 'UV'|'GENERATED'|'OBJECT', interpolation
//             'Linear'|'Closest', extension 'REPEAT'|'EXTEND'|'CLIP', node}, a float input the same
//             with a scalar value and channel 'LUMINANCE'|'RED'|'ALPHA'; input nodes (inputs)
//             {kind, ..., vector: {coordinates, mapping} for 'CHECKER' / 'NOISE', fac_output}.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <optional>
#include <span>
#include <string>

#include "scene/scene.h"
#include "shaders/texture.h"

namespace gdpt::python {

namespace py = pybind11;

using FloatArray = py::array_t<float, py::array::c_style>;
using IntArray = py::array_t<int32_t, py::array::c_style>;

// numpy.empty(count, dtype) for arrays that Blender's foreach_get fills: large ones are advised as
// transparent huge pages before their first touch (see advise_huge_pages in scene_convert.cpp).
py::array empty_array(py::ssize_t count, const py::dtype& dtype);

// A copy of one exported mesh, kept by the viewport across exports so that a change that leaves
// the geometry alone does not read the mesh from Blender again (SceneBuilder::stored_mesh).
struct StoredMesh {
  std::shared_ptr<const Mesh> mesh;
};

// Incrementally filled scene; handed over (moved) to a render session.
class SceneBuilder {
 public:
  // positions: (n, 3); indices: (m, 3) or flat 3m, int32 vertex indices; corner_normals: (m, 3, 3)
  // or empty; corner_uvs: (m, 3, 2) or empty; material_slot: (m,) or empty. Returns the mesh index.
  int add_mesh(const FloatArray& positions, const IntArray& indices,
               const std::optional<FloatArray>& corner_normals,
               const std::optional<FloatArray>& corner_uvs,
               const std::optional<IntArray>& material_slot);
  // The same mesh from Blender's own arrays, gathered per triangle corner here (memory-bound
  // loops, much faster than numpy fancy indexing): corner_loops (3 per triangle) index
  // loop_vertex; normals are per vertex (normals_per_loop false: kept per vertex, as
  // Mesh::vertex_normals) or per loop (gathered per corner), or empty; loop_uvs (2 per loop) may
  // be empty; loop_tangents (4 per loop: Blender's loop tangent and bitangent sign, for Normal
  // Map nodes) and loop_colors (3 per loop: a colour attribute, for Color Attribute nodes) may
  // be None or empty.
  int add_mesh_loops(const FloatArray& positions, const IntArray& loop_vertex,
                     const IntArray& corner_loops, const FloatArray& normals, bool normals_per_loop,
                     const FloatArray& loop_uvs, const IntArray& material_slot,
                     const std::optional<FloatArray>& loop_tangents,
                     const std::optional<FloatArray>& loop_colors);
  // Triangle/quad meshes straight from Blender's polygon arrays: triangulated here with Blender's
  // loop-triangle rule (quads split 0-2, or 1-3 when the 0-2 split folds the quad), so the
  // add-on never touches per-triangle data in Python. poly_material: one per polygon.
  int add_mesh_polys(const FloatArray& positions, const IntArray& loop_vertex,
                     const IntArray& loop_start, const IntArray& loop_total,
                     const FloatArray& normals, bool normals_per_loop, const FloatArray& loop_uvs,
                     const IntArray& poly_material, const std::optional<FloatArray>& loop_tangents,
                     const std::optional<FloatArray>& loop_colors, bool smooth_vertex_normals);
  // pass_index: the object's Pass Index (IndexOB pass).
  // visibility: RayKind bits of the rays that see the instance (Object > Visibility > Ray
  // Visibility).
  // terminator_geometry_offset: Object > Shading > Shadow Terminator > Geometry Offset, in
  // [0, 1] (Instance::terminator_geometry_offset); terminator_shading_offset: its Shading
  // Offset, in [0, 1] (Instance::terminator_shading_offset).
  // caustics_caster / caustics_receiver: Cycles' Cast / Receive Shadow Caustics
  // (Instance::caustics_caster / caustics_receiver).
  void add_instance(int mesh, const FloatArray& matrix, const py::list& slot_material,
                    int pass_index = 0, uint32_t visibility = kRayAll, bool holdout = false,
                    float terminator_geometry_offset = 0.1f, float terminator_shading_offset = 0.0f,
                    bool caustics_caster = false, bool caustics_receiver = false);
  int add_material(const py::dict& material);
  // rgba: (h, w, 4) or flat, row 0 at the bottom; converted to scene linear from `colorspace`
  // unless it is empty (already scene linear).
  int add_image(const std::string& name, int width, int height, const FloatArray& rgba,
                const std::string& colorspace);
  void add_light(const py::dict& light);
  void set_camera(const py::dict& camera);
  void set_world(const py::dict& world);

  // The arrays of mesh `index` as the core holds them (copies), for the export tests:
  // positions (n, 3), indices (m, 3), corner_normals (m, 3, 3) or empty, vertex_normals (n, 3) or
  // empty, corner_uvs (m, 3, 2) or empty, material_slot (m,) or empty.
  py::dict mesh_arrays(int index) const;
  // Blender's texture space of mesh `index` (Mesh.texspace_location / texspace_size), for
  // Generated texture coordinates.
  void set_mesh_texspace(int index, const py::sequence& location, const py::sequence& size);
  // The Geometry node's Pointiness and / or Random Per Island of mesh `index`, computed from
  // Blender's edges (2 per edge) and vertex normals (3 per vertex; used for Pointiness only), for
  // meshes whose materials read them.
  void set_mesh_geometry_attributes(int index, const IntArray& edges,
                                    const FloatArray& vertex_normals, bool pointiness,
                                    bool random_per_island);
  // The per-object settings of instance `index` / the flags of light `index` as the core holds
  // them, for the export tests: {pass_index, visibility, holdout, terminator_geometry_offset,
  // terminator_shading_offset, caustics_caster, caustics_receiver} / {camera_visible,
  // cast_shadow, caustics_light}.
  py::dict instance_settings(int index) const;
  py::dict light_settings(int index) const;
  size_t mesh_count() const { return scene_.meshes.size(); }
  size_t instance_count() const { return scene_.instances.size(); }
  size_t triangle_count() const;
  // A copy of mesh `index` as exported, and the mesh added back from such a copy (its index).
  StoredMesh stored_mesh(int index) const;
  int add_stored_mesh(const StoredMesh& stored);
  Scene take() { return std::move(scene_); }
  const Scene& scene() const { return scene_; }

 private:
  void validate_material(const MaterialDesc& desc);

  Scene scene_;
  std::vector<Texture> image_stand_ins_;  // validate_material()'s images
};

}  // namespace gdpt::python
