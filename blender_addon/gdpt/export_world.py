# The world -> Scene::World dict: a constant colour, or an equirectangular Environment Texture
# (optionally rotated by a Mapping node), times the Background strength; optionally a second
# such Background that camera rays see (Light Path's Is Camera Ray).
import numpy as np
from mathutils import Euler

from . import export_node_groups as groups

IDENTITY12 = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]


def _source(socket):
    """The output feeding `socket` in the group-flattened tree (export_node_groups), through
    reroutes and muted nodes; None if unlinked."""
    return groups.source(socket)


BLACK = {"color": (0.0, 0.0, 0.0), "strength": 0.0}


def world_dict(world, images, warn):
    """The world's Background (colour or environment texture, strength); with "camera": the
    Background camera rays see instead, when the Surface is a Mix Shader whose factor is Light
    Path's Is Camera Ray (the lighting one on its first shader input, the camera's on the
    second)."""
    if world is None:
        return dict(BLACK)
    groups.reset()
    if not world.use_nodes or world.node_tree is None:
        return {"color": tuple(world.color), "strength": 1.0}
    outputs = [n for n in world.node_tree.nodes
               if n.type == 'OUTPUT_WORLD' and n.is_active_output and not n.mute]
    if not outputs:
        return dict(BLACK)
    out = _source(outputs[0].inputs["Surface"])
    if out is None:
        return dict(BLACK)
    node = out.node
    if node.type == 'MIX_SHADER':
        fac = _source(node.inputs[0])
        if fac is not None and fac.node.type == 'LIGHT_PATH' and fac.name == "Is Camera Ray":
            d = _background_of(world, node.inputs[1], images, warn)
            d["camera"] = _background_of(world, node.inputs[2], images, warn)
            return d
        warn(f"world '{world.name}': a Mix Shader is supported with Light Path's Is Camera Ray "
             f"as its factor only; using its first shader")
        return _background_of(world, node.inputs[1], images, warn)
    if node.type != 'BACKGROUND':
        warn(f"world '{world.name}': node '{node.name}' ({node.bl_idname}) is not "
             f"supported by Gradient PT; using the world colour")
        return {"color": tuple(world.color), "strength": 1.0}
    return _background(world, node, images, warn)


def _background_of(world, socket, images, warn):
    """_background() of the Background node feeding a shader socket (none: black)."""
    out = _source(socket)
    if out is None:
        return dict(BLACK)
    if out.node.type != 'BACKGROUND':
        warn(f"world '{world.name}': node '{out.node.name}' ({out.node.bl_idname}) is not "
             f"supported by Gradient PT; using black")
        return dict(BLACK)
    return _background(world, out.node, images, warn)


def _background(world, background, images, warn):
    d = {
        "color": tuple(background.inputs["Color"].default_value)[:3],
        "strength": float(background.inputs["Strength"].default_value),
        "rotation": np.array(IDENTITY12, dtype=np.float32),
    }
    if background.inputs["Strength"].is_linked:
        warn(f"world '{world.name}': a linked Background strength is not supported; using "
             f"its value")
    color = _source(background.inputs["Color"])
    if color is None:
        return d
    node = color.node
    if node.type == 'RGB':
        d["color"] = tuple(color.default_value)[:3]
    elif node.type == 'TEX_ENVIRONMENT':
        if node.projection != 'EQUIRECTANGULAR':
            warn(f"world '{world.name}': {node.projection} environment projection is not "
                 f"supported by Gradient PT; using equirectangular")
        index = images.get(node.image)
        if index < 0:
            d["color"] = (1.0, 0.0, 1.0)
        else:
            d["image"] = index
            d["color"] = (1.0, 1.0, 1.0)
            d["rotation"] = _rotation(world, node, warn)
    else:
        warn(f"world '{world.name}': node '{node.name}' ({node.bl_idname}) is not supported by "
             f"Gradient PT; using the Background colour")
    return d


def _rotation(world, env_node, warn):
    vec = _source(env_node.inputs["Vector"])
    if vec is None:
        return np.array(IDENTITY12, dtype=np.float32)
    node = vec.node
    if node.type == 'MAPPING' and node.vector_type in {'POINT', 'VECTOR'}:
        r = Euler(node.inputs["Rotation"].default_value, 'XYZ').to_matrix()
        rows = [[r[i][0], r[i][1], r[i][2], 0.0] for i in range(3)]
        return np.array(rows, dtype=np.float32).ravel()
    if node.type != 'TEX_COORD':
        warn(f"world '{world.name}': environment vector from '{node.name}' is not supported; "
             f"using the view direction")
    return np.array(IDENTITY12, dtype=np.float32)
