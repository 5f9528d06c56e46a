# Mesh export: what export_mesh.add_mesh hands to the core equals Blender's own loop triangles
# (Mesh.loop_triangles), triangle by triangle and corner by corner: vertex indices, positions,
# shading normals (Blender's split normals; none for an all-flat mesh), the active render UV map
# and the material slot. The fast path (triangles and quads, triangulated in the module with
# Blender's rule) and the n-gon path (Blender's ear clipping) both run, on:
#  - triangles, planar and non-planar quads, and an arrowhead quad that Blender splits along 1-3,
#    smooth and flat faces mixed (split normals), two materials, per-loop (discontinuous) UVs;
#  - an all-smooth quad sphere (vertex normals) with degenerate quads at its poles, whose active
#    render UV map is not the first;
#  - n-gons (convex and concave), all flat (no normals), material indices;
#  - custom split normals;
#  - an evaluated mesh (Subdivision Surface modifier) from the depsgraph;
#  - the object's ray visibility flags as the core's bits, and their panel;
#  - Cycles' Shadow Caustics flags (object Cast / Receive, light Shadow Caustics) through a whole
#    export into the core's Instance / Light fields, an instanced object with its own object's
#    flags, and their panels;
#  - subsurface materials: Principled's subsurface and the Subsurface Scattering node become the
#    diffuse Cycles falls back to, reported once per material by node name when the radius is
#    not 0 (Cycles would carry light under the surface).
import os
import sys
from types import SimpleNamespace

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import scenes as S  # noqa: E402

check = S.check


def make_mesh(name, verts, faces, smooth, materials=(), uv_layers=("UVMap",), render_uv=0):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    for k, layer_name in enumerate(uv_layers):
        layer = me.uv_layers.new(name=layer_name)
        for loop in me.loops:  # discontinuous: a per-vertex gather would be caught
            layer.data[loop.index].uv = (0.01 * loop.index + k, 0.1 * loop.vertex_index)
    if uv_layers:
        me.uv_layers[render_uv].active_render = True
    for p in me.polygons:
        p.use_smooth = smooth(p.index)
    for m in materials:
        me.materials.append(m)
    for p in me.polygons:
        p.material_index = (p.index % len(materials)) if len(materials) > 1 else 0
    me.update()
    return me


def reference(mesh):
    """Blender's triangles and corner attributes, read item by item through RNA."""
    # Blender splits quads with its face normals when they are up to date, as they are whenever a
    # renderer has read the mesh's normals (the export does): compute them first.
    [p.normal for p in mesh.polygons]
    mesh.calc_loop_triangles()
    tris = list(mesh.loop_triangles)
    corner_loops = np.array([list(t.loops) for t in tris], dtype=np.int64)
    loop_vertex = np.array([l.vertex_index for l in mesh.loops], dtype=np.int64)
    smooth = [p.use_smooth for p in mesh.polygons]
    ref = {
        "indices": loop_vertex[corner_loops],
        "positions": np.array([v.co[:] for v in mesh.vertices], dtype=np.float32),
        "material_slot": np.array([mesh.polygons[t.polygon_index].material_index for t in tris]),
        "normals": None,
        "uvs": None,
    }
    if any(smooth) or mesh.has_custom_normals:
        mesh.calc_normals_split()
        normals = np.array([l.normal[:] for l in mesh.loops], dtype=np.float32)
        ref["normals"] = normals[corner_loops]
    layer = next((u for u in mesh.uv_layers if u.active_render), None)
    if layer is not None:
        uvs = np.array([d.uv[:] for d in layer.data], dtype=np.float32)
        ref["uvs"] = uvs[corner_loops]
    return ref


