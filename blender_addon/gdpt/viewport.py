# The 3D viewport's Rendered mode: one ViewportSession per viewport engine (engine.py's
# view_update / view_draw, Cycles' split).
#
# view_update (a depsgraph change): exports the scene with the view's camera and starts a
# _gdpt.ViewportJob, which builds the BVH and renders progressive passes on its own thread and
# publishes the display image (a G-PT reconstruction, or the primal) under a lock.
# view_draw (every redraw): a moved view only restarts the job with a new camera (the BVH is
# kept); the newest image is uploaded into a GPUTexture and drawn with Blender's display shader,
# so the viewport's view transform applies. A timer tags the Rendered viewports for redraw while
# a job has unseen images; the job stops when its engine is freed (leaving Rendered mode,
# closing the file, quitting) or when no viewport shows Gradient PT any more.
import atexit
import time
import weakref

import bpy
import gpu
from gpu_extras.presets import draw_texture_2d

from . import export_mesh, export_scene, native, properties, viewport_camera

MARKER = "GDPT:"
# Seconds between the redraw timer's looks at the jobs.
REDRAW_INTERVAL = 0.02
# Viewport Samples 0: until stopped (the largest sample count the settings allow).
UNLIMITED_SAMPLES = 1 << 24

_live = weakref.WeakSet()  # sessions with a job, stopped at exit
# Jobs replaced by a new export: cancelled, dropped by the timer once their thread has returned
# (so that Blender's thread never waits for a pass or a solve to end).
_retiring = []
# The last image drawn (job, restart, version, samples, solved, rect, size): read by the viewport
# test and benchmark.
LAST_DRAW = {}
_jobs_started = [0]  # jobs started in this process (LAST_DRAW["job"])
# The last viewport export: meshes read from Blender and meshes kept from the export before, the
# kinds of change (classify_updates) and the export's seconds.
LAST_EXPORT = {}
# Object data whose geometry updates drop the kept meshes of the objects using it.
_OBJECT_DATA_TYPES = (bpy.types.Mesh, bpy.types.Curve, bpy.types.MetaBall)


def render_settings(scene):
    """The settings dict of a viewport job: the render's, with the viewport's samples and mode,
    one sample per pass (the first image after one pass)."""
    s = scene.gdpt
    d = properties.settings_dict(scene)
    d["mode"] = s.preview_mode
    d["samples"] = int(s.preview_samples) or UNLIMITED_SAMPLES
    d["time_limit"] = 0.0
    d["samples_per_pass"] = 1
    d["sample_offset"] = 0  # farm settings: the viewport always renders a whole frame
    d["frame_samples"] = 0
    return d


def display_settings(scene):
    s = scene.gdpt
    norm = s.preview_reconstruction if s.preview_mode == 'GPT' else 'NONE'
    return {"norm": norm, "alpha": float(s.alpha), "start_divider": int(s.preview_start_divider)}


def _restart_key(scene):
    """What restarts the job when it changes, besides the depsgraph's own updates."""
    return (tuple(sorted(render_settings(scene).items())),
            tuple(sorted(display_settings(scene).items())))


