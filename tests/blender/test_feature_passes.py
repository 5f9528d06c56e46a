# The Feature reconstruction in the engine, headless: a room (white walls of colour
# (0.2, 0.5, 0.8)) with a mirror sphere, a diffuse ball and an area light, rendered with
# reconstruction Feature, writes the Denoising Albedo / Normal / Depth passes under Blender's
# names, with:
#  - the floor's albedo (0.2, 0.5, 0.8) where the normal pass is the floor's (0, 0, 1);
#  - Normal of unit length wherever a surface is seen, Depth the path length to the feature hit
#    there (0 where the camera sees nothing), the mirror's pixels the albedo of what they reflect;
#  - a finite Combined image whose relMSE against a 1024-spp G-PT + L2 reference (unbiased) is
#    lower than that of G-PT + L1 at the same 64 samples (both renders from the same seed); in PT
#    mode at 16 samples (8 per half) the Feature image is finite, has the reference's mean within
#    2% and a relMSE no higher than plain PT's (the identity is a candidate: a sound choice never
#    loses to it; the lamp seen in the mirror has its neighbours' features and must not be spread);
#  - the EXR also holds Primal A / B and every variance: gdpt-reconstruct --norm feature on it
#    gives the engine's Combined;
#  - in G-PT mode (not in PT mode) the EXR holds Gradient X / Y A / B, G-PT's gradients over the
#    same halves: over 16 samples (8 per half) (A + B) / 2 is Gradient X / Y to float rounding,
#    and A and B differ;
#  - the Gradient Reconstruct compositor node with norm Feature gives the engine's image from the
#    Render Layers of a Feature render (with the half gradients linked too), reports an error on
#    an L1 render and when only some of the half gradients are linked.
import os
import subprocess
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
import exr  # noqa: E402
import scenes as S  # noqa: E402

check = S.check
FLOOR = (0.2, 0.5, 0.8)
SPP = 16


def build():
    scene = S.clear()
    S.room(size=4.0, color=FLOOR)
    S.uv_sphere("ball", 0.7, (-0.8, 0.3, 0.7), S.diffuse("ball", (0.8, 0.3, 0.2)))
    S.uv_sphere("mirror", 0.6, (0.9, 0.0, 0.6), S.glossy("mirror", 0.0))
    S.camera((0, -5.5, 2.0), (0, 0, 1.2), lens=28)
    S.light('AREA', (0, 0, 3.95), 300.0, target=(0, 0, 0), size=1.0)
    scene.render.resolution_x, scene.render.resolution_y = 64, 48
    return scene


def combined(ch):
    rgb = exr.rgb(ch, "ViewLayer.Combined.")
    check(np.all(np.isfinite(rgb)), "Combined is finite")
    return rgb


