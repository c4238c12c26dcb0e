#!/usr/bin/env python3
"""Writes the test scenes of the paper's §6 (Martín, Pueyo, Tost) as animated glTF 2.0.

  table-<lights>-<camera>.gltf  Shirley's table and four chairs in a room (~450 static
                                triangles), one moving 16-polygon "space car" flying round the
                                table, four ceiling lights (lights=static) or two static and two
                                moving ones (lights=dynamic); camera static, pan (centre of
                                interest animated) or follow (eye and centre follow the car).
                                Table 2 of the paper: six configurations.
  cubes-<n>.gltf                a room with three chairs and n = 1, 2, 4, 8, 16, 32 cubes
                                (6 polygons each) on long paths across the room; static camera.
                                Tables 3 and 4.
  cubic.gltf                    a highly partitioned scene: a 3 x 3 grid of cells separated by
                                walls with doorways, a light per cell, a box touring the cells
                                and a camera following it. Table 5.

Every animation lasts DURATION seconds: 400 frames at 24 fps. Only the standard library is
used and the output is deterministic, so regenerated files are byte-identical.

usage: make_paper_scenes.py OUTDIR [NAME ...]     (no NAME: every scene)
"""
import argparse
import base64
import json
import math
import os
import struct
import sys

FPS = 24.0
FRAMES = 400
DURATION = (FRAMES - 1) / FPS  # frame 399 is the last key

WHITE, WOOD, RED, BLUE, LIGHT, CAR = range(6)
MATERIALS = [
    ("white", (0.75, 0.75, 0.72), None),
    ("wood", (0.55, 0.38, 0.22), None),
    ("red", (0.7, 0.12, 0.1), None),
    ("blue", (0.15, 0.25, 0.65), None),
    ("light", (0.8, 0.8, 0.8), (1.0, 0.95, 0.85)),
    ("car", (0.85, 0.8, 0.2), None),
]


def f32(x):
    return struct.unpack("<f", struct.pack("<f", x))[0]