def compare(name, mesh, tangents=False):
    import gdpt.export_mesh as export_mesh
    from gdpt import _gdpt
    builder = _gdpt.SceneBuilder()
    index = export_mesh.add_mesh(builder, mesh, tangents)
    got = builder.mesh_arrays(index)
    print(f"{name}: normals per " + ("corner" if got["corner_normals"].size else "vertex" if
                                     got["vertex_normals"].size else "- (flat)"))
    ref = reference(mesh)
    check(np.array_equal(got["positions"], ref["positions"]), f"{name}: positions")
    check(got["indices"].shape == ref["indices"].shape,
          f"{name}: {len(ref['indices'])} triangles, as Blender's loop triangles")
    # A quad with two corners at one position has one real triangle either way; which of the two
    # coincident corners it uses is a rounding tie in Blender's own test. Such quads may differ.
    same = (got["indices"] == ref["indices"]).all(axis=1)
    tri_poly = [t.polygon_index for t in mesh.loop_triangles]
    degenerate = [len({tuple(mesh.vertices[v].co) for v in mesh.polygons[p].vertices}) < 4 and
                  len(mesh.polygons[p].vertices) == 4 for p in tri_poly]
    check(all(same[t] or degenerate[t] for t in range(len(same))),
          f"{name}: the same vertices at every corner, in Blender's order ({int(same.sum())} of "
          f"{len(same)} triangles; the others in quads with two corners at one position)")
    normals = got["corner_normals"]
    if normals.size == 0 and got["vertex_normals"].size:  # kept per vertex (all smooth)
        normals = got["vertex_normals"][got["indices"]]
    if ref["normals"] is None:
        check(normals.size == 0, f"{name}: all flat, no shading normals")
    else:
        err = float(np.abs(normals[same] - ref["normals"][same]).max())
        check(err < 1e-5, f"{name}: corner normals are Blender's split normals (max error {err})")
    if ref["uvs"] is None:
        check(got["corner_uvs"].size == 0, f"{name}: no UV map, no UVs")
    else:
        check(np.array_equal(got["corner_uvs"][same], ref["uvs"][same]),
              f"{name}: corner UVs from the active render UV map")
    slots = got["material_slot"] if got["material_slot"].size else np.zeros(len(ref["indices"]))
    check(np.array_equal(slots, ref["material_slot"]), f"{name}: material slot per triangle")
    if tangents:  # for Normal Map nodes: Blender's MikkTSpace tangents of the render UV map
        layer = next(u for u in mesh.uv_layers if u.active_render)
        mesh.calc_tangents(uvmap=layer.name)
        corners = np.array([list(t.loops) for t in mesh.loop_triangles], dtype=np.int64)
        t_ref = np.array([l.tangent[:] for l in mesh.loops], dtype=np.float32)[corners]
        s_ref = np.array([l.bitangent_sign for l in mesh.loops], dtype=np.float32)[corners]
        check(np.array_equal(got["corner_tangents"][same], t_ref[same]) and
              np.array_equal(got["corner_tangent_signs"][same], s_ref[same]) and
              np.abs(s_ref).min() == 1.0,
              f"{name}: corner tangents and bitangent signs are Blender's loop tangents")
    else:
        check(got["corner_tangents"].size == 0, f"{name}: no tangents unless asked for")
    return ref


def translated(material):
    from gdpt.export_materials import translate_material
    warnings = []
    d = translate_material(material, {}, warnings.append)
    return d, warnings


