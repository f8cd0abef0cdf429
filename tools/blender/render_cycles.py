# Renders frames of a glTF dataset with Blender Cycles for `dynbench render --engine cycles`.
#   blender --background --factory-startup --python tools/blender/render_cycles.py -- JOB.json
# JOB.json (written by src/render/cycles_backend.cpp) names the dataset, the settings, and per
# frame the time, the camera (glTF world matrix and lens) and every punctual light, all already
# evaluated by dynbench so both engines see the same cameras and lights. For each frame this
# writes a multilayer EXR of Cycles' passes; dynbench turns it into the feature-buffer contract.
# Prints "DYNBENCH_FRAME_DONE <frame>" after each frame and exits 0, or 1 with "DYNBENCH_ERROR ...".
import json
import math
import sys

import numpy

# Blender 3.4's glTF importer uses numpy.bool, which numpy 1.24 (Debian bookworm) removed.
if not hasattr(numpy, "bool"):
    numpy.bool = numpy.bool_

import bpy  # noqa: E402
from mathutils import Matrix  # noqa: E402


def fail(message):
    print("DYNBENCH_ERROR " + message, flush=True)
    sys.exit(1)


job = json.load(open(sys.argv[sys.argv.index("--") + 1]))
bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
scene.render.fps = max(1, round(job["fps"]))
scene.render.fps_base = scene.render.fps / job["fps"]
try:
    bpy.ops.import_scene.gltf(filepath=job["dataset"], convert_lighting_mode="RAW")
except Exception as error:
    fail("the glTF importer failed: " + str(error))

# glTF is +Y up, Blender +Z up; the importer maps (x, y, z) to (x, -z, y).
Y_UP_TO_Z_UP = Matrix(((1, 0, 0, 0), (0, 0, -1, 0), (0, 1, 0, 0), (0, 0, 0, 1)))


def blender_matrix(column_major):
    m = Matrix([[column_major[4 * c + r] for c in range(4)] for r in range(4)])
    return Y_UP_TO_Z_UP @ m


# Lights and cameras come from the job, not from the importer.
for obj in list(scene.objects):
    if obj.type in {"LIGHT", "CAMERA"}:
        bpy.data.objects.remove(obj, do_unlink=True)

camera_data = bpy.data.cameras.new("dynbench_camera")
camera = bpy.data.objects.new("dynbench_camera", camera_data)
scene.collection.objects.link(camera)
scene.camera = camera
camera_data.sensor_fit = "VERTICAL"

lights = []
for i, light in enumerate(job["frames"][0]["lights"] if job["frames"] else []):
    kind = {"point": "POINT", "spot": "SPOT", "directional": "SUN"}[light["type"]]
    data = bpy.data.lights.new("dynbench_light_%d" % i, kind)
    if kind in {"POINT", "SPOT"}:
        data.shadow_soft_size = 0.0  # a point, as KHR_lights_punctual says
    else:
        data.angle = 0.0
    obj = bpy.data.objects.new(data.name, data)
    scene.collection.objects.link(obj)
    lights.append(obj)

world = bpy.data.worlds.new("dynbench_world")
scene.world = world
world.use_nodes = True
nodes, links = world.node_tree.nodes, world.node_tree.links
background = nodes["Background"]
environment = job["environment"]
if environment["kind"] == "image":
    texture = nodes.new("ShaderNodeTexEnvironment")
    texture.image = bpy.data.images.load(environment["file"])
    texture.interpolation = "Closest"  # dynbench looks up the nearest pixel
    # Blender's equirectangular centre looks down +X; dynbench's (glTF -Z) is Blender +Y. Turning
    # the lookup direction by -90 degrees about Z brings +Y to +X.
    coordinates = nodes.new("ShaderNodeTexCoord")
    mapping = nodes.new("ShaderNodeMapping")
    mapping.vector_type = "VECTOR"
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, -math.pi / 2)
    links.new(coordinates.outputs["Generated"], mapping.inputs["Vector"])
    links.new(mapping.outputs["Vector"], texture.inputs["Vector"])
    links.new(texture.outputs["Color"], background.inputs["Color"])
    background.inputs["Strength"].default_value = environment["intensity"]
elif environment["kind"] == "constant":
    r, g, b = environment["radiance"]
    background.inputs["Color"].default_value = (r, g, b, 1.0)
    background.inputs["Strength"].default_value = 1.0
else:
    background.inputs["Strength"].default_value = 0.0

render = scene.render
render.engine = "CYCLES"
render.resolution_x = job["width"]
render.resolution_y = job["height"]
render.resolution_percentage = 100
render.film_transparent = False
render.use_motion_blur = False
if job["threads"] > 0:
    render.threads_mode = "FIXED"
    render.threads = job["threads"]
render.image_settings.file_format = "OPEN_EXR_MULTILAYER"
render.image_settings.color_depth = "32"
render.image_settings.exr_codec = "ZIP"
cycles = scene.cycles
cycles.device = "CPU"
cycles.samples = job["samples_per_pixel"]
cycles.use_adaptive_sampling = False
cycles.use_denoising = False
cycles.seed = job["seed"] % 2147483647
cycles.max_bounces = job["bounces"]
cycles.diffuse_bounces = job["bounces"]
cycles.glossy_bounces = job["bounces"]
cycles.transmission_bounces = job["bounces"]
cycles.transparent_max_bounces = 16
cycles.caustics_reflective = True
cycles.caustics_refractive = True
cycles.blur_glossy = 0.0
cycles.sample_clamp_direct = 0.0
cycles.sample_clamp_indirect = 0.0
# dynbench takes every buffer at the pixel centre's hit; Cycles' narrowest box filter (0.01 px) is
# the closest it gets to that.
cycles.pixel_filter_type = "BOX"
cycles.filter_width = 0.01

layer = scene.view_layers[0]
layer.use_pass_z = True
layer.use_pass_normal = True
layer.use_pass_position = True
for kind in ("diffuse", "glossy", "transmission"):
    for part in ("direct", "indirect", "color"):
        setattr(layer, "use_pass_%s_%s" % (kind, part), True)
layer.use_pass_emit = True
layer.use_pass_environment = True

for frame in job["frames"]:
    position = frame["time"] * scene.render.fps / scene.render.fps_base
    whole = math.floor(position)
    scene.frame_set(int(whole), subframe=position - whole)
    cam = frame["camera"]
    camera.matrix_world = blender_matrix(cam["world"])
    camera_data.angle_y = cam["yfov"]
    camera_data.clip_start = cam["znear"]
    camera_data.clip_end = cam["zfar"]
    for obj, light in zip(lights, frame["lights"]):
        obj.matrix_world = blender_matrix(light["world"])
        r, g, b = light["color"]
        obj.data.color = (r, g, b)
        # RAW units, as the importer's RAW mode: a point or spot light of intensity I (cd) is
        # 4 pi I "watts" in Blender, a directional light of E lux has strength E.
        if obj.data.type == "SUN":
            obj.data.energy = light["intensity"]
        else:
            obj.data.energy = light["intensity"] * 4.0 * math.pi
        if obj.data.type == "SPOT":
            obj.data.spot_size = 2.0 * light["outer_cone"]
            obj.data.spot_blend = 1.0 - light["inner_cone"] / light["outer_cone"] if light["outer_cone"] > 0 else 0.0
        obj.hide_render = not light["visible"]
    render.filepath = frame["output"]
    bpy.ops.render.render(write_still=True)
    print("DYNBENCH_FRAME_DONE %d" % frame["frame"], flush=True)
sys.exit(0)
