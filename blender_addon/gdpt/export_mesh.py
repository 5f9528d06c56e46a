# Evaluated geometry -> triangle meshes (object space) and instances.
#
# Every renderable object comes from depsgraph.object_instances, so modifiers, geometry-nodes
# instances, particles and collection instances all arrive the same way. A mesh is exported once
# per evaluated mesh datablock and shared by all its instances (the core builds one BVH per mesh).
# Curves, text, surfaces and metaballs are converted with to_mesh().
#
# Arrays are filled with foreach_get into preallocated numpy buffers and gathered per triangle
# corner with numpy: the corner (loop) indices pick vertex indices, normals and UVs.

import ctypes

import numpy as np

_GEOMETRY_TYPES = {'MESH', 'CURVE', 'SURFACE', 'FONT', 'META', 'CURVES'}


def _raw_int_column(collection, column, attr):
    """Column `column` (in 32-bit words) of the C array behind a mesh collection, read directly
    through as_pointer(): Blender 3.4's RNA foreach_get takes a slow per-item path for
    loops.vertex_index and polygons.loop_start/loop_total (about 1 s per 1M items). The layout is
    checked at run time (element stride from consecutive pointers; values against RNA at the
    first, middle and last element); None means "use foreach_get"."""
    count = len(collection)
    if count < 2:
        return None
    base = collection[0].as_pointer()
    stride = collection[1].as_pointer() - base
    if base == 0 or stride <= 0 or stride % 4 or column >= stride // 4:
        return None
    words = stride // 4
    buffer = (ctypes.c_int32 * (count * words)).from_address(base)
    values = np.frombuffer(buffer, dtype=np.int32).reshape(count, words)[:, column].copy()
    for i in (0, count // 2, count - 1):
        if getattr(collection[i], attr) != values[i]:
            return None
    return values


def _int_field(collection, column, attr):
    values = _raw_int_column(collection, column, attr)
    if values is None:
        values = np.empty(len(collection), dtype=np.int32)
        collection.foreach_get(attr, values)
    return values


def _corner_loops_fast(mesh, loop_total, loop_vertex, co):
    """Loop indices of the triangle corners and the polygon of each triangle, for meshes made of
    triangles and quads only, in Blender's loop-triangle order and split (quads: 0-1-2, 0-2-3).
    foreach_get on loop_triangles goes through Blender's slow per-item path (1.5 s per array for
    1M triangles); polygon and loop fields are read as raw arrays."""
    loop_start = _int_field(mesh.polygons, 0, "loop_start")  # MPoly.loopstart
    per_poly = loop_total - 2
    tri_poly = np.repeat(np.arange(len(loop_total), dtype=np.int32), per_poly)
    # k = index of the triangle within its polygon (0, or 1 for the second half of a quad).
    k = np.arange(len(tri_poly), dtype=np.int32) - np.repeat(np.cumsum(per_poly) - per_poly,
                                                              per_poly).astype(np.int32)
    s = loop_start[tri_poly]
    corners = np.empty((len(tri_poly), 3), dtype=np.int32)
    corners[:, 0] = s
    corners[:, 1] = s + 1 + k
    corners[:, 2] = s + 2 + k
    # Blender splits a quad along 1-3 instead when the 0-2 split would fold it (concave or
    # strongly non-planar quads): (v1 - v0) x (v2 - v0) and (v3 - v0) x (v2 - v0) point the same
    # way. Its triangles are then 0-1-3 and 1-2-3.
    quads = np.flatnonzero(loop_total == 4)
    if len(quads):
        q = loop_start[quads][:, None] + np.arange(4, dtype=np.int32)[None, :]
        v = np.take(co.reshape(-1, 3), loop_vertex[q], axis=0)  # (quads, 4, 3) float32
        # Same float32 operation order as Blender's test, so nearly planar quads split alike.
        a = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
        b = np.cross(v[:, 3] - v[:, 0], v[:, 2] - v[:, 0])
        flip = (a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1]) + a[:, 2] * b[:, 2] > 0.0
        if flip.any():
            first = (np.cumsum(per_poly) - per_poly)[quads[flip]]  # first triangle of the quad
            s = loop_start[quads[flip]]
            corners[first] = np.stack([s, s + 1, s + 3], axis=1)
            corners[first + 1] = np.stack([s + 1, s + 2, s + 3], axis=1)
    return corners.ravel(), tri_poly


