# The compositor node "Gradient Reconstruct": a screened Poisson solve of Primal, Gradient X and
# Gradient Y (+ Emission) with its own alpha and norm, tweakable without re-rendering.
#
# A Python add-on cannot run native code inside Blender's compositor, so the node is a
# CompositorNodeCustomGroup whose internal node group only outputs an internal float Image
# datablock (".GDPT Reconstruct"). The add-on fills that image before the compositor reads it:
#   - the engine: render() calls `fill_after_render` once its film is final (Blender composites
#     only after every view layer has been rendered). The passes of the layer are cached in
#     memory (`_CACHE`, per (scene, view layer)), but only while some scene has such a node.
#   - a change of the node's `alpha` or `norm`: the update callback solves again from the cached
#     passes (or re-reads the EXR file) and rewrites the image; a node property change makes the
#     compositor run again, so the artist sees the result without re-rendering.
#   - a render_pre handler, for nodes that read only EXR files (Blender does not call the engine
#     at all when the compositor has no Render Layers node).
# An input is read from what it is linked to (through reroutes): a Render Layers pass (the cached
# passes of that scene and view layer) or a multilayer EXR Image node (read through OpenImageIO by
# the `_gdpt` module). Anything else (an unlinked Primal / Gradient input, a Blur in between, no
# cached passes) is reported on the node, in the console (`GDPT:` lines) and, during a render,
# with RenderEngine.report; a render then clears the image to black, so a stale result is never
# composited silently. (Blender's composite_pre handlers do not run for a render's compositing.)
#
# Reconstruction rule (docs/user-guide.md): Image = solve(Primal, Gradient X, Gradient Y) + Emission,
# through `_gdpt.reconstruct`, the same C++ code as the engine and the gdpt-reconstruct CLI. The
# Feature norm also reads the render's feature passes from its Render Layers, and G-PT's gradients
# over the primal's halves from the optional inputs Gradient X A / X B / Y A / Y B when all four
# are linked.
import os
import sys
import textwrap
import threading
import time

import bpy
import nodeitems_utils
import numpy as np
from bpy.app.handlers import persistent
from bpy.props import EnumProperty, FloatProperty
from nodeitems_utils import NodeItem

from . import export_camera, native

NODE_IDNAME = "CompositorNodeGDPTReconstruct"
MARKER = "GDPT:"
# G-PT's gradients over the primal's halves (Primal A / B's samples), optional inputs, all four
# or none: with them the Feature norm solves each half on its own (film keys).
HALF_GRADIENT_KEYS = {"Gradient X A": "gradient_x_a", "Gradient X B": "gradient_x_b",
                      "Gradient Y A": "gradient_y_a", "Gradient Y B": "gradient_y_b"}
INPUTS = ("Primal", "Gradient X", "Gradient Y", "Emission", *HALF_GRADIENT_KEYS)
REQUIRED = INPUTS[:3]
# Render Layers pass names the node can read, and their keys in the engine's film dict: the
# first four every render has.
FILM_KEYS = {"Primal": "primal", "Gradient X": "gradient_x", "Gradient Y": "gradient_y",
             "Emission": "emission", **HALF_GRADIENT_KEYS}
# The Feature norm's inputs besides (engine film keys): a render with the Feature reconstruction
# caches them; they are not Blender passes, so the node reads them only from Render Layers. The
# variances of the pixel means (the Variance pass) give the Weighted candidate, as in the render.
FEATURE_KEYS = tuple(f"{k}{v}" for k in ("primal_a", "primal_b", "denoising_albedo",
                                         "denoising_normal", "denoising_depth")
                     for v in ("", "_variance")) + ("variance",)

# (scene name, view layer name) -> {film key: (height, width, 3) float32} of the last render, and
# under "placement" (frame width, frame height, x, y) when it rendered an uncropped Render Region:
# the compositor then works on frame-sized buffers with the region in place.
_CACHE = {}
# node.as_pointer() -> (level, message): the last outcome, drawn on the node.
_STATUS = {}
# The file last read for Image-node inputs: (path, layer) -> (mtime, {pass: (h, w, 3)}).
_EXR_CACHE = {}
# node.as_pointer() -> (input arrays, alpha, result) of the node's last L1 image: an alpha tweak
# on the same arrays (the same objects: a render or a changed file makes new ones) starts from it.
_LAST_L1 = {}
# Warm start only within this alpha ratio either way: bench_reconstruct --warm measured the warm
# objective within 0.1% of the cold solve's there, and 0.45% above it for a 4x change.
WARM_ALPHA_RATIO = 2.0


