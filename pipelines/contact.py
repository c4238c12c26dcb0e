#!/usr/bin/env python3
"""Near-contact geometry against converged references (issue 15, docs/design.md §10), at the
default settings: the configurations where light leaks through, or darkness creeps out of,
geometry that touches or nearly touches.

Static variants of the bundled Cornell scene (its animation dropped, frame 0), each through the
four stages of animation.mk (bench.stage_commands) and two rad-reference renders of different
seeds, compared with rad-diff --ref2 (RMSE / mean and bias over non-emitters, the references'
noise removed):

  empty             the room and its light only (no contact but the walls' edges)
  lamp-one-sided    the light 2 cm under the ceiling, emitting downwards only
  lamp-two-sided    the same light double-sided: it also lights the 2 cm gap above it
  blender-style     every material doubleSided (Blender's glTF exporter default), lamp 2 cm down
  box-on-floor      the tall box standing on the floor
  shelf-on-wall     a 1 cm shelf against the back wall, 25 cm above the floor

usage: contact.py [--bin DIR] [--out DIR] [--size 176x120] [--spp 256] [--only a,b] [--check]
  --check   exit 1 when a variant's stage fails or its |bias| exceeds 2 %; ctest `pipeline_contact`
References are kept in OUT/NAME/reference-seedS and reused when the scene has not changed.
"""
import argparse
import copy
import hashlib
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import bench  # noqa: E402
from extremes import SCENE, add_mesh, run_variant  # noqa: E402

W, H, D = 0.556, 0.5488, 0.5592  # the room (pipelines/scenes/make_cornell_moving.py)
BIAS_BOUND = 0.02


def static_room(g, keep=()):
    """The bundled scene without its animation and without the boxes not in `keep`."""
    names = [n.get("name") for n in g["nodes"]]
    drop = {names.index(b) for b in ("tall_box", "short_box") if b not in keep}
    scene = g["scenes"][g.get("scene", 0)]
    scene["nodes"] = [n for n in scene["nodes"] if n not in drop]
    g.pop("animations", None)
    return g


def lowered_lamp(g, two_sided):
    names = [n.get("name") for n in g["nodes"]]
    g["nodes"][names.index("light")]["translation"] = [0.0, -0.019, 0.0]
    if two_sided:
        for m in g["materials"]:
            if m.get("name") == "light":
                m["doubleSided"] = True
    return g


def all_double_sided(g):
    for m in g["materials"]:
        m["doubleSided"] = True
    return lowered_lamp(g, True)


def shelf(g):
    x0, x1, y0, y1, z0 = 0.05, 0.30, 0.24, 0.25, D - 0.12
    quads = [
        [(x0, y1, z0), (x0, y1, D), (x1, y1, D), (x1, y1, z0)],  # top, +y
        [(x0, y0, z0), (x1, y0, z0), (x1, y0, D), (x0, y0, D)],  # underside, -y
        [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],  # front edge, -z
    ]
    return add_mesh(g, "shelf", [t for q in quads for t in ([q[0], q[1], q[2]], [q[0], q[2], q[3]])],
                    0)


VARIANTS = [
    ("empty", lambda g: static_room(g)),
    ("lamp-one-sided", lambda g: lowered_lamp(static_room(g), False)),
    ("lamp-two-sided", lambda g: lowered_lamp(static_room(g), True)),
    ("blender-style", lambda g: all_double_sided(static_room(g))),
    ("box-on-floor", lambda g: static_room(g, keep=("tall_box",))),
    ("shelf-on-wall", lambda g: shelf(static_room(g))),
]


def reference(bin_dir, scene, out, seed, size, spp, log):
    """rad-reference of frame 0, rendered again only when the scene or the settings change."""
    with open(scene, "rb") as f:
        key = "%s %s %d %s" % (hashlib.sha256(f.read()).hexdigest(), size, spp,
                               " ".join(bench.reference_filter()) or "filtered")
    ref = os.path.join(out, "reference-seed%d" % seed)
    stamp = os.path.join(ref, "made-from")
    if os.path.exists(stamp) and open(stamp).read() == key:
        return ref
    bench.run([os.path.join(bin_dir, "rad-reference"), scene, "-o", ref, "--frames", "0-0",
               "--size", size, "--spp", str(spp), "--seed", str(seed)] + bench.reference_filter(),
              log)
    with open(stamp, "w") as f:
        f.write(key)
    return ref


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "contact"))
    ap.add_argument("--size", default="176x120")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--only", default="")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    failures = []
    with open(SCENE) as f:
        source = json.load(f)
    only = set(a.only.split(",")) if a.only else None
    print("%-16s %12s %9s %12s %8s" % ("variant", "RMSE/mean", "bias", "ref noise", "s"))
    for name, make in VARIANTS:
        if only and name not in only:
            continue
        out, r = run_variant(a.bin, a.out, name, make(copy.deepcopy(source)), a.size)
        seconds, log = r["seconds"], os.path.join(out, "pipeline.log")
        if r["failed"]:
            print("%-16s %12s %9s %12s %8.2f  %s failed: %s" % (name, "-", "-", "-", seconds,
                                                               r["failed"], r["error"]))
            failures.append("%s: %s failed" % (name, r["failed"]))
            continue
        scene = os.path.join(out, "scene.gltf")
        refs = [reference(a.bin, scene, out, s, a.size, a.spp, log) for s in (0, 1)]
        p = subprocess.run([os.path.join(a.bin, "rad-diff"), os.path.join(out, "frames", "0000.exr"),
                            os.path.join(refs[0], "0000.exr"), "--ref2",
                            os.path.join(refs[1], "0000.exr"), "--json"],
                           capture_output=True, text=True, check=True)
        d = json.loads(p.stdout)["difference"]
        print("%-16s %11.2f%% %+8.2f%% %11.2f%% %8.2f" % (
            name, 100 * d["rmse_over_mean"], 100 * d["bias"], 100 * d["noise_over_mean"], seconds))
        if abs(d["bias"]) > BIAS_BOUND:
            failures.append("%s: bias %+.2f %% (bound %g %%)" % (name, 100 * d["bias"],
                                                                100 * BIAS_BOUND))
    if a.check and failures:
        sys.exit("contact.py: " + "; ".join(failures))


if __name__ == "__main__":
    main()
