#!/usr/bin/env python3
"""Writes a floor of furnished rooms of a chosen size as animated glTF 2.0 (issue 58's
million-triangle scene).

A corridor with rooms on both sides: classrooms (rows of desks and chairs, a teacher's desk,
shelves of books) to the north, offices (desks along the walls, a wall of shelves) to the
south; walls with doorways, ceiling light panels in every room and along the corridor. Each
piece of furniture, each light panel, a room's shell and a corridor segment is one glTF mesh
that many nodes share (glTF instancing): a room is a parent node that places its shell, its
furniture and its lights, so the file holds one copy of each mesh whatever the floor's size,
as a user's exported building does. The radiosity still needs every instance's patches in the
world, so the triangle count is that of the instances. The space car flies along the corridor;
the camera walks out of the first classroom into the corridor and looks into the office across
it. The animation lasts 4 s: 96 frames at 24 fps.

    make_floor.py OUT.gltf --triangles 100000

The floor grows by pitches (a classroom, an office and the corridor segment between them, about
20k triangles); the walls' tessellation is then set so the count meets the request to within
a few per cent (the exact figure goes to stderr). Only the standard library is used and the
output is deterministic.
"""
import argparse
import base64
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_paper_scenes as M  # noqa: E402

ROOM_W, ROOM_D, HEIGHT = 7.0, 6.0, 3.0  # a room's width along the corridor, depth, height
WALL = 0.1  # wall thickness between rooms and between a room and the corridor
CORRIDOR = 2.4
PITCH = ROOM_W + WALL
DOOR_X, DOOR_W, DOOR_H = 1.0, 1.0, 2.1  # a room's doorway, along its corridor wall
PITCH_TRIANGLES = 20000
DURATION = 4.0
BOOK = 6  # material index of the books (appended to the paper scenes' materials)
MATERIALS = M.MATERIALS + [("books", (0.6, 0.15, 0.12), None)]


def tri_count(quads):
    return sum(2 if len(q) == 4 else 1 for q in quads)


def lines(length, cell, cuts=()):
    """Grid lines over [0, length]: about `cell` apart, plus the cuts (doorway edges)."""
    n = max(1, int(round(length / cell)))
    pts = {round(length * i / n, 9) for i in range(n + 1)} | {round(c, 9) for c in cuts}
    return sorted(pts)


def wall(origin, du, dv, us, vs, hole=None):
    """Quads between grid lines us (along unit du) and vs (along dv) from origin; front =
    du x dv. hole: (u0, u1, v0, v1), the cells inside it are left out (a doorway)."""
    out = []
    for i in range(len(us) - 1):
        for j in range(len(vs) - 1):
            if hole and us[i] >= hole[0] and us[i + 1] <= hole[1] and \
                    vs[j] >= hole[2] and vs[j + 1] <= hole[3]:
                continue
            out.append([tuple(origin[k] + du[k] * u + dv[k] * v for k in range(3))
                        for u, v in ((us[i], vs[j]), (us[i + 1], vs[j]), (us[i + 1], vs[j + 1]),
                                     (us[i], vs[j + 1]))])
    return out


X, Y, Z = (1, 0, 0), (0, 1, 0), (0, 0, 1)


def room_shell(cell):
    """A room [0,W] x [0,H] x [0,D], inward-facing, its doorway in the wall z = 0."""
    W, H, D = ROOM_W, HEIGHT, ROOM_D
    door = (DOOR_X, DOOR_X + DOOR_W, 0.0, DOOR_H)
    q = wall((0, 0, 0), Z, X, lines(D, cell), lines(W, cell))  # floor, +y
    q += wall((0, H, 0), X, Z, lines(W, cell), lines(D, cell))  # ceiling, -y
    q += wall((0, 0, 0), X, Y, lines(W, cell, door[:2]), lines(H, cell, door[3:]), door)
    q += wall((0, 0, D), Y, X, lines(H, cell), lines(W, cell))  # back wall, -z
    q += wall((0, 0, 0), Y, Z, lines(H, cell), lines(D, cell))  # +x
    q += wall((W, 0, 0), Z, Y, lines(D, cell), lines(H, cell))  # -x
    return q


