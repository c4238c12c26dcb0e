#!/usr/bin/env python3
"""Planning past one machine (issue 17): from one measured run of the pipeline, the wall time
slurm.mk would take on 1, 4, 16 and 64 nodes of this machine's size, its critical path, and the
serial part that bounds the speed-up.

It runs animation.mk once on one core (taskset), so that every piece's time is a one-core time:
the reports give rad-global's and rad-intervals' time, each movie's bake time (rad-movies
`movie_seconds`), each frame's compose time, and each tool's fixed cost (reading the scene and
its inputs: the report's total minus the pieces); ffmpeg is the rest of the run's wall time.
Then, as slurm.mk runs it on N nodes of C cores with SHARDS = N x C (one core per task):

  global || intervals   one task each (global: the sum of its key times; with --global-windows,
                        W = min(N x C, keys) windows, each paying a from-scratch first key
                        (key 0's time) and the rest coherent, then the merge)
  movies                movie i in shard i % SHARDS; each shard pays the fixed cost once;
                        shards are list-scheduled on the N x C cores (longest first)
  compose               SHARDS contiguous chunks of frames, each paying the fixed cost once
  mp4 + contact sheet   one task each, side by side
  + one scheduling latency per stage boundary (--latency, seconds; measured on the local
    cluster: tests/slurm/cluster.sh)

The serial part is what no number of nodes shortens, the critical path on unlimited nodes: the
longer of global and intervals (or, windowed, the slowest window and the merge), the fixed cost
of one movies and one compose task (scene loading), the longest single movie and frame (a piece
is not split), ffmpeg and the latencies. The one-core time over it bounds the speed-up.

usage: farm_model.py --scene SCENE [--frames 0-95] [--size 352x240] [--nodes 1,4,16,64]
                     [--cores N] [--latency 1.0] [--global-windows] [--bin DIR] [--out DIR]
       farm_model.py --from DIR ...   (model an earlier one-core run in DIR, without running)
       farm_model.py --self-test      (the model's arithmetic on made-up pieces)
"""
import argparse
import heapq
import json
import os
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def fail(msg):
    print("farm_model.py: " + msg, file=sys.stderr)
    sys.exit(1)


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        fail("%s: %s" % (path, e))


def measure(args):
    """animation.mk on one core into args.out; returns its wall seconds."""
    shutil.rmtree(args.out, ignore_errors=True)
    os.makedirs(args.out)
    cmd = ["taskset", "-c", "0", "make", "-s", "--no-print-directory", "-C", ROOT, "-f",
           os.path.join(HERE, "animation.mk"), "BIN=" + os.path.abspath(args.bin),
           "SCENE=" + os.path.abspath(args.scene), "OUT=" + os.path.abspath(args.out),
           "FRAMES=" + args.frames, "SIZE=" + args.size]
    print("farm_model: one-core run: " + " ".join(cmd), file=sys.stderr)
    t0 = time.monotonic()
    with open(os.path.join(args.out, "pipeline.log"), "w") as log:
        if subprocess.run(cmd, stdout=log, stderr=log).returncode != 0:
            fail("animation.mk failed (see %s/pipeline.log)" % args.out)
    wall = time.monotonic() - t0
    with open(os.path.join(args.out, "wall-seconds"), "w") as f:
        f.write("%.3f\n" % wall)
    return wall


def pieces(run_dir):
    """The one-core run's pieces: seconds of each stage part."""
    g = load(os.path.join(run_dir, "global-report.json"))
    i = load(os.path.join(run_dir, "intervals-report.json"))
    m = load(os.path.join(run_dir, "movies-report.json"))
    c = load(os.path.join(run_dir, "compose-report.json"))
    if "movie_seconds" not in m:
        fail("%s: no movie_seconds (made by an older rad-movies)" % os.path.join(run_dir, "movies-report.json"))
    keys = [k["seconds_links"] + k["seconds_solve"] + k.get("seconds_coherence", 0.0) for k in g["key_times"]]
    movies = [(int(mid), s) for mid, s in m["movie_seconds"]]
    frames = [f["seconds"] for f in c["frames"]]
    p = {
        "global": g["seconds"]["total"],
        "global_fixed": g["seconds"]["total"] - sum(keys),
        "keys": keys,
        "intervals": i["total_seconds"],
        "movies": movies,
        "movies_fixed": m["seconds"]["total"] - sum(s for _, s in movies),
        "frames": frames,
        "compose_fixed": c["seconds"] - sum(frames),
    }
    with open(os.path.join(run_dir, "wall-seconds")) as f:
        wall = float(f.read())
    stages = p["global"] + p["intervals"] + m["seconds"]["total"] + c["seconds"]
    p["video"] = max(0.0, wall - stages)  # ffmpeg (mp4 and contact sheet) and process starts
    p["wall"] = wall
    return p


def makespan(tasks, slots):
    """List scheduling, longest first, of task seconds on `slots` cores."""
    ends = [0.0] * min(slots, max(1, len(tasks)))
    for t in sorted(tasks, reverse=True):
        heapq.heapreplace(ends, ends[0] + t)
    return max(ends)


