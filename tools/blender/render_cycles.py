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

def node_math(tree, operation, *inputs, clamp=False):
    """A Math node of `tree` computing `operation` of inputs that are numbers or sockets."""
    node = tree.nodes.new("ShaderNodeMath")
    node.operation = operation
    node.use_clamp = clamp
    for i, value in enumerate(inputs):
        if isinstance(value, (int, float)):
            node.inputs[i].default_value = value
        else:
            tree.links.new(value, node.inputs[i])
    return node.outputs[0]


def gltf_brdf(material):
    """Rebuilds the importer's Principled BSDF as glTF 2.0's Appendix B BRDF, the BRDF dynbench
    renders (src/render/bsdf.h), from Cycles closures:
      dielectric = 0.96 Lambert(baseColor) + GGX with Fresnel(f0 = 0.04) on v.h
      metal      = GGX with Fresnel(f0 = baseColor) on v.h
      mix by metallic, plus emission, alpha as the importer wired it.
    Blender 3.4's Principled BSDF alone is not that BRDF: its Disney diffuse adds retro-reflection
    and its diffuse is not reduced by the specular layer. Its specular lobe is (a GGX with a
    per-microfacet Fresnel), so it is used with a black base colour for the dielectric's specular
    layer and with metallic 1 for the metal. glTF's diffuse weight is 1 - F(v.h), which depends on
    the light direction; Cycles has no such closure, so it is fixed at 1 - f0 = 0.96, its value
    when v and l are not far apart (docs/feature-buffers.md, "Agreement with Cycles", gives the
    difference this leaves)."""
    if not material or not material.use_nodes:
        return
    tree = material.node_tree
    nodes, links = tree.nodes, tree.links
    for principled in [n for n in nodes if n.type == "BSDF_PRINCIPLED"]:
        outputs = [link.to_socket for link in principled.outputs["BSDF"].links]
        if not outputs:
            continue

        def feed(socket, name):
            # The Principled input's texture wiring or constant, carried over (an unlinked normal
            # is the shading normal on both).
            source = principled.inputs[name]
            if source.is_linked:
                links.new(source.links[0].from_socket, socket)
            elif name != "Normal":
                socket.default_value = source.default_value

        def specular_lobe(metallic):
            lobe = nodes.new("ShaderNodeBsdfPrincipled")
            lobe.distribution = "GGX"
            lobe.inputs["Metallic"].default_value = metallic
            lobe.inputs["Specular"].default_value = 0.5  # f0 = 0.08 x 0.5 = 0.04
            lobe.inputs["Specular Tint"].default_value = 0.0
            if metallic > 0:
                feed(lobe.inputs["Base Color"], "Base Color")
            else:
                lobe.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
            feed(lobe.inputs["Roughness"], "Roughness")
            feed(lobe.inputs["Normal"], "Normal")
            return lobe.outputs["BSDF"]

        weight = nodes.new("ShaderNodeMixRGB")
        weight.blend_type = "MULTIPLY"
        weight.inputs["Fac"].default_value = 1.0
        feed(weight.inputs["Color1"], "Base Color")
        weight.inputs["Color2"].default_value = (0.96, 0.96, 0.96, 1.0)
        diffuse = nodes.new("ShaderNodeBsdfDiffuse")
        diffuse.inputs["Roughness"].default_value = 0.0  # Lambert
        links.new(weight.outputs["Color"], diffuse.inputs["Color"])
        feed(diffuse.inputs["Normal"], "Normal")
        dielectric = nodes.new("ShaderNodeAddShader")
        links.new(diffuse.outputs["BSDF"], dielectric.inputs[0])
        links.new(specular_lobe(0.0), dielectric.inputs[1])
        surface = nodes.new("ShaderNodeMixShader")
        feed(surface.inputs["Fac"], "Metallic")
        links.new(dielectric.outputs["Shader"], surface.inputs[1])
        links.new(specular_lobe(1.0), surface.inputs[2])
        shader = surface.outputs["Shader"]

        emission = nodes.new("ShaderNodeEmission")
        feed(emission.inputs["Color"], "Emission")
        feed(emission.inputs["Strength"], "Emission Strength")
        add = nodes.new("ShaderNodeAddShader")
        links.new(shader, add.inputs[0])
        links.new(emission.outputs["Emission"], add.inputs[1])
        shader = add.outputs["Shader"]

        alpha = principled.inputs["Alpha"]
        if alpha.is_linked or alpha.default_value < 1.0:
            transparent = nodes.new("ShaderNodeBsdfTransparent")
            cutout = nodes.new("ShaderNodeMixShader")
            feed(cutout.inputs["Fac"], "Alpha")
            links.new(transparent.outputs["BSDF"], cutout.inputs[1])
            links.new(shader, cutout.inputs[2])
            shader = cutout.outputs["Shader"]
        for socket in outputs:
            links.new(shader, socket)
        nodes.remove(principled)


