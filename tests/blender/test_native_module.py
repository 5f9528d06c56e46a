# The add-on's choice between the builds of its C++ module (blender_addon/gdpt/native.py):
#  - `_gdpt_cpu` reports the CPU's x86-64 level as glibc's dynamic loader does (`ld.so --help`
#    lists the glibc-hwcaps levels this CPU supports): the oracle for the choice;
#  - by default the fastest build the CPU runs is loaded, and on a CPU that runs x86-64-v3 after
#    `make build` that is the x86-64-v3 build; an add-on folder without it loads the baseline;
#  - GDPT_ISA forces a build, and a bad value gives a clear error instead of a render;
#  - every build renders the analytic scene right: a diffuse sphere of albedo 0.8 under a uniform
#    white sky (no other object) reflects exactly 0.8 (it is convex, so every path leaves after one
#    bounce), and the sky is 1.0, in each build;
#  - on the benchmark's noisy Cornell box the builds' images (same seed) differ by less than a
#    quarter of what two seeds of the baseline build do (the builds differ only in rounding, e.g.
#    FMA, which moves few paths onto other branches), and their means agree within 2%.
# Each build is rendered in its own Blender process (only one build can live in a process).
import glob
import os
import re
import shutil
import subprocess
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import scenes as S  # noqa: E402

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "bench", "blender"))
from compare_cycles import cornell  # noqa: E402

check = S.check
ALBEDO = 0.8
SIZE = 48
SAMPLES = 64


def glibc_level():
    """The highest x86-64-vN that glibc's dynamic loader reports as supported (1 if none)."""
    out = subprocess.run(["/lib64/ld-linux-x86-64.so.2", "--help"], capture_output=True,
                         text=True, check=True).stdout
    levels = [int(v) for v in re.findall(r"x86-64-v(\d) \(supported", out)]
    check(levels or "glibc-hwcaps" in out, "ld.so --help lists the glibc-hwcaps levels")
    return max(levels, default=1)


def sphere_scene():
    scene = S.clear()
    scene.world.color = (1.0, 1.0, 1.0)
    S.camera((0, -4, 0), (0, 0, 0), lens=50)
    S.uv_sphere("ball", 1.0, (0, 0, 0), S.diffuse("ball", (ALBEDO,) * 3), segments=64, rings=32)
    S.setup_gdpt(scene, SAMPLES, mode='PT', reconstruction='NONE', bounces=4)
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    return scene


def cornell_scene(seed):
    """The benchmark's Cornell box (area lamp, glossy ball): noisy, many bounces."""
    scene = S.clear()
    cornell(scene)
    S.setup_gdpt(scene, SAMPLES, mode='PT', reconstruction='NONE', bounces=4, seed=seed)
    scene.render.resolution_x, scene.render.resolution_y = 48, 36
    return scene


def render(scene, out):
    """Renders `scene`; returns (build, image)."""
    from gdpt import engine
    engine.LAST_RENDER.clear()
    S.render(scene, out)
    check(engine.LAST_RENDER.get("status") == "finished", f"Gradient PT rendered {out}")
    return engine.LAST_RENDER["build"], S.read_rgb(out)


def check_sphere(build, image):
    """The sphere's centre reflects 0.8, the corners see the sky's 1.0 (per-pixel tolerance:
    64 spp of sky sampling against the BSDF, MIS-weighted)."""
    c = SIZE // 2
    centre = image[c - 6:c + 6, c - 6:c + 6]
    corners = np.concatenate([image[:4, :4], image[:4, -4:], image[-4:, :4], image[-4:, -4:]])
    check(abs(centre.mean() - ALBEDO) < 0.01 * ALBEDO,
          f"{build} build: the sphere's centre is {centre.mean():.4f} (analytic {ALBEDO})")
    check(np.abs(corners - 1.0).max() < 1e-4, f"{build} build: the sky is 1.0 in the corners")
    return centre.mean()


def child(out, seed):
    """In a second Blender process: render the two scenes with the build GDPT_ISA asks."""
    from gdpt import native
    module, build, error = native.load()
    if module is None:
        # What the user sees: the render reports the error instead of rendering.
        from gdpt import engine
        try:
            S.render(sphere_scene(), out + "_sphere.exr")
        except RuntimeError:
            pass
        print("CHILD_ERROR", engine.LAST_ERROR.get("message", ""), flush=True)
        return
    # (One bpy scene: each set-up clears the previous one, so build each just before its render.)
    for name, make in (("sphere", sphere_scene), ("cornell", lambda: cornell_scene(seed))):
        build, image = render(make(), f"{out}_{name}.exr")
        np.save(f"{out}_{name}.npy", image)
    print("CHILD_BUILD", build, module.__file__, flush=True)