class InputError(Exception):
    """An input that cannot be read; the message names the node and what to do."""


def _module():
    module, _, error = native.load()
    if module is None:
        raise InputError(error)
    return module


def _say(node, level, message, console=True):
    _STATUS[node.as_pointer()] = (level, message)
    if console:
        print(f"{MARKER} {'compositor' if level == 'INFO' else 'warning'}: "
              f"Gradient Reconstruct '{node.name}': {message}", flush=True)


# --- the node's internal group and image --------------------------------------------------------

def _new_image(width, height):
    image = bpy.data.images.new(".GDPT Reconstruct", max(width, 1), max(height, 1), alpha=True,
                                float_buffer=True)
    image.generated_color = (0.0, 0.0, 0.0, 0.0)
    image.colorspace_settings.name = 'Linear'  # the solve is scene linear: no conversion
    return image


def _new_group(image):
    tree = bpy.data.node_groups.new(".GDPT Reconstruct", "CompositorNodeTree")
    for name in INPUTS:
        socket = tree.inputs.new("NodeSocketColor", name)
        socket.default_value = (0.0, 0.0, 0.0, 1.0)
    tree.outputs.new("NodeSocketColor", "Image")
    group_in = tree.nodes.new("NodeGroupInput")
    group_in.location = (-300, 0)
    group_out = tree.nodes.new("NodeGroupOutput")
    group_out.location = (300, 0)
    image_node = tree.nodes.new("CompositorNodeImage")
    image_node.name = "Reconstruction"
    image_node.image = image
    tree.links.new(image_node.outputs["Image"], group_out.inputs["Image"])
    return tree


def node_image(node):
    tree = node.node_tree
    image_node = tree.nodes.get("Reconstruction") if tree is not None else None
    return image_node.image if image_node is not None else None


def _write_image(node, rgb, placement=None, alpha=None):
    """rgb: (height, width, 3) float32, rows bottom-up; written with alpha 1, or `alpha`
    ((height, width[, 1]), the render's coverage with Film > Transparent). With a placement
    (frame width, frame height, x, y) the image is the frame, rgb at (x, y), alpha 0 elsewhere."""
    image = node_image(node)
    if image is None:
        raise InputError("the node's internal image is missing (delete and re-add the node)")
    height, width = rgb.shape[:2]
    x = y = 0
    if placement is not None:
        width, height, x, y = placement
    if tuple(image.size) != (width, height):
        # A generated image regenerates its buffer at the new size.
        image.generated_width, image.generated_height = width, height
    rgba = np.zeros((height, width, 4), dtype=np.float32)
    rgba[y:y + rgb.shape[0], x:x + rgb.shape[1], :3] = rgb
    rgba[y:y + rgb.shape[0], x:x + rgb.shape[1], 3] = (
        1.0 if alpha is None else alpha.reshape(rgb.shape[:2]))
    image.pixels.foreach_set(rgba.ravel())
    image.update()


def _clear_image(node):
    image = node_image(node)
    if image is not None:
        width, height = image.size
        image.pixels.foreach_set(np.zeros(width * height * 4, dtype=np.float32))
        image.update()


# --- where the inputs come from ------------------------------------------------------------------

def _upstream(socket):
    """(node, output socket) feeding `socket`, through reroutes; None when not linked."""
    while socket.is_linked:
        link = socket.links[0]
        if link.is_muted:
            return None
        node = link.from_node
        if node.type != 'REROUTE':
            return node, link.from_socket
        socket = node.inputs[0]
    return None


