#!/usr/bin/env python3
"""Speed/accuracy curve (issue 7 item 5; docs/design.md §8 "error vs converged reference").

Sweeps each accuracy knob on its own, every other one at its default, on one scene: for every
setting the whole pipeline runs and its frames are compared with a converged path-traced
reference (rad-reference). The error is docs/design.md §10's: RMSE / mean over the pixels that are
not emitters, with the bias beside it (rad-diff). Writes OUT/tradeoff.csv (knob, value, seconds
per frame, RMSE / mean, bias, the older relative L2), OUT/tradeoff.gp and, when gnuplot is installed, OUT/tradeoff.png with the Pareto
front (the settings no other setting beats in both time and error) marked.

Two references with independent noise (seeds 0 and 1) take the reference's own Monte Carlo
noise out of the error, which otherwise hides the knobs' effects (rad-diff --ref2, through
bench.ReferenceNoise). Each setting runs --repeat times and the least CPU time of the four stages
(user + system, all threads) is kept: the outputs are bit-identical, and CPU time is what other
processes on the machine disturb least (wall time of the same run is in the CSV).

usage: tradeoff.py [--scene GLTF] [--frames 0-47] [--size 176x120] [--spp 128] [--repeat 3]
                   [--out DIR] [--eval-frame N] [--references DIR0,DIR1] [--knobs K1,K2]

With --eval-frame the error is that one frame's (references of it alone, or --references'); the
presets (PRESETS: the README's draft and final settings) are rows of their own.
"""
import argparse
import csv
import hashlib
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import bench  # noqa: E402

# knob name -> (stage, flag, the other values swept). The default setting is run once (row
# "default") and belongs to every knob's curve; its value comes from the tool itself
# (`--print-defaults`), not from a copy here.
KNOBS = [
    ("eps", "global", "--eps", ["0.5", "0.1", "0.02", "0.005", "0.001", "0.0001"]),
    ("key-step", "global", "--key-step", ["32", "24", "8", "4"]),
    ("bad-links", "global", "--bad-links", ["none", "partial", "all"]),
    ("rays", "global", "--rays", ["4", "64"]),
    ("texel-density", "intervals", "--texel-density", ["0.25", "0.5", "2"]),
    ("size-ratio", "intervals", "--size-ratio", ["2"]),
    ("level-hysteresis", "intervals", "--level-hysteresis", ["0", "0.2"]),
    ("hidden-gap", "intervals", "--hidden-gap", ["0", "12"]),
    ("movie-key-step", "movies", "--movie-key-step", ["24", "12", "3", "1"]),
    ("max-samples", "movies", "--max-samples", ["4", "8", "16", "32"]),
    ("weak-share", "movies", "--weak-share", ["0", "0.3"]),
    ("gather-rays", "movies", "--gather-rays", ["0", "4", "32"]),
    ("near-shooter-levels", "movies", "--near-shooter-levels", ["1", "2"]),
    ("gather-partial-share", "movies", "--gather-partial-share", ["0.001", "0.004"]),
]
# Combined settings, each one more row of the sweep (knob "preset"): the tools' own quality
# presets (`--preset`, defined once in each stage's parameter table), given to the stages that
# have quality knobs, as the Makefiles' QUALITY does.
PRESETS = [
    ("draft", {"global": ["--preset", "draft"], "movies": ["--preset", "draft"]}),
    ("final", {"global": ["--preset", "final"], "movies": ["--preset", "final"]}),
]
TOOLS = {"global": "rad-global", "intervals": "rad-intervals", "movies": "rad-movies",
         "compose": "rad-compose"}


def knob_defaults(bin_dir):
    """knob -> the default value its tool reports (`TOOL --print-defaults`, one JSON object keyed
    by long option name), as the label of the default on each knob's curve; "default" for a tool
    that cannot be asked (e.g. --replot without binaries)."""
    asked = tool_defaults(bin_dir)
    label = lambda v: "%g" % v if isinstance(v, float) else str(v)
    return {k: label(asked[s][f.lstrip("-")]) if f.lstrip("-") in asked[s] else "default"
            for k, s, f, _ in KNOBS}


def tool_defaults(bin_dir):
    """stage -> its tool's `--print-defaults` object ({} when the tool cannot be asked)."""
    asked = {}
    for stage in TOOLS:
        try:
            p = subprocess.run([os.path.join(bin_dir, TOOLS[stage]), "--print-defaults"],
                               capture_output=True, text=True, check=True)
            asked[stage] = json.loads(p.stdout)
        except (OSError, subprocess.CalledProcessError, ValueError):
            asked[stage] = {}
    return asked


