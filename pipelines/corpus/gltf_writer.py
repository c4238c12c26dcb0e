"""Writes a converted MGF scene as glTF 2.0 (SCENE.gltf + SCENE.bin) in the form rad reads.

One node and one mesh per MGF object (formats/gltf_scene.md: a mesh node is the unit of motion),
one primitive per material in it, float32 positions shared within a primitive, uint32 indices.
Geometry is in world coordinates, so every node sits at the origin; an animated node (a mover)
only translates. A camera (glTF camera node, -Z forward, +Y up) may follow a path of keys, each
looking at a target; rotations are slerped by glTF's LINEAR sampler between keys.
"""
import json
import math
import os
import struct

import mgf_material


def _f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


def look_at_quaternion(position, target):
    """glTF rotation (x, y, z, w) of a camera at position looking at target, +Y up."""
    f = [target[k] - position[k] for k in range(3)]
    n = math.sqrt(sum(c * c for c in f))
    f = [c / n for c in f]
    r = [f[1] * 0 - f[2] * 1, f[2] * 0 - f[0] * 0, f[0] * 1 - f[1] * 0]  # f x (0, 1, 0)
    n = math.sqrt(sum(c * c for c in r))
    if n < 1e-9:
        raise ValueError("camera looks straight up or down")
    r = [c / n for c in r]
    u = [r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2], r[0] * f[1] - r[1] * f[0]]
    z = [-c for c in f]
    m = [[r[0], u[0], z[0]], [r[1], u[1], z[1]], [r[2], u[2], z[2]]]  # columns: right, up, back
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 0.5 / math.sqrt(trace + 1.0)
        q = [(m[2][1] - m[1][2]) * s, (m[0][2] - m[2][0]) * s, (m[1][0] - m[0][1]) * s, 0.25 / s]
    else:
        i = max(range(3), key=lambda k: m[k][k])
        j, k = (i + 1) % 3, (i + 2) % 3
        s = 2.0 * math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k])
        q = [0.0, 0.0, 0.0, (m[k][j] - m[j][k]) / s]
        q[i] = 0.25 * s
        q[j] = (m[j][i] + m[i][j]) / s
        q[k] = (m[k][i] + m[i][k]) / s
    return q


