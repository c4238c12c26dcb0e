#!/usr/bin/env python3
"""The corpus of public scenes: RenderPark's MGF test scenes, fetched and converted at benchmark time.

  scenes.py fetch-and-convert OUTDIR [SCENE...] [--repo PATH] [--keep REGEX]
  scenes.py list

The scenes come from the public repository OscarChavarro/rpkCpp (a C++ port of RenderPark),
folder etc/. Its licence (GPL-3.0 for the code) does not clearly cover the scenes, so they are
never committed: this script reads them from a copy of that repository, converts them with
mgf_to_gltf.py and adds what an animation needs (a camera path, one moving object), per scene
from the table SCENES in this script. OUTDIR/NAME/NAME.gltf (+ .bin) per scene and OUTDIR/INDEX.txt (triangles,
emitters, bounds, what the converter dropped) are written.

--repo: the repository as a bare git directory (what `git clone --bare` or a mirror gives; the
pinned commit is read, else HEAD with a warning) or a checkout. Default: $RPKCPP_REPO, else the
mirror /work/.mirror/OscarChavarro+rpkCpp/repo. To get it:
  git clone --bare https://github.com/OscarChavarro/rpkCpp rpkCpp.git

The RenderPark scenes office2 and classroom are kept out of the project for checking (issues 56
and 58): they are not in the table, never extracted, and refused by name (held_out.py).
Exit codes: 0 success; 1 bad or refused input, a repository without the scenes; 2 usage.
"""
import argparse
import hashlib
import math
import os
import re
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import held_out  # noqa: E402
import mgf_reader  # noqa: E402
import mgf_to_gltf  # noqa: E402

PROG = "scenes.py"
PINNED_COMMIT = "37e5ff4eede5fd7444916eb06f0379db137fefc9"
DEFAULT_MIRROR = "/work/.mirror/OscarChavarro+rpkCpp/repo"
FPS = 24.0

