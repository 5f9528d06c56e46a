# Renders every material of a library on a sphere over a ground plane, with Gradient PT and with
# Cycles set up as the agreement suite's oracle, and compares them per material. A library is a
# folder of material scripts (one .txt/.py per material, as the Node-To-Python add-on writes them)
# and of .blend files (every material in each, appended one at a time).
#   blender -b --factory-startup --addons gdpt --python-exit-code 1 --python run.py --
#           --lib DIR --out DIR [--json FILE] [--md FILE] [--only NAME,...] [--reuse 1]
#           [--source TEXT] (where the library comes from, for the report's header)
# Verdict: PASS (means within 2% and relMSE < 1%, the agreement suite's bounds, per pixel or over
# 8x8-pixel blocks: at equal sample counts a caustic-heavy material is noise-limited per pixel, and
# a biased translation still shows over blocks), REPORTED (outside them and Gradient PT warned
# about what it did not translate: the warnings name the nodes), FAIL (outside them with no
# warning, or the render or the script failed). --reuse 1 rescores the EXRs already in --out.
import json
import os
import sys
import time

import bpy

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "tests", "blender"))
import adapt  # noqa: E402
import scenes as S  # noqa: E402

SAMPLES = int(os.environ.get("GDPT_MATERIAL_SAMPLES", "128"))
SIZE = int(os.environ.get("GDPT_MATERIAL_SIZE", "96"))
BOUNCES = 4
THRESHOLD, MEAN_TOLERANCE = 0.01, 0.02


def build_scene(scene, material):
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.world.color = (0.05, 0.05, 0.06)
    S.plane("ground", 8.0, (0, 0, 0), material=S.diffuse("ground", (0.5, 0.5, 0.5)))
    S.uv_sphere("ball", 1.0, (0, 0, 1.0), material)
    S.light('AREA', (1.5, -2.0, 4.0), 400.0, target=(0, 0, 1.0), size=1.5)
    S.camera((0, -4.2, 1.6), (0, 0, 1.0), lens=40)
    return scene


def render(scene, engine, path, reuse=False):
    import gdpt.engine as engine_module
    if reuse and os.path.exists(path) and os.path.exists(path + ".json"):
        with open(path + ".json") as f:
            return tuple(json.load(f))
    if engine == 'GDPT':
        S.setup_gdpt(scene, SAMPLES, bounces=BOUNCES)
        engine_module.LAST_RENDER.clear()
    else:
        S.setup_cycles(scene, SAMPLES, bounces=BOUNCES)
    t0 = time.time()
    S.render(scene, path)
    seconds = time.time() - t0
    if engine == 'GDPT':
        last = dict(engine_module.LAST_RENDER)
        if last.get("samples") != SAMPLES:
            raise RuntimeError(f"Gradient PT did not render (got {last})")
        result = (seconds, list(last.get("warnings", [])))
    else:
        result = (seconds, [])
    with open(path + ".json", "w") as f:
        json.dump(result, f)
    return result


