#!/usr/bin/env python3
"""docs/design.md §10's figure split into pixels at geometric edges and the rest (issue 56).

usage: edge_split.py TEST REF [--ref2 REF2] --items ITEMS [--emitter-margin PX] [--json]

TEST, REF, REF2: EXR frames (rad-compose, rad-reference, cycles_reference.py); ITEMS: the
frame's item buffer (rad-intervals --item-buffers DIR), whose Z channel places the edges. Its
ids name patch nodes at their movies' levels, so neighbouring ids differ inside a flat wall
too; the geometry is read from the depth instead. On a plane 1/Z is affine in the pixel
position, so its second difference across a pixel (along x, y and both diagonals) is zero
unless a plane changes there (a crease: wall against wall, box on floor) or the depth jumps (a
silhouette: one surface in front of another); such a pixel, and a surface pixel beside the
background, is an edge pixel. Edges come two pixels wide, one on each side.

Per class, over pixels that are not emitters (luminance above 10 x the median of the lit
reference pixels, rad-diff's rule, in the reference or in the test: Cycles' pixel-centre filter
spreads its samples 0.01 px, so now and then a pixel whose centre lies that close to a lamp's
outline takes part of the lamp, a few hundred times the wall's radiance, which alone would be
the whole figure; --emitter-margin 1 leaves out the pixels beside an emitter too, where that
happens): RMSE / mean and bias, channels pooled, each class normalised by
its own reference mean; with --ref2 the references' noise is removed as rad-diff does. The
classes: all (every pixel, background included: rad-diff's figure), interior (surface pixels
away from edges), edge, and the edge pixels split into silhouette and crease. A stand-in until
rad-diff splits its figures the same way.
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile

KINK = 1e-4  # relative second difference of 1/Z that marks a change of plane
JUMP = 0.02  # relative depth step between neighbours that marks a silhouette


def read_exr(path, channels):
    """(width, height, rows of per-pixel tuples), row 0 = top, via oiiotool's FITS output."""
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "x.fits")
        subprocess.run(["oiiotool", path, "--ch", channels, "-d", "float", "-o", out],
                       check=True)
        raw = open(out, "rb").read()
    cards, pos = {}, 0
    while True:
        card = raw[pos:pos + 80].decode("ascii")
        pos += 80
        if card[:8].strip() == "END":
            break
        if card[8:10] == "= ":
            cards[card[:8].strip()] = card[10:].split("/")[0].strip()
    pos = -(-pos // 2880) * 2880
    dims = [int(cards["NAXIS%d" % (i + 1)]) for i in range(int(cards["NAXIS"]))]
    c, w, h = ([1] + dims) if len(dims) == 2 else dims
    flat = struct.unpack(">%df" % (c * w * h), raw[pos:pos + 4 * c * w * h])
    rows = [[tuple(flat[(y * w + x) * c:(y * w + x + 1) * c]) for x in range(w)]
            for y in range(h)]
    return w, h, rows[::-1]  # FITS stores the bottom row first


def classify(items):
    """Per pixel: None (background), 'interior', 'silhouette' or 'crease'."""
    w, h, rows = read_exr(items, "Z")
    z = [[r[0] if 0.0 < r[0] < float("inf") else None for r in row] for row in rows]
    out = [[None] * w for _ in range(h)]
    for y in range(h):
        for x in range(w):
            if z[y][x] is None:
                continue
            cls = "interior"
            for dy in (-1, 0, 1):
                for dx in (-1, 0, 1):
                    if not (0 <= y + dy < h and 0 <= x + dx < w):
                        continue
                    n = z[y + dy][x + dx]
                    if n is None or abs(n - z[y][x]) > JUMP * min(n, z[y][x]):
                        cls = "silhouette"
            if cls == "interior" and 0 < x < w - 1 and 0 < y < h - 1:
                c = 1.0 / z[y][x]
                for dy, dx in ((0, 1), (1, 0), (1, 1), (1, -1)):
                    a, b = z[y - dy][x - dx], z[y + dy][x + dx]
                    if a and b and abs(1.0 / a - 2.0 * c + 1.0 / b) > KINK * c:
                        cls = "crease"
            out[y][x] = cls
    return out


def figures(test, ref, ref2, cls, margin):
    def luminance(image):
        return [0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2] for row in image for p in row]

    lum = luminance(ref2 and [[tuple((a + b) / 2 for a, b in zip(p, q)) for p, q in zip(r, s)]
                              for r, s in zip(ref, ref2)] or ref)
    lit = sorted(v for v in lum if v > 0)
    limit = 10.0 * lit[len(lit) // 2] if lit else float("inf")
    lum = [max(a, b) for a, b in zip(lum, luminance(test))]
    w, h = len(ref[0]), len(ref)
    emitter = [v > limit for v in lum]
    for _ in range(margin):
        emitter = [any(emitter[(y + dy) * w + x + dx] for dy in (-1, 0, 1) for dx in (-1, 0, 1)
                       if 0 <= y + dy < h and 0 <= x + dx < w)
                   for y in range(h) for x in range(w)]
    acc = {k: [0, 0.0, 0.0, 0.0, 0.0, 0.0]
           for k in ("all", "interior", "edge", "silhouette", "crease")}
    for y, row in enumerate(cls):
        for x, c in enumerate(row):
            if emitter[y * w + x]:
                continue
            t, r = test[y][x], ref[y][x]
            r2 = ref2[y][x] if ref2 else r
            classes = ("all",) if c is None else ("all", c) if c == "interior" else ("all", c,
                                                                                       "edge")
            for k in classes:
                a = acc[k]
                a[0] += 3
                for ch in range(3):
                    m = (r[ch] + r2[ch]) / 2
                    a[1] += m
                    a[2] += t[ch] - m
                    a[3] += (t[ch] - r[ch]) ** 2
                    a[4] += (t[ch] - r2[ch]) ** 2
                    a[5] += (r[ch] - r2[ch]) ** 2
    out = {}
    for k, (n, mean, diff, e1, e2, noise) in acc.items():
        if n == 0:
            continue
        mean /= n
        se = (e1 / n + e2 / n) / 2 - noise / n / 2 if ref2 else e1 / n
        out[k] = {"pixels": n // 3, "rmse_over_mean": max(se, 0.0) ** 0.5 / mean,
                  "bias": diff / n / mean}
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("test")
    p.add_argument("ref")
    p.add_argument("--ref2")
    p.add_argument("--items", required=True)
    p.add_argument("--emitter-margin", type=int, default=0,
                   help="also leave out pixels within PX of an emitter pixel")
    p.add_argument("--json", action="store_true")
    a = p.parse_args()
    test = read_exr(a.test, "R,G,B")[2]
    ref = read_exr(a.ref, "R,G,B")[2]
    ref2 = read_exr(a.ref2, "R,G,B")[2] if a.ref2 else None
    res = figures(test, ref, ref2, classify(a.items), a.emitter_margin)
    if a.json:
        json.dump(res, sys.stdout, indent=1)
        print()
        return
    for k, v in res.items():
        print("%-10s %6d px  rmse/mean %6.2f %%  bias %+6.2f %%" %
              (k, v["pixels"], 100 * v["rmse_over_mean"], 100 * v["bias"]))


if __name__ == "__main__":
    main()
