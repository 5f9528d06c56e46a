# The Depth (Z), IndexOB and IndexMA passes (View Layer > Passes > Data) with Gradient PT, filled as
# Cycles fills them: the view-axis distance of the first surface the camera ray of a pixel's first
# sample meets (1e10 where it meets none), and that object's and material's Pass Index (0).
#  - analytic: a camera facing a wall 5 m away along its axis gives 5.0 everywhere (PT and G-PT,
#    perspective and orthographic), the sky beside the wall 1e10;
#  - against Cycles on a scene with a floor, a sphere and sky (PT: per-pixel jitter like Cycles'):
#    the same pixels are sky, and on the others the depths agree without bias (median relative
#    difference within 0.3%; single pixels differ by ~1% on the sloped floor because each engine's
#    sample 0 lands elsewhere in the pixel). G-PT's sample 0 has one jitter for the whole image, so
#    its Depth pass sits at one sub-pixel position (a constant offset of under a pixel);
#  - IndexOB / IndexMA on the same scene (object and material pass indices 2/7 and 4/9): the same
#    values as Cycles on more than 98% of the pixels (the rest: silhouettes, sample 0 elsewhere);
#  - Normal and Mist (every sample; World > Mist Pass start 3 m, depth 6 m, linear) on the same
#    scene: mean absolute difference to Cycles' below 0.01 / 0.005, the floor's normal (0, 0, 1),
#    the sky's mist 1.
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import exr  # noqa: E402
import scenes as S  # noqa: E402

check = S.check


def depth(scene, name, engine, indices=False, **kw):
    """The Depth pass, and with indices=True also the IndexOB and IndexMA passes."""
    layer = scene.view_layers[0]
    layer.use_pass_z = True
    layer.use_pass_object_index = layer.use_pass_material_index = indices
    ch = exr.read_exr(S.render_engine(scene, name, engine, 4, **kw))
    names = ["ViewLayer.Depth.Z"] + (["ViewLayer.IndexOB.X", "ViewLayer.IndexMA.X"]
                                     if indices else [])
    for n in names:
        check(n in ch, f"{name}: the EXR has {n}")
    return [ch[n] for n in names] if indices else ch[names[0]]


