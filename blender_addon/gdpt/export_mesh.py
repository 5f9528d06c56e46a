# Evaluated geometry -> triangle meshes (object space) and instances.
#
# Every renderable object comes from depsgraph.object_instances, so modifiers, geometry-nodes
# instances, particles and collection instances all arrive the same way. A mesh is exported once
# per evaluated mesh datablock and shared by all its instances (the core builds one BVH per mesh).
# Curves, text, surfaces and metaballs are converted with to_mesh().
#
# Arrays are filled with foreach_get into preallocated numpy buffers: loop triangles give the
# vertex indices and the corner (loop) indices used to gather split normals and UVs.

import numpy as np

_GEOMETRY_TYPES = {'MESH', 'CURVE', 'SURFACE', 'FONT', 'META', 'CURVES'}


def mesh_arrays(mesh):
    """(positions, indices, corner_normals or None, corner_uvs or None, material_slot) of a
    mesh, all float32 / int32 and C-contiguous."""
    mesh.calc_loop_triangles()
    tri_count = len(mesh.loop_triangles)
    vert_count = len(mesh.vertices)
    positions = np.empty(vert_count * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", positions)
    indices = np.empty(tri_count * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("vertices", indices)
    material_slot = np.empty(tri_count, dtype=np.int32)
    mesh.loop_triangles.foreach_get("material_index", material_slot)

    # Smooth / flat: split normals already hold face normals for flat faces and sharp edges, so
    # one gather covers every mix. All-flat meshes skip it: the core then uses geometric normals.
    smooth = np.empty(len(mesh.polygons), dtype=bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    corner_loops = None
    corner_normals = None
    if smooth.any() or mesh.has_custom_normals:
        corner_loops = np.empty(tri_count * 3, dtype=np.int32)
        mesh.loop_triangles.foreach_get("loops", corner_loops)
        mesh.calc_normals_split()
        loop_normals = np.empty(len(mesh.loops) * 3, dtype=np.float32)
        mesh.loops.foreach_get("normal", loop_normals)
        corner_normals = np.ascontiguousarray(loop_normals.reshape(-1, 3)[corner_loops])

    corner_uvs = None
    uv_layer = None
    for layer in mesh.uv_layers:
        if layer.active_render:
            uv_layer = layer
    if uv_layer is None and len(mesh.uv_layers):
        uv_layer = mesh.uv_layers[0]
    if uv_layer is not None and tri_count:
        if corner_loops is None:
            corner_loops = np.empty(tri_count * 3, dtype=np.int32)
            mesh.loop_triangles.foreach_get("loops", corner_loops)
        loop_uvs = np.empty(len(mesh.loops) * 2, dtype=np.float32)
        uv_layer.data.foreach_get("uv", loop_uvs)
        corner_uvs = np.ascontiguousarray(loop_uvs.reshape(-1, 2)[corner_loops])
    return positions, indices, corner_normals, corner_uvs, material_slot


def _matrix12(m):
    a = np.array(m, dtype=np.float32)  # 4x4 rows
    return np.ascontiguousarray(a[:3, :4]).ravel()


class GeometryExporter:
    """Collects meshes and instances; `visit` is called for each depsgraph object instance."""

    def __init__(self, builder, materials, warn):
        self.builder = builder
        self.materials = materials
        self.warn = warn
        self.mesh_index = {}  # evaluated data pointer -> scene mesh index (-1: empty)
        self.export_seconds = 0.0

    def _mesh_for(self, obj):
        data = obj.data
        key = data.as_pointer() if data is not None else ("object", obj.name)
        if key in self.mesh_index:
            return self.mesh_index[key]
        if obj.type == 'MESH':
            mesh = obj.data
            index = self._add_mesh(mesh)
        else:
            mesh = obj.to_mesh()
            try:
                index = self._add_mesh(mesh) if mesh is not None else -1
            finally:
                obj.to_mesh_clear()
        self.mesh_index[key] = index
        return index

    def _add_mesh(self, mesh):
        positions, indices, normals, uvs, slots = mesh_arrays(mesh)
        if len(indices) == 0:
            return -1
        return self.builder.add_mesh(positions, indices, normals, uvs, slots)

    def visit(self, inst, obj, matrix):
        """Adds one instance of geometry object `obj` placed by `matrix` (already copied)."""
        if obj.type not in _GEOMETRY_TYPES:
            return
        if obj.type == 'CURVES':
            self.warn(f"hair curves of '{obj.name}' are not supported by Gradient PT (skipped)")
            return
        mesh = self._mesh_for(obj)
        if mesh < 0:
            return
        slots = [self.materials.get(slot.material) for slot in obj.material_slots]
        self.builder.add_instance(mesh, _matrix12(matrix), slots)
