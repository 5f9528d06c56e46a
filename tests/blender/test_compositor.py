# The compositor node "Gradient Reconstruct" (blender_addon/gdpt/compositor_node.py):
#  - farm command line: a .blend with Render Layers -> Gradient Reconstruct (L1, alpha 0.05) ->
#    Composite, rendered by `blender -b scene.blend -E GDPT -f 1` into a multilayer EXR: the
#    engine's console lines are there, Blender exits 0, and the EXR's Composite layer equals the
#    gdpt-reconstruct CLI run on the same EXR's passes with the node's settings;
#  - in this session, L2 with alpha 0.05 and 1.0 and L1 with alpha 1.0 (Emission through a
#    reroute): the composite equals the C++ reconstruction (`_gdpt.reconstruct`) of the render's
#    own passes read back from the EXR, and the node's alpha and norm really change the image;
#  - the node's settings, not the engine's (scene.gdpt.reconstruction L1 / alpha 0.2), are used;
#  - a node with unlinked Gradient X / Y: a warning naming the input, a finished render, and a
#    black (not stale) node output;
#  - tweaking alpha / norm after the render re-solves from the cached passes (the node's image
#    equals the reconstruction with the new settings); without cached passes the node says so
#    and leaves its image alone;
#  - that re-solve runs in a background thread: on passes enlarged to 512x384 (L1), setting alpha
#    returns in a small fraction of the solve's time with the image not yet changed and a
#    "Solving" progress line on the node; once done, the image equals the synchronous solve of
#    the same passes; two quick changes are coalesced into the last one;
#  - an L1 alpha tweak of at most 2x starts from the node's last L1 image (its status says so)
#    and lands within 0.5% of the cold solve in the mean; a 6x jump solves cold;
#  - a copied node owns its image (tweaking the copy leaves the original alone);
#  - two view layers: each node solves the layer its Render Layers node names;
#  - a multilayer EXR Image node as the source (read through the module's OpenImageIO reader),
#    also at render time when Blender does not call the engine (no Render Layers node);
#  - disabling the add-on with the node in a rendered scene, then loading another file, and
#    quitting: no crash (exit status 0).
import math
import os
import subprocess
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import exr  # noqa: E402
import scenes as S  # noqa: E402

check = S.check

SAMPLES = 16
NODE = "CompositorNodeGDPTReconstruct"
WARM_MEAN_DIFF = 0.005  # a warm L1 image against the cold solve at the same alpha, in the mean


def build(scene):
    S.room()
    S.camera((0, -5.5, 2.0), (0, 0, 1.8), lens=28)
    # A camera-visible emitter fills Emission: the node must add it back.
    S.plane("panel", 1.2, (0, 0, 3.9), (math.pi, 0, 0), S.emission("panel", (1, 0.9, 0.8), 5.0))
    S.uv_sphere("ball", 0.7, (0.4, 0.3, 0.7), S.diffuse("ball", (0.8, 0.8, 0.8)), 24, 12)
    S.setup_gdpt(scene, SAMPLES, mode='GPT', reconstruction='L1')  # the engine's own: L1, 0.2


def compositor(scene, link_gradients=True):
    """Render Layers -> Gradient Reconstruct -> Composite (Emission through a reroute)."""
    scene.use_nodes = True
    tree = scene.node_tree
    for n in list(tree.nodes):
        tree.nodes.remove(n)
    rl = tree.nodes.new("CompositorNodeRLayers")
    node = tree.nodes.new(NODE)
    comp = tree.nodes.new("CompositorNodeComposite")
    reroute = tree.nodes.new("NodeReroute")
    tree.links.new(rl.outputs["Primal"], node.inputs["Primal"])
    if link_gradients:
        tree.links.new(rl.outputs["Gradient X"], node.inputs["Gradient X"])
        tree.links.new(rl.outputs["Gradient Y"], node.inputs["Gradient Y"])
    tree.links.new(rl.outputs["Emission"], reroute.inputs[0])
    tree.links.new(reroute.outputs[0], node.inputs["Emission"])
    tree.links.new(node.outputs["Image"], comp.inputs["Image"])
    return node


