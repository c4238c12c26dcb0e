#!/usr/bin/env python3
"""The corpus of public scenes, in MGF, fetched and converted at benchmark time.

  scenes.py fetch-and-convert OUTDIR [SCENE...] [--repo PATH] [--mgf-repo PATH] [--keep REGEX]
  scenes.py list

Two public repositories (SOURCES): OscarChavarro/rpkCpp (a C++ port of RenderPark), folder etc/,
RenderPark's test scenes; and RichardBruce/data, folder mgf_scenes/, the MGF distribution's own
samples (Greg Ward, LBL: the bathroom, the NRC open-plan office). Neither states a licence that
covers the scenes, so they are never committed: this script reads them from a copy of each
repository at a pinned commit, checks the files it read against the digests in SCENES, converts
them with mgf_to_gltf.py and adds what an animation needs (a camera path, one moving object), per
scene from the table SCENES in this script. OUTDIR/NAME/NAME.gltf (+ .bin) per scene and
OUTDIR/INDEX.txt (triangles, emitters, bounds, what the converter dropped) are written.

--repo, --mgf-repo: each repository as a bare git directory (what `git clone --bare` or a mirror
gives; the pinned commit is read, else HEAD with a warning) or a checkout. Defaults: $RPKCPP_REPO
and $MGF_DATA_REPO, else the mirrors under /work/.mirror/. To get them:
  git clone --bare https://github.com/OscarChavarro/rpkCpp rpkCpp.git
  git clone --bare https://github.com/RichardBruce/data mgf-data.git

The RenderPark scenes office2 and classroom are kept out of the project for checking (issues 56
and 58): they are not in the table, never extracted, and refused by name (held_out.py).
Exit codes: 0 success; 1 bad or refused input, a repository without the scenes, a file whose
digest differs; 2 usage.
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
FPS = 24.0

# The repositories the scenes come from: where to clone them, the commit read, the default copy
# and the environment variable that overrides it.
SOURCES = {
    "rpkCpp": {"url": "https://github.com/OscarChavarro/rpkCpp",
               "commit": "37e5ff4eede5fd7444916eb06f0379db137fefc9",
               "mirror": "/work/.mirror/OscarChavarro+rpkCpp/repo", "env": "RPKCPP_REPO",
               "option": "--repo"},
    "mgf-data": {"url": "https://github.com/RichardBruce/data",
                 "commit": "c5e6cd5be78bb2c1aa14028c6dc60f2b6d6c59d7",
                 "mirror": "/work/.mirror/RichardBruce+data/repo", "env": "MGF_DATA_REPO",
                 "option": "--mgf-repo"},
}

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
    },    # The MGF distribution's samples (SOURCES["mgf-data"]).
    "bathroom": {
        "source": "mgf-data", "mgf": "mgf_scenes/bathroom.mgf", "needs": [], "up": "z", "qcd": 2,
        "held_out": False,
        "digest": "6c605c131dc97c96170031c3ab3d7357cfddadc2b5b524c9693d47659494475c",
        "character": "bathroom (Radiance, measured materials): 4 small bulbs in reflectors on an "
                     "arm above the mirror, a vanity with drawers, a toilet, a tub behind a "
                     "shower door, tiles; a small room of big walls beside thin fittings "
                     "(faucets, towel rack)",
        "yfov": 62.0,
        "camera": [(0.0, (1.0, 1.6, -2.35), (0.15, 1.2, -0.85)),
                   (1.5, (0.9, 1.6, -2.35), (0.15, 1.2, -0.85)),
                   (3.0, (0.8, 1.6, -2.35), (0.15, 1.2, -0.85))],
        "mover": {"name": "moving_toilet", "match": r"^toilet(\.|$)",
                  "keys": [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.2, 0.0, 0.0))]},
    },
    "erw-table": {
        "source": "mgf-data", "mgf": "mgf_scenes/ERW5/scene7.mgf", "needs": [], "up": "y", "qcd": 2,
        "held_out": False,
        "digest": "bdfb78629c356038cbb55ada7d880c1b694dacfd23c9a1045b84e03ff0a4a3c4",
        "character": "Eurographics Rendering Workshop 1994 test scene 7 (Peter Shirley): a 6 x 6 x 3 m "
                     "room, a table and four chairs of thin legs and slats, lit by one 10 cm fixture "
                     "at the ceiling (L_e 1,760 W/m2/sr): one tiny bright lamp over a large room",
        "yfov": 60.0,
        "camera": [(0.0, (-2.6, 1.8, 2.6), (0.0, 1.2, 0.0)),
                   (1.5, (-2.2, 1.8, 2.8), (0.0, 1.2, 0.0)),
                   (3.0, (-1.8, 1.8, 2.9), (0.0, 1.2, 0.0))],
        # The file has no objects: the chair east of the table, by its triangles.
        "mover": {"name": "moving_chair", "match": r"^scene$",
                  "triangles_within": ((0.40, -0.01, -0.30), (0.95, 0.85, 0.25)),
                  "keys": [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.3, 0.0, 0.0))]},
    },
    "nrc-office": {
        # room.mgf's README: the room is material, room, furn and one lighting design together.
        "source": "mgf-data", "needs": ["mgf_scenes/nrcoff"], "up": "z", "qcd": 2,
        "mgf": "mgf_scenes/nrcoff/nrc-design3.mgf",
        "parts": ["material.mgf", "room.mgf", "furn.mgf", "design3.mgf"],
        "held_out": True,
        "digest": "a8b4f7b7f27a73043eed4ca5bdaaa4c501d0007e909a5b7d1149bf8b5dafe428",
        "character": "open-plan office (NRC lighting study, Greg Ward): 12 x 6.7 m, 6 cubicles "
                     "of 1.6 m partitions, desks with drawers, terminals, overhead cabinets, "
                     "chairs; 10 recessed 2 x 4 ft troffers (IES rs4gn) flush with the ceiling",
        # The desk clutter (daffodils in vases, mugs, books, pencils, waste baskets): 24,828 of
        # its 52,656 triangles in objects of a few centimetres.
        "drop": r"/(vase|mug|pencil|openbook|book|wastebasket)(/|$)",
        "yfov": 60.0,
        "camera": [(0.0, (0.6, 2.1, -0.6), (6.5, 0.8, -4.6)),
                   (1.5, (0.9, 2.1, -0.6), (6.5, 0.8, -4.6)),
                   (3.0, (1.2, 2.1, -0.6), (6.5, 0.8, -4.6))],
        # One of the two mirrored chairs of the first cubicles (the node holds both: the
        # triangles within the box are taken).
        "mover": {"name": "moving_chair", "match": r"^furn/cub/cubfurn\[0\]/chair/",
                  "triangles_within": ((3.0, -0.1, -3.0), (3.9, 1.0, -1.7)),
                  "keys": [(0.0, (0.0, 0.0, 0.0)), (3.0, (0.5, 0.0, 0.3))]},
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


def extract(repo, paths, dest, pinned):
    """Copies repository paths (files or folders) under dest; returns the commit read."""
    for p in paths:
        held_out.check(p)
    if _is_bare(repo):
        has_pin = subprocess.run(["git", "--git-dir", repo, "cat-file", "-e", pinned + "^{commit}"],
                                 capture_output=True).returncode == 0
        commit = pinned if has_pin else _git(repo, "rev-parse", "HEAD").decode().strip()
        if not has_pin:
            print(f"{PROG}: {repo}: warning: commit {pinned[:12]} absent; reading HEAD {commit[:12]}",
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


def _inside(tri, box):
    lo, hi = box
    return all(lo[k] <= p[k] <= hi[k] for p in tri for k in range(3))


def merge_mover(scene, spec):
    """Merges what the spec selects into one node named spec['name'], appended last: the objects
    whose names match spec['match'] and, with 'within', whose bounds lie in that box; or, with
    'triangles_within', the matching objects' triangles that lie in that box (an object that
    holds several copies, as MGF's mirrored arrays make, gives one)."""
    pattern = re.compile(spec["match"])
    chosen, merged = [], {}
    for name, by_material in list(scene.nodes.items()):
        if not pattern.search(name) or not any(by_material.values()):
            continue
        if "within" in spec:
            lo, hi = _node_bounds(by_material)
            box_lo, box_hi = spec["within"]
            if any(lo[k] < box_lo[k] or hi[k] > box_hi[k] for k in range(3)):
                continue
        box = spec.get("triangles_within")
        taken = 0
        for key, tris in by_material.items():
            inside = [t for t in tris if box is None or _inside(t, box)]
            merged.setdefault(key, []).extend(inside)
            by_material[key] = [t for t in tris if box is not None and not _inside(t, box)]
            taken += len(inside)
        if not taken:
            continue
        chosen.append(name)
        if not any(by_material.values()):
            del scene.nodes[name]
    if not chosen:
        raise CorpusError(f"mover {spec['name']}: no object matches '{spec['match']}'")
    scene.nodes[spec["name"]] = {k: v for k, v in merged.items() if v}
    return chosen