# What counts as a real difference. Timing: the least CPU time of three runs still varies by
# about 5 % on this machine (max-samples 16 and 32 give frames bit-identical to the default's
# and measured 2-5 % faster). Error: the noise-removed estimate moves by well under 1 %
# (relative) between settings that change the frames only slightly.
TIME_TOLERANCE = 0.05
ERROR_TOLERANCE = 0.01


def dominates(a, b, time_tol=TIME_TOLERANCE, err_tol=ERROR_TOLERANCE):
    """a = (seconds, rmse) dominates b: no worse in either, and better beyond the noise in one
    (epsilon-dominance; a setting 1 % faster at the same error is a tie, not a better one)."""
    (ta, ea), (tb, eb) = a, b
    if ta > tb or ea > eb:
        return False
    return ta < tb * (1.0 - time_tol) or ea < eb * (1.0 - err_tol)


def pareto(points, time_tol=TIME_TOLERANCE, err_tol=ERROR_TOLERANCE):
    """Indices of the points no other point dominates, by increasing time."""
    front = [i for i, p in enumerate(points)
             if not any(dominates(q, p, time_tol, err_tol) for q in points)]
    return sorted(front, key=lambda i: points[i][0])


def self_test():
    # Strictly better beyond the noise in one objective, no worse in the other: dominates.
    assert dominates((0.90, 1.0), (1.0, 1.0))
    assert dominates((1.0, 0.98), (1.0, 1.0))
    # Within the noise: a tie, both stay on the front (bit-identical frames timed 2 % apart).
    assert not dominates((0.98, 1.0), (1.0, 1.0))
    assert not dominates((1.0, 0.995), (1.0, 1.0))
    # Worse in one objective never dominates, however much better in the other.
    assert not dominates((0.5, 1.001), (1.0, 1.0))
    assert not dominates((1.001, 0.5), (1.0, 1.0))
    points = [(1.0, 1.0), (0.98, 1.0), (0.5, 2.0), (2.0, 0.5), (1.2, 1.1)]
    assert pareto(points) == [2, 1, 0, 3], pareto(points)  # 0 and 1 tie; 4 is 17 % slower
    assert pareto(points, 0.0, 0.0) == [2, 1, 3], pareto(points, 0.0, 0.0)  # no tolerance
    print("tradeoff.py: self-test passed")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("--scene", default=os.path.join(HERE, "scenes", "cornell-moving.gltf"))
    ap.add_argument("--frames", default="0-47")
    ap.add_argument("--size", default="176x120")
    ap.add_argument("--spp", type=int, default=128)
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "tradeoff"))
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--repeat", type=int, default=3, help="timed runs per setting (fastest kept)")
    ap.add_argument("--eval-frame", type=int, default=None,
                    help="compare only this frame (references of it alone), e.g. one midway "
                         "between key textures, as the README's accuracy table does")
    ap.add_argument("--references", default=None,
                    help="DIR0,DIR1: two existing rad-reference renders with the frames' pixel "
                         "filter (the default, blackman-harris 1.5) of "
                         "different seeds (same scene, size and frames) instead of rendering them")
    ap.add_argument("--knobs", default=None,
                    help="comma-separated knobs (and presets) to sweep; default: all")
    ap.add_argument("--self-test", action="store_true",
                    help="check the Pareto front's dominance rule and exit (ctest runs this)")
    ap.add_argument("--check-knobs", action="store_true",
                    help="check that every swept flag is one of its tool's options, run nothing")
    ap.add_argument("--replot", action="store_true",
                    help="recompute the front and the plot from OUT/tradeoff.csv, run nothing")
    a = ap.parse_args()
    if a.self_test:
        self_test()
        return
    if a.check_knobs:
        check_knobs(a.bin)
        return
    if a.replot:
        replot(a.out, knob_defaults(a.bin))
        return
    os.makedirs(a.out, exist_ok=True)
    log = os.path.join(a.out, "tradeoff.log")
    first, last = (int(x) for x in a.frames.split("-"))
    nframes = last - first + 1

    # The frames' pixel filter (bench.reference_filter): a reference filtered otherwise would
    # add an edge error floor that no accuracy knob moves.
    # Named by the scene's content hash, so that a sweep of another scene into the same --out
    # renders its own references instead of taking another scene's.
    with open(a.scene, "rb") as f:
        scene_hash = hashlib.sha256(f.read()).hexdigest()[:12]
    ref_frames = a.frames if a.eval_frame is None else "%d-%d" % (a.eval_frame, a.eval_frame)
    ref_last = last if a.eval_frame is None else a.eval_frame
    refs = a.references.split(",") if a.references else []
    if a.references and (len(refs) != 2 or not all(
            os.path.exists(os.path.join(r, "%04d.exr" % ref_last)) for r in refs)):
        sys.exit("tradeoff: --references: two directories with %04d.exr expected" % ref_last)
    for seed in (0, 1) if not refs else ():
        ref = os.path.join(a.out, "reference-%s-%s-%s-filtered-%dspp-seed%d" % (
            scene_hash, ref_frames, a.size, a.spp, seed))
        if not os.path.exists(os.path.join(ref, "%04d.exr" % ref_last)):
            print("tradeoff: reference, %d spp, seed %d" % (a.spp, seed), file=sys.stderr,
                  flush=True)
            t, _, _ = bench.run([os.path.join(a.bin, "rad-reference"), a.scene, "-o", ref,
                              "--frames", ref_frames, "--fps", "24", "--size", a.size, "--spp",
                              str(a.spp), "--seed", str(seed)] + bench.reference_filter(), log)
            print("tradeoff: reference took %.1f s" % t, file=sys.stderr)
        refs.append(ref)
    if a.eval_frame is not None:
        refs = [os.path.join(r, "%04d.exr" % a.eval_frame) for r in refs]
    noise = bench.ReferenceNoise(a.bin, refs)
    print("tradeoff: reference noise %.2f %% of the mean, removed from the errors"
          % (100 * noise.noise_over_mean()), file=sys.stderr)

    # The default is timed first and again last (its least CPU time over both is kept): the
    # machine's speed drifts over a 10-minute sweep (another job ending on the other core made
    # later settings 7 % faster than the same computation timed first).
    chosen = set(a.knobs.split(",")) if a.knobs else None
    runs = ([("default", "-", {})]
            + [(k, v, {s: [f, v]}) for k, s, f, vs in KNOBS for v in vs
               if chosen is None or k in chosen]
            + [("preset", name, flags) for name, flags in PRESETS
               if chosen is None or "preset" in chosen or name in chosen]
            + [("default", "-", {})])
    # One untimed run first: the first run pays for cold caches (binaries, scene, references).
    bench.pipeline(a.bin, a.scene, os.path.join(a.out, "runs", "warm-up"), a.frames, a.size, {},
                   log)
    settings = {}  # (knob, value) -> row; insertion order, so the default comes first
    for knob, value, flags in runs:
        out = os.path.join(a.out, "runs", "%s-%s" % (knob, value))
        print("tradeoff: %s = %s" % (knob, value), file=sys.stderr, flush=True)
        try:
            times, walls = [], []
            for _ in range(max(1, a.repeat)):
                r = bench.pipeline(a.bin, a.scene, out, a.frames, a.size, flags, log)
                times.append(r["cpu_total"])
                walls.append(r["total"])
            row = settings.get((knob, value))
            if row is None:  # the frames are compared once: a second timing gives the same frames
                frames = os.path.join(out, "frames")
                if a.eval_frame is not None:
                    frames = os.path.join(frames, "%04d.exr" % a.eval_frame)
                err = noise.error_of(frames)
                row = settings[(knob, value)] = {
                    "knob": knob, "value": value, **err,
                    "peak_mib": r["peak_mib"], "times": [], "walls": []}
        except RuntimeError as e:
            print("tradeoff: %s = %s: %s" % (knob, value, e), file=sys.stderr)
            continue
        row["times"] += times
        row["walls"] += walls
        shutil.rmtree(os.path.join(out, "movies"), ignore_errors=True)  # keep the disk small

    rows = list(settings.values())
    for row in rows:
        t, w = row["times"], row["walls"]
        row.update({"seconds_per_frame": min(t) / nframes,
                    "seconds_spread": (max(t) - min(t)) / min(t),
                    "wall_seconds_per_frame": min(w) / nframes})
    report(a.out, rows, knob_defaults(a.bin))