class _Buffer:
    def __init__(self):
        self.data = bytearray()
        self.views, self.accessors = [], []

    def add(self, payload, target, component, kind, count, bounds=None):
        while len(self.data) % 4:
            self.data.append(0)
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload)}
        if target:
            view["target"] = target
        self.views.append(view)
        self.data.extend(payload)
        acc = {"bufferView": len(self.views) - 1, "componentType": component, "count": count, "type": kind}
        if bounds:
            acc["min"], acc["max"] = bounds
        self.accessors.append(acc)
        return len(self.accessors) - 1

    def floats(self, values, kind):
        width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[kind]
        bounds = None
        if kind == "SCALAR":
            bounds = ([_f32(min(values))], [_f32(max(values))])
        return self.add(struct.pack(f"<{len(values)}f", *values), None, 5126, kind, len(values) // width, bounds)


def _primitive(buf, triangles, material):
    index_of, positions, indices = {}, [], []
    for tri in triangles:
        for p in tri:
            q = (_f32(p[0]), _f32(p[1]), _f32(p[2]))
            if q not in index_of:
                index_of[q] = len(positions)
                positions.append(q)
            indices.append(index_of[q])
    lo = [min(p[k] for p in positions) for k in range(3)]
    hi = [max(p[k] for p in positions) for k in range(3)]
    flat = [c for p in positions for c in p]
    pos = buf.add(struct.pack(f"<{len(flat)}f", *flat), 34962, 5126, "VEC3", len(positions), (lo, hi))
    idx = buf.add(struct.pack(f"<{len(indices)}I", *indices), 34963, 5125, "SCALAR", len(indices))
    return {"attributes": {"POSITION": pos}, "indices": idx, "material": material}


def _materials(scene, sides):
    """glTF materials of the keys in use, in order of first use; names kept unique."""
    index, out, taken, notes, emission = {}, [], {}, {}, {}
    for node in scene.nodes.values():
        for key in node:
            if key in index:
                continue
            name, mat = scene.materials[key]
            fields, rgb, dropped = mgf_material.to_gltf(mat, sides)
            taken[name] = taken.get(name, 0) + 1
            unique = name if taken[name] == 1 else f"{name}#{taken[name]}"
            index[key] = len(out)
            out.append(dict(name=unique, **fields))
            notes[unique] = dropped
            emission[key] = max(rgb)
    return index, out, notes, emission


def write(scene, path, sides="one", camera=None, movers=None, name="scene"):
    """Writes path (.gltf) and its .bin; returns a summary dict for INDEX.txt.

    camera: {"yfov": radians, "keys": [(t, position, target), ...]} (one key: a still camera);
    movers: {node name: [(t, (dx, dy, dz)), ...]} translations of whole objects over time.
    """
    buf = _Buffer()
    mat_index, materials, notes, mat_strength = _materials(scene, sides)
    nodes, meshes = [], []
    triangles = emitters = 0
    emitter_objects, emission = 0, []
    lo, hi = [math.inf] * 3, [-math.inf] * 3
    for node_name, by_material in scene.nodes.items():
        prims = []
        for key, tris in by_material.items():
            if not tris:
                continue
            prims.append(_primitive(buf, tris, mat_index[key]))
            triangles += len(tris)
            emitters += len(tris) if mat_strength[key] > 0 else 0
            for tri in tris:
                for p in tri:
                    for k in range(3):
                        lo[k], hi[k] = min(lo[k], p[k]), max(hi[k], p[k])
        lit = [mat_strength[k] for k, t in by_material.items() if t and mat_strength[k] > 0]
        emitter_objects += 1 if lit else 0
        emission += lit
        if prims:
            meshes.append({"name": node_name, "primitives": prims})
            nodes.append({"name": node_name, "mesh": len(meshes) - 1})
    channels, samplers = [], []

    def animate(node, path_name, times, values, kind):
        samplers.append({"input": buf.floats(times, "SCALAR"), "output": buf.floats(values, kind),
                         "interpolation": "LINEAR"})
        channels.append({"sampler": len(samplers) - 1, "target": {"node": node, "path": path_name}})

    moved = []
    for mover, keys in (movers or {}).items():
        hits = [i for i, n in enumerate(nodes) if n["name"] == mover]
        if not hits:
            raise ValueError(f"mover '{mover}': no object of that name")
        animate(hits[0], "translation", [t for t, _ in keys], [c for _, d in keys for c in d], "VEC3")
        moved.append(mover)
    cameras = []
    if camera:
        keys = camera["keys"]
        rotations = [look_at_quaternion(p, t) for _, p, t in keys]
        for i in range(1, len(rotations)):  # shortest arc between keys
            if sum(a * b for a, b in zip(rotations[i - 1], rotations[i])) < 0:
                rotations[i] = [-c for c in rotations[i]]
        cameras.append({"name": "camera", "type": "perspective",
                        "perspective": {"yfov": camera["yfov"], "znear": camera.get("znear", 0.05)}})
        nodes.append({"name": "camera", "camera": 0, "translation": list(keys[0][1]), "rotation": rotations[0]})
        if len(keys) > 1:
            times = [k[0] for k in keys]
            animate(len(nodes) - 1, "translation", times, [c for _, p, _ in keys for c in p], "VEC3")
            animate(len(nodes) - 1, "rotation", times, [c for q in rotations for c in q], "VEC4")
    bin_name = os.path.splitext(os.path.basename(path))[0] + ".bin"
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    gltf = {
        "asset": {"version": "2.0", "generator": "rad pipelines/corpus/mgf_to_gltf.py"},
        "scene": 0,
        "scenes": [{"name": name, "nodes": list(range(len(nodes)))}],
        "nodes": nodes, "meshes": meshes, "materials": materials,
        "accessors": buf.accessors, "bufferViews": buf.views,
        "buffers": [{"byteLength": len(buf.data), "uri": bin_name}],
    }
    if any("extensions" in m for m in materials):
        gltf["extensionsUsed"] = ["KHR_materials_emissive_strength"]
    if cameras:
        gltf["cameras"] = cameras
    if channels:
        gltf["animations"] = [{"name": "corpus", "samplers": samplers, "channels": channels}]
    with open(os.path.join(os.path.dirname(path) or ".", bin_name), "wb") as f:
        f.write(buf.data)
    with open(path, "w") as f:
        json.dump(gltf, f, indent=None, separators=(",", ":"))
        f.write("\n")
    return {"triangles": triangles, "emitting_triangles": emitters, "nodes": len(meshes),
            "materials": len(materials), "bounds": (lo, hi), "dropped": notes, "moved": moved,
            "emitter_objects": emitter_objects,
            "emission_range": (min(emission, default=0.0), max(emission, default=0.0))}