def _source(scene, node, name):
    """Where input `name` reads from: ('LAYER', scene name, view layer, pass) or
    ('FILE', path, layer, pass); None for an unlinked optional input."""
    # A node made before an input existed lacks its socket: that input is unlinked.
    socket = node.inputs.get(name)
    found = _upstream(socket) if socket is not None else None
    if found is None:
        if name in REQUIRED:
            raise InputError(f"input '{name}' is not linked: connect it to the '{name}' output "
                             f"of a Render Layers node (or of a multilayer EXR Image node)")
        return None
    src, socket = found
    if src.mute:
        raise InputError(f"input '{name}' comes from the muted node '{src.name}'")
    if src.type not in ('R_LAYERS', 'IMAGE'):
        raise InputError(f"input '{name}' is linked to '{src.name}' ({src.bl_label}); Gradient "
                         f"Reconstruct reads passes straight from a Render Layers node or a "
                         f"multilayer EXR Image node (reroutes are fine, other nodes are not)")
    if socket.name not in FILM_KEYS:
        raise InputError(f"input '{name}' is linked to output '{socket.name}' of '{src.name}'; "
                         f"it must be one of the passes {', '.join(FILM_KEYS)}")
    if src.type == 'R_LAYERS':
        source_scene = src.scene or scene
        return ('LAYER', source_scene.name, src.layer, socket.name)
    image = src.image  # an Image node
    if image is None or image.type != 'MULTILAYER':
        raise InputError(f"input '{name}': Image node '{src.name}' does not hold a multilayer "
                         f"EXR")
    path = bpy.path.abspath(image.filepath, library=image.library)
    return ('FILE', os.path.normpath(path), src.layer, socket.name)


def _read_file(path, layer, pass_name):
    """Pass `pass_name` of view layer `layer` of a multilayer EXR. The four passes the node can
    use are read together and kept until the file changes (one file at a time: these are
    full-resolution float images)."""
    if not os.path.isfile(path):
        raise InputError(f"the EXR file '{path}' does not exist")
    mtime = os.path.getmtime(path)
    cached = _EXR_CACHE.get((path, layer))
    if cached is None or cached[0] != mtime:
        try:
            data = _module().read_exr_passes(path, layer, [], list(FILM_KEYS))
        except RuntimeError as e:
            raise InputError(str(e)) from None
        _EXR_CACHE.clear()
        cached = (mtime, data)
        _EXR_CACHE[(path, layer)] = cached
    if pass_name not in cached[1]:
        raise InputError(f"'{path}' has no pass '{pass_name}' in view layer '{layer}'")
    return cached[1][pass_name]


class NoCache(InputError):
    """The passes of a Render Layers input are not in memory (not rendered in this session)."""


def _array(source):
    kind, where, layer, pass_name = source
    if kind == 'LAYER':
        film = _CACHE.get((where, layer))
        if film is None:
            raise NoCache(f"no cached passes of view layer '{layer}' of scene '{where}': the "
                          f"node is solved at the next render (F12); passes are kept in memory "
                          f"for this Blender session only")
        if FILM_KEYS[pass_name] not in film:
            raise InputError(f"the last render of view layer '{layer}' of scene '{where}' has no "
                             f"pass '{pass_name}' (a G-PT render with the Feature "
                             f"reconstruction has it)")
        return film[FILM_KEYS[pass_name]]
    return _read_file(where, layer, pass_name)


def sources(scene, node):
    """{input name: source} for the linked inputs (raises InputError for a bad one)."""
    found = {}
    for name in INPUTS:
        src = _source(scene, node, name)
        if src is not None:
            found[name] = src
    return found


