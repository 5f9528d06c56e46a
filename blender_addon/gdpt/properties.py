# Render settings (scene.gdpt) and per-view-layer pass toggles (view_layer.gdpt).
# The names of scene.gdpt are part of the contract with tests and tools (see docs/conventions.md).

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty


def _update_passes(self, context):
    # Re-registers the passes so the Render Layers node shows the change at once.
    view_layer = context.view_layer if context else None
    if view_layer is not None:
        view_layer.update_render_passes()


class GDPTRenderSettings(bpy.types.PropertyGroup):
    samples: IntProperty(
        name="Samples", description="Samples per pixel (each G-PT sample traces a base path and "
        "four shifted paths)", default=64, min=1, max=1 << 24, soft_max=4096)
    time_limit: FloatProperty(
        name="Time Limit", description="Stop after this many seconds, keeping the samples done "
        "(0 = no limit)", default=0.0, min=0.0, subtype='TIME_ABSOLUTE', unit='TIME_ABSOLUTE')
    max_bounces: IntProperty(
        name="Max Bounces", description="Path segments after the camera ray", default=8, min=0,
        max=1024)
    # Per-kind limits, Cycles' names and defaults.
    diffuse_bounces: IntProperty(
        name="Diffuse", description="Maximum number of diffuse reflection bounces, bounded by "
        "the total maximum", default=4, min=0, max=1024)
    glossy_bounces: IntProperty(
        name="Glossy", description="Maximum number of glossy reflection bounces, bounded by the "
        "total maximum", default=4, min=0, max=1024)
    transmission_bounces: IntProperty(
        name="Transmission", description="Maximum number of transmission bounces, bounded by the "
        "total maximum", default=12, min=0, max=1024)
    # Sampling > Noise Threshold, Cycles' names and ranges (integrators/adaptive_sampling.h).
    # Off by default here: GDPT's benchmarks and tests render fixed sample counts.
    use_adaptive_sampling: BoolProperty(
        name="Noise Threshold", description="Adaptively stop sampling pixels once their noise "
        "is below the threshold (and their neighbours' too)", default=False)
    adaptive_threshold: FloatProperty(
        name="Noise Threshold", description="Noise level at which a pixel stops taking samples: "
        "the standard deviation of its estimate over the square root of its brightness, as "
        "Cycles' (lower is less noisy and slower)", default=0.01, min=0.0001, max=1.0,
        soft_min=0.001, precision=4)
    adaptive_min_samples: IntProperty(
        name="Min Samples", description="Samples every pixel takes before it may stop (0: a "
        "quarter of the samples, from 4 to 64)", default=0, min=0, max=4096)
    # Light Paths > Caustics, Cycles' names, ranges and defaults.
    blur_glossy: FloatProperty(
        name="Filter Glossy", description="Adaptively blur glossy shaders after blurry bounces, "
        "to reduce noise at the cost of accuracy (as Cycles'; 0 = off)", default=1.0, min=0.0,
        max=10.0)
    caustics_reflective: BoolProperty(
        name="Reflective Caustics", description="Use reflective caustics, resulting in a "
        "brighter image (more noise but added realism)", default=True)
    caustics_refractive: BoolProperty(
        name="Refractive Caustics", description="Use refractive caustics, resulting in a "
        "brighter image (more noise but added realism)", default=True)
    # Cycles' Min Light Bounces (Sampling > Advanced) with Cycles' meaning: Russian roulette may
    # end a path only after this many bounces past the first indirect hit (Cycles' kernel counts
    # min_light_bounces + 1), i.e. the core's rr_depth = min_light_bounces + 1. GDPT's default 2
    # is the core's rr_depth 3, chosen by error at equal cost (docs/performance.md, "Russian
    # roulette"); Cycles' default is 0.
    min_light_bounces: IntProperty(
        name="Min Light Bounces", description="Minimum number of light bounces before Russian "
        "roulette may end a path. Higher values reduce noise in the first bounces but make each "
        "sample slower (Cycles' default is 0)", default=2, min=0, max=1023)
    mode: EnumProperty(
        name="Integrator",
        items=[('GPT', "Gradient-Domain", "Gradient-domain path tracing: primal, gradients and a "
                "screened Poisson reconstruction"),
               ('PT', "Path Tracing", "Plain path tracing (no gradients; Combined = Primal + "
                "Emission)")],
        default='GPT')
    reconstruction: EnumProperty(
        name="Reconstruction",
        items=[('L1', "L1", "Robust iteratively reweighted solve (fewer outliers, slightly biased)"),
               ('L2', "L2", "Unbiased screened Poisson solve (exact DCT)"),
               ('WEIGHTED', "Variance Weighted", "Each term weighted by its per-pixel variance"),
               ('FEATURE', "Feature", "The L1 solution filtered by filters guided by the Denoising "
                "Albedo, Normal and Depth passes, chosen per pixel by an error estimate from two "
                "halves of the samples (renders those passes too)"),
               ('NONE', "None", "Combined = Primal + Emission")],
        default='L1')
    alpha: FloatProperty(
        name="Alpha", description="Weight of the primal image against the gradients in the "
        "reconstruction (higher keeps more of the noisy primal)", default=0.2, min=1e-4, max=100.0,
        soft_max=2.0)
    shift_threshold: FloatProperty(
        name="Shift Roughness Threshold", description="GGX alpha below which a vertex is treated "
        "as specular by the shift mapping (half-vector copy instead of reconnection)",
        default=0.001, min=0.0, max=1.0, precision=4)
    # Film > Pixel Filter, Cycles' names, ranges and defaults (GDPT's own settings: an artist
    # switching engines keeps them; Cycles' are not read).
    pixel_filter_type: EnumProperty(
        name="Pixel Filter", description="Pixel filter type, as Cycles' (each camera sample is "
        "placed by it: primal and gradients alike)",
        items=[('BOX', "Box", "Box filter"),
               ('GAUSSIAN', "Gaussian", "Gaussian filter"),
               ('BLACKMAN_HARRIS', "Blackman-Harris", "Blackman-Harris filter")],
        default='BLACKMAN_HARRIS')
    filter_width: FloatProperty(
        name="Width", description="Pixel filter width, as Cycles'", default=1.5, min=0.01,
        max=10.0, subtype='PIXEL')
    seed: IntProperty(name="Seed", description="Random seed (the image does not depend on the "
                      "thread count)", default=0, min=0)
    # Cycles' Sample Offset: a render farm splits one frame's samples over machines, each
    # rendering its own range; gdpt-merge combines their EXRs exactly (docs/farm.md).
    sample_offset: IntProperty(
        name="Sample Offset", description="Index of the first sample to render: this render "
        "takes samples Sample Offset .. Sample Offset + Samples - 1 of the seed's sequence, so "
        "renders of disjoint ranges merge exactly (gdpt-merge)", default=0, min=0,
        max=(1 << 31) - 1)
    frame_samples: IntProperty(
        name="Frame Samples", description="Samples of the whole frame when renders of disjoint "
        "sample ranges make it up (0: Sample Offset + Samples). The Feature reconstruction's "
        "halves split the frame's sample sequence at its middle, so every part of a frame must "
        "give the same total (gdpt-farm sets it)", default=0, min=0, max=(1 << 31) - 1)
    threads: IntProperty(name="Threads", description="Render threads (0 = all cores)", default=0,
                         min=0, max=1024)
    clamp: FloatProperty(name="Clamp", description="Maximum sample value (0 = off)", default=0.0,
                         min=0.0)
    preview_interval: FloatProperty(
        name="Preview Interval",
        description="Seconds between reconstructed preview updates of the image, at least "
                    "(previews that take long are spaced to cost at most 5% of the render; none "
                    "in background renders, blender -b, where no image is shown until it is "
                    "saved)",
        default=3.0, min=0.5, max=600.0)

    # The 3D viewport's Rendered mode (viewport.py), as Cycles' Sampling > Viewport.
    preview_samples: IntProperty(
        name="Viewport Samples", description="Samples per pixel in the viewport's Rendered mode "
        "(0 = until stopped)", default=256, min=0, max=1 << 24, soft_max=4096)
    preview_start_divider: IntProperty(
        name="Start Resolution Divider", description="After a change, the viewport first "
        "renders one pass at the resolution divided by this, then at twice that resolution and "
        "so on, for an image at once (1 = off)",
        default=8, min=1, max=64)
    preview_mode: EnumProperty(
        name="Viewport Integrator",
        items=[('GPT', "Gradient-Domain", "Gradient-domain path tracing, reconstructed"),
               ('PT', "Path Tracing", "Plain path tracing (Primal + Emission)")],
        default='GPT')
    preview_reconstruction: EnumProperty(
        name="Viewport Reconstruction",
        items=[('L2', "L2", "Unbiased screened Poisson solve (exact DCT, fast)"),
               ('L1', "L1", "Robust iteratively reweighted solve (slower)"),
               ('WEIGHTED', "Variance Weighted", "Each term weighted by its per-pixel variance"),
               ('NONE', "None", "Primal + Emission")],
        default='L2')


