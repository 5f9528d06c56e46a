# Material translation never fails a render: for every shader node type Blender registers that a
# material tree accepts, materials that use it as the surface, inside a Mix Shader, feeding a
# colour input, feeding a normal input and inside a node group. Each material is translated on
# its own (translated without a warning, or a warning that names the node, and a dict the core
# accepts), and all of them render in one small frame that must finish with finite pixels.
# Also the case found by hand: Background shaders mixed by a Light Falloff node in an object
# material once stopped the render ("node index -1 out of range").
#   blender -b --factory-startup --addons gdpt --python-exit-code 1 --python this.py -- --out DIR
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import scenes as S  # noqa: E402

check = S.check
SKIP = {"ShaderNodeGroup", "ShaderNodeCustomGroup"}  # groups are one of the uses below


def node_types():
    """bl_idnames of the ShaderNode subclasses a material's tree can hold (outputs aside)."""
    probe = bpy.data.materials.new("probe")
    probe.use_nodes = True
    names = []
    for name in sorted(dir(bpy.types)):
        cls = getattr(bpy.types, name)
        if not (isinstance(cls, type) and issubclass(cls, bpy.types.ShaderNode)) or name in SKIP:
            continue
        try:
            node = probe.node_tree.nodes.new(name)
        except RuntimeError:
            continue
        if node.type.startswith('OUTPUT') or not node.outputs:
            probe.node_tree.nodes.remove(node)
            continue
        names.append(name)
        probe.node_tree.nodes.remove(node)
    bpy.data.materials.remove(probe)
    return names


def first_output(node, want_shader=None):
    outs = [o for o in node.outputs if o.enabled]
    if want_shader is not None:
        preferred = [o for o in outs if (o.type == 'SHADER') == want_shader]
        outs = preferred or outs
    return outs[0]


def build(kind, node_type):
    m, nt, out = S._material(f"{kind}:{node_type}")
    diffuse = nt.nodes.new("ShaderNodeBsdfDiffuse")
    if kind == "group":
        ng = bpy.data.node_groups.new(f"group:{node_type}", 'ShaderNodeTree')
        inner = ng.nodes.new(node_type)
        source = first_output(inner, want_shader=True)
        ng.outputs.new('NodeSocketShader' if source.type == 'SHADER' else 'NodeSocketColor', "Out")
        gout = ng.nodes.new("NodeGroupOutput")
        ng.links.new(source, gout.inputs[0])
        node = nt.nodes.new("ShaderNodeGroup")
        node.node_tree = ng
        nt.links.new(node.outputs[0], out.inputs["Surface"])
        return m
    node = nt.nodes.new(node_type)
    if kind == "surface":
        nt.links.new(first_output(node, want_shader=True), out.inputs["Surface"])
    elif kind == "mix":
        mix = nt.nodes.new("ShaderNodeMixShader")
        nt.links.new(diffuse.outputs[0], mix.inputs[1])
        nt.links.new(first_output(node, want_shader=True), mix.inputs[2])
        nt.links.new(mix.outputs[0], out.inputs["Surface"])
    else:
        socket = "Color" if kind == "color" else "Normal"
        nt.links.new(first_output(node, want_shader=False), diffuse.inputs[socket])
        nt.links.new(diffuse.outputs[0], out.inputs["Surface"])
    return m


def background_falloff():
    """The material found stopping renders: two Background shaders mixed by Light Falloff."""
    m, nt, out = S._material("background_falloff")
    falloff = nt.nodes.new("ShaderNodeLightFalloff")
    a = nt.nodes.new("ShaderNodeBackground")
    b = nt.nodes.new("ShaderNodeBackground")
    mix = nt.nodes.new("ShaderNodeMixShader")
    nt.links.new(falloff.outputs["Linear"], mix.inputs[0])
    nt.links.new(a.outputs[0], mix.inputs[1])
    nt.links.new(b.outputs[0], mix.inputs[2])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    return m


# The Geometry node's outputs Gradient PT does not compute (each reported, 0.5 standing in): none
# of Blender 3.4's.
GEOMETRY_UNSUPPORTED = set()


def geometry_outputs_translate(builder, images, export_materials):
    """Every Geometry output into an Emission colour and strength: a warning for exactly the
    unsupported ones."""
    probe, nt, _ = S._material("geometry outputs")
    names = [o.name for o in nt.nodes.new("ShaderNodeNewGeometry").outputs]
    bpy.data.materials.remove(probe)
    for output in names:
        m, nt, out = S._material(f"geometry output {output}")
        emit = nt.nodes.new("ShaderNodeEmission")
        geometry = nt.nodes.new("ShaderNodeNewGeometry")
        nt.links.new(geometry.outputs[output], emit.inputs["Color"])
        nt.links.new(geometry.outputs[output], emit.inputs["Strength"])
        nt.links.new(emit.outputs[0], out.inputs["Surface"])
        warnings = []
        export_materials.MaterialCache(builder, images, warnings.append).get(m)
        check(bool(warnings) == (output in GEOMETRY_UNSUPPORTED),
              f"Geometry output {output}: warnings {warnings}")
    print(f"Geometry outputs {names}: only {sorted(GEOMETRY_UNSUPPORTED)} reported", flush=True)