def _write_parts(entry, src_root):
    """An entry made of several MGF files read in turn (MGF's `i` of each, as the NRC office's
    README composes it) gets a small file that includes them, written beside them."""
    mgf = os.path.join(src_root, entry["mgf"])
    if "parts" in entry:
        with open(mgf, "w") as f:
            f.write("# written by pipelines/corpus/scenes.py\n" + "".join(f"i {p}\n" for p in entry["parts"]))
    return mgf


def drop_objects(scene, pattern):
    """Removes the objects whose names match; returns (objects, triangles) removed."""
    gone = [n for n in scene.nodes if re.search(pattern, n)]
    triangles = sum(len(t) for n in gone for t in scene.nodes[n].values())
    for n in gone:
        del scene.nodes[n]
    return len(gone), triangles


def files_digest(files, src_root):
    """sha256 over the sorted relative paths of every file read and each file's own sha256:
    one figure that changes if any scene file, include or IES file does."""
    h = hashlib.sha256()
    for rel in sorted({os.path.relpath(f, src_root) for f in files}):
        h.update(f"{rel} {_sha256(os.path.join(src_root, rel))}\n".encode())
    return h.hexdigest()


def convert_scene(name, src_root, out_dir, keep=None):
    """Converts one table entry; returns (summary, mover objects). keep: a pattern; only the
    objects whose names match it are written (for bisecting a scene), the mover only if it does.
    CorpusError if the files read differ from the entry's digest."""
    entry = SCENES[name]
    mgf = _write_parts(entry, src_root)
    scene = mgf_to_gltf.read(mgf, entry["up"], 1.0, entry["qcd"], entry.get("orient_closed", False))
    digest = files_digest([f for f in scene.report.files if f != mgf or "parts" not in entry], src_root)
    if entry.get("digest") and digest != entry["digest"]:
        raise CorpusError(f"{mgf}: the files read have digest {digest}, not the table's {entry['digest']} "
                          "(another commit of the repository?)")
    dropped = drop_objects(scene, entry["drop"]) if "drop" in entry else (0, 0)
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
    summary.update({"digest": digest, "dropped_objects": dropped})
    return summary, chosen


