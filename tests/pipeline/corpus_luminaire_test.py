#!/usr/bin/env python3
"""The corpus converter's luminaires and shells (pipelines/corpus) on small texts the test writes.

  corpus_luminaire_test.py --bin BUILD/bin [unittest arguments, e.g. IesTest]

IesTest: an IES file's flux (a cosine distribution integrates to pi x I0; a uniform one in
quadrant symmetry to 4 pi x I, half up, half down), and MGF's ies entity placed by its transform
and -m multiplier as diffuse emitters of that flux, facing down, whose power rad-inspect reads.
ShellTest: a surface that transmits everything (Radiance's illum around a bulb) is left out, not
kept as a black shell over the lamp.
"""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORPUS = os.path.join(ROOT, "pipelines", "corpus")
sys.path.insert(0, CORPUS)

import ies_luminaire  # noqa: E402
import mgf_to_gltf  # noqa: E402
import corpus_test_common  # noqa: E402
from corpus_test_common import FLOOR_MGF  # noqa: E402

BIN = None
WHITE_EFFICACY = 183.07


def ies_text(vertical, horizontal, candela, width=0.5, length=1.0, height=0.0, units=2, multiplier=1.0):
    """An LM-63-1995 file: one lamp, type C photometry, ballast factors 1."""
    rows = "\n".join(" ".join(f"{c:g}" for c in row) for row in candela)
    return (f"IESNA:LM-63-1995\n[TEST] written by corpus_luminaire_test.py\nTILT=NONE\n"
            f"1 -1 {multiplier:g} {len(vertical)} {len(horizontal)} 1 {units} {width:g} {length:g} {height:g}\n"
            f"1 1 50\n{' '.join(f'{a:g}' for a in vertical)}\n{' '.join(f'{a:g}' for a in horizontal)}\n{rows}\n")


COSINE = ies_text(list(range(0, 91, 5)), [0], [[1000.0 * math.cos(math.radians(t)) for t in range(0, 91, 5)]])

MGF = FLOOR_MGF + """
# Two luminaires 1 m apart, 3 m up, each twice the file's candelas.
ies lum.ies -m 2 -t 1 2 3 -a 2 -t 1 0 0
"""

SHELL = """
m bulb =
\tc
\ted 1000
v b0 =
\tp 0 0 0
v b1 =
\tp 0 0.1 0
v b2 =
\tp 0.1 0.1 0
v b3 =
\tp 0.1 0 0
o lamp
f b0 b1 b2 b3
m illum =
\tts 1 0
v sc =
\tp 0.05 0.05 0
sph sc 0.5
o
"""


class IesTest(unittest.TestCase):
    def test_cosine_distribution_gives_pi_i0_downward(self):
        lum = ies_luminaire.parse(COSINE)
        self.assertAlmostEqual(lum.flux_down, math.pi * 1000.0, delta=2e-3 * math.pi * 1000.0)
        self.assertEqual(lum.flux_up, 0.0)
        self.assertEqual((lum.width, lum.length, lum.height), (0.5, 1.0, 0.0))
        (poly, exitance), = ies_luminaire.emitters(lum)
        self.assertAlmostEqual(exitance, lum.flux_down / 0.5)
        self.assertTrue(all(p[2] == 0.0 for p in poly))

    def test_uniform_quadrants_split_up_and_down_in_feet(self):
        text = ies_text(list(range(0, 181, 10)), [0, 45, 90], [[100.0] * 19] * 3, width=2, length=4, units=1)
        lum = ies_luminaire.parse(text, multiplier=3.0)
        self.assertAlmostEqual(lum.flux_down, 3 * 2 * math.pi * 100.0, delta=1e-3 * 600 * math.pi)
        self.assertAlmostEqual(lum.flux_up, lum.flux_down, delta=1e-6 * lum.flux_down)
        self.assertAlmostEqual(lum.width, 2 * 0.3048)
        self.assertAlmostEqual(lum.length, 4 * 0.3048)
        self.assertEqual(len(ies_luminaire.emitters(lum)), 2)

    def test_no_tilt_line_is_an_error(self):
        with self.assertRaises(ies_luminaire.IesError):
            ies_luminaire.parse(COSINE.replace("TILT=NONE", ""))

    def test_mgf_ies_entity_places_diffuse_emitters(self):
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "lum.ies"), "w") as f:
                f.write(COSINE)
            with open(os.path.join(d, "room.mgf"), "w") as f:
                f.write(MGF)
            gltf = os.path.join(d, "room.gltf")
            summary, _ = mgf_to_gltf.convert(os.path.join(d, "room.mgf"), gltf, up="z",
                                             camera={"yfov": 1.0, "keys": [(0.0, (0, 1, 8), (0, 0, 0))]})
            self.assertEqual(summary["emitting_triangles"], 4)
            self.assertFalse(summary["unknown_entities"])
            flux = 2.0 * ies_luminaire.parse(COSINE).flux_down
            self.assertEqual(summary["luminaires"]["lum.ies"][0], 2)
            self.assertTrue(any(line.startswith("IES luminaire lum.ies (2 placed)")
                                for line in mgf_to_gltf.dropped_lines(summary)))
            with open(gltf) as f:
                g = json.load(f)
            (lamp,) = [m for m in g["materials"] if "emissiveFactor" in m]
            strength = lamp["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"]
            self.assertAlmostEqual(strength, flux / 0.5 / (math.pi * WHITE_EFFICACY), delta=1e-4 * strength)
            if BIN is None:
                return
            r = subprocess.run([os.path.join(BIN, "rad-inspect"), "--json", gltf], capture_output=True, text=True)
            self.assertEqual(r.returncode, 0, r.stderr)
            emitters = json.loads(r.stdout)["emitters"]
            total = sum(e["power_w"][1] for e in emitters)
            self.assertAlmostEqual(total, 2 * flux / WHITE_EFFICACY, delta=1e-3 * total)


class ShellTest(unittest.TestCase):
    def test_fully_transmitting_shell_is_left_out(self):
        with tempfile.TemporaryDirectory() as d:
            with open(os.path.join(d, "bulb.mgf"), "w") as f:
                f.write(SHELL)
            summary, _ = mgf_to_gltf.convert(os.path.join(d, "bulb.mgf"), os.path.join(d, "bulb.gltf"))
            self.assertEqual(summary["triangles"], 2)  # the lamp's quad; no sphere
            (n,) = summary["invisible"].values()  # the sphere's polygons, each counted
            self.assertEqual(summary["invisible"], {"illum": n})
            self.assertGreater(n, 8)
            self.assertIn(f"{n} polygons of illum left out: it transmits everything and reflects nothing",
                          mgf_to_gltf.dropped_lines(summary))


if __name__ == "__main__":
    corpus_test_common.main(sys.modules[__name__])
