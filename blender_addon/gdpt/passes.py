# The render passes of GDPT and how a film snapshot becomes one Blender render layer buffer.
#
# Writing pixels: one layer.passes.foreach_set("rect", buffer) per update, with the passes
# concatenated in the layer's own order. Assigning pass.rect per pass goes through Python
# sequences and takes seconds on a full-HD frame.

import numpy as np

# (name, channels, channel ids, type, view-layer toggle); order = registration order.
PASSES = (
    ("Primal", 3, "RGB", 'COLOR', "use_pass_primal"),
    ("Gradient X", 3, "RGB", 'COLOR', "use_pass_gradients"),
    ("Gradient Y", 3, "RGB", 'COLOR', "use_pass_gradients"),
    ("Emission", 3, "RGB", 'COLOR', "use_pass_emission"),
    ("Variance", 3, "XYZ", 'VECTOR', "use_pass_variance"),
    ("Shift Failures", 1, "X", 'VALUE', "use_pass_shift_failures"),
)

# Film key for each pass name.
_FILM_KEYS = {
    "Primal": "primal",
    "Gradient X": "gradient_x",
    "Gradient Y": "gradient_y",
    "Emission": "emission",
    "Variance": "variance",
    "Shift Failures": "shift_failures",
    "Sample Count": "sample_count",
    "Shift Attempts": "shift_attempts",
    "Gradient Halves": "gradient_halves",
    "Depth": "depth",
    "IndexOB": "object_index",
    "IndexMA": "material_index",
    "Normal": "normal",
    "Mist": "mist",
    "Denoising Albedo": "denoising_albedo",
    "Denoising Normal": "denoising_normal",
    "Denoising Depth": "denoising_depth",
    "Denoising Albedo Variance": "denoising_albedo_variance",
    "Denoising Normal Variance": "denoising_normal_variance",
    "Denoising Depth Variance": "denoising_depth_variance",
    "Primal A": "primal_a",
    "Primal B": "primal_b",
    "Primal A Variance": "primal_a_variance",
    "Primal B Variance": "primal_b_variance",
    "Gradient X A": "gradient_x_a",
    "Gradient X B": "gradient_x_b",
    "Gradient Y A": "gradient_y_a",
    "Gradient Y B": "gradient_y_b",
}

# The feature passes, registered when the Feature reconstruction renders them
# (feature_passes_on): the guides under the names Blender's Denoise node and Cycles use, and
# what `gdpt-reconstruct --norm feature` and the compositor node read besides (the primal's
# halves over even / odd samples, each pass's variance of its pixel mean).
FEATURE_PASSES = (
    ("Denoising Albedo", 3, "RGB", 'COLOR'),
    ("Denoising Normal", 3, "XYZ", 'VECTOR'),
    ("Denoising Depth", 1, "Z", 'VALUE'),
    ("Primal A", 3, "RGB", 'COLOR'),
    ("Primal B", 3, "RGB", 'COLOR'),
    ("Primal A Variance", 3, "XYZ", 'VECTOR'),
    ("Primal B Variance", 3, "XYZ", 'VECTOR'),
    ("Denoising Albedo Variance", 3, "XYZ", 'VECTOR'),
    ("Denoising Normal Variance", 3, "XYZ", 'VECTOR'),
    ("Denoising Depth Variance", 1, "Z", 'VALUE'),
)

# G-PT's gradients over the primal's halves (the even / odd samples of Primal A / B), registered
# with the feature passes in G-PT mode: the Feature reconstruction solves each half on its own.
# In PT mode the gradients are the primal's differences, which Primal A / B already give.
GRADIENT_HALF_PASSES = (
    ("Gradient X A", 3, "RGB", 'COLOR'),
    ("Gradient X B", 3, "RGB", 'COLOR'),
    ("Gradient Y A", 3, "RGB", 'COLOR'),
    ("Gradient Y B", 3, "RGB", 'COLOR'),
)


# What gdpt-merge needs to combine renders of disjoint sample ranges exactly (reconstruct/
# pass_merge.h), always registered: the samples per pixel; the shift attempts per sample
# (Shift Failures' weight); the luminance means of each pixel's forward gradient halves and
# their variances (X, Y, Z, W: dx's and dy's means, then their variances), which the Variance
# pass sums with the neighbours' backward halves.
MERGE_PASSES = (
    ("Sample Count", 1, "X", 'VALUE'),
    ("Shift Attempts", 1, "X", 'VALUE'),
    ("Gradient Halves", 4, "XYZW", 'VECTOR'),
)


