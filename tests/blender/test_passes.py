# The multilayer EXR written by a Gradient PT render (as `-f 1` writes it) holds every pass with
# the right values, for every view layer:
#  - channels: Combined RGBA, Primal, Gradient X, Gradient Y, Emission (RGB), Variance (XYZ),
#    Shift Failures (X), in both view layers;
#  - Emission: exactly the radiance of the emitter the camera sees (its interior pixels), zero
#    where the camera sees no emitter; Primal is zero there (a pure emitter reflects nothing);
#  - Variance >= 0, Shift Failures in [0, 1], everything finite;
#  - Combined equals the reconstruction of the passes: by the gdpt-reconstruct CLI run on the
#    EXR (L1, the engine's setting) and by the module's reconstruct (L2 on a second render);
#  - the gradient passes are consistent with the primal in Blender's row order: an L2
#    reconstruction from the EXR's passes agrees with Primal + Emission (a flipped dx/dy
#    convention anywhere between the core and the file makes this fail badly);
#  - the second view layer (sphere excluded) really differs where the sphere is.
import math
import os
import subprocess
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import exr  # noqa: E402
import scenes as S  # noqa: E402

check = S.check

PASSES = {"Combined": "RGBA", "Primal": "RGB", "Gradient X": "RGB", "Gradient Y": "RGB",
          "Emission": "RGB", "Variance": "XYZ", "Shift Failures": "X"}
PANEL_RADIANCE = np.array([1.0, 0.9, 0.8]) * 5.0


def build(scene):
    S.room()
    S.camera((0, -5.5, 2.0), (0, 0, 1.8), lens=28)
    # The emitter is visible to the camera: it fills the Emission pass.
    S.plane("panel", 1.2, (0, 0, 3.9), (math.pi, 0, 0),
            S.emission("panel", tuple(PANEL_RADIANCE / 5.0), 5.0))
    gloss = S.glossy("gloss", 0.3)
    coll = bpy.data.collections.new("Sphere")
    scene.collection.children.link(coll)
    ball = S.uv_sphere("ball", 0.8, (0.3, 0.2, 0.8), gloss)
    scene.collection.objects.unlink(ball)
    coll.objects.link(ball)
    second = scene.view_layers.new("Second")
    second.layer_collection.children["Sphere"].exclude = True


