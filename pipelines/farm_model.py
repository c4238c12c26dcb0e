#!/usr/bin/env python3
"""Planning past one machine (issue 17): from one measured run of the pipeline, the wall time
slurm.mk would take on 1, 4, 16 and 64 nodes of this machine's size, its critical path, and the
serial part that bounds the speed-up.

It runs animation.mk once on one core (taskset), so that every piece's time is a one-core time:
the reports give rad-global's and rad-intervals' time, each movie's bake time (rad-movies
`movie_seconds`), each frame's compose time, and each tool's fixed cost (reading the scene and
its inputs: the report's total minus the pieces; rad-compose's also its seconds_inputs, read
before the frame loop); ffmpeg is the rest of the run's wall time.
Then, as slurm.mk runs it on N nodes of C cores with SHARDS = N x C (one core per task):

  global || intervals   one task each, the longer on the path (global: the sum of its key
                        times; with --global-windows, W = min(N x C, keys) windows, each paying
                        its reading, set-up and writing once, the per-key folding per key, a
                        from-scratch first key and the rest coherent, then the merge; priced
                        from the report's parts, or timed on two windows and their merge with
                        --time-windows; with --interval-windows (slurm.mk's INTERVAL_WINDOWS),
                        rad-intervals' item buffers in W = min(N x C, frames) windows of frames,
                        each paying the set-up and its frames' share of the per-frame time,
                        then the pass over their counts: the set-up and
                        --interval-merge-fraction of the per-frame time, what drawing no item
                        buffer leaves of it). slurm.mk's last window task runs each merge, so
                        no latency before it; with --window-merge-stage a merge job's latency
                        is on its own stage's path)
  movies                movie i in shard i % SHARDS; each shard pays the fixed cost once;
                        shards are list-scheduled on the N x C cores (longest first).
                        With --piece-keys K (slurm.mk's MOVIE_PIECE_KEYS, issue 58), a movie of
                        n > K keys is P = ceil(n / K) pieces, every movie's pieces dealt to
                        the shards in order, each paying the movie's planning (its report's
                        seconds_plan) and its share of the movie's key time; each task then
                        joins the movies whose last piece it holds (slurm.mk: a second process,
                        the fixed cost once, and per movie reading and writing its bytes at the
                        run's write rate). With --merge-stage, as slurm.mk did before: the
                        merges as a stage of their own, movie m in task m % SHARDS, one more
                        stage boundary
  compose               SHARDS contiguous chunks of frames, each paying the fixed cost once
  mp4 + contact sheet   one task each, side by side; with --video-segments (slurm.mk, issue 58)
                        each compose chunk also encodes its frames as a segment (the one-core
                        mp4 encode's time per frame) and the mp4 task only concatenates them
                        (-c copy); the contact sheet decodes its eight frames. The three are
                        timed on the run's frames, one core each (video-seconds.json)
  + one scheduling latency per stage on the critical path (--latency, seconds; measured on the
    local cluster: tests/slurm/cluster.sh): global || intervals, movies (and, with
    --merge-stage, their merges), compose, the mp4

The serial part is what no number of nodes shortens, the critical path on unlimited nodes: the
longer of global and intervals (or, windowed, the slowest window and its merge), the fixed cost
of one movies and one compose task (scene loading), the longest single movie (with pieces: the
longest piece with the merge its task does) and frame, ffmpeg and the latencies. The one-core time over it
bounds the speed-up.

usage: farm_model.py --scene SCENE [--frames 0-95] [--size 352x240] [--nodes 1,4,16,64]
                     [--cores N] [--latency 1.0] [--global-windows] [--time-windows]
                     [--interval-windows] [--window-merge-stage] [--piece-keys K]
                     [--piece-seconds T] [--merge-stage] [--video-segments] [--bin DIR]
                     [--out DIR]
       farm_model.py --from DIR ...   (model an earlier one-core run in DIR, without running)
       farm_model.py --self-test      (the model's arithmetic on made-up pieces)
"""
import argparse
import heapq
import json
import math
import os
import shlex
import shutil
import subprocess
import sys
import tempfile
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


