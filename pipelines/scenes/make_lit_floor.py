#!/usr/bin/env python3
"""Writes lit-floor.gltf: a floor lit by one square lamp, with an upright panel, seen obliquely.

The scene on which an independent renderer's references are checked against rad-reference
before they judge anything (pipelines/cycles_reference.py; docs/design.md §6.6): emission units
(the lamp's L_e = emissiveFactor x KHR_materials_emissive_strength), Lambertian reflection, a
one-sided lamp whose back the camera sees through, and the framing (the floor's corners and the
panel fall at known pixels, asymmetrically left/right and top/bottom). Static, one frame.

usage: make_lit_floor.py OUT.gltf

Only the Python standard library is used; the output is deterministic.
"""
import base64
import json
import math
import struct
import sys

buffer = bytearray()
views, accessors, meshes, nodes = [], [], [], []


def add_view(data, target):
    while len(buffer) % 4:
        buffer.append(0)
    views.append({"buffer": 0, "byteOffset": len(buffer), "byteLength": len(data),
                  "target": target})
    buffer.extend(data)
    return len(views) - 1


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def add_quad(name, corners, material):
    """corners: 4 points, counter-clockwise seen from the front; two triangles."""
    pv = add_view(b"".join(struct.pack("<3f", *v) for v in corners), 34962)
    iv = add_view(b"".join(struct.pack("<H", i) for i in (0, 1, 2, 0, 2, 3)), 34963)
    accessors.append({"bufferView": pv, "componentType": 5126, "count": 4, "type": "VEC3",
                      "min": [f32(min(v[k] for v in corners)) for k in range(3)],
                      "max": [f32(max(v[k] for v in corners)) for k in range(3)]})
    accessors.append({"bufferView": iv, "componentType": 5123, "count": 6, "type": "SCALAR"})
    meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": len(accessors) - 2},
                                                 "indices": len(accessors) - 1,
                                                 "material": material}]})
    nodes.append({"name": name, "mesh": len(meshes) - 1})


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


def look_at(eye, target):
    """glTF rotation of a camera at eye looking at target, no roll (yaw, then pitch)."""
    f = [target[i] - eye[i] for i in range(3)]
    n = math.sqrt(sum(x * x for x in f))
    f = [x / n for x in f]
    yaw, pitch = math.atan2(-f[0], -f[2]), math.asin(f[1])
    return list(qmul((0.0, math.sin(yaw / 2), 0.0, math.cos(yaw / 2)),
                     (math.sin(pitch / 2), 0.0, 0.0, math.cos(pitch / 2))))


def material(name, rgb, strength=None):
    m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(rgb) + [1.0],
                                                "metallicFactor": 0.0, "roughnessFactor": 1.0}}
    if strength:
        m["emissiveFactor"] = [1.0, 0.8, 0.6]
        m["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": strength}}
    return m


add_quad("floor", [(-0.5, 0, -0.5), (-0.5, 0, 0.5), (0.5, 0, 0.5), (0.5, 0, -0.5)], 0)
add_quad("panel", [(-0.35, 0, -0.2), (-0.1, 0, -0.2), (-0.1, 0.3, -0.2), (-0.35, 0.3, -0.2)], 1)
add_quad("lamp", [(-0.15, 0.8, -0.15), (0.15, 0.8, -0.15), (0.15, 0.8, 0.15),
                  (-0.15, 0.8, 0.15)], 2)  # faces down
eye = (0.35, 0.9, 1.3)
nodes.append({"name": "camera", "camera": 0, "translation": list(eye),
              "rotation": look_at(eye, (0.0, 0.05, 0.0))})

gltf = {
    "asset": {"version": "2.0", "generator": "rad pipelines/scenes/make_lit_floor.py"},
    "extensionsUsed": ["KHR_materials_emissive_strength"],
    "scene": 0,
    "scenes": [{"name": "lit-floor", "nodes": list(range(len(nodes)))}],
    "nodes": nodes,
    "meshes": meshes,
    "materials": [material("floor", (0.6, 0.5, 0.4)), material("panel", (0.3, 0.6, 0.3)),
                  material("lamp", (0.5, 0.5, 0.5), 8.0)],
    "cameras": [{"name": "camera", "type": "perspective",
                 "perspective": {"yfov": 0.8, "znear": 0.01, "zfar": 10.0}}],
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(buffer), "uri": "data:application/octet-stream;base64," +
                 base64.b64encode(bytes(buffer)).decode()}],
}

with open(sys.argv[1] if len(sys.argv) > 1 else "lit-floor.gltf", "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
