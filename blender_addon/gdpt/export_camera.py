# The scene camera -> Scene::Camera dict (Blender conventions, as Cycles' blender/camera.cpp).
import numpy as np
from mathutils import Vector


def render_resolution(render):
    """Pixel size of the frame after the resolution percentage, in Blender's integer arithmetic
    (render_init_from_main: size * xsch / 100)."""
    pct = render.resolution_percentage
    return (max(1, render.resolution_x * pct // 100), max(1, render.resolution_y * pct // 100))


def render_region(render):
    """The render region (Render Region / border) as (x, y, width, height) in pixels of the frame,
    y from the bottom, or None when the whole frame renders. Blender computes it in float32 and
    truncates (render_init_from_main), and gives the engine a result of exactly that size."""
    if not render.use_border:
        return None
    width, height = render_resolution(render)
    f = np.float32
    x0 = int(f(render.border_min_x) * f(width))
    x1 = int(f(render.border_max_x) * f(width))
    y0 = int(f(render.border_min_y) * f(height))
    y1 = int(f(render.border_max_y) * f(height))
    if (x0, y0, x1, y1) == (0, 0, width, height):
        return None
    return x0, y0, x1 - x0, y1 - y0


def rigid_matrix12(m):
    # The camera's scale must not scale the image plane or the lens: keep rotation + position.
    loc, rot, _scale = m.decompose()
    r = rot.to_matrix()
    rows = [[r[i][0], r[i][1], r[i][2], loc[i]] for i in range(3)]
    return np.array(rows, dtype=np.float32).ravel()


def _focus_distance(cam_obj, cam):
    dof = cam.dof
    if dof.focus_object is None:
        return float(dof.focus_distance)
    # Distance along the view axis to the focus object's origin (as Cycles).
    m = cam_obj.matrix_world
    view = (m.to_3x3() @ Vector((0.0, 0.0, 1.0))).normalized()
    delta = m.translation - dof.focus_object.matrix_world.translation
    return abs(view.dot(delta))


def camera_dict(scene, cam_obj, warn):
    cam = cam_obj.data
    render = scene.render
    width, height = render_resolution(render)
    if cam.type == 'PANO':
        warn("panoramic cameras are not supported by Gradient PT; rendering as perspective")
    d = {
        "projection": 'ORTHO' if cam.type == 'ORTHO' else 'PERSP',
        "sensor_fit": cam.sensor_fit,
        "matrix": rigid_matrix12(cam_obj.matrix_world),
        "focal_length_mm": float(cam.lens),
        "sensor_width_mm": float(cam.sensor_width),
        "sensor_height_mm": float(cam.sensor_height),
        "shift_x": float(cam.shift_x),
        "shift_y": float(cam.shift_y),
        "ortho_scale": float(cam.ortho_scale),
        "clip_start": float(cam.clip_start),
        "clip_end": float(cam.clip_end),
        "width": width,
        "height": height,
        "pixel_aspect": float(render.pixel_aspect_x / render.pixel_aspect_y),
        "aperture_radius": 0.0,
        "focus_distance": _focus_distance(cam_obj, cam),
    }
    region = render_region(render)
    if region:
        d["region_x"], d["region_y"], d["region_width"], d["region_height"] = region
    if cam.dof.use_dof:
        fstop = max(float(cam.dof.aperture_fstop), 1e-5)
        if cam.type == 'ORTHO':
            d["aperture_radius"] = 1.0 / (2.0 * fstop)
        else:
            d["aperture_radius"] = float(cam.lens) * 1e-3 / (2.0 * fstop)
        if cam.dof.aperture_blades >= 3:
            warn("polygonal aperture blades are not supported by Gradient PT; using a disc")
    return d