def blocks(image, k=8):
    h, w = image.shape[0] // k * k, image.shape[1] // k * k
    return image[:h, :w].reshape(h // k, k, w // k, k, -1).mean(axis=(1, 3))


def verdict(err, err_blocks, ratio, warnings):
    if min(err, err_blocks) < THRESHOLD and abs(ratio - 1.0) < MEAN_TOLERANCE:
        return "PASS"
    return "REPORTED" if warnings else "FAIL"


def load_script(path):
    """(materials the script made, settings lost loading it)."""
    with open(path, encoding="utf-8") as f:
        return adapt.load(bpy, f.read(), path)


def load_from_blend(path, material):
    """([the material appended from the .blend], its image textures whose files are missing)."""
    with bpy.data.libraries.load(path, link=False) as (source, target):
        target.materials = [material]
    loaded = [m for m in target.materials if m is not None]
    missing = sorted({f"image '{n.image.name}' ({n.image.filepath}) missing" for m in loaded
                      for n in m.node_tree.nodes if n.type == 'TEX_IMAGE' and n.image
                      and n.image.packed_file is None and not n.image.has_data
                      and not os.path.exists(bpy.path.abspath(n.image.filepath))})
    return loaded, missing


def library_entries(lib):
    """(row name, file, loader) per material: one per script, one per material of each .blend
    (named 'material [file]' when two files hold materials of the same name)."""
    entries = []
    for f in sorted(os.listdir(lib)):
        path = os.path.join(lib, f)
        if f.endswith((".txt", ".py")):
            entries.append((os.path.splitext(f)[0], f, lambda p=path: load_script(p)))
        elif f.endswith(".blend"):
            with bpy.data.libraries.load(path) as (source, _):
                names = list(source.materials)
            entries += [(m, f, lambda p=path, m=m: load_from_blend(p, m)) for m in names]
    counts = {}
    for name, _, _ in entries:
        counts[name] = counts.get(name, 0) + 1
    return [(f"{n} [{os.path.splitext(f)[0]}]" if counts[n] > 1 else n, f, load)
            for n, f, load in entries]


def run_material(entry, out_dir, reuse):
    name, file, load = entry
    row = {"file": file, "name": name}
    scene = S.clear()
    try:
        materials, skipped = load()
    except Exception as e:  # a material that does not load is a row of the table, not the end
        row.update(verdict="FAIL", reason=f"material does not load in Blender 3.4: "
                   f"{type(e).__name__}: {e}".splitlines()[0])
        return row
    if not materials:
        row.update(verdict="FAIL", reason="no material loaded")
        return row
    material = materials[0]
    row.update(material=material.name, skipped_on_load=skipped,
               nodes=sorted({n.bl_idname for n in material.node_tree.nodes}))
    build_scene(scene, material)
    safe = "".join(c if c.isalnum() else "_" for c in name)
    try:
        t_gdpt, warnings = render(scene, 'GDPT', os.path.join(out_dir, f"{safe}_gdpt.exr"), reuse)
        t_cycles, _ = render(scene, 'CYCLES', os.path.join(out_dir, f"{safe}_cycles.exr"), reuse)
    except Exception as e:
        row.update(verdict="FAIL", reason=f"render failed: {type(e).__name__}: {e}".splitlines()[0])
        return row
    a = S.read_rgb(os.path.join(out_dir, f"{safe}_gdpt.exr"))
    b = S.read_rgb(os.path.join(out_dir, f"{safe}_cycles.exr"))
    err, err_blocks = S.rel_mse(a, b), S.rel_mse(blocks(a), blocks(b))
    ratio = float(a.mean() / max(b.mean(), 1e-9))
    row.update(rel_mse=err, rel_mse_8px_blocks=err_blocks, mean_ratio=ratio, warnings=warnings,
               seconds_gdpt=round(t_gdpt, 1), seconds_cycles=round(t_cycles, 1),
               verdict=verdict(err, err_blocks, ratio, warnings))
    print(f"MATERIAL {name}: {row['verdict']} relMSE {err:.5f} (8-px blocks {err_blocks:.5f}) "
          f"mean ratio {ratio:.3f} warnings {warnings}", flush=True)
    return row


def markdown(rows, lib):
    lines = [f"Library: `{lib}`; {SAMPLES} spp each engine, {SIZE}x{SIZE}, {BOUNCES} bounces.", "",
             "| Material | Verdict | relMSE | relMSE 8-px blocks | Mean GDPT/Cycles "
             "| Gradient PT warnings / reason | Settings lost loading into 3.4 |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        err = f"{r['rel_mse']:.4f}" if "rel_mse" in r else "-"
        err8 = f"{r['rel_mse_8px_blocks']:.4f}" if "rel_mse" in r else "-"
        ratio = f"{r['mean_ratio']:.3f}" if "mean_ratio" in r else "-"
        why = "; ".join(r.get("warnings") or []) or r.get("reason", "")
        lost = len(r.get("skipped_on_load", []))
        lines.append(f"| {r['name']} | {r['verdict']} | {err} | {err8} | {ratio} "
                     f"| {why.replace('|', '/')} | {lost} |")
    return "\n".join(lines) + "\n"


def main():
    a = S.args()
    lib, out_dir = a.get("lib"), a.get("out")
    if not lib or not os.path.isdir(lib) or not out_dir:
        raise SystemExit("usage: run.py -- --lib DIR (material scripts, .blend files) --out DIR "
                         "[--json F] [--md F]")
    os.makedirs(out_dir, exist_ok=True)
    only = set(a["only"].split(",")) if "only" in a else None
    rows = [run_material(e, out_dir, a.get("reuse") == "1") for e in library_entries(lib)
            if only is None or e[0] in only]
    if not rows:
        raise SystemExit(f"no material scripts (.txt/.py) or .blend materials in {lib}"
                         + (f" named {sorted(only)}" if only else ""))
    json_path = a.get("json", os.path.join(out_dir, "materials.json"))
    with open(json_path, "w") as f:
        json.dump({"library": a.get("source", lib), "samples": SAMPLES, "size": SIZE, "materials": rows}, f,
                  indent=1)
    with open(a.get("md", os.path.join(out_dir, "materials.md")), "w") as f:
        f.write(markdown(rows, a.get("source", lib)))
    counts = {v: sum(r["verdict"] == v for r in rows) for v in ("PASS", "REPORTED", "FAIL")}
    print(f"MATERIALS {len(rows)}: {counts}", flush=True)


main()
