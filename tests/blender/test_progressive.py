# Progressive updates (engine.render's poll): every Preview Interval the image shows the film so
# far, reconstructed, written through one layer buffer that every update of the render reuses.
#  - passes.layer_buffer into a reused buffer full of NaN equals a fresh buffer: every element is
#    written, passes GDPT does not produce (and channels it lacks) are zeros;
#  - a render long enough for several previews (Preview Interval 0.5 s): the previews' sample
#    counts rise, up to the final count; each preview's Combined mean is within 1% of the
#    final image's (a Cornell box converges in the mean long before it converges per pixel: the
#    means agree to 0.1%), which a preview from an unzeroed or overwritten buffer, from the wrong
#    pass, or with NaNs fails; and no two previews are the same image (their mean squares differ)
#    while the first has more noise than the final image (a larger mean square: the mean square
#    is the squared mean plus the noise variance), which a preview repeating a stale image fails;
#  - the same for G-PT, whose previews are L2 reconstructions of the snapshot's passes (except
#    the noise comparison: the reconstruction smooths the noise);
#  - engine.preview_gap: the Preview Interval for cheap previews, and for costly ones (a full-HD
#    G-PT L2 solve) a gap that keeps previews at 5% of the time;
#  - these renders run in background mode, which by default takes no previews (nothing shows
#    them): the test asks for them with GDPT_PREVIEWS_IN_BACKGROUND=1, and checks that without it
#    a render takes none and still finishes.
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import scenes as S  # noqa: E402

check = S.check


class FakePass:
    def __init__(self, name, channels):
        self.name, self.channels = name, channels


class FakeLayer:
    passes = [FakePass("Combined", 4), FakePass("Primal", 3), FakePass("Depth", 1),
              FakePass("Normal", 3), FakePass("Shift Failures", 1), FakePass("Unknown", 2)]


def check_layer_buffer_reuse():
    from gdpt import passes
    rng = np.random.default_rng(1)
    h, w = 3, 5
    film = {"width": w, "height": h, "primal": rng.random((h, w, 3), dtype=np.float32),
            "alpha": rng.random((h, w, 1), dtype=np.float32),
            "depth": rng.random((h, w, 1), dtype=np.float32),
            "shift_failures": rng.random((h, w, 1), dtype=np.float32)}  # no "normal"
    combined = rng.random((h, w, 3), dtype=np.float32)
    fresh = passes.layer_buffer(FakeLayer, film, combined)
    size = passes.layer_buffer_size(FakeLayer, w * h)
    check(fresh.size == size == 14 * w * h, f"layer buffer of {size} floats (14 per pixel)")
    stale = np.full(size, np.nan, dtype=np.float32)
    reused = passes.layer_buffer(FakeLayer, film, combined, out=stale)
    check(reused is stale and np.array_equal(reused, fresh),
          "a reused buffer full of NaN is filled exactly as a fresh one")
    n = w * h
    normal = fresh[8 * n:11 * n]
    check(not np.any(normal) and not np.any(fresh[12 * n:]),
          "passes the film lacks (Normal, an unknown one) are zeros")
    check(np.array_equal(fresh[7 * n:8 * n], film["depth"].ravel()), "Depth comes from the film")
    try:
        passes.layer_buffer(FakeLayer, film, combined, out=np.empty(size - 1, np.float32))
        check(False, "a buffer of the wrong size is refused")
    except ValueError:
        check(True, "a buffer of the wrong size is refused")


def render_with_previews(scene, out, mode, samples, reconstruction):
    import gdpt.engine as engine
    S.setup_gdpt(scene, samples, mode=mode, reconstruction=reconstruction, bounces=4)
    scene.gdpt.preview_interval = 0.5
    os.environ[engine.PREVIEWS_IN_BACKGROUND] = "1"
    try:
        path = S.render(scene, os.path.join(out, f"{mode}.exr"))
    finally:
        del os.environ[engine.PREVIEWS_IN_BACKGROUND]
    final = S.read_rgb(path)
    r = engine.LAST_RENDER
    check(r["status"] == "finished" and r["samples"] == samples,
          f"{mode}: Gradient PT rendered {samples} spp")
    previews = r["previews"]
    counts = [p[0] for p in previews]
    print(f"{mode}: render {r['render']:.2f} s, previews at {counts} spp", flush=True)
    check(len(previews) >= 2, f"{mode}: {len(previews)} previews (at least 2)")
    # (A snapshot requested during the last pass shows the final count.)
    check(all(0 < a < b for a, b in zip(counts, counts[1:])) and counts[-1] <= samples,
          f"{mode}: preview sample counts rise up to the final count")
    mean, mean_sq = float(np.mean(final)), float(np.mean(final * final))
    for spp, m, _ in previews:
        check(math.isfinite(m) and abs(m / mean - 1.0) < 0.01,
              f"{mode}: preview at {spp} spp has mean {m:.5f}, final {mean:.5f} (within 1%)")
    squares = [p[2] for p in previews]
    print(f"{mode}: mean squares {squares}, final {mean_sq}", flush=True)
    check(len(set(squares)) == len(squares), f"{mode}: every preview shows a new image")
    if mode == 'PT':  # (an L2 reconstruction smooths the noise this measures)
        check(squares[0] > mean_sq, f"{mode}: the first preview is noisier than the final image")


def check_preview_gap():
    from gdpt import engine
    check(engine.preview_gap(3.0, 0.01) == 3.0, "cheap previews keep the Preview Interval")
    check(abs(engine.preview_gap(3.0, 0.4) - 8.0) < 1e-9,
          "a 0.4 s preview is followed by 8 s without one (at most 5% of the time)")


def main():
    out = S.args()["out"]
    os.makedirs(out, exist_ok=True)
    check_layer_buffer_reuse()
    check_preview_gap()
    scene = S.clear()
    S.room()
    S.camera((0, -5.5, 2.0), (0, 0, 1.7), lens=30)
    S.light('AREA', (0, 0, 3.95), 150.0, target=(0, 0, 0), size=1.0)
    S.uv_sphere("a", 0.7, (-0.8, 0.2, 0.7), S.diffuse("a", (0.8, 0.8, 0.8)))
    S.uv_sphere("b", 0.7, (0.8, 0.6, 0.7), S.glossy("b", 0.3))
    scene.render.resolution_x, scene.render.resolution_y = 320, 240
    # About 3 s of PT (13 spp per pass at this size) and 2.5 s of G-PT on 2 cores.
    render_with_previews(scene, out, 'PT', 128, 'NONE')
    render_with_previews(scene, out, 'GPT', 48, 'L2')

    import gdpt.engine as engine
    S.setup_gdpt(scene, 128, mode='PT', reconstruction='NONE', bounces=4)
    scene.gdpt.preview_interval = 0.5
    S.render(scene, os.path.join(out, "background.exr"))
    r = engine.LAST_RENDER
    check(r["status"] == "finished" and r["samples"] == 128 and r["previews"] == [],
          f"a background render takes no previews ({r['render']:.2f} s, finished)")


main()
