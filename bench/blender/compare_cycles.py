# Driver of compare_cycles.sh (runs inside Blender). Prints BENCH lines.
import os
import sys
import time

import bpy
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(here, "..", "..", "tests", "blender"))
import scenes as S  # noqa: E402

RES = tuple(int(v) for v in os.environ.get("GDPT_BENCH_RES", "96x72").split("x"))
SAMPLES = int(os.environ.get("GDPT_BENCH_SAMPLES", "32"))
REF_SAMPLES = int(os.environ.get("GDPT_BENCH_REF_SAMPLES", "512"))
BOUNCES = int(os.environ.get("GDPT_BENCH_BOUNCES", "4"))
# The reference renders, whose timing gives the marginal rates, are repeated this many times
# with the engines alternating; the median time counts. A single ~2 s render moved Cycles' rate
# by +-12% between runs on this shared machine.
REPEATS = int(os.environ.get("GDPT_BENCH_REPEATS", "3"))
# Min Light Bounces (Russian roulette may end a path only after that many bounces past the first
# indirect hit) of the comparisons, one comparison per entry: a number sets both engines to it
# (the same termination rule, q = min(sqrt(max throughput), 1), from the same vertex); "defaults"
# leaves each engine at its own default (Cycles 0, GDPT 2). Paths that end later cost more per
# sample and have less noise per sample, so samples/s ratios only compare like with like at
# equal settings.
MIN_LIGHT_BOUNCES = os.environ.get("GDPT_BENCH_MIN_LIGHT_BOUNCES", "0,2,defaults").split(",")
# Cycles' sampling pattern: its default Progressive Multi-Jitter, or SOBOL.
CYCLES_PATTERN = os.environ.get("GDPT_BENCH_CYCLES_PATTERN", "PROGRESSIVE_MULTI_JITTER")


def cornell(scene):
    S.room()
    S.camera((0, -5.5, 2.0), (0, 0, 1.7), lens=30)
    S.light('AREA', (0, 0, 3.95), 150.0, target=(0, 0, 0), size=1.0)
    S.uv_sphere("a", 0.7, (-0.8, 0.2, 0.7), S.diffuse("a", (0.8, 0.8, 0.8)))
    S.uv_sphere("b", 0.7, (0.8, 0.6, 0.7), S.glossy("b", 0.3))


def textured(scene):
    cornell(scene)
    img = bpy.data.images.new("grid", 256, 256)
    img.generated_type = 'COLOR_GRID'
    back = bpy.data.objects["back"]
    back.data.materials.clear()
    back.data.materials.append(S.image_material("tex", img))
    floor = bpy.data.objects["floor"]
    floor.data.materials.clear()
    floor.data.materials.append(S.image_material("tex2", img))


def render(scene, engine, samples, path, min_bounces, seed=1):
    if engine == 'GDPT':
        S.setup_gdpt(scene, samples, mode='PT', reconstruction='NONE', bounces=BOUNCES, seed=seed)
        if min_bounces != "defaults":
            scene.gdpt.min_light_bounces = int(min_bounces)
    else:
        S.setup_cycles(scene, samples, bounces=BOUNCES, seed=seed)
        scene.cycles.sampling_pattern = CYCLES_PATTERN
        if min_bounces != "defaults":
            scene.cycles.min_light_bounces = int(min_bounces)
    scene.render.resolution_x, scene.render.resolution_y = RES
    t0 = time.perf_counter()
    S.render(scene, path)
    return time.perf_counter() - t0, S.read_rgb(path)