def main():
    out_dir = S.args()["out"]
    os.makedirs(out_dir, exist_ok=True)
    scene = S.clear()
    from gdpt import export_images, export_materials, native
    types = node_types()
    check(len(types) > 80, f"{len(types)} shader node types found")
    materials = [background_falloff()]
    for node_type in types:
        for kind in ("surface", "mix", "color", "normal", "group"):
            materials.append(build(kind, node_type))

    # Each material alone: no exception, and a warning, if any, names the node.
    module, _, error = native.load()
    check(module is not None, f"the _gdpt module loads ({error})")
    builder = module.SceneBuilder()
    images = export_images.ImageCache(builder, lambda message: None)
    unnamed = []
    reported = 0
    for m in materials:
        warnings = []
        export_materials.MaterialCache(builder, images, warnings.append).get(m)
        if not warnings:
            continue
        reported += 1
        node_type = m.name.split(":")[-1]
        names = {n.name for n in m.node_tree.nodes}
        group = bpy.data.node_groups.get("group:" + node_type)
        if group is not None and m.name.startswith("group:"):
            names |= {n.name for n in group.nodes}
        if not any(name in w for w in warnings for name in names):
            unnamed.append(f"{m.name}: {warnings}")
    check(not unnamed, f"every warning names a node ({len(unnamed)} do not: {unnamed[:5]})")
    geometry_outputs_translate(builder, images, export_materials)
    print(f"{len(materials)} materials, {reported} with warnings", flush=True)

    # Microfacet distributions: Beckmann and Ashikhmin-Shirley are rendered as Cycles does,
    # silently; Multiscatter GGX too on the Glossy, Glass, Anisotropic and Principled BSDFs
    # (energy-compensated GGX). The Anisotropic BSDF exports each of its distributions.
    for node_type, distribution, exported, warned in (
            ("ShaderNodeBsdfGlossy", 'BECKMANN', 'BECKMANN', False),
            ("ShaderNodeBsdfGlass", 'BECKMANN', 'BECKMANN', False),
            ("ShaderNodeBsdfRefraction", 'BECKMANN', 'BECKMANN', False),
            ("ShaderNodeBsdfGlossy", 'GGX', 'GGX', False),
            ("ShaderNodeBsdfGlass", 'SHARP', 'GGX', False),
            ("ShaderNodeBsdfGlass", 'MULTI_GGX', 'MULTI_GGX', False),
            ("ShaderNodeBsdfGlossy", 'MULTI_GGX', 'MULTI_GGX', False),
            ("ShaderNodeBsdfPrincipled", 'MULTI_GGX', 'MULTI_GGX', False),
            ("ShaderNodeBsdfPrincipled", 'GGX', 'GGX', False),
            ("ShaderNodeBsdfGlossy", 'ASHIKHMIN_SHIRLEY', 'ASHIKHMIN_SHIRLEY', False),
            ("ShaderNodeBsdfAnisotropic", 'GGX', 'GGX', False),
            ("ShaderNodeBsdfAnisotropic", 'ASHIKHMIN_SHIRLEY', 'ASHIKHMIN_SHIRLEY', False),
            ("ShaderNodeBsdfAnisotropic", 'BECKMANN', 'BECKMANN', False),
            ("ShaderNodeBsdfAnisotropic", 'MULTI_GGX', 'MULTI_GGX', False)):
        m = S.shader_material(f"{node_type}:{distribution}", node_type, distribution=distribution)
        warnings = []
        d = export_materials.translate_material(m, images, warnings.append)
        got = d["nodes"][d["root"]].get("distribution")
        check(got == exported and bool(warnings) == warned,
              f"{node_type} {distribution}: exported as {got}, warnings {warnings}")

    # All of them in one frame: a grid of small quads, each its own material.
    cols = math.ceil(math.sqrt(len(materials)))
    for k, m in enumerate(materials):
        x, y = k % cols, k // cols
        S.plane(f"q{k}", 0.9, (x - cols / 2, y - cols / 2, 0), material=m)
    S.camera((0, 0, cols * 1.2), (0, 0, 0), lens=35)
    S.light('SUN', (0, 0, 5), 3.0, target=(0, 0, 0))
    scene.render.resolution_x = scene.render.resolution_y = 4 * cols
    import gdpt.engine as engine
    S.setup_gdpt(scene, 2, mode='GPT', reconstruction='L2', bounces=2)
    engine.LAST_RENDER.clear()
    path = S.render(scene, os.path.join(out_dir, "all_nodes.exr"))
    info = engine.LAST_RENDER
    check(info.get("status") == "finished", f"the frame of {len(materials)} materials finished")
    image = S.read_rgb(path)
    check(np.isfinite(image).all(), "every pixel finite")
    print("ALL NODE TYPES RENDERED", flush=True)


main()
