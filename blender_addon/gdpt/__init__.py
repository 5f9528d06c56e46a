# GDPT: gradient-domain path tracing render engine for Blender 3.4.
#
# The add-on only translates Blender data into flat arrays (export_*.py) and hands them to the
# C++ core through the `_gdpt` pybind11 module, which scripts/install-addon.sh puts next to this
# file (and its x86-64-v3 build in x86-64-v3/, see native.py).

bl_info = {
    "name": "Gradient PT",
    "author": "GDPT developers",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Render Properties > Render Engine > Gradient PT",
    "description": "Gradient-domain path tracer (Kettunen et al. 2015) with screened Poisson "
                   "reconstruction",
    "category": "Render",
}

# The C++ module first: native.py picks the build this CPU runs (baseline or x86-64-v3) before
# any other file imports `_gdpt`.
from . import native  # noqa: E402

native.load()

if "bpy" in locals():
    import importlib

    for _module in (properties, passes, export_images, export_materials, export_mesh,  # noqa: F821
                    export_lights, export_camera, export_world, export_scene,
                    viewport_camera, viewport, engine, ui, compositor_node):  # noqa: F821
        importlib.reload(_module)
else:
    from . import (properties, passes, export_images, export_materials, export_mesh,
                   export_lights, export_camera, export_world, export_scene, viewport_camera,
                   viewport, engine, ui, compositor_node)

import bpy  # noqa: E402


def register():
    properties.register()
    bpy.utils.register_class(engine.GDPTRenderEngine)
    ui.register()
    compositor_node.register()


def unregister():
    compositor_node.unregister()
    ui.unregister()
    bpy.utils.unregister_class(engine.GDPTRenderEngine)
    properties.unregister()
