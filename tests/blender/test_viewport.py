# The 3D viewport's Rendered mode, in Blender with a window (Xvfb, Mesa's software OpenGL; run by
# test_viewport.sh). A generated scene is rendered with F12 twice (the lamp on the left, then on
# the right) to PNG; then a 3D viewport in camera view switches to Rendered, and when its image
# has all its samples the area is saved with screenshot_area. Both are display-transformed 8-bit
# (Standard view transform): block means of the camera frame in the screenshot must match block
# means of the F12 image; after the lamp moves, the next screenshot must match the second F12
# render and differ from the first where the light moved; after the sphere's material changes
# colour, the next must match a third F12 render. The lamp move and the material change must
# update the job's session in place (no mesh read, no BVH build), a mesh edit must rebuild it;
# leaving Rendered mode must stop the job, and Blender must quit with 0.
#   blender -b --factory-startup --addons gdpt --python test_viewport.py -- --make SCENE.blend
#   blender --factory-startup --addons gdpt SCENE.blend --python test_viewport.py -- --out DIR
# (a .blend on the command line: no splash screen over the viewport)
import math
import os
import sys
import time
import traceback

import bpy
import numpy as np

ARGS = sys.argv[sys.argv.index("--") + 1:]
SAMPLES = 8
BLOCKS = (8, 6)  # block means compared: columns, rows
# 8-bit display levels: the mean and the worst block difference allowed against F12 (different
# resolutions and seeds, so the noise differs), and the least the lamp move must change.
MEAN_TOLERANCE = 3.0
BLOCK_TOLERANCE = 12.0
LAMP_CHANGE = 20.0
TIMEOUT = 420.0
FRAME_ZOOM = -12.0
LAMP_LEFT, LAMP_RIGHT = (-2.0, -1.0, 3.0), (2.0, -1.0, 3.0)
RED, BLUE = (0.8, 0.1, 0.1, 1.0), (0.1, 0.2, 0.8, 1.0)


def fail(message):
    print(f"viewport test FAILED: {message}", flush=True)
    os._exit(1)


def check(cond, message):
    if not cond:
        fail(message)
    print("ok:", message, flush=True)