def render(scene, path, engine_runs=True):
    import gdpt.engine as engine
    engine.LAST_RENDER.clear()
    S.render(scene, path, multilayer=True)
    info = engine.LAST_RENDER
    if engine_runs:
        check(info.get("status") == "finished" and info.get("samples") == SAMPLES,
              f"Gradient PT rendered {info.get('samples')}/{SAMPLES} samples "
              f"({info.get('status')})")
    return exr.read_exr(path), info


def layer_rgb(ch, layer, name):
    return np.ascontiguousarray(exr.rgb(ch, f"{layer}.{name}."))


def solve(ch, norm, alpha):
    """The C++ reconstruction (same library as the engine and the CLI) of the EXR's passes."""
    from gdpt import _gdpt
    get = lambda name: layer_rgb(ch, "ViewLayer", name)  # noqa: E731
    return _gdpt.reconstruct(get("Primal"), get("Gradient X"), get("Gradient Y"), None,
                             get("Emission"), norm, alpha)


def max_rel_diff(a, b):
    return float(np.abs(a - b).max() / max(1.0, np.abs(b).max()))


def node_pixels(node):
    from gdpt import compositor_node
    image = compositor_node.node_image(node)
    px = np.empty(len(image.pixels), dtype=np.float32)
    image.pixels.foreach_get(px)
    return px.reshape(image.size[1], image.size[0], 4)


def test_command_line(out, build_dir):
    """`blender -b scene.blend -E GDPT -f 1`, as a farm runs it; L1, alpha 0.05 against the CLI."""
    scene = S.clear()
    build(scene)
    node = compositor(scene)
    node.norm, node.alpha = 'L1', 0.05
    s = scene.render.image_settings
    s.file_format, s.color_depth, s.exr_codec = 'OPEN_EXR_MULTILAYER', '32', 'ZIP'
    scene.render.use_file_extension = True
    scene.render.filepath = os.path.join(out, "farm_")
    blend = os.path.join(out, "compositor.blend")
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    exr_path = os.path.join(out, "farm_0001.exr")
    if os.path.exists(exr_path):
        os.remove(exr_path)
    run = subprocess.run([bpy.app.binary_path, "-b", "--factory-startup", "--addons", "gdpt",
                          blend, "-E", "GDPT", "-f", "1"], capture_output=True, text=True,
                         timeout=240)
    log = run.stdout + run.stderr
    if run.returncode != 0:
        print(log)
    check(run.returncode == 0, f"blender -b ... -E GDPT -f 1 exits 0 (got {run.returncode})")
    check(f"GDPT: view layer 'ViewLayer' finished: {SAMPLES}/{SAMPLES} samples" in log,
          "the Gradient PT engine rendered (its console line)")
    check("Gradient Reconstruct 'Gradient Reconstruct': L1, alpha 0.05, 64x48" in log,
          "the node solved with its own settings (its console line)")
    ch = exr.read_exr(exr_path)
    composite = exr.rgb(ch, "Composite.Combined.")
    cli = os.path.join(build_dir, "reconstruct", "gdpt-reconstruct")
    cli_out = os.path.join(out, "farm_cli.exr")
    subprocess.run([cli, exr_path, "-o", cli_out, "--norm", "l1", "--alpha", "0.05", "--layer",
                    "ViewLayer"], check=True)
    ref = exr.rgb(exr.read_exr(cli_out), "")
    err = max_rel_diff(composite, ref)
    check(err < 1e-4, f"composite = gdpt-reconstruct --norm l1 --alpha 0.05 on the same passes "
                      f"(max abs diff / max {err:.2e})")
    engine_combined = layer_rgb(ch, "ViewLayer", "Combined")
    check(max_rel_diff(composite, engine_combined) > 1e-3,
          "the node's settings, not the engine's (L1, alpha 0.2), made the composite")
    return exr_path


