#!/usr/bin/env python3
"""The image figures of issue 56 per scene (docs/design.md §10), printed as one table and
written to OUT/image-figures.csv: `make -f pipelines/bench.mk image`.

For each scene and preset, the four stages of animation.mk (bench.stage_commands, with
rad-intervals writing its item buffers) over FRAMES, then at EVAL_FRAME against two rad-reference
renders of different seeds with the frames' pixel filter (the default of both tools), through
`rad-diff --ref2 --seams ITEMS --scene SCENE`:

  rmse, bias      RMSE / mean and bias over non-emitting pixels, edges in, the references'
                  noise removed (goal: default <= 2 %, |bias| <= 1 %; final <= 1 %)
  edge, interior  the same figure over edge pixels and interior pixels apart
  struct, floor   the structured error's p95 (7x7-smoothed luminance error, >= 3 px from
                  edges) and the references' own (goal: struct <= floor + 1 point)
  seam            the largest |step(test) - step(ref)| across seams of coplanar patches of one
                  material, relative to the local mean, and the references' floor (goal: <= 1 %
                  beyond the floor)

Scenes: the project's own (--own: the bundled scene, three of the paper's scenes, the four seam
scenes of make_seam_scenes.py) and, with --corpus DIR (the output of
`pipelines/corpus/scenes.py fetch-and-convert DIR`), the public ones found there, each marked
`public` or `held-out` (kept out of tuning). References are kept in OUT/references/ under the
scene file's digest and reused.

usage: image_figures.py [--bin DIR] [--out DIR] [--own a,b|none] [--corpus DIR] [--frames 0-24]
                        [--eval-frame 20] [--size 352x240] [--spp 1024] [--presets default,final]
                        [--check]
  --check   exit 1 unless every row has every figure (ctest `pipeline_image_figures_runs`)
"""
import argparse
import csv
import hashlib
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "corpus"))
import bench  # noqa: E402

PAPER = ("table-static-static", "cubes-8", "cubic")
SEAM_SCENES = ("office-fan", "slivers", "t-junctions", "ngon")
OWN = ("cornell-moving",) + PAPER + SEAM_SCENES
PRESETS = {"default": {}, "final": {"global": ["--preset", "final"],
                                   "movies": ["--preset", "final"]}}
COLUMNS = ("scene", "kind", "preset", "rmse", "bias", "edge", "interior", "struct", "floor",
           "seam", "seam_floor", "noise", "seconds", "peak_mib")


def own_scene(name, work):
    """The glTF file of one of the project's own scenes (the paper's are generated into work/)."""
    committed = os.path.join(HERE, "scenes", name + ".gltf")
    if os.path.exists(committed):
        return committed
    if name in PAPER:
        path = os.path.join(work, name + ".gltf")
        if not os.path.exists(path):
            subprocess.run([sys.executable, os.path.join(HERE, "scenes", "make_paper_scenes.py"),
                            work, name], check=True, capture_output=True)
        return path
    raise SystemExit("image_figures.py: %s: not one of the project's scenes (%s)"
                     % (name, ", ".join(OWN)))


def corpus_scenes(corpus):
    """(name, path, kind) of every converted scene in a scenes.py output folder."""
    import scenes  # noqa: E402 (pipelines/corpus/scenes.py: the table of public scenes)
    found = []
    for name, entry in scenes.SCENES.items():
        path = os.path.join(corpus, name, name + ".gltf")
        if os.path.exists(path):
            found.append((name, path, "held-out" if entry["held_out"] else "public"))
    return found


def digest(path):
    h = hashlib.sha256()
    for p in [path] + [os.path.splitext(path)[0] + ".bin"]:
        if os.path.exists(p):
            with open(p, "rb") as f:
                h.update(f.read())
    return h.hexdigest()[:12]


def references(args, name, scene, log):
    """Two rad-reference renders of EVAL_FRAME (seeds 0 and 1), kept under the scene's digest."""
    frame = args.eval_frame
    paths = []
    for seed in (0, 1):
        d = os.path.join(args.out, "references", "%s-%s-%d-%s-%dspp-seed%d" % (
            name, digest(scene), frame, args.size, args.spp, seed))
        f = os.path.join(d, "%04d.exr" % frame)
        if not os.path.exists(f):
            bench.run([os.path.join(args.bin, "rad-reference"), scene, "-o", d, "--frames",
                       "%d-%d" % (frame, frame), "--size", args.size, "--spp", str(args.spp),
                       "--seed", str(seed)], log)
        paths.append(f)
    return paths


def figures(args, scene, frames_dir, items_dir, refs):
    """rad-diff's figures of one frame against the two references, in percent."""
    name = "%04d.exr" % args.eval_frame
    p = subprocess.run([os.path.join(args.bin, "rad-diff"), os.path.join(frames_dir, name),
                        refs[0], "--ref2", refs[1], "--seams", os.path.join(items_dir, name),
                        "--scene", scene, "--json"], capture_output=True, text=True)
    if p.returncode != 0:
        raise RuntimeError(p.stderr.strip())
    d = json.loads(p.stdout)
    diff, seams = d["difference"], d.get("seams", {})
    st, regions = diff.get("structured_error", {}), diff.get("regions", {})
    pct = lambda v: None if v is None else 100.0 * v  # noqa: E731
    return {"rmse": pct(diff["rmse_over_mean"]), "bias": pct(diff["bias"]),
            "edge": pct(regions.get("edge", {}).get("rmse_over_mean")),
            "interior": pct(regions.get("interior", {}).get("rmse_over_mean")),
            "struct": pct(st.get("p95")), "floor": pct(st.get("reference_floor_p95")),
            "seam": pct(seams.get("excess", {}).get("max_abs")),
            "seam_floor": pct(seams.get("reference_floor_max_abs")),
            "noise": pct(diff["noise_over_mean"])}


