#!/usr/bin/env python3
"""Converts an MGF scene (Greg Ward's Materials and Geometry Format) to glTF 2.0 for rad.

  mgf_to_gltf.py SCENE.mgf -o OUT.gltf [--up z] [--scale 1] [--sides one] [--qcd 4] [--orient-closed]
                 [--camera PX,PY,PZ,TX,TY,TZ] [--yfov 55] [--json]

Reads the file and its includes (i, with transforms and arrays), the transforms (xf), colours
(c, cxy, cspec, cct, cmix), materials (m, rd, ed; rs, ts, td, ir dropped and reported), vertices
(v, p, n), faces (f: convex ones fanned from their first vertex, concave ones and faces with
seams ear-clipped) and the primitives sph, cyl, cone, ring, torus, prism (tessellated as
RenderPark does). Each MGF object (o) becomes a glTF node with its own mesh; geometry is in
world coordinates. See mgf_material.py for the reflectance, emission and sides rules.

Writes OUT.gltf and OUT.bin. A summary (triangles, emitting triangles, bounds, what was dropped)
goes to stderr, or as JSON to stdout with --json. The RenderPark scenes office2 and classroom
are held out of the project and refused by name (held_out.py).

Exit codes: 0 success; 1 bad or refused input; 2 usage; 3 the output cannot be written.
Example:
  mgf_to_gltf.py rpkCpp/etc/office3/office.mgf -o office3.gltf --up y --camera 0,1.6,-1,0,1.2,2
"""
import argparse
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import gltf_writer  # noqa: E402
import held_out  # noqa: E402
import mgf_primitives  # noqa: E402
import mesh_cleanup  # noqa: E402
import mgf_reader  # noqa: E402

PROG = "mgf_to_gltf.py"
UP_AXES = {
    # MGF files are mostly z-up (RenderPark's and Radiance's habit); glTF is y-up.
    "z": ((1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0), (0.0, -1.0, 0.0, 0.0)),
    "y": ((1.0, 0.0, 0.0, 0.0), (0.0, 1.0, 0.0, 0.0), (0.0, 0.0, 1.0, 0.0)),
}


def root_matrix(up, scale):
    m = UP_AXES[up]
    return tuple(tuple(c * scale if k < 3 else c for k, c in enumerate(row)) for row in m)


def convert(mgf_path, gltf_path, up="z", scale=1.0, sides="one", qcd=mgf_primitives.DEFAULT_QCD,
            camera=None, movers=None, name=None, orient_closed=False):
    """Reads and writes one scene; returns the writer's summary plus the reader's report."""
    scene = read(mgf_path, up, scale, qcd, orient_closed)
    return write(scene, gltf_path, sides, camera, movers, name), scene


def read(mgf_path, up="z", scale=1.0, qcd=mgf_primitives.DEFAULT_QCD, orient_closed=False):
    """The MGF scene in glTF's frame, inside-out closed objects turned outward if asked."""
    held_out.check(mgf_path)
    scene = mgf_reader.read(mgf_path, root_matrix(up, scale), qcd)
    if orient_closed:
        scene.report.reoriented = mesh_cleanup.orient_closed_outward(scene)
    return scene


def write(scene, gltf_path, sides="one", camera=None, movers=None, name=None):
    """Writes a read scene; the writer's summary with the reader's report added."""
    summary = gltf_writer.write(scene, gltf_path, sides=sides, camera=camera, movers=movers,
                                name=name or os.path.splitext(os.path.basename(gltf_path))[0])
    r = scene.report
    summary.update({"faces": r.faces, "primitives": r.primitives, "unknown_entities": r.unknown,
                    "faces_with_normals_ignored": r.face_normals, "files": len(r.files),
                    "duplicates": r.duplicates, "reoriented": r.reoriented,
                    "invisible": r.invisible,
                    "luminaires": {os.path.basename(f): v for f, v in r.luminaires.items()}})
    return summary


_COMPONENTS = {"rs": "specular reflectance rs", "ts": "specular transmittance ts",
               "td": "diffuse transmittance td", "ir": "index of refraction ir"}