def test_render_layers(out):
    scene = S.clear()
    build(scene)
    scene.render.resolution_percentage = 50  # the node's image starts at 32x24: it must follow
    node = compositor(scene)
    scene.render.resolution_percentage = 100
    results = {}
    for norm, alpha in (('L2', 0.05), ('L2', 1.0), ('L1', 1.0)):
        node.norm, node.alpha = norm, alpha
        ch, info = render(scene, os.path.join(out, f"rl_{norm}_{alpha}.exr"))
        check(not info["warnings"], f"no warnings ({info['warnings']})")
        composite = exr.rgb(ch, "Composite.Combined.")
        check(np.all(ch["Composite.Combined.A"] == 1.0), "composite alpha = 1")
        ref = solve(ch, norm, alpha)
        err = max_rel_diff(composite, ref)
        check(err < 1e-4, f"{norm} alpha {alpha}: composite = C++ reconstruction of the render's "
                          f"passes (max abs diff / max {err:.2e})")
        check(composite.mean() > 0.05, f"the composite is lit (mean {composite.mean():.3f})")
        results[(norm, alpha)] = (composite, ch)
    a, b = results[('L2', 0.05)][0], results[('L2', 1.0)][0]
    diff = float(np.abs(a - b).mean())
    check(diff > 5e-3, f"alpha 0.05 and 1.0 give different images (mean abs diff {diff:.4f})")
    # Alpha weights the noisy primal: alpha 1 stays closer to Primal + Emission than alpha 0.05.
    ch = results[('L2', 1.0)][1]
    noisy = layer_rgb(ch, "ViewLayer", "Primal") + layer_rgb(ch, "ViewLayer", "Emission")
    d1, d005 = (float(np.abs(x - noisy).mean()) for x in (b, a))
    check(d1 < d005, f"alpha 1 keeps more of the primal ({d1:.4f} < {d005:.4f})")
    l1 = results[('L1', 1.0)][0]
    check(float(np.abs(l1 - b).mean()) > 1e-3, "L1 and L2 differ")
    return scene, node, ch


def test_update_from_cache(scene, node, ch):
    """After the last render (L1, alpha 1): tweak the node, as an artist does in the UI."""
    from gdpt import compositor_node
    before = node_pixels(node)
    node.alpha = 0.3  # the update callback re-solves from the cached passes
    compositor_node.wait_for_solves()
    px = node_pixels(node)
    err = max_rel_diff(px[..., :3], solve(ch, 'L1', 0.3))
    check(err < 1e-4, f"alpha 1 -> 0.3 re-solves from the cache (L1; max rel diff {err:.2e})")
    check(float(np.abs(px - before).mean()) > 1e-3, "the node's image changed")
    node.norm = 'L2'
    compositor_node.wait_for_solves()
    px = node_pixels(node)
    err = max_rel_diff(px[..., :3], solve(ch, 'L2', 0.3))
    check(err < 1e-4, f"norm L1 -> L2 re-solves from the cache (max rel diff {err:.2e})")
    level, message = compositor_node._STATUS[node.as_pointer()]
    check(level == 'INFO' and "L2, alpha 0.3" in message, f"node status: '{message}'")

    # A scene that was never rendered has no cached passes: the node says so.
    fresh = bpy.data.scenes.new("Fresh")
    fresh.render.resolution_x, fresh.render.resolution_y = S.WIDTH, S.HEIGHT
    fresh.render.resolution_percentage = 100
    fresh.use_nodes = True
    tree = fresh.node_tree
    rl = tree.nodes.get("Render Layers") or tree.nodes.new("CompositorNodeRLayers")
    rl.scene = fresh  # a new node refers to the active scene
    other = tree.nodes.new(NODE)
    for name in ("Primal", "Gradient X", "Gradient Y"):
        tree.links.new(rl.outputs[name], other.inputs[name])
    image_before = node_pixels(other).copy()
    other.alpha = 0.5
    level, message = compositor_node._STATUS[other.as_pointer()]
    check(level == 'WARNING' and "no cached passes" in message and "'Fresh'" in message,
          f"no cache is reported on the node: '{message}'")
    check(np.array_equal(node_pixels(other), image_before), "and its image is left alone")
    fresh.use_nodes = False