def build_scene(path):
    scene = bpy.context.scene
    for obj in list(bpy.data.objects):
        bpy.data.objects.remove(obj)
    bpy.ops.mesh.primitive_plane_add(size=8.0)
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=(-1.0, 0.5, 0.5))
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.7, location=(1.0, 0.0, 0.7))
    red = bpy.data.materials.new("Red")
    red.diffuse_color = RED  # no nodes: Blender's diffuse colour
    bpy.context.active_object.data.materials.append(red)
    light = bpy.data.lights.new("Lamp", 'POINT')
    light.energy = 800.0
    light.shadow_soft_size = 0.3
    lamp = bpy.data.objects.new("Lamp", light)
    lamp.location = LAMP_LEFT
    scene.collection.objects.link(lamp)
    cam = bpy.data.cameras.new("Camera")
    camera = bpy.data.objects.new("Camera", cam)
    camera.location = (0.0, -7.0, 4.0)
    camera.rotation_euler = (math.radians(60), 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera
    scene.world = scene.world or bpy.data.worlds.new("World")
    scene.world.use_nodes = False
    scene.world.color = (0.05, 0.05, 0.05)
    scene.render.engine = 'GDPT'
    scene.render.resolution_x, scene.render.resolution_y = 320, 240
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    s = scene.gdpt
    s.samples = 32
    s.reconstruction = 'L2'
    s.preview_samples = SAMPLES
    s.preview_start_divider = 4
    bpy.ops.wm.save_as_mainfile(filepath=path)


def f12(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    from gdpt import engine
    check(engine.LAST_RENDER.get("status") == "finished", f"F12 render by Gradient PT: {path}")


def load_rgb(path):
    """8-bit display RGB, rows bottom-up, as floats 0-255."""
    img = bpy.data.images.load(path, check_existing=False)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return px.reshape(h, w, 4)[:, :, :3] * 255.0


def block_means(rgb):
    h, w, _ = rgb.shape
    cols, rows = BLOCKS
    out = np.empty((rows, cols, 3))
    for r in range(rows):
        for c in range(cols):
            out[r, c] = rgb[r * h // rows:(r + 1) * h // rows,
                            c * w // cols:(c + 1) * w // cols].mean(axis=(0, 1))
    return out


def job_status():
    """The status of the viewport's job (one Rendered viewport)."""
    from gdpt import viewport
    sessions = [s for s in viewport._live if s.job is not None]
    check(len(sessions) == 1, f"one viewport session has a job ({len(sessions)})")
    return sessions[0].job.status()


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = max((a for a in window.screen.areas if a.type == 'VIEW_3D'),
               key=lambda a: a.width * a.height)
    region = next(r for r in area.regions if r.type == 'WINDOW')
    return window, area, region


def frame_of_screenshot(path, area, region):
    """The camera frame's pixels in a screenshot of `area` (the rectangle the engine drew)."""
    from gdpt import viewport
    rgb = load_rgb(path)
    x, y, w, h = viewport.LAST_DRAW["rect"]
    x0 = int(round(x)) + region.x - area.x
    y0 = int(round(y)) + region.y - area.y
    # One pixel in from the frame's edges (rounding of its position).
    return rgb[y0 + 1:y0 + int(h) - 1, x0 + 1:x0 + int(w) - 1]


class Steps:
    """The test as a timer-driven sequence (the window must draw between steps)."""

    def __init__(self):
        self.scene = bpy.context.scene
        self.lamp = self.scene.objects["Lamp"]
        self.start = time.perf_counter()
        self.stage = "renders"
        self.wait_from = 0.0
        self.shots = []

    def __call__(self):
        try:
            if time.perf_counter() - self.start > TIMEOUT:
                fail(f"timed out in stage {self.stage}")
            return getattr(self, self.stage)()
        except Exception:
            traceback.print_exc()
            fail(f"exception in stage {self.stage}")

    def renders(self):
        os.makedirs(OUT, exist_ok=True)
        f12(self.scene, os.path.join(OUT, "f12_left.png"))
        self.lamp.location = LAMP_RIGHT
        f12(self.scene, os.path.join(OUT, "f12_right.png"))
        self.material = bpy.data.materials["Red"]
        self.material.diffuse_color = BLUE
        f12(self.scene, os.path.join(OUT, "f12_blue.png"))
        self.material.diffuse_color = RED
        self.lamp.location = LAMP_LEFT
        window, area, region = view3d()
        space = area.spaces.active
        space.overlay.show_overlays = False
        space.show_gizmo = False
        space.show_region_toolbar = False
        space.show_region_ui = False
        space.region_3d.view_perspective = 'CAMERA'
        # A frame of about 400x300 px: few pixels for a loaded machine's software GL and CPU.
        space.region_3d.view_camera_zoom = FRAME_ZOOM
        space.region_3d.view_camera_offset = (0.0, 0.0)
        space.shading.type = 'RENDERED'
        self.stage = "wait_image"
        self.wait_from = time.perf_counter()
        self.shown = (0, 0)  # (job, restart) of the image before the change
        return 0.2

    def wait_image(self):
        from gdpt import viewport
        d = viewport.LAST_DRAW
        if (d.get("job", 0), d.get("restart", 0)) <= self.shown or d.get("samples") != SAMPLES \
                or d.get("rendering"):
            return 0.2
        if not hasattr(self, "first_seconds"):
            self.first_seconds = time.perf_counter() - self.wait_from
        time.sleep(0.3)
        window, area, region = view3d()
        path = os.path.join(OUT, f"viewport_{len(self.shots)}.png")
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screenshot_area(filepath=path)
        self.shots.append(frame_of_screenshot(path, area, region))
        print(f"viewport image {len(self.shots)}: {SAMPLES} samples after "
              f"{time.perf_counter() - self.wait_from:.2f} s, frame {d['rect']}, "
              f"{d['size'][0]}x{d['size'][1]} px, solved {d['solved']}", flush=True)
        if len(self.shots) == 1:
            check(viewport.LAST_EXPORT["exported"] == 3 and viewport.LAST_EXPORT["reused"] == 0,
                  f"the first export reads the 3 meshes: {viewport.LAST_EXPORT}")
            self.compare(self.shots[0], "f12_left.png")
            self.status = job_status()
            self.shown = (d["job"], d["restart"])  # the lamp move must restart the render
            self.lamp.location = LAMP_RIGHT
            self.wait_from = time.perf_counter()
            return 0.2
        self.check_in_place(d, "light" if len(self.shots) == 2 else "material")
        if len(self.shots) == 2:
            self.compare(self.shots[1], "f12_right.png")
            before, after = block_means(self.shots[0]), block_means(self.shots[1])
            change = (after - before).mean(axis=2)
            half = BLOCKS[0] // 2
            check(change[:, :half].mean() < -LAMP_CHANGE / 4 and
                  change[:, half:].mean() > LAMP_CHANGE / 4,
                  f"the lamp moved right: the left half darkened ({change[:, :half].mean():.1f}),"
                  f" the right half brightened ({change[:, half:].mean():.1f})")
            check(np.abs(change).max() > LAMP_CHANGE,
                  f"the largest block change {np.abs(change).max():.1f} > {LAMP_CHANGE}")
            self.shown = (d["job"], d["restart"])
            self.material.diffuse_color = BLUE
            self.wait_from = time.perf_counter()
            return 0.2
        self.compare(self.shots[2], "f12_blue.png")
        self.full_rect = d["rect"]
        self.free_views = ['PERSP', 'ORTHO']
        self.stage = "free_view"
        return 0.0

    def check_in_place(self, d, kind):
        """The change of `kind` restarted the same job with its session updated in place: no
        mesh read from Blender, no BVH built."""
        from gdpt import viewport
        status = job_status()
        check(d["job"] == self.shown[0], f"the {kind} change kept the job")
        check(viewport.LAST_EXPORT["exported"] == 0 and viewport.LAST_EXPORT["reused"] == 3 and
              viewport.LAST_EXPORT["changes"] == [kind],
              f"the {kind} change read no mesh: {viewport.LAST_EXPORT}")
        check(status["bvh_builds"] == self.status["bvh_builds"] and
              status["in_place_updates"] == self.status["in_place_updates"] + 1,
              f"the {kind} change updated the session in place, no BVH build: {status}")
        self.status = status

    def border(self):
        """Back in camera view with a Render Region: the right half of the frame only renders
        and draws, and matches the right half of the F12 image (lamp right, blue sphere)."""
        from gdpt import viewport
        self.restart = viewport.LAST_DRAW["restart"]
        r = self.scene.render
        r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = 0.5, 1.0, 0.0, 1.0
        r.use_border = True
        view3d()[1].spaces.active.region_3d.view_perspective = 'CAMERA'
        self.stage = "wait_border"
        return 0.2

    def wait_border(self):
        from gdpt import viewport
        d = viewport.LAST_DRAW
        if d["restart"] <= self.restart or d["samples"] != SAMPLES or d["rendering"]:
            return 0.2
        x, y, w, h = self.full_rect
        check(abs(d["rect"][0] - (x + w / 2)) < 1.0 and abs(d["rect"][2] - w / 2) < 1.0,
              f"Render Region: the right half of the frame {self.full_rect} draws: {d['rect']}")
        time.sleep(0.3)
        window, area, region = view3d()
        path = os.path.join(OUT, "viewport_border.png")
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screenshot_area(filepath=path)
        f12_blue = load_rgb(os.path.join(OUT, "f12_blue.png"))
        f12_blue = f12_blue[:, f12_blue.shape[1] // 2:]
        self.compare_to(frame_of_screenshot(path, area, region), f12_blue,
                        "the right half of f12_blue.png")
        # An edit of the cube's mesh: only that mesh is read again, and the BVH built again.
        self.status = job_status()
        cube = next(o for o in self.scene.objects if o.name.startswith("Cube"))
        cube.data.vertices[0].co.z += 0.1
        cube.data.update()
        self.stage = "wait_geometry_edit"
        return 0.2

    def wait_geometry_edit(self):
        from gdpt import viewport
        status = job_status()
        if status["bvh_builds"] + status["in_place_updates"] <= \
                self.status["bvh_builds"] + self.status["in_place_updates"]:
            return 0.2
        check(viewport.LAST_EXPORT["exported"] == 1 and viewport.LAST_EXPORT["reused"] == 2,
              f"a mesh edit reads that mesh again and keeps the others: {viewport.LAST_EXPORT}")
        check(status["bvh_builds"] == self.status["bvh_builds"] + 1,
              f"a mesh edit builds the BVH again: {status}")
        view3d()[1].spaces.active.shading.type = 'SOLID'
        self.stage = "left_mode"
        self.wait_from = time.perf_counter()
        return 0.1

    def free_view(self):
        """Free view, perspective then orthographic: the view moves (a restart of the same job,
        no export) and the image fills the region."""
        from gdpt import viewport
        window, area, region = view3d()
        rv3d = area.spaces.active.region_3d
        if not self.free_views:
            self.stage = "border"
            return 0.0
        self.projection = self.free_views.pop(0)
        self.restart = viewport.LAST_DRAW["restart"]
        self.job = viewport.LAST_DRAW["job"]
        rv3d.view_perspective = self.projection
        rv3d.view_distance = 12.0
        self.stage = "wait_free_view"
        return 0.2

    def wait_free_view(self):
        from gdpt import viewport
        d = viewport.LAST_DRAW
        window, area, region = view3d()
        if d["restart"] <= self.restart:
            return 0.05
        full = (region.width, region.height)
        if not hasattr(self, "first_size"):
            self.first_size = d["size"]
        if d["size"] != full:
            return 0.05
        check(d["job"] == self.job, f"{self.projection} free view: the view moved without a new "
              "export (the job restarted with a new camera)")
        # A restart renders 1/4, then 1/2, then full resolution; a fast machine may replace the
        # 1/4 image before this timer sees it, so the first image seen is one of the reduced ones.
        reduced = [(region.width // 4, region.height // 4), (region.width // 2, region.height // 2)]
        check(self.first_size in reduced, f"{self.projection} free view: the first image has a "
              f"reduced start resolution {reduced} (divider 4): {self.first_size}")
        del self.first_size
        check(d["rect"] == (0, 0) + full,
              f"{self.projection} free view: the image fills the region {full}")
        time.sleep(0.3)
        path = os.path.join(OUT, f"free_{self.projection}.png")
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.screen.screenshot_area(filepath=path)
        shot = load_rgb(path)
        inside = shot[region.y - area.y:region.y - area.y + region.height]
        check(inside.std() > 10.0, f"{self.projection} free view: not blank (std "
              f"{inside.std():.1f})")
        self.stage = "free_view"
        return 0.0

    def compare(self, frame, f12_name):
        self.compare_to(frame, load_rgb(os.path.join(OUT, f12_name)), f12_name)

    def compare_to(self, frame, f12, f12_name):
        a, b = block_means(frame), block_means(f12)
        check(frame.std() > 10.0 and 20.0 < frame.mean() < 235.0,
              f"the viewport image is not blank (mean {frame.mean():.1f}, std {frame.std():.1f})")
        diff = np.abs(a - b)
        print(f"block means viewport - F12 ({f12_name}):\n{np.round((a - b).mean(axis=2), 1)}",
              flush=True)
        check(diff.mean() < MEAN_TOLERANCE,
              f"viewport matches {f12_name}: mean block difference {diff.mean():.2f} < "
              f"{MEAN_TOLERANCE}")
        check(diff.max() < BLOCK_TOLERANCE,
              f"viewport matches {f12_name}: worst block difference {diff.max():.2f} < "
              f"{BLOCK_TOLERANCE}")

    def left_mode(self):
        from gdpt import viewport
        if viewport._retiring and time.perf_counter() - self.wait_from < 10.0:
            return 0.1  # the thread ends after its tile or solve in flight
        check(len(viewport._live) == 0 and len(viewport._retiring) == 0,
              f"leaving Rendered mode stopped the viewport job and its thread ended (after "
              f"{time.perf_counter() - self.wait_from:.2f} s)")
        # Quitting while a render runs (no sample limit) must stop it and exit 0 (the shell
        # script checks the exit code).
        self.job = viewport.LAST_DRAW["job"]
        self.scene.gdpt.preview_samples = 0
        view3d()[1].spaces.active.shading.type = 'RENDERED'
        self.stage = "quit_while_rendering"
        return 0.2

    def quit_while_rendering(self):
        from gdpt import viewport
        d = viewport.LAST_DRAW
        if d["job"] <= self.job or d["size"][0] < 10 or not d["rendering"]:
            return 0.2
        print("viewport test passed (quitting while the viewport renders)", flush=True)
        bpy.ops.wm.quit_blender()
        return None


if "--make" in ARGS:
    build_scene(os.path.abspath(ARGS[ARGS.index("--make") + 1]))
else:
    OUT = os.path.abspath(ARGS[ARGS.index("--out") + 1])
    bpy.app.timers.register(Steps(), first_interval=1.0)
