#!/usr/bin/env python3
"""Numerical extremes through the real tools (docs/design.md §9, issue 15), at the default settings.

Variants of the bundled Cornell scene (one frame, 88x60), each run through the four stages of
animation.mk (bench.stage_commands: the same command lines):

  base          the scene as it is
  emission 1e-6 / 1e6   every emitter x 1e-6 / x 1e6: frames scale linearly (1e-6 relative)
  scale 1e-3 / 1e4      the whole scene (meshes, camera, clip planes) x 1e-3 / x 1e4: frames
                        unchanged (1e-4 relative)
  rho 0         every reflectance 0: direct light only
  sliver        a sliver triangle (aspect 1e-4) lying on the floor, touching the walls' edges

Every frame must be finite and non-negative (no NaN, no Inf), and every stage must exit 0.
The scene's walls already meet along edges (the form-factor kernel is singular there).

usage: extremes.py [--bin DIR] [--out DIR] [--size 88x60] [--check]
  --check   exit 1 on the first violated bound (the ctest `pipeline_extremes` runs it)
"""
import argparse
import base64
import copy
import json
import os
import struct
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import bench  # noqa: E402
import furnace  # noqa: E402

SCENE = os.path.join(HERE, "scenes", "cornell-moving.gltf")


def scaled_emission(g, k):
    for m in g["materials"]:
        ext = m.setdefault("extensions", {})
        if "emissiveFactor" in m and any(m["emissiveFactor"]):
            s = ext.setdefault("KHR_materials_emissive_strength", {"emissiveStrength": 1.0})
            s["emissiveStrength"] = s.get("emissiveStrength", 1.0) * k
    used = g.setdefault("extensionsUsed", [])
    if "KHR_materials_emissive_strength" not in used:
        used.append("KHR_materials_emissive_strength")
    return g


def scaled_scene(g, s):
    """Every root node's translation and every mesh node's scale x s; the cameras' clip planes
    x s (animation channels of translation x s too)."""
    roots = set(g["scenes"][g.get("scene", 0)]["nodes"])
    for i, n in enumerate(g["nodes"]):
        if i not in roots:
            continue
        if "translation" in n:
            n["translation"] = [x * s for x in n["translation"]]
        if "mesh" in n:
            n["scale"] = [x * s for x in n.get("scale", [1.0, 1.0, 1.0])]
    for c in g.get("cameras", []):
        p = c.get("perspective", {})
        for key in ("znear", "zfar"):
            if key in p:
                p[key] *= s
    # Animated translations: the sampler outputs (float VEC3 accessors) x s.
    buffers = [bytearray(base64.b64decode(b["uri"].split(",", 1)[1])) for b in g["buffers"]]
    for a in g.get("animations", []):
        for ch in a["channels"]:
            if ch["target"]["path"] != "translation":
                continue
            acc = g["accessors"][a["samplers"][ch["sampler"]]["output"]]
            view = g["bufferViews"][acc["bufferView"]]
            buf = buffers[view["buffer"]]
            off = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
            for k in range(3 * acc["count"]):
                (x,) = struct.unpack_from("<f", buf, off + 4 * k)
                struct.pack_into("<f", buf, off + 4 * k, x * s)
            for key in ("min", "max"):
                if key in acc:
                    acc[key] = [struct.unpack("<f", struct.pack("<f", x * s))[0] for x in acc[key]]
    for b, data in zip(g["buffers"], buffers):
        b["uri"] = "data:application/octet-stream;base64," + base64.b64encode(bytes(data)).decode()
    return g


def black_materials(g):
    for m in g["materials"]:
        m.setdefault("pbrMetallicRoughness", {})["baseColorFactor"] = [0.0, 0.0, 0.0, 1.0]
    return g


def add_mesh(g, name, triangles, material):
    """Appends a mesh node of `triangles` (lists of three (x, y, z), counter-clockwise seen from
    the front) with one material, its data in a buffer of its own."""
    pts = [p for t in triangles for p in t]
    data = b"".join(struct.pack("<3f", *p) for p in pts)
    idx = b"".join(struct.pack("<H", i) for i in range(len(pts)))
    pad = b"\0" * (-len(idx) % 4)
    g["buffers"].append({"byteLength": len(data) + len(idx) + len(pad),
                         "uri": "data:application/octet-stream;base64," +
                                base64.b64encode(data + idx + pad).decode()})
    b = len(g["buffers"]) - 1
    g["bufferViews"] += [{"buffer": b, "byteOffset": 0, "byteLength": len(data)},
                         {"buffer": b, "byteOffset": len(data), "byteLength": len(idx)}]
    v = len(g["bufferViews"]) - 2
    f32 = lambda x: struct.unpack("<f", struct.pack("<f", x))[0]  # noqa: E731
    g["accessors"] += [{"bufferView": v, "componentType": 5126, "count": len(pts), "type": "VEC3",
                        "min": [f32(min(p[k] for p in pts)) for k in range(3)],
                        "max": [f32(max(p[k] for p in pts)) for k in range(3)]},
                       {"bufferView": v + 1, "componentType": 5123, "count": len(pts),
                        "type": "SCALAR"}]
    a = len(g["accessors"]) - 2
    g["meshes"].append({"name": name, "primitives": [
        {"attributes": {"POSITION": a}, "indices": a + 1, "material": material}]})
    g["nodes"].append({"name": name, "mesh": len(g["meshes"]) - 1})
    g["scenes"][g.get("scene", 0)]["nodes"].append(len(g["nodes"]) - 1)
    return g