class GDPTViewLayerSettings(bpy.types.PropertyGroup):
    use_pass_primal: BoolProperty(name="Primal", default=True, update=_update_passes)
    use_pass_gradients: BoolProperty(name="Gradients", default=True, update=_update_passes)
    use_pass_emission: BoolProperty(name="Emission", default=True, update=_update_passes)
    use_pass_variance: BoolProperty(name="Variance", default=True, update=_update_passes)
    use_pass_shift_failures: BoolProperty(name="Shift Failures", default=True,
                                          update=_update_passes)


_classes = (GDPTRenderSettings, GDPTViewLayerSettings)


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.gdpt = PointerProperty(type=GDPTRenderSettings)
    bpy.types.ViewLayer.gdpt = PointerProperty(type=GDPTViewLayerSettings)


def unregister():
    del bpy.types.ViewLayer.gdpt
    del bpy.types.Scene.gdpt
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)


def settings_dict(scene):
    """scene.gdpt as the plain dict the _gdpt module reads."""
    s = scene.gdpt
    return {
        "mode": s.mode,
        "samples": int(s.samples),
        "time_limit": float(s.time_limit),
        "max_bounces": int(s.max_bounces),
        "max_diffuse_bounces": int(s.diffuse_bounces),
        "max_glossy_bounces": int(s.glossy_bounces),
        "max_transmission_bounces": int(s.transmission_bounces),
        "rr_depth": int(s.min_light_bounces) + 1,
        "seed": int(s.seed),
        "sample_offset": int(s.sample_offset),
        "frame_samples": int(s.frame_samples),
        "threads": int(s.threads),
        "clamp": float(s.clamp),
        "adaptive_threshold": float(s.adaptive_threshold) if s.use_adaptive_sampling else 0.0,
        "adaptive_min_samples": int(s.adaptive_min_samples),
        "shift_threshold": float(s.shift_threshold),
        "pixel_filter": s.pixel_filter_type,
        "filter_width": float(s.filter_width),
        "blur_glossy": float(s.blur_glossy),
        "caustics_reflective": bool(s.caustics_reflective),
        "caustics_refractive": bool(s.caustics_refractive),
        # Blender's Render Properties > Film > Transparent.
        "transparent_background": bool(scene.render.film_transparent),
    }