def compare(name, build, out, min_bounces):
    import gdpt.engine as engine
    scene = S.clear()
    build(scene)
    row = {}
    # A 1-spp render per engine first: one-time costs of the first render of a scene in the
    # process (OpenColorIO config and processors, Cycles' device and kernels) are not per-render
    # costs, and would otherwise land in the fixed cost of the 32-spp render below.
    first = {eng: render(scene, eng, 1, os.path.join(out, f"{name}_{eng}_warm.exr"),
                         min_bounces)[0]
             for eng in ('GDPT', 'CYCLES')}
    rays = 0.0
    low = {}
    for eng in ('GDPT', 'CYCLES'):
        t, img = render(scene, eng, SAMPLES, os.path.join(out, f"{name}_{eng}_{SAMPLES}.exr"),
                        min_bounces)
        render_only = engine.LAST_RENDER["render"] if eng == 'GDPT' else t
        if eng == 'GDPT':
            rays = engine.LAST_RENDER["rays"] / (RES[0] * RES[1] * SAMPLES)
        low[eng] = (t, render_only, img)
    ref_times = {'GDPT': [], 'CYCLES': []}
    refs = {}
    for _ in range(max(1, REPEATS)):
        for eng in ('GDPT', 'CYCLES'):
            t_ref, refs[eng] = render(scene, eng, REF_SAMPLES,
                                      os.path.join(out, f"{name}_{eng}_ref.exr"), min_bounces)
            ref_times[eng].append(t_ref)
    for eng in ('GDPT', 'CYCLES'):
        t, render_only, img = low[eng]
        t_ref = float(np.median(ref_times[eng]))
        row[eng] = (t, render_only, S.rel_mse(img, refs[eng]), refs[eng], t_ref)
    pixels = RES[0] * RES[1] * SAMPLES
    g, c = row['GDPT'], row['CYCLES']
    cross = S.rel_mse(g[3], c[3])
    setting = ("each engine's default (GDPT 2, Cycles 0)" if min_bounces == "defaults"
               else f"{min_bounces} in both engines")
    print(f"BENCH {name}: {RES[0]}x{RES[1]}, {SAMPLES} spp, {BOUNCES} bounces, min light bounces "
          f"{setting}; Cycles pattern {CYCLES_PATTERN}")
    print(f"  GDPT PT : {g[0]:.2f} s wall ({g[1]:.2f} s render) = {pixels / g[0] / 1e6:.3f} "
          f"Msamples/s wall; relMSE vs own {REF_SAMPLES} spp: {g[2]:.5f}; {rays:.2f} rays per "
          f"sample (camera, extension and shadow rays)")
    print(f"  Cycles  : {c[0]:.2f} s wall = {pixels / c[0] / 1e6:.3f} Msamples/s; relMSE vs "
          f"own {REF_SAMPLES} spp: {c[2]:.5f}")
    print(f"  samples/s ratio GDPT/Cycles (wall): {c[0] / g[0]:.2f}x; relMSE ratio "
          f"GDPT/Cycles: {g[2] / max(c[2], 1e-12):.2f}; references differ by relMSE {cross:.5f}")
    # Each render's wall time includes fixed costs (Blender's render setup, sync, BVH, image
    # write) that weigh heavily at this small size. The marginal rate between the two sample
    # counts each engine rendered cancels them: the throughput of the sampling itself.
    extra = RES[0] * RES[1] * (REF_SAMPLES - SAMPLES)
    mg, mc = extra / max(g[4] - g[0], 1e-9), extra / max(c[4] - c[0], 1e-9)
    # Work-normalised noise: relMSE x time per sample (marginal), lower is better. Unlike the
    # samples/s ratio it does not depend on how much work each engine puts into one sample
    # (e.g. where Russian roulette starts).
    efficiency = (c[2] / mc) / max(g[2] / mg, 1e-30)
    spread = {e: (min(ts), max(ts)) for e, ts in ref_times.items()}
    print(f"  {REF_SAMPLES}-spp render times, {len(ref_times['GDPT'])} alternating runs: GDPT "
          f"{spread['GDPT'][0]:.2f}-{spread['GDPT'][1]:.2f} s, Cycles {spread['CYCLES'][0]:.2f}-"
          f"{spread['CYCLES'][1]:.2f} s (medians used)")
    print(f"  marginal samples/s ({SAMPLES} -> {REF_SAMPLES} spp): GDPT {mg / 1e6:.3f} M, "
          f"Cycles {mc / 1e6:.3f} M: ratio {mg / mc:.2f}x; fixed cost per render GDPT "
          f"{g[0] - RES[0] * RES[1] * SAMPLES / mg:.2f} s, Cycles "
          f"{c[0] - RES[0] * RES[1] * SAMPLES / mc:.2f} s (first 1-spp render of the scene: "
          f"GDPT {first['GDPT']:.2f} s, Cycles {first['CYCLES']:.2f} s)")
    # The ratio of each alternating pair of reference renders (GDPT then Cycles, seconds apart):
    # how far the machine's drift moves the ratio within this run.
    pairs = [(tc - c[0]) / max(tg - g[0], 1e-9)
             for tg, tc in zip(ref_times['GDPT'], ref_times['CYCLES'])]
    # Their median: each pair's two renders ran seconds apart, so drift of the machine's speed
    # over the run moves it less than the ratio of the two engines' median times above.
    print(f"  marginal ratio of each alternating pair: {min(pairs):.2f}x-{max(pairs):.2f}x, "
          f"median {float(np.median(pairs)):.2f}x")
    print(f"  efficiency 1 / (relMSE x marginal time per sample), GDPT/Cycles: {efficiency:.2f}x")