def run_child(isa, out, user_scripts=None, seed=1):
    env = dict(os.environ)
    env.pop("GDPT_ISA", None)
    if isa is not None:
        env["GDPT_ISA"] = isa
    if user_scripts is not None:
        env["BLENDER_USER_SCRIPTS"] = user_scripts
    proc = subprocess.run(
        [bpy.app.binary_path, "-b", "--factory-startup", "--addons", "gdpt", "--python",
         os.path.abspath(__file__), "--", "--child", out, "--seed", str(seed)],
        env=env, capture_output=True, text=True, timeout=300)
    lines = {line.split(" ", 1)[0]: line.split(" ", 1)[1].strip()
             for line in proc.stdout.splitlines() if line.startswith("CHILD_")}
    check(lines, f"the child Blender (GDPT_ISA={isa}) reported back (exit {proc.returncode})")
    return lines


def main():
    a = S.args()
    if "child" in a:
        child(a["child"], int(a["seed"]))
        return
    out = a["out"]
    os.makedirs(out, exist_ok=True)
    from gdpt import _gdpt_cpu, native

    # --- The CPU's level, against glibc's ---
    level = _gdpt_cpu.x86_64_level()
    check(level == glibc_level(), f"_gdpt_cpu reports x86-64 level {level}, as glibc does")

    # --- The default choice in this process ---
    module, build, error = native.load()
    check(module is not None and error is None, f"the {build} build loaded")
    # scripts/assemble-addon.sh stages the build tree's x86-64-v3 module unless it is older
    # than the baseline one (built from older sources).
    v3 = glob.glob(os.path.join(a["build"], "x86-64-v3", "blender_addon", "_gdpt.*so"))
    baseline = glob.glob(os.path.join(a["build"], "blender_addon", "_gdpt.*so"))
    fresh_v3 = bool(v3) and os.path.getmtime(v3[0]) > os.path.getmtime(baseline[0])
    expected = "x86-64-v3" if level >= 3 and fresh_v3 else "baseline"
    check(build == expected, f"the default build is {expected} (CPU level {level}, x86-64-v3 "
                             f"build {'built' if fresh_v3 else 'not built'})")
    check(os.path.samefile(module.__file__, native.module_file(build)),
          "gdpt._gdpt is the chosen build's file")
    from gdpt import _gdpt
    check(_gdpt is module, "`from gdpt import _gdpt` gets the chosen build")
    own_build, own = render(sphere_scene(), os.path.join(out, "default_sphere.exr"))
    check(own_build == build, "the render used the chosen build")
    check_sphere(build, own)

    # --- Each build forced, in its own process ---
    base = os.path.join(out, "baseline_seed2")
    run_child("baseline", base, seed=2)
    builds = [b for b in native.BUILDS if native.module_file(b) and level >= native.BUILDS[b][1]]
    images = {}
    for b in builds:
        lines = run_child(b, os.path.join(out, b))
        check(lines.get("CHILD_BUILD", "").split(" ")[0] == b, f"GDPT_ISA={b} loads the {b} build")
        check_sphere(b, np.load(os.path.join(out, f"{b}_sphere.npy")))
        images[b] = np.load(os.path.join(out, f"{b}_cornell.npy"))
    seed2 = np.load(base + "_cornell.npy")
    noise = S.rel_mse(seed2, images["baseline"])
    for b, image in images.items():
        if b == "baseline":
            continue
        diff = S.rel_mse(image, images["baseline"])
        check(diff < 0.25 * noise, f"Cornell box, {b} against baseline: relMSE {diff:.6f}, "
                                   f"below a quarter of the baseline's seed-to-seed {noise:.5f}")
        mean, ref = image.mean(), images["baseline"].mean()
        check(abs(mean - ref) < 0.02 * ref, f"Cornell box mean {mean:.4f} ({b}) against "
                                            f"{ref:.4f} (baseline)")

    # --- An add-on folder without the x86-64-v3 build loads the baseline ---
    user = os.path.join(out, "no_variant")
    shutil.rmtree(user, ignore_errors=True)
    shutil.copytree(os.path.dirname(native.__file__), os.path.join(user, "addons", "gdpt"),
                    ignore=shutil.ignore_patterns("x86-64-v3", "__pycache__"))
    lines = run_child(None, os.path.join(out, "no_variant"), user_scripts=user)
    check(lines.get("CHILD_BUILD", "").split(" ")[0] == "baseline",
          "without an x86-64-v3 build the baseline loads")
    if level >= 3:
        lines = run_child("x86-64-v3", os.path.join(out, "forced_missing"), user_scripts=user)
        check("has no x86-64-v3 build" in lines.get("CHILD_ERROR", ""),
              f"GDPT_ISA=x86-64-v3 without that build is a clear error: {lines}")

    # --- A bad GDPT_ISA is a clear error, not a render ---
    lines = run_child("avx9000", os.path.join(out, "bad"))
    message = lines.get("CHILD_ERROR", "")
    check("GDPT_ISA='avx9000'" in message and "baseline" in message,
          f"a bad GDPT_ISA is reported: {message!r}")


main()