def corridor_segment(cell):
    """One pitch of the corridor, x in [0, PITCH], z in [0, CORRIDOR]: floor, ceiling, the
    south wall (z = 0, the office's doorway) and the north wall (z = CORRIDOR, the
    classroom's), with the doorways' jambs and thresholds across the wall thickness."""
    L, H, C = PITCH, HEIGHT, CORRIDOR
    north = (DOOR_X, DOOR_X + DOOR_W)
    south = (ROOM_W - DOOR_X - DOOR_W, ROOM_W - DOOR_X)  # the office is turned half round
    q = wall((0, 0, 0), Z, X, lines(C, cell), lines(L, cell))
    q += wall((0, H, 0), X, Z, lines(L, cell), lines(C, cell))
    q += wall((0, 0, 0), X, Y, lines(L, cell, south), lines(H, cell, [DOOR_H]),
              south + (0.0, DOOR_H))
    q += wall((0, 0, C), Y, X, lines(H, cell, [DOOR_H]), lines(L, cell, north),
              (0.0, DOOR_H) + north)
    for (a, b), z0, z1 in ((north, C, C + WALL), (south, -WALL, 0.0)):
        q.append([(a, 0, z1), (a, 0, z0), (a, DOOR_H, z0), (a, DOOR_H, z1)])  # faces +x
        q.append([(b, 0, z0), (b, 0, z1), (b, DOOR_H, z1), (b, DOOR_H, z0)])  # faces -x
        q.append([(a, DOOR_H, z0), (b, DOOR_H, z0), (b, DOOR_H, z1), (a, DOOR_H, z1)])  # -y
        q.append([(a, 0, z0), (a, 0, z1), (b, 0, z1), (b, 0, z0)])  # the threshold, +y
    return q


def corridor_end(facing):
    """The corridor's end wall at x = 0 (facing +1, faces +x) or at x = 0 facing -x."""
    us, vs = lines(HEIGHT, 0.5), lines(CORRIDOR, 0.5)
    return wall((0, 0, 0), Y, Z, us, vs) if facing > 0 else wall((0, 0, 0), Z, Y, vs, us)


def subdivided_box(x0, y0, z0, x1, y1, z1, n=1, bottom=True):
    """M.box with its top face an n x n grid (a desk top that shadows resolve on)."""
    q = M.box(x0, y0, z0, x1, y1, z1, bottom)
    top = q[0]
    return wall(top[0], Z, X, lines(z1 - z0, (z1 - z0) / n), lines(x1 - x0, (x1 - x0) / n)) \
        + q[1:]


def leg(cx, cz, r, h, sides=8):
    """A round leg: a prism of `sides` quads from y = 0 to h, faces outwards."""
    q = []
    for k in range(sides):
        a0, a1 = 2 * math.pi * k / sides, 2 * math.pi * (k + 1) / sides
        p0 = (cx + r * math.cos(a0), cz - r * math.sin(a0))
        p1 = (cx + r * math.cos(a1), cz - r * math.sin(a1))
        q.append([(p0[0], 0.0, p0[1]), (p1[0], 0.0, p1[1]), (p1[0], h, p1[1]), (p0[0], h, p0[1])])
    return q


def desk():
    """1.2 x 0.6 m, 0.75 m high, centred; the user sits at +z facing -z."""
    q = subdivided_box(-0.6, 0.72, -0.3, 0.6, 0.75, 0.3, n=4)
    for sx in (-1, 1):
        for sz in (-1, 1):
            q += leg(sx * 0.54, sz * 0.24, 0.025, 0.72)
    q += M.box(-0.55, 0.35, -0.29, 0.55, 0.70, -0.27)  # modesty panel
    return q


def chair():
    """Seat 0.44 m square, the back at +z: a user faces -z."""
    q = M.box(-0.22, 0.42, -0.22, 0.22, 0.46, 0.22)
    for sx in (-1, 1):
        for sz in (-1, 1):
            q += leg(sx * 0.19, sz * 0.19, 0.018, 0.42, 6)
    q += M.box(-0.22, 0.46, 0.18, 0.22, 0.92, 0.22)
    return q


def shelf():
    """(wood quads, book quads): 1.0 m wide, 0.35 deep, 2.0 high, open towards +z, backed at
    z = 0; four boards of books."""
    wood = M.box(-0.5, 0.0, 0.0, -0.48, 2.0, 0.35) + M.box(0.48, 0.0, 0.0, 0.5, 2.0, 0.35)
    wood += M.box(-0.48, 0.0, 0.0, 0.48, 2.0, 0.02)
    books = []
    for b in range(5):
        y = 0.05 + b * 0.45
        wood += M.box(-0.48, y, 0.02, 0.48, y + 0.02, 0.35)
        if b == 4:
            break
        x = -0.46
        for k in range(14):  # books of varying widths and heights
            w, h = 0.04 + 0.01 * (k % 3), 0.24 + 0.03 * ((k * 7) % 4)
            books += M.box(x, y + 0.02, 0.04, x + w, y + 0.02 + h, 0.30, bottom=False)
            x += w + 0.015
    return wood, books