def with_sliver(g):
    """A triangle 0.5 m long and 50 um wide, 1 mm above the floor, from wall to wall."""
    return add_mesh(g, "sliver", [[(0.0, 0.001, 0.3), (0.556, 0.001, 0.30005),
                                   (0.556, 0.001, 0.3)]], 0)


VARIANTS = [
    ("base", lambda g: g),
    ("emission-1e-6", lambda g: scaled_emission(g, 1e-6)),
    ("emission-1e6", lambda g: scaled_emission(g, 1e6)),
    ("scale-1e-3", lambda g: scaled_scene(g, 1e-3)),
    ("scale-1e4", lambda g: scaled_scene(g, 1e4)),
    ("rho-0", black_materials),
    ("sliver", with_sliver),
]


def run_variant(bin_dir, out_root, name, gltf, size):
    """Writes the variant's scene to OUT_ROOT/NAME/scene.gltf and runs the four stages there on
    frame 0. Returns (its folder, bench.run_stages' result)."""
    out = os.path.join(out_root, name)
    os.makedirs(out, exist_ok=True)
    scene = os.path.join(out, "scene.gltf")
    with open(scene, "w") as f:
        json.dump(gltf, f)
    log = os.path.join(out, "pipeline.log")
    open(log, "w").close()
    return out, bench.run_stages(bin_dir, scene, out, "0-0", size, {}, log)


def frame_stats(path):
    mean, lo, bad = furnace.exr_mean(path)
    return {"mean": mean, "min": lo, "non_finite": bad}


def relative_difference(a, b, scale_a, out):
    """max |scale_a * a - b| / max |b| over every sample (oiiotool), b the reference."""
    scaled = os.path.join(out, "scaled.exr")
    subprocess.run(["oiiotool", a, "--mulc", repr(scale_a), "-d", "float", "-o", scaled],
                   check=True, capture_output=True)
    diff = bench.oiiotool_stats([scaled, b, "--absdiff"])["Stats Max"]
    ref = bench.oiiotool_stats([b, "--abs"])["Stats Max"]
    return max(diff) / max(max(ref), 1e-300)

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "extremes"))
    ap.add_argument("--size", default="88x60")
    ap.add_argument("--check", action="store_true")
    a = ap.parse_args()
    with open(SCENE) as f:
        source = json.load(f)
    frames, failures = {}, []
    print("%-14s %12s %12s %6s  %s" % ("variant", "frame mean", "min", "bad", "note"))
    for name, make in VARIANTS:
        out, r = run_variant(a.bin, a.out, name, make(copy.deepcopy(source)), a.size)
        if r["failed"]:
            failures.append("%s: %s failed: %s" % (name, r["failed"], r["error"]))
            print("%-14s %12s %12s %6s  %s failed" % (name, "-", "-", "-", r["failed"]))
            continue
        frames[name] = os.path.join(out, "frames", "0000.exr")
        s = frame_stats(frames[name])
        note = ""
        if s["non_finite"] or s["min"] < 0:
            note = "NON-FINITE OR NEGATIVE"
            failures.append("%s: frame has NaN, Inf or negative values" % name)
        print("%-14s %12.6g %12.6g %6d  %s" % (name, s["mean"], s["min"], s["non_finite"], note))
    bounds = [("emission-1e-6", 1e6, 1e-6), ("emission-1e6", 1e-6, 1e-6),
              ("scale-1e-3", 1.0, 1e-4), ("scale-1e4", 1.0, 1e-4)]
    for name, k, bound in bounds:
        if name not in frames or "base" not in frames:
            continue
        d = relative_difference(frames[name], frames["base"], k, os.path.join(a.out, name))
        ok = d <= bound
        print("%-14s max |%g x frame - base| / max |base| = %.3g (bound %g)%s" % (
            name, k, d, bound, "" if ok else "  EXCEEDED"))
        if not ok:
            failures.append("%s: frames differ from base by %.3g relative (bound %g)" %
                            (name, d, bound))
    if a.check and failures:
        sys.exit("extremes.py: " + "; ".join(failures))


if __name__ == "__main__":
    main()