# Per scene: the MGF file and what it needs beside it (folders), the file's up axis, the circle
# resolution (RenderPark's 4 segments a quarter circle, or 2 where rounded furniture corners
# would multiply the triangles), whether it is kept out of tuning, the camera path (keys of time
# in s, position, target, in glTF coordinates: y up, metres) and one moving object (the objects
# selected by a name pattern and, optionally, lying within a box, merged into one node that
# translates). Every camera looks at walls with furniture and at least one lamp.
SCENES = {
    "graz": {
        "mgf": "etc/office1/graz.mgf", "needs": ["etc/office1"], "up": "z", "qcd": 4,
        "held_out": False,
        # From AutoCAD through Radiance, whose materials are two-sided: its closed objects (wall,
        # floor and ceiling slabs, cabinets: 351 of its 375 m^2) face inward, its lamps outward.
        "orient_closed": True,
        "character": "AutoCAD office (TU Graz): 4 suspended luminaires emitting up and down, "
                     "desks with computers, shelves of binders with thin metal parts, 3 swivel "
                     "chairs; thousands of small objects, slivers",
        "yfov": 60.0,
        "camera": [(0.0, (1.6, 1.55, -0.95), (2.6, 1.6, -4.7)),
                   (1.5, (2.1, 1.55, -1.0), (2.6, 1.6, -4.7)),
                   (3.0, (2.6, 1.55, -1.05), (2.6, 1.6, -4.7))],
        "mover": {"name": "moving_chair", "match": r"chair", "within": ((0.9, -0.1, -3.8), (2.0, 1.3, -2.5)),
                  "keys": [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.45, 0.0, 0.2))]},
    },
    "office3": {
        "mgf": "etc/office3/office.mgf", "needs": ["etc/office3"], "up": "y", "qcd": 2,
        "held_out": True,
        "character": "Radiance office (LBL building 90 model): two ceiling panels flush with the "
                     "ceiling, a desk lamp, a corner desk, bookcases, a window with 24 blind "
                     "slats; rounded furniture edges of cylinders and spheres",
        "yfov": 60.0,
        "camera": [(0.0, (2.0, 2.75, -1.3), (-2.28, 2.7, 0.6)),
                   (1.5, (2.0, 2.75, -0.4), (-2.28, 2.7, 0.6)),
                   (3.0, (2.0, 2.75, 0.5), (-2.28, 2.7, 0.6))],
        "mover": {"name": "moving_chair", "match": r"^chair2(\.|$)",
                  "keys": [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.5, 0.0, -0.1))]},
    },
    "hospital": {
        "mgf": "etc/hospital/hosp.mgf", "needs": ["etc/hospital", "etc/Materials"], "up": "z",
        "qcd": 2, "held_out": True,
        "character": "hospital floor (RenderPark, KU Leuven): corridors, reception, waiting "
                     "room with wall lamps, ceiling panels 1 mm under the ceiling, doors, chairs, "
                     "a coat rack of spheres and cylinders; hosp.mgf includes every piece of "
                     "furniture twice (exact copies dropped)",
        "yfov": 55.0,
        "camera": [(0.0, (5.6, 1.5, -6.6), (3.0, 1.3, -4.7)),
                   (1.5, (5.6, 1.5, -5.9), (3.0, 1.3, -4.7)),
                   (3.0, (5.6, 1.5, -5.2), (3.0, 1.3, -4.7))],
        "mover": {"name": "moving_chair", "match": r"^structure/chair-3\[1\](/|$)",
                  "keys": [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.5, 0.0, 0.0))]},
    },
    "corridor": {
        "mgf": "etc/corridor.mgf", "needs": [], "up": "z", "qcd": 4, "held_out": False,
        "character": "tall L-shaped corridor (RenderPark): 57 small ceiling lamps in rows, a "
                     "pillar, a torus on a pin, a shelf with a sphere; big walls beside small "
                     "lamps, a hexagonal floor",
        "yfov": 55.0,
        "camera": [(0.0, (0.5, 3.0, -1.0), (-1.5, 5.0, -19.0)),
                   (1.5, (0.5, 3.0, -2.5), (-1.5, 5.0, -19.0)),
                   (3.0, (0.5, 3.0, -4.0), (-1.5, 5.0, -19.0))],
        "mover": {"name": "moving_sphere", "match": r"^versiering1$",
                  "keys": [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.8, 0.0, 0.7))]},
    },
    "soda": {
        "mgf": "etc/soda.mgf", "needs": [], "up": "y", "qcd": 2, "held_out": False,
        "character": "ice-cream parlour (Radiance): 5 hanging spherical lamps, tables with "
                     "chairs, a counter with stools, freezers; many curved pieces",
        "yfov": 55.0,
        "camera": [(0.0, (-1.4, 1.6, 6.0), (0.6, 1.2, -2.5)),
                   (1.5, (-0.6, 1.6, 6.0), (0.6, 1.2, -2.5)),
                   (3.0, (0.2, 1.6, 6.0), (0.6, 1.2, -2.5))],
        "mover": {"name": "moving_stool", "match": r"^stool3(\.|$)",
                  "keys": [(0.0, (0.0, 0.0, 0.0)), (3.0, (-0.5, 0.0, 0.0))]},
    },
}


class CorpusError(ValueError):
    pass


# ---- the repository ----------------------------------------------------------------------

def _is_bare(repo):
    return os.path.isfile(os.path.join(repo, "HEAD")) and os.path.isdir(os.path.join(repo, "objects"))


def _git(repo, *args):
    r = subprocess.run(["git", "--git-dir", repo, *args], capture_output=True)
    if r.returncode:
        raise CorpusError(f"{repo}: git {' '.join(args)}: {r.stderr.decode(errors='replace').strip()}")
    return r.stdout


