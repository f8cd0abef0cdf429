# Imports a glTF dataset into an empty Blender scene and prints what arrived, for dynbench's tests:
#   blender --background --factory-startup --python tools/blender/import_gltf.py -- DATASET.gltf
# Prints one line "DYNBENCH_IMPORT {json}" and exits 0 when the importer finished, 1 otherwise.
import json
import sys

import numpy

# Blender 3.4's glTF importer uses numpy.bool, which numpy 1.24 (Debian bookworm) removed.
if not hasattr(numpy, "bool"):
    numpy.bool = numpy.bool_

import bpy  # noqa: E402

path = sys.argv[sys.argv.index("--") + 1]
bpy.ops.wm.read_factory_settings(use_empty=True)
try:
    result = bpy.ops.import_scene.gltf(filepath=path)
except Exception as error:  # the importer raises on files it cannot read
    print("DYNBENCH_IMPORT " + json.dumps({"result": "error", "error": str(error)}))
    sys.exit(1)
objects = bpy.context.scene.objects
summary = {
    "result": sorted(result)[0] if result else "",
    "objects": len(objects),
    "meshes": sum(1 for o in objects if o.type == "MESH"),
    "armatures": sum(1 for o in objects if o.type == "ARMATURE"),
    "cameras": sum(1 for o in objects if o.type == "CAMERA"),
    "lights": sum(1 for o in objects if o.type == "LIGHT"),
    "actions": len(bpy.data.actions),
    "images": len(bpy.data.images),
    # Morph targets become shape keys: the non-basis keys of every mesh object.
    "shape_keys": sum(len(o.data.shape_keys.key_blocks) - 1 for o in objects if o.type == "MESH" and o.data.shape_keys),
}
print("DYNBENCH_IMPORT " + json.dumps(summary))
sys.stdout.flush()
sys.exit(0 if "FINISHED" in result else 1)
