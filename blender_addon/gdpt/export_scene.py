# One render's sync: depsgraph -> _gdpt.SceneBuilder. Runs once per view layer and frame.
import time

from . import export_camera, export_images, export_lights, export_materials, export_mesh
from . import export_world


class ExportStats:
    def __init__(self):
        self.seconds = 0.0
        self.cpu_seconds = 0.0  # CPU time of this thread (less sensitive to a loaded machine)
        self.meshes = 0
        self.instances = 0
        self.triangles = 0
        self.lights = 0
        self.materials = 0


def export_scene(module, depsgraph, camera_object, warn, camera=None, mesh_store=None):
    """Builds and returns (builder, stats). `camera_object` is the evaluated scene camera;
    `camera`, when given, is the camera dict to use instead (the viewport's view); `mesh_store`
    (export_mesh.MeshStore, the viewport's) gives the meshes kept from the last export."""
    t0 = time.perf_counter()
    c0 = time.thread_time()
    scene = depsgraph.scene
    builder = module.SceneBuilder()
    images = export_images.ImageCache(builder, warn)
    materials = export_materials.MaterialCache(builder, images, warn)
    geometry = export_mesh.GeometryExporter(builder, materials, warn, mesh_store)
    lights = 0

    # World first: its image must exist before set_world references it.
    builder.set_world(export_world.world_dict(scene.world, images, warn))
    if camera is None:
        camera = export_camera.camera_dict(scene, camera_object, warn)
    builder.set_camera(camera)

    for inst in depsgraph.object_instances:
        obj = inst.object
        if not inst.show_self:
            continue
        # The matrix must be copied inside the loop: the instance iterator reuses its storage.
        matrix = inst.matrix_world.copy()
        if obj.type == 'LIGHT':
            problem = export_lights.light_problem(obj)
            if problem:
                warn(problem)
                continue
            builder.add_light(export_lights.light_dict(obj, matrix, warn))
            lights += 1
        else:
            geometry.visit(inst, obj, matrix)

    if builder.instance_count == 0 and lights == 0:
        warn("the scene has no visible objects and no lights: nothing to render but the world")
    stats = ExportStats()
    stats.seconds = time.perf_counter() - t0
    stats.cpu_seconds = time.thread_time() - c0
    stats.meshes = builder.mesh_count
    stats.instances = builder.instance_count
    stats.triangles = builder.triangle_count
    stats.lights = lights
    stats.materials = len(materials.index)
    return builder, stats