def test_background_resolve(scene, node):
    """A change of alpha returns at once; the solve runs in a thread and its image, once shown,
    equals the synchronous solve. Run on the cached passes enlarged 8x (512x384) so that the L1
    solve takes long enough to be seen running."""
    from gdpt import _gdpt, compositor_node
    key = (scene.name, "ViewLayer")
    saved = dict(compositor_node._CACHE[key])
    big = {k: np.ascontiguousarray(np.tile(v, (8, 8, 1))) for k, v in saved.items()
           if isinstance(v, np.ndarray) and v.ndim == 3 and v.shape[2] == 3}
    compositor_node._CACHE[key].update(big)
    compositor_node._CACHE[key]["alpha"] = None
    compositor_node._CACHE[key]["placement"] = None
    try:
        node.norm, node.alpha = 'L1', 0.5
        compositor_node.wait_for_solves()
        before = node_pixels(node).copy()
        start = time.monotonic()
        node.alpha = 0.15  # more than WARM_ALPHA_RATIO away: a cold solve, long enough to see
        returned = time.monotonic() - start
        job = compositor_node._JOBS[node.as_pointer()]
        running = compositor_node.solving(node)
        unchanged = np.array_equal(node_pixels(node), before)
        line = compositor_node._STATUS[node.as_pointer()][1]
        compositor_node.wait_for_solves()
        check(running and unchanged, f"setting alpha returned in {returned * 1e3:.0f} ms with the "
                                     f"solve still running and the image unchanged")
        check(returned < 0.2 * job.seconds, f"the setter took {returned * 1e3:.0f} ms, the "
                                            f"background solve {job.seconds * 1e3:.0f} ms")
        check(line.startswith("Solving L1, alpha 0.15"), f"progress line while solving: '{line}'")
        check(float(job.progress[0]) == 1.0, "the progress slot reached 1")
        ref = _gdpt.reconstruct(big["primal"], big["gradient_x"], big["gradient_y"], None,
                                big["emission"], 'L1', 0.15)
        px = node_pixels(node)
        check(px.shape[:2] == ref.shape[:2] and np.array_equal(px[..., :3], ref),
              "the image shown after the background solve equals the synchronous solve")
        level, message = compositor_node._STATUS[node.as_pointer()]
        check(level == 'INFO' and "L1, alpha 0.15" in message and "solved in" in message
              and "from the alpha" not in message, f"status after the solve: '{message}'")
        # Two changes while solving: one follow-up solve with the last settings.
        node.alpha = 0.6
        node.alpha = 0.7
        compositor_node.wait_for_solves()
        ref = _gdpt.reconstruct(big["primal"], big["gradient_x"], big["gradient_y"], None,
                                big["emission"], 'L1', 0.7)
        check(np.array_equal(node_pixels(node)[..., :3], ref), "quick changes end on the last one")
    finally:
        compositor_node._CACHE[key] = saved
        node.norm, node.alpha = 'L2', 0.3  # as test_update_from_cache left it
        compositor_node.wait_for_solves()


def test_warm_start(node, ch):
    """An L1 alpha tweak within WARM_ALPHA_RATIO starts from the node's last L1 image (the
    library's short warm schedule) and lands close to the cold solve; a larger jump, or new
    passes, solves cold."""
    from gdpt import compositor_node
    node.norm, node.alpha = 'L1', 0.4
    compositor_node.wait_for_solves()
    err = max_rel_diff(node_pixels(node)[..., :3], solve(ch, 'L1', 0.4))
    check(err < 1e-4, f"L2 -> L1 at alpha 0.4 solves cold ({err:.2e})")
    node.alpha = 0.3
    compositor_node.wait_for_solves()
    message = compositor_node._STATUS[node.as_pointer()][1]
    check("from the alpha 0.4 image" in message, f"alpha 0.4 -> 0.3 starts warm: '{message}'")
    cold = solve(ch, 'L1', 0.3)
    px = node_pixels(node)[..., :3]
    rel = float(np.abs(px - cold).mean() / np.abs(cold).mean())
    check(0.0 < rel < WARM_MEAN_DIFF, f"the warm image is within {WARM_MEAN_DIFF:.1%} of the "
                                      f"cold solve's in the mean ({rel:.3%})")
    node.alpha = 0.05
    compositor_node.wait_for_solves()
    message = compositor_node._STATUS[node.as_pointer()][1]
    err = max_rel_diff(node_pixels(node)[..., :3], solve(ch, 'L1', 0.05))
    check(err < 1e-4 and "from the alpha" not in message,
          f"alpha 0.3 -> 0.05 (6x) solves cold ({err:.2e}, '{message}')")
    node.norm, node.alpha = 'L2', 0.3  # as test_update_from_cache left it
    compositor_node.wait_for_solves()