def _request(scene, node, threads, warm=False):
    """Everything one solve of the node needs, read from Blender on the main thread: the input
    arrays (never written to, so safe to use from another thread) and the node's settings;
    `warm`: start from the node's last L1 image when it qualifies (_warm_start). Raises
    InputError when an input cannot be read."""
    srcs = sources(scene, node)
    arrays = {name: _array(src) for name, src in srcs.items()}
    shapes = {a.shape for a in arrays.values()}
    if len(shapes) != 1:
        raise InputError("the inputs differ in resolution: "
                         + ", ".join(f"{n} {a.shape[1]}x{a.shape[0]}" for n, a in arrays.items()))
    halves = [n for n in HALF_GRADIENT_KEYS if n in arrays]
    if 0 < len(halves) < len(HALF_GRADIENT_KEYS):
        raise InputError("link all four of " + ", ".join(HALF_GRADIENT_KEYS) + " or none "
                         "(unlinked: " + ", ".join(n for n in HALF_GRADIENT_KEYS if n not in halves)
                         + ")")
    layers = {(src[1], src[2]) for src in srcs.values() if src[0] == 'LAYER'}
    cached = _CACHE.get(layers.pop(), {}) if len(layers) == 1 else {}
    features = None
    if node.norm == 'FEATURE':
        if not all(k in cached for k in FEATURE_KEYS) or \
                any(src[0] != 'LAYER' for src in srcs.values()):
            raise InputError("the Feature norm needs Render Layers inputs from a Gradient PT "
                             "render with Reconstruction set to Feature (its feature passes)")
        features = {k: cached[k] for k in FEATURE_KEYS}
        features.update({HALF_GRADIENT_KEYS[n]: np.ascontiguousarray(arrays[n], dtype=np.float32)
                         for n in halves})
    emission = arrays.get("Emission")
    request = {
        "passes": [np.ascontiguousarray(arrays[n], dtype=np.float32) for n in REQUIRED],
        "emission": None if emission is None else np.ascontiguousarray(emission, dtype=np.float32),
        "norm": node.norm, "alpha": float(node.alpha), "threads": int(threads),
        "features": features, "placement": cached.get("placement"), "mask": cached.get("alpha"),
        "initial": None, "warm_from": None}
    if warm:
        _warm_start(node, request)
    return request


def _inputs_of(request):
    return (*request["passes"], request["emission"])


def _warm_start(node, request):
    """Sets the request's initial image to the node's last L1 result when that was solved from
    the same input arrays at an alpha within WARM_ALPHA_RATIO (L1 only: the other norms are
    direct or start from L2 anyway)."""
    last = _LAST_L1.get(node.as_pointer())
    if request["norm"] != 'L1' or last is None:
        return
    inputs, alpha, rgb = last
    same = all(a is b for a, b in zip(inputs, _inputs_of(request)))
    ratio = max(alpha, request["alpha"]) / max(min(alpha, request["alpha"]), 1e-12)
    if same and ratio <= WARM_ALPHA_RATIO:
        request["initial"], request["warm_from"] = rgb, alpha


def _solve(request, progress=None):
    """The C++ solve of a request: safe off the main thread (the call releases the GIL)."""
    r = request
    variance = r["features"]["variance"] if r["features"] else None
    return _module().reconstruct(*r["passes"], variance, r["emission"], r["norm"], r["alpha"],
                                 r["threads"], features=r["features"], progress=progress,
                                 initial=r["initial"])


def _show(node, request, rgb, seconds=None):
    """Writes a solve's result into the node's image and its status line (main thread)."""
    mask = request["mask"]
    if mask is not None and mask.shape[:2] != rgb.shape[:2]:
        mask = None
    _write_image(node, rgb, request["placement"], mask)
    if request["norm"] == 'L1':
        _LAST_L1[node.as_pointer()] = (_inputs_of(request), request["alpha"], rgb)
    else:
        _LAST_L1.pop(node.as_pointer(), None)
    height, width = rgb.shape[:2]
    warm = request["warm_from"]
    _say(node, 'INFO', f"{request['norm']}, alpha {request['alpha']:g}, {width}x{height}"
                       + ("" if request["emission"] is not None else ", no Emission input")
                       + ("" if seconds is None else f", solved in {seconds:.1f} s")
                       + ("" if warm is None else f" (from the alpha {warm:g} image)"))


def reconstruct_node(scene, node, threads=0):
    """Solves the node from its inputs now and writes its image; returns the RGB result. Raises
    InputError when an input cannot be read (the image is then left untouched). A background
    re-solve of the node still running is superseded: its result is dropped."""
    request = _request(scene, node, threads)
    _supersede(node)
    rgb = _solve(request)
    _show(node, request, rgb)
    return rgb


# --- re-solves off the main thread -----------------------------------------------------------------
# A change of alpha or norm in the UI must not freeze Blender for the length of a solve (seconds
# for L1 at 1080p): the update callback reads the inputs, starts the solve in a thread (the C++
# call releases the GIL) and returns. A timer (bpy.app.timers) shows the progress on the node and,
# once the solve is done, writes the image and makes the compositor run again. One solve per node
# at a time: changes made meanwhile are coalesced into one more solve with the latest settings.

