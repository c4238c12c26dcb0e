#!/usr/bin/env python3
"""The MGF converter of the public-scene corpus (pipelines/corpus) on small MGF texts.

  corpus_converter_test.py --bin BUILD/bin [unittest arguments, e.g. ConverterTest]

ConverterTest writes an MGF scene (a quad, a transformed and an arrayed include, an emitter, a
coloured reflectance, a concave face, a face with a hole joined by a seam, a sphere), converts it
and checks triangle counts, transformed positions, emission and reflectance, in the glTF and as
rad-inspect reads it. HeldOutTest checks that the held-out RenderPark scenes (office2, classroom)
are refused by name by both scripts, before any file is read.
"""
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
CORPUS = os.path.join(ROOT, "pipelines", "corpus")
sys.path.insert(0, CORPUS)

import corpus_test_common  # noqa: E402
import mgf_colour  # noqa: E402
import mgf_to_gltf  # noqa: E402

BIN = None

SUB = """
# one triangle, 1 x 1 in the xy plane, facing +z
v s0 =
\tp 0 0 0
v s1 =
\tp 1 0 0
v s2 =
\tp 0 1 0
o tri
f s0 s1 s2
o
"""

MAIN = """
# A neutral grey 50 % wall: a 2 x 1 quad facing +z (MGF z is up: glTF +y).
m grey =
\tc
\trd 0.5
o quad
v q0 =
\tp 0 0 0
v q1 =
\tp 2 0 0
v q2 =
\tp 2 1 0
v q3 =
\tp 0 1 0
f q0 q1 q2 q3
o
# The include is moved by -t then turned by -rz 90, in that order (MGF spec, xf).
o moved
i sub.mgf -t 10 0 0 -rz 90
o
# Three instances 1 apart in z.
i sub.mgf -t 0 0 5 -a 3 -t 0 0 1
# An emitter: 1 m^2, ed 1000 lm/m^2 in neutral colour, facing down (-z).
m lamp =
\tc
\t\tcxy 0.333333 0.333333
\trd 0
\ted 1000
v e0 =
\tp 0 0 3
v e1 =
\tp 0 1 3
v e2 =
\tp 1 1 3
v e3 =
\tp 1 0 3
o lamp
f e0 e1 e2 e3
o
# A red reflectance: the Rec. 709 red primary at Y = 0.1.
m red =
\tc
\t\tcxy 0.64 0.33
\trd 0.1
\trs 0.05 0.1
# A concave L of area 3 (6 corners: 4 triangles).
v l0 =
\tp 0 0 -1
v l1 =
\tp 2 0 -1
v l2 =
\tp 2 1 -1
v l3 =
\tp 1 1 -1
v l4 =
\tp 1 2 -1
v l5 =
\tp 0 2 -1
o ell
f l0 l1 l2 l3 l4 l5
o
# A 4 x 4 square with a 2 x 2 hole, joined by a seam (MGF has no holes): area 12.
v h0 =
\tp 0 0 -2
v h1 =
\tp 4 0 -2
v h2 =
\tp 4 4 -2
v h3 =
\tp 0 4 -2
v h4 =
\tp 1 1 -2
v h5 =
\tp 1 3 -2
v h6 =
\tp 3 3 -2
v h7 =
\tp 3 1 -2
o holed
f h0 h1 h2 h3 h0 h4 h5 h6 h7 h4
o
# A sphere of radius 0.5: 2 x qcd bands of 4 x qcd segments.
m grey
v sc =
\tp 5 5 5
o ball
sph sc 0.5
o
"""


def _gltf_triangles(path):
    """{node name: [(material index, [3 points])]} of a written glTF."""
    with open(path) as f:
        g = json.load(f)
    with open(os.path.join(os.path.dirname(path), g["buffers"][0]["uri"]), "rb") as f:
        data = f.read()

    def accessor(i):
        a = g["accessors"][i]
        view = g["bufferViews"][a["bufferView"]]
        n = a["count"] * {"VEC3": 3, "SCALAR": 1}[a["type"]]
        return struct.unpack_from(f"<{n}{'f' if a['componentType'] == 5126 else 'I'}", data, view["byteOffset"])

    out = {}
    for node in g["nodes"]:
        if "mesh" not in node:
            continue
        for prim in g["meshes"][node["mesh"]]["primitives"]:
            pos, idx = accessor(prim["attributes"]["POSITION"]), accessor(prim["indices"])
            for k in range(0, len(idx), 3):
                tri = [tuple(pos[3 * idx[k + j]:3 * idx[k + j] + 3]) for j in range(3)]
                out.setdefault(node["name"], []).append((prim["material"], tri))
    return g, out


