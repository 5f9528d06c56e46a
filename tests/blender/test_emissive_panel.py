# The outside scene of the G-PT bias once found beside a camera-visible emissive mesh: a Cornell
# box whose light is an Emission-only panel a millimetre below the ceiling (strength 40). G-PT +
# L2 at N samples against Gradient PT's PT at 2N, in 10-pixel blocks of the non-emitted light
# (Combined minus Emission: the panel's own pixels hold none): every block within 10% of PT's
# (the bias made the ceiling beside the panel 40-60% brighter). Scaling the pixels within 10 of
# the panel by 1.4 must fail the same check (the test's power against that error).
import os
import sys

import bpy  # noqa: F401
import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import scenes as S  # noqa: E402

SAMPLES = 384  # G-PT; PT renders twice as many (at 96 the blocks on the panel's edge vary by 23%)
BLOCK, BOUND, DIM = 10, 0.10, 0.02


def build():
    scene = S.clear()
    scene.render.resolution_x, scene.render.resolution_y = 200, 150
    S.room()
    panel = S.plane("panel", 1.0, (0, 0, 3.999), material=S.emission("panel", (1, 1, 1), 40.0))
    panel.rotation_euler = (np.pi, 0, 0)
    S.uv_sphere("ball", 0.7, (-0.8, 0.4, 0.7), S.diffuse("ball", (0.8, 0.8, 0.8)))
    S.uv_sphere("ball2", 0.5, (0.9, -0.3, 0.5), S.diffuse("ball2", (0.8, 0.8, 0.8)))
    S.camera((0, -6.8, 2.0), (0, 0, 2.1), lens=30)
    return scene


def reflected(path):
    ch = S.exr.read_exr(path)
    combined = S.exr.rgb(ch, "ViewLayer.Combined.")
    emission = S.exr.rgb(ch, "ViewLayer.Emission.")
    return (combined - emission).mean(axis=2), emission.mean(axis=2)


def block_errors(g, p):
    """|mean(g) / mean(p) - 1| per block whose PT mean is above DIM."""
    h, w = p.shape[0] // BLOCK * BLOCK, p.shape[1] // BLOCK * BLOCK

    def means(x):
        return x[:h, :w].reshape(h // BLOCK, BLOCK, w // BLOCK, BLOCK).mean(axis=(1, 3))

    mg, mp = means(g), means(p)
    lit = mp > DIM
    return np.abs(mg[lit] / mp[lit] - 1.0)


def main():
    scene = build()
    pt, emission = reflected(S.render_engine(scene, "panel_pt", 'GDPT', 2 * SAMPLES, mode='PT',
                                             reconstruction='NONE'))
    gpt, _ = reflected(S.render_engine(scene, "panel_gpt", 'GDPT', SAMPLES, mode='GPT',
                                       reconstruction='L2'))
    S.check(emission.max() > 30.0, f"the panel is seen by the camera (emission {emission.max():.1f})")
    errors = block_errors(gpt, pt)
    print(f"{errors.size} blocks; worst {errors.max():.3f}, mean {errors.mean():.4f}", flush=True)
    S.check(errors.max() < BOUND, f"G-PT + L2 within {BOUND:.0%} of PT in every lit "
            f"{BLOCK}-pixel block (worst {errors.max():.3f})")
    # The power: the ceiling around the panel 40% brighter, as the bias made it.
    panel = emission > 0.0
    near = np.zeros_like(panel)
    ys, xs = np.nonzero(panel)
    near[max(ys.min() - 10, 0):ys.max() + 11, max(xs.min() - 10, 0):xs.max() + 11] = True
    injected = np.where(near & ~panel, gpt * 1.4, gpt)
    worst = block_errors(injected, pt).max()
    S.check(worst >= BOUND, f"the ceiling beside the panel 40% brighter fails the check "
            f"(worst block {worst:.3f})")


main()
