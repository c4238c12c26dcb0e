#!/usr/bin/env python3
"""Writes the clutter scene of issue 58 as glTF 2.0: many small objects packed in three dimensions,
what fills rad-global's link bound on the RenderPark office graz (docs/results.md, "Which links
fill the link bound").

A closed white room lit by two ceiling panels, and in it a cabinet of SHELVES shelf boards, each
holding a row of BINDERS binders: a binder is a closed box 6 cm x 30 cm x 28 cm standing 2 mm
from the next, with a ring mechanism inside (a base plate and RINGS rings, each ring a loop of
small quads around a bent strip). The binders' small parts lie within a few of their own sizes
of hundreds of others, above, below and beside them, as graz's binders, keyboards and chairs do.

    make_clutter_scenes.py OUT.gltf [--shelves 4] [--binders 12] [--rings 2] [--segments 8]

Static: frame 0 is the whole animation. Only the standard library is used and the output is
deterministic.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_paper_scenes as M  # noqa: E402

W, H, D = 4.0, 2.6, 3.5  # the room
BINDER_W, BINDER_H, BINDER_D, BINDER_GAP = 0.06, 0.30, 0.28, 0.002
SHELF_PITCH, SHELF_T = 0.36, 0.02
WHITE, WOOD, BLUE, METAL, LIGHT = range(5)
MATERIALS = [
    ("white", (0.8, 0.8, 0.78), None),
    ("wood", (0.6, 0.44, 0.3), None),
    ("blue", (0.15, 0.25, 0.65), None),
    ("metal", (0.55, 0.55, 0.58), None),
    ("light", (0.0, 0.0, 0.0), (1.0, 0.97, 0.9)),
]


def ring(cx, cy, cz, radius, width, segments):
    """A ring of `segments` quads about the x axis through (cx, cy, cz): a bent strip `width`
    wide along x, facing outward."""
    quads = []
    for k in range(segments):
        a0, a1 = 2 * math.pi * k / segments, 2 * math.pi * (k + 1) / segments
        p = [(cy + radius * math.cos(a), cz + radius * math.sin(a)) for a in (a0, a1)]
        x0, x1 = cx - 0.5 * width, cx + 0.5 * width
        quads.append([(x0, p[0][0], p[0][1]), (x0, p[1][0], p[1][1]),
                      (x1, p[1][0], p[1][1]), (x1, p[0][0], p[0][1])])
    return quads


def binder(x0, y0, z0, rings, segments):
    """A binder's box (x0, y0, z0 its low corner) and its ring mechanism inside."""
    shell = M.box(x0, y0, z0, x0 + BINDER_W, y0 + BINDER_H, z0 + BINDER_D)
    cx = x0 + 0.5 * BINDER_W
    metal = M.box(cx - 0.01, y0 + 0.02, z0 + 0.04, cx + 0.01, y0 + 0.023, z0 + BINDER_D - 0.04)
    for k in range(rings):
        cz = z0 + BINDER_D * (k + 1) / (rings + 1)
        metal += ring(cx, y0 + 0.04, cz, 0.015, 0.004, segments)
    return shell, metal


def scene(shelves, binders, rings, segments):
    g = M.Gltf("clutter-%dx%d" % (shelves, binders))
    count = M.ceiling_lit_room(g, W, H, D, WHITE, LIGHT)
    width = binders * (BINDER_W + BINDER_GAP)
    x0, z0 = 0.5 * (W - width), D - BINDER_D - 0.02
    boards, shells, metal = [], [], []
    for s in range(shelves):
        y = 0.3 + s * SHELF_PITCH
        boards += M.box(x0 - 0.02, y - SHELF_T, z0 - 0.01, x0 + width + 0.02, y, D)
        for b in range(binders):
            shell, parts = binder(x0 + b * (BINDER_W + BINDER_GAP), y, z0, rings, segments)
            shells += shell
            metal += parts
    for name, quads, material in (("boards", boards, WOOD), ("binders", shells, BLUE),
                                  ("metal", metal, METAL)):
        count += g.split_mesh_nodes(name, quads, material)
    g.still_camera((2.0, 1.3, 0.4), (2.0, 0.9, D), yfov=1.0)
    return g, count


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--shelves", type=int, default=4)
    ap.add_argument("--binders", type=int, default=12, help="binders a shelf")
    ap.add_argument("--rings", type=int, default=2, help="rings a binder")
    ap.add_argument("--segments", type=int, default=8, help="quads a ring")
    a = ap.parse_args()
    if not (1 <= a.shelves <= 6 and 1 <= a.binders <= 60 and 0 <= a.rings <= 4
            and 3 <= a.segments <= 32):
        sys.exit("make_clutter_scenes.py: --shelves 1-6, --binders 1-60, --rings 0-4, "
                 "--segments 3-32")
    g, count = scene(a.shelves, a.binders, a.rings, a.segments)
    g.write(a.out, 12.0, MATERIALS)
    print("make_clutter_scenes.py: %s: %d triangles (%d shelves of %d binders)"
          % (a.out, count, a.shelves, a.binders), file=sys.stderr)


if __name__ == "__main__":
    main()
