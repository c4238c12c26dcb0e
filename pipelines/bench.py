#!/usr/bin/env python3
"""Reproduces the paper's §6 tables with this toolchain (issue 7; docs/design.md §8).

Every configuration runs the whole pipeline twice with the same binaries, one after the
other on this machine:

  coherent    the default: space-time links reused between key times (rad-global), texture
              movies as long as visibility allows, static blockers once per movie (rad-movies);
  scratch     the per-frame static two-pass method the paper compares against:
              rad-global --no-coherence, rad-intervals --max-length 1 (every movie one frame),
              rad-movies --no-coherence (every blocker re-rendered for every frame).

Wall time and peak resident memory are measured per stage from the child processes
(os.wait4), so no external timer is needed. Speed-up = scratch time / coherent time, measured
as a ratio in one run. The coherent and scratch frames are compared with rad-diff.

Both are compared with rad-reference at one frame (midway between two key times near the
middle; --reference-spp, 0 skips it): two independent path-traced references A and B (seeds 0
and 1) give the error of a frame T as docs/design.md §10 defines it, computed by `rad-diff T A --ref2
B`: RMSE / mean and bias over the pixels that are not emitters, the references' own noise
removed (d^2 = (rmse(T,A)^2 + rmse(T,B)^2)/2 - noise^2, noise^2 = mean((A-B)^2)/2). The older
relative L2 (normalised by the reference's RMS, which a visible light dominates) is kept beside
it, labelled as such.

A finished run of one configuration and mode is kept in OUT/NAME/MODE/result.json with the
frames, size, binaries' commit and pinned CPUs it was measured with; a later invocation with the
same settings reuses it, so a long full run that is interrupted resumes where it stopped
(--fresh measures everything again). The texture movies are deleted once a mode is measured
(tens of GB for a full run; --keep-movies keeps them).

usage: bench.py [--frames N] [--size WxH] [--out DIR] [--bin DIR] [--only NAME,...] [--fresh]
                [--reference-spp N] [--keep-movies]
"""
import argparse
import csv
import json
import os
import shlex
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

TABLE2 = ["table-static-static", "table-static-pan", "table-static-follow",
          "table-dynamic-static", "table-dynamic-pan", "table-dynamic-follow"]
TABLE3 = ["cubes-%d" % n for n in (1, 2, 4, 8, 16, 32)]
TABLE5 = ["cubic"]
BUNDLED = {"cornell-moving": os.path.join(HERE, "scenes", "cornell-moving.gltf")}


class Timeout(RuntimeError):
    """run()'s command ran past its limit and was killed: its seconds and peak MiB until then."""

    def __init__(self, message, seconds, peak_mib):
        super().__init__(message)
        self.seconds, self.peak_mib = seconds, peak_mib


def run(cmd, log, limit=None):
    """Runs cmd, its output appended to log; returns (seconds, peak RSS in MiB, CPU seconds).
    Raises RuntimeError on failure, Timeout (killed) after `limit` seconds if given."""
    t0 = time.monotonic()
    with open(log, "ab") as f:
        f.write(("$ " + " ".join(cmd) + "\n").encode())
        f.flush()
        p = subprocess.Popen(cmd, stdout=f, stderr=f)
        while True:
            pid, status, usage = os.wait4(p.pid, 0 if limit is None else os.WNOHANG)
            if pid:
                break
            if time.monotonic() - t0 > limit:
                p.kill()
                _, _, usage = os.wait4(p.pid, 0)
                raise Timeout("%s ran past %g s (see %s)" % (os.path.basename(cmd[0]), limit, log),
                              time.monotonic() - t0, usage.ru_maxrss / 1024.0)
            time.sleep(0.2)
    dt = time.monotonic() - t0
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError("%s failed (see %s)" % (os.path.basename(cmd[0]), log))
    return dt, usage.ru_maxrss / 1024.0, usage.ru_utime + usage.ru_stime


SCRATCH_FLAGS = {"global": ["--no-coherence"], "intervals": ["--max-length", "1"],
                 "movies": ["--no-coherence"], "compose": []}