def furniture_triangles():
    wood, books = shelf()
    return {"desk": tri_count(desk()), "chair": tri_count(chair()),
            "shelf": tri_count(wood) + tri_count(books), "light": 2}


def classroom_layout():
    """(kind, x, z, yaw) in the room's frame: students face the back wall (+z)."""
    out = []
    for r in range(4):
        for c in range(4):
            x, z = 1.3 + c * 1.5, 1.7 + r * 1.05
            out += [("desk", x, z, math.pi), ("chair", x, z - 0.5, math.pi)]
    out += [("desk", ROOM_W / 2, ROOM_D - 1.0, 0.0), ("chair", ROOM_W / 2, ROOM_D - 0.5, 0.0)]
    out += [("shelf", 0.02, z, math.pi / 2) for z in (2.4, 3.6)]  # against x = 0, open to +x
    out += [("light", x, z, 0.0) for x in (1.75, 5.25) for z in (1.5, 4.5)]
    return out


def office_layout():
    out = []
    for side, x in ((1, 0.35), (-1, ROOM_W - 0.35)):
        for z in (1.4, 2.8, 4.2):  # desks against the side walls, users face the wall
            yaw = side * math.pi / 2
            out += [("desk", x, z, yaw), ("chair", x + side * 0.55, z, yaw)]
    out += [("shelf", 1.0 + 1.25 * k, ROOM_D - 0.02, math.pi) for k in range(5)]
    out += [("light", x, z, 0.0) for x in (1.75, 5.25) for z in (1.5, 4.5)]
    return out


def triangles_for(pitches, cell):
    f = furniture_triangles()
    room = tri_count(room_shell(cell))
    per_pitch = 2 * room + tri_count(corridor_segment(cell)) + 2 * f["light"] + \
        sum(f[k] for k, *_ in classroom_layout() + office_layout())
    return pitches * per_pitch + 2 * tri_count(corridor_end(1)) + tri_count(M.space_car())


def plan(target):
    """(pitches, wall cell size) whose triangle count is nearest the target."""
    pitches = max(1, int(round(target / PITCH_TRIANGLES)))
    cells = [0.12 * 1.05 ** k for k in range(60)]
    cell = min(cells, key=lambda c: abs(triangles_for(pitches, c) - target))
    return pitches, cell


class Floor(M.Gltf):
    """M.Gltf with parent nodes: only the roots are listed in the scene."""

    def __init__(self, name):
        super().__init__(name)
        self.roots = []

    def child(self, parent, name, mesh, translation, yaw):
        n = self.node(name, mesh, translation=translation, rotation=M.quat_y(yaw))
        self.nodes[parent].setdefault("children", []).append(n)
        return n

    def write(self, path, light_strength, materials=None):
        super().write(path, light_strength, materials)
        with open(path) as f:
            g = json.load(f)
        g["scenes"][0]["nodes"] = self.roots
        with open(path, "w") as f:
            json.dump(g, f, indent=1)
            f.write("\n")


def build(target):
    pitches, cell = plan(target)
    g = Floor("floor-%d" % target)
    wood, books = shelf()
    mesh = {"desk": g.mesh("desk", desk(), M.WOOD), "chair": g.mesh("chair", chair(), M.BLUE),
            "light": g.mesh("light_panel", M.light_quad(0, 0, 0, 0.3), M.LIGHT)}
    shelf_wood, shelf_books = g.mesh("shelf", wood, M.WOOD), g.mesh("books", books, BOOK)
    room = g.mesh("room_shell", room_shell(cell), M.WHITE)
    segment = g.mesh("corridor_segment", corridor_segment(cell), M.WHITE)

    def furnish(parent, prefix, layout):
        for i, (kind, x, z, yaw) in enumerate(layout):
            name = "%s_%s%d" % (prefix, kind, i)
            if kind == "shelf":
                g.child(parent, name, shelf_wood, (x, 0.0, z), yaw)
                g.child(parent, name + "_books", shelf_books, (x, 0.0, z), yaw)
            elif kind == "light":
                g.child(parent, name, mesh["light"], (x, HEIGHT - 0.002, z), yaw)
            else:
                g.child(parent, name, mesh[kind], (x, 0.0, z), yaw)

    for p in range(pitches):
        x0 = p * PITCH
        seg = g.node("corridor%d" % p, segment, translation=(x0, 0.0, 0.0))
        g.roots.append(seg)
        for k, x in enumerate((1.8, 5.3)):
            g.child(seg, "corridor%d_light%d" % (p, k), mesh["light"],
                    (x, HEIGHT - 0.002, CORRIDOR / 2), 0.0)
        north = g.node("classroom%d" % p, translation=(x0, 0.0, CORRIDOR + WALL))
        south = g.node("office%d" % p, translation=(x0 + ROOM_W, 0.0, -WALL),
                       rotation=M.quat_y(math.pi))
        g.roots += [north, south]
        for parent, prefix, layout in ((north, "classroom%d" % p, classroom_layout()),
                                       (south, "office%d" % p, office_layout())):
            g.child(parent, prefix + "_shell", room, (0.0, 0.0, 0.0), 0.0)
            furnish(parent, prefix, layout)
    length = pitches * PITCH
    g.roots.append(g.node("corridor_end0", g.mesh("corridor_end0", corridor_end(1), M.WHITE)))
    g.roots.append(g.node("corridor_end1", g.mesh("corridor_end1", corridor_end(-1), M.WHITE),
                          translation=(length, 0.0, 0.0)))
    animate(g, length)
    return g, triangles_for(pitches, cell), pitches, cell