def subsurface_translation():
    def principled(name, radius, twice=False):
        m = S.shader_material(name, "ShaderNodeBsdfPrincipled", **{
            "Base Color": (0.8, 0.2, 0.1, 1), "Subsurface": 0.7,
            "Subsurface Color": (0.1, 0.3, 0.9, 1), "Subsurface Radius": radius})
        if twice:  # the node reached twice (through a Mix Shader) is still reported once
            nt = m.node_tree
            mix = nt.nodes.new("ShaderNodeMixShader")
            bsdf = nt.nodes["Principled BSDF"]
            nt.links.new(bsdf.outputs[0], mix.inputs[1])
            nt.links.new(bsdf.outputs[0], mix.inputs[2])
            nt.links.new(mix.outputs[0], nt.nodes["Material Output"].inputs["Surface"])
        return m

    transport = "subsurface scattering, rendered as diffuse (no subsurface transport), of " \
        "'{}'"
    d, warnings = translated(principled("sss_zero", (0.0, 0.0, 0.0)))
    node = d["nodes"][d["root"]]
    check(not warnings and node["kind"] == "PRINCIPLED" and
          abs(node["subsurface"]["value"] - 0.7) < 1e-6 and
          np.allclose(node["subsurface_color"]["value"], (0.1, 0.3, 0.9)),
          "Principled subsurface of radius 0: translated with its weight and colour, no warning")
    for twice in (False, True):
        _, warnings = translated(principled(f"sss_radius_{twice}", (1.0, 0.2, 0.1), twice))
        check(len(warnings) == 1 and transport.format("Principled BSDF") in warnings[0],
              f"Principled subsurface of radius > 0{' reached twice' if twice else ''}: one "
              f"warning naming the node ({warnings})")
    d, warnings = translated(S.shader_material("plain", "ShaderNodeBsdfPrincipled"))
    check(not warnings and "subsurface" not in d["nodes"][d["root"]],
          "Principled without subsurface: no subsurface inputs, no warning")
    for scale, radius, expect_warning in ((1.0, (0.0, 0.0, 0.0), False),
                                          (0.0, (1.0, 0.2, 0.1), False),
                                          (1.0, (-1.0, 0.0, 0.0), False),
                                          (0.05, (1.0, 0.0, 0.0), True)):
        m = S.shader_material(f"sss_node_{scale}_{radius}", "ShaderNodeSubsurfaceScattering",
                              Color=(0.2, 0.8, 0.3, 1), Radius=radius, Scale=scale)
        d, warnings = translated(m)
        node = d["nodes"][d["root"]]
        check(node["kind"] == "DIFFUSE" and node["roughness"]["value"] == 0.0 and
              np.allclose(node["color"]["value"], (0.2, 0.8, 0.3)) and
              len(warnings) == int(expect_warning) and
              all(transport.format("Subsurface Scattering") in w for w in warnings),
              f"Subsurface Scattering node, radius {radius} x scale {scale}: a Lambert diffuse of "
              f"its colour, {'one warning' if expect_warning else 'no warning'} ({warnings})")


