#!/usr/bin/env python3
"""Writes a closed unit cube, walls facing in, of reflectance RHO, lit by a point lamp of 1 cd
at its centre: issue 57's power conservation case.

The lamp emits 4 pi I W and the walls absorb all of it, so their mean irradiance is
4 pi I / (A (1 - rho)) and their mean radiosity rho 4 pi I / (A (1 - rho)), A = 6 m^2. By
symmetry every wall's mean is that. A camera inside looks at the far wall.

usage: make_lamp_box.py RHO OUT.gltf
Only the Python standard library is used; the output is deterministic.
"""
import base64
import json
import struct
import sys

rho, out = float(sys.argv[1]), sys.argv[2]
# Each face counter-clockwise seen from inside the cube (its normal points to the centre).
faces = [[(0, 0, 0), (0, 0, 1), (1, 0, 1), (1, 0, 0)], [(0, 1, 0), (1, 1, 0), (1, 1, 1), (0, 1, 1)],
         [(0, 0, 0), (0, 1, 0), (0, 1, 1), (0, 0, 1)], [(1, 0, 0), (1, 0, 1), (1, 1, 1), (1, 1, 0)],
         [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], [(0, 0, 1), (0, 1, 1), (1, 1, 1), (1, 0, 1)]]
buffer, views, accessors, meshes, nodes = bytearray(), [], [], [], []
for k, f in enumerate(faces):
    views.append({"buffer": 0, "byteOffset": len(buffer), "byteLength": 48})
    buffer += b"".join(struct.pack("<3f", *v) for v in f)
    accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": 4,
                      "type": "VEC3", "min": [min(v[i] for v in f) for i in range(3)],
                      "max": [max(v[i] for v in f) for i in range(3)]})
    views.append({"buffer": 0, "byteOffset": len(buffer), "byteLength": 12})
    buffer += struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    accessors.append({"bufferView": len(views) - 1, "componentType": 5123, "count": 6,
                      "type": "SCALAR"})
    meshes.append({"name": "wall%d" % k, "primitives": [{
        "attributes": {"POSITION": len(accessors) - 2}, "indices": len(accessors) - 1,
        "material": 0}]})
    nodes.append({"name": "wall%d" % k, "mesh": k})
nodes.append({"name": "lamp", "translation": [0.5, 0.5, 0.5],
              "extensions": {"KHR_lights_punctual": {"light": 0}}})
nodes.append({"name": "camera", "camera": 0, "translation": [0.5, 0.5, 0.9]})
gltf = {
    "asset": {"version": "2.0", "generator": "rad pipelines/scenes/make_lamp_box.py"},
    "extensionsUsed": ["KHR_lights_punctual"],
    "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1.0}]}},
    "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}], "nodes": nodes,
    "meshes": meshes,
    "materials": [{"name": "wall", "pbrMetallicRoughness": {
        "baseColorFactor": [rho, rho, rho, 1.0], "metallicFactor": 0.0}}],
    "cameras": [{"type": "perspective", "perspective": {"yfov": 1.2, "znear": 0.01}}],
    "accessors": accessors, "bufferViews": views,
    "buffers": [{"byteLength": len(buffer), "uri": "data:application/octet-stream;base64," +
                 base64.b64encode(bytes(buffer)).decode()}],
}
with open(out, "w") as f:
    json.dump(gltf, f, indent=1)
    f.write("\n")