# node.as_pointer() -> _Job running for that node.
_JOBS = {}
# node.as_pointer() -> count of solves started for it: a finished job whose number is no longer
# the latest (a render or another change solved the node since) is dropped.
_GENERATION = {}
_POLL_SECONDS = 0.1


class _Job:
    def __init__(self, node, request):
        key = node.as_pointer()
        _GENERATION[key] = _GENERATION.get(key, 0) + 1
        self.key, self.generation, self.request = key, _GENERATION[key], request
        self.progress = np.zeros(1, dtype=np.float32)
        self.result = self.error = self.seconds = None
        self.again = False  # the settings changed while solving: solve once more when done
        self.started = time.monotonic()
        self.thread = threading.Thread(target=self._run, name="GDPT node solve", daemon=True)
        self.thread.start()

    def _run(self):
        try:
            self.result = _solve(self.request, self.progress)
        except Exception as e:  # reported on the node by the timer
            self.error = e
        self.seconds = time.monotonic() - self.started

    def line(self):
        r = self.request
        return (f"Solving {r['norm']}, alpha {r['alpha']:g}: {100 * float(self.progress[0]):.0f}%"
                f" ({time.monotonic() - self.started:.1f} s)")


def _supersede(node):
    key = node.as_pointer()
    _GENERATION[key] = _GENERATION.get(key, 0) + 1
    job = _JOBS.get(key)
    if job is not None:
        job.again = False


def _start(node, request):
    job = _JOBS.get(node.as_pointer())
    if job is not None and job.thread.is_alive():
        job.again = True
        return
    job = _JOBS[node.as_pointer()] = _Job(node, request)
    _say(node, 'INFO', job.line())
    if not bpy.app.timers.is_registered(_poll_jobs):
        bpy.app.timers.register(_poll_jobs, first_interval=_POLL_SECONDS, persistent=True)


def _node_by_pointer(key):
    for scene in bpy.data.scenes:
        for node in nodes_in(scene, all_trees=True):
            if node.as_pointer() == key:
                return scene, node
    return None, None


def _redraw_node_editors():
    wm = bpy.context.window_manager
    for window in wm.windows if wm is not None else ():
        for area in window.screen.areas:
            if area.type == 'NODE_EDITOR':
                area.tag_redraw()


def _finish(job):
    """A job's thread has ended: show its result, or start the coalesced next solve."""
    del _JOBS[job.key]
    scene, node = _node_by_pointer(job.key)
    if node is None:  # removed meanwhile
        return
    if job.again:
        _current()._on_setting(node, bpy.context)
    elif job.generation != _GENERATION.get(job.key):
        return
    elif job.error is not None:
        _say(node, 'ERROR', f"{job.error} (the image was not updated)")
    else:
        _show(node, job.request, job.result, job.seconds)
        # See _on_setting: makes the compositor run again with the new image.
        node.node_tree.interface_update(bpy.context)


def _poll_jobs():
    """Timer: progress lines of running solves, results of finished ones."""
    for job in list(_JOBS.values()):
        if job.thread.is_alive():
            _, node = _node_by_pointer(job.key)
            if node is not None:
                _say(node, 'INFO', job.line(), console=False)
        else:
            _finish(job)
    _redraw_node_editors()
    return _POLL_SECONDS if _JOBS else None


def wait_for_solves():
    """Blocks until every background solve (and any coalesced follow-up) is done and shown: for
    scripts and tests (a background-mode Blender runs no timers)."""
    while _JOBS:
        for job in list(_JOBS.values()):
            job.thread.join()
        _poll_jobs()


def solving(node):
    """True while a background solve of the node runs."""
    job = _JOBS.get(node.as_pointer())
    return job is not None and job.thread.is_alive()


# --- the engine's hook and the update callback --------------------------------------------------

def _threads(scene):
    settings = getattr(scene, "gdpt", None)  # absent while the add-on is disabled
    return settings.threads if settings is not None else 0