def main():
    a = S.args()
    out = a["out"]
    os.makedirs(out, exist_ok=True)
    scene = S.clear()
    build(scene)
    S.setup_gdpt(scene, 64, mode='GPT', reconstruction='L1', bounces=4)
    path = S.render(scene, os.path.join(out, "passes.exr"), multilayer=True)
    ch = exr.read_exr(path)

    for layer in ("ViewLayer", "Second"):
        for name, ids in PASSES.items():
            for c in ids:
                check(f"{layer}.{name}.{c}" in ch, f"{layer}.{name}.{c} in the EXR")
    for name, plane in ch.items():
        check(np.isfinite(plane).all(), f"{name} finite")

    def get(layer, name):
        return np.stack([ch[f"{layer}.{name}.{c}"] for c in PASSES[name]], axis=-1)

    layer = "ViewLayer"
    emission = get(layer, "Emission")
    primal = get(layer, "Primal")
    combined = get(layer, "Combined")
    # Interior of the panel: the pixel and its 8 neighbours see it fully.
    seen = emission.sum(axis=-1) > 0
    interior = seen.copy()
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            interior &= np.roll(np.roll(seen, dy, 0), dx, 1)
    check(interior.sum() >= 10, f"the panel covers {interior.sum()} interior pixels")
    err = np.abs(emission[interior] - PANEL_RADIANCE).max()
    check(err < 1e-3 * PANEL_RADIANCE.max(), f"Emission = panel radiance inside (max err {err})")
    check(np.abs(primal[interior]).max() < 1e-6, "Primal is 0 on the pure emitter")
    far = ~seen
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            far &= ~np.roll(np.roll(seen, dy, 0), dx, 1)
    check(np.abs(emission[far]).max() == 0.0, "Emission is 0 where no emitter is seen")
    check(primal[far].mean() > 0.01, f"Primal lit elsewhere (mean {primal[far].mean():.4f})")
    variance = get(layer, "Variance")
    check(variance.min() >= 0.0, "Variance >= 0")
    failures = get(layer, "Shift Failures")
    check(failures.min() >= 0.0 and failures.max() <= 1.0, "Shift Failures in [0, 1]")
    check(np.all(combined[..., 3] == 1.0), "Combined alpha = 1")

    # Combined = CLI reconstruction of the passes (same norm and alpha as the engine).
    cli = os.path.join(a["build"], "reconstruct", "gdpt-reconstruct")
    for layer_name in ("ViewLayer", "Second"):
        cli_out = os.path.join(out, f"cli_{layer_name}.exr")
        subprocess.run([cli, path, "-o", cli_out, "--norm", "l1", "--alpha", "0.2", "--layer",
                        layer_name], check=True)
        ref = exr.rgb(exr.read_exr(cli_out), "")
        mine = get(layer_name, "Combined")[..., :3]
        err = S.rel_mse(mine, ref, eps=1e-3)
        check(err < 1e-5, f"{layer_name}: Combined = gdpt-reconstruct L1 (relMSE {err:.2e})")

    # Gradient convention through Blender's pass storage: L2 from the EXR's passes ~ primal.
    from gdpt import _gdpt
    recon = _gdpt.reconstruct(np.ascontiguousarray(primal), get(layer, "Gradient X").copy(),
                              get(layer, "Gradient Y").copy(), None, emission.copy(), "L2", 0.2)
    err = S.rel_mse(recon, primal + emission)
    mean_ratio = recon.mean() / (primal + emission).mean()
    check(err < 0.05 and abs(mean_ratio - 1) < 0.02,
          f"L2 reconstruction of the EXR passes agrees with Primal + Emission (relMSE {err:.4f},"
          f" mean ratio {mean_ratio:.4f})")
    # The same with a transposed gradient convention must be clearly worse (the test can fail).
    bad = _gdpt.reconstruct(np.ascontiguousarray(primal), -get(layer, "Gradient X"),
                            -get(layer, "Gradient Y"), None, emission.copy(), "L2", 0.2)
    bad_err = S.rel_mse(bad, primal + emission)
    check(bad_err > 4 * err, f"negated gradients are detected (relMSE {bad_err:.4f})")

    # View layers: the sphere is excluded from "Second".
    c1 = get("ViewLayer", "Combined")[..., :3]
    c2 = get("Second", "Combined")[..., :3]
    diff = np.abs(c1 - c2).sum(axis=-1)
    check((diff > 0.05).sum() > 50, f"the view layers differ on {(diff > 0.05).sum()} pixels")
    check(c2.mean() > 0.01, "the second view layer rendered")

    # Engine setting L2: Combined equals the module's L2 solve of the same passes.
    scene.gdpt.reconstruction = 'L2'
    scene.view_layers["Second"].use = False
    path2 = S.render(scene, os.path.join(out, "passes_l2.exr"), multilayer=True)
    ch = exr.read_exr(path2)
    recon = _gdpt.reconstruct(np.ascontiguousarray(get(layer, "Primal")),
                              get(layer, "Gradient X").copy(), get(layer, "Gradient Y").copy(),
                              None, get(layer, "Emission").copy(), "L2", 0.2)
    err = S.rel_mse(get(layer, "Combined")[..., :3], recon, eps=1e-3)
    check(err < 1e-8, f"Combined = L2 reconstruction of the passes (relMSE {err:.2e})")
    check("Second.Combined.R" not in ch, "a disabled view layer is not rendered")
    print("ALL PASS CHECKS PASSED", flush=True)


main()