for material in bpy.data.materials:
    gltf_brdf(material)


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

def light_shader(data, light):
    """The parts of a KHR_lights_punctual light Blender lacks, as the light's emission strength
    (the factor dynbench's src/render/lights.cpp applies beside I / d^2):
    - range: the recommended window clamp(1 - (d / range)^4, 0, 1), d the distance to the lit point
      (Light Path's Ray Length in a light shader); Blender's lights have no range and would light
      everything beyond it;
    - spot: the squared linear ramp clamp((cos a - cos outer) / (cos inner - cos outer), 0, 1)^2,
      cos a = -z of the emission direction in the light's frame (Texture Coordinate's Normal);
      Blender's own cone edge (spot_blend) is a smoothstep and is switched off. Blender 3.4's spot
      also scales by cos a (measured: tests/cycles_test.cpp), divided out here."""
    ranged = light["type"] != "directional" and light.get("range", 0.0) > 0.0
    if not ranged and light["type"] != "spot":
        return
    data.use_nodes = True
    tree = data.node_tree
    nodes, links = tree.nodes, tree.links
    emission = next(n for n in nodes if n.type == "EMISSION")

    strength = None
    if ranged:
        distance = nodes.new("ShaderNodeLightPath").outputs["Ray Length"]
        r4 = node_math(tree, "POWER", node_math(tree, "DIVIDE", distance, light["range"]), 4.0)
        strength = node_math(tree, "SUBTRACT", 1.0, r4, clamp=True)
    if light["type"] == "spot":
        z = nodes.new("ShaderNodeSeparateXYZ")
        links.new(nodes.new("ShaderNodeTexCoord").outputs["Normal"], z.inputs["Vector"])
        cos_outer, cos_inner = math.cos(light["outer_cone"]), math.cos(light["inner_cone"])
        scale = 1.0 / max(1e-3, cos_inner - cos_outer)
        ramp = node_math(tree, "MULTIPLY_ADD", z.outputs["Z"], -scale, -cos_outer * scale, clamp=True)
        factor = node_math(tree, "DIVIDE", node_math(tree, "POWER", ramp, 2.0), node_math(tree, "MULTIPLY", z.outputs["Z"], -1.0))
        strength = factor if strength is None else node_math(tree, "MULTIPLY", strength, factor)
    links.new(strength, emission.inputs["Strength"])


lights = []
for i, light in enumerate(job["frames"][0]["lights"] if job["frames"] else []):
    kind = {"point": "POINT", "spot": "SPOT", "directional": "SUN"}[light["type"]]
    data = bpy.data.lights.new("dynbench_light_%d" % i, kind)
    if kind in {"POINT", "SPOT"}:
        data.shadow_soft_size = 0.0  # a point, as KHR_lights_punctual says
    else:
        data.angle = 0.0
    # A light's kind, range and cones are its definition's: the same in every frame.
    if kind == "SPOT":
        data.spot_size = 2.0 * light["outer_cone"]
        data.spot_blend = 0.0  # KHR's ramp is the light shader's (light_shader)
    light_shader(data, light)
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
# The geometry buffers are the pixel centre's hit; Cycles' narrowest box filter (0.01 px) is the
# closest it gets to that. The radiance goes through the job's pixel filter (docs/feature-buffers.md):
# with one, each frame is rendered twice, first at the centre with one sample for the geometry
# passes (Cycles averages the normal pass over the filter), then through the filter.
CENTRE_FILTER = ("BOX", 0.01)
pixel_filter = job.get("pixel_filter", {"type": "centre"})
RADIANCE_FILTER = {
    "centre": CENTRE_FILTER,
    "box": ("BOX", pixel_filter.get("width", 1.0)),
    "blackman-harris": ("BLACKMAN_HARRIS", pixel_filter.get("width", 1.5)),
}[pixel_filter["type"]]
cycles.pixel_filter_type, cycles.filter_width = CENTRE_FILTER

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
        obj.hide_render = not light["visible"]
    if "geometry_output" in frame:
        cycles.samples = 1
        cycles.pixel_filter_type, cycles.filter_width = CENTRE_FILTER
        render.filepath = frame["geometry_output"]
        bpy.ops.render.render(write_still=True)
    cycles.samples = job["samples_per_pixel"]
    cycles.pixel_filter_type, cycles.filter_width = RADIANCE_FILTER
    render.filepath = frame["output"]
    bpy.ops.render.render(write_still=True)
    print("DYNBENCH_FRAME_DONE %d" % frame["frame"], flush=True)
sys.exit(0)
