#!/usr/bin/env python3
"""Writes a closed unit room built as Blender users build rooms: six slabs 0.1 m thick (closed
boxes, faces out; the floor's and ceiling's run under and over the walls), reflectance 0.5, a
point lamp of 1 cd at the centre, a camera inside. Issue 57's diagnosis of the lamp rooms'
indirect deficit (docs/results.md, "Lamps: leaks, fallback pixels, ..."): the pipeline against
rad-reference on this room with `double` (Blender's default export: every material
doubleSided) and with `single`.

usage: make_lamp_slab_box.py double|single OUT.gltf
Only the Python standard library is used; the output is deterministic.
"""
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_paper_scenes import Gltf, box, quat_look  # noqa: E402

T = 0.1
SLABS = [(-T, -T, -T, 1 + T, 0, 1 + T), (-T, 1, -T, 1 + T, 1 + T, 1 + T),
         (-T, 0, 0, 0, 1, 1), (1, 0, 0, 1 + T, 1, 1), (0, 0, -T, 1, 1, 0), (0, 0, 1, 1, 1, 1 + T)]


def main():
    if len(sys.argv) != 3 or sys.argv[1] not in ("double", "single"):
        sys.exit("usage: make_lamp_slab_box.py double|single OUT.gltf")
    out = sys.argv[2]
    g = Gltf("lamp-slab-box")
    for k, b in enumerate(SLABS):
        g.node("slab%d" % k, g.mesh("slab%d" % k, box(*b), 0))
    lamp = g.node("lamp", translation=(0.5, 0.5, 0.5))
    eye = (0.5, 0.5, 0.95)
    g.node("camera", camera=g.camera(1.4), translation=eye,
           rotation=quat_look(eye, (0.5, 0.45, 0.0)))
    g.write(out, 1.0, [("white", (0.5, 0.5, 0.5), None)])
    with open(out) as f:
        gltf = json.load(f)
    gltf["materials"][0]["doubleSided"] = sys.argv[1] == "double"
    gltf["extensionsUsed"] = ["KHR_lights_punctual"]
    gltf["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1.0}]}}
    gltf["nodes"][lamp]["extensions"] = {"KHR_lights_punctual": {"light": 0}}
    with open(out, "w") as f:
        json.dump(gltf, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
