# Node groups are flattened at export: each case builds one material (or world) twice, with
# node groups (group inputs linked and unlinked, interface defaults overridden on the group node,
# nested groups, reroutes inside, a Group Output socket left unconnected, shader sockets crossing
# the group boundary) and as the same nodes without groups, and renders both with the same seed:
# the images must be identical, with no warning. Without the flattening every grouped material
# renders magenta (Group nodes unsupported).
#   blender -b --factory-startup --addons gdpt --python-exit-code 1 --python this.py -- --out DIR
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import scenes as S  # noqa: E402

check = S.check


def group(name, inputs, outputs):
    """A shader node group with interface sockets (type, name[, default]); returns (tree, its
    Group Input node, its Group Output node)."""
    ng = bpy.data.node_groups.new(name, 'ShaderNodeTree')
    for kind, socket_name, *default in inputs:
        s = ng.inputs.new(kind, socket_name)
        if default:
            s.default_value = default[0]
    for kind, socket_name, *default in outputs:
        s = ng.outputs.new(kind, socket_name)
        if default:
            s.default_value = default[0]
    gin = ng.nodes.new("NodeGroupInput")
    gout = ng.nodes.new("NodeGroupOutput")
    return ng, gin, gout


def instance(nt, tree):
    node = nt.nodes.new("ShaderNodeGroup")
    node.node_tree = tree
    return node


def principled(use_group):
    """A Principled BSDF in a group: Base Color linked from outside, Roughness through a reroute
    from an unlinked group input (the group node's value, not the interface default), Metallic
    from a Value node outside."""
    m, nt, out = S._material("principled")
    rgb = nt.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0.8, 0.3, 0.1, 1.0)
    metal = nt.nodes.new("ShaderNodeValue")
    metal.outputs[0].default_value = 0.4
    if not use_group:
        p = nt.nodes.new("ShaderNodeBsdfPrincipled")
        p.distribution = 'GGX'
        p.inputs["Roughness"].default_value = 0.35
        nt.links.new(rgb.outputs[0], p.inputs["Base Color"])
        nt.links.new(metal.outputs[0], p.inputs["Metallic"])
        nt.links.new(p.outputs[0], out.inputs["Surface"])
        return m
    ng, gin, gout = group("PrincipledGroup",
                          [("NodeSocketColor", "Color"), ("NodeSocketFloat", "Roughness", 0.25),
                           ("NodeSocketFloat", "Metallic")], [("NodeSocketShader", "BSDF")])
    p = ng.nodes.new("ShaderNodeBsdfPrincipled")
    p.distribution = 'GGX'
    reroute = ng.nodes.new("NodeReroute")
    ng.links.new(gin.outputs["Color"], p.inputs["Base Color"])
    ng.links.new(gin.outputs["Roughness"], reroute.inputs[0])
    ng.links.new(reroute.outputs[0], p.inputs["Roughness"])
    ng.links.new(gin.outputs["Metallic"], p.inputs["Metallic"])
    ng.links.new(p.outputs[0], gout.inputs["BSDF"])
    g = instance(nt, ng)
    g.inputs["Roughness"].default_value = 0.35
    nt.links.new(rgb.outputs[0], g.inputs["Color"])
    nt.links.new(metal.outputs[0], g.inputs["Metallic"])
    nt.links.new(g.outputs["BSDF"], out.inputs["Surface"])
    return m


