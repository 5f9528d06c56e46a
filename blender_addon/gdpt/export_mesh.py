# Evaluated geometry -> triangle meshes (object space) and instances.
#
# Every renderable object comes from depsgraph.object_instances, so modifiers, geometry-nodes
# instances, particles and collection instances all arrive the same way. A mesh is exported once
# per evaluated mesh datablock and shared by all its instances (the core builds one BVH per mesh).
# Curves, text, surfaces and metaballs are converted with to_mesh().
#
# Arrays are filled with foreach_get (or read raw, see _raw_int_column) into preallocated numpy
# buffers in Blender's own domains (vertices, loops); the module gathers them per triangle corner.

import ctypes

import numpy as np

from . import native

_GEOMETRY_TYPES = {'MESH', 'CURVE', 'SURFACE', 'FONT', 'META', 'CURVES'}


def _empty(count, dtype):
    """np.empty(count, dtype). Large arrays come from the module, which advises their pages as
    transparent huge pages before foreach_get first touches them: on Linux, first touching
    fresh memory in 4 KB pages cost more than the copies themselves (about 0.2 s for the 40 MB of
    a 1M-triangle mesh on the 2-core benchmark VM)."""
    dtype = np.dtype(dtype)
    module = native.load()[0]  # None: engine.py reports it; numpy's own buffers still work here
    if module is None or count * dtype.itemsize < (2 << 20):
        return np.empty(count, dtype=dtype)
    return module.empty(count, dtype)


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
    values = _empty(count, np.int32)
    values[:] = np.frombuffer(buffer, dtype=np.int32).reshape(count, words)[:, column]
    for i in (0, count // 2, count - 1):
        if getattr(collection[i], attr) != values[i]:
            return None
    return values


def _int_field(collection, column, attr):
    values = _raw_int_column(collection, column, attr)
    if values is None:
        values = _empty(len(collection), np.int32)
        collection.foreach_get(attr, values)
    return values


def _corner_loops_slow(mesh):
    """Any polygons (n-gons are ear-clipped by Blender): read the loop triangles."""
    mesh.calc_loop_triangles()
    tri_count = len(mesh.loop_triangles)
    corners = _empty(tri_count * 3, np.int32)
    mesh.loop_triangles.foreach_get("loops", corners)
    tri_poly = _empty(tri_count, np.int32)
    mesh.loop_triangles.foreach_get("polygon_index", tri_poly)
    return corners, tri_poly


def _normals_and_uvs(mesh, own_vertex_normals=False):
    """(normals, per_loop, smooth_vertex_normals, loop_uvs) in Blender's domains. All smooth
    without custom normals: vertex normals, or with `own_vertex_normals` none and
    smooth_vertex_normals True (the module computes them, the same from one export to the next,
    which Blender's are not). Custom / auto-smooth normals or a smooth/flat mix: Blender's split
    (per-loop) normals, which hold face normals for flat faces. All flat: none (the core then
    uses the geometric normals). UVs: the active render UV map, per loop, or none."""
    smooth = np.empty(len(mesh.polygons), dtype=bool)
    mesh.polygons.foreach_get("use_smooth", smooth)
    normals = np.empty(0, dtype=np.float32)
    per_loop = own = False
    if mesh.has_custom_normals or (smooth.any() and (mesh.use_auto_smooth or not smooth.all())):
        mesh.calc_normals_split()
        normals = _empty(len(mesh.loops) * 3, np.float32)
        mesh.loops.foreach_get("normal", normals)
        per_loop = True
    elif smooth.any() and own_vertex_normals:
        own = True
    elif smooth.any():
        normals = _empty(len(mesh.vertices) * 3, np.float32)
        mesh.vertex_normals.foreach_get("vector", normals)  # raw array, unlike vertices.normal
    loop_uvs = np.empty(0, dtype=np.float32)
    uv_layer = None
    for layer in mesh.uv_layers:
        if layer.active_render:
            uv_layer = layer
    if uv_layer is None and len(mesh.uv_layers):
        uv_layer = mesh.uv_layers[0]
    if uv_layer is not None:
        loop_uvs = _empty(len(mesh.loops) * 2, np.float32)
        uv_layer.data.foreach_get("uv", loop_uvs)
    return normals, per_loop, own, loop_uvs


def _poly_material(mesh):
    """Material slot per polygon, or an empty array when every polygon uses slot 0."""
    # Blender 3.4 keeps material indices in an attribute that only exists when one is non-zero.
    attribute = mesh.attributes.get("material_index")
    if attribute is None:
        return np.empty(0, dtype=np.int32)
    poly_material = _empty(len(mesh.polygons), np.int32)
    if attribute.domain == 'FACE' and attribute.data_type == 'INT':
        attribute.data.foreach_get("value", poly_material)
    else:
        mesh.polygons.foreach_get("material_index", poly_material)
    return poly_material


def _loop_tangents(mesh, warn):
    """Blender's MikkTSpace tangents of the active render UV map and the bitangent signs, 4
    floats per loop (what Cycles' Normal Map node uses), or None when Blender cannot compute them
    (no UV map, or faces with more than 4 corners)."""
    layer = next((l for l in mesh.uv_layers if l.active_render), None)
    if layer is None and len(mesh.uv_layers):
        layer = mesh.uv_layers[0]
    if layer is None:
        warn(f"mesh '{mesh.name}' has a normal-mapped material but no UV map: the normal map is "
             "ignored there")
        return None
    try:
        mesh.calc_tangents(uvmap=layer.name)
    except RuntimeError as e:
        reason = str(e).strip()
        warn(f"mesh '{mesh.name}': no tangents for its normal map ({reason}); the normal map "
             "is ignored there")
        return None
    loops = len(mesh.loops)
    tangents = _empty(loops * 3, np.float32)
    mesh.loops.foreach_get("tangent", tangents)
    signs = _empty(loops, np.float32)
    mesh.loops.foreach_get("bitangent_sign", signs)
    out = np.empty((loops, 4), dtype=np.float32)
    out[:, :3] = tangents.reshape(loops, 3)
    out[:, 3] = signs
    return out.ravel()


def _loop_colors(mesh, name, warn):
    """The colour attribute `name` ("" for the render colour attribute) as linear RGB per loop,
    what Cycles' Color Attribute node reads; None (with a warning) when the mesh has none."""
    attrs = mesh.color_attributes
    attr = None
    if name:
        attr = attrs.get(name)
    elif 0 <= attrs.render_color_index < len(attrs):
        attr = attrs[attrs.render_color_index]
    if attr is None or attr.domain not in {'POINT', 'CORNER'}:
        warn(f"mesh '{mesh.name}' has no colour attribute '{name or '(render)'}': the Color "
             "Attribute node reads black there, as in Cycles")
        return None
    rgba = _empty(len(attr.data) * 4, np.float32)
    attr.data.foreach_get("color", rgba)
    rgb = rgba.reshape(-1, 4)[:, :3]
    if attr.domain == 'POINT':
        rgb = rgb[_int_field(mesh.loops, 0, "vertex_index")]
    return np.ascontiguousarray(rgb, dtype=np.float32).ravel()


def _add_geometry_attributes(builder, index, mesh, attributes):
    """Blender's edges (and vertex normals, for Pointiness) for the Geometry node attributes
    the module computes as Cycles does (blender_addon/module/mesh_attributes.h)."""
    edges = _empty(len(mesh.edges) * 2, np.int32)
    mesh.edges.foreach_get("vertices", edges)
    normals = np.empty(0, dtype=np.float32)
    if "pointiness" in attributes:
        normals = _empty(len(mesh.vertices) * 3, np.float32)
        mesh.vertex_normals.foreach_get("vector", normals)
    builder.set_mesh_geometry_attributes(index, edges, normals, "pointiness" in attributes,
                                         "random_per_island" in attributes)


def add_mesh(builder, mesh, tangents=False, warn=print, color_attribute=None,
             geometry_attributes=frozenset()):
    """Adds `mesh` to the scene; returns its index, or -1 when it has no faces. Only Blender's
    own arrays (vertices, loops, polygons) are read here; the module builds the triangles and
    gathers the corner attributes in C++. `tangents`: also the UV map's tangents (for materials
    with a Normal Map node); `color_attribute`: also that colour attribute ("" for the render
    one; None: none), for Color Attribute nodes; `geometry_attributes`: the Geometry node's
    Pointiness / Random Per Island ('pointiness', 'random_per_island') to compute."""
    poly_count = len(mesh.polygons)
    if poly_count == 0:
        return -1
    loop_tangents = _loop_tangents(mesh, warn) if tangents else None
    loop_colors = None if color_attribute is None else _loop_colors(mesh, color_attribute, warn)
    positions = _empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", positions)
    loop_total = _int_field(mesh.polygons, 1, "loop_total")  # MPoly.totloop
    loop_vertex = _int_field(mesh.loops, 0, "vertex_index")  # MLoop.v
    poly_material = _poly_material(mesh)
    if loop_total.min() >= 3 and loop_total.max() <= 4:
        loop_start = _int_field(mesh.polygons, 0, "loop_start")  # MPoly.loopstart
        normals, per_loop, own, loop_uvs = _normals_and_uvs(mesh, own_vertex_normals=True)
        index = builder.add_mesh_polys(positions, loop_vertex, loop_start, loop_total, normals,
                                       per_loop, loop_uvs, poly_material, loop_tangents,
                                       loop_colors, smooth_vertex_normals=own)
    else:
        normals, per_loop, _, loop_uvs = _normals_and_uvs(mesh)
        # N-gons: Blender's ear clipping, through its loop triangles (slower reads).
        corner_loops, tri_poly = _corner_loops_slow(mesh)
        if len(corner_loops) == 0:
            return -1
        tri_material = poly_material[tri_poly] if len(poly_material) else poly_material
        index = builder.add_mesh_loops(positions, loop_vertex, corner_loops, normals, per_loop,
                                       loop_uvs, np.ascontiguousarray(tri_material),
                                       loop_tangents, loop_colors)
    if geometry_attributes:
        _add_geometry_attributes(builder, index, mesh, geometry_attributes)
    # Texture space for Generated coordinates (Blender computes the automatic one on access).
    builder.set_mesh_texspace(index, tuple(mesh.texspace_location), tuple(mesh.texspace_size))
    return index


# Object > Visibility > Ray Visibility -> the core's RayKind bits (scene/scene.h).
_RAY_KINDS = (("visible_camera", 1 << 0), ("visible_diffuse", 1 << 1), ("visible_glossy", 1 << 2),
              ("visible_transmission", 1 << 3), ("visible_shadow", 1 << 4))


def ray_visibility(obj):
    bits = 0
    for prop, bit in _RAY_KINDS:
        if getattr(obj, prop, True):
            bits |= bit
    return bits


def _cycles_object_setting(obj, name, default):
    # Cycles' object settings live in the Cycles add-on's properties (obj.cycles); without that
    # add-on they take Cycles' defaults. The value has the default's type (float or bool).
    return type(default)(getattr(getattr(obj, "cycles", None), name, default))


def terminator_geometry_offset(obj):
    """Object > Shading > Shadow Terminator > Geometry Offset (Cycles' default 0.1)."""
    return _cycles_object_setting(obj, "shadow_terminator_geometry_offset", 0.1)


def terminator_shading_offset(obj):
    """Object > Shading > Shadow Terminator > Shading Offset (Cycles' default 0)."""
    return _cycles_object_setting(obj, "shadow_terminator_offset", 0.0)


def caustics_caster(obj):
    """Object > Shading > Caustics > Cast Shadow Caustics (Cycles' default off)."""
    return _cycles_object_setting(obj, "is_caustics_caster", False)


def caustics_receiver(obj):
    """Object > Shading > Caustics > Receive Shadow Caustics (Cycles' default off)."""
    return _cycles_object_setting(obj, "is_caustics_receiver", False)


def _matrix12(m):
    a = np.array(m, dtype=np.float32)  # 4x4 rows
    return np.ascontiguousarray(a[:3, :4]).ravel()


class MeshStore:
    """The viewport's meshes from its last export, by (object name, tangents, colours, geometry
    attributes): a later
    export adds them back without reading Blender's mesh, unless `forget` dropped the object
    (its geometry changed)."""

    def __init__(self):
        self.meshes = {}  # key -> _gdpt.StoredMesh, or None for an object without faces
        self.reused = 0
        self.exported = 0

    def add_to(self, builder, key):
        self.reused += 1
        stored = self.meshes[key]
        return -1 if stored is None else builder.add_stored_mesh(stored)

    def keep(self, builder, key, index):
        self.exported += 1
        self.meshes[key] = None if index < 0 else builder.stored_mesh(index)

    def forget(self, object_name):
        for key in [k for k in self.meshes if k[0] == object_name]:
            del self.meshes[key]


class GeometryExporter:
    """Collects meshes and instances; `visit` is called for each depsgraph object instance."""

    def __init__(self, builder, materials, warn, store=None):
        self.builder = builder
        self.materials = materials
        self.warn = warn
        self.mesh_index = {}  # evaluated data pointer -> scene mesh index (-1: empty)
        self.export_seconds = 0.0
        # MeshStore of the viewport (meshes kept from its last export), or None.
        self.store = store

    def _mesh_for(self, obj, tangents, colors, attributes):
        # Meshes: the evaluated mesh datablock (modifiers applied) is what instances share.
        # Other types: to_mesh() depends on the object's own modifiers, so key by the original
        # object (instances of it in collections or particles still share one mesh). Tangents,
        # colours and geometry attributes are read only for objects whose materials use them
        # (part of the key).
        if obj.type == 'MESH':
            key = (obj.data.as_pointer(), tangents, colors, attributes)
        else:
            key = ("object", obj.original.as_pointer(), tangents, colors, attributes)
        if key in self.mesh_index:
            return self.mesh_index[key]
        stored_key = (obj.original.name_full, tangents, colors, attributes)
        if self.store is not None and stored_key in self.store.meshes:
            index = self.store.add_to(self.builder, stored_key)
            self.mesh_index[key] = index
            return index
        if obj.type == 'MESH':
            mesh = obj.data
            index = self._add_mesh(mesh, tangents, colors, attributes)
        else:
            mesh = obj.to_mesh()
            try:
                index = (self._add_mesh(mesh, tangents, colors, attributes)
                         if mesh is not None else -1)
            finally:
                obj.to_mesh_clear()
        self.mesh_index[key] = index
        if self.store is not None:
            self.store.keep(self.builder, stored_key, index)
        return index

    def _add_mesh(self, mesh, tangents, colors, attributes):
        # The module rejects malformed arrays (NaN vertices, indices out of range) with a
        # ValueError naming the array: the render goes on without that mesh.
        try:
            return add_mesh(self.builder, mesh, tangents, self.warn, colors, attributes)
        except ValueError as e:
            self.warn(f"mesh '{mesh.name}' skipped: {e}")
            return -1

    def visit(self, inst, obj, matrix):
        """Adds one instance of geometry object `obj` placed by `matrix` (already copied)."""
        if obj.type not in _GEOMETRY_TYPES:
            return
        if obj.type == 'CURVES':
            self.warn(f"hair curves of '{obj.name}' are not supported by Gradient PT (skipped)")
            return
        slots = [self.materials.get(slot.material) for slot in obj.material_slots]
        tangents = any(self.materials.has_normal_map(index) for index in slots)
        colors = next((self.materials.color_attribute(index) for index in slots
                       if self.materials.color_attribute(index) is not None), None)
        attributes = frozenset().union(*(self.materials.geometry_attributes(index)
                                         for index in slots))
        mesh = self._mesh_for(obj, tangents, colors, attributes)
        if mesh < 0:
            return
        self.builder.add_instance(mesh, _matrix12(matrix), slots, obj.pass_index,
                                  ray_visibility(obj), bool(obj.is_holdout),
                                  terminator_geometry_offset(obj),
                                  terminator_shading_offset(obj),
                                  caustics_caster=caustics_caster(obj),
                                  caustics_receiver=caustics_receiver(obj))