def nodes_in(scene, all_trees=False):
    """The Gradient Reconstruct nodes of the scene's compositor (when it is used)."""
    tree = scene.node_tree if scene.use_nodes or all_trees else None
    if tree is None:
        return []
    return [n for n in tree.nodes if n.bl_idname == NODE_IDNAME]


def any_node():
    return any(nodes_in(s) for s in bpy.data.scenes)


def fill_after_render(scene, view_layer_name, film, threads, warn, placement=None):
    """Called by the engine's render() with the final film of one view layer (scene: original
    datablock). Caches the passes while some scene has a Gradient Reconstruct node, then solves
    every node that reads this view layer; bad inputs of this scene's nodes are reported with
    warn(). (In PT mode the film's gradients are differences of the primal: the node then returns
    the PT image + Emission whatever its settings.) placement: see _CACHE."""
    if not any_node():
        _CACHE.clear()
        return
    key = (scene.name, view_layer_name)
    _CACHE[key] = {k: film[k] for k in FILM_KEYS.values() if k in film}
    _CACHE[key].update({k: film[k] for k in FEATURE_KEYS if k in film})
    _CACHE[key]["placement"] = placement
    _CACHE[key]["alpha"] = film.get("alpha")
    for owner in bpy.data.scenes:
        for node in nodes_in(owner):
            try:
                srcs = sources(owner, node)
                if key in {(s[1], s[2]) for s in srcs.values() if s[0] == 'LAYER'}:
                    reconstruct_node(owner, node, threads)
            except InputError as e:
                if owner != scene:
                    continue  # reported when its own scene renders
                _clear_image(node)
                _say(node, 'ERROR', str(e))
                warn(f"compositor node '{node.name}' (Gradient Reconstruct): {e}")


def _unshare():
    """Gives every node its own group and image. A copied node (Shift+D, Scene > Full Copy)
    starts out sharing the original's group: Blender 3.4 counts the users of some copies after the
    node's copy() callback, so reassigning node_tree there corrupts the user counts (measured:
    'ID user decrement error' after a Full Copy). This runs after depsgraph updates instead."""
    seen = set()
    for scene in bpy.data.scenes:
        for node in nodes_in(scene, all_trees=True):
            tree = node.node_tree
            if tree is None or tree.as_pointer() not in seen:
                if tree is not None:
                    seen.add(tree.as_pointer())
                continue
            image = node_image(node)
            width, height = image.size if image is not None else (64, 64)
            node.node_tree = _new_group(_new_image(width, height))
            seen.add(node.node_tree.as_pointer())
            try:  # same result as the original, when its inputs can be read now
                reconstruct_node(scene, node, _threads(scene))
            except InputError:
                pass


@persistent
def _depsgraph_update_post(_scene, _depsgraph=None):
    _unshare()


def _owner_scene(node):
    tree = node.id_data
    for scene in bpy.data.scenes:
        if scene.node_tree == tree:
            return scene
    return None


def _on_setting(node, context):
    scene = _owner_scene(node)
    if scene is None:
        return
    _unshare()  # a copy must not overwrite its original's image
    try:
        request = _request(scene, node, _threads(scene), warm=True)
    except NoCache as e:
        _say(node, 'WARNING', f"{e} (the image was not updated)")
        return
    except InputError as e:
        _say(node, 'ERROR', f"{e} (the image was not updated)")
        return
    _start(node, request)


@persistent
def _render_pre(scene, _depsgraph=None):
    """Nodes that read only EXR files are solved before every render: Blender does not even call
    the engine when the compositor has no Render Layers node. (Nodes reading Render Layers are
    solved by the engine; bad inputs are reported there.)"""
    for node in nodes_in(scene):
        try:
            srcs = sources(scene, node)
            if all(s[0] == 'FILE' for s in srcs.values()):
                reconstruct_node(scene, node, _threads(scene))
        except InputError as e:
            _say(node, 'ERROR', str(e))


# --- the node -------------------------------------------------------------------------------------

def _current():
    """This module as loaded now. The node class registered first in a Blender session stays
    registered across disable / enable / Reload Scripts (see unregister), so its callbacks look
    the implementation up at call time instead of binding to the module that defined them."""
    return sys.modules[__name__]


def _update_setting(node, context):
    _current()._on_setting(node, context)


