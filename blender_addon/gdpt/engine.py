# The Gradient PT render engine: sync, progressive render, reconstruction, passes.
#
# render() runs once per view layer (and frame). Timeline:
#   export (depsgraph -> arrays) -> _gdpt.RenderJob (BVH, lights) -> job.render(poll)
# poll() runs on Blender's thread about every 0.1 s while the core renders on its own threads: it
# checks Esc (test_break), prints progress, and every `preview_interval` seconds (not in background
# renders) asks for a film snapshot, reconstructs it (L2, the fast exact solve) and shows it with
# update_result. At the end the film is reconstructed with the chosen norm and every pass is
# written in one foreach_set.
import os
import time

import bpy
import numpy as np

from . import compositor_node, export_camera, export_scene, native, passes, properties, viewport

MARKER = "GDPT:"  # every console line of the engine starts with it (tests look for it)
# Set to 1, background renders take progressive previews too (tests, benchmarks of their cost).
PREVIEWS_IN_BACKGROUND = "GDPT_PREVIEWS_IN_BACKGROUND"

# Figures of the last finished render() in this process (samples, timings): read by the tests
# and the benchmark to tell that Gradient PT really rendered and what the add-on cost.
LAST_RENDER = {}
LAST_ERROR = {}  # the last error reported (message), for the same readers


# Pixel-samples per progressive pass. Every pass ends in a barrier and a film commit, and with
# 1 spp per pass each sample also finds its pixel's accumulator out of cache: 1-spp passes cost
# 3% at 320x240 against passes of 13 spp, and several percent more in idle tails on small frames
# (docs/user-guide.md, "Rendering"). Passes of about this many pixel-samples (0.3-0.5 s on 2 cores)
# do not; a cancel discards at most one. Frames of 1024x1024 and up keep 1 spp per pass. The
# count depends only on the frame size, never on time: pass sizes group the sums, so the image
# stays the same for a seed.
PASS_PIXEL_SAMPLES = 1 << 20


# Previews take Blender's thread, and in the solve every core, away from the render: the next one
# is asked for no sooner than the last one's cost divided by this share after it ended. At
# 1920x1080 on 2 cores a G-PT preview (L2 solve and write) takes about 0.4 s and cost 0.55 s of
# render time each: every 3 s that was 20% of the render (docs/user-guide.md, "Rendering").
PREVIEW_MAX_SHARE = 0.05


def preview_gap(interval, cost):
    """Seconds from the end of a preview that took `cost` seconds to the next request: at least
    the Preview Interval, longer when previews would take more than PREVIEW_MAX_SHARE of the
    time."""
    return max(interval, cost / PREVIEW_MAX_SHARE)