def test_copy_owns_its_image(scene, node, ch):
    """A copied node (a scene copy here; Shift+D alike) gets its own image: tweaking the
    copy leaves the original's result alone."""
    from gdpt import compositor_node
    original = node_pixels(node).copy()
    bpy.context.window.scene = scene
    bpy.ops.scene.new(type='FULL_COPY')
    copy_scene = bpy.context.scene
    copy = next(n for n in copy_scene.node_tree.nodes if n.bl_idname == NODE)
    copy_scene.node_tree.nodes["Render Layers"].scene = scene  # read the rendered passes
    copy.alpha = 0.9
    compositor_node.wait_for_solves()
    check(compositor_node.node_image(copy) != compositor_node.node_image(node),
          "the copy has its own image")
    err = max_rel_diff(node_pixels(copy)[..., :3], solve(ch, copy.norm, 0.9))
    check(err < 1e-4, f"the copy solved with its own alpha 0.9 ({err:.2e})")
    check(np.array_equal(node_pixels(node), original), "the original's image is unchanged")
    bpy.context.window.scene = scene
    # Kept with its compositor off. (After any scene copy, Blender 3.4 logs "Deleting OB... which
    # still has 1 users" when the next test clears the objects; seen without the add-on's node
    # too, harmless.)
    copy_scene.use_nodes = False


def test_two_view_layers(out):
    """Each node solves the view layer its Render Layers node names (render() runs per layer)."""
    scene = S.clear()
    build(scene)
    coll = bpy.data.collections.new("Sphere")
    scene.collection.children.link(coll)
    ball = scene.objects["ball"]
    scene.collection.objects.unlink(ball)
    coll.objects.link(ball)
    second = scene.view_layers.new("Second")
    second.layer_collection.children["Sphere"].exclude = True  # the layers differ
    node = compositor(scene)
    node.norm, node.alpha = 'L2', 0.2
    tree = scene.node_tree
    rl2 = tree.nodes.new("CompositorNodeRLayers")
    rl2.layer = "Second"
    other = tree.nodes.new(NODE)
    other.norm, other.alpha = 'L2', 0.2
    for name in ("Primal", "Gradient X", "Gradient Y", "Emission"):
        tree.links.new(rl2.outputs[name], other.inputs[name])
    ch, _ = render(scene, os.path.join(out, "two_layers.exr"))
    from gdpt import _gdpt
    for n, layer in ((node, "ViewLayer"), (other, "Second")):
        get = lambda name: layer_rgb(ch, layer, name)  # noqa: E731
        ref = _gdpt.reconstruct(get("Primal"), get("Gradient X"), get("Gradient Y"), None,
                                get("Emission"), 'L2', 0.2)
        err = max_rel_diff(node_pixels(n)[..., :3], ref)
        check(err < 1e-4, f"node reading '{layer}' = L2 solve of that layer's passes ({err:.2e})")
    diff = float(np.abs(node_pixels(node) - node_pixels(other)).max())
    check(diff > 1e-3, f"the two layers' solves differ (max diff {diff:.3f})")