def _area_normal(tri):
    a, b, c = tri
    u = [b[i] - a[i] for i in range(3)]
    v = [c[i] - a[i] for i in range(3)]
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    length = math.sqrt(sum(x * x for x in n))
    return length / 2, [x / length for x in n]


class ConverterTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        d = cls.tmp.name
        with open(os.path.join(d, "sub.mgf"), "w") as f:
            f.write(SUB)
        with open(os.path.join(d, "main.mgf"), "w") as f:
            f.write(MAIN)
        cls.gltf = os.path.join(d, "out", "main.gltf")
        cls.summary, _ = mgf_to_gltf.convert(os.path.join(d, "main.mgf"), cls.gltf, up="z", qcd=4,
                                             camera={"yfov": 1.0, "keys": [(0.0, (1, 1, 8), (1, 1, 0))]})
        cls.g, cls.nodes = _gltf_triangles(cls.gltf)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_quad_is_two_triangles_facing_up(self):
        tris = self.nodes["quad"]
        self.assertEqual(len(tris), 2)
        self.assertAlmostEqual(sum(_area_normal(t)[0] for _, t in tris), 2.0, places=6)
        for _, t in tris:  # MGF +z is glTF +y; MGF (x, y, z) -> glTF (x, z, -y)
            self.assertEqual([round(c, 6) for c in _area_normal(t)[1]], [0.0, 1.0, 0.0])
        corners = {p for _, t in tris for p in t}
        self.assertEqual(corners, {(0.0, 0.0, 0.0), (2.0, 0.0, 0.0), (2.0, 0.0, -1.0), (0.0, 0.0, -1.0)})

    def test_include_transform_applies_in_order(self):
        # -t 10 0 0 then -rz 90: MGF (0,0,0) -> (10,0,0) -> (0,10,0); glTF (0, 0, -10).
        (_, tri), = self.nodes["moved/sub/tri"]
        expected = [(0.0, 0.0, -10.0), (0.0, 0.0, -11.0), (-1.0, 0.0, -10.0)]
        for p, q in zip(tri, expected):
            self.assertEqual([round(c, 5) for c in p], list(q))

    def test_array_include_makes_named_instances(self):
        for k in range(3):
            (_, tri), = self.nodes[f"sub-2[{k}]/tri"]
            self.assertAlmostEqual(tri[0][1], 5.0 + k, places=5)  # MGF z = 5 + k is glTF y

    def test_emission_from_ed(self):
        (mat, tri), (_, tri2) = self.nodes["lamp"]
        m = self.g["materials"][mat]
        strength = m["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"]
        radiance = [c * strength for c in m["emissiveFactor"]]
        expected = 1000.0 / (math.pi * 183.07)  # ed is lm/m^2 of exitance; 183.07 lm/W
        for c in radiance:
            self.assertAlmostEqual(c, expected, delta=2e-3 * expected)
        self.assertEqual(m["pbrMetallicRoughness"]["baseColorFactor"][:3], [0.0, 0.0, 0.0])
        self.assertEqual([round(c, 6) for c in _area_normal(tri)[1]], [0.0, -1.0, 0.0])

    def test_reflectance_colour(self):
        names = {m["name"]: m for m in self.g["materials"]}
        self.assertEqual(names["grey"]["pbrMetallicRoughness"]["baseColorFactor"], [0.5, 0.5, 0.5, 1.0])
        red = names["red"]["pbrMetallicRoughness"]["baseColorFactor"]
        self.assertAlmostEqual(mgf_colour.luminance(red[:3]), 0.1, places=5)
        self.assertLess(max(red[1], red[2]), 1e-5)
        self.assertEqual(self.summary["dropped"]["red"], [("rs", 0.05)])
        self.assertIn("specular reflectance rs dropped from red (0.05)", mgf_to_gltf.dropped_lines(self.summary))

    def test_concave_face(self):
        tris = self.nodes["ell"]
        self.assertEqual(len(tris), 4)
        self.assertAlmostEqual(sum(_area_normal(t)[0] for _, t in tris), 3.0, places=6)
        for _, t in tris:  # all wound as the face, none outside the L's notch
            self.assertAlmostEqual(_area_normal(t)[1][1], 1.0, places=6)
            cx = sum(p[0] for p in t) / 3
            cz = sum(p[2] for p in t) / 3
            self.assertFalse(cx > 1 and cz < -1, f"triangle {t} in the notch")

    def test_face_with_seamed_hole(self):
        tris = self.nodes["holed"]
        self.assertAlmostEqual(sum(_area_normal(t)[0] for _, t in tris), 12.0, places=6)
        for _, t in tris:
            cx = sum(p[0] for p in t) / 3
            cz = sum(p[2] for p in t) / 3
            self.assertFalse(1 < cx < 3 and -3 < cz < -1, f"triangle {t} in the hole")

    def test_sphere(self):
        tris = self.nodes["ball"]
        self.assertEqual(len(tris), 2 * 16 + 6 * 32)  # two polar fans, six bands of quads
        centre = (5.0, 5.0, -5.0)
        for _, t in tris:
            _, n = _area_normal(t)
            mid = [sum(p[k] for p in t) / 3 - centre[k] for k in range(3)]
            self.assertGreater(sum(n[k] * mid[k] for k in range(3)), 0.0)

    def test_rad_inspect_reads_it(self):
        if BIN is None:
            self.skipTest("no --bin")
        r = subprocess.run([os.path.join(BIN, "rad-inspect"), "--json", self.gltf], capture_output=True, text=True)
        self.assertEqual(r.returncode, 0, r.stderr)
        info = json.loads(r.stdout)
        self.assertEqual(info["triangles"], self.summary["triangles"])
        self.assertEqual(info["triangles"], 2 + 1 + 3 + 2 + 4 + 8 + 224)
        (lamp,) = info["emitters"]
        for watts in lamp["power_w"]:  # pi L A = ed / 183.07 for 1 m^2
            self.assertAlmostEqual(watts, 1000.0 / 183.07, delta=5e-3)