def extract(repo, paths, dest):
    """Copies repository paths (files or folders) under dest; returns the commit read."""
    for p in paths:
        held_out.check(p)
    if _is_bare(repo):
        has_pin = subprocess.run(["git", "--git-dir", repo, "cat-file", "-e", PINNED_COMMIT + "^{commit}"],
                                 capture_output=True).returncode == 0
        commit = PINNED_COMMIT if has_pin else _git(repo, "rev-parse", "HEAD").decode().strip()
        if not has_pin:
            print(f"{PROG}: {repo}: warning: commit {PINNED_COMMIT[:12]} absent; reading HEAD {commit[:12]}",
                  file=sys.stderr)
        listing = _git(repo, "ls-tree", "-r", "--name-only", commit, "--", *paths).decode().splitlines()
        for name in listing:
            held_out.check(name)
            out = os.path.join(dest, name)
            os.makedirs(os.path.dirname(out), exist_ok=True)
            with open(out, "wb") as f:
                f.write(_git(repo, "cat-file", "blob", f"{commit}:{name}"))
        return commit
    for p in paths:
        src = os.path.join(repo, p)
        if os.path.isdir(src):
            for root, _, files in os.walk(src):
                for name in files:
                    rel = os.path.relpath(os.path.join(root, name), repo)
                    held_out.check(rel)
                    os.makedirs(os.path.join(dest, os.path.dirname(rel)), exist_ok=True)
                    shutil.copyfile(os.path.join(root, name), os.path.join(dest, rel))
        elif os.path.isfile(src):
            os.makedirs(os.path.dirname(os.path.join(dest, p)), exist_ok=True)
            shutil.copyfile(src, os.path.join(dest, p))
        else:
            raise CorpusError(f"{repo}: {p}: not in the repository")
    return "checkout"


# ---- the animation -----------------------------------------------------------------------

def _node_bounds(by_material):
    pts = [p for tris in by_material.values() for tri in tris for p in tri]
    return ([min(p[k] for p in pts) for k in range(3)], [max(p[k] for p in pts) for k in range(3)])


def merge_mover(scene, spec):
    """Merges the objects the spec selects into one node named spec['name'], appended last."""
    pattern = re.compile(spec["match"])
    chosen = []
    for name, by_material in scene.nodes.items():
        if not pattern.search(name) or not any(by_material.values()):
            continue
        if "within" in spec:
            lo, hi = _node_bounds(by_material)
            box_lo, box_hi = spec["within"]
            if any(lo[k] < box_lo[k] or hi[k] > box_hi[k] for k in range(3)):
                continue
        chosen.append(name)
    if not chosen:
        raise CorpusError(f"mover {spec['name']}: no object matches '{spec['match']}'")
    merged = {}
    for name in chosen:
        for key, tris in scene.nodes.pop(name).items():
            merged.setdefault(key, []).extend(tris)
    scene.nodes[spec["name"]] = merged
    return chosen


def convert_scene(name, src_root, out_dir, keep=None):
    """Converts one table entry; returns (summary, mover objects). keep: a pattern; only the
    objects whose names match it are written (for bisecting a scene), the mover only if it does."""
    entry = SCENES[name]
    mgf = os.path.join(src_root, entry["mgf"])
    scene = mgf_to_gltf.read(mgf, entry["up"], 1.0, entry["qcd"], entry.get("orient_closed", False))
    if keep:
        pattern = re.compile(keep)
        for node in [n for n in scene.nodes if not pattern.search(n)]:
            del scene.nodes[node]
    try:
        chosen = merge_mover(scene, entry["mover"])
        movers = {entry["mover"]["name"]: entry["mover"]["keys"]}
    except CorpusError:
        if not keep:
            raise
        chosen, movers = [], {}
    camera = {"yfov": math.radians(entry["yfov"]), "keys": entry["camera"]}
    os.makedirs(out_dir, exist_ok=True)
    summary = mgf_to_gltf.write(scene, os.path.join(out_dir, name + ".gltf"), camera=camera, movers=movers,
                                name=name)
    return summary, chosen


def _sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        h.update(f.read())
    return h.hexdigest()