def _corner_loops_slow(mesh):
    """Any polygons (n-gons are ear-clipped by Blender): read the loop triangles."""
    mesh.calc_loop_triangles()
    tri_count = len(mesh.loop_triangles)
    corners = np.empty(tri_count * 3, dtype=np.int32)
    mesh.loop_triangles.foreach_get("loops", corners)
    tri_poly = np.empty(tri_count, dtype=np.int32)
    mesh.loop_triangles.foreach_get("polygon_index", tri_poly)
    return corners, tri_poly


def mesh_arrays(mesh):
    """(positions, indices, corner_normals or None, corner_uvs or None, material_slot) of a
    mesh, all float32 / int32 and C-contiguous."""
    poly_count = len(mesh.polygons)
    vert_count = len(mesh.vertices)
    positions = np.empty(vert_count * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", positions)
    loop_total = _int_field(mesh.polygons, 1, "loop_total")  # MPoly.totloop
    loop_vertex = _int_field(mesh.loops, 0, "vertex_index")  # MLoop.v
    if poly_count and loop_total.min() >= 3 and loop_total.max() <= 4:
        corner_loops, tri_poly = _corner_loops_fast(mesh, loop_total, loop_vertex, positions)
    else:
        corner_loops, tri_poly = _corner_loops_slow(mesh)
    indices = np.ascontiguousarray(loop_vertex[corner_loops])
    # Blender 3.4 keeps material indices in an attribute that only exists when one is non-zero.
    poly_material = np.zeros(poly_count, dtype=np.int32)
    attribute = mesh.attributes.get("material_index")
    if attribute is not None and attribute.domain == 'FACE' and attribute.data_type == 'INT':
        attribute.data.foreach_get("value", poly_material)
    elif attribute is not None:
        mesh.polygons.foreach_get("material_index", poly_material)
    material_slot = np.ascontiguousarray(poly_material[tri_poly])

    # Shading normals per corner. Custom / auto-smooth normals need Blender's split normals.
    # Otherwise smooth faces use vertex normals and flat faces their face normal, which is what
    # the split normals would be; all-flat meshes send none (the core uses geometric normals).
    smooth = np.empty(poly_count, dtype=bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    corner_normals = None
    if mesh.has_custom_normals or (mesh.use_auto_smooth and smooth.any()):
        mesh.calc_normals_split()
        loop_normals = np.empty(len(mesh.loops) * 3, dtype=np.float32)
        mesh.loops.foreach_get("normal", loop_normals)
        corner_normals = np.take(loop_normals.reshape(-1, 3), corner_loops, axis=0)
    elif smooth.any():
        vertex_normals = np.empty(vert_count * 3, dtype=np.float32)
        mesh.vertex_normals.foreach_get("vector", vertex_normals)  # raw array, unlike .normal
        corner_normals = np.take(vertex_normals.reshape(-1, 3), indices, axis=0)
        if not smooth.all():
            face_normals = np.empty(poly_count * 3, dtype=np.float32)
            mesh.polygon_normals.foreach_get("vector", face_normals)
            flat_corner = np.repeat(~smooth[tri_poly], 3)
            corner_normals[flat_corner] = np.take(face_normals.reshape(-1, 3),
                                                  np.repeat(tri_poly, 3)[flat_corner], axis=0)

    corner_uvs = None
    uv_layer = None
    for layer in mesh.uv_layers:
        if layer.active_render:
            uv_layer = layer
    if uv_layer is None and len(mesh.uv_layers):
        uv_layer = mesh.uv_layers[0]
    if uv_layer is not None and len(corner_loops):
        loop_uvs = np.empty(len(mesh.loops) * 2, dtype=np.float32)
        uv_layer.data.foreach_get("uv", loop_uvs)
        corner_uvs = np.take(loop_uvs.reshape(-1, 2), corner_loops, axis=0)
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
        # Meshes: the evaluated mesh datablock (modifiers applied) is what instances share.
        # Other types: to_mesh() depends on the object's own modifiers, so key by the original
        # object (instances of it in collections or particles still share one mesh).
        if obj.type == 'MESH':
            key = obj.data.as_pointer()
        else:
            key = ("object", obj.original.as_pointer())
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
