#!/usr/bin/env python3
"""Writes examples/orbit/orbit.gltf: the small scene `dynbench stats` runs on in the README.

A ground plane, a crate sliding across it with a point light riding on it, a static point light,
and a first-person camera circling the crate at 60 key frames per second while its yaw swings
back and forth like a player looking around. Everything is generated here (CC0); run
`python3 examples/make_orbit.py` to regenerate it byte for byte.
"""
import base64
import json
import math
import pathlib
import struct

FPS = 60
SECONDS = 5.0


def pack(values):
    return struct.pack("<%df" % len(values), *values)


class Writer:
    def __init__(self):
        self.bin = bytearray()
        self.views, self.accessors = [], []

    def accessor(self, values, kind, count, extra=None, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": 4 * len(values)}
        if target:
            view["target"] = target
        self.views.append(view)
        self.bin += pack(values)
        acc = {"bufferView": len(self.views) - 1, "componentType": 5126, "count": count, "type": kind}
        acc.update(extra or {})
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def indices(self, values):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.views.append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": 2 * len(values), "target": 34963})
        self.bin += struct.pack("<%dH" % len(values), *values)
        self.accessors.append({"bufferView": len(self.views) - 1, "componentType": 5123, "count": len(values), "type": "SCALAR"})
        return len(self.accessors) - 1


def bounds(positions):
    xs, ys, zs = positions[0::3], positions[1::3], positions[2::3]
    return {"min": [min(xs), min(ys), min(zs)], "max": [max(xs), max(ys), max(zs)]}


def yaw_quat(deg):
    h = math.radians(deg) / 2
    return [0.0, math.sin(h), 0.0, math.cos(h)]


def main():
    w = Writer()
    plane = [-10, 0, -10, 10, 0, -10, 10, 0, 10, -10, 0, 10]
    plane_n = [0, 1, 0] * 4
    plane_mesh = {"primitives": [{"attributes": {
        "POSITION": w.accessor(plane, "VEC3", 4, bounds(plane), 34962),
        "NORMAL": w.accessor(plane_n, "VEC3", 4, None, 34962)},
        "indices": w.indices([0, 2, 1, 0, 3, 2]), "material": 0}], "name": "ground"}
    box, box_n, box_i = [], [], []
    for axis in range(3):
        for sign in (-1, 1):
            n = [0, 0, 0]
            n[axis] = sign
            u, v = [(axis + 1) % 3, (axis + 2) % 3]
            base = len(box) // 3
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                p = [0, 0, 0]
                p[axis], p[u], p[v] = 0.5 * sign, 0.5 * a, 0.5 * b
                box += p
                box_n += n
            quad = [0, 1, 2, 0, 2, 3] if sign > 0 else [0, 2, 1, 0, 3, 2]
            box_i += [base + q for q in quad]
    box_mesh = {"primitives": [{"attributes": {
        "POSITION": w.accessor(box, "VEC3", 24, bounds(box), 34962),
        "NORMAL": w.accessor(box_n, "VEC3", 24, None, 34962)},
        "indices": w.indices(box_i), "material": 1}], "name": "crate"}

    keys = int(SECONDS * FPS) + 1
    times = [k / FPS for k in range(keys)]
    cam_t, cam_r, crate_t = [], [], []
    for t in times:
        angle = 2 * math.pi * t / SECONDS  # one orbit
        cam_t += [8 * math.sin(angle), 1.7, 8 * math.cos(angle)]
        look = math.degrees(angle) + 35 * math.sin(2 * math.pi * 0.8 * t)  # face the centre, swing
        cam_r += yaw_quat(look)
        crate_t += [3 * math.sin(2 * math.pi * t / SECONDS * 2), 0.5, 0.0]
    t_acc = w.accessor(times, "SCALAR", keys, {"min": [0.0], "max": [times[-1]]})
    samplers = [
        {"input": t_acc, "output": w.accessor(cam_t, "VEC3", keys)},
        {"input": t_acc, "output": w.accessor(cam_r, "VEC4", keys)},
        {"input": t_acc, "output": w.accessor(crate_t, "VEC3", keys)},
    ]
    gltf = {
        "asset": {"version": "2.0", "generator": "dynbench examples/make_orbit.py", "copyright": "CC0 1.0"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "extensions": {"KHR_lights_punctual": {"lights": [
            {"type": "point", "name": "lamp", "color": [1, 0.9, 0.8], "intensity": 200},
            {"type": "point", "name": "crate light", "color": [0.3, 0.6, 1], "intensity": 20}]}},
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 4]}],
        "nodes": [
            {"name": "ground", "mesh": 0},
            {"name": "lamp", "translation": [0, 6, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"name": "crate", "mesh": 1, "children": [3]},
            {"name": "crate light", "translation": [0, 1, 0], "extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"name": "player", "camera": 0},
        ],
        "cameras": [{"name": "player", "type": "perspective",
                     "perspective": {"yfov": math.radians(60), "aspectRatio": 16 / 9, "znear": 0.05, "zfar": 200}}],
        "meshes": [plane_mesh, box_mesh],
        "materials": [
            {"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.45, 1], "metallicFactor": 0, "roughnessFactor": 0.9}},
            {"name": "crate", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.4, 0.2, 1], "metallicFactor": 0, "roughnessFactor": 0.6}},
        ],
        "animations": [{"name": "orbit", "samplers": samplers, "channels": [
            {"sampler": 0, "target": {"node": 4, "path": "translation"}},
            {"sampler": 1, "target": {"node": 4, "path": "rotation"}},
            {"sampler": 2, "target": {"node": 2, "path": "translation"}},
        ]}],
        "accessors": w.accessors,
        "bufferViews": w.views,
        "buffers": [{"byteLength": len(w.bin),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(w.bin)).decode()}],
    }
    out = pathlib.Path(__file__).resolve().parent / "orbit" / "orbit.gltf"
    out.write_text(json.dumps(gltf, indent=1) + "\n")
    print(f"wrote {out} ({out.stat().st_size} bytes)")


if __name__ == "__main__":
    main()
