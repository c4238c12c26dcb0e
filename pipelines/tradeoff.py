#!/usr/bin/env python3
"""Speed/accuracy curve (issue 7 item 5; DESIGN.md §8 "error vs converged reference").

Sweeps each accuracy knob on its own, every other one at its default, on one scene: for every
setting the whole pipeline runs and its frames are compared with a converged path-traced
reference (rad-reference). Writes OUT/tradeoff.csv (knob, value, seconds per frame, RMSE,
relative L2), OUT/tradeoff.gp and, when gnuplot is installed, OUT/tradeoff.png with the Pareto
front (the settings no other setting beats in both time and error) marked.

usage: tradeoff.py [--scene GLTF] [--frames 0-11] [--size 176x120] [--spp 1024] [--out DIR]
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import bench  # noqa: E402

# knob name -> (stage, flag, values); the first value of each list is not special.
KNOBS = [
    ("eps", "global", "--eps", ["0.5", "0.1", "0.02", "0.005"]),
    ("key-step", "global", "--key-step", ["12", "6", "3", "1"]),
    ("bad-links", "global", "--bad-links", ["none", "lights", "partial", "all"]),
    ("texel-density", "intervals", "--texel-density", ["0.25", "0.5", "1", "2"]),
    ("max-samples", "movies", "--max-samples", ["4", "8", "16", "32", "64"]),
]


def pareto(points):
    """Indices of the points not dominated in (seconds, rmse)."""
    front = []
    for i, (t, e) in enumerate(points):
        if not any((t2 <= t and e2 <= e) and (t2 < t or e2 < e) for t2, e2 in points):
            front.append(i)
    return sorted(front, key=lambda i: points[i][0])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("--scene", default=os.path.join(HERE, "scenes", "cornell-moving.gltf"))
    ap.add_argument("--frames", default="0-11")
    ap.add_argument("--size", default="176x120")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "tradeoff"))
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    log = os.path.join(a.out, "tradeoff.log")
    first, last = (int(x) for x in a.frames.split("-"))
    nframes = last - first + 1

    # Pixel-centre samples: rad-compose point-samples pixels, so an antialiased reference would
    # add an edge-coverage error floor that no accuracy knob moves.
    ref = os.path.join(a.out, "reference-centres-%dspp" % a.spp)
    if not os.path.exists(os.path.join(ref, "%04d.exr" % last)):
        print("tradeoff: reference, %d spp" % a.spp, file=sys.stderr, flush=True)
        t, _ = bench.run([os.path.join(a.bin, "rad-reference"), a.scene, "-o", ref, "--frames",
                          a.frames, "--fps", "24", "--size", a.size, "--spp", str(a.spp),
                          "--pixel-centres"], log)
        print("tradeoff: reference took %.1f s (%.2f s/frame)" % (t, t / nframes), file=sys.stderr)

    rows = []
    runs = [("default", None, None, "-")] + [(k, s, f, v) for k, s, f, vs in KNOBS for v in vs]
    for knob, stage, flag, value in runs:
        out = os.path.join(a.out, "runs", "%s-%s" % (knob, value))
        flags = {stage: [flag, value]} if stage else {}
        print("tradeoff: %s = %s" % (knob, value), file=sys.stderr, flush=True)
        try:
            r = bench.pipeline(a.bin, a.scene, out, a.frames, a.size, flags, log)
        except RuntimeError as e:
            print("tradeoff: %s = %s: %s" % (knob, value, e), file=sys.stderr)
            continue
        p = subprocess.run([os.path.join(a.bin, "rad-diff"), os.path.join(out, "frames"), ref,
                            "--json"], capture_output=True, text=True)
        if p.returncode != 0:
            print("tradeoff: rad-diff: " + p.stderr.strip(), file=sys.stderr)
            continue
        d = json.loads(p.stdout)["difference"]
        rows.append({"knob": knob, "value": value, "seconds_per_frame": r["total"] / nframes,
                     "rmse": float(d["rmse"]), "relative_l2": float(d["relative_l2"]),
                     "peak_mib": r["peak_mib"]})
        shutil.rmtree(os.path.join(out, "movies"), ignore_errors=True)  # keep the disk small

    front = pareto([(r["seconds_per_frame"], r["rmse"]) for r in rows])
    for i, r in enumerate(rows):
        r["pareto"] = int(i in front)
    csv_path = os.path.join(a.out, "tradeoff.csv")
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["knob", "value", "seconds_per_frame", "rmse",
                                          "relative_l2", "peak_mib", "pareto"])
        w.writeheader()
        w.writerows(rows)
    print("%-14s %-8s %12s %12s %12s %s" % ("knob", "value", "s/frame", "rmse", "rel. L2",
                                             "pareto"))
    for r in rows:
        print("%-14s %-8s %12.4f %12.5g %12.5g %s" % (r["knob"], r["value"],
                                                      r["seconds_per_frame"], r["rmse"],
                                                      r["relative_l2"], "*" if r["pareto"] else ""))
    write_plot(a.out, rows, front)


def write_plot(out, rows, front):
    dat = os.path.join(out, "tradeoff.dat")
    with open(dat, "w") as f:
        knobs = []
        for r in rows:
            if r["knob"] not in knobs:
                knobs.append(r["knob"])
        for k in knobs:
            f.write("# %s\n" % k)
            for r in rows:
                if r["knob"] == k:
                    f.write("%g %g \"%s\"\n" % (r["seconds_per_frame"], r["rmse"], r["value"]))
            f.write("\n\n")
        f.write("# pareto\n")
        for i in front:
            f.write("%g %g\n" % (rows[i]["seconds_per_frame"], rows[i]["rmse"]))
    gp = os.path.join(out, "tradeoff.gp")
    plots = ["'%s' index %d using 1:2 with linespoints title '%s', '' index %d using 1:2:3 "
             "with labels offset 0.8,0.6 font ',8' notitle" % (dat, i, k, i)
             for i, k in enumerate(knobs)]
    plots.append("'%s' index %d using 1:2 with lines lw 3 lc rgb '#80000000' title 'Pareto front'"
                 % (dat, len(knobs)))
    with open(gp, "w") as f:
        f.write("set terminal pngcairo size 900,600\n" if has_cairo() else
                "set terminal png size 900,600\n")
        f.write("set output '%s'\n" % os.path.join(out, "tradeoff.png"))
        f.write("set logscale xy\nset xlabel 'seconds per frame'\nset ylabel 'RMSE vs path-traced"
                " reference (W/m^2/sr)'\nset key outside right\nset grid\n")
        f.write("plot " + ", \\\n     ".join(plots) + "\n")
    if shutil.which("gnuplot"):
        subprocess.run(["gnuplot", gp], check=False)


def has_cairo():
    try:
        p = subprocess.run(["gnuplot", "-e", "set terminal"], capture_output=True, text=True)
        return "pngcairo" in (p.stdout + p.stderr)
    except OSError:
        return False


if __name__ == "__main__":
    main()
