# The 3D viewport's view as a camera dict (export_camera.camera_dict's layout) and the rectangle
# of the region it is drawn into. Camera view: the scene camera, at the size its frame has on
# screen, drawn into that frame. Free view: a camera with the region's view and projection
# matrices, as many pixels as the region. The Render Region (camera view) and the viewport's
# Render Border (free view) become the camera's region: only its pixels render and draw.
from bpy_extras.view3d_utils import location_3d_to_region_2d

from . import export_camera

# Cycles' free-view sensor: the projection matrix fixes the field of view, any sensor does.
_SENSOR_MM = 36.0
# A camera frame zoomed far past the region renders at most this many times the region's size.
_MAX_FRAME_SCALE = 2.0


def _camera_frame(scene, camera_object, region, rv3d):
    """(x, y, width, height) of the camera's frame in region pixels, or None if off-screen."""
    corners = camera_object.data.view_frame(scene=scene)
    points = [location_3d_to_region_2d(region, rv3d, camera_object.matrix_world @ c)
              for c in corners]
    if any(p is None for p in points):
        return None
    xs = [p.x for p in points]
    ys = [p.y for p in points]
    return min(xs), min(ys), max(xs) - min(xs), max(ys) - min(ys)


def _camera_view(scene, camera_object, region, rv3d, warn):
    frame = _camera_frame(scene, camera_object, region, rv3d)
    if frame is None or frame[2] < 1 or frame[3] < 1:
        return None, None
    x, y, w, h = frame
    scale = min(1.0, _MAX_FRAME_SCALE * max(region.width, region.height) / max(w, h))
    d = export_camera.camera_dict(scene, camera_object, warn)
    for key in ("region_x", "region_y", "region_width", "region_height"):
        d.pop(key, None)
    d["width"] = max(1, round(w * scale))
    d["height"] = max(1, round(h * scale))
    if not scene.render.use_border:
        return d, (x, y, w, h)
    # The Render Region, in pixels of this frame.
    r = scene.render
    return _border(d, (x, y, w, h), r.border_min_x, r.border_min_y, r.border_max_x,
                   r.border_max_y)


def _border(d, rect, min_x, min_y, max_x, max_y):
    """Restricts camera dict `d` to a border given as fractions of its image, and `rect` (the
    image's place on screen) to the border's. No border when it is empty or the whole image."""
    width, height = d["width"], d["height"]
    x0, x1 = int(min_x * width), int(max_x * width)
    y0, y1 = int(min_y * height), int(max_y * height)
    if x1 <= x0 or y1 <= y0 or (x0, y0, x1, y1) == (0, 0, width, height):
        return d, rect
    d.update(region_x=x0, region_y=y0, region_width=x1 - x0, region_height=y1 - y0)
    sx, sy = rect[2] / width, rect[3] / height
    return d, (rect[0] + x0 * sx, rect[1] + y0 * sy, (x1 - x0) * sx, (y1 - y0) * sy)


def _free_view(space, region, rv3d):
    to_world = rv3d.view_matrix.inverted()
    p = rv3d.window_matrix
    d = {"sensor_fit": 'HORIZONTAL', "sensor_width_mm": _SENSOR_MM, "sensor_height_mm": _SENSOR_MM,
         "shift_x": 0.0, "shift_y": 0.0, "width": region.width, "height": region.height,
         "pixel_aspect": 1.0, "aperture_radius": 0.0, "focus_distance": 10.0,
         "focal_length_mm": 50.0, "ortho_scale": 1.0}
    if rv3d.is_perspective:
        d["projection"] = 'PERSP'
        # window_matrix[0][0] = 1 / tan(horizontal half-angle) = focal / (sensor / 2).
        d["focal_length_mm"] = float(p[0][0]) * _SENSOR_MM / 2.0
        d["clip_start"] = float(space.clip_start)
        d["clip_end"] = float(space.clip_end)
    else:
        # The ortho view sees clip_end / 2 on both sides of its centre (as Cycles): the rays start
        # that far behind it.
        d["projection"] = 'ORTHO'
        d["ortho_scale"] = 2.0 / float(p[0][0])
        back = 0.5 * float(space.clip_end)
        to_world = to_world.copy()
        to_world.translation += to_world.col[2].xyz * back
        d["clip_start"] = 0.0
        d["clip_end"] = 2.0 * back
    d["matrix"] = export_camera.rigid_matrix12(to_world)
    rect = (0, 0, region.width, region.height)
    if not space.use_render_border:
        return d, rect
    return _border(d, rect, space.render_border_min_x, space.render_border_min_y,
                   space.render_border_max_x, space.render_border_max_y)


def view_camera(scene, depsgraph, space, region, rv3d, warn):
    """(camera dict, (x, y, width, height) to draw into), or (None, None) when nothing shows."""
    if region.width < 1 or region.height < 1:
        return None, None
    if rv3d.view_perspective == 'CAMERA':
        if scene.camera is None:
            return None, None
        return _camera_view(scene, scene.camera.evaluated_get(depsgraph), region, rv3d, warn)
    return _free_view(space, region, rv3d)


def camera_key(camera):
    """A comparable form of a camera dict (its matrix is a numpy array)."""
    return tuple(sorted((k, tuple(v.tolist()) if hasattr(v, "tolist") else v)
                        for k, v in camera.items()))
