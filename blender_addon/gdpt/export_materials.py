# Blender material node trees -> MaterialDesc dicts (see blender_addon/module/scene_convert.h).
#
# Walks from the active Material Output's Surface input over the tree with its node groups
# flattened (export_node_groups.py). Supported shader nodes: Principled BSDF, Diffuse, Glossy,
# Anisotropic (GGX, Beckmann, Ashikhmin-Shirley, Multiscatter GGX; its Tangent: Cycles' default
# radial tangent, a Tangent node, Radial or UV Map, or a vector), Glass, Emission (and, reported,
# Background: Cycles shows it as one on a surface), Transparent, Mix Shader, Add Shader, Subsurface
# Scattering and Principled's subsurface (the diffuse Cycles falls back to at radius 0; a larger
# radius renders the same, reported); a colour or float output on a shader socket becomes an
# Emission, and an unlinked shader input is no closure (black), as in Cycles.
# Inputs may be constants, RGB / Value nodes, colour / math / curve nodes, Blackbody, Fresnel,
# Layer Weight, Geometry (Normal, True Normal, Incoming, Backfacing, Tangent, Pointiness,
# Parametric, Random Per Island), Light Path (read per path: its own direction and state), Vector
# Transform (World / Object / Camera, Cycles' camera space) and Wireframe (per triangle; Use Pixel
# Size reported: the camera's pixel), image and procedural textures read at UV, Generated or
# Object coordinates, optionally through a Mapping node. The Displacement output (a Displacement
# node) renders as Cycles' Bump Only. Reroutes and muted nodes are followed. Anything else is
# reported once per material (naming the node)
# and followed through its mute pass-through link when it has one; otherwise a
# magenta diffuse (shaders) or the socket's own value (inputs) stands in, so the render still
# completes. A material whose translation fails (or that the core rejects) renders magenta, with
# a warning naming it and the node.

from mathutils import Euler, Matrix

from . import export_node_groups as groups

MAGENTA = (1.0, 0.0, 1.0)
# A second chain of Normal Map / Bump nodes in one material: its input keeps the surface's normal.
_SECOND_PERTURBATION = "second normal perturbation (only the first chain is modelled; this input " \
    "gets the surface's normal) in"
IDENTITY12 = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]

_SHADERS = {
    'BSDF_PRINCIPLED', 'BSDF_DIFFUSE', 'BSDF_GLOSSY', 'BSDF_GLASS', 'EMISSION',
    'BSDF_TRANSPARENT', 'MIX_SHADER', 'ADD_SHADER', 'BSDF_TRANSLUCENT', 'BSDF_VELVET',
    'BSDF_REFRACTION', 'SUBSURFACE_SCATTERING', 'BSDF_ANISOTROPIC',
}
# Cycles turns a BSSRDF channel of a smaller radius into a diffuse BSDF (BSSRDF_MIN_RADIUS).
_BSSRDF_MIN_RADIUS = 1e-8
_NO_TRANSPORT = "subsurface scattering, rendered as diffuse (no subsurface transport), of"
# The Principled BSDF's distributions: Multiscatter GGX as GGX with an energy-compensating lobe.
_PRINCIPLED = {'GGX': 'GGX', 'MULTI_GGX': 'MULTI_GGX'}
# The microfacet distributions the core renders as Cycles does (Sharp is GGX at roughness 0;
# Blender offers Ashikhmin-Shirley on the Glossy BSDF only).
_MICROFACET = {'GGX': 'GGX', 'SHARP': 'GGX', 'BECKMANN': 'BECKMANN',
               'ASHIKHMIN_SHIRLEY': 'ASHIKHMIN_SHIRLEY'}
# The Glossy and Glass BSDFs': those, and Multiscatter GGX as energy-compensated GGX (Glossy: an
# added multiple-scattering lobe; Glass: the lobe scaled to conserve energy). Blender 3.4's
# Refraction BSDF offers Sharp, Beckmann and GGX only.
_GLOSSY = dict(_MICROFACET, MULTI_GGX='MULTI_GGX')
# The Anisotropic BSDF's: those of the Glossy BSDF (Multiscatter GGX: the energy-compensating lobe
# of the widths' root mean square).
_ANISOTROPIC = {'GGX': 'GGX', 'BECKMANN': 'BECKMANN', 'ASHIKHMIN_SHIRLEY': 'ASHIKHMIN_SHIRLEY',
                'MULTI_GGX': 'MULTI_GGX'}
# Colour / math nodes between inputs and shaders, and their modes the core models.
_INPUT_NODES = {'MIX', 'MIX_RGB', 'MATH', 'INVERT', 'VALTORGB', 'SEPRGB', 'SEPARATE_COLOR',
                'COMBRGB', 'COMBINE_COLOR', 'GAMMA', 'BRIGHTCONTRAST', 'HUE_SAT', 'MAP_RANGE',
                'CLAMP', 'RGBTOBW', 'VERTEX_COLOR', 'ATTRIBUTE', 'TEX_CHECKER', 'TEX_NOISE',
                'TEX_COORD', 'UVMAP', 'MAPPING', 'SEPXYZ', 'TEX_VORONOI', 'TEX_GRADIENT',
                'TEX_WAVE', 'TEX_MUSGRAVE', 'TEX_WHITE_NOISE', 'TEX_MAGIC', 'VECT_MATH', 'COMBXYZ',
                'TEX_BRICK', 'CURVE_RGB', 'CURVE_VEC', 'CURVE_FLOAT', 'BLACKBODY', 'SEPHSV',
                'COMBHSV', 'FRESNEL', 'LAYER_WEIGHT', 'NEW_GEOMETRY', 'LIGHT_PATH',
                'VECT_TRANSFORM', 'WIREFRAME'}
# The Geometry node's outputs the core reads from the view of the hit or from the mesh there
# (Position: coordinates).
_GEOMETRY_OUTPUTS = {'Normal', 'True Normal', 'Incoming', 'Backfacing', 'Tangent', 'Pointiness',
                     'Parametric', 'Random Per Island'}
# Those the mesh export computes for the meshes whose materials read them (Mesh::vertex_pointiness,
# Mesh::triangle_island_random), by the names GeometryExporter passes on.
_MESH_ATTRIBUTE_OUTPUTS = {'Pointiness': 'pointiness', 'Random Per Island': 'random_per_island'}
# The Light Path node's outputs in object materials (Is Volume Scatter Ray: no volumes, 0).
_LIGHT_PATH_OUTPUTS = {'Is Camera Ray', 'Is Shadow Ray', 'Is Diffuse Ray', 'Is Glossy Ray',
                       'Is Singular Ray', 'Is Reflection Ray', 'Is Transmission Ray',
                       'Ray Length', 'Ray Depth', 'Diffuse Depth', 'Glossy Depth',
                       'Transparent Depth', 'Transmission Depth'}