def _init_node(node, context):
    r = context.scene.render if context and context.scene else None
    size = export_camera.render_resolution(r) if r else (64, 64)
    node.node_tree = _new_group(_new_image(*size))


def _draw_node(node, layout):
    layout.prop(node, "norm", expand=True)
    layout.prop(node, "alpha")
    status = _STATUS.get(node.as_pointer())
    if status is not None:
        # Wrapped to the node's width: an error message is the whole point of the line.
        level, message = status
        icon = {'ERROR': 'ERROR', 'WARNING': 'INFO'}.get(level, 'NONE')
        col = layout.column(align=True)
        for i, line in enumerate(textwrap.wrap(message, max(16, int(node.width / 7)))):
            col.label(text=line, icon=icon if i == 0 else 'BLANK1')


class GDPTReconstructNode(bpy.types.CompositorNodeCustomGroup):
    """Screened Poisson reconstruction of Gradient PT passes: solve(Primal, Gradient X,
    Gradient Y) + Emission"""
    bl_idname = NODE_IDNAME
    bl_label = "Gradient Reconstruct"
    bl_icon = 'NODE_COMPOSITING'
    bl_width_default = 180

    alpha: FloatProperty(
        name="Alpha", description="Weight of the primal image against the gradients (higher "
        "keeps more of the noisy primal)", default=0.2, min=1e-4, max=100.0, soft_max=2.0,
        update=_update_setting)
    norm: EnumProperty(
        name="Norm",
        items=[('L1', "L1", "Robust iteratively reweighted solve (fewer outliers, slightly "
                "biased)"),
               ('L2', "L2", "Unbiased screened Poisson solve (exact DCT)"),
               ('FEATURE', "Feature", "L1 filtered by feature-guided filters, chosen per pixel "
                "(Render Layers of a render with the Feature reconstruction)")],
        default='L1', update=_update_setting)

    @classmethod
    def poll(cls, tree):
        return tree.bl_idname == "CompositorNodeTree"

    def init(self, context):
        _current()._init_node(self, context)

    def free(self):
        # The group and image go with the next save / reload once nothing uses them (a copy of
        # the node may still share them); removing datablocks from a free callback is not safe.
        _current()._STATUS.pop(self.as_pointer(), None)

    def draw_buttons(self, context, layout):
        _current()._draw_node(self, layout)


class _Category(nodeitems_utils.NodeCategory):
    @classmethod
    def poll(cls, context):
        return context.space_data.tree_type == "CompositorNodeTree"


_CATEGORIES = "GDPT_COMPOSITOR_NODES"


def register():
    # Registered once per Blender session (see unregister).
    if bpy.types.Node.bl_rna_get_subclass_py(NODE_IDNAME) is None:
        bpy.utils.register_class(GDPTReconstructNode)
    # Add > Gradient PT > Gradient Reconstruct (and the node search).
    nodeitems_utils.register_node_categories(
        _CATEGORIES, [_Category("GDPT_CMP", "Gradient PT", items=[NodeItem(NODE_IDNAME)])])
    bpy.app.handlers.render_pre.append(_render_pre)
    bpy.app.handlers.depsgraph_update_post.append(_depsgraph_update_post)


def unregister():
    if _render_pre in bpy.app.handlers.render_pre:
        bpy.app.handlers.render_pre.remove(_render_pre)
    if _depsgraph_update_post in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_depsgraph_update_post)
    nodeitems_utils.unregister_node_categories(_CATEGORIES)
    # The node class is never unregistered. Blender 3.4 frees an unregistered node type but only
    # retypes the nodes of the main database: the copies of the scene in the dependency graphs
    # (the view layers', the render pipeline's) keep pointing at the freed type and crash when
    # Blender frees them: at quit (exit status 139 after a successful `blender -b ... -f 1`) or
    # at the next file load after disabling the add-on (both reproduced). So the type lives until
    # Blender exits; while the add-on is disabled, existing nodes keep their last image.
    if bpy.app.timers.is_registered(_poll_jobs):
        bpy.app.timers.unregister(_poll_jobs)
    _JOBS.clear()  # running threads end on their own; their results are dropped
    _CACHE.clear()
    _EXR_CACHE.clear()
    _STATUS.clear()