def measure(args, name, scene, kind, preset, log):
    out = os.path.join(args.out, name, preset)
    items = os.path.join(out, "items")
    flags = {k: list(v) for k, v in PRESETS[preset].items()}
    flags["intervals"] = flags.get("intervals", []) + ["--item-buffers", items]
    row = {"scene": name, "kind": kind, "preset": preset}
    try:
        run = bench.pipeline(args.bin, scene, out, args.frames, args.size, flags, log)
        row.update(seconds=run["total"], peak_mib=run["peak_mib"])
        row.update(figures(args, scene, os.path.join(out, "frames"), items,
                           references(args, name, scene, log)))
    except (RuntimeError, OSError, ValueError, KeyError) as e:
        row["error"] = str(e).splitlines()[-1] if str(e) else type(e).__name__
    return row


def fmt(v, spec="%.2f"):
    return "-" if v is None else spec % v


def verdict(row):
    """Which of issue 56's goals a row misses (empty: none)."""
    miss = []
    goal = 2.0 if row["preset"] == "default" else 1.0
    if row.get("rmse") is not None and row["rmse"] > goal:
        miss.append("rmse>%g" % goal)
    if row.get("bias") is not None and abs(row["bias"]) > 1.0:
        miss.append("|bias|>1")
    if row.get("struct") is not None and row.get("floor") is not None \
            and row["struct"] > row["floor"] + 1.0:
        miss.append("struct>floor+1")
    if row.get("seam") is not None and row.get("seam_floor") is not None \
            and row["seam"] > row["seam_floor"] + 1.0:
        miss.append("seam>floor+1")
    return ",".join(miss) or "ok"


def print_table(rows, args):
    print("image figures at frame %d of %s, %s, references 2 x %d spp (percent of the mean)"
          % (args.eval_frame, args.frames, args.size, args.spp))
    head = "%-20s %-8s %-7s %6s %6s %6s %6s %6s %6s %6s %6s %7s  %s" % (
        "scene", "kind", "preset", "rmse", "bias", "edge", "inter", "struct", "floor", "seam",
        "sfloor", "s", "goals")
    print(head)
    for r in rows:
        if "error" in r:
            print("%-20s %-8s %-7s failed: %s" % (r["scene"], r["kind"], r["preset"], r["error"]))
            continue
        print("%-20s %-8s %-7s %6s %6s %6s %6s %6s %6s %6s %6s %7s  %s" % (
            r["scene"], r["kind"], r["preset"], fmt(r["rmse"]), fmt(r["bias"]), fmt(r["edge"]),
            fmt(r["interior"]), fmt(r["struct"]), fmt(r["floor"]), fmt(r["seam"]),
            fmt(r["seam_floor"]), fmt(r["seconds"], "%.1f"), verdict(r)))


def write_csv(rows, path):
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(path), suffix=".tmp")
    with os.fdopen(fd, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=COLUMNS + ("goals", "error"), extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(dict(r, goals="" if "error" in r else verdict(r)))
    os.replace(tmp, path)  # atomic: a killed run leaves the previous table


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog=__doc__.split("\n\n", 1)[1])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--out", default="out/image")
    ap.add_argument("--own", default=",".join(OWN), help="own scenes, comma-separated, or none")
    ap.add_argument("--corpus", help="folder of scenes.py fetch-and-convert (public scenes)")
    ap.add_argument("--frames", default="0-24")
    ap.add_argument("--eval-frame", type=int, default=20)
    ap.add_argument("--size", default="352x240")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--presets", default="default,final")
    ap.add_argument("--check", action="store_true",
                    help="exit 1 unless every row has every figure")
    args = ap.parse_args()
    args.out = os.path.abspath(args.out)
    presets = [p for p in args.presets.split(",") if p]
    for p in presets:
        if p not in PRESETS:
            ap.error("--presets: %s is not one of %s" % (p, ", ".join(PRESETS)))
    os.makedirs(os.path.join(args.out, "scenes"), exist_ok=True)
    chosen = [] if args.own == "none" else [s for s in args.own.split(",") if s]
    todo = [(n, own_scene(n, os.path.join(args.out, "scenes")), "own") for n in chosen]
    if args.corpus:
        todo += corpus_scenes(args.corpus)
    log = os.path.join(args.out, "image-figures.log")
    rows = []
    for name, scene, kind in todo:
        for preset in presets:
            print("image_figures.py: %s %s ..." % (name, preset), file=sys.stderr, flush=True)
            rows.append(measure(args, name, scene, kind, preset, log))
            write_csv(rows, os.path.join(args.out, "image-figures.csv"))
    print_table(rows, args)
    return exit_status(rows, COLUMNS, args.check, "image_figures.py")


def exit_status(rows, columns, check, prog):
    """1 when a row failed, or with check when a row lacks one of columns' figures (each
    named on stderr); else 0."""
    if any("error" in r for r in rows):
        return 1
    if check:
        missing = [(r["scene"], c) for r in rows for c in columns if r.get(c) is None]
        for scene, column in missing:
            print("%s: %s: no %s figure" % (prog, scene, column), file=sys.stderr)
        return 1 if missing else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