def _sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        h.update(f.read())
    return h.hexdigest()


def index_block(name, summary, chosen, mgf_path):
    entry = SCENES[name]
    source = SOURCES[entry.get("source", "rpkCpp")]
    lo, hi = summary["bounds"]
    keys = entry["camera"]
    end = keys[-1][0]
    frames = int(math.ceil(end * FPS))
    mk = entry["mover"]
    shift = mk["keys"][-1][1]
    lines = [
        f"{name}: {entry['mgf']} ({'held out of tuning' if entry['held_out'] else 'development'})",
        f"  source      {source['url']} at {source['commit'][:12]}"
        + (f", {' + '.join(entry['parts'])} read in turn" if "parts" in entry else ""),
        f"  character   {entry['character']}",
        f"  sha256      {_sha256(mgf_path)} (this file); {summary['digest']} (every file read"
        + (", checked" if entry.get("digest") else "") + ")",
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
    objects, triangles = summary["dropped_objects"]
    if objects:
        dropped.append(f"{objects} objects ({triangles} triangles) left out by the table: '{entry['drop']}'")
    lines += [f"  dropped     {d}" for d in dropped] or ["  dropped     nothing"]
    return "\n".join(lines)


def fetch_and_convert(out, names, repos, keep=None):
    """repos: {source: path of its copy}. Extracts each source's files under OUT/src/SOURCE."""
    blocks, commits = [], {}
    for source in sorted({SCENES[n].get("source", "rpkCpp") for n in names}):
        mine = [n for n in names if SCENES[n].get("source", "rpkCpp") == source]
        needs = sorted({p for n in mine for p in ([] if "parts" in SCENES[n] else [SCENES[n]["mgf"]])
                        + SCENES[n]["needs"]})
        commits[source] = extract(repos[source], needs, os.path.join(out, "src", source),
                                  SOURCES[source]["commit"])
    for name in names:
        src = os.path.join(out, "src", SCENES[name].get("source", "rpkCpp"))
        summary, chosen = convert_scene(name, src, os.path.join(out, name), keep)
        blocks.append(index_block(name, summary, chosen, os.path.join(src, SCENES[name]["mgf"])))
        print(f"{PROG}: {name}: {summary['triangles']} triangles, {summary['emitting_triangles']} emitting "
              f"-> {os.path.join(out, name, name + '.gltf')}", file=sys.stderr)
    header = [
        "# The public MGF corpus, converted by pipelines/corpus/scenes.py (never committed: the",
        "# scenes' licence is unclear). Sources: "
        + "; ".join(f"{SOURCES[s]['url']} at commit {c}" for s, c in sorted(commits.items())) + ".",
        "#" + (f" Only the objects matching '{keep}'." if keep else "") + " Held out of tuning: "
        + (", ".join(n for n in names if SCENES[n]["held_out"]) or "none of these")
        + ". Not in the corpus at all: office2, classroom.",
        "",
    ]
    with open(os.path.join(out, "INDEX.txt"), "w") as f:
        f.write("\n".join(header) + "\n\n".join(blocks) + "\n")


def repositories(names, given):
    """{source: path} for the sources the scenes need: the option, else the environment
    variable, else the mirror; CorpusError if a copy is missing."""
    repos = {}
    for source in {SCENES[n].get("source", "rpkCpp") for n in names}:
        spec = SOURCES[source]
        repo = given.get(source) or os.environ.get(spec["env"]) or spec["mirror"]
        if not os.path.isdir(repo):
            clone = os.path.basename(spec["url"]) + ".git"
            raise CorpusError(f"{repo}: no copy of {spec['url']} here; clone it: git clone --bare "
                              f"{spec['url']} {clone}, then {spec['option']} {clone}")
        repos[source] = repo
    return repos


def main(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n\n".join(__doc__.split("\n\n")[1:]))
    sub = ap.add_subparsers(dest="command", required=True)
    fc = sub.add_parser("fetch-and-convert", help="extract the scenes and convert them into OUTDIR")
    fc.add_argument("outdir")
    fc.add_argument("scenes", nargs="*", help=f"scenes (default all: {', '.join(SCENES)})")
    fc.add_argument("--repo", help="rpkCpp as a bare git directory or a checkout")
    fc.add_argument("--mgf-repo", help="RichardBruce/data as a bare git directory or a checkout")
    fc.add_argument("--keep", metavar="REGEX",
                    help="write only the objects whose names match (to bisect a scene; not the corpus)")
    sub.add_parser("list", help="print the scenes of the table")
    args = ap.parse_args(argv)
    if args.command == "list":
        for name, e in SCENES.items():
            print(f"{name}\t{e.get('source', 'rpkCpp')}:{e['mgf']}\t{'held-out' if e['held_out'] else 'development'}")
        return 0
    names = args.scenes or list(SCENES)
    try:
        for n in names:
            held_out.check(n)
            if n not in SCENES:
                raise CorpusError(f"{n}: not a scene of the corpus (scenes: {', '.join(SCENES)})")
        repos = repositories(names, {"rpkCpp": args.repo, "mgf-data": args.mgf_repo})
        if args.keep:
            re.compile(args.keep)
        fetch_and_convert(args.outdir, names, repos, args.keep)
    except (CorpusError, held_out.HeldOutError, mgf_reader.MgfError, ValueError, re.error) as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