_RAMP_TABLE_SIZE = 256  # Cycles' RAMP_TABLE_SIZE
_VORONOI_FEATURES = {'F1', 'F2', 'SMOOTH_F1', 'DISTANCE_TO_EDGE'}  # 3D
_MAPPING_TYPES = {'POINT', 'TEXTURE', 'VECTOR'}  # Normal normalises: not a fixed transform
_BLENDS = {'MIX', 'ADD', 'MULTIPLY', 'SUBTRACT', 'SCREEN', 'DIVIDE', 'DIFFERENCE', 'DARKEN',
           'LIGHTEN'}
# Every operation of Blender 3.4's Math node (shaders/math_node.h).
_MATH_OPS = {'ADD', 'SUBTRACT', 'MULTIPLY', 'DIVIDE', 'MULTIPLY_ADD', 'POWER', 'LOGARITHM', 'SQRT',
             'INVERSE_SQRT', 'ABSOLUTE', 'EXPONENT', 'MINIMUM', 'MAXIMUM', 'LESS_THAN',
             'GREATER_THAN', 'SIGN', 'COMPARE', 'SMOOTH_MIN', 'SMOOTH_MAX', 'ROUND', 'FLOOR',
             'CEIL', 'TRUNC', 'FRACT', 'MODULO', 'WRAP', 'SNAP', 'PINGPONG', 'SINE', 'COSINE',
             'TANGENT', 'ARCSINE', 'ARCCOSINE', 'ARCTANGENT', 'ARCTAN2', 'SINH', 'COSH', 'TANH',
             'RADIANS', 'DEGREES'}


def _matrix12(m):
    return [m[r][c] for r in range(3) for c in range(4)]


