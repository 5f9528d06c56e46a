# Cycles-like panels for scene.gdpt and view_layer.gdpt, and GDPT in the COMPAT_ENGINES of the
# Blender panels that apply to it (output, dimensions, camera, light, world, material, ...).
import bpy
from bpy.types import Panel

ENGINE = "GDPT"


def _split(layout):
    """The layout of Blender's property panels: labels left, values right, no keyframe dots."""
    layout.use_property_split = True
    layout.use_property_decorate = False
    return layout


class _Panel:
    """A GDPT panel of the Properties editor, shown while GDPT is the render engine."""
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class _RenderPanel(_Panel):
    bl_context = "render"


class GDPT_PT_sampling(_RenderPanel, Panel):
    bl_label = "Sampling"

    def draw(self, context):
        layout = _split(self.layout)
        s = context.scene.gdpt
        col = layout.column(align=True)
        col.prop(s, "samples")
        col.prop(s, "time_limit")
        # Cycles' layout: the toggle as a heading checkbox, its threshold beside it.
        row = layout.row(heading="Noise Threshold", align=True)
        row.prop(s, "use_adaptive_sampling", text="")
        sub = row.row()
        sub.active = s.use_adaptive_sampling
        sub.prop(s, "adaptive_threshold", text="")
        sub = layout.column()
        sub.active = s.use_adaptive_sampling
        sub.prop(s, "adaptive_min_samples", text="Min Samples")
        col = layout.column()
        col.prop(s, "seed")
        col.prop(s, "sample_offset")
        col.prop(s, "frame_samples")
        col.prop(s, "clamp")
        col.prop(s, "min_light_bounces")


class GDPT_PT_sampling_viewport(_RenderPanel, Panel):
    """Sampling > Viewport: the 3D viewport's Rendered mode (as Cycles' panel of that name)."""
    bl_label = "Viewport"
    bl_parent_id = "GDPT_PT_sampling"

    def draw(self, context):
        layout = _split(self.layout)
        s = context.scene.gdpt
        col = layout.column(align=True)
        col.prop(s, "preview_samples", text="Samples")
        col.prop(s, "preview_start_divider", text="Start Divider")
        col = layout.column()
        col.prop(s, "preview_mode", text="Integrator")
        sub = col.column()
        sub.active = s.preview_mode == 'GPT'
        sub.prop(s, "preview_reconstruction", text="Reconstruction")


class GDPT_PT_light_paths(_RenderPanel, Panel):
    bl_label = "Light Paths"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = _split(self.layout)
        s = context.scene.gdpt
        col = layout.column(align=True)
        col.prop(s, "max_bounces", text="Total")
        col = layout.column(align=True)
        col.prop(s, "diffuse_bounces")
        col.prop(s, "glossy_bounces")
        col.prop(s, "transmission_bounces")


class GDPT_PT_light_paths_caustics(_RenderPanel, Panel):
    """Light Paths > Caustics, as Cycles' panel of that name."""
    bl_label = "Caustics"
    bl_parent_id = "GDPT_PT_light_paths"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = _split(self.layout)
        s = context.scene.gdpt
        layout.prop(s, "blur_glossy")
        col = layout.column(heading="Caustics", align=True)
        col.prop(s, "caustics_reflective", text="Reflective")
        col.prop(s, "caustics_refractive", text="Refractive")


class GDPT_PT_film(_RenderPanel, Panel):
    bl_label = "Film"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = _split(self.layout)
        col = layout.column()
        col.prop(context.scene.gdpt, "pixel_filter_type")
        col.prop(context.scene.gdpt, "filter_width")
        # Blender's own setting (Cycles and EEVEE show it in their Film panels).
        layout.prop(context.scene.render, "film_transparent", text="Transparent")


class GDPT_PT_gradient_domain(_RenderPanel, Panel):
    bl_label = "Gradient Domain"

    def draw(self, context):
        layout = _split(self.layout)
        s = context.scene.gdpt
        layout.prop(s, "mode")
        col = layout.column()
        col.active = s.mode == 'GPT'
        col.prop(s, "shift_threshold")


class GDPT_PT_reconstruction(_RenderPanel, Panel):
    bl_label = "Reconstruction"

    def draw(self, context):
        layout = _split(self.layout)
        s = context.scene.gdpt
        col = layout.column()
        col.active = s.mode == 'GPT'
        col.prop(s, "reconstruction")
        sub = col.column()
        sub.active = s.reconstruction != 'NONE'
        sub.prop(s, "alpha")


class GDPT_PT_performance(_RenderPanel, Panel):
    bl_label = "Performance"
    bl_options = {'DEFAULT_CLOSED'}

    def draw(self, context):
        layout = _split(self.layout)
        s = context.scene.gdpt
        layout.prop(s, "threads")
        layout.prop(s, "preview_interval")