def main():
    os.makedirs(S.args()["out"], exist_ok=True)
    scene = build()
    path = S.render_engine(scene, "feature", 'GDPT', SPP, reconstruction='FEATURE')
    ch = exr.read_exr(path)
    # The halves split the frame's SPP samples at its middle; gdpt-merge compares the record.
    split = exr.read_string_attributes(path).get("gdpt.ViewLayer.half_split")
    check(split == str(SPP // 2), f"the EXR records the halves' split at {SPP // 2} ({split})")
    for name in ("Denoising Albedo.R", "Denoising Albedo.G", "Denoising Albedo.B",
                 "Denoising Normal.X", "Denoising Normal.Y", "Denoising Normal.Z",
                 "Denoising Depth.Z"):
        check(f"ViewLayer.{name}" in ch, f"the EXR has {name}")
    albedo = np.stack([ch[f"ViewLayer.Denoising Albedo.{c}"] for c in "RGB"], -1)
    normal = np.stack([ch[f"ViewLayer.Denoising Normal.{c}"] for c in "XYZ"], -1)
    depth = ch["ViewLayer.Denoising Depth.Z"]
    floor = np.abs(normal[..., 2] - 1.0) < 1e-4
    floor_albedo = np.median(albedo[floor], axis=0) if floor.any() else np.zeros(3)
    check(floor.sum() > 200 and np.allclose(floor_albedo, FLOOR, atol=1e-4),
          f"the floor's albedo is {FLOOR}: median {floor_albedo} over {floor.sum()} pixels")
    length = np.linalg.norm(normal, axis=-1)
    check(float(np.median(length)) > 0.999, f"normals are unit (median length "
                                            f"{np.median(length):.4f})")
    seen = length > 0.999  # every sample met a surface
    d = depth[seen]
    check(np.all(np.isfinite(depth)) and float(d.min()) > 2.0 and float(d.max()) < 12.0,
          f"depth within the room's distances where surfaces are seen ({d.min():.3f} .. "
          f"{d.max():.3f})")
    check(float(depth.min()) >= 0.0, f"depth never negative (min {depth.min():.3f})")
    # The mirror sphere shows what it reflects: the walls' albedos (red, green or the white
    # walls' colour), never the mirror's own 0.9 grey.
    grey = np.all(np.abs(albedo - 0.9) < 0.02, axis=-1)
    check(int(grey.sum()) == 0, f"no pixel has the mirror's albedo ({int(grey.sum())} do)")
    feature = combined(ch)
    test_half_gradients(ch)
    test_module_half_gradient_keys(ch, feature)
    test_command_line(ch, feature)

    # Equal samples at 4 x SPP: at 16 spp each half has 8 samples, too few for the estimate.
    feature = combined(exr.read_exr(S.render_engine(scene, "feature_cmp", 'GDPT', 4 * SPP,
                                                    reconstruction='FEATURE')))
    l1 = combined(exr.read_exr(S.render_engine(scene, "l1", 'GDPT', 4 * SPP, reconstruction='L1')))
    ref = combined(exr.read_exr(S.render_engine(scene, "reference", 'GDPT', 1024,
                                                reconstruction='L2', seed=7)))
    for name, img in (("feature", feature), ("l1", l1)):
        print(f"relMSE {name}: {S.rel_mse(img, ref):.5f}, mean {img.mean():.4f} vs "
              f"{ref.mean():.4f}")
    e_feature, e_l1 = S.rel_mse(feature, ref), S.rel_mse(l1, ref)
    check(e_feature < e_l1, f"relMSE at {4 * SPP} spp: Feature {e_feature:.5f}, L1 {e_l1:.5f} "
                            f"(ratio {e_l1 / max(e_feature, 1e-12):.2f})")
    pt_feature = combined(exr.read_exr(S.render_engine(scene, "pt_feature", 'GDPT', SPP, mode='PT',
                                                       reconstruction='FEATURE')))
    pt_plain = combined(exr.read_exr(S.render_engine(scene, "pt_none", 'GDPT', SPP, mode='PT',
                                                     reconstruction='NONE')))
    pt_passes = exr.read_exr(os.path.join(S.args()["out"], "pt_feature.exr"))
    for name in HALF_GRADIENTS:
        check(f"ViewLayer.{name}.R" not in pt_passes, f"a PT render has no {name} pass")
    check("ViewLayer.Primal A.R" in pt_passes, "a PT Feature render has Primal A")
    e_pt_feature, e_pt = S.rel_mse(pt_feature, ref), S.rel_mse(pt_plain, ref)
    print(f"PT at {SPP} spp: relMSE Feature {e_pt_feature:.5f}, plain PT {e_pt:.5f}")
    check(e_pt_feature <= e_pt, f"PT at {SPP} spp: relMSE Feature {e_pt_feature:.5f} <= plain PT "
                                f"{e_pt:.5f} (ratio {e_pt / max(e_pt_feature, 1e-12):.2f})")
    mean_error = abs(float(pt_feature.mean()) / float(ref.mean()) - 1.0)
    check(mean_error < 0.02, f"PT + Feature: the reference's mean within {100 * mean_error:.2f}%")
    test_compositor_node(scene)
    print("feature passes: all checks passed")


HALF_GRADIENTS = ("Gradient X A", "Gradient X B", "Gradient Y A", "Gradient Y B")


def test_half_gradients(ch):
    """G-PT's gradients over the halves: with 8 samples per half, their mean is the gradient."""
    for name in HALF_GRADIENTS:
        check(f"ViewLayer.{name}.R" in ch, f"the EXR has {name}")
    for axis in "XY":
        whole = exr.rgb(ch, f"ViewLayer.Gradient {axis}.")
        a = exr.rgb(ch, f"ViewLayer.Gradient {axis} A.")
        b = exr.rgb(ch, f"ViewLayer.Gradient {axis} B.")
        # Each pass is a float32 rounding of a double mean: relative errors of 6e-8 each.
        bound = 1e-6 * (np.abs(a) + np.abs(b) + np.abs(whole)) + 1e-9
        err = np.abs(0.5 * (a + b) - whole)
        check(np.all(err <= bound), f"(A + B) / 2 = Gradient {axis} (max error "
                                    f"{float(err.max()):.2e}, worst error / bound "
                                    f"{float((err / bound).max()):.3f})")
        differ = float(np.mean(np.abs(a - b))) / max(float(np.mean(np.abs(whole))), 1e-12)
        check(differ > 0.1, f"Gradient {axis} A and B differ: mean |A - B| / mean |Gradient "
                            f"{axis}| = {differ:.3f}")


def test_module_half_gradient_keys(ch, feature):
    """_gdpt.reconstruct reads the half gradients from the features dict (gradient_x_a ...):
    all four give the engine's Combined; three, or one of the wrong size, are refused by name."""
    from gdpt import _gdpt

    def get(name, channels):
        return np.ascontiguousarray(np.stack([ch[f"ViewLayer.{name}.{c}"] for c in channels],
                                             -1).squeeze(-1 if len(channels) == 1 else None),
                                    dtype=np.float32)
    features = {}
    for name, key, channels in (("Primal A", "primal_a", "RGB"), ("Primal B", "primal_b", "RGB"),
                                ("Denoising Albedo", "denoising_albedo", "RGB"),
                                ("Denoising Normal", "denoising_normal", "XYZ"),
                                ("Denoising Depth", "denoising_depth", "Z")):
        features[key] = get(name, channels)
        features[key + "_variance"] = get(name + " Variance", "Z" if channels == "Z" else "XYZ")
    for name in HALF_GRADIENTS:
        features[name.lower().replace(" ", "_")] = get(name, "RGB")

    def solve(f):
        return _gdpt.reconstruct(get("Primal", "RGB"), get("Gradient X", "RGB"),
                                 get("Gradient Y", "RGB"), get("Variance", "XYZ"),
                                 get("Emission", "RGB"), 'FEATURE', 0.2, 0, features=f)
    err = float(np.abs(solve(features) - feature).max() / max(float(np.abs(feature).max()), 1e-6))
    check(err < 1e-5, f"_gdpt.reconstruct with the half gradients = the engine's Combined "
                      f"(max diff / max {err:.2e})")
    three = {k: v for k, v in features.items() if k != "gradient_y_b"}
    small = dict(features, gradient_x_a=features["gradient_x_a"][1:])
    for bad, expect in ((three, "missing gradient_y_b"), (small, "gradient_x_a: wrong size")):
        try:
            solve(bad)
            message = "(no error)"
        except ValueError as e:
            message = str(e)
        check(expect in message, f"_gdpt.reconstruct refuses it: {message}")


def test_command_line(ch, feature):
    """The EXR holds what gdpt-reconstruct --norm feature reads; it gives the engine's image."""
    for name in ("Primal A", "Primal B", "Primal A Variance", "Primal B Variance",
                 "Denoising Albedo Variance", "Denoising Normal Variance"):
        check(f"ViewLayer.{name}.X" in ch or f"ViewLayer.{name}.R" in ch, f"the EXR has {name}")
    check("ViewLayer.Denoising Depth Variance.Z" in ch, "the EXR has Denoising Depth Variance")
    a = S.args()
    cli = os.path.join(a["build"], "reconstruct", "gdpt-reconstruct")
    cli_out = os.path.join(a["out"], "cli_feature.exr")
    subprocess.run([cli, os.path.join(a["out"], "feature.exr"), "-o", cli_out, "--norm", "feature",
                    "--alpha", "0.2", "--layer", "ViewLayer"], check=True)
    ref = exr.rgb(exr.read_exr(cli_out), "")
    err = float(np.abs(feature - ref).max() / max(float(np.abs(ref).max()), 1e-6))
    check(err < 1e-5, f"Combined = gdpt-reconstruct --norm feature on the EXR (max diff / max "
                      f"{err:.2e})")


def test_compositor_node(scene):
    """The Gradient Reconstruct node with norm Feature on the Render Layers of a Feature render
    gives the engine's Combined; on an L1 render (no feature passes) it reports why not."""
    import gdpt.engine as engine_module
    # The Render Layers node shows the half gradients once the scene renders G-PT + Feature.
    S.setup_gdpt(scene, SPP, reconstruction='FEATURE')
    scene.view_layers[0].update_render_passes()
    node = S.reconstruct_tree(scene, norm='FEATURE', alpha=0.2)
    tree = scene.node_tree
    rl = next(n for n in tree.nodes if n.type == 'R_LAYERS')
    for name in HALF_GRADIENTS:
        tree.links.new(rl.outputs[name], node.inputs[name])
    ch = exr.read_exr(S.render_engine(scene, "node", 'GDPT', SPP, reconstruction='FEATURE'))
    composite = exr.rgb(ch, "Composite.Combined.")
    engine_rgb = exr.rgb(ch, "ViewLayer.Combined.")
    err = float(np.abs(composite - engine_rgb).max() / max(float(np.abs(engine_rgb).max()), 1e-6))
    check(err < 1e-4, f"node (Feature, half gradients linked) = the engine's Feature Combined "
                      f"(max diff / max {err:.2e})")
    tree.links.remove(node.inputs["Gradient Y B"].links[0])
    S.render_engine(scene, "node_three", 'GDPT', SPP, reconstruction='FEATURE')
    warnings = engine_module.LAST_RENDER.get("warnings", [])
    check(any("link all four" in w and "unlinked: Gradient Y B" in w for w in warnings),
          f"three of the four half gradients linked: reported ({warnings})")
    for name in HALF_GRADIENTS[:3]:
        tree.links.remove(node.inputs[name].links[0])
    S.render_engine(scene, "node_l1", 'GDPT', SPP, reconstruction='L1')
    warnings = engine_module.LAST_RENDER.get("warnings", [])
    check(any("Feature norm needs" in w for w in warnings),
          f"Feature node on an L1 render: reported ({warnings})")
    scene.use_nodes = False


main()
