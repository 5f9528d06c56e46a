# Blender lights -> Scene::Light dicts. Units are Blender's (W, W/m^2 for sun); the core applies
# Cycles' conversions (point/spot intensity P / 4 pi, area radiance P / (4 A): docs/lights.md).
import numpy as np


def _matrix12(m):
    return np.ascontiguousarray(np.array(m, dtype=np.float32)[:3, :4]).ravel()


def light_dict(obj, matrix, warn):
    light = obj.data
    if light.use_nodes and light.node_tree is not None:
        linked = [n for n in light.node_tree.nodes
                  if n.type not in {'OUTPUT_LIGHT', 'EMISSION'} and not n.mute]
        if linked:
            warn(f"light '{light.name}': light node trees are not supported by Gradient PT "
                 f"(using colour and power)")
    d = {
        "type": light.type,
        "matrix": _matrix12(matrix),
        "color": tuple(light.color),
        "power": float(light.energy),
        # Object > Visibility > Camera: Cycles shows the lamp itself to camera rays only then.
        "camera_visible": bool(obj.visible_camera),
        # Cycles' Light > Cast Shadow (its add-on's property group; absent without Cycles).
        "cast_shadow": bool(getattr(getattr(light, "cycles", None), "cast_shadow", True)),
        # Cycles' Light > Shadow Caustics (read for shadow caustics; off without Cycles).
        "caustics_light": bool(getattr(getattr(light, "cycles", None), "is_caustics_light",
                                       False)),
    }
    if light.type in {'POINT', 'SPOT'}:
        d["radius"] = float(light.shadow_soft_size)
    if light.type == 'SPOT':
        d["spot_size"] = float(light.spot_size)
        d["spot_blend"] = float(light.spot_blend)
    elif light.type == 'SUN':
        d["sun_angle"] = float(light.angle)
    elif light.type == 'AREA':
        d["shape"] = light.shape
        d["size_x"] = float(light.size)
        d["size_y"] = float(light.size_y if light.shape in {'RECTANGLE', 'ELLIPSE'} else light.size)
    return d


def light_problem(obj):
    """Why light object `obj` cannot light anything (a message), or None."""
    light = obj.data
    if light.energy == 0.0 or max(light.color) <= 0.0:
        return f"light '{obj.name}' has zero strength: it adds no light"
    if light.type == 'AREA':
        size_y = light.size_y if light.shape in {'RECTANGLE', 'ELLIPSE'} else light.size
        if light.size <= 0.0 or size_y <= 0.0:
            return f"light '{obj.name}' has zero area: it emits nothing (skipped)"
    return None