class _Translator:
    def __init__(self, material, images, warn):
        self.material = material
        self.images = images
        self.warn_sink = warn
        self.warned = set()
        self.nodes = []
        # The normal chain (MaterialDesc::bumps and normal_map): the displacement as bump, then
        # the Normal Map and the Bump nodes the BSDFs' Normal inputs lead to.
        self.displacement_bump = None  # its dict
        self.normal_map = None  # its dict
        self.bumps = []  # Bump nodes' dicts, innermost first
        self.chain_top = None  # the node the BSDFs read the chain's normal from
        self.chain_nodes = set()
        self.inputs = []  # colour / math input nodes (MaterialDesc::inputs)
        self.color_attribute = None  # name read by Color Attribute nodes ("": the render one)
        self.uv_tangents = False  # a Tangent node reads the UV map's tangents
        self.mesh_attributes = set()  # _MESH_ATTRIBUTE_OUTPUTS' values the material reads
        self.input_index = {}  # node name -> index in self.inputs
        self.current = None  # the node being translated (named when translation fails)

    # --- reporting ---------------------------------------------------------------------------

    def warn(self, node, what):
        key = (node.name, what)
        if key in self.warned:
            return
        self.warned.add(key)
        self.warn_sink(f"material '{self.material.name}': {what} '{node.name}' "
                       f"({node.bl_idname}) is not supported by Gradient PT")

    # --- link following ----------------------------------------------------------------------

    @staticmethod
    def _source(socket):
        """The output socket feeding `socket` in the group-flattened tree, through reroutes
        and muted nodes; None if unlinked."""
        return groups.source(socket)

    @staticmethod
    def _passthrough_input(node, output):
        return node.passthrough(output)

    # --- shaders -----------------------------------------------------------------------------

    def shader(self, socket):
        """Node index for the closure feeding `socket`, -1 for none (black/transparent)."""
        out = self._source(socket)
        if out is None:
            return -1
        node = out.node
        self.current = node
        if out.type != 'SHADER':
            # Cycles converts a colour (or vector) on a shader socket to an Emission of that
            # colour, a float to the strength of a white one (ShaderGraph::connect).
            if out.type == 'VALUE':
                return self._add({"kind": "EMISSION", "color": {"value": (1.0, 1.0, 1.0)},
                                  "strength": self._value_of(out, {"value": 1.0})})
            return self._add({"kind": "EMISSION", "strength": {"value": 1.0},
                              "color": self._color_of(out, {"value": (0.0, 0.0, 0.0)})})
        if node.type == 'BACKGROUND':
            # On a surface Cycles shows a Background closure as an Emission of colour x
            # strength, but lights the scene with less of it (one measure: 8% less light in a
            # room than the same Emission): an approximation, reported.
            self.warn(node, "Background shader on a surface (rendered as Emission; Cycles "
                      "lights the scene less with it) in an object material:")
            return self._emission(node)
        if node.type not in _SHADERS:
            self.warn(node, "shader node")
            passthrough = self._passthrough_input(node, out)
            if passthrough is not None and passthrough.type == 'SHADER':
                return self.shader(passthrough)
            return self._add({"kind": "DIFFUSE", "color": {"value": MAGENTA}})
        return getattr(self, "_" + node.type.lower())(node)

    def _add(self, d):
        self.nodes.append(d)
        return len(self.nodes) - 1

    def _bsdf_principled(self, n):
        i = n.inputs
        if n.distribution not in _PRINCIPLED:
            self.warn(n, f"distribution {n.distribution} (rendered as GGX) of")
        subsurface = i["Subsurface"]
        has_subsurface = subsurface.is_linked or subsurface.default_value != 0.0
        if has_subsurface:
            # Cycles' radius is Subsurface Radius x Subsurface.
            self._warn_transport(n, i["Subsurface Radius"], subsurface)
        normal_linked = self.normal(i["Normal"])
        clearcoat_normal_linked = self.normal(i["Clearcoat Normal"])
        d = {
            "kind": "PRINCIPLED",
            "color": self.color(i["Base Color"]),
            "metallic": self.value(i["Metallic"]),
            "specular": self.value(i["Specular"]),
            "specular_tint": self.value(i["Specular Tint"]),
            "roughness": self.value(i["Roughness"]),
            "ior": self.value(i["IOR"]),
            "transmission": self.value(i["Transmission"]),
            "sheen": self.value(i["Sheen"]),
            "sheen_tint": self.value(i["Sheen Tint"]),
            "clearcoat": self.value(i["Clearcoat"]),
            "clearcoat_roughness": self.value(i["Clearcoat Roughness"]),
            "normal_linked": normal_linked,
            "clearcoat_normal_linked": clearcoat_normal_linked,
            "emission": self.color(i["Emission"]),
            "emission_strength": self.value(i["Emission Strength"]),
            "alpha": self.value(i["Alpha"]),
            "anisotropy": self.value(i["Anisotropic"]),
            "rotation": self.value(i["Anisotropic Rotation"]),
            "tangent": self.tangent(i["Tangent"]),
            "distribution": _PRINCIPLED.get(n.distribution, 'GGX'),
        }
        if has_subsurface:
            d["subsurface"] = self.value(subsurface)
            d["subsurface_color"] = self.color(i["Subsurface Color"])
        return self._add(d)

    def _warn_transport(self, n, radius, scale):
        """Reports a BSSRDF whose radius (radius x scale, per channel) may reach Cycles' minimum:
        Cycles carries light under the surface there, Gradient PT renders the diffuse it falls
        back to below the minimum."""
        r = tuple(radius.default_value)
        if radius.is_linked:
            transport = True
        elif scale.is_linked:
            transport = any(c != 0.0 for c in r)  # the scale may take either sign
        else:
            transport = max(c * scale.default_value for c in r) >= _BSSRDF_MIN_RADIUS
        if transport:
            self.warn(n, _NO_TRANSPORT)

    def _subsurface_scattering(self, n):
        # Cycles' BSSRDF of radius 0 is a Lambert diffuse of the node's Color (bssrdf_setup).
        i = n.inputs
        self._warn_transport(n, i["Radius"], i["Scale"])
        linked = self.normal(i["Normal"])
        return self._add({"kind": "DIFFUSE", "color": self.color(i["Color"]),
                          "roughness": {"value": 0.0}, "normal_linked": linked})

    def _bsdf_diffuse(self, n):
        linked = self.normal(n.inputs["Normal"])
        return self._add({"kind": "DIFFUSE", "color": self.color(n.inputs["Color"]),
                          "roughness": self.value(n.inputs["Roughness"]),
                          "normal_linked": linked})

    def _distribution(self, n, supported=_MICROFACET):
        if n.distribution not in supported:
            self.warn(n, f"distribution {n.distribution} (rendered as GGX) of")
        return supported.get(n.distribution, 'GGX')

    def _bsdf_glossy(self, n):
        distribution = self._distribution(n, _GLOSSY)
        linked = self.normal(n.inputs["Normal"])
        roughness = self.value(n.inputs["Roughness"])
        if n.distribution == 'SHARP':
            roughness = {"value": 0.0}
        return self._add({"kind": "GLOSSY", "color": self.color(n.inputs["Color"]),
                          "roughness": roughness, "distribution": distribution,
                          "normal_linked": linked})

    def _bsdf_anisotropic(self, n):
        if n.distribution not in _ANISOTROPIC:
            self.warn(n, f"distribution {n.distribution} (rendered as GGX) of")
        linked = self.normal(n.inputs["Normal"])
        return self._add({"kind": "ANISOTROPIC", "color": self.color(n.inputs["Color"]),
                          "distribution": _ANISOTROPIC.get(n.distribution, 'GGX'),
                          "roughness": self.value(n.inputs["Roughness"]),
                          "anisotropy": self.value(n.inputs["Anisotropy"]),
                          "rotation": self.value(n.inputs["Rotation"]),
                          "tangent": self.tangent(n.inputs["Tangent"]), "normal_linked": linked})

    def _bsdf_glass(self, n):
        distribution = self._distribution(n, _GLOSSY)
        linked = self.normal(n.inputs["Normal"])
        roughness = self.value(n.inputs["Roughness"])
        if n.distribution == 'SHARP':
            roughness = {"value": 0.0}
        return self._add({"kind": "GLASS", "color": self.color(n.inputs["Color"]),
                          "roughness": roughness, "ior": self.value(n.inputs["IOR"]),
                          "distribution": distribution, "normal_linked": linked})

    def _bsdf_refraction(self, n):
        index = self._bsdf_glass(n)  # the same inputs and distributions
        self.nodes[index]["kind"] = "REFRACTION"
        return index

    def _emission(self, n):
        return self._add({"kind": "EMISSION", "color": self.color(n.inputs["Color"]),
                          "strength": self.value(n.inputs["Strength"])})

    def _bsdf_translucent(self, n):
        linked = self.normal(n.inputs["Normal"])
        return self._add({"kind": "TRANSLUCENT", "color": self.color(n.inputs["Color"]),
                          "normal_linked": linked})

    def _bsdf_velvet(self, n):
        linked = self.normal(n.inputs["Normal"])
        return self._add({"kind": "VELVET", "color": self.color(n.inputs["Color"]),
                          "roughness": self.value(n.inputs["Sigma"]), "normal_linked": linked})

    def _bsdf_transparent(self, n):
        return self._add({"kind": "TRANSPARENT", "color": self.color(n.inputs["Color"])})

    def _mix_shader(self, n):
        fac = self.value(n.inputs[0])
        a = self.shader(n.inputs[1])
        b = self.shader(n.inputs[2])
        return self._add({"kind": "MIX", "fac": fac, "a": a, "b": b})

    def _add_shader(self, n):
        a = self.shader(n.inputs[0])
        b = self.shader(n.inputs[1])
        return self._add({"kind": "ADD", "a": a, "b": b})

    # --- inputs ------------------------------------------------------------------------------

    def normal(self, socket):
        """A BSDF's Normal (or Clearcoat Normal) input: a tangent-space Normal Map node, or a
        Bump node with the chain of Bump nodes (and at its base a Normal Map) on its own Normal
        input, becomes the material's normal chain (one per material: the first found; another
        one is reported and its input gets the surface's normal). Returns whether the input
        takes the chain's normal; an unlinked input keeps the surface's normal (interpolated, or
        the displacement's, which replaces it as in Cycles)."""
        out = self._source(socket)
        if out is None:
            return False
        node = out.node
        if node.type not in ('BUMP', 'NORMAL_MAP'):
            self.warn(node, "normal / tangent input node")
            return False
        if self.chain_top is None:
            self.chain_top = node
            self._chain(node)
            return True
        if node == self.chain_top:
            return True
        if node in self.chain_nodes:
            self.warn(node, "normal input reading an inner node of a chain of Bump nodes (it gets "
                      "the whole chain's normal) in")
            return True
        self.warn(node, _SECOND_PERTURBATION)
        return False

    def tangent(self, socket):
        """An anisotropic lobe's Tangent input (TangentInput): unlinked, or the Geometry node's
        Tangent, is Cycles' default, radial about the object's Z axis; a Tangent node is radial
        about its axis or its UV map's tangent (the active render UV map's MikkTSpace tangents,
        exported with the mesh); any other vector is read as it is (world space)."""
        out = self._source(socket)
        if out is None or (out.node.type == 'NEW_GEOMETRY' and out.name == "Tangent"):
            return {"source": "RADIAL", "axis": 2}
        node = out.node
        if node.type == 'TANGENT':
            if node.direction_type == 'RADIAL':
                return {"source": "RADIAL", "axis": "XYZ".index(node.axis)}
            if node.uv_map:
                self.warn(node, f"UV map '{node.uv_map}' (the active render UV map's tangents "
                          "are used) of")
            self.uv_tangents = True
            return {"source": "UV_MAP"}
        return {"source": "VECTOR", "vector": self.color(socket)}

    def _view_normal(self, socket):
        """A Fresnel / Layer Weight Normal input: unlinked or the Geometry node's Normal is the
        interpolated normal; a Normal Map / Bump node the material's normal chain (normal()).
        Returns whether it reads the chain."""
        out = self._source(socket)
        if out is None or (out.node.type == 'NEW_GEOMETRY' and out.name == "Normal"):
            return False
        return self.normal(socket)

    def _chain(self, top):
        """The material's normal chain ending at `top`: the Bump nodes down their Normal inputs
        (innermost first in self.bumps) and a tangent-space Normal Map at the base."""
        node, stack = top, []
        while node is not None and node.type == 'BUMP':
            stack.append(node)
            out = self._source(node.inputs["Normal"])
            if out is None or (out.node.type == 'NEW_GEOMETRY' and out.name == "Normal"):
                node = None
            elif out.node.type in ('BUMP', 'NORMAL_MAP'):
                node = out.node
            else:
                self.warn(out.node, "node on a Bump's Normal input (not followed)")
                node = None
        self.chain_nodes = set(stack)
        if node is not None:
            self.chain_nodes.add(node)
            self._normal_map(node)
        for bump in reversed(stack):
            for name in ("Strength", "Distance"):
                if bump.inputs[name].is_linked:
                    self.warn(bump, f"linked {name} (its default value is used) of")
            self.bumps.append({"height": self.value(bump.inputs["Height"]),
                               "strength": float(bump.inputs["Strength"].default_value),
                               "distance": float(bump.inputs["Distance"].default_value),
                               "invert": bool(bump.invert)})

    def _normal_map(self, node):
        if node.space != 'TANGENT':
            self.warn(node, f"{node.space.lower()}-space normal map")
            return
        if node.uv_map:
            self.warn(node, "UV map other than the active render UV map in")
        if node.inputs["Strength"].is_linked:
            self.warn(node, "linked Strength (its default value is used) of")
        self.normal_map = {"color": self.color(node.inputs["Color"]),
                           "strength": float(node.inputs["Strength"].default_value)}

    def displacement(self, socket):
        """The Material Output's Displacement as Cycles' Bump Only method renders it: the
        displacement's component along the normal, (Height - Midlevel) Scale for a Displacement
        node, is the height of a bump of distance and strength 1 that replaces the surface's
        normal (Cycles' bump_from_displacement). It takes the material's perturbation."""
        out = self._source(socket)
        if out is None:
            return
        node = out.node
        self.current = node
        # Cycles' setting (absent when the Cycles add-on is off: its default, Bump Only).
        cycles = getattr(self.material, "cycles", None)
        method = getattr(cycles, "displacement_method", 'BUMP')
        if method != 'BUMP':
            self.warn(node, f"displacement method {method} (rendered as Bump Only) with")
        if node.type == 'VECTOR_DISPLACEMENT':
            self._vector_displacement(node)
            return
        if node.type != 'DISPLACEMENT':
            self.warn(node, "displacement node (the displacement is ignored)")
            return
        if node.inputs["Normal"].is_linked:
            self.warn(node, "linked Normal (the displacement is ignored) of")
            return

        def math(op, a, b):
            return self._push_input({"kind": "MATH", "op": op, "value_a": a, "value_b": b})

        i = node.inputs
        offset = math("SUBTRACT", self.value(i["Height"]), self.value(i["Midlevel"]))
        height = math("MULTIPLY", offset, self.value(i["Scale"]))
        self.displacement_bump = {"height": height, "strength": 1.0, "distance": 1.0,
                                  "invert": False, "replaces_normal": True}

    def _vector_displacement(self, node):
        """A Vector Displacement node as Cycles' Bump Only method renders it: the height is the
        displacement's component along the normal, with the vector (Vector - Midlevel) Scale
        taken to world space by the node's space (BumpDesc::vector_space; tangent space reads the
        active render UV map's tangents)."""
        i = node.inputs

        def vector_math(op, a, b=None, scale=None):
            d = {"kind": "VECTOR_MATH", "op": op, "a": a}
            if b is not None:
                d["b"] = b
            if scale is not None:
                d["value_a"] = scale
            return {"value": (0.0, 0.0, 0.0), "node": self._push_input(d)["node"]}

        mid = self.value(i["Midlevel"])
        if set(mid) != {"value"}:  # linked: the same value on each axis
            mid_rgb = {"value": (0.0, 0.0, 0.0), "node": self._push_input(
                {"kind": "COMBINE_XYZ", "value_a": mid, "value_b": mid, "value_c": mid})["node"]}
        else:
            mid_rgb = {"value": (mid["value"],) * 3}
        offset = vector_math("SUBTRACT", self.color(i["Vector"]), mid_rgb)
        vector = vector_math("SCALE", offset, scale=self.value(i["Scale"]))
        if node.space == 'TANGENT':
            self.uv_tangents = True
        self.displacement_bump = {"strength": 1.0, "distance": 1.0, "invert": False,
                                  "replaces_normal": True, "vector": vector,
                                  "vector_space": node.space}

    def color(self, socket):
        d = {"value": self._default_rgb(socket)}
        out = self._source(socket)
        if out is None:
            return d
        return self._color_of(out, d)

    def _color_of(self, out, d):
        """A colour input fed by output `out`; d holds the input's own value."""
        node = out.node
        self.current = node
        if node.type == 'LIGHT_FALLOFF':
            f = self._falloff(node, out)
            return {"value": (f["value"],) * 3, "node": f["node"]} if "node" in f else \
                self.color(node.inputs["Strength"])
        if self._unsupported_geometry(node, out):
            d["value"] = (0.5, 0.5, 0.5)
            return d
        if node.type == 'RGB':
            d["value"] = tuple(out.default_value)[:3]
        elif node.type == 'VALUE':
            v = out.default_value
            d["value"] = (v, v, v)
        elif node.type == 'TEX_IMAGE':
            self._texture(node, d)
        elif node.type in _INPUT_NODES and self._input_node(node, out) is not None:
            d["node"] = self._input_node(node, out)
        else:
            if node.type not in _INPUT_NODES:  # those warned about their mode
                self.warn(node, "input node")
            passthrough = self._passthrough_input(node, out)
            if passthrough is not None and passthrough.type in {'RGBA', 'VALUE', 'VECTOR'}:
                return self.color(passthrough)
            d["value"] = MAGENTA
        return d

    def value(self, socket):
        # A colour socket (an unsupported node's pass-through input) reads as its luminance.
        v = socket.default_value
        if hasattr(v, "__len__"):
            r, g, b = tuple(v)[:3]
            v = 0.2126 * r + 0.7152 * g + 0.0722 * b
        d = {"value": float(v)}
        out = self._source(socket)
        if out is None:
            return d
        return self._value_of(out, d)

    def _value_of(self, out, d):
        """A float input fed by output `out`; d holds the input's own value."""
        node = out.node
        self.current = node
        if node.type == 'LIGHT_FALLOFF':
            return self._falloff(node, out)
        if self._unsupported_geometry(node, out):
            d["value"] = 0.5
            return d
        if node.type == 'VALUE':
            d["value"] = float(out.default_value)
        elif node.type == 'RGB':
            r, g, b = tuple(out.default_value)[:3]
            d["value"] = 0.2126 * r + 0.7152 * g + 0.0722 * b
        elif node.type == 'TEX_IMAGE':
            self._texture(node, d)
            d["channel"] = 'ALPHA' if out.name == "Alpha" else 'LUMINANCE'
        elif node.type in _INPUT_NODES and self._input_node(node, out) is not None:
            d["node"] = self._input_node(node, out)
        else:
            if node.type not in _INPUT_NODES:  # those warned about their mode
                self.warn(node, "input node")
            passthrough = self._passthrough_input(node, out)
            if passthrough is not None and passthrough.type in {'RGBA', 'VALUE'}:
                return self.value(passthrough)
        return d

    def _unsupported_geometry(self, node, out):
        """A Geometry output Gradient PT does not compute (none of Blender 3.4's; one a later
        version adds): reported by name; 0.5 stands in."""
        if node.type != 'NEW_GEOMETRY' or out.name in _GEOMETRY_OUTPUTS or out.name == "Position":
            return False
        self.warn(node, f"output {out.name} (0.5 stands in) of")
        return True

    def _push_input(self, d):
        """Appends input node d (not keyed to a Blender node); returns a float input reading it."""
        self.inputs.append(d)
        return {"value": 0.0, "node": len(self.inputs) - 1}

    def _falloff(self, node, out):
        """Light Falloff (Cycles' svm_node_light_falloff) as a float input: Strength, times the ray
        length L (Linear) or L^2 (Constant), times L^2 / (Smooth + L^2) for Smooth > 0; built from
        Light Path's Ray Length and Math nodes (evaluated per path, as the ray length is)."""
        smooth = node.inputs["Smooth"]
        if smooth.is_linked:
            self.warn(node, "linked Smooth (its default value is used) of")
        s = float(smooth.default_value)
        strength = self.value(node.inputs["Strength"])
        if out.name == "Quadratic" and s <= 0.0:
            return strength
        length = self._push_input({"kind": "LIGHT_PATH", "output": "Ray Length"})

        def math(op, a, b):
            return self._push_input({"kind": "MATH", "op": op, "value_a": a, "value_b": b})

        if out.name == "Linear":
            strength = math("MULTIPLY", strength, length)
        elif out.name == "Constant":
            strength = math("MULTIPLY", math("MULTIPLY", strength, length), length)
        if s > 0.0:
            squared = math("MULTIPLY", length, length)
            ratio = math("DIVIDE", squared, math("ADD", squared, {"value": s}))
            strength = math("MULTIPLY", strength, ratio)
        return strength

    def _curve_table(self, node, channels, combined=False):
        """Cycles' baked table of a curve mapping: RAMP_TABLE_SIZE entries over the curves'
        x range (at least [0, 1]); RGB Curves apply the combined curve (the 4th) first."""
        mapping = node.mapping
        mapping.initialize()
        curves = list(mapping.curves)
        xs = [p.location[0] for c in curves[:channels + (1 if combined else 0)] for p in c.points]
        lo, hi = min([0.0] + xs), max([1.0] + xs)
        table = []
        evaluate = mapping.evaluate
        for i in range(_RAMP_TABLE_SIZE):
            t = lo + i / (_RAMP_TABLE_SIZE - 1) * (hi - lo)
            if combined:
                t = evaluate(curves[3], t)
            row = [evaluate(curves[k], t) for k in range(channels)]
            table.extend(row + [0.0] * (4 - channels))
        return table, [lo, hi, 0.0, 1.0]

    def _input_node(self, node, out):
        """Index of a Mix / MixRGB / Math / Invert / Color Ramp node's output `out` in
        self.inputs (translated once), or None (with a warning) for a mode Gradient PT does not
        model."""
        per_output = node.type in {'VALTORGB', 'SEPRGB', 'SEPARATE_COLOR', 'TEX_CHECKER',
                                   'TEX_NOISE', 'TEX_COORD', 'SEPXYZ', 'TEX_VORONOI',
                                   'TEX_GRADIENT', 'TEX_WAVE', 'TEX_MUSGRAVE',
                                   'TEX_WHITE_NOISE', 'NEW_GEOMETRY', 'TEX_MAGIC',
                                   'VECT_MATH', 'TEX_BRICK', 'SEPHSV', 'LAYER_WEIGHT',
                                   'LIGHT_PATH'}
        key = (node.name, out.name if per_output else "")
        if key in self.input_index:
            return self.input_index[key]
        d = None
        if node.type == 'MIX_RGB' and node.blend_type in _BLENDS:
            d = {"kind": "MIX", "blend": node.blend_type, "clamp_result": bool(node.use_clamp),
                 "fac": self.value(node.inputs["Fac"]), "a": self.color(node.inputs["Color1"]),
                 "b": self.color(node.inputs["Color2"])}
        elif node.type == 'MIX' and (node.data_type == 'RGBA' and node.blend_type in _BLENDS or
                                     node.data_type == 'FLOAT'):
            # Blender 3.4's Mix node: inputs 0 Factor (float), 2 / 3 A / B (float), 6 / 7 A / B
            # (colour). A float mix is a plain interpolation, linear in the operands, so it is
            # done on colours and read as luminance by the float socket downstream.
            rgba = node.data_type == 'RGBA'
            a, b = (node.inputs[6], node.inputs[7]) if rgba else (node.inputs[2], node.inputs[3])
            d = {"kind": "MIX", "blend": node.blend_type if rgba else 'MIX',
                 "clamp_factor": bool(node.clamp_factor), "clamp_result": bool(node.clamp_result),
                 "fac": self.value(node.inputs[0]), "a": self.color(a), "b": self.color(b)}
        elif node.type == 'MATH' and node.operation in _MATH_OPS:
            d = {"kind": "MATH", "op": node.operation, "clamp_result": bool(node.use_clamp),
                 "value_a": self.value(node.inputs[0]), "value_b": self.value(node.inputs[1]),
                 "value_c": self.value(node.inputs[2])}
        elif node.type == 'TEX_BRICK':
            i = node.inputs
            d = {"kind": "BRICK", "a": self.color(i["Color1"]), "b": self.color(i["Color2"]),
                 "c": self.color(i["Mortar"]), "value_a": self.value(i["Scale"]),
                 "value_b": self.value(i["Mortar Size"]),
                 "value_c": self.value(i["Mortar Smooth"]), "value_d": self.value(i["Bias"]),
                 "value_e": self.value(i["Brick Width"]), "value_f": self.value(i["Row Height"]),
                 "brick": {"offset": float(node.offset),
                           "offset_frequency": int(node.offset_frequency),
                           "squash": float(node.squash),
                           "squash_frequency": int(node.squash_frequency)},
                 "vector": self._vector(i["Vector"], 'GENERATED'),
                 "fac_output": out.name == "Fac"}
        elif node.type == 'VECT_MATH':
            # Inputs: three vectors and the float Scale (IOR for Refract).
            d = {"kind": "VECTOR_MATH", "op": node.operation,
                 "a": self.color(node.inputs[0]), "b": self.color(node.inputs[1]),
                 "c": self.color(node.inputs[2]), "value_a": self.value(node.inputs[3]),
                 "fac_output": out.name == "Value"}
        elif node.type == 'INVERT':
            d = {"kind": "INVERT", "fac": self.value(node.inputs["Fac"]),
                 "a": self.color(node.inputs["Color"])}
        elif node.type == 'VALTORGB':
            # The table Cycles bakes from the ramp: RAMP_TABLE_SIZE entries of evaluate().
            ramp = node.color_ramp
            table = []
            for i in range(_RAMP_TABLE_SIZE):
                table.extend(ramp.evaluate(i / (_RAMP_TABLE_SIZE - 1)))
            d = {"kind": "RAMP", "fac": self.value(node.inputs["Fac"]), "ramp": table,
                 "ramp_interpolate": ramp.interpolation != 'CONSTANT',
                 "ramp_alpha": out.name == "Alpha"}
        elif node.type == 'SEPRGB' or node.type == 'SEPXYZ' or (
                node.type == 'SEPARATE_COLOR' and node.mode == 'RGB'):
            channel = [o.name for o in node.outputs].index(out.name)
            d = {"kind": "SEPARATE", "a": self.color(node.inputs[0]), "channel": channel}
        elif node.type == 'SEPHSV' or (node.type == 'SEPARATE_COLOR' and node.mode == 'HSV'):
            channel = [o.name for o in node.outputs].index(out.name)
            d = {"kind": "SEPARATE_HSV", "a": self.color(node.inputs[0]), "channel": channel}
        elif node.type == 'COMBHSV' or (node.type == 'COMBINE_COLOR' and node.mode == 'HSV'):
            d = {"kind": "COMBINE_HSV", "value_a": self.value(node.inputs[0]),
                 "value_b": self.value(node.inputs[1]), "value_c": self.value(node.inputs[2])}
        elif node.type == 'COMBRGB' or (node.type == 'COMBINE_COLOR' and node.mode == 'RGB'):
            d = {"kind": "COMBINE", "value_a": self.value(node.inputs[0]),
                 "value_b": self.value(node.inputs[1]), "value_c": self.value(node.inputs[2])}
        elif node.type == 'COMBXYZ':
            d = {"kind": "COMBINE_XYZ", "value_a": self.value(node.inputs[0]),
                 "value_b": self.value(node.inputs[1]), "value_c": self.value(node.inputs[2])}
        elif node.type == 'GAMMA':
            d = {"kind": "GAMMA", "a": self.color(node.inputs["Color"]),
                 "value_a": self.value(node.inputs["Gamma"])}
        elif node.type == 'HUE_SAT':
            d = {"kind": "HUE_SAT", "a": self.color(node.inputs["Color"]),
                 "fac": self.value(node.inputs["Fac"]), "value_a": self.value(node.inputs["Hue"]),
                 "value_b": self.value(node.inputs["Saturation"]),
                 "value_c": self.value(node.inputs["Value"])}
        elif node.type == 'MAP_RANGE' and node.data_type == 'FLOAT' and \
                node.interpolation_type == 'LINEAR':
            bounds = [node.inputs[k] for k in ("From Min", "From Max", "To Min", "To Max")]
            for socket in bounds:
                if socket.is_linked:
                    self.warn(node, f"linked {socket.name} (its default value is used) of")
            d = {"kind": "MAP_RANGE", "value_a": self.value(node.inputs["Value"]),
                 "bounds": [float(s.default_value) for s in bounds],
                 "clamp_result": bool(node.clamp)}
        elif node.type == 'CLAMP':
            d = {"kind": "CLAMP", "value_a": self.value(node.inputs["Value"]),
                 "value_b": self.value(node.inputs["Min"]),
                 "value_c": self.value(node.inputs["Max"]),
                 "clamp_range": node.clamp_type == 'RANGE'}
        elif out.name == "Color" and (node.type == 'VERTEX_COLOR' or (
                node.type == 'ATTRIBUTE' and node.attribute_type == 'GEOMETRY')):
            # Color Attribute node, or the Attribute node naming a colour attribute.
            name = node.layer_name if node.type == 'VERTEX_COLOR' else node.attribute_name
            if self.color_attribute is not None and self.color_attribute != name:
                self.warn(node, "second colour attribute (the first one is used) in")
            if self.color_attribute is None:
                self.color_attribute = name
            d = {"kind": "ATTRIBUTE"}
        elif node.type == 'TEX_CHECKER':
            d = {"kind": "CHECKER", "a": self.color(node.inputs["Color1"]),
                 "b": self.color(node.inputs["Color2"]),
                 "value_a": self.value(node.inputs["Scale"]),
                 "vector": self._vector(node.inputs["Vector"], 'GENERATED'),
                 "fac_output": out.name == "Fac"}
        elif node.type == 'TEX_NOISE':
            d = {"kind": "NOISE", "dimensions": int(node.noise_dimensions[0]),
                 "value_d": self.value(node.inputs["W"]),
                 "value_a": self.value(node.inputs["Scale"]),
                 "value_b": self.value(node.inputs["Detail"]),
                 "value_c": self.value(node.inputs["Roughness"]),
                 "fac": self.value(node.inputs["Distortion"]),
                 "vector": self._vector(node.inputs["Vector"], 'GENERATED'),
                 "fac_output": out.name == "Fac"}
        elif node.type == 'TEX_VORONOI' and node.voronoi_dimensions == '3D' and \
                node.feature in _VORONOI_FEATURES and \
                out.name in {"Distance", "Color", "Position"}:
            # Distance to Edge has a Distance only (Euclidean, whatever the metric).
            d = {"kind": "VORONOI", "feature": node.feature,
                 "value_a": self.value(node.inputs["Scale"]),
                 "value_b": self.value(node.inputs["Randomness"]),
                 "value_c": self.value(node.inputs["Exponent"]),
                 "value_d": self.value(node.inputs["Smoothness"]), "metric": node.distance,
                 "vector": self._vector(node.inputs["Vector"], 'GENERATED'),
                 "fac_output": out.name == "Distance", "position_output": out.name == "Position"}
        elif node.type == 'TEX_WAVE':
            bands = node.wave_type == 'BANDS'
            d = {"kind": "WAVE", "wave_type": node.wave_type,
                 "direction": node.bands_direction if bands else node.rings_direction,
                 "profile": node.wave_profile,
                 "value_a": self.value(node.inputs["Scale"]),
                 "value_b": self.value(node.inputs["Distortion"]),
                 "value_c": self.value(node.inputs["Detail"]),
                 "value_d": self.value(node.inputs["Detail Scale"]),
                 "value_e": self.value(node.inputs["Detail Roughness"]),
                 "value_f": self.value(node.inputs["Phase Offset"]),
                 "vector": self._vector(node.inputs["Vector"], 'GENERATED'),
                 "fac_output": out.name == "Fac"}
        elif node.type == 'TEX_MUSGRAVE' and node.musgrave_dimensions == '3D':
            d = {"kind": "MUSGRAVE", "musgrave_type": node.musgrave_type,
                 "value_a": self.value(node.inputs["Scale"]),
                 "value_b": self.value(node.inputs["Detail"]),
                 "value_c": self.value(node.inputs["Dimension"]),
                 "value_d": self.value(node.inputs["Lacunarity"]),
                 "value_e": self.value(node.inputs["Offset"]),
                 "value_f": self.value(node.inputs["Gain"]),
                 "vector": self._vector(node.inputs["Vector"], 'GENERATED'),
                 "fac_output": True}
        elif node.type == 'TEX_WHITE_NOISE' and node.noise_dimensions == '3D':
            socket = node.inputs["Vector"]
            # Unlinked, Cycles 3.4 reads the socket's value (0, 0, 0): a constant vector.
            vector = self._vector(socket) if self._source(socket) is not None else \
                {"coordinates": 'UV', "mapping": [0.0] * 12}
            d = {"kind": "WHITE_NOISE", "vector": vector, "fac_output": out.name == "Value"}
        elif node.type == 'TEX_MAGIC':
            d = {"kind": "MAGIC", "depth": int(node.turbulence_depth),
                 "value_a": self.value(node.inputs["Scale"]),
                 "value_b": self.value(node.inputs["Distortion"]),
                 "vector": self._vector(node.inputs["Vector"], 'GENERATED'),
                 "fac_output": out.name == "Fac"}
        elif node.type == 'TEX_GRADIENT':
            d = {"kind": "GRADIENT", "gradient": node.gradient_type,
                 "vector": self._vector(node.inputs["Vector"], 'GENERATED'),
                 "fac_output": out.name == "Fac"}
        elif (node.type == 'TEX_COORD' and out.name in {"UV", "Generated", "Object"}) or \
                (node.type == 'NEW_GEOMETRY' and out.name == "Position") or \
                node.type == 'UVMAP' or \
                (node.type == 'MAPPING' and node.vector_type in _MAPPING_TYPES):
            # A coordinate used as a colour or value (e.g. through Separate XYZ).
            d = {"kind": "COORDINATES", "vector": self._vector_of(out)}
        elif node.type in {'CURVE_RGB', 'CURVE_VEC', 'CURVE_FLOAT'}:
            kind = {'CURVE_RGB': "RGB_CURVES", 'CURVE_VEC': "VECTOR_CURVES",
                    'CURVE_FLOAT': "FLOAT_CURVE"}[node.type]
            table, bounds = self._curve_table(node, 1 if kind == "FLOAT_CURVE" else 3,
                                              combined=kind == "RGB_CURVES")
            d = {"kind": kind, "fac": self.value(node.inputs[0]), "ramp": table,
                 "bounds": bounds}
            if kind == "FLOAT_CURVE":
                d["value_a"] = self.value(node.inputs["Value"])
            else:
                d["a"] = self.color(node.inputs[1])
        elif node.type == 'LIGHT_PATH' and out.name in _LIGHT_PATH_OUTPUTS:
            d = {"kind": "LIGHT_PATH", "output": out.name}
        elif node.type == 'NEW_GEOMETRY' and out.name in _GEOMETRY_OUTPUTS:
            d = {"kind": "GEOMETRY", "output": out.name}
            if out.name in _MESH_ATTRIBUTE_OUTPUTS:
                self.mesh_attributes.add(_MESH_ATTRIBUTE_OUTPUTS[out.name])
        elif node.type == 'FRESNEL':
            d = {"kind": "FRESNEL", "value_a": self.value(node.inputs["IOR"]),
                 "normal_linked": self._view_normal(node.inputs["Normal"])}
        elif node.type == 'LAYER_WEIGHT':
            d = {"kind": "LAYER_WEIGHT", "value_a": self.value(node.inputs["Blend"]),
                 "channel": 0 if out.name == "Fresnel" else 1,
                 "normal_linked": self._view_normal(node.inputs["Normal"])}
        elif node.type == 'VECT_TRANSFORM':
            d = {"kind": "VECTOR_TRANSFORM", "vector_type": node.vector_type,
                 "from": node.convert_from, "to": node.convert_to,
                 "a": self.color(node.inputs["Vector"])}
        elif node.type == 'WIREFRAME':
            # Use Pixel Size: the camera's pixel at the hit stands in for Cycles' ray
            # differentials, which it equals only where the camera sees the surface directly.
            if node.use_pixel_size:
                self.warn(node, "Use Pixel Size seen other than by the camera (reflections, "
                          "refractions, indirect light: wires as wide as the camera's pixel at "
                          "the hit, not Cycles' ray differentials) of")
            d = {"kind": "WIREFRAME", "value_a": self.value(node.inputs["Size"]),
                 "pixel_size": bool(node.use_pixel_size)}
        elif node.type == 'BLACKBODY':
            d = {"kind": "BLACKBODY", "value_a": self.value(node.inputs["Temperature"])}
        elif node.type == 'RGBTOBW':
            d = {"kind": "RGB_TO_BW", "a": self.color(node.inputs["Color"])}
        elif node.type == 'BRIGHTCONTRAST':
            d = {"kind": "BRIGHT_CONTRAST", "a": self.color(node.inputs["Color"]),
                 "value_a": self.value(node.inputs["Bright"]),
                 "value_b": self.value(node.inputs["Contrast"])}
        if d is None:
            mode = (getattr(node, "blend_type", None) or getattr(node, "operation", None) or
                    getattr(node, "mode", None) or getattr(node, "interpolation_type", None) or
                    getattr(node, "noise_dimensions", None) or
                    getattr(node, "musgrave_dimensions", None) or
                    (f"{node.voronoi_dimensions} {node.feature}" if node.type == 'TEX_VORONOI'
                     else None))
            self.warn(node, f"mode {mode} of the input node" if mode else "input node")
            return None
        self.inputs.append(d)
        self.input_index[key] = len(self.inputs) - 1
        return self.input_index[key]

    @staticmethod
    def _default_rgb(socket):
        v = socket.default_value
        try:
            return tuple(v)[:3]
        except TypeError:
            return (float(v),) * 3

    def _texture(self, node, d):
        image = node.image
        index = self.images.get(image) if image is not None else -1
        if index < 0:
            self.warn(node, "image texture without pixels:")
            d["value"] = MAGENTA if isinstance(d["value"], tuple) else d["value"]
            return
        if node.projection != 'FLAT':
            self.warn(node, f"projection {node.projection} (rendered as flat) of")
        d["image"] = index
        d["interpolation"] = 'Closest' if node.interpolation == 'Closest' else 'Linear'
        d["extension"] = node.extension if node.extension in {'REPEAT', 'EXTEND', 'CLIP'} \
            else 'REPEAT'
        d.update(self._vector(node.inputs["Vector"]))

    def _vector(self, socket, default='UV'):
        """{coordinates, mapping[, vector_node]} of a texture's Vector input: a Texture
        Coordinate output (UV, Generated, Object), a UV Map node, the Geometry node's Position,
        any input node's result (coordinates 'NODE', e.g. a Vector Math node or coordinates
        mixed with a Noise Texture's colour; vector_node its index), or a Mapping node (Point /
        Texture) over one of them; unlinked, the texture's own default (UV for Image Texture,
        Generated for procedural textures). mapping is a row-major 3x4 transform of the
        coordinates."""
        out = self._source(socket)
        if out is None:
            return {"coordinates": default, "mapping": IDENTITY12}
        return self._vector_of(out, default)

    def _vector_of(self, out, default='UV'):
        """_vector() of the output socket `out` (a Texture Coordinate, UV Map or Mapping
        output)."""
        plain = {"coordinates": default, "mapping": IDENTITY12}
        node = out.node
        if node.type == 'UVMAP':
            if node.uv_map:
                self.warn(node, "UV map other than the active render UV map in")
            return {"coordinates": 'UV', "mapping": IDENTITY12}
        if node.type == 'TEX_COORD' and out.name in {"UV", "Generated", "Object"}:
            if out.name == "Object" and node.object is not None:
                self.warn(node, "Object output relative to another object of")
            return {"coordinates": out.name.upper(), "mapping": IDENTITY12}
        if node.type == 'NEW_GEOMETRY' and out.name == "Position":
            return {"coordinates": 'POSITION', "mapping": IDENTITY12}
        if node.type == 'MAPPING' and node.vector_type in _MAPPING_TYPES:
            inner = self._vector(node.inputs["Vector"], default)
            # Vector type: a direction, no translation (the Location socket is hidden).
            loc = node.inputs["Location"].default_value if node.vector_type != 'VECTOR' \
                else (0.0, 0.0, 0.0)
            rot = node.inputs["Rotation"].default_value
            scale = node.inputs["Scale"].default_value
            for name in ("Location", "Rotation", "Scale"):
                if node.inputs[name].is_linked:
                    self.warn(node, f"linked {name} of")
            m = (Matrix.Translation(loc) @ Euler(rot, 'XYZ').to_matrix().to_4x4()
                 @ Matrix.Diagonal((scale[0], scale[1], scale[2], 1.0)))
            if node.vector_type == 'TEXTURE':
                m = m.inverted_safe()
            im = inner["mapping"]
            inner_m = Matrix([im[0:4], im[4:8], im[8:12], [0, 0, 0, 1]])
            return dict(inner, mapping=_matrix12(m @ inner_m))
        if node.type in _INPUT_NODES and node.type not in {'TEX_COORD', 'MAPPING'}:
            index = self._input_node(node, out)  # warns itself when it cannot
            if index is not None:
                return {"coordinates": 'NODE', "vector_node": index, "mapping": IDENTITY12}
            return plain
        self.warn(node, f"output {out.name} of the texture coordinate node"
                  if node.type == 'TEX_COORD' else "texture coordinate node")
        return plain


