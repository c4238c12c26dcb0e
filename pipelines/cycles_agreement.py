#!/usr/bin/env python3
"""Cycles against rad-reference on one scene, both through the pixel centres (issue 56).

Before Cycles references judge anything, the two renderers must agree where there is nothing
to judge: this renders SCENE's frame with pipelines/cycles_reference.py --pixel-filter none and
with rad-reference --pixel-filter none (two seeds, so rad-diff removes the path tracer's noise),
then prints rad-diff's figure (docs/design.md §10) of Cycles against them. A wrong emission
unit shows as a bias, a framing off by a fraction of a pixel or a flipped axis as a large
RMSE at every edge. By default the scene is pipelines/scenes/make_lit_floor.py's.

usage: cycles_agreement.py [--scene SCENE] [--frame F] [--size WxH] [--spp N]
                           [--cycles-spp N] [--bin DIR] [--out DIR] [--check]
  --check   exit 1 unless rmse/mean <= 3 % and |bias| <= 1 % (the test's small renders);
            exit 77 (ctest's skip) when blender is not installed
"""
import argparse
import json
import os
import shutil
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit("cycles_agreement.py: %s failed (%d): %s" %
                 (os.path.basename(cmd[0]) if not cmd[0].endswith("python3") else cmd[1],
                  r.returncode, r.stderr.strip()))
    return r.stdout


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--scene", help="glTF scene (default: a fresh make_lit_floor.py scene)")
    p.add_argument("--frame", type=int, default=0)
    p.add_argument("--size", default="352x240")
    p.add_argument("--spp", type=int, default=1024, help="rad-reference's samples, each seed")
    p.add_argument("--cycles-spp", type=int, default=1024)
    p.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    p.add_argument("--out", default=os.path.join(ROOT, "out", "cycles-agreement"))
    p.add_argument("--check", action="store_true")
    a = p.parse_args()
    if not shutil.which("blender"):
        print("cycles_agreement.py: blender is not installed (pipelines/apt_install.sh blender "
              "python3-numpy); skipped", file=sys.stderr)
        sys.exit(77 if a.check else 4)
    os.makedirs(a.out, exist_ok=True)
    scene = a.scene
    if not scene:
        scene = os.path.join(a.out, "lit-floor.gltf")
        run([sys.executable, os.path.join(HERE, "scenes", "make_lit_floor.py"), scene])
    frames = "%d-%d" % (a.frame, a.frame)
    refs = []
    for seed in (0, 1):
        d = os.path.join(a.out, "reference-s%d" % seed)
        run([os.path.join(a.bin, "rad-reference"), scene, "-o", d, "--frames", frames, "--size",
             a.size, "--spp", str(a.spp), "--seed", str(seed), "--pixel-filter", "none"])
        refs.append(d)
    cycles = os.path.join(a.out, "cycles")
    run([sys.executable, os.path.join(HERE, "cycles_reference.py"), scene, "-o", cycles,
         "--frames", frames, "--size", a.size, "--spp", str(a.cycles_spp), "--pixel-filter",
         "none", "--bin", a.bin])
    out = run([os.path.join(a.bin, "rad-diff"), cycles, refs[0], "--ref2", refs[1], "--json"])
    total = json.loads(out)["difference"]
    rmse, bias = total["rmse_over_mean"], total["bias"]
    print("Cycles --pixel-filter none (%d spp) against rad-reference --pixel-filter none "
          "(2 x %d spp), "
          "%s frame %d at %s: rmse/mean %.2f %%, bias %+.2f %%, the references' noise %.2f %%" %
          (a.cycles_spp, a.spp, os.path.basename(scene), a.frame, a.size, 100 * rmse, 100 * bias,
           100 * total.get("noise_over_mean", float("nan"))))
    if a.check and not (rmse <= 0.03 and abs(bias) <= 0.01):
        sys.exit("cycles_agreement.py: Cycles and rad-reference disagree beyond 3 % / 1 %")


if __name__ == "__main__":
    main()
