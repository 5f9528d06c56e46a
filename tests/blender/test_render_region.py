# Render Region (Blender's border, Ctrl+B in the camera view): Gradient PT renders only the region,
# and its pixels are the whole frame's pixels.
#  - PT, region cropped (Crop to Render Region): the EXR is the region's size as Blender computes
#    it, and its Primal pass equals the whole frame's Primal there (the core samples a region
#    pixel exactly as the same pixel of the frame: bit for bit in the C++ tests);
#  - G-PT, cropped: Primal, Gradient X and Gradient Y equal the frame's away from the region's edges
#    (at the edges the offsets that leave the region are missing, as at the frame's edges); the
#    reconstruction of the region is close to the frame's there;
#  - not cropped: a frame-sized image with the region in place (alpha 1 inside, 0 outside);
#
# "Equal" is bit for bit (docs/conventions.md, "Determinism"). A wrong region offset changes
# nearly every value.
#  - the Gradient Reconstruct compositor node: its image is the cropped region, or the frame with
#    the region in place, equal to the engine's Combined;
#  - a resolution percentage whose float product would round differently (29% of 100 px) still
#    gives Blender's own size.
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import exr  # noqa: E402
import scenes as S  # noqa: E402

check = S.check
BORDER = (0.21, 0.68, 0.33, 0.87)  # min x, max x, min y, max y (fractions of the frame)


def build(scene):
    S.room()
    S.camera((0, -5.5, 2.0), (0, 0, 1.7), lens=30)
    S.light('AREA', (0, 0, 3.95), 150.0, target=(0, 0, 0), size=1.0)
    S.uv_sphere("ball", 0.7, (0.3, 0.2, 0.7), S.glossy("gloss", 0.3))


def passes(path, names):
    ch = exr.read_exr(path)
    return {n: np.stack([ch[f"ViewLayer.{n}.{c}"] for c in "RGB"], axis=-1) for n in names}


def render(scene, path, border, crop, multilayer=True):
    import gdpt.engine as engine
    r = scene.render
    r.use_border = border
    r.use_crop_to_border = crop
    r.border_min_x, r.border_max_x, r.border_min_y, r.border_max_y = BORDER
    engine.LAST_RENDER.clear()
    S.render(scene, path, multilayer=multilayer)
    check(engine.LAST_RENDER.get("render", 0) > 0, f"Gradient PT rendered {path}")
    return path


def same_pixels(a, b):
    """Equal bit for bit; also the fraction of the values that differ."""
    if a.shape != b.shape:
        return False, 1.0
    off = a != b
    return not off.any(), off.mean()


def blender_region(width, height):
    # Blender's render_init_from_main: float32 products, truncated.
    f = np.float32
    x0, x1 = int(f(BORDER[0]) * f(width)), int(f(BORDER[1]) * f(width))
    y0, y1 = int(f(BORDER[2]) * f(height)), int(f(BORDER[3]) * f(height))
    return x0, y0, x1 - x0, y1 - y0


