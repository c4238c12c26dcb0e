#!/usr/bin/env python3
"""Builds a furnished room lit by Blender lamps and exports it with Blender's own glTF exporter.

Issue 57's test scene, as a Blender user makes it: a 4 x 3 x 2.6 m room of boxes (floor,
ceiling, three walls and a front wall with a wide opening), a table and a chair, a cube that
moves across the floor, and three lamp objects: a 60 W point lamp 30 cm under the ceiling, a
150 W spot (45 degrees, blend 0.3) over the table, and a sun of 4 W/m^2 shining in through the
opening. Lamps are punctual: radius 0 (point, spot) and angle 0 (sun), so Blender's own Cycles
render is the point-light render the toolchain makes. Materials are Principled BSDFs whose base
colour is what the toolchain reads (reflectance); Blender marks them double-sided.

The export is Blender's exporter at its defaults (glTF "Standard" lighting mode: a P W lamp is
P / (4 pi) x 683 cd, a sun of S W/m^2 is S x 683 lux) except for what the scene needs:
export_cameras and export_lights on (both off by default), one embedded .gltf file.

usage: blender -b --factory-startup -P make_blender_lamp_room.py -- OUT.gltf [--blend OUT.blend]

The render size is 352x240 (the exported camera's aspectRatio). The animation: 48 frames at 24 fps (2 s), the cube sliding 1.5 m along +X.
"""
import math
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_room_kit as kit  # noqa: E402

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
out = argv[0] if argv else "lamp-room.gltf"
blend = argv[argv.index("--blend") + 1] if "--blend" in argv else None

kit.new_scene(47)
box, lamp = kit.box, kit.lamp

WALL = ("wall", (0.7, 0.7, 0.68))
W, D, H, T = 4.0, 3.0, 2.6, 0.1  # width (x), depth (y), height (z), wall thickness
box("floor", (0, 0, -T / 2), (W + 2 * T, D + 2 * T, T), ("floor", (0.45, 0.35, 0.25)))
box("ceiling", (0, 0, H + T / 2), (W + 2 * T, D + 2 * T, T), ("ceiling", (0.8, 0.8, 0.8)))
box("wall-left", (-W / 2 - T / 2, 0, H / 2), (T, D, H), WALL)
box("wall-right", (W / 2 + T / 2, 0, H / 2), (T, D, H), WALL)
box("wall-back", (0, D / 2 + T / 2, H / 2), (W, T, H), WALL)
# The front wall (y = -D/2) with an opening 2 m wide, 0.8 to 2.2 m high.
box("front-left", (-1.5, -D / 2 - T / 2, H / 2), (1.0, T, H), WALL)
box("front-right", (1.5, -D / 2 - T / 2, H / 2), (1.0, T, H), WALL)
box("front-low", (0, -D / 2 - T / 2, 0.4), (2.0, T, 0.8), WALL)
box("front-high", (0, -D / 2 - T / 2, 2.4), (2.0, T, 0.4), WALL)
TABLE = ("table", (0.55, 0.3, 0.15))
box("table-top", (0.6, 0.6, 0.72), (1.2, 0.8, 0.05), TABLE)
for dx in (-0.55, 0.55):
    for dy in (-0.35, 0.35):
        box("table-leg", (0.6 + dx, 0.6 + dy, 0.35), (0.05, 0.05, 0.7), TABLE)
box("chair-seat", (-0.4, 0.5, 0.45), (0.45, 0.45, 0.05), ("chair", (0.2, 0.35, 0.5)))
box("chair-back", (-0.6, 0.5, 0.75), (0.05, 0.45, 0.6), ("chair", (0.2, 0.35, 0.5)))
cube = box("moving-cube", (-1.4, -0.6, 0.2), (0.4, 0.4, 0.4), ("cube", (0.7, 0.15, 0.1)))
cube.keyframe_insert("location", frame=0)
cube.location.x += 1.5
cube.keyframe_insert("location", frame=48)
for fc in cube.animation_data.action.fcurves:
    for k in fc.keyframe_points:
        k.interpolation = "LINEAR"


lamp("ceiling-lamp", "POINT", 60.0, (-0.8, -0.2, H - 0.3))
spot = lamp("table-spot", "SPOT", 150.0, (0.6, 0.6, 2.2))
spot.spot_size = math.radians(45.0)
spot.spot_blend = 0.3
# The sun: 4 W/m^2, 35 degrees below the horizon, shining in through the opening (+Y, -Z).
lamp("sun", "SUN", 4.0, (0, -3, 3), (math.radians(55.0), 0.0, math.radians(10.0)))

kit.camera(60.0, (1.7, -1.35, 1.9), (62.0, 0.0, 48.0))

if blend:
    bpy.ops.wm.save_as_mainfile(filepath=blend)
kit.export(out)