def animate(g, length):
    times = [DURATION * i / 32 for i in range(33)]
    reach = min(length - 0.6, 2 * PITCH - 0.6)

    def car_pos(t):  # along the corridor and back, 1.4 m up
        a = 2 * math.pi * t / DURATION
        return (0.6 + (reach - 0.6) * 0.5 * (1 - math.cos(a)), 1.4,
                CORRIDOR / 2 + 0.4 * math.sin(a))

    car = g.node("space_car", g.mesh("space_car", M.space_car(), M.CAR))
    g.roots.append(car)
    g.animate(car, "translation", times, [car_pos(t) for t in times])
    g.animate(car, "rotation", times,
              [M.quat_y(0.0 if math.sin(2 * math.pi * t / DURATION) >= 0 else math.pi)
               for t in times])
    # The camera: from the back of the first classroom to its doorway, into the corridor, and
    # to the office's doorway across it, looking in.
    door_n = (DOOR_X + DOOR_W / 2, CORRIDOR + WALL)
    door_s = (ROOM_W - DOOR_X - DOOR_W / 2, -WALL)
    path = [(0.0, (4.5, 1.6, CORRIDOR + WALL + 4.8), (door_n[0], 1.1, door_n[1])),
            (1.4, (door_n[0] + 0.2, 1.6, door_n[1] + 0.9), (door_n[0], 1.2, CORRIDOR / 2)),
            (2.2, (door_n[0] + 0.3, 1.6, CORRIDOR / 2 + 0.3), (car_pos(2.2)[0], 1.3, 1.0)),
            (3.2, (door_s[0], 1.6, CORRIDOR / 2), (door_s[0], 1.0, -ROOM_D / 2)),
            (DURATION, (door_s[0], 1.6, 0.35), (door_s[0] + 1.0, 0.9, -ROOM_D + 1.0))]

    def along(t, k):
        for (t0, *a), (t1, *b) in zip(path, path[1:]):
            if t <= t1:
                s = (t - t0) / (t1 - t0)
                s = s * s * (3 - 2 * s)
                return tuple(a[k][i] + (b[k][i] - a[k][i]) * s for i in range(3))
        return path[-1][k + 1]

    cam = g.node("camera", camera=g.camera(1.0))
    g.roots.append(cam)
    g.animate(cam, "translation", times, [along(t, 0) for t in times])
    g.animate(cam, "rotation", times, [M.quat_look(along(t, 0), along(t, 1)) for t in times])


def write(g, path):
    """The file, atomically."""
    tmp = path + ".tmp"
    g.write(tmp, 30.0, MATERIALS)
    os.replace(tmp, path)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--triangles", type=int, default=100000)
    a = ap.parse_args()
    if a.triangles < 5000:
        sys.exit("make_floor.py: --triangles %d: at least 5000" % a.triangles)
    g, count, pitches, cell = build(a.triangles)
    write(g, a.out)
    print("make_floor.py: %s: %d triangles (%d classrooms, %d offices, walls in %.2f m cells, "
          "%d nodes, %d meshes)" % (a.out, count, pitches, pitches, cell, len(g.nodes),
                                    len(g.meshes)), file=sys.stderr)


if __name__ == "__main__":
    main()
