#!/usr/bin/env python3
"""Writes the contact scene of issue 58 as glTF 2.0: what real furniture is made of, and what the
refinement ran away on in the RenderPark office (docs/results.md, "A corpus of public scenes").

A closed white room lit by two ceiling panels, and against its back wall a shelf of COLS x ROWS
cubbies. Each cubby is its own unit of five boards (bottom, top, two sides, back), and each board
is a closed box 1 cm thick, so

  * boards touch face to face: a cubby's side board against its neighbour's (no gap) and a cubby's
    bottom board on the top board of the cubby below (--gap, 20 micrometres by default: the
    office's boards are that far apart, a rounding of its coordinates);
  * a strip lies on a face: a 2 mm lip along the front of every bottom board, and a label (a
    quad of no thickness, facing up) lying on it;
  * two coplanar quads face opposite ways and overlap: a partition of no thickness made of two
    one-sided quads back to back, the one half shifted against the other;
  * a box rests on the floor, and a book (a box) stands in every cubby.

Most pairs of boards cannot see each other (a board is between), and their bounding spheres are
near each other: the configuration where rad-global's cluster links had refined every such pair
down to top-level patches.

    make_contact_scenes.py OUT.gltf [--cols 6] [--rows 4] [--gap 2e-5] [--turn 0]

--turn DEG turns the shelf about the vertical by DEG degrees: its coplanar faces are then coplanar
only to single precision, as in a converted scene. Static: frame 0 is the whole animation. Only the
standard library is used and the output is deterministic.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_paper_scenes as M  # noqa: E402

W, H, D = 4.0, 2.6, 3.5  # the room
CUBBY, DEPTH, BOARD = 0.36, 0.35, 0.01  # a cubby's outer width and height, depth, board
WHITE, WOOD, RED, BLUE, LIGHT = range(5)
MATERIALS = [
    ("white", (0.8, 0.8, 0.78), None),
    ("wood", (0.6, 0.44, 0.3), None),
    ("red", (0.7, 0.12, 0.1), None),
    ("blue", (0.15, 0.25, 0.65), None),
    ("light", (0.0, 0.0, 0.0), (1.0, 0.97, 0.9)),
]


def cubby(x0, y0, z0):
    """The five boards of a cubby whose outer box starts at (x0, y0, z0) (the back at z0)."""
    x1, y1, z1, t = x0 + CUBBY, y0 + CUBBY, z0 + DEPTH, BOARD
    return (M.box(x0, y0, z0 + t, x1, y0 + t, z1) +  # bottom
            M.box(x0, y1 - t, z0 + t, x1, y1, z1) +  # top
            M.box(x0, y0 + t, z0 + t, x0 + t, y1 - t, z1) +  # left side
            M.box(x1 - t, y0 + t, z0 + t, x1, y1 - t, z1) +  # right side
            M.box(x0, y0, z0, x1, y1, z0 + t))  # back


def lip_and_label(x0, y0, z0):
    """A 2 mm lip lying along the front of a cubby's bottom board, and a label of no thickness
    lying on the board's top face, facing up."""
    t, x1, z1 = BOARD, x0 + CUBBY, z0 + DEPTH
    lip = M.box(x0 + t, y0 + t, z1 - 0.02, x1 - t, y0 + t + 0.002, z1)
    y = y0 + t
    label = [[(x0 + 0.1, y, z1 - 0.12), (x0 + 0.1, y, z1 - 0.05), (x0 + 0.2, y, z1 - 0.05),
              (x0 + 0.2, y, z1 - 0.12)]]
    return lip, label


def book(x0, y0, z0, k):
    t = BOARD
    w = 0.03 + 0.01 * (k % 3)
    bx = x0 + t + 0.05 + 0.07 * (k % 4)
    return M.box(bx, y0 + t, z0 + t + 0.05, bx + w, y0 + t + 0.22 + 0.02 * (k % 5), z0 + DEPTH - 0.04)


def partition():
    """Two one-sided quads of no thickness back to back on the plane x = 0.7, the second shifted
    by half its width along z: they overlap on half of each."""
    x, y0, y1 = 0.7, 0.0, 1.2
    a = [(x, y0, 0.8), (x, y0, 1.6), (x, y1, 1.6), (x, y1, 0.8)]  # faces +x
    b = [(x, y0, 1.2), (x, y1, 1.2), (x, y1, 2.0), (x, y0, 2.0)]  # faces -x
    return [a, b]


def turned(quads, degrees, cx, cz):
    """The quads turned about the vertical through (cx, cz)."""
    c, s = math.cos(math.radians(degrees)), math.sin(math.radians(degrees))
    return [[(cx + c * (p[0] - cx) + s * (p[2] - cz), p[1], cz - s * (p[0] - cx) + c * (p[2] - cz))
             for p in q] for q in quads]


def scene(cols, rows, gap, turn):
    g = M.Gltf("contact-shelf-%dx%d" % (cols, rows))
    count = M.ceiling_lit_room(g, W, H, D, WHITE, LIGHT)
    # The shelf: its back against the back wall (z = D), cubbies facing -z; built facing +z at
    # z in [0, DEPTH] and placed by mirroring z.
    sx0 = 0.5 * (W - cols * CUBBY)
    boards, lips, labels, books = [], [], [], []
    for r in range(rows):
        y0 = r * (CUBBY + gap)
        for c in range(cols):
            x0 = sx0 + c * CUBBY
            boards += cubby(x0, y0, 0.0)
            lip, label = lip_and_label(x0, y0, 0.0)
            lips += lip
            labels += label
            books += book(x0, y0, 0.0, r * cols + c)

    def placed(quads):
        mirrored = [[(p[0], p[1], D - p[2]) for p in reversed(q)] for q in quads]
        return turned(mirrored, turn, 0.5 * W, D - 0.5 * DEPTH) if turn else mirrored

    for name, quads, material in (("boards", boards, WOOD), ("lips", lips, WOOD),
                                  ("labels", labels, WHITE), ("books", books, BLUE)):
        q = placed(quads)
        count += g.split_mesh_nodes(name, q, material)
    g.node("partition", g.mesh("partition", partition(), WHITE))
    box = M.box(2.6, 0.0, 1.0, 3.1, 0.45, 1.5)  # resting on the floor, its bottom on it
    g.node("box", g.mesh("box", box, RED))
    count += 2 * 2 + 2 * len(box)
    g.still_camera((2.0, 1.4, 0.3), (2.0, 0.75, D), yfov=1.0)
    return g, count


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--cols", type=int, default=6)
    ap.add_argument("--rows", type=int, default=4)
    ap.add_argument("--gap", type=float, default=2e-5,
                    help="between a cubby's bottom board and the top board of the one below (m)")
    ap.add_argument("--turn", type=float, default=0.0, help="turn the shelf by this many degrees")
    a = ap.parse_args()
    if not (1 <= a.cols <= 20 and 1 <= a.rows <= 6):
        sys.exit("make_contact_scenes.py: --cols 1-20 and --rows 1-6 (the room's size)")
    if not (0.0 <= a.gap <= 0.01):
        sys.exit("make_contact_scenes.py: --gap %g: expected 0 to 0.01 m" % a.gap)
    g, count = scene(a.cols, a.rows, a.gap, a.turn)
    g.write(a.out, 12.0, MATERIALS)
    print("make_contact_scenes.py: %s: %d triangles (%d x %d cubbies)" % (a.out, count, a.cols,
                                                                         a.rows), file=sys.stderr)


if __name__ == "__main__":
    main()