def feature_passes_on(scene):
    """Whether the render computes the feature passes: the Feature reconstruction needs them."""
    settings = getattr(scene, "gdpt", None)
    return settings is not None and settings.reconstruction == 'FEATURE'


def gradient_half_passes_on(scene):
    """Whether the render computes G-PT's gradients over the halves: feature passes, G-PT."""
    return feature_passes_on(scene) and scene.gdpt.mode == 'GPT'


def register_passes(engine, scene, view_layer):
    engine.register_pass(scene, view_layer, "Combined", 4, "RGBA", 'COLOR')
    settings = getattr(view_layer, "gdpt", None)
    for name, channels, chan_id, kind, toggle in PASSES:
        if settings is None or getattr(settings, toggle):
            engine.register_pass(scene, view_layer, name, channels, chan_id, kind)
    # Blender's own data-pass toggles (View Layer > Passes > Data, as for Cycles).
    if view_layer.use_pass_z:
        engine.register_pass(scene, view_layer, "Depth", 1, "Z", 'VALUE')
    if view_layer.use_pass_object_index:
        engine.register_pass(scene, view_layer, "IndexOB", 1, "X", 'VALUE')
    if view_layer.use_pass_material_index:
        engine.register_pass(scene, view_layer, "IndexMA", 1, "X", 'VALUE')
    if view_layer.use_pass_normal:
        engine.register_pass(scene, view_layer, "Normal", 3, "XYZ", 'VECTOR')
    if view_layer.use_pass_mist:
        engine.register_pass(scene, view_layer, "Mist", 1, "Z", 'VALUE')
    if feature_passes_on(scene):
        for name, channels, chan_id, kind in FEATURE_PASSES:
            engine.register_pass(scene, view_layer, name, channels, chan_id, kind)
    if gradient_half_passes_on(scene):
        for name, channels, chan_id, kind in GRADIENT_HALF_PASSES:
            engine.register_pass(scene, view_layer, name, channels, chan_id, kind)
    for name, channels, chan_id, kind in MERGE_PASSES:
        engine.register_pass(scene, view_layer, name, channels, chan_id, kind)


# World > Mist Pass falloff -> Cycles' exponent.
_MIST_FALLOFF = {'QUADRATIC': 2.0, 'LINEAR': 1.0, 'INVERSE_QUADRATIC': 0.5}


def data_pass_settings(scene, view_layer):
    """The render settings of the Normal and Mist passes for this view layer (Passes > Data) and
    the scene's World > Mist Pass (Blender's defaults without a world)."""
    d = {"normal_pass": bool(view_layer.use_pass_normal),
         "mist_pass": bool(view_layer.use_pass_mist),
         "feature_passes": feature_passes_on(scene)}
    world = scene.world
    if world is not None:
        mist = world.mist_settings
        d.update(mist_start=float(mist.start), mist_depth=float(mist.depth),
                 mist_falloff=_MIST_FALLOFF.get(mist.falloff, 2.0))
    return d


def layer_buffer_size(layer, count):
    """Floats in one buffer for every pass of `layer` at `count` pixels."""
    return sum(p.channels for p in layer.passes) * count


def layer_buffer(layer, film, combined_rgb, out=None):
    """One float32 buffer for every pass of `layer` (its order), from a film dict and the
    reconstructed RGB image. Passes GDPT does not produce (e.g. Depth) are written as zeros.
    `out`: a buffer of layer_buffer_size() floats to fill and return instead of a new one (every
    element is written). Progressive updates reuse one: a fresh 166 MB buffer (1920x1080) cost
    0.66-1.1 s of page faults per update on the benchmark VM, a reused one 6 ms."""
    height, width = film["height"], film["width"]
    count = width * height
    passes = list(layer.passes)
    total = sum(p.channels for p in passes) * count
    buffer = np.empty(total, dtype=np.float32) if out is None else out
    if buffer.size != total:
        raise ValueError(f"layer buffer of {buffer.size} floats for {total}")
    offset = 0
    for p in passes:
        size = p.channels * count
        view = buffer[offset:offset + size].reshape(count, p.channels)
        if p.name == "Combined":
            view[:, :3] = combined_rgb.reshape(count, 3)
            # Coverage: 1 unless Film > Transparent leaves the background out.
            view[:, 3] = film["alpha"].reshape(count) if "alpha" in film else 1.0
        elif p.name in _FILM_KEYS and _FILM_KEYS[p.name] in film:
            data = film[_FILM_KEYS[p.name]].reshape(count, -1)
            used = min(p.channels, data.shape[1])
            view[:, :used] = data[:, :used]
            view[:, used:] = 0.0
        else:
            view[:] = 0.0
        offset += size
    return buffer