class HeldOutTest(unittest.TestCase):
    """office2 and classroom are kept out of the project for checking (issues 56, 58)."""

    def run_script(self, *args):
        return subprocess.run([sys.executable, *args], capture_output=True, text=True)

    def test_converter_refuses_held_out_files(self):
        with tempfile.TemporaryDirectory() as d:
            for rel in ("office2/office2.mgf", "oficina002/office2.mgf", "salon/classroom.mgf", "x/Classroom.mgf"):
                path = os.path.join(d, rel)
                os.makedirs(os.path.dirname(path), exist_ok=True)
                with open(path, "w") as f:
                    f.write(SUB)
                r = self.run_script(os.path.join(CORPUS, "mgf_to_gltf.py"), path, "-o", os.path.join(d, "o.gltf"))
                self.assertEqual(r.returncode, 1, rel)
                self.assertIn("held-out scene", r.stderr)
                self.assertFalse(os.path.exists(os.path.join(d, "o.gltf")))

    def test_converter_refuses_held_out_includes(self):
        with tempfile.TemporaryDirectory() as d:
            os.makedirs(os.path.join(d, "office2"))
            with open(os.path.join(d, "office2", "x.mgf"), "w") as f:
                f.write(SUB)
            with open(os.path.join(d, "main.mgf"), "w") as f:
                f.write("i office2/x.mgf\n")
            r = self.run_script(os.path.join(CORPUS, "mgf_to_gltf.py"), os.path.join(d, "main.mgf"),
                                "-o", os.path.join(d, "o.gltf"))
            self.assertEqual(r.returncode, 1)
            self.assertIn("held-out scene", r.stderr)

    def test_scenes_refuses_held_out_names(self):
        with tempfile.TemporaryDirectory() as d:
            for name in ("office2", "classroom"):
                r = self.run_script(os.path.join(CORPUS, "scenes.py"), "fetch-and-convert", d, name, "--repo", d)
                self.assertEqual(r.returncode, 1, name)
                self.assertIn("held-out scene", r.stderr)
            self.assertEqual(os.listdir(d), [])

    def test_scene_table_has_no_held_out_file(self):
        import held_out
        import scenes
        for name, entry in scenes.SCENES.items():
            for path in [name, entry["mgf"]] + entry["needs"]:
                held_out.check(path)  # raises on a held-out name


if __name__ == "__main__":
    corpus_test_common.main(sys.modules[__name__])