def main():
    out = S.args()["out"]
    os.makedirs(out, exist_ok=True)
    scene = S.clear()
    build(scene)
    width, height = 80, 60
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    x0, y0, w, h = blender_region(width, height)
    print(f"region {w}x{h} at ({x0}, {y0}) of {width}x{height}")

    # --- PT: the cropped region is the frame's pixels, bit for bit ---
    S.setup_gdpt(scene, 8, mode='PT', reconstruction='NONE')
    full = passes(render(scene, os.path.join(out, "pt_full.exr"), False, False), ["Primal"])
    part = passes(render(scene, os.path.join(out, "pt_region.exr"), True, True), ["Primal"])
    check(part["Primal"].shape == (h, w, 3),
          f"cropped PT region is {part['Primal'].shape[1]}x{part['Primal'].shape[0]} "
          f"(Blender's region {w}x{h})")
    same = full["Primal"][y0:y0 + h, x0:x0 + w]
    ok, frac = same_pixels(part["Primal"], same)
    check(ok, f"PT region Primal equals the frame's ({100 * frac:.2f}% of values differ)")
    check(same.mean() > 0.01, f"the region is lit (mean {same.mean():.3f})")

    # --- G-PT: interior pixels equal, reconstruction close ---
    S.setup_gdpt(scene, 16, mode='GPT', reconstruction='L1')
    names = ["Primal", "Gradient X", "Gradient Y"]
    full = passes(render(scene, os.path.join(out, "gpt_full.exr"), False, False), names)
    part = passes(render(scene, os.path.join(out, "gpt_region.exr"), True, True), names)
    for n in names:
        a = part[n][1:-1, 1:-1]
        b = full[n][y0 + 1:y0 + h - 1, x0 + 1:x0 + w - 1]
        ok, frac = same_pixels(a, b)
        check(ok, f"G-PT region {n} equals the frame's away from the edges ({100 * frac:.2f}% "
              f"of values differ)")
    check(np.abs(part["Gradient X"]).max() > 0, "the region has gradients")
    ch_full = exr.read_exr(os.path.join(out, "gpt_full.exr"))
    ch_part = exr.read_exr(os.path.join(out, "gpt_region.exr"))
    comb_full = exr.rgb(ch_full, "ViewLayer.Combined.")[y0:y0 + h, x0:x0 + w]
    comb_part = exr.rgb(ch_part, "ViewLayer.Combined.")
    err = S.rel_mse(comb_part, comb_full)
    check(err < 0.01, f"G-PT region reconstruction close to the frame's (relMSE {err:.5f})")

    # --- Not cropped: a frame-sized image, the region in place ---
    S.setup_gdpt(scene, 8, mode='PT', reconstruction='NONE')
    path = render(scene, os.path.join(out, "pt_uncropped.exr"), True, False, multilayer=False)
    ch = exr.read_exr(path)
    alpha = ch["A"]
    check(alpha.shape == (height, width), f"uncropped image is {alpha.shape[1]}x{alpha.shape[0]}")
    inside = np.zeros_like(alpha, dtype=bool)
    inside[y0:y0 + h, x0:x0 + w] = True
    check(np.all(alpha[inside] == 1.0) and np.all(alpha[~inside] == 0.0),
          "alpha is 1 in the region and 0 outside")
    rgb = np.stack([ch[c] for c in "RGB"], axis=-1)
    ok, frac = same_pixels(rgb[inside].reshape(h, w, 3), same)
    check(ok, f"the uncropped region's pixels are the frame's ({100 * frac:.2f}% differ)")

    # --- The Gradient Reconstruct compositor node on a region: cropped, its image is the
    # region; uncropped, the frame with the region in place, as Blender's Render Layers buffers
    # (before 2026-12-01 it wrote a region-sized image, which the compositor placed centred) ---
    S.setup_gdpt(scene, 8, mode='GPT', reconstruction='L1')
    S.reconstruct_tree(scene, 'L1', scene.gdpt.alpha)  # the engine's own solve: Combined
    for crop in (True, False):
        ch = exr.read_exr(render(scene, os.path.join(out, f"node_{crop}.exr"), True, crop))
        composite = exr.rgb(ch, "Composite.Combined.")
        combined = exr.rgb(ch, "ViewLayer.Combined.")
        expect = (h, w, 3) if crop else (height, width, 3)
        check(composite.shape == expect and combined.shape == expect,
              f"node on a {'cropped' if crop else 'uncropped'} region: {composite.shape}")
        err = float(np.abs(composite - combined).max())
        check(err < 1e-5, f"node on a {'cropped' if crop else 'uncropped'} region: Composite "
              f"equals the engine's Combined (max |diff| {err:.3g})")
    scene.use_nodes = False

    # --- Resolution percentage in Blender's integer arithmetic ---
    scene.render.resolution_x, scene.render.resolution_y = 100, 100
    scene.render.resolution_percentage = 29  # 100 * 0.29 = 28.999999999999996 in double
    S.setup_gdpt(scene, 1, mode='PT', reconstruction='NONE')
    ch = exr.read_exr(render(scene, os.path.join(out, "pct.exr"), False, False, False))
    import gdpt.engine as engine
    size = (engine.LAST_RENDER.get("width"), engine.LAST_RENDER.get("height"))
    check(ch["R"].shape == (29, 29) and size == (29, 29),
          f"29% of 100 px: Blender's image {ch['R'].shape[1]} px, Gradient PT's {size} (29)")
    check(np.all(ch["A"] == 1.0) and np.all(np.isfinite(ch["R"])), "every pixel written")
    print("render region: all checks passed")


main()