def samples_per_pass(pixels, settings):
    """Samples per pixel of one pass. 1 with a time limit, which is checked between passes."""
    if settings.time_limit > 0:
        return 1
    return max(1, min(settings.samples, PASS_PIXEL_SAMPLES // max(pixels, 1)))


def _clock(seconds):
    seconds = max(0.0, seconds)
    minutes = int(seconds // 60)
    return f"{minutes:02d}:{seconds - 60 * minutes:05.2f}"


class GDPTRenderEngine(bpy.types.RenderEngine):
    bl_idname = "GDPT"
    bl_label = "Gradient PT"
    bl_use_postprocess = True
    bl_use_preview = False
    bl_use_shading_nodes_custom = False  # materials use Blender's (Cycles') shader nodes
    bl_use_eevee_viewport = True  # Material Preview uses EEVEE; Rendered mode is view_draw below

    def __init__(self):
        self._viewport = None  # viewport.ViewportSession, in the 3D viewport's Rendered mode

    def __del__(self):
        # Blender frees the engine when its viewport leaves Rendered mode, the file closes or
        # Blender quits: the viewport's render thread must stop with it.
        session = getattr(self, "_viewport", None)
        if session is not None:
            session.free()

    # --- the 3D viewport's Rendered mode (viewport.py) -----------------------------------------

    def view_update(self, context, depsgraph):
        if self._viewport is None:
            self._viewport = viewport.ViewportSession()
        self._viewport.update(self, context, depsgraph)

    def view_draw(self, context, depsgraph):
        if self._viewport is not None:
            self._viewport.draw(self, context, depsgraph)

    def update_render_passes(self, scene=None, renderlayer=None):
        passes.register_passes(self, scene, renderlayer)

    # --- helpers ------------------------------------------------------------------------------

    def _warn(self, message):
        if message in self._warned:
            return
        self._warned.add(message)
        print(f"{MARKER} warning: {message}", flush=True)
        self.report({'WARNING'}, f"Gradient PT: {message}")

    def _error(self, message):
        LAST_ERROR["message"] = message
        print(f"{MARKER} error: {message}", flush=True)
        self.report({'ERROR'}, f"Gradient PT: {message}")

    def _combined(self, module, film, norm, settings, out=None):
        """The Combined RGB image; `out` (optional) takes it when no solve is needed."""
        if norm == 'NONE' or (settings.mode == 'PT' and norm != 'FEATURE'):
            return np.add(film["primal"], film["emission"], out=out)
        return module.reconstruct(film["primal"], film["gradient_x"], film["gradient_y"],
                                  film["variance"], film["emission"], norm, settings.alpha,
                                  settings.threads,
                                  features=film if norm == 'FEATURE' else None)

    def _write(self, result, layer, film, combined, layer_buffer, show=True):
        """Writes every pass into `result` through `layer_buffer` (passes.layer_buffer's `out`);
        `show`: display it now (previews; end_result shows the final image itself: an
        update_result just before it made the final write 0.1 s slower at 1920x1080, 1.04
        against 0.94 s over 6 renders each)."""
        layer.passes.foreach_set("rect", passes.layer_buffer(layer, film, combined, layer_buffer))
        if show:
            self.update_result(result)

    def _record(self, layer_name, settings, film):
        """Records in the render's metadata (multilayer EXR header `gdpt.<view layer>.<key>`)
        what gdpt-merge needs to merge renders of disjoint sample ranges and rebuild Combined."""
        record = {"mode": settings.mode, "seed": settings.seed,
                  "sample_offset": settings.sample_offset, "samples": film["samples"],
                  "half_split": film["half_split"],
                  "reconstruction": settings.reconstruction, "alpha": repr(float(settings.alpha))}
        result = self.get_result()
        for key, value in record.items():
            result.stamp_data_add_field(f"gdpt.{layer_name}.{key}", str(value))

    # --- render -------------------------------------------------------------------------------

    def render(self, depsgraph):
        self._warned = set()
        scene = depsgraph.scene
        view_layer = depsgraph.view_layer
        settings = scene.gdpt
        t_start = time.perf_counter()

        module, build, import_error = native.load()
        if module is None:
            self._error(import_error)
            return
        if scene.camera is None:
            self._error("the scene has no active camera: add a camera and set it as the scene "
                        "camera (Scene Properties > Camera)")
            return
        camera = scene.camera.evaluated_get(depsgraph)
        # The whole frame, or the Render Region (border): Blender's result has exactly this size.
        region = export_camera.render_region(scene.render)
        width, height = region[2:] if region else export_camera.render_resolution(scene.render)

        self.update_stats("", "Synchronizing scene")
        try:
            builder, stats = export_scene.export_scene(module, depsgraph, camera, self._warn)
        except Exception as e:  # a broken datablock must not take Blender down
            self._error(f"scene export failed: {e}")
            raise
        print(f"{MARKER} view layer '{view_layer.name}' frame {scene.frame_current}: exported "
              f"{stats.instances} instances of {stats.meshes} meshes ({stats.triangles} "
              f"triangles), {stats.lights} lights, {stats.materials} materials in "
              f"{stats.seconds:.3f} s", flush=True)

        t_session = time.perf_counter()
        try:
            render_settings = properties.settings_dict(scene)
            render_settings.update(passes.data_pass_settings(scene, view_layer))
            render_settings["samples_per_pass"] = samples_per_pass(width * height, settings)
            job = module.RenderJob(builder, render_settings)  # BVH, lights
        except ValueError as e:
            self._error(str(e))
            return
        session_seconds = time.perf_counter() - t_session
        for w in job.warnings():
            self._warn(w)

        result = self.begin_result(0, 0, width, height, layer=view_layer.name)
        layer = result.layers[0]
        for candidate in result.layers:
            if candidate.name == view_layer.name:
                layer = candidate
        combined_pass = layer.passes.get("Combined")
        if combined_pass is not None and len(combined_pass.rect) != width * height:
            # Writing anyway would scramble the image: refuse instead.
            self.end_result(result, cancel=True)
            self._error(f"Blender's render result has {len(combined_pass.rect)} pixels, Gradient "
                        f"PT computed a {width}x{height} image (render region / resolution)")
            return

        # Reused by every update of this render: fresh pages of a full-HD frame's buffers cost
        # more than the update itself (passes.layer_buffer).
        buffers = {"layer": module.empty(passes.layer_buffer_size(layer, width * height),
                                         np.dtype(np.float32)),
                   "combined": module.empty(width * height * 3, np.dtype(np.float32))
                   .reshape(height, width, 3)}

        t_render = time.perf_counter()
        interval = settings.preview_interval
        # Background renders (blender -b) show no image until it is written, so they take no
        # previews: at 1920x1080 on 2 cores each cost 0.5 s of G-PT render time (docs/user-guide.md,
        # "Rendering"). PREVIEWS_IN_BACKGROUND (the environment variable) takes them anyway.
        previews_on = not bpy.app.background or os.environ.get(PREVIEWS_IN_BACKGROUND) == "1"
        state = {"next_preview": t_render + min(1.0, interval), "cancelled": False,
                 "last_line": 0.0, "last_done": -1}
        # (samples, mean and mean square of the Combined RGB) of each preview, for LAST_RENDER.
        previews = []

        def poll(done, total, elapsed, snapshot_ready):
            flags = 0
            if self.test_break():
                state["cancelled"] = True
                return 1
            now = time.perf_counter()
            if snapshot_ready:
                film = job.snapshot()  # views, valid until the next snapshot
                combined = self._combined(module, film, 'L2', settings, buffers["combined"])
                self._write(result, layer, film, combined, buffers["layer"])
                flat = combined.reshape(-1)
                previews.append((film["samples"], float(np.mean(flat)),
                                 float(np.vdot(flat, flat)) / max(flat.size, 1)))
                end = time.perf_counter()
                # The first preview also pays one-time costs (Blender's result buffers, FFTW's
                # plans): 1.9 s at 1920x1080. Its cost would space the others far too widely.
                if len(previews) > 1:
                    state["next_preview"] = max(state["next_preview"],
                                                end + preview_gap(interval, end - now))
            if previews_on and now >= state["next_preview"]:
                state["next_preview"] = now + interval
                flags |= 2
            # ETA from the sample rate of the finished passes, counted down on the wall clock so
            # it moves between passes; the time limit caps it.
            now_elapsed = now - t_render
            remaining = None
            if done > 0:
                remaining = max(0.0, elapsed / done * total - now_elapsed)
            if settings.time_limit > 0:
                left = max(0.0, settings.time_limit - now_elapsed)
                remaining = left if remaining is None else min(remaining, left)
            info = f"Sample {done}/{total}"
            if remaining is not None:
                info += f" | Remaining:{_clock(remaining)}"
            # One console line per finished sample count, at most every 0.5 s, or every 5 s.
            if (done != state["last_done"] and now - state["last_line"] >= 0.5) or \
                    now - state["last_line"] >= 5.0:
                state["last_line"] = now
                state["last_done"] = done
                self.update_stats("", info)
                self.update_progress(done / max(total, 1))
            return flags

        try:
            job.render(poll, 0.1)
        except Exception as e:
            self._error(f"render failed: {e}")
            self.end_result(result, cancel=True)
            return
        t_done = time.perf_counter()

        film = job.passes()
        norm = settings.reconstruction
        self.update_stats("", f"Sample {film['samples']}/{settings.samples} | Reconstructing "
                              f"({norm})")
        combined = self._combined(module, film, norm, settings, buffers["combined"])
        t_reconstruct = time.perf_counter()
        self._write(result, layer, film, combined, buffers["layer"], show=False)
        self.end_result(result)
        self._record(view_layer.name, settings, film)
        # Gradient Reconstruct compositor nodes solve from this layer's passes now: Blender
        # composites after render() returns (compositor_node.py).
        try:
            placement = None
            if region and not scene.render.use_crop_to_border:
                placement = export_camera.render_resolution(scene.render) + region[:2]
            compositor_node.fill_after_render(scene.original, view_layer.name, film,
                                              settings.threads, self._warn, placement)
        except Exception as e:  # the node must never cost the render
            self._warn(f"Gradient Reconstruct compositor nodes were not updated: {e}")
        t_end = time.perf_counter()
        status = "cancelled" if state["cancelled"] else "finished"
        LAST_RENDER.clear()
        LAST_RENDER.update(
            view_layer=view_layer.name, status=status, samples=film["samples"], width=width,
            height=height, export=stats.seconds, export_cpu=stats.cpu_seconds,
            setup=session_seconds, render=t_done - t_render,
            reconstruct=t_reconstruct - t_done, write=t_end - t_reconstruct,
            total=t_end - t_start, triangles=stats.triangles, rays=job.rays_traced(),
            warnings=sorted(self._warned), build=build, previews=previews)
        print(f"{MARKER} view layer '{view_layer.name}' {status}: {film['samples']}/"
              f"{settings.samples} samples, {width}x{height}, mode {settings.mode}, "
              f"reconstruction {norm}, {build} build; export {stats.seconds:.3f} s, scene setup "
              f"{session_seconds:.3f} s, render "
              f"{t_done - t_render:.3f} s, reconstruction {t_reconstruct - t_done:.3f} s, "
              f"write {t_end - t_reconstruct:.3f} s, total {t_end - t_start:.3f} s", flush=True)
