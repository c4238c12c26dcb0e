#!/usr/bin/env python3
"""Writes a floor lit by one KHR_lights_punctual lamp, seen from straight above (orthographic).

The closed forms of issue 57 through the real tools: a plane cannot see itself, so a pixel showing
the floor at x is exactly rho / pi x E(x), with E the lamp's irradiance: I cos(theta) / d^2 for a
point lamp, times the extension's smooth cone falloff for a spot, E cos(theta) for a sun. The
camera is orthographic, looking down -Y with image up along -Z, xmag = ymag = HALF: the pixel
(i, j) of a W x H image shows the floor at x = HALF (2 (i + 1/2) / W - 1),
z = HALF (2 (j + 1/2) / H - 1). The floor is a square of side 2 x FLOOR (20 m: "infinite" for
the lamp at 1 m), reflectance RHO, one quad.

usage: make_lamp_floor.py OUT.gltf [--lamp point|spot|sun] [--move] [--blocker] [--move-blocker]
                          [--blender]

  --move          the lamp moves along +X by 1 m over 2 s (LINEAR), so its shadow moves
  --blocker       a 0.4 m square board, facing up, 0.5 m above the floor at x in [0.2, 0.6]
  --move-blocker  the board (implies --blocker) moves along -Z by 1 m over 2 s
  --blender  asset.generator names Blender's exporter, so --light-units auto reads blender units

Lamp: intensity I = 10 cd (colour 1, 0.8, 0.6) at (0, 1, 0) shining down; spot cones 0.3 and
0.6 rad; sun E = 2 lux at 30 degrees from the vertical, tilted toward +X.
Only the Python standard library is used; the output is deterministic.
"""
import base64
import json
import math
import struct
import sys

FLOOR, HALF, RHO = 10.0, 2.0, 0.5
args = sys.argv[1:]
out = args[0] if args and not args[0].startswith("--") else "lamp-floor.gltf"
lamp = args[args.index("--lamp") + 1] if "--lamp" in args else "point"
buffer = bytearray()
views, accessors, meshes, nodes = [], [], [], []


def add_view(data):
    while len(buffer) % 4:
        buffer.append(0)
    views.append({"buffer": 0, "byteOffset": len(buffer), "byteLength": len(data)})
    buffer.extend(data)
    return len(views) - 1


def add_accessor(values, fmt, type_, ctype, minmax=False):
    view = add_view(b"".join(struct.pack("<" + fmt, *v) for v in values))
    a = {"bufferView": view, "componentType": ctype, "count": len(values), "type": type_}
    if minmax:
        a["min"] = [min(v[k] for v in values) for k in range(len(values[0]))]
        a["max"] = [max(v[k] for v in values) for k in range(len(values[0]))]
    accessors.append(a)
    return len(accessors) - 1


def add_quad(name, corners, material):
    """corners: 4 points, counter-clockwise seen from the front; two triangles."""
    p = add_accessor(corners, "3f", "VEC3", 5126, True)
    i = add_accessor([(0,), (1,), (2,), (0,), (2,), (3,)], "H", "SCALAR", 5123)
    meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": p}, "indices": i,
                                                 "material": material}]})
    nodes.append({"name": name, "mesh": len(meshes) - 1})


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz]


DOWN = [-math.sin(math.pi / 4), 0.0, 0.0, math.cos(math.pi / 4)]  # -Z local -> -Y world
F = FLOOR
add_quad("floor", [(-F, 0, -F), (-F, 0, F), (F, 0, F), (F, 0, -F)], 0)
if "--blocker" in args or "--move-blocker" in args:
    add_quad("blocker", [(0.2, 0.5, -0.2), (0.2, 0.5, 0.2), (0.6, 0.5, 0.2), (0.6, 0.5, -0.2)], 0)
nodes.append({"name": "camera", "camera": 0, "translation": [0.0, 5.0, 0.0], "rotation": DOWN})
light = {"name": lamp, "type": "directional" if lamp == "sun" else lamp, "color": [1.0, 0.8, 0.6],
         "intensity": 2.0 if lamp == "sun" else 10.0}
if lamp == "spot":
    light["spot"] = {"innerConeAngle": 0.3, "outerConeAngle": 0.6}
lamp_node = {"name": "lamp", "translation": [0.0, 1.0, 0.0], "rotation": DOWN,
             "extensions": {"KHR_lights_punctual": {"light": 0}}}
if lamp == "sun":
    tilt = math.radians(30.0)  # about +Z: the direction -Y turns toward +X
    lamp_node["rotation"] = qmul([0.0, 0.0, math.sin(tilt / 2), math.cos(tilt / 2)], DOWN)
nodes.append(lamp_node)
animations = []


def move(name, node, start, end):
    t = add_accessor([(0.0,), (2.0,)], "f", "SCALAR", 5126, True)
    v = add_accessor([start, end], "3f", "VEC3", 5126)
    animations.append({"name": name,
                       "samplers": [{"input": t, "output": v, "interpolation": "LINEAR"}],
                       "channels": [{"sampler": 0, "target": {"node": node, "path": "translation"}}]})


if "--move" in args:
    move("lamp-moves", len(nodes) - 1, (0.0, 1.0, 0.0), (1.0, 1.0, 0.0))
if "--move-blocker" in args:
    move("board-moves", 1, (0.0, 0.0, 0.0), (0.0, 0.0, -1.0))

generator = ("Khronos glTF Blender I/O v3.4.50" if "--blender" in args
             else "rad pipelines/scenes/make_lamp_floor.py")
gltf = {
    "asset": {"version": "2.0", "generator": generator},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensionsRequired": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [light]}},
    "scene": 0,
    "scenes": [{"name": "lamp-floor", "nodes": list(range(len(nodes)))}],
    "nodes": nodes,
    "meshes": meshes,
    "materials": [{"name": "floor", "pbrMetallicRoughness": {
        "baseColorFactor": [RHO, RHO, RHO, 1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
    "cameras": [{"name": "camera", "type": "orthographic",
                 "orthographic": {"xmag": HALF, "ymag": HALF, "znear": 0.01, "zfar": 20.0}}],
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(buffer), "uri": "data:application/octet-stream;base64," +
                 base64.b64encode(bytes(buffer)).decode()}],
}
if animations:
    gltf["animations"] = animations

with open(out, "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