class Gltf:
    def __init__(self, name):
        self.name = name
        self.buffer = bytearray()
        self.views, self.accessors, self.meshes, self.nodes = [], [], [], []
        self.samplers, self.channels = [], []
        self.cameras = []

    def view(self, data, target=None):
        while len(self.buffer) % 4:
            self.buffer.append(0)
        v = {"buffer": 0, "byteOffset": len(self.buffer), "byteLength": len(data)}
        if target:
            v["target"] = target
        self.views.append(v)
        self.buffer.extend(data)
        return len(self.views) - 1

    def mesh(self, name, quads, material):
        """quads: lists of 3 or 4 corners, CCW seen from the front."""
        verts, tris = [], []
        for q in quads:
            base = len(verts)
            verts.extend(q)
            tris.append((base, base + 1, base + 2))
            if len(q) == 4:
                tris.append((base, base + 2, base + 3))
        return self.indexed_mesh(name, verts, tris, material)

    def indexed_mesh(self, name, verts, tris, material):
        """verts: 3D points; tris: index triples, CCW seen from the front (shared vertices)."""
        idx = [i for t in tris for i in t]
        pv = self.view(b"".join(struct.pack("<3f", *v) for v in verts), 34962)
        iv = self.view(b"".join(struct.pack("<H", i) for i in idx), 34963)
        lo = [f32(min(v[k] for v in verts)) for k in range(3)]
        hi = [f32(max(v[k] for v in verts)) for k in range(3)]
        self.accessors.append({"bufferView": pv, "componentType": 5126, "count": len(verts),
                               "type": "VEC3", "min": lo, "max": hi})
        self.accessors.append({"bufferView": iv, "componentType": 5123, "count": len(idx),
                               "type": "SCALAR"})
        n = len(self.accessors)
        self.meshes.append({"name": name, "primitives": [
            {"attributes": {"POSITION": n - 2}, "indices": n - 1, "material": material}]})
        return len(self.meshes) - 1

    def node(self, name, mesh=None, translation=None, rotation=None, camera=None):
        n = {"name": name}
        if mesh is not None:
            n["mesh"] = mesh
        if camera is not None:
            n["camera"] = camera
        if translation is not None:
            n["translation"] = [float(x) for x in translation]
        if rotation is not None:
            n["rotation"] = [float(x) for x in rotation]
        self.nodes.append(n)
        return len(self.nodes) - 1

    def floats(self, values, kind):
        v = self.view(b"".join(struct.pack("<f", x) for x in values))
        n = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[kind]
        a = {"bufferView": v, "componentType": 5126, "count": len(values) // n, "type": kind}
        if kind == "SCALAR":
            a["min"], a["max"] = [f32(min(values))], [f32(max(values))]
        self.accessors.append(a)
        return len(self.accessors) - 1

    def animate(self, node, path, times, values):
        """values: one tuple per key time (3 for translation, 4 for rotation x y z w)."""
        t = self.floats(times, "SCALAR")
        o = self.floats([c for v in values for c in v], "VEC3" if path == "translation" else "VEC4")
        self.samplers.append({"input": t, "output": o, "interpolation": "LINEAR"})
        self.channels.append({"sampler": len(self.samplers) - 1,
                              "target": {"node": node, "path": path}})
        self.nodes[node][path] = [float(x) for x in values[0]]

    def split_mesh_nodes(self, name, quads, material):
        """Nodes NAME0, NAME1, ... of at most 8000 quads each (16-bit indices take at most 32,000
        vertices a mesh); returns the triangles they add."""
        for part in range(0, len(quads), 8000):
            n = "%s%d" % (name, part // 8000)
            self.node(n, self.mesh(n, quads[part:part + 8000], material))
        return 2 * len(quads)

    def still_camera(self, eye, target, yfov=0.9):
        """A camera node "camera" at eye looking at target."""
        return self.node("camera", camera=self.camera(yfov), translation=eye,
                         rotation=quat_look(eye, target))

    def camera(self, yfov=0.9):
        self.cameras.append({"name": "camera", "type": "perspective",
                             "perspective": {"yfov": yfov, "znear": 0.02, "zfar": 50.0}})
        return len(self.cameras) - 1

    def write(self, path, light_strength, materials=None):
        """materials: (name, rgb, emission or None) per index; default the paper scenes'."""
        mats = []
        for name, rgb, emission in materials or MATERIALS:
            m = {"name": name, "pbrMetallicRoughness": {"baseColorFactor": list(rgb) + [1.0],
                                                        "metallicFactor": 0.0,
                                                        "roughnessFactor": 1.0}}
            if emission:
                m["emissiveFactor"] = list(emission)
                m["extensions"] = {"KHR_materials_emissive_strength":
                                   {"emissiveStrength": light_strength}}
            mats.append(m)
        g = {
            "asset": {"version": "2.0", "generator": "rad pipelines/scenes/" +
                      os.path.basename(sys.argv[0] or "make_paper_scenes.py")},
            "extensionsUsed": ["KHR_materials_emissive_strength"],
            "scene": 0,
            "scenes": [{"name": self.name, "nodes": list(range(len(self.nodes)))}],
            "nodes": self.nodes,
            "meshes": self.meshes,
            "materials": mats,
            "cameras": self.cameras,
            "accessors": self.accessors,
            "bufferViews": self.views,
            "buffers": [{"byteLength": len(self.buffer),
                         "uri": "data:application/octet-stream;base64," +
                                base64.b64encode(bytes(self.buffer)).decode()}],
        }
        if self.channels:
            g["animations"] = [{"name": "motion", "samplers": self.samplers,
                                "channels": self.channels}]
        # Atomic: a reader never sees half a file, a failed run leaves the old one.
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            json.dump(g, f, indent=1)
            f.write("\n")
        os.replace(tmp, path)


# --- geometry -----------------------------------------------------------------------------

def box(x0, y0, z0, x1, y1, z1, bottom=True):
    """Axis-aligned box, faces outwards."""
    q = [
        [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],  # +y
        [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],  # +z
        [(x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)],  # -z
        [(x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1)],  # +x
        [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],  # -x
    ]
    if bottom:
        q.append([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)])  # -y
    return q


def grid(origin, du, dv, n):
    """An n x n grid of quads spanning origin + [0,1] du + [0,1] dv (front = du x dv)."""
    out = []
    for i in range(n):
        for j in range(n):
            p = [tuple(origin[k] + du[k] * (i + a) / n + dv[k] * (j + b) / n for k in range(3))
                 for a, b in ((0, 0), (1, 0), (1, 1), (0, 1))]
            out.append(p)
    return out


def room(w, h, d, n):
    """Inward-facing room [0,w] x [0,h] x [0,d], each wall an n x n grid."""
    return {
        "floor": grid((0, 0, 0), (0, 0, d), (w, 0, 0), n),
        "ceiling": grid((0, h, 0), (w, 0, 0), (0, 0, d), n),
        "wall_z0": grid((0, 0, 0), (w, 0, 0), (0, h, 0), n),
        "wall_z1": grid((0, 0, d), (0, h, 0), (w, 0, 0), n),
        "wall_x0": grid((0, 0, 0), (0, h, 0), (0, 0, d), n),
        "wall_x1": grid((w, 0, 0), (0, 0, d), (0, h, 0), n),
    }


def table(cx, cz):
    q = box(cx - 0.7, 0.72, cz - 0.45, cx + 0.7, 0.76, cz + 0.45)
    for sx in (-1, 1):
        for sz in (-1, 1):
            x, z = cx + sx * 0.62, cz + sz * 0.37
            q += box(x - 0.03, 0.0, z - 0.03, x + 0.03, 0.72, z + 0.03, bottom=False)[1:]
    return q


def chair(cx, cz, facing):
    """facing: +1 the back is at -z (sits facing +z), -1 the back at +z."""
    q = box(cx - 0.22, 0.42, cz - 0.22, cx + 0.22, 0.46, cz + 0.22)
    for sx in (-1, 1):
        for sz in (-1, 1):
            x, z = cx + sx * 0.19, cz + sz * 0.19
            q += box(x - 0.02, 0.0, z - 0.02, x + 0.02, 0.42, z + 0.02, bottom=False)[1:]
    bz = cz - facing * 0.2
    q += box(cx - 0.22, 0.46, bz - 0.02, cx + 0.22, 0.95, bz + 0.02)
    return q


def ceiling_lit_room(g, w, h, d, wall_material, light_material, light_xs=(1.3, 2.7), light_z=1.6):
    """Adds an inward-facing room [0,w] x [0,h] x [0,d] of 4 x 4 quads a wall and 0.2 m square
    lights 2 mm under its ceiling at (x, light_z) for x in light_xs; returns the triangles."""
    count = 0
    for name, quads in room(w, h, d, 4).items():
        g.node(name, g.mesh(name, quads, wall_material))
        count += 2 * len(quads)
    for i, cx in enumerate(light_xs):
        name = "light%d" % i
        g.node(name, g.mesh(name, light_quad(0, 0, 0, 0.2), light_material),
               translation=(cx, h - 0.002, light_z))
        count += 2
    return count


def light_quad(cx, y, cz, s):
    return [[(cx - s, y, cz - s), (cx + s, y, cz - s), (cx + s, y, cz + s), (cx - s, y, cz + s)]]


def space_car():
    """16 polygons: body (6), cabin (5, sits on the body), fins (4 triangles + ... )."""
    q = box(-0.3, -0.06, -0.15, 0.3, 0.06, 0.15)
    q += box(-0.12, 0.06, -0.1, 0.12, 0.16, 0.1, bottom=False)
    q += [[(-0.3, 0.0, 0.15), (-0.1, 0.0, 0.15), (-0.2, 0.0, 0.4)],
          [(-0.1, 0.0, -0.15), (-0.3, 0.0, -0.15), (-0.2, 0.0, -0.4)],
          [(-0.3, 0.06, 0.0), (-0.3, 0.2, 0.0), (-0.15, 0.06, 0.0)],
          [(0.3, -0.06, 0.0), (0.42, 0.0, 0.0), (0.3, 0.06, 0.0)]]
    # the last two fins are seen from both sides: add their backs
    q += [[(-0.15, 0.06, 0.0), (-0.3, 0.2, 0.0), (-0.3, 0.06, 0.0)]]
    assert len(q) == 16, len(q)
    return q


# --- animation helpers --------------------------------------------------------------------

def quat_look(eye, target):
    """Rotation taking the camera's -Z onto target - eye with +Y up (x y z w)."""
    f = [target[k] - eye[k] for k in range(3)]
    n = math.sqrt(sum(c * c for c in f))
    z = [-c / n for c in f]
    up = (0.0, 1.0, 0.0)
    x = [up[1] * z[2] - up[2] * z[1], up[2] * z[0] - up[0] * z[2], up[0] * z[1] - up[1] * z[0]]
    n = math.sqrt(sum(c * c for c in x))
    x = [c / n for c in x]
    y = [z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]]
    m = [[x[0], y[0], z[0]], [x[1], y[1], z[1]], [x[2], y[2], z[2]]]
    tr = m[0][0] + m[1][1] + m[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        return ((m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s, 0.25 * s)
    i = max(range(3), key=lambda k: m[k][k])
    j, k = (i + 1) % 3, (i + 2) % 3
    s = math.sqrt(1.0 + m[i][i] - m[j][j] - m[k][k]) * 2
    q = [0.0, 0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (m[j][i] + m[i][j]) / s
    q[k] = (m[k][i] + m[i][k]) / s
    q[3] = (m[k][j] - m[j][k]) / s
    return tuple(q)


def key_times(n):
    return [DURATION * i / (n - 1) for i in range(n)]


def quat_y(rad):
    return (0.0, math.sin(rad / 2), 0.0, math.cos(rad / 2))


# --- scenes -------------------------------------------------------------------------------

def table_scene(lights, camera):
    g = Gltf("table-%s-%s" % (lights, camera))
    W, H, D = 5.0, 2.8, 5.0
    for name, quads in room(W, H, D, 4).items():
        g.node(name, g.mesh(name, quads, RED if name == "wall_x1" else WHITE))
    g.node("table", g.mesh("table", table(2.5, 2.5), WOOD))
    for i, (x, z, f) in enumerate([(2.0, 1.7, 1), (3.0, 1.7, 1), (2.0, 3.3, -1), (3.0, 3.3, -1)]):
        g.node("chair%d" % i, g.mesh("chair%d" % i, chair(x, z, f), BLUE if i % 2 else WOOD))
    times = key_times(17)
    for i, (x, z) in enumerate([(1.25, 1.25), (3.75, 1.25), (1.25, 3.75), (3.75, 3.75)]):
        m = g.mesh("light%d" % i, light_quad(0, 0, 0, 0.2), LIGHT)
        n = g.node("light%d" % i, m, translation=(x, H - 0.002, z))
        if lights == "dynamic" and i >= 2:
            g.animate(n, "translation", times,
                      [(x + 0.8 * math.sin(2 * math.pi * t / DURATION + i), H - 0.002, z)
                       for t in times])
    car = g.node("space_car", g.mesh("space_car", space_car(), CAR), translation=(2.5, 1.3, 1.0))
    car_times = key_times(33)

    def car_pos(t):
        a = 2 * math.pi * t / DURATION
        return (2.5 + 1.5 * math.sin(a), 1.25 + 0.25 * math.sin(2 * a), 2.5 - 1.5 * math.cos(a))

    g.animate(car, "translation", car_times, [car_pos(t) for t in car_times])
    g.animate(car, "rotation", car_times, [quat_y(-2 * math.pi * t / DURATION) for t in car_times])
    cam = g.node("camera", camera=g.camera(0.9))
    eye0 = (0.4, 1.7, 0.4)
    if camera == "static":
        g.nodes[cam]["translation"] = list(eye0)
        g.nodes[cam]["rotation"] = list(quat_look(eye0, (2.5, 0.8, 2.5)))
    elif camera == "pan":
        g.nodes[cam]["translation"] = list(eye0)
        g.animate(cam, "rotation", car_times,
                  [quat_look(eye0, (2.5 + 1.2 * math.sin(2 * math.pi * t / DURATION), 0.8,
                                    2.5 + 1.2 * math.cos(2 * math.pi * t / DURATION)))
                   for t in car_times])
    else:
        eyes = []
        for t in car_times:
            p = car_pos(t)
            eyes.append((2.5 + 0.85 * (p[0] - 2.5) * 1.6, 1.9, 2.5 + 0.85 * (p[2] - 2.5) * 1.6))
        g.animate(cam, "translation", car_times, eyes)
        g.animate(cam, "rotation", car_times,
                  [quat_look(e, car_pos(t)) for e, t in zip(eyes, car_times)])
    return g


def cubes_scene(n):
    g = Gltf("cubes-%d" % n)
    W, H, D = 6.0, 3.0, 6.0
    for name, quads in room(W, H, D, 3).items():
        g.node(name, g.mesh(name, quads, BLUE if name == "wall_z1" else WHITE))
    for i, (x, z, f) in enumerate([(1.2, 4.8, -1), (3.0, 5.0, -1), (4.8, 4.8, -1)]):
        g.node("chair%d" % i, g.mesh("chair%d" % i, chair(x, z, f), WOOD))
    for i, (x, z) in enumerate([(2.0, 2.0), (4.0, 2.0), (2.0, 4.0), (4.0, 4.0)]):
        g.node("light%d" % i, g.mesh("light%d" % i, light_quad(x, H - 0.002, z, 0.2), LIGHT))
    times = key_times(41)
    cube = g.mesh("cube", box(-0.15, -0.15, -0.15, 0.15, 0.15, 0.15), RED)
    for i in range(n):
        # Lissajous paths across the whole room, each cube its own phase and height.
        ph = 2 * math.pi * i / max(n, 1)
        y = 0.4 + 1.6 * ((i * 0.618) % 1.0)

        def pos(t, ph=ph, y=y, i=i):
            a = 2 * math.pi * t / DURATION
            return (3.0 + 2.4 * math.sin(a * (1 + i % 3) + ph), y,
                    3.0 + 2.4 * math.sin(a * (2 + i % 2) + 1.7 * ph))

        c = g.node("cube%d" % i, cube)
        g.animate(c, "translation", times, [pos(t) for t in times])
    cam = g.node("camera", camera=g.camera(1.0))
    eye = (0.3, 2.2, 0.3)
    g.nodes[cam]["translation"] = list(eye)
    g.nodes[cam]["rotation"] = list(quat_look(eye, (3.6, 0.8, 3.6)))
    return g


def cubic_scene():
    g = Gltf("cubic")
    C, H, T = 3.0, 2.6, 0.1  # cell size, height, wall thickness; 3 x 3 cells
    W = 3 * C
    for name, quads in room(W, H, W, 3).items():
        g.node(name, g.mesh(name, quads, WHITE))
    walls = []
    door = 1.0
    for k in (1, 2):
        for c in range(3):
            a0, a1 = c * C, (c + 1) * C
            m = (a0 + a1) / 2
            # walls along z at x = k*C and along x at z = k*C, each with a doorway in the middle
            walls += box(k * C - T / 2, 0, a0, k * C + T / 2, H, m - door / 2, bottom=False)
            walls += box(k * C - T / 2, 0, m + door / 2, k * C + T / 2, H, a1, bottom=False)
            walls += box(a0, 0, k * C - T / 2, m - door / 2, H, k * C + T / 2, bottom=False)
            walls += box(m + door / 2, 0, k * C - T / 2, a1, H, k * C + T / 2, bottom=False)
    g.node("walls", g.mesh("walls", walls, WHITE))
    for i in range(3):
        for j in range(3):
            g.node("light%d%d" % (i, j),
                   g.mesh("light%d%d" % (i, j),
                          light_quad((i + 0.5) * C, H - 0.002, (j + 0.5) * C, 0.2), LIGHT))
    # The box tours the cells through the doorways: a closed path of cell centres.
    tour = [(0, 0), (1, 0), (2, 0), (2, 1), (1, 1), (0, 1), (0, 2), (1, 2), (2, 2), (2, 1),
            (1, 1), (1, 0), (0, 0)]
    pts = [((i + 0.5) * C, 0.5, (j + 0.5) * C) for i, j in tour]
    times = key_times(len(pts))
    obj = g.node("box", g.mesh("box", box(-0.25, -0.25, -0.25, 0.25, 0.25, 0.25), RED))
    g.animate(obj, "translation", times, pts)
    cam = g.node("camera", camera=g.camera(1.1))
    # Camera behind and above the box, in the same cell (it trails by a fraction of a segment).
    eyes, rots = [], []
    for k, p in enumerate(pts):
        prev = pts[k - 1] if k else pts[1]
        d = [p[0] - prev[0], p[2] - prev[2]]
        n = math.hypot(*d) or 1.0
        e = (p[0] - 1.2 * d[0] / n, 1.6, p[2] - 1.2 * d[1] / n)
        eyes.append(e)
        rots.append(quat_look(e, p))
    g.animate(cam, "translation", times, eyes)
    g.animate(cam, "rotation", times, rots)
    return g


def all_scenes():
    for lights in ("static", "dynamic"):
        for camera in ("static", "pan", "follow"):
            yield "table-%s-%s" % (lights, camera), lambda l=lights, c=camera: (table_scene(l, c), 30.0)
    for n in (1, 2, 4, 8, 16, 32):
        yield "cubes-%d" % n, lambda n=n: (cubes_scene(n), 30.0)
    yield "cubic", lambda: (cubic_scene(), 30.0)


def scene_set_main(prog, doc, scenes, argv=None):
    """The command line of a generator of named scenes: `PROG OUTDIR [NAME...]` writes
    OUTDIR/NAME.gltf for each wanted scene of `scenes` ((name, make) pairs, make() returning
    (Gltf, light strength)) and prints its path; exits 2 with one line on a usage error, 0
    after --help (which writes nothing)."""
    scenes = list(scenes)
    names = [name for name, _ in scenes]
    parser = argparse.ArgumentParser(
        prog=prog, description=doc.split("\n\n")[0], epilog="scenes: " + " ".join(names),
        formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("outdir", metavar="OUTDIR", help="folder to write NAME.gltf into")
    parser.add_argument("names", metavar="NAME", nargs="*", help="scenes to write (default: all)")
    args = parser.parse_args(sys.argv[1:] if argv is None else argv)
    # A folder named like an option is a typo for one (`--help` once became a folder).
    if args.outdir.startswith("-"):
        parser.error(f"OUTDIR {args.outdir!r} starts with '-'; write ./{args.outdir} to mean it")
    unknown = [n for n in args.names if n not in names]
    if unknown:
        parser.error("unknown scene " + ", ".join(unknown) + "; scenes: " + " ".join(names))
    os.makedirs(args.outdir, exist_ok=True)
    for name, make in scenes:
        if args.names and name not in args.names:
            continue
        g, strength = make()
        path = os.path.join(args.outdir, name + ".gltf")
        g.write(path, strength)
        print(path)


def main():
    scene_set_main("make_paper_scenes.py", __doc__, all_scenes())


if __name__ == "__main__":
    main()
