#!/usr/bin/env python3
"""Writes a lecture hall of a chosen size as animated glTF 2.0 (issue 16's scale scenes).

Rows of desks and chairs (the paper's table and chair, 100 triangles a seat) in a room whose
walls are tessellated to make up the requested triangle count, a grid of ceiling lights (one
per 3 x 3 m), the paper's 16-polygon "space car" flying along the front row, and a camera that
follows it. With --moving-light one ceiling light travels along the hall. The hall grows with
the count (about 1.6 m^2 of floor a seat), so the number of lights and what each patch sees
grow too, as in a user's real rooms.

    make_hall.py OUT.gltf --triangles 10000 [--moving-light]

The count is met to within a seat's 100 triangles plus one wall row; the exact figure goes to
stderr. Only the standard library is used and the output is deterministic.
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_paper_scenes as M  # noqa: E402

SEAT_TRIANGLES = 100  # M.table (22 quads) + M.chair (28 quads)
PITCH_X, PITCH_Z = 1.6, 1.5  # desk spacing along a row, row spacing
HEIGHT = 3.0
LIGHT_SPACING = 3.0


def triangles(quads):
    return sum(2 if len(q) == 4 else 1 for q in quads)


def layout(target):
    """(seats per row, rows, wall grid n) whose total is close to target."""
    seats = max(1, int(round(0.8 * target / SEAT_TRIANGLES)))
    per_row = max(1, int(math.ceil(math.sqrt(seats * 1.4))))
    rows = max(1, int(math.ceil(seats / per_row)))
    w, d = per_row * PITCH_X + 2.0, rows * PITCH_Z + 3.0
    lights = int(math.ceil(w / LIGHT_SPACING)) * int(math.ceil(d / LIGHT_SPACING))
    rest = max(0, target - rows * per_row * SEAT_TRIANGLES - 2 * lights)
    n = max(1, int(round(math.sqrt(rest / 12.0))))  # room(): 6 walls of n x n quads
    return per_row, rows, n


def hall(target, moving_light):
    per_row, rows, n = layout(target)
    W, D, H = per_row * PITCH_X + 2.0, rows * PITCH_Z + 3.0, HEIGHT
    g = M.Gltf("hall-%d%s" % (target, "-moving-light" if moving_light else ""))
    count = 0
    for name, quads in M.room(W, H, D, n).items():
        g.node(name, g.mesh(name, quads, M.WHITE))
        count += triangles(quads)
    for r in range(rows):  # one mesh a row: fewer than 65536 vertices each
        z = 3.0 + r * PITCH_Z
        desks, chairs = [], []
        for s in range(per_row):
            x = 1.0 + (s + 0.5) * PITCH_X
            desks += M.table(x, z)
            chairs += M.chair(x, z + 0.65, -1)
        g.node("desks%d" % r, g.mesh("desks%d" % r, desks, M.WOOD))
        g.node("chairs%d" % r, g.mesh("chairs%d" % r, chairs, M.BLUE))
        count += triangles(desks) + triangles(chairs)
    nx, nz = int(math.ceil(W / LIGHT_SPACING)), int(math.ceil(D / LIGHT_SPACING))
    times = M.key_times(17)
    for i in range(nx):
        for j in range(nz):
            x, z = (i + 0.5) * W / nx, (j + 0.5) * D / nz
            name = "light%d_%d" % (i, j)
            node = g.node(name, g.mesh(name, M.light_quad(0, 0, 0, 0.25), M.LIGHT),
                          translation=(x, H - 0.002, z))
            count += 2
            if moving_light and i == 0 and j == 0:
                g.animate(node, "translation", times,
                          [(x + (W - 2 * x) * 0.5 * (1 - math.cos(2 * math.pi * t / M.DURATION)),
                            H - 0.002, z) for t in times])
    car = g.node("space_car", g.mesh("space_car", M.space_car(), M.CAR))
    count += triangles(M.space_car())
    car_times = M.key_times(33)

    def car_pos(t):  # along the front row and back, 1.3 m up
        a = 2 * math.pi * t / M.DURATION
        return (1.0 + (W - 2.0) * 0.5 * (1 - math.cos(a)), 1.3, 2.2 + 0.3 * math.sin(2 * a))

    g.animate(car, "translation", car_times, [car_pos(t) for t in car_times])
    g.animate(car, "rotation", car_times,
              [M.quat_y(0.0 if math.sin(2 * math.pi * t / M.DURATION) >= 0 else math.pi)
               for t in car_times])
    cam = g.node("camera", camera=g.camera(1.0))
    eyes = [(min(max(car_pos(t)[0] - 1.5, 0.4), W - 0.4), 2.2, 0.4) for t in car_times]
    g.animate(cam, "translation", car_times, eyes)
    g.animate(cam, "rotation", car_times,
              [M.quat_look(e, car_pos(t)) for e, t in zip(eyes, car_times)])
    return g, count, (per_row, rows, n, nx * nz, W, D)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("out")
    ap.add_argument("--triangles", type=int, default=10000)
    ap.add_argument("--moving-light", action="store_true")
    a = ap.parse_args()
    if a.triangles < 200:
        sys.exit("make_hall.py: --triangles %d: at least 200" % a.triangles)
    g, count, (per_row, rows, n, lights, W, D) = hall(a.triangles, a.moving_light)
    tmp = a.out + ".tmp"
    g.write(tmp, 30.0)
    os.replace(tmp, a.out)
    print("make_hall.py: %s: %d triangles (%d rows of %d seats, walls %dx%d, %d lights, "
          "%.1f x %.1f m)" % (a.out, count, rows, per_row, n, n, lights, W, D), file=sys.stderr)


if __name__ == "__main__":
    main()