def stage_commands(bin_dir, scene, out, frames, size, flags):
    """The four stages' command lines as animation.mk writes them (its `stage-commands` target),
    so the pipeline measured here is the one the README runs; flags: stage -> extra arguments,
    passed as the Makefile's STAGE_FLAGS. Returns [(stage, argv)] in pipeline order."""
    fr = frames if isinstance(frames, str) else "0-%d" % (frames - 1)
    make = ["make", "-s", "--no-print-directory", "-C", ROOT, "-f",
            os.path.join(HERE, "animation.mk"), "stage-commands", "BIN=" + os.path.abspath(bin_dir),
            "SCENE=" + os.path.abspath(scene), "OUT=" + os.path.abspath(out), "FRAMES=" + fr, "FPS=24", "SIZE=" + size]
    make += ["%s_FLAGS=%s" % (stage.upper(), shlex.join(args)) for stage, args in flags.items()]
    printed = subprocess.run(make, capture_output=True, text=True, check=True).stdout
    commands = [line.split("\t", 1) for line in printed.splitlines() if "\t" in line]
    return [(stage, shlex.split(command)) for stage, command in commands]


def pipeline(bin_dir, scene, out, frames, size, flags, log):
    """Runs the four stages into out/; flags: stage name -> extra arguments. Returns per-stage
    (seconds, peak MiB, CPU seconds), total seconds and CPU seconds, and overall peak MiB."""
    os.makedirs(out, exist_ok=True)
    flags = {k: list(v) for k, v in flags.items()}
    flags["compose"] = flags.get("compose", []) + ["--no-png"]  # timed: EXR frames only
    stages = {stage: run(argv, log)
              for stage, argv in stage_commands(bin_dir, scene, out, frames, size, flags)}
    total = sum(s[0] for s in stages.values())
    peak = max(s[1] for s in stages.values())
    cpu = sum(s[2] for s in stages.values())
    return {"stages": stages, "total": total, "cpu_total": cpu, "peak_mib": peak}


def run_stages(bin_dir, scene, out, frames, size, flags, log):
    """The four stages of animation.mk into out/, until one fails (its output appended to log).
    Returns {"seconds", "peak_mib", "failed": the stage that failed or None, "error": its last
    `rad-` line or None}: for the scripts that report a failed stage and go on."""
    os.makedirs(out, exist_ok=True)
    result = {"seconds": 0.0, "peak_mib": 0.0, "failed": None, "error": None}
    for stage, argv in stage_commands(bin_dir, scene, out, frames, size, flags):
        try:
            t, mib, _ = run(argv, log)
        except RuntimeError:
            with open(log) as f:
                last = [l for l in f.read().splitlines() if l.startswith("rad-")][-1:]
            result.update(failed=stage, error=last[0] if last else "(see %s)" % log)
            return result
        result["seconds"] += t
        result["peak_mib"] = max(result["peak_mib"], mib)
    return result


def oiiotool_stats(args):
    """`oiiotool ARGS --printstats` as {key: [numbers]}, from lines such as
    `Stats Avg: 1.0 1.0 1.0 (float)` and `NanCount: 0 0 0`."""
    p = subprocess.run(["oiiotool"] + list(args) + ["--printstats"], capture_output=True,
                       text=True, check=True)
    stats = {}
    for line in p.stdout.splitlines():
        key, _, rest = line.strip().partition(":")
        values = []
        for word in rest.split():
            try:
                values.append(float(word))
            except ValueError:
                pass  # "(float)", units
        stats[key] = values
    return stats


def settings_of(bin_dir, frames, size):
    """What a stored result must match to be reused: the run's shape, the binaries (commit of
    the source tree and the rad-* modification times) and the CPUs this process may use."""
    try:
        commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                                capture_output=True, text=True).stdout.strip()
    except OSError:
        commit = ""
    stamps = {t: int(os.path.getmtime(os.path.join(bin_dir, t))) for t in
              ("rad-global", "rad-intervals", "rad-movies", "rad-compose")}
    return {"frames": frames, "size": size, "commit": commit, "binaries": stamps,
            "cpus": sorted(os.sched_getaffinity(0))}


