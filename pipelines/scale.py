#!/usr/bin/env python3
"""How the pipeline scales with the scene (issue 16): the lecture hall of
pipelines/scenes/make_hall.py at several triangle counts through the four stages of
animation.mk, each stage timed and its peak memory measured from the child process.

Prints per size the stages' seconds and peak MiB, rad-global's links and nodes, and the log-log
slope of links and of rad-global's time against the triangle count over the sizes that
finished (a linear fit of log y on log x). The links' slope is that of the links rad-global
makes at the first key time with no link bound (a second rad-global run, --frames F-F
--max-links 2^31, after the pipeline): the pipeline's own runs stop refining at the 4 M link
bound from the 30k-triangle hall on, and a count held at the bound says nothing about how the
links grow (it had put the slope over 1k-100k at 0.88). A stage that runs past --max-seconds
is killed and reported; the larger sizes are then skipped (they would take longer still).
Writes OUT/scale.csv and, with gnuplot, OUT/scale.png.

With --scene floor the scenes are make_floor.py's floors of furnished rooms (issue 58: a
million triangles, meshes shared by many nodes); the table also gives each size's key times at
the link bound.

usage: scale.py [--triangles 1000,3000,10000,30000,100000] [--frames 0-95] [--size 352x240]
                [--scene hall|floor] [--moving-light] [--max-seconds 1800] [--bin DIR] [--out DIR] [--no-unbounded]
                [--check]
  --no-unbounded  skip the unbounded first-key run (the links' slope is then the pipeline's,
            bounded, largest key's)
  --check   exit 1 unless every size finished, each hall has its requested triangle count to
            within 10 % (requests of 1000 or more), every stage reported its peak memory and
            the first-key unbounded run counted links (the ctest pipeline_scale_runs, on small
            halls)
"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import bench  # noqa: E402

STAGES = ("global", "intervals", "movies", "compose")


# --max-links' largest value: no bound.
UNBOUNDED_LINKS = 2 ** 31


def first_key_unbounded(global_argv, out, log, limit):
    """rad-global's pipeline command at its first frame alone with no link bound: the links it
    makes there (patch + cluster links), its seconds and peak MiB."""
    argv, i = [], 0
    while i < len(global_argv):
        a = global_argv[i]
        if a in ("-o", "--frames", "--report") and i + 1 < len(global_argv):
            value = global_argv[i + 1]
            if a == "-o":
                value = os.path.join(out, "first-key-unbounded.rlh")
            elif a == "--frames":
                first = value.split("-")[0]
                value = "%s-%s" % (first, first)
            else:
                value = os.path.join(out, "first-key-unbounded-report.json")
            argv += [a, value]
            i += 2
            continue
        argv.append(a)
        i += 1
    argv += ["--max-links", str(UNBOUNDED_LINKS)]
    seconds, mib, _ = bench.run(argv, log, limit=limit)
    with open(os.path.join(out, "first-key-unbounded-report.json")) as f:
        k = json.load(f)["key_times"][0]
    os.remove(os.path.join(out, "first-key-unbounded.rlh"))
    return k.get("links", 0) + k.get("cluster_links", 0), seconds, mib


GENERATORS = {"hall": "make_hall.py", "floor": "make_floor.py"}


def one_size(bin_dir, out_root, triangles, frames, size, moving_light, limit, unbounded=True,
             kind="hall"):
    name = "%s-%d%s" % (kind, triangles, "-moving-light" if moving_light else "")
    out = os.path.join(out_root, name)
    requested = triangles
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    scene = os.path.join(out, name + ".gltf")
    made = subprocess.run([sys.executable, os.path.join(HERE, "scenes", GENERATORS[kind]), scene,
                           "--triangles", str(triangles)] +
                          (["--moving-light"] if moving_light else []),
                          check=True, capture_output=True, text=True)
    actual = int(made.stderr.split(":")[2].split()[0])
    log = os.path.join(out, "pipeline.log")
    row = {"scene": name, "triangles": actual, "requested": requested, "status": "ok"}
    left = limit
    flags = {"compose": ["--no-png"]}
    commands = bench.stage_commands(bin_dir, scene, out, frames, size, flags)
    for stage, argv in commands:
        t0 = time.monotonic()
        try:
            seconds, mib, cpu = bench.run(argv, log, limit=max(left, 1.0))
        except bench.Timeout as killed:
            row[stage + "_s"], row[stage + "_mib"] = killed.seconds, killed.peak_mib
            row["status"] = stage + " timeout"
            break
        except RuntimeError:
            row[stage + "_s"], row["status"] = time.monotonic() - t0, stage + " failed"
            break
        row[stage + "_s"], row[stage + "_mib"], row[stage + "_cpu"] = seconds, mib, cpu
        left -= seconds
    try:
        with open(os.path.join(out, "global-report.json")) as f:
            g = json.load(f)
        keys = g.get("key_times") or []
        # Patch links and cluster links (issue 16: clustering), the largest key.
        row["links"] = max(k.get("links", 0) + k.get("cluster_links", 0)
                           for k in keys) if keys else None
        row["nodes"] = max(k.get("nodes", 0) for k in keys) if keys else None
        row["link_cap"] = any(k.get("link_cap_reached") for k in keys)
        row["keys"] = len(keys)
        row["keys_at_bound"] = sum(1 for k in keys if k.get("link_cap_reached"))
    except (OSError, ValueError):
        pass
    if unbounded and row["status"] == "ok":
        try:
            row["links_unbounded"], row["unbounded_s"], row["unbounded_mib"] = \
                first_key_unbounded(dict(commands)["global"], out, log, max(limit, 1.0))
        except (bench.Timeout, RuntimeError, OSError, ValueError, KeyError, IndexError) as e:
            row["status"] = "first-key unbounded run failed (%s)" % type(e).__name__
    row["reported_memory"] = all(
        _reported_peak(os.path.join(out, stage + "-report.json")) for stage in STAGES
        if stage + "_s" in row)
    shutil.rmtree(os.path.join(out, "movies"), ignore_errors=True)  # large; not needed after
    return row


def _reported_peak(path):
    try:
        with open(path) as f:
            return json.load(f).get("peak_memory_mb", 0) > 0
    except (OSError, ValueError):
        return False


def slope(points):
    """Least-squares slope of log y against log x."""
    pts = [(math.log(x), math.log(y)) for x, y in points if x > 0 and y and y > 0]
    if len(pts) < 2:
        return None
    mx = sum(p[0] for p in pts) / len(pts)
    my = sum(p[1] for p in pts) / len(pts)
    sxx = sum((p[0] - mx) ** 2 for p in pts)
    return sum((p[0] - mx) * (p[1] - my) for p in pts) / sxx if sxx > 0 else None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--triangles", default="1000,3000,10000,30000,100000")
    ap.add_argument("--frames", default="0-95")
    ap.add_argument("--size", default="352x240")
    ap.add_argument("--moving-light", action="store_true")
    ap.add_argument("--scene", choices=sorted(GENERATORS), default="hall",
                    help="hall: make_hall.py's lecture hall; floor: make_floor.py's floor of "
                    "furnished rooms, its meshes instanced (issue 58)")
    ap.add_argument("--max-seconds", type=float, default=1800.0,
                    help="per size, for the four stages together")
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "scale"))
    ap.add_argument("--no-unbounded", action="store_true")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    if a.moving_light and a.scene != "hall":
        sys.exit("scale.py: --moving-light: only with --scene hall")
    os.makedirs(a.out, exist_ok=True)
    rows = []
    for n in [int(x) for x in a.triangles.split(",")]:
        print("scale: %s of %d triangles, frames %s at %s ..." % (a.scene, n, a.frames, a.size),
              file=sys.stderr, flush=True)
        row = one_size(a.bin, a.out, n, a.frames, a.size, a.moving_light, a.max_seconds,
                       not a.no_unbounded, a.scene)
        rows.append(row)
        print("scale:   %s" % row["status"], file=sys.stderr, flush=True)
        if row["status"] != "ok":
            break  # the larger sizes would run longer still
    print("%-26s %8s %9s %8s %7s  %s  %s" % ("scene", "tris", "links", "nodes", "bound",
                                              " ".join("%16s" % s for s in STAGES),
                                              "total s  status"))
    for r in rows:
        cells = " ".join("%7.1fs %6.0fM" % (r.get(s + "_s", 0), r.get(s + "_mib", 0))
                         if s + "_s" in r else "%16s" % "-" for s in STAGES)
        total = sum(r.get(s + "_s", 0) for s in STAGES)
        bound = "%d/%d" % (r["keys_at_bound"], r["keys"]) if "keys" in r else "-"
        print("%-26s %8d %9s %8s %7s  %s  %7.1f  %s%s" % (
            r["scene"], r["triangles"], r.get("links", "-"), r.get("nodes", "-"), bound, cells,
            total,
            r["status"], " (link bound reached)" if r.get("link_cap") else ""))
    for r in rows:  # on a shared machine the wall seconds above include others' load
        print("%-26s CPU seconds (user + system): %s" % (r["scene"], " ".join(
            "%s %.1f" % (s, r[s + "_cpu"]) for s in STAGES if s + "_cpu" in r)))
    done = [r for r in rows if r["status"] == "ok"]
    unbounded = all("links_unbounded" in r for r in done)
    counted = "links_unbounded" if unbounded else "links"
    if unbounded:
        for r in done:
            print("%-26s first key, no link bound: %d links, %.1f s, %.0f MiB" % (
                r["scene"], r["links_unbounded"], r["unbounded_s"], r["unbounded_mib"]))
    sl = slope([(r["triangles"], r.get(counted)) for r in done])
    st = slope([(r["triangles"], r.get("global_s")) for r in done])
    fmt = lambda v: "%.3f" % v if v is not None else "-"
    print("log-log slope against triangles: links %s (%s), rad-global time %s "
          "(goal for links: <= 1.2)" % (
              fmt(sl), "first key, no link bound" if unbounded else "largest key, bounded",
              fmt(st)))
    path = os.path.join(a.out, "scale.csv")
    fields = ["scene", "triangles", "links", "nodes", "link_cap", "keys", "keys_at_bound",
              "status"] + \
        [s + k for s in STAGES for k in ("_s", "_mib", "_cpu")] + \
        ["links_unbounded", "unbounded_s", "unbounded_mib"]
    with open(path + ".tmp", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    os.replace(path + ".tmp", path)
    print("scale: %s" % path, file=sys.stderr)
    if shutil.which("gnuplot") and len(done) >= 2:
        data = os.path.join(a.out, "scale.dat")
        with open(data, "w") as f:
            for r in done:
                f.write("%d %d %.3f\n" % (r["triangles"], r[counted], r["global_s"]))
        png = os.path.join(a.out, "scale.png")
        script = ("set terminal png size 800,500; set output '%s'; set logscale xy;"
                  "set xlabel 'triangles'; set ylabel 'links'; set y2label 'rad-global seconds';"
                  "set y2tics; set logscale y2; set key left top;"
                  "plot '%s' using 1:2 with linespoints title '%s',"
                  " '' using 1:3 axes x1y2 with linespoints title 'rad-global seconds (the pipeline run)'"
                  % (png, data, "links (first key, no link bound)" if unbounded
                     else "links (largest key)"))
        subprocess.run(["gnuplot", "-e", script], check=False)
        print("scale: %s" % png, file=sys.stderr)
    if a.check:
        bad = [r["scene"] + ": " + r["status"] for r in rows if r["status"] != "ok"]
        bad += [r["scene"] + ": %d triangles" % r["triangles"] for r in rows
                if r["requested"] >= 1000 and abs(r["triangles"] / r["requested"] - 1) > 0.1]
        bad += [r["scene"] + ": a stage's report has no peak_memory_mb" for r in rows
                if not r.get("reported_memory")]
        if not a.no_unbounded:
            bad += [r["scene"] + ": no first-key unbounded link count" for r in rows
                    if "links_unbounded" not in r or not r["links_unbounded"] > 0]
        for b in bad:
            print("scale.py: %s" % b, file=sys.stderr)
        sys.exit(1 if bad else 0)


if __name__ == "__main__":
    main()
