#!/usr/bin/env python3
"""Builds a second furnished room lit by Blender's three lamp types and exports it with Blender's
own glTF exporter: issue 57's held-out scene.

Held out: the toolchain is not tuned on it (docs/conventions.md §8). `make -f pipelines/bench.mk
lights` builds it, renders it through the pipeline and compares the frame with Blender's own
Cycles render of the same frame (pipelines/lights.py). It differs from make_blender_lamp_room.py
in every part a user would choose: a 5 x 3.6 x 2.8 m study of boxes (floor, ceiling, four
walls, a window 1.6 m wide in the left wall), a desk, a bookshelf against the back wall, a low
sofa block and a rug; a warm 40 W point lamp 0.5 m under the ceiling near the back-right
corner, a cool 90 W spot (60 degrees, blend 0.5) tilted onto the desk from the front wall, and
a 3 W/m^2 sun from the left through the window. Lamps are punctual: radius 0 (point, spot) and
angle 0 (sun). Materials are Principled BSDFs of roughness 1 and specular 0 whose base colour
is the reflectance the toolchain reads; Blender marks them double-sided. Nothing moves.

The export is Blender's exporter at its defaults (glTF "Standard" lighting mode) except for
export_cameras and export_lights on (both off by default), one embedded .gltf file.

usage: blender -b --factory-startup -P make_blender_lamp_study.py -- OUT.gltf

The render size is 352x240 (the exported camera's aspectRatio); 24 frames at 24 fps.
"""
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_room_kit as kit  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = argv[0] if argv else "lamp-study.gltf"

kit.new_scene(23)
box, lamp = kit.box, kit.lamp

WALL = ("plaster", (0.62, 0.66, 0.6))
W, D, H, T = 5.0, 3.6, 2.8, 0.12  # width (x), depth (y), height (z), wall thickness
box("floor", (0, 0, -T / 2), (W + 2 * T, D + 2 * T, T), ("oak", (0.5, 0.38, 0.22)))
box("ceiling", (0, 0, H + T / 2), (W + 2 * T, D + 2 * T, T), ("ceiling", (0.85, 0.83, 0.78)))
box("wall-right", (W / 2 + T / 2, 0, H / 2), (T, D, H), WALL)
box("wall-back", (0, D / 2 + T / 2, H / 2), (W, T, H), WALL)
box("wall-front", (0, -D / 2 - T / 2, H / 2), (W, T, H), WALL)
# The left wall (x = -W/2) with a window 1.6 m wide, 0.9 to 2.3 m high.
box("left-a", (-W / 2 - T / 2, -1.2, H / 2), (T, 1.2, H), WALL)
box("left-b", (-W / 2 - T / 2, 1.2, H / 2), (T, 1.2, H), WALL)
box("left-sill", (-W / 2 - T / 2, 0, 0.45), (T, 1.2, 0.9), WALL)
box("left-lintel", (-W / 2 - T / 2, 0, 2.55), (T, 1.2, 0.5), WALL)
DESK = ("walnut", (0.35, 0.22, 0.12))
box("desk-top", (-0.9, -0.9, 0.75), (1.4, 0.7, 0.04), DESK)
box("desk-side-a", (-1.57, -0.9, 0.365), (0.04, 0.66, 0.73), DESK)
box("desk-side-b", (-0.23, -0.9, 0.365), (0.04, 0.66, 0.73), DESK)
SHELF = ("shelf", (0.75, 0.72, 0.65))
box("shelf-back", (0.9, 1.7, 1.0), (1.8, 0.04, 2.0), SHELF)
for k, z in enumerate((0.02, 0.5, 1.0, 1.5, 1.98)):
    box("shelf-board-%d" % k, (0.9, 1.5, z), (1.8, 0.36, 0.04), SHELF)
box("books", (0.5, 1.52, 0.66), (0.7, 0.26, 0.28), ("books", (0.55, 0.12, 0.1)))
box("sofa-base", (1.6, -0.7, 0.22), (0.9, 1.8, 0.44), ("sofa", (0.18, 0.3, 0.22)))
box("sofa-back", (2.2, -0.7, 0.55), (0.25, 1.8, 0.5), ("sofa", (0.18, 0.3, 0.22)))
box("rug", (0.5, -0.2, 0.005), (1.6, 1.2, 0.01), ("rug", (0.6, 0.5, 0.35)))


lamp("corner-lamp", "POINT", 40.0, (1.7, 1.0, H - 0.5), colour=(1.0, 0.85, 0.65))
# The spot hangs by the front wall, tilted 25 degrees from the vertical toward the desk (+Y).
spot = lamp("desk-spot", "SPOT", 90.0, (-0.9, -1.6, 2.2), (math.radians(25.0), 0.0, 0.0),
            colour=(0.75, 0.85, 1.0))
spot.spot_size = math.radians(60.0)
spot.spot_blend = 0.5
# The sun: 3 W/m^2 from the left, 40 degrees above the horizon, in through the window (+X, -Z).
lamp("sun", "SUN", 3.0, (-4, 0, 3), (0.0, math.radians(-50.0), 0.0), colour=(1.0, 0.96, 0.9))

kit.camera(55.0, (2.1, -1.55, 1.6), (75.0, 0.0, 62.0))

kit.export(out)