def time_video(run_dir):
    """One core's seconds of the run's mp4 (one encode), its contact sheet, and the mp4 as
    segments of 4 chunks joined by `encode.sh concat` (the join alone): video-seconds.json."""
    path = os.path.join(run_dir, "video-seconds.json")
    if os.path.exists(path):
        return load(path)
    frames_dir = os.path.join(run_dir, "frames")
    numbers = sorted(int(n[:-4]) for n in os.listdir(frames_dir) if n.endswith(".png"))
    if not numbers:
        fail("%s: no frames to time the encodes on" % frames_dir)
    first, last = numbers[0], numbers[-1]
    encode = os.path.join(HERE, "encode.sh")
    scratch = os.path.join(run_dir, "video-timing")
    os.makedirs(scratch, exist_ok=True)

    def timed(*args):
        t0 = time.monotonic()
        if subprocess.run(["taskset", "-c", "0", encode] + list(args)).returncode != 0:
            fail("encode.sh %s failed" % args[0])
        return time.monotonic() - t0
    frames = "%d-%d" % (first, last)
    out = {"mp4": timed("mp4", frames_dir, frames, "24", os.path.join(scratch, "one.mp4")),
           "contact": timed("contact", frames_dir, frames, "24", os.path.join(scratch, "c.png"))}
    n = last - first + 1
    chunks = ["%d-%d" % (first + n * j // 4, first + n * (j + 1) // 4 - 1) for j in range(4)]
    for c in chunks:
        timed("segment", frames_dir, c, "24", os.path.join(frames_dir, "segment-%s.mp4" % c))
    out["concat"] = timed("concat", frames_dir, ",".join(chunks), "24",
                          os.path.join(scratch, "cat.mp4"))
    for c in chunks:
        os.remove(os.path.join(frames_dir, "segment-%s.mp4" % c))
    shutil.rmtree(scratch, ignore_errors=True)
    with open(path, "w") as f:
        json.dump(out, f)
    return out


def time_global_windows(run_dir, args):
    """rad-global of the one-core run in two windows and their merge, each on one core
    (global-windows-seconds.json): a window task's seconds once (reading the scene, the set-up,
    writing the window file) and per key beyond its solve (the mean of the two windows), the
    second window's first key (from scratch, past key 0) and the merge task's total. The merged
    file must be the run's global.rlh byte for byte."""
    path = os.path.join(run_dir, "global-windows-seconds.json")
    if os.path.exists(path):
        return load(path)
    bin_dir = os.path.abspath(args.bin)
    out = subprocess.run(["make", "-s", "--no-print-directory", "-C", ROOT, "-f",
                          os.path.join(HERE, "animation.mk"), "BIN=" + bin_dir,
                          "SCENE=" + os.path.abspath(args.scene), "OUT=" + os.path.abspath(run_dir),
                          "FRAMES=" + args.frames, "SIZE=" + args.size, "stage-commands"],
                         capture_output=True, text=True)
    cmd = [line.split("\t", 1)[1] for line in out.stdout.splitlines() if line.startswith("global\t")]
    if out.returncode != 0 or not cmd:
        fail("animation.mk stage-commands gave no global command: " + out.stderr.strip())
    words = shlex.split(cmd[0])
    scratch = os.path.join(run_dir, "global-windows-timing")
    os.makedirs(scratch, exist_ok=True)

    def run(extra, output, report):
        w = list(words)
        w[w.index("-o") + 1] = output
        w[w.index("--report") + 1] = report
        if subprocess.run(["taskset", "-c", "0"] + w + extra,
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode != 0:
            fail("%s failed" % " ".join(w + extra))
        return load(report)
    ranges = subprocess.run(words[:1] + words[1:] + ["--print-windows", "2"], capture_output=True,
                            text=True).stdout.split()
    if len(ranges) != 2:
        fail("rad-global --print-windows 2 gave %r" % ranges)
    reports, files = [], []
    for j, r in enumerate(ranges):
        files.append(os.path.join(scratch, "w%d.rkw" % j))
        reports.append(run(["--window", r], files[-1], files[-1][:-4] + "-report.json"))
    # The merge writes the run's own -o and --report (its provenance records the command line),
    # so the run's files are moved aside while it runs, compared, and put back.
    rlh, report = words[words.index("-o") + 1], words[words.index("--report") + 1]
    for f in (rlh, report):
        os.replace(f, f + ".one-run")
    try:
        if subprocess.run(["taskset", "-c", "0"] + words + ["--merge"] + files,
                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode != 0:
            fail("rad-global --merge of %s failed" % " ".join(files))
        m = load(report)
        same = subprocess.run(["cmp", "-s", rlh, rlh + ".one-run"]).returncode == 0
    finally:
        for f in (rlh, report):
            os.replace(f + ".one-run", f)
    if not same:
        fail("the merge of two windows differs from %s" % rlh)

    def key_seconds(k):
        return k["seconds_links"] + k["seconds_solve"] + k.get("seconds_coherence", 0.0)
    base = [r["seconds"]["read"] + r["seconds"]["setup"] + r["seconds"]["write"] for r in reports]
    per_key = [(r["seconds"]["total"] - b - sum(key_seconds(k) for k in r["key_times"]))
               / len(r["key_times"]) for r, b in zip(reports, base)]
    result = {"window_base": sum(base) / 2, "per_key": sum(per_key) / 2,
              "scratch_key": key_seconds(reports[1]["key_times"][0]),
              "merge": m["seconds"]["total"], "windows": ranges}
    shutil.rmtree(scratch, ignore_errors=True)
    with open(path, "w") as f:
        json.dump(result, f)
    return result


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
    # Per movie: its keys and planning seconds (rad-movies' work_seconds; older reports have none,
    # and their movies cannot be cut: one key, no planning).
    plans = {int(w["movie"]): (int(w["keys"]), float(w["seconds_plan"]))
             for w in m.get("work_seconds", []) if w.get("piece", -1) < 0}
    frames = [f["seconds"] for f in c["frames"]]
    movie_bytes = {}
    for mid, _ in movies:
        path = os.path.join(run_dir, "movies", "%06d.exr" % mid)
        movie_bytes[mid] = os.path.getsize(path) if os.path.exists(path) else 0
    p = {
        "global": g["seconds"]["total"],
        "global_fixed": g["seconds"]["total"] - sum(keys),
        "keys": keys,
        "intervals": i["total_seconds"],
        "intervals_fixed": i["setup_seconds"],
        "intervals_frames": i["frames"],
        "movies": movies,
        "movie_plans": {mid: plans.get(mid, (1, 0.0)) for mid, _ in movies},
        "movies_fixed": m["seconds"]["total"] - sum(s for _, s in movies),
        # Each movie's bytes, and the seconds of writing a byte: a merge reads a cut movie's
        # pieces and writes the movie (a constant movie's pieces are one key each).
        "movie_bytes": movie_bytes,
        "write_per_byte": m["seconds"].get("write", 0.0) / max(1, sum(movie_bytes.values())),
        "frames": frames,
        # Every compose chunk reads the scene, global.rlh, intervals.rti and its movies' headers
        # before its first frame (the report's seconds_inputs; older reports have none and their
        # chunks were charged the frame loop's fixed part alone).
        "compose_fixed": c.get("seconds_inputs", 0.0) + c["seconds"] - sum(frames),
    }
    if all(x in g["seconds"] for x in ("read", "setup", "merge", "write")):
        p["global_parts"] = {x: g["seconds"][x] for x in ("read", "setup", "merge", "write")}
    windows_path = os.path.join(run_dir, "global-windows-seconds.json")
    if os.path.exists(windows_path):
        p["global_windows"] = load(windows_path)
    with open(os.path.join(run_dir, "wall-seconds")) as f:
        wall = float(f.read())
    stages = p["global"] + p["intervals"] + m["seconds"]["total"] + c["seconds"] + c.get("seconds_inputs", 0.0)
    p["video"] = max(0.0, wall - stages)  # ffmpeg (mp4 and contact sheet) and process starts
    p["wall"] = wall
    return p


def makespan(tasks, slots):
    """List scheduling, longest first, of task seconds on `slots` cores."""
    ends = [0.0] * min(slots, max(1, len(tasks)))
    for t in sorted(tasks, reverse=True):
        heapq.heapreplace(ends, ends[0] + t)
    return max(ends)


def window_costs(p):
    """What a rad-global window task costs beside its keys' solves, and its merge:
    (base, per_key, scratch, merge). base: reading the scene, the set-up and writing the window
    file, once per task; per_key: what each key costs beyond its solve (folding its links into
    the activity intervals, its records); scratch: the first key of a window past key 0, solved
    from scratch; merge: the merge task. Measured when the run timed windows
    (global-windows-seconds.json, time_global_windows); else from the one run's report (the
    merge as its merge pass, reading and writing; every window's first key as long as key 0);
    for a run without the report's seconds, its whole fixed cost for base and merge, as before."""
    gw = p.get("global_windows")
    if gw:
        return gw["window_base"], gw["per_key"], gw["scratch_key"], gw["merge"]
    sec = p.get("global_parts")
    if not sec:
        return p["global_fixed"], 0.0, p["keys"][0], p["global_fixed"]
    base = sec["read"] + sec["setup"] + sec["write"]
    per_key = max(0.0, p["global_fixed"] - base - sec["merge"]) / len(p["keys"])
    return base, per_key, p["keys"][0], sec["read"] + sec["merge"] + sec["write"]


def global_path(p, slots, windows, latency=0.0, merge_in_task=True):
    """rad-global's time on the critical path: one task, or min(slots, keys) windows side by side,
    each paying its fixed cost and a from-scratch first key, then the merge: run by the last
    window task to end (slurm.mk's default: no scheduling latency between) or, merge_in_task
    False, as a job of its own after one latency."""
    if not windows or slots <= 1:
        return p["global"]
    k = len(p["keys"])
    w = min(slots, k)
    base, per_key, scratch, merge = window_costs(p)
    bounds = [k * j // w for j in range(w + 1)]
    slowest = max(base + per_key * (b - a) + (p["keys"][0] if a == 0 else scratch)
                  + sum(p["keys"][a + 1:b]) for a, b in zip(bounds, bounds[1:]))
    return slowest + merge + (0.0 if merge_in_task else latency)


def intervals_path(p, slots, windows, merge_fraction, latency=0.0, merge_in_task=True):
    """rad-intervals' time on the critical path: one task, or windows of frames side by side and
    the pass over their counts (rad-intervals --window, --merge), run by the last window task or,
    merge_in_task False, as a job of its own after one latency."""
    if not windows or slots <= 1:
        return p["intervals"]
    n = p["intervals_frames"]
    w = min(slots, n)
    per_frame = (p["intervals"] - p["intervals_fixed"]) / n
    largest = max(n * (j + 1) // w - n * j // w for j in range(w))
    slowest = p["intervals_fixed"] + per_frame * largest
    merge = p["intervals_fixed"] + per_frame * n * merge_fraction
    return slowest + merge + (0.0 if merge_in_task else latency)


def movie_pieces(p, piece_keys, piece_seconds=0.0):
    """(movie id, piece index, seconds) of every piece, and {movie id: seconds to merge it} of
    the movies cut. A movie of n > K keys is ceil(n / K) pieces, as rad-movies --piece-keys cuts
    it, each paying the movie's planning and its share of the key time
    (tools/stages/movie_pieces.h); its merge reads its pieces and writes it: twice its bytes at
    the run's write rate. With piece_seconds T (rad-movies --piece-costs, the cut by known cost,
    tools/stages/movie_cut.h): a movie of s seconds is min(n, ceil(s / T)) pieces, the others
    whole (the costs are this run's own: a farm reads an earlier run's)."""
    out, merges = [], {}
    for mid, s in p["movies"]:
        keys, plan = p.get("movie_plans", {}).get(mid, (1, 0.0))
        if piece_seconds > 0:
            count = max(1, min(keys, int(math.ceil(s / piece_seconds))))
        else:
            count = (keys + piece_keys - 1) // piece_keys if piece_keys > 0 and keys > piece_keys else 1
        if count == 1:
            out.append((mid, 0, s))
            continue
        merges[mid] = 2.0 * p.get("write_per_byte", 0.0) * p.get("movie_bytes", {}).get(mid, 0)
        for j in range(count):
            n = keys * (j + 1) // count - keys * j // count
            out.append((mid, j, plan + (s - plan) * n / keys))
    return out, merges


def deal_by_cost(seconds, shards):
    """rad-movies' dealByCost (tools/stages/movie_cut.h): each unit's shard, the units longest
    first (ties: the lower unit), each to the shard with the least so far (ties: the lower)."""
    load = [0.0] * max(1, shards)
    shard_of = [0] * len(seconds)
    for u in sorted(range(len(seconds)), key=lambda u: -seconds[u]):
        s = min(range(len(load)), key=lambda i: (load[i], i))
        load[s] += seconds[u]
        shard_of[u] = s
    return shard_of


def units_shards(pieces, shards, piece_keys, piece_seconds):
    """Each unit's shard as rad-movies' shardWork deals them: by cost, in order, or by movie id."""
    if piece_seconds > 0:
        return deal_by_cost([s for _, _, s in pieces], shards)
    return [(u if piece_keys > 0 else mid) % shards for u, (mid, _, _) in enumerate(pieces)]


def merge_seconds(p, merges, shards):
    """The merges side by side, as slurm.mk runs them: movie m in merge task m % shards, each
    task paying the fixed cost once (0: no movie cut, no merge)."""
    if not merges:
        return 0.0
    tasks = [0.0] * shards
    for mid, s in merges.items():
        tasks[mid % shards] += s
    return p["movies_fixed"] + max(tasks)


def video_path(p, segments):
    """The encodes after the frames: both whole encodes (the run's remainder), or with segments
    the longer of the concatenation and the contact sheet (side by side)."""
    if not segments:
        return p["video"]
    v = p["video_parts"]
    return max(v["concat"], v["contact"])


def merges_in_tasks(p, pieces, merges, shards, shard_of=None):
    """Per movie shard, the seconds of the merges its task does after its pieces (slurm.mk's
    --merge-ready): the fixed cost of its second process, once, and the merge of every movie
    whose last piece (in dealing order) it holds. 0 where a shard has no piece of a cut movie.
    shard_of: each unit's shard (default: dealt in order)."""
    if shard_of is None:
        shard_of = [u % shards for u in range(len(pieces))]
    out = [0.0] * shards
    last = {}
    holders = set()
    for u, (mid, _, _) in enumerate(pieces):
        if mid in merges:
            last[mid] = shard_of[u]
            holders.add(shard_of[u])
    for shard in holders:
        out[shard] += p["movies_fixed"]
    for mid, shard in last.items():
        out[shard] += merges[mid]
    return out


def model(p, nodes, cores, latency, windows, piece_keys=0, segments=False, merge_stage=False,
          piece_seconds=0.0, interval_windows=False, interval_merge_fraction=0.01,
          window_merge_stage=False):
    slots = nodes * cores
    shards = slots
    movie_shards = [0.0] * shards
    pieces, merges = movie_pieces(p, piece_keys, piece_seconds)
    merge = merge_seconds(p, merges, shards) if merge_stage else 0.0
    shard_of = units_shards(pieces, shards, piece_keys, piece_seconds)  # rad-movies' shardWork
    for u, (mid, _, s) in enumerate(pieces):
        movie_shards[shard_of[u]] += s
    if not merge_stage:
        movie_shards = [a + b for a, b in
                        zip(movie_shards, merges_in_tasks(p, pieces, merges, shards, shard_of))]
    movie_tasks = [p["movies_fixed"] + s for s in movie_shards if s > 0.0]
    n = len(p["frames"])
    chunks = min(shards, n)
    encode = p["video_parts"]["mp4"] / n if segments else 0.0  # a segment's encode, per frame
    compose_tasks = [p["compose_fixed"] + sum(p["frames"][n * j // chunks:n * (j + 1) // chunks])
                     + encode * (n * (j + 1) // chunks - n * j // chunks) for j in range(chunks)]
    g = global_path(p, slots, windows, latency, not window_merge_stage)
    iv = intervals_path(p, slots, interval_windows, interval_merge_fraction, latency,
                        not window_merge_stage)
    path = {
        "global || intervals": max(g, iv),
        "movies": makespan(movie_tasks, slots),
        "movie merge": merge,
        "compose": makespan(compose_tasks, slots),
        "mp4 + contact sheet": video_path(p, segments),
        "scheduling": stage_boundaries(merge_stage and merge) * latency,
    }
    return path, sum(path.values())


def stage_boundaries(movie_merge):
    """The stages on the critical path, each started after one scheduling latency: global ||
    intervals, movies (and their merges when a stage of their own), compose, the mp4. A window
    merge run as a job of its own has its latency in its stage's path (global_path,
    intervals_path), so that it counts only when that stage is the longer of the two."""
    return 4 + (1 if movie_merge else 0)


def serial_part(p, latency, windows, piece_keys=0, segments=False, merge_stage=False,
                piece_seconds=0.0, interval_windows=False, interval_merge_fraction=0.01,
                window_merge_stage=False):
    """The critical path with unlimited nodes: what no number of nodes shortens."""
    g = global_path(p, len(p["keys"]), windows, latency, not window_merge_stage)
    iv = intervals_path(p, p["intervals_frames"], interval_windows, interval_merge_fraction,
                        latency, not window_merge_stage)
    pieces, merges = movie_pieces(p, piece_keys, piece_seconds)
    if merge_stage:
        merge = merge_seconds(p, merges, max(1, len(merges)))
        longest = max(s for _, _, s in pieces)
    else:  # one task a piece: the task of a movie's last piece also merges it
        merge = p["movies_fixed"] if merges else 0.0
        last = {mid: j for mid, j, _ in pieces}
        longest = max(s + (merges[mid] if mid in merges and j == last[mid] else 0.0)
                      for mid, j, s in pieces)
    encode = p["video_parts"]["mp4"] / len(p["frames"]) if segments else 0.0
    return {
        "global || intervals": max(g, iv),
        "scene loading": p["movies_fixed"] + p["compose_fixed"],
        "longest movie": longest,
        "movie merge": merge,
        "longest frame": max(p["frames"]) + encode,
        "ffmpeg": video_path(p, segments),
        "scheduling": stage_boundaries(merge_stage and merge) * latency,
    }


def self_test_reports(check):
    """pieces() on made-up reports (part of --self-test)."""
    # A run's reports: compose's fixed cost takes what rad-compose reads before its frame loop
    # (seconds_inputs: 1.5 s), beside the loop's own 0.5 s; before, the 1.5 s was in no chunk.
    with tempfile.TemporaryDirectory() as run:
        reports = {"global-report.json": {"seconds": {"total": 3.0}, "key_times": [
                       {"seconds_links": 1.0, "seconds_solve": 1.0}]},
                   "intervals-report.json": {"total_seconds": 1.0, "setup_seconds": 0.5,
                                             "frames": 2},
                   "movies-report.json": {"seconds": {"total": 2.0}, "movie_seconds": [[0, 1.5]]},
                   "compose-report.json": {"seconds": 1.0, "seconds_inputs": 1.5,
                                           "frames": [{"seconds": 0.25}, {"seconds": 0.25}]}}
        for name, value in reports.items():
            with open(os.path.join(run, name), "w") as f:
                json.dump(value, f)
        with open(os.path.join(run, "wall-seconds"), "w") as f:
            f.write("10.0")
        r = pieces(run)
        check("compose fixed: inputs and the loop's own", r["compose_fixed"], 1.5 + 0.5)
        check("video: the wall beside the stages", r["video"], 10.0 - 3.0 - 1.0 - 2.0 - 2.5)


def self_test():
    """The model's arithmetic on made-up pieces (ctest pipeline_farm_model_arithmetic)."""
    def check(what, got, want):
        if abs(got - want) > 1e-9:
            fail("self-test: %s: %g, expected %g" % (what, got, want))
    check("LPT of 3,3,2,2,2 on 2 cores", makespan([3, 3, 2, 2, 2], 2), 7)  # 3+2+2 | 3+2
    check("LPT of 5,1,1,1 on 4 cores", makespan([5, 1, 1, 1], 4), 5)
    check("no task", makespan([], 4), 0)
    p = {"global": 10.0, "global_fixed": 0.0, "keys": [4.0, 2.0, 2.0, 2.0], "intervals": 1.0,
         "intervals_fixed": 0.2, "intervals_frames": 10,
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
    # Windows with measured costs (time_global_windows): each window task pays 0.3 s once and
    # 0.1 s a key beyond its solves, a window past key 0 starts with a 3 s key from scratch; the
    # merge takes 0.25 s. Two windows of keys 4+2 | 2+2: 0.5 + 4 + 2 = 6.5 and 0.5 + 3 + 2 =
    # 5.5, then the merge.
    m = dict(p, global_windows={"window_base": 0.3, "per_key": 0.1, "scratch_key": 3.0,
                                "merge": 0.25})
    path, wall = model(m, 1, 2, 1.0, True)
    check("measured windows, merged by the last window task", path["global || intervals"],
          6.5 + 0.25)
    path, wall = model(m, 1, 2, 1.0, True, window_merge_stage=True)
    check("the merge as a job: one latency more", path["global || intervals"], 6.5 + 1.0 + 0.25)
    check("a merge job is no stage of every path", path["scheduling"], 4.0)
    # From the one run's report: read 0.1, set-up 0.1, merge pass 0.2, write 0.1 of a fixed
    # 1.3 s leave 0.8 s for the 4 keys' folding, 0.2 s a key; windows of 2 keys: 0.3 + 0.4 +
    # 4 + 2 and 0.3 + 0.4 + 4 (key 0's time) + 2; the merge 0.1 + 0.2 + 0.1.
    e = dict(p, global_fixed=1.3, global_parts={"read": 0.1, "setup": 0.1, "merge": 0.2,
                                                 "write": 0.1})
    path, wall = model(e, 1, 2, 1.0, True)
    check("windows from the one run's report", path["global || intervals"], 6.7 + 0.4)
    # rad-intervals in windows of frames: 10 frames of 2 s after 0.2 s of set-up, on 4 cores
    # windows of 2, 3, 2, 3 frames, then the pass over their counts (the set-up and 1 %).
    q = dict(p, intervals=20.2, **{"global": 1.0})
    path, wall = model(q, 2, 2, 1.0, False)
    check("intervals as one task", path["global || intervals"], 20.2)
    path, wall = model(q, 2, 2, 1.0, False, interval_windows=True)
    check("intervals in four windows and the pass, in the last window task",
          path["global || intervals"], 0.2 + 3 * 2.0 + 0.2 + 0.01 * 20.0)
    check("the pass in a window task: no stage more", path["scheduling"], 4.0)
    path, wall = model(q, 2, 2, 1.0, False, interval_windows=True, window_merge_stage=True)
    check("the pass as a job: its latency on the intervals' path", path["global || intervals"],
          0.2 + 3 * 2.0 + 1.0 + 0.2 + 0.01 * 20.0)
    # The pass's latency counts only when rad-intervals is the longer: rad-global one task of
    # 30 s is the path, whatever rad-intervals' windows and their merge job take.
    r = dict(q, **{"global": 30.0})
    path, wall = model(r, 2, 2, 1.0, False, interval_windows=True, window_merge_stage=True)
    check("global longer: the intervals' merge latency off the path",
          path["global || intervals"], 30.0)
    check("global longer: four stages", path["scheduling"], 4.0)
    check("global longer: serial part", serial_part(r, 1.0, False, interval_windows=True,
                                                    window_merge_stage=True)["scheduling"], 4.0)
    serial = serial_part(q, 1.0, False, interval_windows=True)
    check("serial: a window of one frame and the pass", serial["global || intervals"],
          0.2 + 2.0 + 0.2 + 0.01 * 20.0)
    check("serial: no stage for the pass", serial["scheduling"], 4.0)
    # Pieces (issue 58): movie 3 (3 s, 6 keys, 1 s of planning) in pieces of at most 2 keys is
    # 3 pieces of 1 + 2/3 s each, the 4th to 6th pieces dealt: shards 3, 0, 1;
    # the merge reads and writes its 600 bytes at 0.0005 s a byte, after the fixed 0.5 s.
    p["movie_plans"] = {0: (2, 0.5), 1: (2, 0.5), 2: (2, 0.5), 3: (6, 1.0)}
    p["movie_bytes"] = {0: 100, 1: 100, 2: 100, 3: 600}
    p["write_per_byte"] = 0.0005
    pieces, merges = movie_pieces(p, 2)
    check("three pieces of movie 3", len([x for x in pieces if x[0] == 3]), 3)
    check("a piece: planning + a third of the keys", pieces[3][2], 1.0 + 2.0 / 3.0)
    check("the merge", merge_seconds(p, merges, 4), 0.5 + 0.6)
    check("no pieces: no merge", merge_seconds(p, movie_pieces(p, 0)[1], 4), 0.0)
    path, wall = model(p, 2, 2, 1.0, False, 2, merge_stage=True)
    check("movies on 4 shards: shard 0 holds movie 0 and a piece of movie 3",
          path["movies"], 0.5 + 1.0 + 1.0 + 2.0 / 3.0)
    check("a stage more", path["scheduling"], 5.0)
    path, wall = model(p, 2, 2, 1.0, True, 2, merge_stage=True, window_merge_stage=True)
    check("and the global merge job's latency on its path", path["global || intervals"], 5.0)
    serial = serial_part(p, 0.0, False, 2, merge_stage=True)
    check("serial: the longest piece",
          serial["longest movie"], 1.0 + 2.0 / 3.0)
    check("serial merge", serial["movie merge"], 1.1)
    check("serial scheduling, windows and merges",
          serial_part(p, 1.0, True, 2, merge_stage=True)["scheduling"], 5.0)
    # The merges in the piece tasks (slurm.mk's default): movie 3's pieces are units 3, 4, 5,
    # in shards 3, 0, 1 of 4; shard 1 holds its last piece and merges it (0.6 s) after its
    # second process's fixed cost (0.5 s); shards 3 and 0 pay that fixed cost too, for nothing
    # to merge. Shard 0: movie 0 (1 s) and piece 1 (5/3 s); shard 1: movie 1 and piece 2 plus
    # the merge.
    path, wall = model(p, 2, 2, 1.0, False, 2)
    check("no merge stage", path["movie merge"], 0.0)
    check("no stage more", path["scheduling"], 4.0)
    check("movies: shard 1 bakes and merges",
          path["movies"], 0.5 + 1.0 + 1.0 + 2.0 / 3.0 + 0.5 + 0.6)
    serial = serial_part(p, 0.0, False, 2)
    check("serial: the last piece and its merge", serial["longest movie"], 1.0 + 2.0 / 3.0 + 0.6)
    check("serial: the merge's fixed cost", serial["movie merge"], 0.5)
    check("serial scheduling, windows, no merge stage", serial_part(p, 1.0, True, 2)["scheduling"], 4.0)
    # Segments: each chunk of two frames encodes them (1 s for 4 frames: 0.5 s a chunk); then
    # the longer of the join (0.25 s) and the contact sheet (0.5 s).
    p["video_parts"] = {"mp4": 1.0, "contact": 0.5, "concat": 0.25}
    path, wall = model(p, 1, 2, 1.0, False, 0, True)
    check("compose chunks encode their segments", path["compose"], 0.1 + 0.5 + 0.5)
    check("the join or the contact sheet", path["mp4 + contact sheet"], 0.5)
    # The cut by known cost (--piece-seconds T = 1.5): movie 3 (3 s, 6 keys, 1 s of planning) in
    # ceil(3 / 1.5) = 2 pieces of 1 + 1 s, the 1 s movies whole; dealt longest first on 4
    # shards: the pieces to shards 0 and 1, movies 0, 1, 2 to shards 2, 3, 2. The last piece's
    # shard (1) merges movie 3: fixed 0.5 s and 0.6 s; shard 0 pays the fixed cost for nothing.
    pieces, merges = movie_pieces(p, 0, 1.5)
    check("two pieces of movie 3 by cost", len([x for x in pieces if x[0] == 3]), 2)
    check("cheap movies whole", len(pieces), 5)
    check("a cost piece: planning + half the keys", pieces[3][2], 2.0)
    check("deal by cost", deal_by_cost([1.0, 1.0, 1.0, 2.0, 2.0], 4) == [2, 3, 2, 0, 1], True)
    path, wall = model(p, 2, 2, 1.0, False, 0, piece_seconds=1.5)
    check("movies by cost: shard 1 bakes the last piece and merges it",
          path["movies"], 0.5 + 2.0 + 0.5 + 0.6)
    serial = serial_part(p, 0.0, False, 0, piece_seconds=1.5)
    check("serial by cost: the last piece and its merge", serial["longest movie"], 2.0 + 0.6)
    self_test_reports(check)
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
    ap.add_argument("--video-segments", action="store_true",
                    help="the mp4 as segments encoded by the compose tasks, then joined (slurm.mk)")
    ap.add_argument("--piece-keys", type=int, default=0,
                    help="movies in pieces of at most K keys (slurm.mk's MOVIE_PIECE_KEYS); 0: whole")
    ap.add_argument("--piece-seconds", type=float, default=0.0,
                    help="the cut by known cost (slurm.mk's MOVIE_PIECE_COSTS, rad-movies "
                    "--piece-costs --piece-seconds T): movies of more than T seconds in pieces "
                    "of about T, the rest whole, dealt longest first; the costs are the run's own")
    ap.add_argument("--interval-windows", action="store_true",
                    help="rad-intervals' item buffers in windows of frames, then the pass over "
                    "their counts (slurm.mk's INTERVAL_WINDOWS)")
    ap.add_argument("--interval-merge-fraction", type=float, default=0.01,
                    help="the pass over the windows' counts, as a fraction of rad-intervals' "
                    "per-frame time (docs/results.md, \"rad-intervals' item buffers by windows\")")
    ap.add_argument("--window-merge-stage", action="store_true",
                    help="rad-global's and rad-intervals' window merges as jobs of their own "
                    "(slurm.mk before the last window task ran them)")
    ap.add_argument("--time-windows", action="store_true",
                    help="with --global-windows: also time rad-global in two windows and their "
                    "merge on one core (global-windows-seconds.json), for the windows' fixed "
                    "cost, a from-scratch key past key 0 and the merge")
    ap.add_argument("--merge-stage", action="store_true",
                    help="with --piece-keys: the merges as a stage of their own (slurm.mk before "
                    "the merges went into the piece tasks)")
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
    if args.time_windows:
        if not args.scene:
            fail("--time-windows needs --scene (the run's scene) and the run's --frames")
        time_global_windows(run_dir, args)
    p = pieces(run_dir)
    if args.video_segments:
        p["video_parts"] = time_video(run_dir)
    one_core = p["wall"]
    print("farm model of %s: one core %.1f s (global %.1f, intervals %.1f, %d movies %.1f + %.2f fixed, "
          "%d frames %.1f + %.2f fixed, ffmpeg %.1f); %d cores per node, %.1f s latency per stage%s%s%s%s%s"
          % (run_dir, one_core, p["global"], p["intervals"], len(p["movies"]),
             sum(s for _, s in p["movies"]), p["movies_fixed"], len(p["frames"]), sum(p["frames"]),
             p["compose_fixed"], p["video"], args.cores, args.latency,
             ", rad-global in time windows" if args.global_windows else "",
             ", rad-intervals' item buffers in windows" if args.interval_windows else "",
             ", movies in pieces of at most %d keys (merged %s)"
             % (args.piece_keys, "as a stage" if args.merge_stage else "in the piece tasks")
             if args.piece_keys else "",
             ", movies of more than %.1f s cut by known cost" % args.piece_seconds
             if args.piece_seconds else "",
             ", the mp4 in segments (encode %.1f, join %.1f, contact sheet %.1f)"
             % (p["video_parts"]["mp4"], p["video_parts"]["concat"], p["video_parts"]["contact"])
             if args.video_segments else ""))
    rows = []
    print("%6s %9s %9s  %s" % ("nodes", "wall s", "speed-up", "critical path (s)"))
    for nodes in [int(x) for x in args.nodes.split(",")]:
        path, wall = model(p, nodes, args.cores, args.latency, args.global_windows,
                           args.piece_keys, args.video_segments, args.merge_stage,
                           args.piece_seconds, args.interval_windows,
                           args.interval_merge_fraction, args.window_merge_stage)
        rows.append({"nodes": nodes, "wall": wall, "path": path})
        print("%6d %9.1f %8.1fx  %s" % (nodes, wall, one_core / wall,
                                        ", ".join("%s %.1f" % kv for kv in path.items())))
    serial = serial_part(p, args.latency, args.global_windows, args.piece_keys,
                         args.video_segments, args.merge_stage, args.piece_seconds,
                         args.interval_windows, args.interval_merge_fraction,
                         args.window_merge_stage)
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