def nested(use_group):
    """Nested groups: an inner group multiplies two values; the outer one holds it and a
    Checker Texture whose scale comes from an unlinked outer input, and leaves its "Spare" colour
    output unconnected (its Group Output value stands in). Outside, a Mix Shader of two Diffuse
    BSDFs reads all three outputs."""
    m, nt, out = S._material("nested")
    mix = nt.nodes.new("ShaderNodeMixShader")
    d1 = nt.nodes.new("ShaderNodeBsdfDiffuse")
    d2 = nt.nodes.new("ShaderNodeBsdfDiffuse")
    nt.links.new(d1.outputs[0], mix.inputs[1])
    nt.links.new(d2.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    if not use_group:
        checker = nt.nodes.new("ShaderNodeTexChecker")
        checker.inputs["Scale"].default_value = 7.0
        math = nt.nodes.new("ShaderNodeMath")
        math.operation = 'MULTIPLY'
        math.inputs[0].default_value = 0.9
        nt.links.new(checker.outputs["Fac"], math.inputs[1])
        nt.links.new(checker.outputs["Color"], d1.inputs["Color"])
        nt.links.new(math.outputs[0], mix.inputs[0])
        d2.inputs["Color"].default_value = (0.1, 0.6, 0.2, 1.0)
        return m
    inner, iin, iout = group("Multiply", [("NodeSocketFloat", "A"), ("NodeSocketFloat", "B")],
                             [("NodeSocketFloat", "Product")])
    math = inner.nodes.new("ShaderNodeMath")
    math.operation = 'MULTIPLY'
    inner.links.new(iin.outputs["A"], math.inputs[0])
    inner.links.new(iin.outputs["B"], math.inputs[1])
    inner.links.new(math.outputs[0], iout.inputs["Product"])
    outer, oin, oout = group("Pattern", [("NodeSocketFloat", "Scale", 5.0)],
                             [("NodeSocketColor", "Color"), ("NodeSocketFloat", "Fac"),
                              ("NodeSocketColor", "Spare")])
    checker = outer.nodes.new("ShaderNodeTexChecker")
    outer.links.new(oin.outputs["Scale"], checker.inputs["Scale"])
    outer.links.new(checker.outputs["Color"], oout.inputs["Color"])
    mul = instance(outer, inner)
    mul.inputs["A"].default_value = 0.9
    reroute = outer.nodes.new("NodeReroute")
    outer.links.new(checker.outputs["Fac"], reroute.inputs[0])
    outer.links.new(reroute.outputs[0], mul.inputs["B"])
    outer.links.new(mul.outputs["Product"], oout.inputs["Fac"])
    oout.inputs["Spare"].default_value = (0.1, 0.6, 0.2, 1.0)
    g = instance(nt, outer)
    g.inputs["Scale"].default_value = 7.0
    nt.links.new(g.outputs["Color"], d1.inputs["Color"])
    nt.links.new(g.outputs["Fac"], mix.inputs[0])
    nt.links.new(g.outputs["Spare"], d2.inputs["Color"])
    return m


def shader_through(use_group):
    """Shaders crossing the boundary: a Glossy BSDF outside enters a group as a shader input,
    is mixed there with an Emission by a group input factor, and leaves as the group's shader.
    The same group is used twice (two instances, one inside the other's input chain), so the
    flattened copies must stay distinct."""
    m, nt, out = S._material("shader_through")
    glossy = nt.nodes.new("ShaderNodeBsdfGlossy")
    glossy.distribution = 'GGX'
    glossy.inputs["Roughness"].default_value = 0.3
    if not use_group:
        e1 = nt.nodes.new("ShaderNodeEmission")
        e1.inputs["Color"].default_value = (0.2, 0.4, 1.0, 1.0)
        mix1 = nt.nodes.new("ShaderNodeMixShader")
        mix1.inputs[0].default_value = 0.3
        nt.links.new(glossy.outputs[0], mix1.inputs[1])
        nt.links.new(e1.outputs[0], mix1.inputs[2])
        e2 = nt.nodes.new("ShaderNodeEmission")
        e2.inputs["Color"].default_value = (0.2, 0.4, 1.0, 1.0)
        mix2 = nt.nodes.new("ShaderNodeMixShader")
        mix2.inputs[0].default_value = 0.6
        nt.links.new(mix1.outputs[0], mix2.inputs[1])
        nt.links.new(e2.outputs[0], mix2.inputs[2])
        nt.links.new(mix2.outputs[0], out.inputs["Surface"])
        return m
    ng, gin, gout = group("Glow", [("NodeSocketShader", "Shader"), ("NodeSocketFloat", "Fac")],
                          [("NodeSocketShader", "Shader")])
    e = ng.nodes.new("ShaderNodeEmission")
    e.inputs["Color"].default_value = (0.2, 0.4, 1.0, 1.0)
    mix = ng.nodes.new("ShaderNodeMixShader")
    ng.links.new(gin.outputs["Fac"], mix.inputs[0])
    ng.links.new(gin.outputs["Shader"], mix.inputs[1])
    ng.links.new(e.outputs[0], mix.inputs[2])
    ng.links.new(mix.outputs[0], gout.inputs["Shader"])
    g1 = instance(nt, ng)
    g1.inputs["Fac"].default_value = 0.3
    g2 = instance(nt, ng)
    g2.inputs["Fac"].default_value = 0.6
    nt.links.new(glossy.outputs[0], g1.inputs["Shader"])
    nt.links.new(g1.outputs[0], g2.inputs["Shader"])
    nt.links.new(g2.outputs[0], out.inputs["Surface"])
    return m


def world_group(scene, use_group):
    """The world's Background inside a group (colour from an RGB node outside, strength an
    unlinked group input), and Light Path's Is Camera Ray choosing it inside another group."""
    world = scene.world
    world.use_nodes = True
    nt = world.node_tree
    for n in list(nt.nodes):
        nt.nodes.remove(n)
    out = nt.nodes.new("ShaderNodeOutputWorld")
    rgb = nt.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0.5, 0.6, 0.9, 1.0)
    seen = nt.nodes.new("ShaderNodeBackground")
    seen.inputs["Color"].default_value = (0.05, 0.05, 0.1, 1.0)
    if not use_group:
        bg = nt.nodes.new("ShaderNodeBackground")
        bg.inputs["Strength"].default_value = 1.7
        nt.links.new(rgb.outputs[0], bg.inputs["Color"])
        path = nt.nodes.new("ShaderNodeLightPath")
        mix = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(path.outputs["Is Camera Ray"], mix.inputs[0])
        nt.links.new(bg.outputs[0], mix.inputs[1])
        nt.links.new(seen.outputs[0], mix.inputs[2])
        nt.links.new(mix.outputs[0], out.inputs["Surface"])
        return
    sky, sin, sout = group("Sky", [("NodeSocketColor", "Color"),
                                   ("NodeSocketFloat", "Strength", 1.0)],
                           [("NodeSocketShader", "Background")])
    bg = sky.nodes.new("ShaderNodeBackground")
    sky.links.new(sin.outputs["Color"], bg.inputs["Color"])
    sky.links.new(sin.outputs["Strength"], bg.inputs["Strength"])
    sky.links.new(bg.outputs[0], sout.inputs["Background"])
    pick, pin, pout = group("CameraPick", [("NodeSocketShader", "Lighting"),
                                           ("NodeSocketShader", "Seen")],
                            [("NodeSocketShader", "Shader")])
    path = pick.nodes.new("ShaderNodeLightPath")
    mix = pick.nodes.new("ShaderNodeMixShader")
    pick.links.new(path.outputs["Is Camera Ray"], mix.inputs[0])
    pick.links.new(pin.outputs["Lighting"], mix.inputs[1])
    pick.links.new(pin.outputs["Seen"], mix.inputs[2])
    pick.links.new(mix.outputs[0], pout.inputs["Shader"])
    g_sky = instance(nt, sky)
    g_sky.inputs["Strength"].default_value = 1.7
    nt.links.new(rgb.outputs[0], g_sky.inputs["Color"])
    g_pick = instance(nt, pick)
    nt.links.new(g_sky.outputs[0], g_pick.inputs["Lighting"])
    nt.links.new(seen.outputs[0], g_pick.inputs["Seen"])
    nt.links.new(g_pick.outputs[0], out.inputs["Surface"])