def main():
    os.makedirs(S.args()["out"], exist_ok=True)

    # --- Analytic: a wall 5 m ahead, filling the left part of the view ---
    scene = S.clear()
    S.plane("wall", 4.0, (-1.0, 5.0, 0.0), (math.pi / 2, 0, 0), S.diffuse("w", (0.5, 0.5, 0.5)))
    S.camera((0, 0, 0), (0, 1, 0), lens=35)
    S.light('SUN', (0, 0, 5), 2.0)
    scene.render.resolution_x, scene.render.resolution_y = 48, 32
    for ortho in (False, True):
        scene.camera.data.type = 'ORTHO' if ortho else 'PERSP'
        scene.camera.data.ortho_scale = 6.0
        for mode in ('PT', 'GPT'):
            z = depth(scene, f"wall_{mode}_{ortho}", 'GDPT', mode=mode, reconstruction='NONE')
            wall = z < 1e9
            check(wall.sum() > 200 and (~wall).sum() > 100,
                  f"{mode} ortho={ortho}: {wall.sum()} wall and {(~wall).sum()} sky pixels")
            err = float(np.abs(z[wall] - 5.0).max())
            check(err < 1e-4, f"{mode} ortho={ortho}: depth on the wall is 5 m (max error {err:.2g})")
            check(np.all(z[~wall] == 1e10), f"{mode} ortho={ortho}: the sky is 1e10")

    # --- Against Cycles ---
    scene = S.clear()
    S.plane("floor", 10.0, (0, 0, 0), material=S.diffuse("floor", (0.6, 0.6, 0.6)))
    S.uv_sphere("ball", 0.8, (0.3, 0, 0.8), S.diffuse("ball", (0.8, 0.3, 0.2)))
    S.camera((0, -6, 1.5), (0, 0, 1.2), lens=35)
    S.light('SUN', (0, 0, 5), 2.0)
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    bpy.data.objects["floor"].pass_index, bpy.data.objects["ball"].pass_index = 2, 7
    bpy.data.materials["floor"].pass_index, bpy.data.materials["ball"].pass_index = 4, 9
    g, g_ob, g_ma = depth(scene, "gdpt", 'GDPT', indices=True, mode='PT', reconstruction='NONE')
    c, c_ob, c_ma = depth(scene, "cycles", 'CYCLES', indices=True)
    for what, a, b, values in (("IndexOB", g_ob, c_ob, {0, 2, 7}),
                               ("IndexMA", g_ma, c_ma, {0, 4, 9})):
        seen = set(np.unique(a).tolist())
        same = float((a == b).mean())
        check(seen == values and same > 0.98,
              f"{what}: values {sorted(seen)}, equal to Cycles' on {100 * same:.1f}% of the pixels")
    sky_g, sky_c = g >= 1e9, c >= 1e9
    disagree = int((sky_g != sky_c).sum())
    check(sky_g.sum() > 200 and disagree <= 0.02 * g.size,
          f"sky pixels: {sky_g.sum()} GDPT, {sky_c.sum()} Cycles, {disagree} differ")
    both = ~sky_g & ~sky_c
    rel = (g[both] - c[both]) / c[both]
    bias, spread = float(np.median(rel)), float(np.median(np.abs(rel)))
    check(abs(bias) < 0.003 and spread < 0.03,
          f"depth agrees with Cycles' (median relative difference {bias:+.4f}, median of its "
          f"magnitude {spread:.4f}: where in the pixel each engine's sample 0 fell)")

    # --- Normal and Mist (every sample, Cycles' definitions) against Cycles, same scene ---
    layer = scene.view_layers[0]
    layer.use_pass_z = layer.use_pass_object_index = layer.use_pass_material_index = False
    layer.use_pass_normal = layer.use_pass_mist = True
    mist = scene.world.mist_settings
    mist.start, mist.depth, mist.falloff = 3.0, 6.0, 'LINEAR'
    out = {}
    for engine, kw in (('GDPT', dict(mode='PT', reconstruction='NONE')), ('CYCLES', {})):
        ch = exr.read_exr(S.render_engine(scene, f"data_{engine}", engine, 16, **kw))
        for n in ("ViewLayer.Normal.X", "ViewLayer.Normal.Y", "ViewLayer.Normal.Z",
                  "ViewLayer.Mist.Z"):
            check(n in ch, f"{engine}: the EXR has {n}")
        out[engine] = (np.stack([ch[f"ViewLayer.Normal.{c}"] for c in "XYZ"], -1),
                       ch["ViewLayer.Mist.Z"])
    (gn, gm), (cn, cm) = out['GDPT'], out['CYCLES']
    n_err = float(np.abs(gn - cn).mean())
    floor = (np.abs(cn[..., 2] - 1.0) < 1e-3)  # the floor faces up: (0, 0, 1) there
    check(floor.sum() > 300 and n_err < 0.01,
          f"Normal agrees with Cycles' (mean |difference| {n_err:.4f}; {floor.sum()} floor pixels)")
    off = np.abs(gn[floor] - (0.0, 0.0, 1.0)).max(axis=-1)
    # (A pixel Cycles saw as pure floor may hold a sample or two of the ball's edge in GDPT.)
    check(float(np.median(off)) < 1e-5 and float((off > 1e-3).mean()) < 0.01,
          f"Normal on the floor is (0, 0, 1) (median deviation {np.median(off):.2g}, "
          f"{int((off > 1e-3).sum())} of {off.size} pixels off by more than 1e-3)")
    m_err = float(np.abs(gm - cm).mean())
    sky = cm >= 1.0 - 1e-6
    # Where Cycles' is 1 (sky, floor beyond start + depth) GDPT's is 1 too, but for pixels at
    # the ball's silhouette where a sample or two of one engine met the ball.
    ones = float((gm[sky] > 1.0 - 1e-6).mean())
    check(m_err < 0.005 and sky.sum() > 200 and ones > 0.98,
          f"Mist agrees with Cycles' (mean |difference| {m_err:.4f}); where Cycles' is 1 "
          f"({sky.sum()} pixels) GDPT's is 1 on {100 * ones:.1f}%")
    check(0.05 < float(gm.mean()) < 0.95, f"Mist varies over the image (mean {gm.mean():.3f})")
    print("depth pass: all checks passed")


main()
