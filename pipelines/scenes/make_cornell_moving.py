#!/usr/bin/env python3
"""Writes pipelines/scenes/cornell-moving.gltf, the bundled default scene.

The Cornell box (dimensions and reflectances of the Cornell University data, as in
tests/data/external/cornell_box, in metres) with a static tall box, a short box that slides
across the floor while turning a little, and a camera that pans from left to right. 4 s of
animation; at the default 24 fps that is frames 0-95.

Only the Python standard library is used; the output is deterministic.
"""
import base64
import json
import math
import struct
import sys

WHITE, RED, GREEN, LIGHT = 0, 1, 2, 3

positions, indices, meshes, nodes = [], [], [], []
buffer = bytearray()
accessors, views = [], []


def add_view(data, target):
    while len(buffer) % 4:
        buffer.append(0)
    views.append({"buffer": 0, "byteOffset": len(buffer), "byteLength": len(data), "target": target})
    buffer.extend(data)
    return len(views) - 1


def add_mesh(name, quads, material):
    """quads: list of 4 corners, CCW seen from the front; each becomes two triangles."""
    verts, idx = [], []
    for q in quads:
        base = len(verts)
        verts.extend(q)
        idx.extend([base, base + 1, base + 2, base, base + 2, base + 3])
    pdata = b"".join(struct.pack("<3f", *v) for v in verts)
    idata = b"".join(struct.pack("<H", i) for i in idx)
    pv = add_view(pdata, 34962)
    iv = add_view(idata, 34963)
    lo = [min(v[k] for v in verts) for k in range(3)]
    hi = [max(v[k] for v in verts) for k in range(3)]
    lo = [struct.unpack("<f", struct.pack("<f", x))[0] for x in lo]
    hi = [struct.unpack("<f", struct.pack("<f", x))[0] for x in hi]
    accessors.append({"bufferView": pv, "componentType": 5126, "count": len(verts), "type": "VEC3",
                      "min": lo, "max": hi})
    accessors.append({"bufferView": iv, "componentType": 5123, "count": len(idx), "type": "SCALAR"})
    meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                 "indices": len(accessors) - 1, "material": material}]})
    return len(meshes) - 1


def box_quads(sx, sy, sz):
    """An open-bottom box centred on the y axis, base at y = 0, faces pointing outwards."""
    x, z = sx / 2, sz / 2
    return [
        [(-x, sy, -z), (-x, sy, z), (x, sy, z), (x, sy, -z)],      # top (+y)
        [(-x, 0, z), (x, 0, z), (x, sy, z), (-x, sy, z)],          # +z
        [(x, 0, -z), (-x, 0, -z), (-x, sy, -z), (x, sy, -z)],      # -z
        [(x, 0, z), (x, 0, -z), (x, sy, -z), (x, sy, z)],          # +x
        [(-x, 0, -z), (-x, 0, z), (-x, sy, z), (-x, sy, -z)],      # -x
    ]


W, H, D = 0.556, 0.5488, 0.5592  # box interior (x, y, z), metres
room = [
    ("floor", [[(0, 0, 0), (0, 0, D), (W, 0, D), (W, 0, 0)]], WHITE),
    ("ceiling", [[(0, H, 0), (W, H, 0), (W, H, D), (0, H, D)]], WHITE),
    ("back_wall", [[(0, 0, D), (0, H, D), (W, H, D), (W, 0, D)]], WHITE),
    ("red_wall", [[(W, 0, 0), (W, 0, D), (W, H, D), (W, H, 0)]], RED),      # x = W, image left
    ("green_wall", [[(0, 0, 0), (0, H, 0), (0, H, D), (0, 0, D)]], GREEN),  # x = 0, image right
    # The light hangs 1 mm below the ceiling, facing down.
    ("light", [[(0.213, H - 0.001, 0.227), (0.343, H - 0.001, 0.227),
                (0.343, H - 0.001, 0.332), (0.213, H - 0.001, 0.332)]], LIGHT),
]
for name, quads, mat in room:
    nodes.append({"name": name, "mesh": add_mesh(name, quads, mat)})

