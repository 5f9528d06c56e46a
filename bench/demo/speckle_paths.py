# Which light makes the demo's remaining bright speckles (speckles.py): the demo's G-PT Feature
# render at its own samples, and the same with the glass sphere's reflection removed for rays
# that left a diffuse surface (its Glass BSDF mixed, by Light Path > Is Diffuse Ray, with a sharp
# Refraction BSDF of the same IOR: the floor's reflective caustic gone, the refractive one kept).
# Per seed and variant: the speckle count against speckles.py's reference and, at each pixel
# where a speckle was seen in any render, the largest of the two halves (Primal A / B) over the
# reference's 5x5 median: the spikes the reconstruction has to work with.
#   /usr/bin/python3 bench/demo/speckle_paths.py [--build build] [--seeds 4]
# Needs speckles.py's scene and reference (out/bench/demo). Writes
# bench/results/demo_speckle_paths.json.
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import speckles as SP  # noqa: E402

R = SP.R
NO_FLOOR_REFLECTION = """
import sys, bpy
src, dst = sys.argv[sys.argv.index("--") + 1:][:2]
bpy.ops.wm.open_mainfile(filepath=src)
nt = bpy.data.materials["Glass"].node_tree
glass = next(n for n in nt.nodes if n.type == 'BSDF_GLASS')
out = next(n for n in nt.nodes if n.type == 'OUTPUT_MATERIAL')
refr = nt.nodes.new("ShaderNodeBsdfRefraction")
refr.distribution = 'SHARP'
refr.inputs["IOR"].default_value = glass.inputs["IOR"].default_value
mix = nt.nodes.new("ShaderNodeMixShader")
nt.links.new(nt.nodes.new("ShaderNodeLightPath").outputs["Is Diffuse Ray"], mix.inputs[0])
nt.links.new(glass.outputs[0], mix.inputs[1])
nt.links.new(refr.outputs[0], mix.inputs[2])
nt.links.new(mix.outputs[0], out.inputs["Surface"])
bpy.ops.wm.save_as_mainfile(filepath=dst)
"""


def main():
    args, ref, out, blender = SP.demo_study("demo_speckle_paths")
    paths = {"glass": [], "no_floor_reflection": []}
    try:
        samples = SP.demo_samples(blender, ref.blend)
        script = os.path.join(out, "no_floor_reflection.py")
        with open(script, "w") as f:
            f.write(NO_FLOOR_REFLECTION)
        blends = {"glass": ref.blend, "no_floor_reflection": os.path.join(out, "variant.blend")}
        blender.run(script, ref.blend, blends["no_floor_reflection"])
        for seed in range(1, args.seeds + 1):
            for name, blend in blends.items():
                path = os.path.join(out, f"{name}_{seed}.exr")
                R.render(blender, blend, "gpt_feature", path, samples=samples, seed=seed)
                paths[name].append(path)
    finally:
        blender.close()
    lum = SP.M.luminance
    masks = [SP.speckle_mask(R.rgb(p), ref.median) for ps in paths.values() for p in ps]
    where = [(int(x), int(y)) for y, x in zip(*np.nonzero(np.any(masks, axis=0)))]
    result = {"samples": samples, "seeds": args.seeds, "commit": R.git("rev-parse", "--short",
                                                                        "HEAD"),
              "pixels": [list(w) for w in where]}
    for name, ps in paths.items():
        spikes = np.zeros(len(where))
        for p in ps:
            halves = [lum(R.rgb(p, f"ViewLayer.Primal {h}.")) / ref.median for h in "AB"]
            spikes = np.maximum(spikes, [max(h[y, x] for h in halves) for x, y in where])
        count = float(np.mean([SP.speckles(R.rgb(p), ref.median) for p in ps]))
        result[name] = {"speckles": count, "halves_max_over_median": spikes.round(2).tolist()}
        print(f"{name:20s} speckles {count:.2f} per render; halves' largest over the median at "
              f"the speckle pixels {np.round(spikes, 1).tolist()}", flush=True)
    with open(os.path.join(SP.ROOT, "bench", "results", "demo_speckle_paths.json"), "w") as f:
        json.dump(result, f, indent=1)


if __name__ == "__main__":
    main()