def _output_node(tree):
    outputs = [n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL' and not n.mute]
    for target in ('CYCLES', 'ALL'):
        for n in outputs:
            if n.is_active_output and n.target == target:
                return n
    for n in outputs:
        if n.target in {'CYCLES', 'ALL'}:
            return n
    return None


def translate_material(material, images, warn):
    """MaterialDesc dict for a Blender material (root -1 = Blender's default grey), with the
    material's Pass Index (IndexMA pass)."""
    d = _translate_surface(material, images, warn)
    if material is not None:
        d["pass_index"] = material.pass_index
    return d


def _translate_surface(material, images, warn):
    if material is None:
        return {"name": "", "nodes": [], "root": -1}
    if not material.use_nodes or material.node_tree is None:
        c = tuple(material.diffuse_color)[:3]
        return {"name": material.name,
                "nodes": [{"kind": "PRINCIPLED", "color": {"value": c},
                           "metallic": {"value": material.metallic},
                           "specular": {"value": material.specular_intensity},
                           "roughness": {"value": material.roughness}}],
                "root": 0}
    t = _Translator(material, images, warn)
    try:
        return _translate_tree(material, t, warn)
    except Exception as e:  # a node this code does not expect must not stop the render
        where = f"node '{t.current.name}' ({t.current.bl_idname})" if t.current else "its tree"
        warn(f"material '{material.name}': translating {where} failed ({type(e).__name__}: {e}); "
             f"rendered magenta")
        return magenta_material(material.name)


def magenta_material(name):
    """The stand-in for a material that cannot be translated."""
    return {"name": name, "nodes": [{"kind": "DIFFUSE", "color": {"value": MAGENTA}}], "root": 0}


def _translate_tree(material, t, warn):
    out = _output_node(material.node_tree)
    if out is None:
        warn(f"material '{material.name}' has no Material Output node; rendered black")
        return {"name": material.name, "nodes": [], "root": -1}
    if out.inputs["Volume"].is_linked:
        warn(f"material '{material.name}': volumes are not supported by Gradient PT (ignored)")
    t.displacement(groups.wrap(out.inputs["Displacement"]))
    root = t.shader(groups.wrap(out.inputs["Surface"]))
    if root < 0:
        # Nothing connected: Cycles renders such a surface black. A black diffuse does the same.
        root = t._add({"kind": "DIFFUSE", "color": {"value": (0.0, 0.0, 0.0)}})
    d = {"name": material.name, "nodes": t.nodes, "root": root, "inputs": t.inputs}
    if t.normal_map is not None:
        d["normal_map"] = t.normal_map
    bumps = ([t.displacement_bump] if t.displacement_bump else []) + t.bumps
    if bumps:
        d["bumps"] = bumps
    if t.color_attribute is not None:
        d["color_attribute"] = t.color_attribute
    if t.uv_tangents:
        d["uv_tangents"] = True
    if t.mesh_attributes:
        d["mesh_attributes"] = sorted(t.mesh_attributes)
    return d


class MaterialCache:
    def __init__(self, builder, images, warn):
        groups.reset()
        self.builder = builder
        self.images = images
        self.warn = warn
        self.index = {}
        # Scene material indices that read the UV map's tangents (a normal map, a Tangent node).
        self.normal_mapped = set()
        self.color_attributes = {}  # scene material index -> colour attribute name it reads
        self.mesh_attributes = {}  # scene material index -> Geometry node attributes it reads

    def get(self, material):
        """Scene material index for a Blender material, -1 for an empty slot."""
        if material is None:
            return -1
        key = material.original.as_pointer()
        if key not in self.index:
            desc = translate_material(material, self.images, self.warn)
            try:
                self.index[key] = self.builder.add_material(desc)
            except ValueError as e:  # rejected by the core's checks: reported, not fatal
                self.warn(f"material '{material.name}': {e}; rendered magenta")
                desc = dict(magenta_material(material.name), pass_index=material.pass_index)
                self.index[key] = self.builder.add_material(desc)
            if "normal_map" in desc or desc.get("uv_tangents"):
                self.normal_mapped.add(self.index[key])
            if "color_attribute" in desc:
                self.color_attributes[self.index[key]] = desc["color_attribute"]
            if "mesh_attributes" in desc:
                self.mesh_attributes[self.index[key]] = frozenset(desc["mesh_attributes"])
        return self.index[key]

    def has_normal_map(self, index):
        return index in self.normal_mapped

    def geometry_attributes(self, index):
        """The Geometry node attributes material `index` reads ('pointiness',
        'random_per_island'), a frozenset."""
        return self.mesh_attributes.get(index, frozenset())

    def color_attribute(self, index):
        """Name of the colour attribute material `index` reads ("" for the render one), or
        None."""
        return self.color_attributes.get(index)

