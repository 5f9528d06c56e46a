# What the add-on's updates cost at full HD: compare_cycles.py's Cornell box at 1920x1080, PT,
# 16 spp, rendered with progressive previews every 3 s (the default Preview Interval, as in the
# UI: GDPT_PREVIEWS_IN_BACKGROUND=1) and as a background render (no previews), alternating, in
# one Blender process; then 1-spp renders for the fixed costs around the core's render (film
# set-up, read-out, write). Prints the engine's own timings (LAST_RENDER).
#   BLENDER_USER_SCRIPTS=<staged add-on> blender -b --factory-startup --addons gdpt \
#     --python bench/blender/update_cost.py
# Knobs (environment): GDPT_BENCH_UPDATE_RES (1920x1080), GDPT_BENCH_UPDATE_SAMPLES (16),
# GDPT_BENCH_UPDATE_REPEATS (2: renders per interval), GDPT_BENCH_UPDATE_MODE (PT, or GPT: then
# the final image is an L1 solve and every preview an L2 solve).
import os
import sys
import tempfile

here = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, here)
sys.path.insert(0, os.path.join(here, "..", "..", "tests", "blender"))
import compare_cycles as C  # noqa: E402
import scenes as S  # noqa: E402

RES = tuple(int(v) for v in os.environ.get("GDPT_BENCH_UPDATE_RES", "1920x1080").split("x"))
SAMPLES = int(os.environ.get("GDPT_BENCH_UPDATE_SAMPLES", "16"))
REPEATS = int(os.environ.get("GDPT_BENCH_UPDATE_REPEATS", "2"))
MODE = os.environ.get("GDPT_BENCH_UPDATE_MODE", "PT")


def render(scene, path, samples, previews):
    import gdpt.engine as engine
    S.setup_gdpt(scene, samples, mode=MODE, reconstruction='L1' if MODE == 'GPT' else 'NONE',
                 bounces=4, seed=1)
    scene.gdpt.min_light_bounces = 2
    scene.gdpt.preview_interval = 3.0
    os.environ[engine.PREVIEWS_IN_BACKGROUND] = "1" if previews else "0"
    S.render(scene, path)
    r = engine.LAST_RENDER
    if r.get("status") != "finished" or r.get("samples") != samples:
        raise RuntimeError("Gradient PT did not render")
    return r


def main():
    scene = S.clear()
    C.cornell(scene)
    scene.render.resolution_x, scene.render.resolution_y = RES
    path = os.path.join(tempfile.mkdtemp(), "update_cost.exr")
    print(f"BENCH updates: Cornell box {RES[0]}x{RES[1]}, {MODE}, {SAMPLES} spp; seconds of the "
          f"core's render and of the whole render() (Blender's Python thread)")
    for i in range(REPEATS):
        for previews in (True, False):
            r = render(scene, path, SAMPLES, previews)
            count = len(r["previews"]) if "previews" in r else "?"  # (older add-ons: ?)
            kind = "previews every 3 s" if previews else "background render"
            print(f"  {kind}: render {r['render']:.2f} s ({count} previews); whole render() "
                  f"{r['total']:.2f} s")
    for i in range(REPEATS):
        r = render(scene, path, 1, False)
        print(f"  1 spp: film set-up and scene {r['setup']:.3f} s, render {r['render']:.3f} s, "
              f"read-out and solve {r['reconstruct']:.3f} s, write {r['write']:.3f} s, whole render() "
              f"{r['total']:.3f} s")


main()