def measured(bin_dir, scene, out, frames, size, flags, log, settings, fresh, keep_movies):
    """pipeline(), or the stored result of an identical earlier run."""
    path = os.path.join(out, "result.json")
    if not fresh and os.path.exists(path):
        try:
            with open(path) as f:
                kept = json.load(f)
            same = {k: v for k, v in kept.get("settings", {}).items() if k != "commit"} == \
                {k: v for k, v in settings.items() if k != "commit"}
            if same and os.path.isdir(os.path.join(out, "frames")):
                return kept["result"]
        except (OSError, ValueError, KeyError):
            pass
    if os.path.exists(path):
        os.remove(path)
    result = pipeline(bin_dir, scene, out, frames, size, flags, log)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump({"settings": settings, "result": result}, f, indent=1)
    os.replace(tmp, path)  # atomic: a killed run leaves no half-written result
    if not keep_movies:
        shutil.rmtree(os.path.join(out, "movies"), ignore_errors=True)
    return result


def link_stats(report_path):
    """Links recomputed per key time from rad-global's report (min, max, mean, % of total)."""
    try:
        with open(report_path) as f:
            r = json.load(f)
    except (OSError, ValueError):
        return None
    keys = r.get("key_times") or []
    rec = [k.get("recomputed") for k in keys if isinstance(k, dict)]
    tot = [k.get("links") for k in keys if isinstance(k, dict)]
    rec = [x for x in rec[1:] if x is not None]  # the first key computes everything
    tot = [x for x in tot[1:] if x]
    if not rec or not tot:
        return None
    return {"min": min(rec), "max": max(rec), "mean": sum(rec) / len(rec),
            "percent": 100.0 * sum(rec) / max(1, sum(tot))}


def frame_difference(bin_dir, a, b):
    """rad_diff of two frame folders, or None when rad-diff is missing or refuses them."""
    try:
        return rad_diff(bin_dir, a, b)
    except (OSError, RuntimeError, ValueError):
        return None