def index_block(name, summary, chosen, mgf_path):
    entry = SCENES[name]
    lo, hi = summary["bounds"]
    keys = entry["camera"]
    end = keys[-1][0]
    frames = int(math.ceil(end * FPS))
    mk = entry["mover"]
    shift = mk["keys"][-1][1]
    lines = [
        f"{name}: {entry['mgf']} ({'held out of tuning' if entry['held_out'] else 'development'})",
        f"  character   {entry['character']}",
        f"  sha256      {_sha256(mgf_path)}",
        f"  triangles   {summary['triangles']} ({summary['emitting_triangles']} emitting, in "
        f"{summary['emitter_objects']} emitting objects); {summary['nodes']} objects, {summary['materials']} materials",
        f"  bounds      x {lo[0]:.3f}..{hi[0]:.3f}  y {lo[1]:.3f}..{hi[1]:.3f}  z {lo[2]:.3f}..{hi[2]:.3f} m (y up)",
        f"  emission    L_e {summary['emission_range'][0]:.4g}..{summary['emission_range'][1]:.4g} W/m2/sr "
        f"(largest channel; physical units: look at the PNGs with COMPOSE_FLAGS=--auto-exposure)",
        f"  animation   {end:g} s = frames 0-{frames - 1} at {FPS:g} fps; camera from "
        f"{tuple(keys[0][1])} to {tuple(keys[-1][1])} looking at {tuple(keys[0][2])}, yfov {entry['yfov']:g} deg",
        (f"  moving      {mk['name']} ({len(chosen)} MGF objects) moves by {shift} m over {mk['keys'][-1][0]:g} s"
         if chosen else "  moving      nothing (the moving object is not among the objects kept)"),
        f"  converter   up {entry['up']}, {entry['qcd']} segments a quarter circle, one-sided surfaces; "
        + ", ".join(f"{n} {k}" for k, n in sorted(summary["faces"].items())) + " faces; "
        + (", ".join(f"{n} {k}" for k, n in sorted(summary["primitives"].items())) or "no primitives"),
    ]
    dropped = mgf_to_gltf.dropped_lines(summary)
    lines += [f"  dropped     {d}" for d in dropped] or ["  dropped     nothing"]
    return "\n".join(lines)


def fetch_and_convert(out, names, repo, keep=None):
    src = os.path.join(out, "src")
    needs = sorted({p for n in names for p in [SCENES[n]["mgf"]] + SCENES[n]["needs"]})
    commit = extract(repo, needs, src)
    blocks = []
    for name in names:
        summary, chosen = convert_scene(name, src, os.path.join(out, name), keep)
        blocks.append(index_block(name, summary, chosen, os.path.join(src, SCENES[name]["mgf"])))
        print(f"{PROG}: {name}: {summary['triangles']} triangles, {summary['emitting_triangles']} emitting "
              f"-> {os.path.join(out, name, name + '.gltf')}", file=sys.stderr)
    header = [
        "# The RenderPark MGF corpus, converted by pipelines/corpus/scenes.py (never committed:",
        "# the scenes' licence is unclear). Source: github.com/OscarChavarro/rpkCpp etc/,",
        f"# commit {commit}." + (f" Only the objects matching '{keep}'." if keep else "") + " Held out of tuning: "
        + ", ".join(n for n in names if SCENES[n]["held_out"]) + ". Not in the corpus at all: office2, classroom.",
        "",
    ]
    with open(os.path.join(out, "INDEX.txt"), "w") as f:
        f.write("\n".join(header) + "\n\n".join(blocks) + "\n")


def main(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n\n".join(__doc__.split("\n\n")[1:]))
    sub = ap.add_subparsers(dest="command", required=True)
    fc = sub.add_parser("fetch-and-convert", help="extract the scenes and convert them into OUTDIR")
    fc.add_argument("outdir")
    fc.add_argument("scenes", nargs="*", help=f"scenes (default all: {', '.join(SCENES)})")
    fc.add_argument("--repo", help="rpkCpp as a bare git directory or a checkout")
    fc.add_argument("--keep", metavar="REGEX",
                    help="write only the objects whose names match (to bisect a scene; not the corpus)")
    sub.add_parser("list", help="print the scenes of the table")
    args = ap.parse_args(argv)
    if args.command == "list":
        for name, e in SCENES.items():
            print(f"{name}\t{e['mgf']}\t{'held-out' if e['held_out'] else 'development'}")
        return 0
    names = args.scenes or list(SCENES)
    try:
        for n in names:
            held_out.check(n)
            if n not in SCENES:
                raise CorpusError(f"{n}: not a scene of the corpus (scenes: {', '.join(SCENES)})")
        repo = args.repo or os.environ.get("RPKCPP_REPO") or DEFAULT_MIRROR
        if not os.path.isdir(repo):
            raise CorpusError(f"{repo}: no copy of rpkCpp here; clone it: git clone --bare "
                              "https://github.com/OscarChavarro/rpkCpp rpkCpp.git, then --repo rpkCpp.git")
        if args.keep:
            re.compile(args.keep)
        fetch_and_convert(args.outdir, names, repo, args.keep)
    except (CorpusError, held_out.HeldOutError, mgf_reader.MgfError, ValueError, re.error) as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
