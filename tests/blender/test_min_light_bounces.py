# Render Properties > Sampling > Min Light Bounces (scene.gdpt.min_light_bounces), with Cycles'
# meaning: Cycles' kernel uses min_light_bounces + 1 and applies roulette at a hit whose bounce
# count exceeds it, so with the setting m the first roulette decides whether vertex m + 2 is
# shaded, from the throughput after scattering at vertex m + 1 (vertex 0: the camera ray's hit);
# the ray to vertex m + 2 is traced either way, for the emission it finds.
#  - analytic: the camera inside a closed diffuse box of albedo 0.5, lit by a point lamp that casts
#    no shadow (no shadow rays), traces exactly the camera ray and the extension rays. Every path
#    has the same throughput, 0.5^(v + 1) after vertex v divided by the roulette probabilities so
#    far, so the expected rays per sample follow from the roulette rule alone
#    (q = min(sqrt(max throughput), 1) after vertex m + 1 and later ones): PT must trace that many,
#    for m = 0 (Cycles' default), 2 (GDPT's) and 8 (no roulette within 4 bounces). A path the
#    roulette stops after a glossy or specular bounce still traces the ray that bounce sampled,
#    for the lamp it may find (Cycles' order); after a diffuse bounce, or when no ray can find
#    emission, it does not. So the same count rule is checked three ways: a diffuse box lit by a
#    point lamp of radius 0 and by an area lamp (stopped paths trace nothing more), and a mirror
#    box (Glossy BSDF, roughness 0, colour 0.5: the same throughput) around the area lamp
#    (stopped paths trace their last ray);
#  - G-PT follows the same setting: fewer rays with a lower minimum;
#  - the image does not depend on it beyond noise (roulette is unbiased).
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(__file__))
import scenes as S  # noqa: E402

check = S.check
ALBEDO = 0.5
BOUNCES = 4


def expected_rays(min_bounces, last_ray):
    """Camera ray + extension rays per sample: the ray leaving vertex v (v = 0..BOUNCES, the last
    one only to look for emitters) is traced when the path survived the roulette at vertices
    min_bounces + 1..v - 1, and at v too unless stopped paths trace their `last_ray`."""
    rays, beta, alive = 1.0, 1.0, 1.0
    for v in range(BOUNCES + 1):
        beta *= ALBEDO
        reached = alive
        if v >= min_bounces + 1:
            q = min(beta ** 0.5, 1.0)
            alive *= q
            beta /= q
        rays += reached if last_ray else alive
    return rays


def render(scene, mode, min_bounces, samples=16):
    import gdpt.engine as engine
    S.setup_gdpt(scene, samples, mode=mode, reconstruction='NONE', bounces=BOUNCES)
    scene.gdpt.min_light_bounces = min_bounces
    engine.LAST_RENDER.clear()
    path = S.render(scene, os.path.join(S.args()["out"], f"box_{mode}_{min_bounces}.exr"))
    info = dict(engine.LAST_RENDER)
    check(info.get("status") == "finished", f"{mode} min {min_bounces}: Gradient PT rendered")
    count = scene.render.resolution_x * scene.render.resolution_y * samples
    return info["rays"] / count, S.read_rgb(path)


def main():
    os.makedirs(S.args()["out"], exist_ok=True)
    scene = S.clear()
    bpy.ops.mesh.primitive_cube_add(size=4.0, location=(0, 0, 2))  # watertight: no ray escapes
    box = bpy.context.active_object
    box.data.materials.append(S.diffuse("box", (ALBEDO, ALBEDO, ALBEDO)))
    S.camera((0, -1.5, 2), (0, 1, 2), lens=20)
    scene.render.resolution_x, scene.render.resolution_y = 48, 32

    diffuse = box.data.materials[0]
    mirror = S.glossy("mirror", 0.0, (ALBEDO, ALBEDO, ALBEDO))
    for kind, material in (('POINT', diffuse), ('AREA', diffuse), ('AREA', mirror)):
        for obj in [o for o in bpy.data.objects if o.type == 'LIGHT']:
            bpy.data.objects.remove(obj)
        box.data.materials[0] = material
        name = f"{kind.lower()} lamp, {'mirror' if material is mirror else 'diffuse'} box"
        lamp = S.light(kind, (0.5, 0.5, 3), 200.0, target=(0.5, 0.5, 0))
        lamp.data.cycles.cast_shadow = False
        if kind == 'AREA':
            lamp.data.size = 0.5
        else:
            lamp.data.shadow_soft_size = 0.0  # a true point: no ray can hit it
        images = {}
        for m in (0, 2, 8):
            # The mirror box sees the lamp only along rare mirror chains: its mean needs 512 spp
            # to be within 1% (the diffuse boxes: 16 spp, and 24576 samples keep the standard
            # error of the mean ray count below 0.5%).
            rays, images[m] = render(scene, 'PT', m, 512 if material is mirror else 16)
            want = expected_rays(m, last_ray=material is mirror)
            check(abs(rays / want - 1) < 0.02, f"{name}, PT min light bounces {m}: "
                                               f"{rays:.4f} rays per sample, analytic {want:.4f}")
        mean = {m: float(img.mean()) for m, img in images.items()}
        check(abs(mean[0] / mean[8] - 1) < 0.02 and abs(mean[2] / mean[8] - 1) < 0.02,
              f"{name}, unbiased: mean radiance {mean[0]:.4f} / {mean[2]:.4f} / "
              f"{mean[8]:.4f} (min 0 / 2 / 8)")
    box.data.materials[0] = diffuse

    gpt = {m: render(scene, 'GPT', m)[0] for m in (0, 2)}
    check(gpt[0] < 0.9 * gpt[2],
          f"G-PT follows the setting: {gpt[0]:.3f} rays per sample at 0, {gpt[2]:.3f} at 2")
    print("ALL CHECKS PASSED", flush=True)


main()
