#!/usr/bin/env python3
"""make_floor.py (issue 58's floor of furnished rooms) at a small size: the file has the
triangle count asked for to within 10 %, holds each mesh once for many nodes (glTF instancing:
the file does not grow with the rooms, the triangles do), and rad-inspect reads it with the
generator's triangle count, a light per panel and the 96 frames of its 4 s animation.

usage: make_floor_test.py BIN_DIR OUT_DIR
"""
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
GENERATOR = os.path.join(HERE, "..", "..", "pipelines", "scenes", "make_floor.py")


def make(out, triangles):
    path = os.path.join(out, "floor-%d.gltf" % triangles)
    made = subprocess.run([sys.executable, GENERATOR, path, "--triangles", str(triangles)],
                          check=True, capture_output=True, text=True)
    return path, int(made.stderr.split(":")[2].split()[0])


def main():
    bin_dir, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    bad = []
    small, small_count = make(out, 10000)
    large, large_count = make(out, 60000)
    for request, count in ((10000, small_count), (60000, large_count)):
        if abs(count / request - 1) > 0.1:
            bad.append("%d triangles asked, %d made" % (request, count))
    with open(small) as f:
        g = json.load(f)
    if len(g["nodes"]) < 5 * len(g["meshes"]):
        bad.append("%d meshes for %d nodes: not instanced" % (len(g["meshes"]), len(g["nodes"])))
    # Six times the triangles, the same meshes: the buffer grows only with the wall cells.
    if os.path.getsize(large) > 8 * os.path.getsize(small):
        bad.append("the file grows with the rooms: %d bytes at 60k, %d at 10k" % (
            os.path.getsize(large), os.path.getsize(small)))
    inspect = subprocess.run([os.path.join(bin_dir, "rad-inspect"), small, "--json"],
                             check=True, capture_output=True, text=True)
    info = json.loads(inspect.stdout)
    if info["triangles"] != small_count:
        bad.append("rad-inspect reads %d triangles, the generator made %d" % (
            info["triangles"], small_count))
    panels = sum(1 for n in g["nodes"] if "_light" in n["name"])
    if len(info["emitters"]) != panels:
        bad.append("%d emitters for %d light panels" % (len(info["emitters"]), panels))
    frames = subprocess.run([os.path.join(bin_dir, "rad-inspect"), "--default-frames", small],
                            check=True, capture_output=True, text=True).stdout.strip()
    if frames != "0-95":
        bad.append("default frames %s, expected 0-95" % frames)
    for b in bad:
        print("make_floor_test.py: %s" % b, file=sys.stderr)
    sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