def rad_diff(bin_dir, test, reference, reference2=None):
    """rad-diff's figures (the "difference" object of --json) of test against reference, and
    against a second reference of another seed when given (its noise removed)."""
    extra = ["--ref2", reference2] if reference2 else []
    p = subprocess.run([os.path.join(bin_dir, "rad-diff"), test, reference, "--json"] + extra,
                       capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError("rad-diff %s %s: %s" % (test, reference, p.stderr.strip()))
    return json.loads(p.stdout)["difference"]


class ReferenceNoise:
    """The error figure of docs/design.md §10 against two path-traced references A, B (files or frame
    directories) with independent noise, as rad-diff computes it (`rad-diff T A --ref2 B`):
    RMSE / mean and bias over non-emitting pixels with the references' noise removed, the
    emitters' own figure, and the older relative L2 against A (labelled as such)."""

    def __init__(self, bin_dir, refs):
        self.bin_dir, self.refs = bin_dir, refs
        self.noise = rad_diff(bin_dir, refs[0], refs[0], refs[1])["noise_over_mean"]

    def noise_over_mean(self):
        return self.noise

    def error_of(self, test):
        d = rad_diff(self.bin_dir, test, self.refs[0], self.refs[1])
        return {"rmse_over_mean": d["rmse_over_mean"], "bias": d["bias"],
                "raw_rmse_over_mean": d["raw_rmse_over_mean"],
                "emitter_rmse_over_mean": d["emitter_rmse_over_mean"],
                "relative_l2": d["relative_l2"]}


def reference_filter(flags=None):
    """rad-reference's pixel-filter arguments for the frames a pipeline makes with `flags` (stage
    -> extra arguments): the frames' filter is rad-intervals' (rad-compose reads it from
    intervals.rti), so the reference takes the intervals' --pixel-filter and --filter-width where
    they are given, and otherwise the default both tools share (blackman-harris 1.5)."""
    args = list((flags or {}).get("intervals", []))
    out = []
    for name in ("--pixel-filter", "--filter-width"):
        for i, a in enumerate(args):
            if a == name and i + 1 < len(args):
                out += [name, args[i + 1]]
            elif a.startswith(name + "="):
                out += [name, a.split("=", 1)[1]]
    return out


def reference_difference(bin_dir, scene, out, frame, size, spp, tests, log):
    """The error of each tests[name] frame file against the path-traced references at `frame`
    (ReferenceNoise: RMSE / mean and bias over non-emitters, the references' noise removed); rendered once and kept in
    OUT/reference-FRAME-SPP/. Returns {name: {...}} or None."""
    ref = os.path.join(bin_dir, "rad-reference")
    if not (os.path.exists(ref) and os.path.exists(os.path.join(bin_dir, "rad-diff"))):
        return None
    name = "%04d.exr" % frame
    refs = []
    for seed in (0, 1):
        d = os.path.join(out, "reference-%d-%dspp-filtered-seed%d" % (frame, spp, seed))
        if not os.path.exists(os.path.join(d, name)):
            run([ref, scene, "-o", d, "--frames", "%d-%d" % (frame, frame), "--size", size,
                 "--spp", str(spp), "--seed", str(seed)] + reference_filter(), log)
        refs.append(os.path.join(d, name))

    noise = ReferenceNoise(bin_dir, refs)
    result = {"frame": frame, "spp": spp, "reference_noise_over_mean": noise.noise_over_mean()}
    for label, path in tests.items():
        if os.path.exists(path):
            result[label] = noise.error_of(path)
    return result


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[1])
    ap.add_argument("--frames", type=int, default=400)
    ap.add_argument("--size", default="352x240")
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "bench"))
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--only", default="")
    ap.add_argument("--fresh", action="store_true", help="ignore results of earlier runs")
    ap.add_argument("--reference-spp", type=int, default=128,
                    help="samples per pixel of each of the two references (0: no reference)")
    ap.add_argument("--keep-movies", action="store_true",
                    help="keep the texture movies of measured runs")
    a = ap.parse_args()
    settings = settings_of(a.bin, a.frames, a.size)
    print("bench: commit %s, CPUs %s" % (settings["commit"], settings["cpus"]), file=sys.stderr)
    scenes_dir = os.path.join(a.out, "scenes")
    wanted = [s for s in a.only.split(",") if s] or TABLE2 + TABLE3 + TABLE5
    generated = [w for w in wanted if w not in BUNDLED]
    if generated:
        subprocess.run([sys.executable, os.path.join(HERE, "scenes", "make_paper_scenes.py"),
                        scenes_dir] + generated, check=True, stdout=subprocess.DEVNULL)
    log = os.path.join(a.out, "bench.log")
    rows = []
    for name in wanted:
        scene = BUNDLED.get(name) or os.path.join(scenes_dir, name + ".gltf")
        row = {"scene": name}
        for mode in ("coherent", "scratch"):
            out = os.path.join(a.out, name, mode)
            print("bench: %s %s (%d frames, %s)" % (name, mode, a.frames, a.size),
                  file=sys.stderr, flush=True)
            row[mode] = measured(a.bin, scene, out, a.frames, a.size,
                                 SCRATCH_FLAGS if mode == "scratch" else {}, log, settings,
                                 a.fresh, a.keep_movies)
        row["links"] = link_stats(os.path.join(a.out, name, "coherent", "global-report.json"))
        row["difference"] = frame_difference(a.bin, os.path.join(a.out, name, "coherent", "frames"),
                                             os.path.join(a.out, name, "scratch", "frames"))
        if a.reference_spp > 0:
            # Midway between two key times of rad-movies (--key-step 6), where interpolation
            # between keys is at its worst; at a key time coherent and scratch agree.
            mid = min(a.frames - 1, (a.frames // 2) // 6 * 6 + 3)
            row["reference"] = reference_difference(
                a.bin, scene, os.path.join(a.out, name), mid, a.size, a.reference_spp,
                {m: os.path.join(a.out, name, m, "frames", "%04d.exr" % mid)
                 for m in ("coherent", "scratch")}, log)
        rows.append(row)
        print_tables(rows, a.frames, a.size, sys.stderr)
    write_csv(rows, a.frames, os.path.join(a.out, "tables.csv"))
    with open(os.path.join(a.out, "tables.json"), "w") as f:
        json.dump({"settings": settings, "rows": rows}, f, indent=1)
    print_tables(rows, a.frames, a.size, sys.stdout)


def fmt_row(r, frames):
    c, s = r["coherent"], r["scratch"]
    return (r["scene"], c["total"], c["total"] / frames, s["total"], s["total"] / frames,
            s["total"] / c["total"] if c["total"] > 0 else float("nan"), c["peak_mib"],
            s["peak_mib"])


def print_tables(rows, frames, size, out):
    head = "%-22s %10s %9s %10s %9s %8s %9s %9s" % (
        "scene", "coh. s", "s/frame", "scratch s", "s/frame", "speed-up", "coh. MiB", "scr. MiB")
    for title, names in (("Table 2: table and chairs", TABLE2),
                         ("Tables 3-4: moving cubes", TABLE3), ("Table 5: cubic", TABLE5),
                         ("Bundled scene", list(BUNDLED))):
        sel = [r for r in rows if r["scene"] in names]
        if not sel:
            continue
        print("\n%s (%d frames, %s, this machine)" % (title, frames, size), file=out)
        print(head, file=out)
        for r in sel:
            print("%-22s %10.2f %9.4f %10.2f %9.4f %8.2f %9.1f %9.1f" % fmt_row(r, frames), file=out)
        if names is TABLE3:
            print("%-22s %8s %8s %10s %8s" % ("links updated/key", "min", "max", "average", "%"),
                  file=out)
            for r in sel:
                l = r.get("links")
                if l:
                    print("%-22s %8d %8d %10.1f %8.2f" % (r["scene"], l["min"], l["max"],
                                                          l["mean"], l["percent"]), file=out)
        print("%-22s %s" % ("per stage", "coherent / scratch seconds (speed-up)"), file=out)
        for r in sel:
            st = []
            for k in ("global", "intervals", "movies", "compose"):
                c, sc = r["coherent"]["stages"][k][0], r["scratch"]["stages"][k][0]
                st.append("%s %.1f/%.1f (%.1fx)" % (k, c, sc, sc / c if c > 0 else float("nan")))
            print("%-22s %s" % (r["scene"], ", ".join(st)), file=out)
        diffs = [(r["scene"], r["difference"]) for r in sel if r.get("difference")]
        for name, d in diffs:
            print("%-22s coherent vs scratch: %s" % (name, json.dumps(d)[:200]),
                  file=out)
        refs = [(r["scene"], r["reference"]) for r in sel if r.get("reference")]
        for name, d in refs:
            fig = lambda m, k: 100 * d.get(m, {}).get(k, float("nan"))
            print("%-22s vs rad-reference at frame %d (%d spp x 2, noise %.2f %% of the mean "
                  "removed), over non-emitters: coherent RMSE/mean %.2f %% bias %+.2f %%, "
                  "scratch %.2f %% bias %+.2f %%" % (
                      name, d["frame"], d["spp"], 100 * d["reference_noise_over_mean"],
                      fig("coherent", "rmse_over_mean"), fig("coherent", "bias"),
                      fig("scratch", "rmse_over_mean"), fig("scratch", "bias")), file=out)
    out.flush()


def write_csv(rows, frames, path):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["scene", "frames", "coherent_s", "coherent_s_per_frame", "scratch_s",
                    "scratch_s_per_frame", "speedup", "coherent_peak_mib", "scratch_peak_mib",
                    "links_min", "links_max", "links_mean", "links_percent",
                    "coherent_vs_reference_rmse_over_mean", "coherent_vs_reference_bias",
                    "scratch_vs_reference_rmse_over_mean", "scratch_vs_reference_bias",
                    "coherent_vs_reference_rel_l2", "scratch_vs_reference_rel_l2"]
                   + ["coherent_%s_s" % s for s in ("global", "intervals", "movies", "compose")]
                   + ["scratch_%s_s" % s for s in ("global", "intervals", "movies", "compose")])
        for r in rows:
            l = r.get("links") or {}
            ref = r.get("reference") or {}
            w.writerow(list(fmt_row(r, frames)[:1]) + [frames] + list(fmt_row(r, frames)[1:])
                       + [l.get("min"), l.get("max"), l.get("mean"), l.get("percent")]
                       + [ref.get(m, {}).get(k) for m in ("coherent", "scratch")
                          for k in ("rmse_over_mean", "bias")]
                       + [ref.get(m, {}).get("relative_l2") for m in ("coherent", "scratch")]
                       + [r["coherent"]["stages"][s][0] for s in
                          ("global", "intervals", "movies", "compose")]
                       + [r["scratch"]["stages"][s][0] for s in
                          ("global", "intervals", "movies", "compose")])


if __name__ == "__main__":
    main()