def dropped_lines(summary):
    """One line per kind of thing the conversion dropped or changed."""
    lines = []
    by_kind = {}
    for material, notes in summary["dropped"].items():
        for kind, what in notes:
            if kind == "changed":
                lines.append(f"material {material}: {what}")
            else:
                by_kind.setdefault(kind, []).append((what, material))
    for kind, label in _COMPONENTS.items():
        found = sorted(by_kind.get(kind, []), reverse=True)
        if len(found) > 3:
            lines.append(f"{label} dropped from {len(found)} materials (largest {found[0][0]:g}: {found[0][1]})")
        elif found:
            lines.append(f"{label} dropped from " + ", ".join(f"{m} ({v:g})" for v, m in found))
    for entity, n in sorted(summary["unknown_entities"].items()):
        lines.append(f"unknown entity '{entity}' skipped {n}x")
    if summary["faces_with_normals_ignored"]:
        lines.append(f"vertex normals of {summary['faces_with_normals_ignored']} faces ignored (flat faces)")
    degenerate = summary["faces"].get("degenerate", 0)
    if degenerate:
        lines.append(f"{degenerate} faces without area skipped")
    for material, n in sorted(summary.get("invisible", {}).items()):
        lines.append(f"{n} polygons of {material} left out: it transmits everything and reflects nothing")
    for ies, (placed, down, up, notes) in sorted(summary.get("luminaires", {}).items()):
        lines.append(f"IES luminaire {ies} ({placed} placed): its candela distribution; kept as diffuse emitters "
                     f"of its output, {down:.0f} lm facing down, {up:.0f} lm facing up, on its luminous opening"
                     + "".join(f"; {n}" for n in notes))
    if summary["duplicates"]:
        lines.append(f"{summary['duplicates']} duplicate triangles (same corners and winding as another) dropped")
    if summary["reoriented"][0]:
        lines.append(f"{summary['reoriented'][0]} closed objects ({summary['reoriented'][1]} triangles) "
                     "faced inward: turned outward")
    forced = summary["faces"].get("ears-forced", 0)
    if forced:
        lines.append(f"{forced} self-intersecting faces cut at their least bad corner")
    return lines


def _camera_arg(text, yfov):
    try:
        v = [float(x) for x in text.split(",")]
    except ValueError:
        v = []
    if len(v) != 6:
        raise argparse.ArgumentTypeError("--camera: expected PX,PY,PZ,TX,TY,TZ")
    return {"yfov": math.radians(yfov), "keys": [(0.0, tuple(v[:3]), tuple(v[3:]))]}


def main(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n\n".join(__doc__.split("\n\n")[1:]))
    ap.add_argument("mgf", help="the MGF file (its includes are read relative to it)")
    ap.add_argument("-o", "--output", required=True, help="the .gltf to write (and its .bin beside it)")
    ap.add_argument("--up", choices=sorted(UP_AXES), default="z", help="the MGF file's up axis (default z)")
    ap.add_argument("--scale", type=float, default=1.0, help="metres per MGF unit after the file's own xf (default 1)")
    ap.add_argument("--sides", choices=["one", "mgf", "two"], default="one",
                    help="one: every surface one-sided, as RenderPark's default; mgf: MGF's sides; two: all two-sided (default one)")
    ap.add_argument("--qcd", type=int, default=mgf_primitives.DEFAULT_QCD,
                    help="segments per quarter circle of sph, cyl, cone, ring, torus (default 4, RenderPark's)")
    ap.add_argument("--orient-closed", action="store_true",
                    help="turn objects that close a surface inside out (faces looking into the solid) outward")
    ap.add_argument("--camera", help="a still camera: PX,PY,PZ,TX,TY,TZ in glTF coordinates (y up)")
    ap.add_argument("--yfov", type=float, default=55.0, help="the camera's vertical field of view in degrees (default 55)")
    ap.add_argument("--json", action="store_true", help="print the summary as JSON on stdout")
    args = ap.parse_args(argv)
    if not (args.scale > 0 and math.isfinite(args.scale)) or args.qcd < 1:
        ap.error("--scale must be positive and finite, --qcd at least 1")
    try:
        camera = _camera_arg(args.camera, args.yfov) if args.camera else None
    except argparse.ArgumentTypeError as e:
        ap.error(str(e))
    try:
        summary, _ = convert(args.mgf, args.output, args.up, args.scale, args.sides, args.qcd, camera,
                             orient_closed=args.orient_closed)
    except (mgf_reader.MgfError, held_out.HeldOutError, ValueError) as e:
        print(f"{PROG}: {e}", file=sys.stderr)
        return 1
    except OSError as e:
        print(f"{PROG}: {e.filename or args.output}: {e.strerror}", file=sys.stderr)
        return 3
    if args.json:
        summary = dict(summary, bounds=[list(b) for b in summary["bounds"]])
        json.dump(summary, sys.stdout, indent=1, sort_keys=True)
        print()
    else:
        lo, hi = summary["bounds"]
        print(f"{PROG}: {args.output}: {summary['triangles']} triangles ({summary['emitting_triangles']} emitting), "
              f"{summary['nodes']} objects, {summary['materials']} materials, bounds "
              f"{', '.join(f'{a:.3f}..{b:.3f}' for a, b in zip(lo, hi))} m", file=sys.stderr)
        for line in dropped_lines(summary):
            print(f"{PROG}: {args.mgf}: {line}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
