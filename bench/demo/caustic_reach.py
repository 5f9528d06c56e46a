# Why the demo's last bright pixels stay at 32 samples: at each Feature speckle pixel that
# speckles.py lists (bench/results/demo_speckles.json), the surfaces the pixel sees (its camera
# ray's centre and the branches it takes through the glass sphere, reflection weighted by Fresnel,
# refraction by the rest), and at each such surface point how the lamp's light through the sphere
# can be found: the chance that a cosine-weighted BSDF sample refracts into and out of the sphere
# and meets the lamp (and, apart, that it reflects off the sphere onto it), the share of the lamp's
# area such refracted paths reach (where a manifold walk from a light sample can succeed: Shadow
# Caustics), the share whose straight segment crosses the sphere (the walk's seeds) and the share
# the point sees directly. A few percent for each technique means a caustic of rare, bright paths:
# 0-3 per half of 16 samples. The scene is traced analytically from the geometry demo_geometry.py
# reads from the demo's .blend: true spheres for the glass ball and the metal ball (64 x 32 UV
# spheres; a branch ends at the metal one), the lamp and the room's five sides. Each pixel is
# traced at its centre and, for the chance that a camera sample meets the lamp through the glass,
# over the pixel filter's footprint (Blackman-Harris, 1.5 px).
#   /usr/bin/python3 bench/demo/caustic_reach.py [--build build] [--directions 2000000]
# Needs speckles.py's scene (out/bench/demo/demo.blend) and its results. Writes
# bench/results/demo_caustic_reach.json.
import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import speckles as SP  # noqa: E402

MIN_BRANCH_WEIGHT = 0.02
LAMP_GRID = 100  # cells per side when measuring the lamp's reachable area


class Ball:
    def __init__(self, center, radius, ior):
        self.c, self.r, self.ior = np.asarray(center, float), float(radius), float(ior)

    def hit(self, o, d, exit_only=False):
        """Ray parameters of the first hit (np.inf for none) of rays o + t d (N x 3)."""
        oc = o - self.c
        b = np.einsum("ij,ij->i", oc, d)
        disc = b * b - (np.einsum("ij,ij->i", oc, oc) - self.r * self.r)
        s = np.sqrt(np.maximum(disc, 0.0))
        near, far = -b - s, -b + s
        t = far if exit_only else np.where(near > 1e-7, near, far)
        return np.where((disc > 0) & (t > 1e-7), t, np.inf)

    def scatter(self, p, d):
        """At points p on the ball, for directions d: (reflected, refracted, Fresnel, TIR)."""
        n = (p - self.c) / self.r
        inside = np.einsum("ij,ij->i", d, n) > 0
        n = np.where(inside[:, None], -n, n)
        eta = np.where(inside, self.ior, 1.0 / self.ior)
        ci = -np.einsum("ij,ij->i", d, n)
        st2 = eta * eta * (1 - ci * ci)
        tir = st2 >= 1
        ct = np.sqrt(np.maximum(1 - st2, 0.0))
        rs = (eta * ci - ct) / (eta * ci + ct)
        rp = (ci - eta * ct) / (ci + eta * ct)
        fresnel = np.where(tir, 1.0, 0.5 * (rs * rs + rp * rp))
        refl = d + 2 * ci[:, None] * n
        refr = eta[:, None] * d + (eta * ci - ct)[:, None] * n
        return refl, refr / np.linalg.norm(refr, axis=1)[:, None], fresnel, tir


def camera_ray(g, x, y):
    """The ray through the centre of pixel (x, y), y counted from the image's bottom (the rows of
    speckles.py's arrays)."""
    w, h = g["resolution"]
    m = np.array(g["camera_matrix"])
    scale = g["sensor_width"] / g["lens"] / max(w, h)  # sensor fit AUTO: the larger side
    d = m[:3, :3] @ np.array([(x + 0.5 - w / 2) * scale, (y + 0.5 - h / 2) * scale, -1.0])
    return m[:3, 3], d / np.linalg.norm(d)


# make_demo_scene.py's room, 4 m, open towards the camera: (name, axis, coordinate, inward normal).
ROOM = (("floor", 2, 0.0, 1.0), ("ceiling", 2, 4.0, -1.0), ("left wall", 0, -2.0, 1.0),
        ("right wall", 0, 2.0, -1.0), ("back wall", 1, 2.0, -1.0))
ROOM_BOX = ((-2.0, -2.0, 0.0), (2.0, 2.0, 4.0))


def room_hit(o, d):
    """(name, point, inward normal) where the ray o + t d leaves the ball's side of the room."""
    best = (np.inf, None)
    for name, axis, at, inward in ROOM:
        if d[axis] * inward < 0:
            t = (at - o[axis]) / d[axis]
            q = o + t * d
            if 0 < t < best[0] and all(ROOM_BOX[0][i] - 1e-6 <= q[i] <= ROOM_BOX[1][i] + 1e-6
                                       for i in range(3) if i != axis):
                best = (t, name, axis, inward)
    if best[1] is None:
        return "out of the room", None, None
    t, name, axis, inward = best
    normal = np.zeros(3)
    normal[axis] = inward
    return name, o + t * d, normal