def export_and_overhead(out):
    import gdpt.engine as engine
    scene = S.clear()
    S.camera((0, -3, 3), (0, 0, 0), lens=35)
    S.light('SUN', (0, 0, 5), 3.0)
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=708, y_subdivisions=708, size=4)
    grid = bpy.context.active_object
    grid.data.polygons.foreach_set("use_smooth", [True] * len(grid.data.polygons))
    grid.data.update()
    S.setup_gdpt(scene, 1, mode='PT', reconstruction='NONE', bounces=1)
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    t0 = time.perf_counter()
    S.render(scene, os.path.join(out, "million.exr"))
    wall = time.perf_counter() - t0
    info = engine.LAST_RENDER
    print(f"BENCH export: {info['triangles']} triangles exported in {info['export']:.3f} s "
          f"(target < 0.5 s; CPU time of Blender's thread {info['export_cpu']:.3f} s)")
    print(f"  render() total {info['total']:.3f} s: export {info['export']:.3f} s, core scene "
          f"setup (BVH, lights) {info['setup']:.3f} s, 1 spp {info['render']:.3f} s, "
          f"reconstruct {info['reconstruct']:.3f} s, "
          f"write {info['write']:.3f} s; operator wall {wall:.3f} s")
    # Add-on overhead on an ordinary scene: everything in render() that is not the core render.
    scene = S.clear()
    cornell(scene)
    S.setup_gdpt(scene, SAMPLES, mode='GPT', reconstruction='L1', bounces=BOUNCES)
    scene.render.resolution_x, scene.render.resolution_y = RES
    S.render(scene, os.path.join(out, "overhead.exr"))
    info = engine.LAST_RENDER
    overhead = info['total'] - info['render'] - info['setup']
    print(f"BENCH overhead (Cornell box G-PT {SAMPLES} spp {RES[0]}x{RES[1]}): render() "
          f"{info['total']:.3f} s, core setup {info['setup']:.3f} s + render {info['render']:.3f} s,"
          f" add-on overhead "
          f"{overhead:.3f} s ({100 * overhead / info['total']:.1f}%: export {info['export']:.3f},"
          f" reconstruct L1 {info['reconstruct']:.3f}, write {info['write']:.3f})")


def main():
    out = S.args()["out"]
    os.makedirs(out, exist_ok=True)
    for min_bounces in MIN_LIGHT_BOUNCES:
        compare("cornell", cornell, out, min_bounces)
        compare("textured", textured, out, min_bounces)
    export_and_overhead(out)


if __name__ == "__main__":  # run by Blender; relmse_seeds.py imports the scenes and render()
    main()