def converted_input(use_group):
    """A float group input, unlinked on the group node, feeding a Mapping's Scale (a vector) in
    front of a Checker Texture: Cycles reads the float as (f, f, f)."""
    m, nt, out = S._material("converted")
    d = nt.nodes.new("ShaderNodeBsdfDiffuse")
    nt.links.new(d.outputs[0], out.inputs["Surface"])
    tree, gin, gout = (nt, None, None) if not use_group else group(
        "Tiles", [("NodeSocketFloat", "Scale", 1.0)], [("NodeSocketColor", "Color")])
    coords = tree.nodes.new("ShaderNodeTexCoord")
    mapping = tree.nodes.new("ShaderNodeMapping")
    checker = tree.nodes.new("ShaderNodeTexChecker")
    tree.links.new(coords.outputs["Object"], mapping.inputs["Vector"])
    tree.links.new(mapping.outputs[0], checker.inputs["Vector"])
    if not use_group:
        mapping.inputs["Scale"].default_value = (3.0, 3.0, 3.0)
        nt.links.new(checker.outputs["Color"], d.inputs["Color"])
        return m
    tree.links.new(gin.outputs["Scale"], mapping.inputs["Scale"])
    tree.links.new(checker.outputs["Color"], gout.inputs["Color"])
    g = instance(nt, tree)
    g.inputs["Scale"].default_value = 3.0
    nt.links.new(g.outputs["Color"], d.inputs["Color"])
    return m


MATERIAL_CASES = {"principled": principled, "nested": nested, "shader_through": shader_through,
                  "converted_input": converted_input}


def scene_for(case, use_group):
    scene = S.clear()
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    S.plane("floor", 8.0, (0, 0, 0), material=S.diffuse("floor", (0.6, 0.6, 0.6)))
    S.camera((0, -4.5, 1.8), (0, 0, 0.7), lens=35)
    S.light('AREA', (0, -1.0, 3.5), 200.0, target=(0, 0, 0), size=1.0)
    if case == "world":
        world_group(scene, use_group)
        material = S.glossy("ball", 0.2)
    else:
        material = MATERIAL_CASES[case](use_group)
    S.uv_sphere("ball", 0.8, (0, 0, 0.8), material)
    return scene


def render(case, use_group, out_dir):
    import gdpt.engine as engine
    scene = scene_for(case, use_group)
    S.setup_gdpt(scene, 4, mode='PT', reconstruction='NONE', bounces=3)
    engine.LAST_RENDER.clear()
    path = S.render(scene, os.path.join(out_dir, f"{case}_{'group' if use_group else 'flat'}.exr"))
    info = engine.LAST_RENDER
    check(info.get("status") == "finished", f"{case} ({'grouped' if use_group else 'flat'}) rendered")
    return S.read_rgb(path), info.get("warnings", [])


def main():
    out_dir = S.args()["out"]
    os.makedirs(out_dir, exist_ok=True)
    for case in list(MATERIAL_CASES) + ["world"]:
        flat, flat_warnings = render(case, False, out_dir)
        grouped, warnings = render(case, True, out_dir)
        check(not flat_warnings and not warnings,
              f"{case}: no warnings ({flat_warnings + warnings})")
        check(flat.mean() > 0.01, f"{case}: the image is lit (mean {flat.mean():.4f})")
        diff = float(np.abs(grouped - flat).max())
        check(diff == 0.0, f"{case}: grouped and flat images identical (max difference {diff:g})")
    print("ALL NODE GROUP CASES PASSED", flush=True)


main()