def branch_ends(ball, metal, g, o, d, weight=1.0, path="", depth=0):
    """[(path, weight, end, point, normal)] where the branches of the ray o + t d end: on a
    surface of the room or on the lamp (seen through the ball's reflections and refractions)."""
    t = ball.hit(o[None], d[None])[0]
    name, p, normal = room_hit(o, d)
    _, lamp = on_lamp(g, o[None], d[None])
    if lamp[0] and not (t < (g["lamp_center"][2] - o[2]) / d[2]):
        return [(path or "direct", weight, "lamp", None, None)]
    t_metal = metal.hit(o[None], d[None])[0]
    if t_metal < t and (p is None or t_metal < np.dot(p - o, d)):
        return [(path or "direct", weight, "metal sphere", None, None)]
    if not np.isfinite(t) or (p is not None and np.dot(p - o, d) < t):
        return [(path or "direct", weight, name, p, normal)]
    if depth == 6:
        return []
    p = o + t * d
    refl, refr, f, tir = (a[0] for a in ball.scatter(p[None], d[None]))
    out = []
    for kind, w, nd in (("R", f, refl), ("T", 1 - f, refr)):
        if weight * w >= MIN_BRANCH_WEIGHT and not (kind == "T" and tir):
            out += branch_ends(ball, metal, g, p, nd, weight * w, path + kind, depth + 1)
    return out


def lamp_square(g):
    """The lamp's centre and half size (a level square facing down, as the demo's)."""
    half = g["lamp_size"] / 2
    assert g["lamp_shape"] == "SQUARE" and not any(g["lamp_rotation"]), "a level square lamp"
    return np.array(g["lamp_center"]), half


def on_lamp(g, o, d):
    """Where rays o + t d (going up) meet the lamp's plane, and whether inside the lamp."""
    c, half = lamp_square(g)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (c[2] - o[:, 2]) / d[:, 2]
    q = o + t[:, None] * d
    inside = (d[:, 2] > 0) & (np.abs(q[:, 0] - c[0]) < half) & (np.abs(q[:, 1] - c[1]) < half)
    return q, inside


def reach(ball, g, p, normal, n, rng):
    """How the lamp's light through the ball reaches the point p of a surface facing `normal`."""
    u1, u2 = rng.random(n), rng.random(n)
    r, phi = np.sqrt(u1), 2 * np.pi * u2
    s = np.cross(normal, [0.0, 0.0, 1.0] if abs(normal[2]) < 0.9 else [1.0, 0.0, 0.0])
    s /= np.linalg.norm(s)
    frame = np.stack([s, np.cross(normal, s), normal])
    local = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1 - u1)], 1)  # cosine-weighted
    d = local @ frame
    o = np.repeat(p[None], n, 0)
    t = ball.hit(o, d)
    hits = np.isfinite(t)
    q1 = o + np.where(hits, t, 0)[:, None] * d
    refl, refr, f, tir = ball.scatter(q1, d)
    # Refracted in and out (the first exit; an internal reflection there is not followed).
    t2 = ball.hit(q1, refr, exit_only=True)
    q2 = q1 + np.where(np.isfinite(t2), t2, 0)[:, None] * refr
    _, out_dir, f2, tir2 = ball.scatter(q2, refr)
    lamp_q, refracted = on_lamp(g, q2, out_dir)
    refracted &= hits & ~tir & ~tir2 & np.isfinite(t2)
    _, reflected = on_lamp(g, q1, refl)
    reflected &= hits & ~np.isfinite(ball.hit(q1, refl))
    c, half = lamp_square(g)
    occupied, _, _ = np.histogram2d(lamp_q[refracted, 0], lamp_q[refracted, 1], bins=LAMP_GRID,
                                    range=[[c[0] - half, c[0] + half], [c[1] - half, c[1] + half]])
    # The lamp's points seen straight from p, and those whose straight segment crosses the ball.
    s = (np.arange(LAMP_GRID) + 0.5) / LAMP_GRID * 2 * half - half
    ys = np.stack(np.meshgrid(c[0] + s, c[1] + s), -1).reshape(-1, 2)
    y = np.column_stack([ys, np.full(len(ys), c[2])])
    seg = y - p
    length = np.linalg.norm(seg, axis=1)
    crossed = ball.hit(np.repeat(p[None], len(y), 0), seg / length[:, None]) < length
    return {"bsdf_refracted_to_lamp": float(refracted.mean()),
            "bsdf_reflected_to_lamp": float(reflected.mean()),
            "lamp_share_reached_refracted": float((occupied > 0).mean()),
            "lamp_share_straight_through_ball": float(crossed.mean()),
            "lamp_share_seen_directly": float(1 - crossed.mean())}