def classify_updates(depsgraph):
    """What the depsgraph updates change, as Cycles' sync reads them: a set of 'geometry' (an
    object's or object data's geometry), 'transform' (an object other than a lamp or the camera
    moved), 'light' (a lamp's data or placement), 'material', 'world', 'image', 'other' (another
    datablock, e.g. a collection or a geometry node tree), and the names of the objects whose
    meshes changed (their kept meshes are dropped; None in it: all of them). Scene updates
    (settings) are left to the restart key; the camera object to view_draw."""
    kinds, changed_objects = set(), set()
    for update in depsgraph.updates:
        data = update.id
        if isinstance(data, bpy.types.Object):
            if data.type == 'CAMERA':
                continue
            if data.type == 'LIGHT':
                if update.is_updated_geometry or update.is_updated_transform or \
                        update.is_updated_shading:
                    kinds.add('light')
                continue
            if update.is_updated_geometry:
                kinds.add('geometry')
                changed_objects.add(data.original.name_full)
            if update.is_updated_transform:
                kinds.add('transform')
            if update.is_updated_shading:
                kinds.add('material')  # e.g. a material slot changed
        elif isinstance(data, _OBJECT_DATA_TYPES):
            if update.is_updated_geometry:
                kinds.add('geometry')
                original = data.original
                changed_objects.update(o.name_full for o in bpy.data.objects
                                       if o.data is not None and o.data.original == original)
        elif isinstance(data, bpy.types.Light):
            kinds.add('light')
        elif isinstance(data, (bpy.types.Material, bpy.types.ShaderNodeTree)):
            kinds.add('material')
        elif isinstance(data, bpy.types.World):
            kinds.add('world')
        elif isinstance(data, bpy.types.Image):
            kinds.add('image')
        elif isinstance(data, (bpy.types.Scene, bpy.types.Camera)):
            continue
        else:
            kinds.add('other')
            if update.is_updated_geometry:
                changed_objects.add(None)
    return kinds, changed_objects