def main():
    subsurface_translation()
    S.clear()
    red, green = S.diffuse("red", (0.8, 0.1, 0.1)), S.diffuse("green", (0.1, 0.8, 0.1))

    # Triangles and quads: planar, non-planar, and an arrowhead (reflex vertex 1: the 0-2
    # diagonal lies outside, Blender splits along 1-3).
    verts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),  # planar quad
             (2, 0, 0), (2, 1, 0.5),  # with 1, 2: non-planar quad 1-4-5-2
             (3, 0, 0), (3.5, 0.25, 0), (4, 0, 0), (3.5, 1.5, 0),  # arrowhead 6-7-8-9
             (5, 0, 0), (6, 0, 0), (5.5, 1, 0.2)]  # triangle
    faces = [(0, 1, 2, 3), (1, 4, 5, 2), (6, 7, 8, 9), (10, 11, 12)]
    me = make_mesh("mixed", verts, faces, smooth=lambda i: i % 2 == 0, materials=(red, green))
    ref = compare("mixed", me)
    compare("mixed", me, tangents=True)
    arrow = ref["indices"][4:6]  # faces 0 and 1 give two triangles each
    check(sorted(map(tuple, arrow.tolist())) == [(6, 7, 9), (7, 8, 9)],
          "the arrowhead quad is split along its 1-3 diagonal")

    # All smooth quads (a UV sphere), the second UV map used for rendering.
    n_seg, n_ring = 12, 6
    verts, faces = [], []
    for i in range(n_ring + 1):
        # Exact poles: degenerate quads (two corners at one position) split along 1-3.
        z = 1.0 if i == 0 else -1.0 if i == n_ring else np.cos(np.pi * i / n_ring)
        r = 0.0 if i in (0, n_ring) else np.sin(np.pi * i / n_ring)
        for j in range(n_seg):
            verts.append((r * np.cos(2 * np.pi * j / n_seg), r * np.sin(2 * np.pi * j / n_seg), z))
    for i in range(n_ring):
        for j in range(n_seg):
            a, b = i * n_seg + j, i * n_seg + (j + 1) % n_seg
            faces.append((a, b, b + n_seg, a + n_seg))
    me = make_mesh("smooth", verts, faces, smooth=lambda i: True, uv_layers=("A", "B"),
                   render_uv=1)
    compare("smooth", me)
    compare("smooth", me, tangents=True)

    # N-gons: a convex hexagon, a concave (L-shaped) hexagon, a pentagon, plus a quad; flat.
    verts = [(0, 0, 0), (2, 0, 0), (3, 1, 0), (2, 2, 0), (0, 2, 0), (-1, 1, 0),
             (4, 0, 0), (6, 0, 0), (6, 1, 0), (5, 1, 0), (5, 3, 0), (4, 3, 0),
             (7, 0, 0), (8, 0, 0), (8.5, 1, 0), (7.5, 2, 0), (6.8, 1, 0),
             (9, 0, 0), (10, 0, 0), (10, 1, 0), (9, 1, 0)]
    faces = [(0, 1, 2, 3, 4, 5), (6, 7, 8, 9, 10, 11), (12, 13, 14, 15, 16), (17, 18, 19, 20)]
    me = make_mesh("ngons", verts, faces, smooth=lambda i: False, materials=(red, green))
    compare("ngons", me)

    # Custom split normals on a quad strip.
    verts = [(x, y, 0.1 * x * x) for y in (0, 1) for x in range(4)]
    faces = [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6)]
    me = make_mesh("custom", verts, faces, smooth=lambda i: True)
    me.use_auto_smooth = True
    tilt = [(0.3 * (k % 3) - 0.3, 0.2, 1.0) for k in range(len(me.loops))]
    me.normals_split_custom_set([tuple(np.array(t) / np.linalg.norm(t)) for t in tilt])
    me.update()
    check(me.has_custom_normals, "custom normals set")
    compare("custom", me)

    # An evaluated mesh: subdivided cube (modifier applied by the depsgraph).
    bpy.ops.mesh.primitive_cube_add()
    cube = bpy.context.active_object
    mod = cube.modifiers.new("subsurf", 'SUBSURF')
    mod.levels = mod.render_levels = 1
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = cube.evaluated_get(depsgraph).data
    check(len(evaluated.polygons) == 24, "the evaluated cube has the modifier's 24 faces")
    compare("evaluated", evaluated)

    # Object > Visibility > Ray Visibility -> RayKind bits (scene/scene.h), and the panel.
    from gdpt.export_mesh import ray_visibility
    obj = bpy.data.objects.new("vis", me)
    check(ray_visibility(obj) == 31, "all rays see an object by default")
    obj.visible_camera, obj.visible_shadow = False, False
    check(ray_visibility(obj) == 2 | 4 | 8, "camera and shadow bits cleared")
    panel = bpy.types.GDPT_PT_ray_visibility
    check(panel.bl_parent_id == "OBJECT_PT_visibility" and "GDPT" in panel.COMPAT_ENGINES and
          "GDPT" in bpy.types.OBJECT_PT_visibility.COMPAT_ENGINES,
          "the Ray Visibility panel sits under Object > Visibility for Gradient PT")
    lamp = bpy.data.lights.new("lamp", 'POINT')
    from gdpt.export_lights import light_dict
    check(light_dict(bpy.data.objects.new("lamp", lamp), obj.matrix_world, print)["cast_shadow"],
          "lamps cast shadows by default")
    lamp.cycles.cast_shadow = False
    check(not light_dict(bpy.data.objects.new("lamp2", lamp), obj.matrix_world, print)[
        "cast_shadow"], "Cycles' Cast Shadow off is exported")
    check("GDPT" in bpy.types.GDPT_PT_light_shadow.COMPAT_ENGINES, "the Shadow light panel")
    shadow_caustics_flags()


