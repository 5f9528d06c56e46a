# The 3D viewport's Rendered mode against Cycles' on the demo scene (run by bench_viewport.sh in
# Blender with a window on Xvfb). The camera frame is shown 1:1 at 960x540 in camera view. For
# each engine: render the viewport to a few samples and wait until it is still, then change the
# lamp's power and lift the sample limit in one step, and take screenshots of the area as fast as
# they come: the time to the first one that differs from the still image is the time to the
# first updated image (to within one screenshot's cost, printed). One more screenshot 2 s after
# the change (or as soon after as Blender's thread allows; the time is printed) gives the relMSE
# against the engine's own F12 render of the changed scene (both through the Standard view
# transform in 8 bits, decoded to linear; the best of +-1 px alignments). For Gradient PT the
# engine's own clock of its first draw after the change is printed too.
#   blender --factory-startup --addons gdpt demo.blend --python bench_viewport.py -- --out DIR
import os
import sys
import time
import traceback

import bpy
import numpy as np

ARGS = sys.argv[sys.argv.index("--") + 1:]
OUT = os.path.abspath(ARGS[ARGS.index("--out") + 1])
WIDTH, HEIGHT = 960, 540
STILL_SAMPLES = int(os.environ.get("GDPT_BENCH_STILL_SAMPLES", "4"))
REF_SAMPLES = int(os.environ.get("GDPT_BENCH_REF_SAMPLES", "256"))
# 1: the references of an earlier run with the same sample count are used again.
REUSE_REFS = os.environ.get("GDPT_BENCH_REUSE_REFS") == "1"
AT_SECONDS = 2.0
UNLIMITED = 1 << 24  # viewport samples after the change (both engines' maximum)
CHANGED_ENERGY_FACTOR = 1.5
# --engines GDPT,CYCLES (the default) or a subset; --label names this add-on build in the lines.
ENGINES = tuple(ARGS[ARGS.index("--engines") + 1].split(",")) if "--engines" in ARGS else \
    ("GDPT", "CYCLES")
LABEL = ARGS[ARGS.index("--label") + 1] if "--label" in ARGS else ""


def log(message):
    print(f"BENCH viewport{' ' + LABEL if LABEL else ''}: {message}", flush=True)


def setup(scene):
    scene.render.resolution_x, scene.render.resolution_y = WIDTH, HEIGHT
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = 'PNG'
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    c = scene.cycles
    c.device = 'CPU'
    c.blur_glossy = 0.0  # both engines unblurred: the reference is Cycles'
    scene.gdpt.blur_glossy = 0.0
    c.use_preview_denoising = False
    c.use_denoising = False
    c.samples = REF_SAMPLES
    c.use_adaptive_sampling = False
    c.max_bounces = scene.gdpt.max_bounces
    scene.gdpt.samples = REF_SAMPLES
    scene.gdpt.reconstruction = 'L2'


def set_viewport_samples(scene, samples):
    scene.gdpt.preview_samples = samples
    scene.cycles.preview_samples = samples


def view3d():
    window = bpy.context.window_manager.windows[0]
    area = max((a for a in window.screen.areas if a.type == 'VIEW_3D'),
               key=lambda a: a.width * a.height)
    region = next(r for r in area.regions if r.type == 'WINDOW')
    return window, area, region


def screenshot(path):
    window, area, region = view3d()
    with bpy.context.temp_override(window=window, area=area, region=region):
        bpy.ops.screen.screenshot_area(filepath=path)
    img = bpy.data.images.load(path, check_existing=False)
    w, h = img.size
    px = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    bpy.data.images.remove(img)
    return px.reshape(h, w, 4)[:, :, :3]


def frame(rgb, scene):
    """The camera frame's pixels of an area screenshot."""
    from gdpt import viewport_camera
    window, area, region = view3d()
    cam = scene.camera.evaluated_get(bpy.context.evaluated_depsgraph_get())
    x, y, w, h = viewport_camera._camera_frame(scene, cam, region, region.data)
    x0, y0 = int(round(x)) + region.x - area.x, int(round(y)) + region.y - area.y
    return rgb[y0:y0 + HEIGHT, x0:x0 + WIDTH]


def to_linear(display):
    return np.where(display <= 0.04045, display / 12.92, ((display + 0.055) / 1.055) ** 2.4)


def rel_mse(image, reference):
    """relMSE of two display images (decoded to linear), the best of +-1 px alignments."""
    a, r = to_linear(image), to_linear(reference)
    best = None
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            a2 = a[1 + dy:a.shape[0] - 1 + dy, 1 + dx:a.shape[1] - 1 + dx]
            r2 = r[1:r.shape[0] - 1, 1:r.shape[1] - 1]
            if a2.shape != r2.shape:
                continue
            v = float(np.mean((a2 - r2) ** 2 / (r2 ** 2 + 1e-2)))
            best = v if best is None else min(best, v)
    return best