def check_knobs(bin_dir):
    """Fails when a swept flag is not an option of its tool (a renamed flag would otherwise make
    every run of that knob fail and drop out of the sweep)."""
    unknown = [k for k, d in knob_defaults(bin_dir).items() if d == "default"]
    asked = tool_defaults(bin_dir)
    unknown += ["preset %s: %s" % (name, f) for name, flags in PRESETS
                for stage, args in flags.items() for f in args
                if f.startswith("--") and f[2:] not in asked[stage]]
    if unknown:
        sys.exit("tradeoff.py: %s: not an option of the tool that --print-defaults reports"
                 % ", ".join(unknown))
    print("tradeoff.py: every knob is an option of its tool")


def replot(out, defaults):
    with open(os.path.join(out, "tradeoff.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for k in ("seconds_per_frame", "seconds_spread", "wall_seconds_per_frame",
                  "rmse_over_mean", "bias", "raw_rmse_over_mean", "emitter_rmse_over_mean",
                  "relative_l2", "peak_mib"):
            r[k] = float(r[k])
    report(out, rows, defaults)


def report(out, rows, defaults):
    """Marks the Pareto front, writes the CSV, prints the table and draws the plot."""
    front = pareto([(r["seconds_per_frame"], r["rmse_over_mean"]) for r in rows])
    for i, r in enumerate(rows):
        r["pareto"] = int(i in front)
    csv_path = os.path.join(out, "tradeoff.csv")
    with open(csv_path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["knob", "value", "seconds_per_frame", "seconds_spread",
                                          "wall_seconds_per_frame",
                                          "rmse_over_mean", "bias", "raw_rmse_over_mean",
                                          "emitter_rmse_over_mean", "relative_l2", "peak_mib",
                                          "pareto"], extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    # RMSE/mean and bias over non-emitters (docs/design.md §10); "raw" keeps the references' noise;
    # the relative L2 is the older figure, normalised by the reference's RMS (lights dominate it).
    print("%-14s %-8s %10s %8s %10s %8s %9s %9s %s" % (
        "knob", "value", "CPU s/fr", "spread", "RMSE/mean", "bias", "raw", "rel. L2", "pareto"))
    for r in rows:
        print("%-14s %-8s %10.4f %7.1f%% %9.3f%% %+7.2f%% %8.3f%% %8.3f%% %s" % (
            r["knob"], r["value"], r["seconds_per_frame"], 100 * r["seconds_spread"],
            100 * r["rmse_over_mean"], 100 * r["bias"], 100 * r["raw_rmse_over_mean"],
            100 * r["relative_l2"], "*" if r["pareto"] else ""))
    print("pareto: not dominated by a setting %.0f %% faster at no more error, or %.0f %% more "
          "accurate at no more time" % (100 * TIME_TOLERANCE, 100 * ERROR_TOLERANCE))
    write_plot(out, rows, front, defaults)


def write_plot(out, rows, front, defaults):
    dat = os.path.join(out, "tradeoff.dat")
    with open(dat, "w") as f:
        default = [r for r in rows if r["knob"] == "default"]
        knobs = [k for k, _, _, _ in KNOBS if any(r["knob"] == k for r in rows)]
        for k in knobs:
            # Each knob's curve passes through the default setting, labelled with its value.
            dv = defaults[k]
            pts = [(r["seconds_per_frame"], r["rmse_over_mean"], r["value"]) for r in rows
                   if r["knob"] == k]
            pts += [(r["seconds_per_frame"], r["rmse_over_mean"], dv) for r in default]
            f.write("# %s\n" % k)
            for t, e, v in sorted(pts):
                f.write("%g %g \"%s\"\n" % (t, e, v))
            f.write("\n\n")
        presets = [r for r in rows if r["knob"] == "preset"]
        if presets:  # combined settings: labelled points, not a curve
            f.write("# presets\n")
            for r in presets:
                f.write("%g %g \"%s\"\n" % (r["seconds_per_frame"], r["rmse_over_mean"],
                                            r["value"]))
            f.write("\n\n")
        f.write("# pareto\n")
        for i in front:
            f.write("%g %g\n" % (rows[i]["seconds_per_frame"], rows[i]["rmse_over_mean"]))
        f.write("\n\n# default\n")
        for r in default:
            f.write("%g %g\n" % (r["seconds_per_frame"], r["rmse_over_mean"]))
    gp = os.path.join(out, "tradeoff.gp")
    plots = ["'%s' index %d using 1:2 with linespoints title '%s', '' index %d using 1:2:3 "
             "with labels offset 0.8,0.6 font ',8' notitle" % (dat, i, k, i)
             for i, k in enumerate(knobs)]
    i = len(knobs)
    if presets:
        plots.append("'%s' index %d using 1:2 with points pt 5 ps 1.5 title 'presets', '' index %d "
                     "using 1:2:3 with labels offset 0.8,-0.6 font ',9' notitle" % (dat, i, i))
        i += 1
    plots.append("'%s' index %d using 1:2 with lines lw 3 lc rgb '#80000000' title 'Pareto front'"
                 % (dat, i))
    plots.append("'%s' index %d using 1:2 with points pt 7 ps 2 lc rgb 'black' title 'default'"
                 % (dat, i + 1))
    with open(gp, "w") as f:
        f.write("set terminal pngcairo size 900,600\n" if has_cairo() else
                "set terminal png size 900,600\n")
        f.write("set output '%s'\n" % os.path.join(out, "tradeoff.png"))
        f.write("set logscale xy\nset xlabel 'CPU seconds per frame'\nset ylabel 'RMSE / mean over non-emitters, vs"
                " path-traced reference'\nset key outside right\nset grid\n")
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