tall = add_mesh("tall_box", box_quads(0.165, 0.33, 0.165), WHITE)
yaw = math.radians(17.0)
nodes.append({"name": "tall_box", "mesh": tall, "translation": [0.37, 0.0, 0.40],
              "rotation": [0.0, math.sin(yaw / 2), 0.0, math.cos(yaw / 2)]})

short = add_mesh("short_box", box_quads(0.165, 0.165, 0.165), WHITE)
short_node = len(nodes)
nodes.append({"name": "short_box", "mesh": short, "translation": [0.13, 0.0, 0.17]})

camera_node = len(nodes)
nodes.append({"name": "camera", "camera": 0, "translation": [0.278, 0.273, -0.8]})


def quat_y(deg):
    a = math.radians(deg) / 2
    return [0.0, math.sin(a), 0.0, math.cos(a)]


def add_floats(values, kind):
    data = b"".join(struct.pack("<f", v) for v in values)
    v = add_view(data, None)
    del views[v]["target"]
    n = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[kind]
    acc = {"bufferView": v, "componentType": 5126, "count": len(values) // n, "type": kind}
    if kind == "SCALAR":
        acc["min"], acc["max"] = [min(values)], [max(values)]
    accessors.append(acc)
    return len(accessors) - 1


times = [0.0, 2.0, 4.0]
t_in = add_floats(times, "SCALAR")
slide = add_floats([0.13, 0.0, 0.17, 0.28, 0.0, 0.19, 0.42, 0.0, 0.17], "VEC3")
turn = add_floats(quat_y(0) + quat_y(-15) + quat_y(-30), "VEC4")
pan = add_floats(quat_y(180 + 7) + quat_y(180) + quat_y(180 - 7), "VEC4")
animation = {
    "name": "slide_and_pan",
    "samplers": [
        {"input": t_in, "output": slide, "interpolation": "LINEAR"},
        {"input": t_in, "output": turn, "interpolation": "LINEAR"},
        {"input": t_in, "output": pan, "interpolation": "LINEAR"},
    ],
    "channels": [
        {"sampler": 0, "target": {"node": short_node, "path": "translation"}},
        {"sampler": 1, "target": {"node": short_node, "path": "rotation"}},
        {"sampler": 2, "target": {"node": camera_node, "path": "rotation"}},
    ],
}
nodes[camera_node]["rotation"] = quat_y(180 + 7)


def material(name, rgb, emission=None, strength=None):
    m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(rgb) + [1.0],
                                                "metallicFactor": 0.0, "roughnessFactor": 1.0}}
    if emission:
        m["emissiveFactor"] = list(emission)
        m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
    return m


gltf = {
    "asset": {"version": "2.0", "generator": "rad pipelines/scenes/make_cornell_moving.py"},
    "extensionsUsed": ["KHR_materials_emissive_strength"],
    "scene": 0,
    "scenes": [{"name": "cornell-moving", "nodes": list(range(len(nodes)))}],
    "nodes": nodes,
    "meshes": meshes,
    "materials": [
        material("white", (0.725, 0.71, 0.68)),
        material("red", (0.63, 0.065, 0.05)),
        material("green", (0.14, 0.45, 0.091)),
        material("light", (0.78, 0.78, 0.78), (1.0, 12 / 17, 4 / 17), 17.0),
    ],
    "cameras": [{"name": "camera", "type": "perspective",
                 "perspective": {"yfov": 0.6860478808414068, "znear": 0.01, "zfar": 3.0}}],
    "animations": [animation],
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(buffer),
                 "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(buffer)).decode()}],
}

out = sys.argv[1] if len(sys.argv) > 1 else "cornell-moving.gltf"
with open(out, "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