def describe(row):
    if "point" not in row:
        return "the lamp itself" if row["end"] == "lamp" else row["end"]
    return (f"{row['end']} {np.round(row['point'], 2).tolist()}, {row['from_contact_m']:.2f} m "
            "from the ball's contact: BSDF refracted "
            f"{row['bsdf_refracted_to_lamp']:.3f}, reflected {row['bsdf_reflected_to_lamp']:.3f}; "
            f"lamp reached refracted {row['lamp_share_reached_refracted']:.3f}, straight through "
            f"the ball {row['lamp_share_straight_through_ball']:.2f}")


# speckles.py's measurements: unbiased (Filter Glossy 0) and with the demo's own setting.
MEASUREMENTS = {"filter_glossy_0": 0.0, "filter_glossy_1": 1.0}


def speckle_pixels():
    """{(x, y): [the measurements that flagged the pixel]} over speckles.py's results files."""
    pixels = {}
    for name, filter_glossy in MEASUREMENTS.items():
        path = SP.results_path(filter_glossy=filter_glossy)
        if not os.path.exists(path):
            continue
        with open(path) as f:
            rows = json.load(f)["per_seed"]["feature"]
        for xy in sorted({(s["x"], s["y"]) for r in rows for s in r.get("speckle_pixels", [])}):
            pixels.setdefault(xy, []).append(name)
    return dict(sorted(pixels.items()))


def blackman_harris(x, width):
    """The pixel filter's 1-D profile over [-width, width] (render/pixel_filter.cpp)."""
    v = np.pi * (x / width + 1.0)
    return 0.35875 - 0.48829 * np.cos(v) + 0.14128 * np.cos(2 * v) - 0.01168 * np.cos(3 * v)


def camera_lamp_chance(ball, metal, g, x, y, n=41):
    """The chance that a camera sample of pixel (x, y), its position drawn from the pixel filter,
    follows Fresnel choices through the ball that end on the lamp, and per chain."""
    kind, width = g["pixel_filter"]
    assert kind == "BLACKMAN_HARRIS", "the demo's filter, Cycles' default"
    offsets = np.linspace(-width, width, n)
    profile = blackman_harris(offsets, width)
    weights = np.outer(profile, profile) / profile.sum() ** 2
    chains = {}
    for i, dy in enumerate(offsets):
        for j, dx in enumerate(offsets):
            o, d = camera_ray(g, x + dx, y + dy)
            for path, w, end, _, _ in branch_ends(ball, metal, g, o, d):
                if end == "lamp":
                    chains[path] = chains.get(path, 0.0) + weights[i, j] * w
    return sum(chains.values()), chains


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--build", default="build")
    p.add_argument("--directions", type=int, default=2000000)
    args = p.parse_args()
    blend = os.path.join(SP.ROOT, "out", "bench", "demo", "demo.blend")
    blender = SP.R.Blender(args.build)
    try:
        g = json.loads(blender.run(os.path.join(HERE, "demo_geometry.py"),
                                   blend).split("DEMO_GEOMETRY ")[1].splitlines()[0])
    finally:
        blender.close()
    ball = Ball(g["ball_center"], g["ball_radius"], g["ior"])
    metal = Ball(g["metal_center"], g["metal_radius"], 1.0)  # opaque: only its hits count
    rng = np.random.default_rng(1)
    contact = ball.c - np.array([0.0, 0.0, ball.r])
    result = {"commit": SP.R.git("rev-parse", "--short", "HEAD"), "directions": args.directions,
              "pixels": []}
    for (x, y), flagged_by in speckle_pixels().items():
        chance, chains = camera_lamp_chance(ball, metal, g, x, y)
        print(f"({x:3d}, {y:3d}) flagged by {', '.join(flagged_by)}: camera samples meeting the "
              f"lamp through the ball {chance:.4f} "
              f"{ {k: round(v, 4) for k, v in chains.items()} }; the pixel centre's branches:",
              flush=True)
        o, d = camera_ray(g, x, y)
        points = []
        for path, w, end, pt, normal in branch_ends(ball, metal, g, o, d):
            row = {"camera_path": path, "weight": round(float(w), 3), "end": end}
            if pt is not None:
                row.update(point=np.round(pt, 3).tolist(),
                           from_contact_m=round(float(np.linalg.norm(pt - contact)), 3),
                           **reach(ball, g, pt, normal, args.directions, rng))
            points.append(row)
            print(f"    {path:6s} w {w:.2f} {describe(row)}", flush=True)
        result["pixels"].append({"x": x, "y": y, "flagged_by": flagged_by,
                                 "camera_samples_meeting_lamp": chance,
                                 "camera_chains_meeting_lamp": chains, "branches": points})
    with open(os.path.join(SP.ROOT, "bench", "results", "demo_caustic_reach.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