def global_seconds(p, slots, windows):
    if not windows or slots <= 1:
        return p["global"]
    k = len(p["keys"])
    w = min(slots, k)
    bounds = [k * j // w for j in range(w + 1)]
    scratch = p["keys"][0]  # a window starts from scratch at its first key
    slowest = max(p["global_fixed"] + scratch + sum(p["keys"][a + 1:b])
                  for a, b in zip(bounds, bounds[1:]))
    merge = p["global_fixed"]  # reading the windows and writing global.rlh
    return slowest + merge


def model(p, nodes, cores, latency, windows):
    slots = nodes * cores
    shards = slots
    movie_shards = [0.0] * shards
    for mid, s in p["movies"]:
        movie_shards[mid % shards] += s
    movie_tasks = [p["movies_fixed"] + s for s in movie_shards if s > 0.0]
    n = len(p["frames"])
    chunks = min(shards, n)
    compose_tasks = [p["compose_fixed"] + sum(p["frames"][n * j // chunks:n * (j + 1) // chunks])
                     for j in range(chunks)]
    g = global_seconds(p, slots, windows)
    path = {
        "global || intervals": max(g, p["intervals"]),
        "movies": makespan(movie_tasks, slots),
        "compose": makespan(compose_tasks, slots),
        "mp4 + contact sheet": p["video"],
        "scheduling": 4 * latency,
    }
    return path, sum(path.values())


def serial_part(p, latency, windows):
    """The critical path with unlimited nodes: what no number of nodes shortens."""
    g = global_seconds(p, len(p["keys"]), windows)
    return {
        "global || intervals": max(g, p["intervals"]),
        "scene loading": p["movies_fixed"] + p["compose_fixed"],
        "longest movie": max(s for _, s in p["movies"]),
        "longest frame": max(p["frames"]),
        "ffmpeg": p["video"],
        "scheduling": 4 * latency,
    }


def self_test():
    """The model's arithmetic on made-up pieces (ctest pipeline_farm_model_arithmetic)."""
    def check(what, got, want):
        if abs(got - want) > 1e-9:
            fail("self-test: %s: %g, expected %g" % (what, got, want))
    check("LPT of 3,3,2,2,2 on 2 cores", makespan([3, 3, 2, 2, 2], 2), 7)  # 3+2+2 | 3+2
    check("LPT of 5,1,1,1 on 4 cores", makespan([5, 1, 1, 1], 4), 5)
    check("no task", makespan([], 4), 0)
    p = {"global": 10.0, "global_fixed": 0.0, "keys": [4.0, 2.0, 2.0, 2.0], "intervals": 1.0,
         "movies": [(0, 1.0), (1, 1.0), (2, 1.0), (3, 3.0)], "movies_fixed": 0.5,
         "frames": [0.25] * 4, "compose_fixed": 0.1, "video": 2.0, "wall": 20.0}
    path, wall = model(p, 1, 2, 1.0, False)
    check("serial global", path["global || intervals"], 10.0)
    check("movies: shard 1 holds movies 1 and 3", path["movies"], 0.5 + 4.0)
    check("compose: two chunks of two frames", path["compose"], 0.1 + 0.5)
    check("one node", wall, 10.0 + 4.5 + 0.6 + 2.0 + 4.0)
    path, wall = model(p, 1, 2, 1.0, True)
    check("two windows, each from scratch", path["global || intervals"], 4.0 + 2.0)
    path, wall = model(p, 8, 2, 0.0, True)
    check("four windows of one key", path["global || intervals"], 4.0)
    check("movies on 16 cores: the longest movie", path["movies"], 0.5 + 3.0)
    serial = serial_part(p, 0.0, False)
    check("serial part", sum(serial.values()), 10.0 + 0.6 + 3.0 + 0.25 + 2.0)
    print("farm_model.py: self-test passed")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scene")
    ap.add_argument("--frames", default="0-95")
    ap.add_argument("--size", default="352x240")
    ap.add_argument("--nodes", default="1,4,16,64")
    ap.add_argument("--cores", type=int, default=os.cpu_count() or 2)
    ap.add_argument("--latency", type=float, default=1.0)
    ap.add_argument("--global-windows", action="store_true")
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "farm-model"))
    ap.add_argument("--from", dest="from_dir")
    ap.add_argument("--json")
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if args.self_test:
        return self_test()
    if args.from_dir:
        run_dir = args.from_dir
    else:
        if not args.scene:
            fail("give --scene (or --from DIR)")
        args.out = os.path.join(args.out, os.path.splitext(os.path.basename(args.scene))[0])
        measure(args)
        run_dir = args.out
    p = pieces(run_dir)
    one_core = p["wall"]
    print("farm model of %s: one core %.1f s (global %.1f, intervals %.1f, %d movies %.1f + %.2f fixed, "
          "%d frames %.1f + %.2f fixed, ffmpeg %.1f); %d cores per node, %.1f s latency per stage%s"
          % (run_dir, one_core, p["global"], p["intervals"], len(p["movies"]),
             sum(s for _, s in p["movies"]), p["movies_fixed"], len(p["frames"]), sum(p["frames"]),
             p["compose_fixed"], p["video"], args.cores, args.latency,
             ", rad-global in time windows" if args.global_windows else ""))
    rows = []
    print("%6s %9s %9s  %s" % ("nodes", "wall s", "speed-up", "critical path (s)"))
    for nodes in [int(x) for x in args.nodes.split(",")]:
        path, wall = model(p, nodes, args.cores, args.latency, args.global_windows)
        rows.append({"nodes": nodes, "wall": wall, "path": path})
        print("%6d %9.1f %8.1fx  %s" % (nodes, wall, one_core / wall,
                                        ", ".join("%s %.1f" % kv for kv in path.items())))
    serial = serial_part(p, args.latency, args.global_windows)
    total = sum(serial.values())
    print("serial part (the critical path on unlimited nodes): %.1f s = %.1f %% of the one-core "
          "time, so the speed-up is at most %.1fx: %s"
          % (total, 100.0 * total / one_core, one_core / total,
             ", ".join("%s %.1f" % kv for kv in serial.items())))
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"one_core": one_core, "pieces": p, "rows": rows, "serial": serial}, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