def shadow_caustics_flags():
    """Cycles' Shadow Caustics flags, set in Blender, arrive in the core's Instance / Light fields
    through a whole export (export_scene, the depsgraph's object instances)."""
    from gdpt import _gdpt, export_scene
    scene = S.clear()
    S.camera((0, -6, 2), (0, 0, 0.5))
    glass = S.uv_sphere("glass", 0.5, (0, 0, 0.5), segments=8, rings=4)
    glass.cycles.is_caustics_caster = True
    floor = S.plane("floor", 4, (0, 0, 0))
    floor.cycles.is_caustics_receiver = True
    wall = S.plane("wall", 4, (0, 2, 2), (1.5708, 0, 0))
    # A collection instance: the instanced object's own flags (caster, not receiver), not its
    # instancer's (receiver only).
    source = bpy.data.objects.new("source", glass.data)
    source.cycles.is_caustics_caster = True
    coll = bpy.data.collections.new("casters")
    coll.objects.link(source)
    instancer = S.link(bpy.data.objects.new("instancer", None))
    instancer.instance_type = 'COLLECTION'
    instancer.instance_collection = coll
    instancer.location = (1.5, 0, 0.5)
    instancer.cycles.is_caustics_receiver = True
    for index, obj in enumerate((glass, floor, wall, source), start=1):
        obj.pass_index = index  # tells the instances apart in the export
    lamp = S.light('POINT', (0, 0, 3), 100.0)
    lamp.data.cycles.is_caustics_light = True
    sun = S.light('SUN', (0, 0, 5), 3.0)
    sun.data.cycles.cast_shadow = False  # tells the lights apart

    depsgraph = bpy.context.evaluated_depsgraph_get()
    warnings = []
    builder, _ = export_scene.export_scene(_gdpt, depsgraph, scene.camera.evaluated_get(depsgraph),
                                           warnings.append)
    flags = {}
    for i in range(builder.instance_count):
        d = builder.instance_settings(i)
        flags[round(d["pass_index"])] = (d["caustics_caster"], d["caustics_receiver"])
    check(flags == {1: (True, False), 2: (False, True), 3: (False, False), 4: (True, False)},
          f"Cast / Receive Shadow Caustics arrive in the core's instances, the collection "
          f"instance with its object's own flags ({flags})")
    lights = sorted((builder.light_settings(i)["cast_shadow"],
                     builder.light_settings(i)["caustics_light"]) for i in range(2))
    check(lights == [(False, False), (True, True)],
          f"Cycles' light Shadow Caustics arrives in the core's lights ({lights})")

    # The panels, drawn into a recording layout (a background Blender draws no panels): they
    # show these properties with Cycles' labels (the properties' own names).
    class Layout:
        def __init__(self):
            self.props = []

        def column(self, **_):
            return self

        def prop(self, data, name, text=None, **_):
            self.props.append((data, name, text))

    shown = {}
    context = SimpleNamespace(object=glass, light=lamp.data)
    for panel in (bpy.types.GDPT_PT_object_caustics, bpy.types.GDPT_PT_light_shadow):
        layout = Layout()
        panel.draw(SimpleNamespace(layout=layout), context)
        shown.update({name: (text, data.bl_rna.properties[name].name)
                      for data, name, text in layout.props if name.startswith("is_caustics")})
    check(shown == {"is_caustics_caster": ("Cast Shadow Caustics",) * 2,
                    "is_caustics_receiver": ("Receive Shadow Caustics",) * 2,
                    "is_caustics_light": ("Shadow Caustics",) * 2},
          f"the Caustics object panel and the Shadow light panel show the three flags with "
          f"Cycles' labels ({shown})")
    panel = bpy.types.GDPT_PT_object_caustics
    check(panel.bl_context == "object" and "GDPT" in panel.COMPAT_ENGINES,
          "the object Caustics panel is in Object Properties for Gradient PT")


main()
