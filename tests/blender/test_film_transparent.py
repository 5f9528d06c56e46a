# Render Properties > Film > Transparent (scene.render.film_transparent) with Gradient PT:
#  - PT: pixels that see only the sky get alpha 0 and no colour; pixels on surfaces alpha 1 and
#    the colour of the opaque render (the world still lights the scene), bit for bit;
#  - the alpha channel agrees with Cycles' (Film > Transparent, same samples, 1-pixel box filter):
#    mean |difference| < 0.02, the two engines' coverage of the silhouettes;
#  - G-PT + L1: the same alpha rule, and the reconstructed sky stays black;
#  - the Gradient Reconstruct compositor node carries the render's alpha;
#  - a Holdout ball (Object > Visibility > Mask): alpha and colour 0 where the camera sees it,
#    alpha as Cycles' (PT and G-PT + L1);
#  - a Transparent sheet before the sky: alpha 1 - mean(sheet colour) there, PT and G-PT, as
#    Cycles'.
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import exr  # noqa: E402
import scenes as S  # noqa: E402

check = S.check
SKY = np.array([0.4, 0.5, 0.6])


def build(scene):
    S.plane("floor", 8.0, (0, 0, 0), material=S.diffuse("floor", (0.6, 0.6, 0.6)))
    S.uv_sphere("ball", 0.8, (0, 0, 0.8), S.diffuse("ball", (0.8, 0.3, 0.2)))
    S.camera((0, -6, 1.2), (0, 0, 1.4), lens=35)
    S.light('SUN', (0, 0, 5), 2.0, target=(1, 1, 0))
    scene.world.color = tuple(SKY)
    scene.render.resolution_x, scene.render.resolution_y = 64, 48


def rgba(path, prefix):
    ch = exr.read_exr(path)
    return np.stack([ch[prefix + c] for c in "RGBA"], axis=-1)


def render(scene, name, transparent, engine='GDPT', **kw):
    scene.render.film_transparent = transparent
    return S.render_engine(scene, name, engine, 32, **kw)


def main():
    os.makedirs(S.args()["out"], exist_ok=True)
    scene = S.clear()
    build(scene)

    # --- PT: sky out, surfaces unchanged ---
    opaque = rgba(render(scene, "pt_opaque", False, mode='PT', reconstruction='NONE'),
                  "ViewLayer.Combined.")
    clear = rgba(render(scene, "pt_clear", True, mode='PT', reconstruction='NONE'),
                 "ViewLayer.Combined.")
    check(np.all(opaque[..., 3] == 1.0), "opaque film: alpha 1 everywhere")
    sky = np.all(np.abs(opaque[..., :3] - SKY) < 1e-6, axis=-1)  # pixels that see only the sky
    surface = clear[..., 3] == 1.0
    check(sky.sum() > 200 and surface.sum() > 1000,
          f"{sky.sum()} sky-only and {surface.sum()} surface-only pixels")
    check(np.all(clear[sky] == 0.0), "transparent film: sky pixels are RGBA 0")
    dev = float(np.abs(clear[surface][:, :3] - opaque[surface][:, :3]).max())
    check(dev == 0.0,
          f"transparent film: surface pixels keep the opaque render's colour (max diff {dev:g})")
    check(not np.any(sky & surface), "no pixel is both")

    # --- Alpha against Cycles ---
    cycles = rgba(render(scene, "cycles_clear", True, engine='CYCLES'), "ViewLayer.Combined.")
    diff = float(np.abs(cycles[..., 3] - clear[..., 3]).mean())
    check(diff < 0.02, f"alpha agrees with Cycles' (mean |diff| {diff:.4f})")
    cyc_sky = float(cycles[sky][:, 3].max())
    check(cyc_sky < 0.05, f"Cycles agrees on the sky pixels (alpha at most {cyc_sky:.4f})")

    # --- G-PT + L1, with the compositor node ---
    S.setup_gdpt(scene, 32, mode='GPT', reconstruction='L1')  # Render Layers shows GDPT's passes
    S.reconstruct_tree(scene, 'L1', scene.gdpt.alpha)
    path = render(scene, "gpt_clear", True, mode='GPT', reconstruction='L1')
    gpt = rgba(path, "ViewLayer.Combined.")
    composite = rgba(path, "Composite.Combined.")
    check(np.all(gpt[sky][:, 3] == 0.0) and np.all(gpt[surface][:, 3] == 1.0),
          "G-PT: alpha 0 on the sky, 1 on surfaces")
    leak = float(np.abs(gpt[sky][:, :3]).max())
    check(leak < 0.05, f"G-PT + L1: the sky stays black (max {leak:.4f})")
    check(np.array_equal(composite[..., 3], gpt[..., 3]),
          "the compositor node's alpha is the render's")
    scene.use_nodes = False

    # --- Holdout ball: alpha 0 and black where the camera sees it, as Cycles (PT and G-PT) ---
    bpy.data.objects["ball"].is_holdout = True
    cyc = rgba(render(scene, "cycles_holdout", True, engine='CYCLES'), "ViewLayer.Combined.")
    hole = surface & (cyc[..., 3] < 1e-6)  # pixels that saw only the ball
    check(hole.sum() > 100, f"{hole.sum()} pixels see only the holdout ball")
    # (G-PT + L1: the reconstruction may leave a trace of colour in the hole, bounded as the sky's.)
    for mode, recon, bound in (('PT', 'NONE', 0.0), ('GPT', 'L1', 0.05)):
        img = rgba(render(scene, f"{mode}_holdout", True, mode=mode, reconstruction=recon),
                   "ViewLayer.Combined.")
        a_diff = float(np.abs(cyc[..., 3] - img[..., 3]).mean())
        inside = float(np.abs(img[hole]).max())
        check(a_diff < 0.02 and float(np.abs(img[hole][:, 3]).max()) == 0.0 and inside <= bound,
              f"{mode} holdout: alpha agrees with Cycles' (mean |diff| {a_diff:.4f}), RGBA in the "
              f"hole at most {inside:.4f}")

    # --- A Transparent sheet before the sky: coverage 1 - mean(colour) there, as Cycles' ---
    bpy.data.objects["ball"].is_holdout = False
    sheet = S.shader_material("sheet", "ShaderNodeBsdfTransparent", Color=(0.5, 0.25, 1.0, 1))
    S.plane("sheet", 3.0, (-2.0, -3.0, 2.2), (math.pi / 2, 0, 0), sheet)
    cyc = rgba(render(scene, "cycles_sheet", True, engine='CYCLES'), "ViewLayer.Combined.")
    behind = sky & (np.abs(cyc[..., 3] - (1.0 - (0.5 + 0.25 + 1.0) / 3.0)) < 0.02)
    check(behind.sum() > 50, f"{behind.sum()} pixels see the sky through the sheet only")
    for mode, recon in (('PT', 'NONE'), ('GPT', 'L1')):
        img = rgba(render(scene, f"{mode}_sheet", True, mode=mode, reconstruction=recon),
                   "ViewLayer.Combined.")
        a_diff = float(np.abs(cyc[..., 3] - img[..., 3]).mean())
        a_behind = float(np.abs(img[behind][:, 3] - 5.0 / 12.0).max())
        check(a_diff < 0.02 and a_behind < 1e-5,
              f"{mode}: alpha through the sheet is 1 - mean(colour) = 5/12 (max error "
              f"{a_behind:.2g}), all alpha within {a_diff:.4f} of Cycles' on average")
    print("film transparent: all checks passed")


main()