class ViewportSession:
    def __init__(self):
        self.job = None
        self.camera_key = None
        self.restart_key = None
        self.seen = -1  # version of the image in the texture
        self.texture = None
        self.image = None  # the latest dict from the job, minus its pixels
        self.samples_total = 0
        self.error = None
        self.mesh_store = export_mesh.MeshStore()
        self.job_number = 0

    # --- view_update ----------------------------------------------------------------------------

    def update(self, engine, context, depsgraph):
        scene = depsgraph.scene
        kinds, changed_objects = classify_updates(depsgraph)
        settings_changed = self.restart_key != _restart_key(scene)
        if self.job is not None and not settings_changed and not kinds:
            return
        module, _build, error = native.load()
        if module is None:
            self._fail(engine, error)
            return
        camera, _rect = viewport_camera.view_camera(scene, depsgraph, context.space_data,
                                                    context.region, context.region_data,
                                                    lambda m: None)
        if camera is None:
            self.retire()
            return
        store = self.mesh_store
        if None in changed_objects:
            store.meshes.clear()
        for name in changed_objects - {None}:
            store.forget(name)
        store.reused = store.exported = 0
        warnings = set()
        try:
            builder, stats = export_scene.export_scene(module, depsgraph, None, warnings.add,
                                                       camera=camera, mesh_store=store)
            if self.job is not None:
                # Same worker: the session keeps its BVH unless the geometry changed.
                self.job.update(builder, render_settings(scene), display_settings(scene))
            else:
                self.job = module.ViewportJob(builder, render_settings(scene),
                                              display_settings(scene))
                _jobs_started[0] += 1
                self.job_number = _jobs_started[0]
                self.seen = -1
        except Exception as e:  # a broken datablock must not take Blender down
            store.meshes.clear()  # the store may hold meshes the job never received
            self._fail(engine, f"viewport export failed: {e}")
            return
        for w in sorted(warnings):
            print(f"{MARKER} viewport warning: {w}", flush=True)
        changes = sorted(kinds) + (['settings'] if settings_changed else [])
        LAST_EXPORT.update(exported=store.exported, reused=store.reused, seconds=stats.seconds,
                           changes=changes)
        print(f"{MARKER} viewport: exported {stats.instances} instances ({store.exported} meshes "
              f"read, {store.reused} kept), {stats.lights} lights in {stats.seconds:.3f} s "
              f"(changed: {', '.join(changes) or 'nothing, the first export'})", flush=True)
        self.error = None
        self.camera_key = viewport_camera.camera_key(camera)
        self.restart_key = _restart_key(scene)
        self.samples_total = int(scene.gdpt.preview_samples)
        _live.add(self)
        _start_timer()

    def _fail(self, engine, message):
        self.retire()
        if message != self.error:
            print(f"{MARKER} viewport error: {message}", flush=True)
            engine.report({'ERROR'}, f"Gradient PT: {message}")
        self.error = message
        engine.update_stats("", f"Error: {message}")

    # --- view_draw ------------------------------------------------------------------------------

    def draw(self, engine, context, depsgraph):
        scene = depsgraph.scene
        camera, rect = viewport_camera.view_camera(scene, depsgraph, context.space_data,
                                                   context.region, context.region_data,
                                                   lambda m: None)
        if self.job is None or camera is None:
            return
        key = viewport_camera.camera_key(camera)
        if key != self.camera_key:
            self.camera_key = key
            self.job.set_camera(camera)
        status = self.job.status()
        if status["error"]:
            self._fail(engine, status["error"])
            return
        latest = self.job.latest(self.seen)
        if latest is not None:
            self._upload(latest)
        if self.texture is None:
            return
        gpu.state.blend_set('ALPHA_PREMULT')
        engine.bind_display_space_shader(scene)
        draw_texture_2d(self.texture, (rect[0], rect[1]), rect[2], rect[3])
        engine.unbind_display_space_shader()
        gpu.state.blend_set('NONE')
        total = self.samples_total or "∞"
        kind = "reconstructed" if self.image["solved"] else "primal"
        engine.update_stats("", f"Sample {self.image['samples']}/{total} ({kind})")
        if (LAST_DRAW.get("job"), LAST_DRAW.get("restart")) != (self.job_number,
                                                                 self.image["restart"]):
            LAST_DRAW["first_draw"] = time.perf_counter()  # of this restart, for the benchmark
        LAST_DRAW.update(job=self.job_number, restart=self.image["restart"], version=self.seen,
                         samples=self.image["samples"], solved=self.image["solved"],
                         rect=tuple(rect),
                         size=(self.image["width"], self.image["height"]),
                         rendering=status["rendering"])

    def _upload(self, latest):
        pixels = latest.pop("image")
        buffer = gpu.types.Buffer('FLOAT', pixels.size, pixels.reshape(-1))
        self.texture = gpu.types.GPUTexture((latest["width"], latest["height"]),
                                            format='RGBA16F', data=buffer)
        self.image = latest
        self.seen = latest["version"]

    # --- redraw and stop ------------------------------------------------------------------------

    def wants_redraw(self):
        """True while the job has an image the texture does not show yet."""
        return self.job is not None and self.job.status()["version"] > self.seen

    def retire(self):
        """Cancels the job without waiting for it (the timer drops it once it has ended)."""
        if self.job is not None:
            self.job.cancel()
            _retiring.append(self.job)
            self.job = None
            _start_timer()
        _live.discard(self)

    def stop(self):
        """Cancels the job and waits for its thread (a pass's tile or a solve at most)."""
        if self.job is not None:
            self.job.stop()
            self.job = None
        _live.discard(self)

    def free(self):
        self.retire()
        self.texture = None


def _rendered_views():
    """The 3D viewport areas in Rendered mode with Gradient PT as the engine."""
    wm = bpy.context.window_manager
    for window in (wm.windows if wm else ()):
        if window.scene.render.engine != "GDPT":
            continue
        for area in window.screen.areas:
            if area.type == 'VIEW_3D' and area.spaces.active.shading.type == 'RENDERED':
                yield area


def _redraw_timer():
    _retiring[:] = [job for job in _retiring if not job.status()["finished"]]
    if not _live:
        return REDRAW_INTERVAL if _retiring else None
    areas = list(_rendered_views())
    if not areas:
        # No viewport shows a job any more (the engine's __del__ may come later): stop them.
        for session in list(_live):
            session.retire()
        return REDRAW_INTERVAL
    if any(session.wants_redraw() for session in list(_live)):
        for area in areas:
            area.tag_redraw()
    return REDRAW_INTERVAL


def _start_timer():
    if not bpy.app.timers.is_registered(_redraw_timer):
        bpy.app.timers.register(_redraw_timer, first_interval=REDRAW_INTERVAL)


@atexit.register
def _stop_all():
    for session in list(_live):
        session.stop()
    while _retiring:
        _retiring.pop().stop()
