# One timed render of the benchmark report (runs inside Blender, the add-on staged):
#   blender -b --factory-startup --addons gdpt --python render_one.py -- \
#       BLEND METHOD OUT.exr (--seconds T | --samples N) [--seed S] [--adaptive THRESHOLD [--adaptive-min N]]
#       [--shadow-caustics OBJECT] [--filter-glossy F]
# METHOD: cycles_default (Cycles as a new scene has it, but denoising off: Debian's Blender has
# no OpenImageDenoise), cycles_unbiased (the same with Filter Glossy 0 and no clamping),
# cycles_bsdf (cycles_unbiased with emissive meshes lit by BSDF rays alone: no light sampling), pt
# (Gradient PT's path tracer), gpt (Gradient PT's G-PT, no reconstruction: the report solves
# its passes with gdpt-reconstruct), gpt_feature (G-PT with the Feature reconstruction in the
# render, which computes the feature passes it needs). --adaptive: Gradient PT's adaptive sampling
# at that noise threshold (off by default, as the add-on's), --adaptive-min its Min Samples.
# --shadow-caustics: Cycles' Shadow Caustics with OBJECT the caster, every other mesh a receiver
# and every lamp a caustics light (both engines). --filter-glossy: Gradient PT's Filter Glossy
# (default 0, unbiased as the cycles_unbiased reference; the demo's own is 1.0, Cycles' default).
# Prints one line `BENCH {json}` with the render call's wall
# time; the samples reached are parsed by the caller from the engines' console lines.
import json
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "tests",
                                "blender"))
import scenes as S  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:]
blend, method, out = argv[0], argv[1], os.path.abspath(argv[2])
opts = dict(zip(argv[3::2], argv[4::2]))
seconds = float(opts.get("--seconds", 0))
samples = int(opts.get("--samples", 0))
seed = int(opts.get("--seed", 1))
adaptive = float(opts.get("--adaptive", 0))
if (seconds > 0) == (samples > 0):
    sys.exit("render_one.py: give exactly one of --seconds and --samples")

bpy.ops.wm.open_mainfile(filepath=blend)
scene = bpy.context.scene
caster = opts.get("--shadow-caustics")
if caster:
    for ob in scene.objects:
        if ob.type == 'MESH':
            ob.cycles.is_caustics_caster = ob.name == caster
            ob.cycles.is_caustics_receiver = ob.name != caster
        elif ob.type == 'LIGHT':
            ob.data.cycles.is_caustics_light = True
many = 1 << 24  # a sample count the time limit ends first
if method.startswith("cycles"):
    scene.render.engine = 'CYCLES'
    c = scene.cycles
    c.device = 'CPU'
    c.use_denoising = False
    c.seed = seed
    c.samples = samples or many
    c.time_limit = seconds
    if method in ("cycles_unbiased", "cycles_bsdf"):
        c.blur_glossy = 0.0
        c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
        # Adaptive sampling stops at its noise threshold, before small frames' budgets end: this
        # curve samples every pixel for the whole budget (the defaults' curve keeps it on).
        c.use_adaptive_sampling = False
        if method == "cycles_bsdf":  # emissive meshes found by BSDF rays only (Multiple Importance off)
            for m in bpy.data.materials:
                m.cycles.sample_as_light = False
    elif method != "cycles_default":
        sys.exit(f"render_one.py: unknown method {method}")
elif method in ("pt", "gpt", "gpt_feature"):
    scene.render.engine = 'GDPT'
    g = scene.gdpt
    g.mode = 'PT' if method == "pt" else 'GPT'
    g.reconstruction = {"pt": 'L2', "gpt": 'NONE', "gpt_feature": 'FEATURE'}[method]
    g.seed = seed
    g.samples = samples or many
    g.time_limit = seconds
    g.blur_glossy = float(opts.get("--filter-glossy", 0.0))  # 0: unbiased, as cycles_unbiased
    g.use_adaptive_sampling = adaptive > 0
    if adaptive > 0:
        g.adaptive_threshold = adaptive
        g.adaptive_min_samples = int(opts.get("--adaptive-min", 0))
else:
    sys.exit(f"render_one.py: unknown method {method}")
scene.render.use_persistent_data = False
t0 = time.perf_counter()
S.render(scene, out, multilayer=True)  # raises when nothing was written
elapsed = time.perf_counter() - t0
print("BENCH " + json.dumps({"method": method, "seconds": elapsed, "engine": scene.render.engine}),
      flush=True)