class Bench:
    def __init__(self):
        self.scene = bpy.context.scene
        setup(self.scene)
        self.lamp = next(o for o in self.scene.objects if o.type == 'LIGHT')
        self.energy = self.lamp.data.energy
        self.results = {}
        self.queue = list(ENGINES)
        self.stage = "references"

    def __call__(self):
        try:
            return getattr(self, self.stage)()
        except Exception:
            traceback.print_exc()
            os._exit(1)

    def references(self):
        os.makedirs(OUT, exist_ok=True)
        self.lamp.data.energy = self.energy * CHANGED_ENERGY_FACTOR
        self.refs = {}
        for engine in ENGINES:
            self.scene.render.engine = engine
            path = os.path.join(OUT, f"reference_{engine}_{REF_SAMPLES}spp.png")
            if not (REUSE_REFS and os.path.exists(path)):
                self.scene.render.filepath = path
                t = time.perf_counter()
                bpy.ops.render.render(write_still=True)
                log(f"{engine} reference, {REF_SAMPLES} samples: {time.perf_counter() - t:.1f} s")
            img = bpy.data.images.load(path, check_existing=False)
            px = np.empty(WIDTH * HEIGHT * 4, dtype=np.float32)
            img.pixels.foreach_get(px)
            bpy.data.images.remove(img)
            self.refs[engine] = px.reshape(HEIGHT, WIDTH, 4)[:, :, :3]
        self.lamp.data.energy = self.energy
        window, area, region = view3d()
        space = area.spaces.active
        space.overlay.show_overlays = False
        space.show_gizmo = False
        space.show_region_toolbar = False
        space.show_region_ui = False
        space.region_3d.view_perspective = 'CAMERA'
        with bpy.context.temp_override(window=window, area=area, region=region):
            bpy.ops.view3d.zoom_camera_1_to_1()
        self.stage = "next_engine"
        return 0.5

    def next_engine(self):
        if not self.queue:
            return self.report()
        self.engine = self.queue.pop(0)
        self.scene.render.engine = self.engine
        set_viewport_samples(self.scene, STILL_SAMPLES)
        self.lamp.data.energy = self.energy
        view3d()[1].spaces.active.shading.type = 'RENDERED'
        self.still = None
        self.stage = "wait_still"
        return 2.0

    def wait_still(self):
        shot = screenshot(os.path.join(OUT, "still.png"))
        if self.still is None or np.abs(shot - self.still).max() > 0:
            self.still = shot
            return 1.0
        # Still: the change (one depsgraph update) and the clock start together.
        self.shots = []
        set_viewport_samples(self.scene, UNLIMITED)
        self.lamp.data.energy = self.energy * CHANGED_ENERGY_FACTOR
        self.t0 = time.perf_counter()
        self.first = None
        self.stage = "after_change"
        return 0.0

    def after_change(self):
        """Screenshots as fast as they come until one differs from the still image."""
        t = time.perf_counter() - self.t0
        shot = screenshot(os.path.join(OUT, "shot.png"))
        self.shots.append(t)
        if np.abs(shot - self.still).mean() <= 1.0 / 255 and t < AT_SECONDS:
            return 0.0
        self.first = t
        self.stage = "at_two_seconds"
        return max(0.0, AT_SECONDS - (time.perf_counter() - self.t0))

    def at_two_seconds(self):
        t = time.perf_counter() - self.t0
        shot = screenshot(os.path.join(OUT, f"at_2s_{self.engine}.png"))
        err = rel_mse(frame(shot, self.scene), self.refs[self.engine])
        engine_side = ""
        if self.engine == "GDPT":
            engine_side = self.gdpt_profile()
        step = self.shots[-1] / max(len(self.shots), 1)
        self.results[self.engine] = (self.first, t, err)
        log(f"{self.engine}: first updated image on screen {self.first:.3f} s after the change "
            f"(screenshots every {step:.2f} s){engine_side}; relMSE {err:.5f} at {t:.2f} s")
        view3d()[1].spaces.active.shading.type = 'SOLID'
        self.stage = "next_engine"
        return 1.0

    def gdpt_profile(self):
        """Where Gradient PT's time after the change went, by its own clocks."""
        from gdpt import viewport
        d, e = viewport.LAST_DRAW, viewport.LAST_EXPORT
        first = d.get("first_draw", d.get("job_first_draw", self.t0))
        text = (f"; its first draw {first - self.t0:.3f} s after the change; export "
                f"{e.get('seconds', 0):.3f} s ({e.get('exported')} meshes read)")
        session = next(iter(viewport._live), None)
        if session is not None and session.job is not None:
            st = session.job.status()
            if "scene_seconds" in st:
                text += (f", scene update {st['scene_seconds']:.3f} s (BVH builds "
                         f"{st['bvh_builds']}, in place {st['in_place_updates']}), first image "
                         f"{st['first_image_seconds']:.3f} s after the update call")
            if "publish_seconds" in st:
                text += (f"; read-outs and solves {st['publish_seconds']:.2f} s of "
                         f"{st['restart_seconds']:.2f} s; shift failures "
                         f"{st['shift_failures']:.3f}")
        return text + (f"; at the screenshot {d.get('samples')} samples, "
                       f"{'solved' if d.get('solved') else 'primal'}, size {d.get('size')}")

    def report(self):
        if len(self.results) < 2:
            bpy.ops.wm.quit_blender()
            return None
        g, c = self.results["GDPT"], self.results["CYCLES"]
        log(f"time to first updated image: Gradient PT {g[0]:.3f} s, Cycles {c[0]:.3f} s, "
            f"ratio Cycles / Gradient PT {c[0] / g[0]:.2f}")
        log(f"relMSE at {AT_SECONDS:.0f} s: Gradient PT {g[2]:.5f}, Cycles {c[2]:.5f}, "
            f"ratio Cycles / Gradient PT {c[2] / g[2]:.2f}")
        bpy.ops.wm.quit_blender()
        return None


bpy.app.timers.register(Bench(), first_interval=2.0)