class GDPT_PT_passes(_Panel, Panel):
    bl_label = "Gradient PT Passes"
    bl_context = "view_layer"

    def draw(self, context):
        layout = _split(self.layout)
        s = context.view_layer.gdpt
        col = layout.column(heading="Include", align=True)
        col.prop(s, "use_pass_primal")
        col.prop(s, "use_pass_gradients")
        col.prop(s, "use_pass_emission")
        col.prop(s, "use_pass_variance")
        col.prop(s, "use_pass_shift_failures")
        col = layout.column(heading="Data", align=True)
        col.prop(context.view_layer, "use_pass_z")
        col.prop(context.view_layer, "use_pass_object_index")
        col.prop(context.view_layer, "use_pass_material_index")
        col.prop(context.view_layer, "use_pass_normal")
        col.prop(context.view_layer, "use_pass_mist")


class GDPT_PT_ray_visibility(_Panel, Panel):
    """Object > Visibility > Ray Visibility: which kinds of rays see the object (as Cycles)."""
    bl_label = "Ray Visibility"
    bl_context = "object"
    bl_parent_id = "OBJECT_PT_visibility"

    @classmethod
    def poll(cls, context):
        ob = context.object
        return super().poll(context) and ob is not None and \
            ob.type in {'MESH', 'CURVE', 'SURFACE', 'FONT', 'META'}

    def draw(self, context):
        layout = _split(self.layout)
        ob = context.object
        col = layout.column(heading="Ray Visibility", align=True)
        col.prop(ob, "visible_camera", text="Camera", toggle=False)
        col.prop(ob, "visible_diffuse", text="Diffuse", toggle=False)
        col.prop(ob, "visible_glossy", text="Glossy", toggle=False)
        col.prop(ob, "visible_transmission", text="Transmission", toggle=False)
        col.prop(ob, "visible_shadow", text="Shadow", toggle=False)


class GDPT_PT_object_caustics(_Panel, Panel):
    """Object Properties: Cycles' Shadow Caustics flags (Cycles' Object > Shading > Caustics; its
    properties, shown when Cycles is loaded)."""
    bl_label = "Caustics"
    bl_context = "object"
    bl_options = {'DEFAULT_CLOSED'}

    @classmethod
    def poll(cls, context):
        ob = context.object
        return super().poll(context) and ob is not None and hasattr(ob, "cycles") and \
            ob.type in {'MESH', 'CURVE', 'SURFACE', 'FONT', 'META'}

    def draw(self, context):
        layout = _split(self.layout)
        cob = context.object.cycles
        col = layout.column()
        col.prop(cob, "is_caustics_caster", text="Cast Shadow Caustics")
        col.prop(cob, "is_caustics_receiver", text="Receive Shadow Caustics")


class GDPT_PT_light_shadow(_Panel, Panel):
    """Light Properties: Cycles' Cast Shadow and Shadow Caustics (its properties; shown when
    Cycles is loaded)."""
    bl_label = "Shadow"
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        light = context.light
        return super().poll(context) and light is not None and hasattr(light, "cycles")

    def draw(self, context):
        layout = _split(self.layout)
        layout.prop(context.light.cycles, "cast_shadow")
        layout.prop(context.light.cycles, "is_caustics_light", text="Shadow Caustics")


_classes = (GDPT_PT_sampling, GDPT_PT_sampling_viewport, GDPT_PT_light_paths,
            GDPT_PT_light_paths_caustics, GDPT_PT_film, GDPT_PT_gradient_domain,
            GDPT_PT_reconstruction, GDPT_PT_performance, GDPT_PT_passes, GDPT_PT_ray_visibility,
            GDPT_PT_object_caustics, GDPT_PT_light_shadow)

# Blender's engine-agnostic panels carry 'BLENDER_RENDER' in COMPAT_ENGINES (the convention of
# Blender's own "Custom Render Engine" template); EEVEE's light / material / world panels draw the
# plain datablock settings and node surfaces GDPT reads, so they are listed by name.
_EXCLUDE = {
    "VIEWLAYER_PT_filter", "VIEWLAYER_PT_layer_passes", "RENDER_PT_freestyle",
    "RENDER_PT_simplify",
}
_EXTRA = {
    "DATA_PT_EEVEE_light", "DATA_PT_spot",
    "EEVEE_MATERIAL_PT_context_material", "EEVEE_MATERIAL_PT_surface",
    "EEVEE_WORLD_PT_surface", "EEVEE_WORLD_PT_mist", "DATA_PT_camera_dof",
    "DATA_PT_camera_dof_aperture",
}

_patched = []


def _compat_panels():
    for panel in bpy.types.Panel.__subclasses__():
        engines = getattr(panel, "COMPAT_ENGINES", None)
        if not isinstance(engines, set) or panel.__name__ in _EXCLUDE:
            continue
        if "BLENDER_RENDER" in engines or panel.__name__ in _EXTRA:
            yield panel


def register():
    for cls in _classes:
        bpy.utils.register_class(cls)
    for panel in _compat_panels():
        if ENGINE not in panel.COMPAT_ENGINES:
            panel.COMPAT_ENGINES.add(ENGINE)
            _patched.append(panel)


def unregister():
    while _patched:
        panel = _patched.pop()
        panel.COMPAT_ENGINES.discard(ENGINE)
    for cls in reversed(_classes):
        bpy.utils.unregister_class(cls)
