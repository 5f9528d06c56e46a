# Loads a material script written by the Node-To-Python add-on for Blender 4.x into Blender 3.4.
# The scripts address sockets by index and Blender 4 reordered some nodes' inputs (Principled BSDF,
# Noise, Voronoi) and replaced group.inputs/outputs with group.interface, so each script is
# rewritten: sockets are found by their Blender 4 name, and whatever 3.4 cannot hold (a socket, a
# property or a link) is skipped and listed, so the material report says what was lost on loading.
# Both engines render the same loaded material, so what was skipped does not bias the comparison.
import re

# Blender 4.x input order -> the Blender 3.4 input name (None: no 3.4 counterpart).
INPUTS_4X = {
    "ShaderNodeBsdfPrincipled": [
        "Base Color", "Metallic", "Roughness", "IOR", "Alpha", "Normal", None, "Subsurface",
        "Subsurface Radius", None, "Subsurface IOR", "Subsurface Anisotropy", "Specular", None,
        "Anisotropic", "Anisotropic Rotation", "Tangent", "Transmission", "Clearcoat",
        "Clearcoat Roughness", None, None, "Clearcoat Normal", "Sheen", None, None, "Emission",
        "Emission Strength"],
    "ShaderNodeTexNoise": ["Vector", "W", "Scale", "Detail", "Roughness", None, None, None,
                           "Distortion"],
    "ShaderNodeTexVoronoi": ["Vector", "W", "Scale", None, None, None, "Smoothness", "Exponent",
                             "Randomness"],
}

# Blender 4.x socket names -> Blender 3.4 names, for scripts that look sockets up by name.
RENAMED_4X = {
    "Subsurface Weight": "Subsurface", "Specular IOR Level": "Specular",
    "Transmission Weight": "Transmission", "Coat Weight": "Clearcoat",
    "Coat Roughness": "Clearcoat Roughness", "Coat Normal": "Clearcoat Normal",
    "Sheen Weight": "Sheen", "Emission Color": "Emission"}


class Skipped:
    """Stands for a socket Blender 3.4 does not have; assignments and links to it are dropped."""

    def __init__(self, label):
        self.label = label


def socket(log, node, kind, index):
    sockets = node.inputs if kind == "in" else node.outputs
    table = INPUTS_4X.get(node.bl_idname) if kind == "in" else None
    if table is not None:
        name = table[index] if index < len(table) else None
        if name is None or name not in sockets:
            log.append(f"{node.name}: input {index} (Blender 4) has no Blender 3.4 socket")
            return Skipped(f"{node.name}.inputs[{index}]")
        return sockets[name]
    if index >= len(sockets):
        log.append(f"{node.name}: {kind}put {index} missing in Blender 3.4")
        return Skipped(f"{node.name}.{kind}puts[{index}]")
    return sockets[index]


def named_socket(log, node, kind, name):
    sockets = node.inputs if kind == "in" else node.outputs
    name = RENAMED_4X.get(name, name)
    if name not in sockets:
        log.append(f"{node.name}: {kind}put '{name}' missing in Blender 3.4")
        return Skipped(f"{node.name}.{kind}puts['{name}']")
    return sockets[name]


def assign(log, target, attr, value):
    if isinstance(target, Skipped):
        return
    try:
        setattr(target, attr, value)
    except (AttributeError, TypeError, ValueError) as e:
        log.append(f"{getattr(target, 'name', target)}.{attr}: not set ({type(e).__name__})")


def link(log, tree, a, b):
    if isinstance(a, Skipped) or isinstance(b, Skipped):
        log.append(f"link {getattr(a, 'label', '')}{getattr(b, 'label', '')} dropped")
        return None
    return tree.links.new(a, b)


def new_socket(log, group, name, in_out, socket_type, **_):
    sockets = group.inputs if in_out == 'INPUT' else group.outputs
    return sockets.new(socket_type, name)


_SOCKET = re.compile(r"\b(\w+)\.(inputs|outputs)\[(\d+)\]")
_ASSIGN = re.compile(r"^(\s*)([\w.\[\]\(\), ']+?)\.(\w+)\s*=\s*(.+)$")
_NAMED = re.compile(r"\b(\w+)\.(inputs|outputs)\[(\"[^\"]+\")\]")
_LINK = re.compile(r"\b(\w+)\.links\.new\(")
_IFACE = re.compile(r"\b(\w+)\.interface\.new_socket\(")


def rewrite(source):
    """The script with socket look-ups, assignments, links and group sockets routed through the
    helpers above (bound to a log by `load`)."""
    out = []
    for line in source.splitlines():
        line = _SOCKET.sub(lambda m: f"_socket({m[1]}, '{'in' if m[2] == 'inputs' else 'out'}', "
                           f"{m[3]})", line)
        line = _NAMED.sub(lambda m: f"_named({m[1]}, '{'in' if m[2] == 'inputs' else 'out'}', "
                          f"{m[3]})", line)
        line = _LINK.sub(lambda m: f"_link({m[1]}, ", line)
        line = _IFACE.sub(lambda m: f"_new_socket({m[1]}, ", line)
        m = _ASSIGN.match(line)
        if m and "==" not in line and not m[2].strip().startswith(("def ", "for ", "if ")):
            line = f"{m[1]}_assign({m[2]}, '{m[3]}', {m[4]})"
        out.append(line)
    return "\n".join(out) + "\n"


def load(bpy, source, label):
    """Runs the rewritten script; returns (materials it created, skipped settings)."""
    log = []
    before = set(bpy.data.materials)
    env = {
        "__name__": "material_script", "bpy": bpy,
        "_socket": lambda n, k, i: socket(log, n, k, i),
        "_assign": lambda t, a, v: assign(log, t, a, v),
        "_named": lambda n, k, name: named_socket(log, n, k, name),
        "_link": lambda tree, a, b: link(log, tree, a, b),
        "_new_socket": lambda g, *a, **k: new_socket(log, g, *a, **k),
    }
    exec(compile(rewrite(source), label, "exec"), env)
    return [m for m in bpy.data.materials if m not in before], log