def test_unlinked_inputs(out):
    import gdpt.engine as engine
    scene = S.clear()
    build(scene)
    node = compositor(scene, link_gradients=False)
    node.norm, node.alpha = 'L2', 0.2
    ch, info = render(scene, os.path.join(out, "unlinked.exr"))
    warnings = [w for w in info["warnings"] if "Gradient Reconstruct" in w]
    print("\n".join(warnings))
    check(len(warnings) == 1 and "input 'Gradient X' is not linked" in warnings[0],
          "one warning names the unlinked input")
    check(engine.LAST_RENDER["status"] == "finished", "the render finished")
    composite = exr.rgb(ch, "Composite.Combined.")
    check(np.all(composite == 0.0), "the node outputs black, not a stale image")
    check(layer_rgb(ch, "ViewLayer", "Combined").mean() > 0.05, "the passes were still written")

    # A node between the pass and the input cannot be evaluated by the add-on: said so, by name.
    from gdpt import compositor_node
    tree = scene.node_tree
    rl = tree.nodes["Render Layers"]
    for name in ("Gradient X", "Gradient Y"):
        tree.links.new(rl.outputs[name], node.inputs[name])
    blur = tree.nodes.new("CompositorNodeBlur")
    blur.name = "My Blur"
    tree.links.new(rl.outputs["Primal"], blur.inputs["Image"])
    tree.links.new(blur.outputs["Image"], node.inputs["Primal"])
    node.alpha = 0.3
    level, message = compositor_node._STATUS[node.as_pointer()]
    check(level == 'ERROR' and "'My Blur' (Blur)" in message and "input 'Primal'" in message,
          f"an input fed through a Blur node is reported: '{message}'")


def test_exr_image_node(out, exr_path):
    """A multilayer EXR loaded in an Image node feeds the node (no render needed to tweak it)."""
    from gdpt import compositor_node
    scene = S.clear()
    build(scene)
    scene.use_nodes = True
    tree = scene.node_tree
    for n in list(tree.nodes):
        tree.nodes.remove(n)
    image = bpy.data.images.load(exr_path)
    src = tree.nodes.new("CompositorNodeImage")
    src.image = image
    src.layer = "ViewLayer"
    node = tree.nodes.new(NODE)
    comp = tree.nodes.new("CompositorNodeComposite")
    for name in ("Primal", "Gradient X", "Gradient Y", "Emission"):
        tree.links.new(src.outputs[name], node.inputs[name])
    tree.links.new(node.outputs["Image"], comp.inputs["Image"])
    node.norm = 'L2'
    node.alpha = 0.4  # update: reads the file
    compositor_node.wait_for_solves()
    ch = exr.read_exr(exr_path)
    err = max_rel_diff(node_pixels(node)[..., :3], solve(ch, 'L2', 0.4))
    check(err < 1e-4, f"EXR Image node: the node's image = L2 solve of the file (max rel diff "
                      f"{err:.2e})")
    # F12 with only a file source: Blender composites without calling the engine; the node is
    # solved before the render (render_pre). The ID property write skips the update callback,
    # so only that path can bring alpha 0.1 into the composite.
    node["alpha"] = 0.1
    rendered, info = render(scene, os.path.join(out, "from_exr.exr"), engine_runs=False)
    check(not info, "no Render Layers node: Blender did not call the engine")
    err = max_rel_diff(exr.rgb(rendered, "Composite.Combined."), solve(ch, 'L2', 0.1))
    check(err < 1e-4, f"EXR Image node at render time: composite = L2 alpha 0.1 solve of the "
                      f"file ({err:.2e})")


def test_disable_with_nodes():
    """Disabling the add-on while a rendered scene holds the node, then loading another file:
    Blender 3.4 crashed here (SIGSEGV) when the node type was unregistered, because dependency
    graph copies of the scene still pointed at the freed type. The test process must survive it
    and then quit cleanly (the quit path crashed the same way)."""
    import addon_utils
    check(any(n.bl_idname == NODE for n in bpy.context.scene.node_tree.nodes),
          "the current scene holds a Gradient Reconstruct node")
    bpy.context.evaluated_depsgraph_get()
    addon_utils.disable("gdpt")
    bpy.ops.wm.read_factory_settings()
    check(True, "disabling the add-on and loading another file did not crash Blender")


def main():
    a = S.args()
    out = a["out"]
    os.makedirs(out, exist_ok=True)
    exr_path = test_command_line(out, a["build"])
    scene, node, ch = test_render_layers(out)
    test_update_from_cache(scene, node, ch)
    test_background_resolve(scene, node)
    test_warm_start(node, ch)
    test_copy_owns_its_image(scene, node, ch)
    test_two_view_layers(out)
    test_unlinked_inputs(out)
    test_exr_image_node(out, exr_path)
    test_disable_with_nodes()  # last: it unloads the add-on
    print("ALL COMPOSITOR CHECKS PASSED", flush=True)


main()
