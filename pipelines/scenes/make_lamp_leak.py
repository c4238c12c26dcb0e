#!/usr/bin/env python3
"""Writes two rooms, one above the other, parted by a thin solid slab, the lower one lit by a
point lamp and a spot that nearly touch the slab: issue 57's light-leak case.

The lower room is [0,4] x [0,2] x [0,4] (walls and floor facing in); the slab is a closed box
(faces out) from y = 2 to y = 2 + SLAB; the upper room's walls and ceiling (facing in) stand on
it up to y = 3 + SLAB. A point lamp of 10 cd hangs GAP under the slab at (1, 2 - GAP, 1); a spot
of 10 cd (cones 0.8 and 1.2 rad) shines down from GAP under the slab inside a recess: a 0.4 m
square pocket of four hanging boards (closed boxes, 1 cm thick, 0.1 m deep) around (3, 2, 2).
Nothing connects the rooms: every ray from the upper room to a lamp crosses the slab, so the
upper room must stay exactly black. A shadow ray shortened at the lamp's end by more than
GAP + SLAB (1.2 cm) lets the lamps' light through.

Cameras: "upper" looks over the upper room (its ceiling faces the lamps through the slab),
"lower" over the lit room (so a test can check the lamps do light).

usage: make_lamp_leak.py OUT.gltf
Only the Python standard library is used; the output is deterministic.
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_paper_scenes import Gltf, box, quat_look, room  # noqa: E402

SLAB, GAP, SIZE, HEIGHT = 0.01, 0.002, 4.0, 2.0
GREY = [("grey", (0.6, 0.6, 0.6), None)]


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else "lamp-leak.gltf"
    g = Gltf("lamp-leak")
    lower = room(SIZE, HEIGHT, SIZE, 1)
    for name in ("floor", "wall_z0", "wall_z1", "wall_x0", "wall_x1"):
        g.node("lower_" + name, g.mesh("lower_" + name, lower[name], 0))
    g.node("slab", g.mesh("slab", box(0, HEIGHT, 0, SIZE, HEIGHT + SLAB, SIZE), 0))
    upper = room(SIZE, 1.0, SIZE, 1)
    for name in ("ceiling", "wall_z0", "wall_z1", "wall_x0", "wall_x1"):
        g.node("upper_" + name, g.mesh("upper_" + name, upper[name], 0),
               translation=(0, HEIGHT + SLAB, 0))
    # The recess: four boards hanging from the slab around the spot.
    cx, cz, r, t, depth = 3.0, 2.0, 0.2, 0.01, 0.1
    y0 = HEIGHT - depth
    boards = [box(cx - r - t, y0, cz - r - t, cx + r + t, HEIGHT, cz - r),
              box(cx - r - t, y0, cz + r, cx + r + t, HEIGHT, cz + r + t),
              box(cx - r - t, y0, cz - r, cx - r, HEIGHT, cz + r),
              box(cx + r, y0, cz - r, cx + r + t, HEIGHT, cz + r)]
    for k, b in enumerate(boards):
        g.node("recess_%d" % k, g.mesh("recess_%d" % k, b, 0))
    down = (-0.7071067811865476, 0.0, 0.0, 0.7071067811865476)  # -Z local -> -Y world
    point = g.node("point_lamp", translation=(1.0, HEIGHT - GAP, 1.0))
    spot = g.node("spot_lamp", translation=(cx, HEIGHT - GAP, cz), rotation=down)
    cam = g.camera(1.2)
    g.node("upper", camera=cam, translation=(0.3, 2.8 + SLAB, 0.3),
           rotation=quat_look((0.3, 2.8 + SLAB, 0.3), (3.0, 2.3, 3.0)))
    g.node("lower", camera=cam, translation=(0.3, 1.6, 3.7),
           rotation=quat_look((0.3, 1.6, 3.7), (2.5, 0.6, 1.2)))
    g.write(out, 1.0, GREY)
    with open(out) as f:
        gltf = json.load(f)
    gltf["extensionsUsed"] = ["KHR_lights_punctual"]
    gltf["extensionsRequired"] = ["KHR_lights_punctual"]
    gltf["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"name": "point", "type": "point", "color": [1.0, 1.0, 1.0], "intensity": 10.0},
        {"name": "spot", "type": "spot", "color": [1.0, 1.0, 1.0], "intensity": 10.0,
         "spot": {"innerConeAngle": 0.8, "outerConeAngle": 1.2}}]}}
    gltf["nodes"][point]["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    gltf["nodes"][spot]["extensions"] = {"KHR_lights_punctual": {"light": 1}}
    with open(out, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
