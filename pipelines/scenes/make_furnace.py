#!/usr/bin/env python3
"""Writes the furnace: a closed cube, 2 m on a side, whose six walls all emit L_e and reflect rho
(docs/design.md §8 "furnace through the whole pipeline"; the closed form is in
tests/data/reference/furnace.json). Every wall's radiance is then exactly

    L = L_e / (1 - rho)

everywhere, whatever the discretisation, so the frames' mean against that value measures how
well the pipeline conserves energy. The camera stands at the centre looking at a corner (three
walls in view, and their edges, where form factors are hardest); the scene is static, so it has
one frame.

usage: make_furnace.py OUT.gltf RHO [--emission L_E] [--walls-split N] [--partition]
       (--walls-split N: each wall as N x N quads, so the first pass starts from more patches;
        --partition: a 10 cm slab standing from floor to ceiling, open at both ends as the cubic
        scene's partition walls are, so part of the floor and ceiling is covered by a solid.
        The closed form still holds on every surface that can be seen)

Only the Python standard library is used; the output is deterministic.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from make_paper_scenes import Gltf, box, quat_look  # noqa: E402


def walls(half, n):
    """The cube's six walls as n x n quads each, counter-clockwise seen from inside."""
    quads = []
    for axis in range(3):
        for side in (-1.0, 1.0):
            # The wall at coordinate `axis` = side * half, spanned by the other two axes, in the
            # order whose cross product points into the cube (towards -side along axis).
            a, b = (axis + 1) % 3, (axis + 2) % 3
            if side > 0:
                a, b = b, a
            def p(i, j):
                q = [0.0, 0.0, 0.0]
                q[axis] = side * half
                q[a] = -half + 2.0 * half * i / n
                q[b] = -half + 2.0 * half * j / n
                return tuple(q)
            for i in range(n):
                for j in range(n):
                    quads.append([p(i, j), p(i + 1, j), p(i + 1, j + 1), p(i, j + 1)])
    return quads


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("rho", type=float)
    ap.add_argument("--emission", type=float, default=0.5, help="L_e of every wall, W/m^2/sr")
    ap.add_argument("--walls-split", type=int, default=1)
    ap.add_argument("--partition", choices=["open", "closed", "floating"], nargs="?",
                    const="open", default=None)
    a = ap.parse_args()
    if not (0.0 <= a.rho < 1.0):
        sys.exit("make_furnace.py: rho %g: must be in [0, 1)" % a.rho)
    g = Gltf("furnace rho=%g" % a.rho)
    g.node("walls", mesh=g.mesh("walls", walls(1.0, max(1, a.walls_split)), 0))
    if a.partition:
        # Touches the floor and the ceiling, and leaves a 0.6 m door at the back (+z).
        y0, y1 = (-0.8, 0.8) if a.partition == "floating" else (-1.0, 1.0)
        faces = box(0.45, y0, -1.0, 0.55, y1, 0.4, bottom=a.partition != "open")
        if a.partition == "open":
            faces = faces[1:]  # no top either
        g.node("partition", mesh=g.mesh("partition", faces, 0))
    eye, corner = (0.0, 0.0, 0.0), (1.0, -1.0, 1.0)
    g.node("camera", camera=g.camera(yfov=1.2), translation=eye, rotation=quat_look(eye, corner))
    g.write(a.out, a.emission, materials=[("wall", (a.rho,) * 3, (1.0, 1.0, 1.0))])
    print("make_furnace.py: %s: rho %g, L_e %g, exact L = %.9g" %
          (a.out, a.rho, a.emission, a.emission / (1.0 - a.rho)), file=sys.stderr)


if __name__ == "__main__":
    main()
