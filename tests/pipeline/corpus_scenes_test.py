#!/usr/bin/env python3
"""scenes.py's table mechanics on a small git repository the test makes (pipelines/corpus).

  corpus_scenes_test.py [unittest arguments]

A scene composed of two MGF files read in turn, fetched from a bare repository at its pinned
commit (a later commit changes a file, and the pinned one is still what is read), its files
checked against the table's digest (a wrong digest refuses the scene), objects left out by name,
and a mover that takes the triangles within a box from an object holding two mirrored copies.
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "pipelines", "corpus"))

import scenes  # noqa: E402
from corpus_test_common import FLOOR_MGF  # noqa: E402

ROOM = FLOOR_MGF

# A unit quad at x = 2 and its mirror image at x = -2, in one object (as MGF's -my arrays make).
FURN = """
m grey
v c0 =
\tp 2 0 0.5
v c1 =
\tp 3 0 0.5
v c2 =
\tp 3 1 0.5
v c3 =
\tp 2 1 0.5
o chair
xf -a 2 -mx
f c0 c1 c2 c3
xf
o
o clutter
f c1 c2 c3
o
m lamp =
\tc
\ted 1000
v l0 =
\tp 0 0 3
v l1 =
\tp 0 1 3
v l2 =
\tp 1 1 3
v l3 =
\tp 1 0 3
o lamp
f l0 l1 l2 l3
o
"""


def _git(repo, *args, cwd=None):
    return subprocess.run(["git", *args], cwd=cwd or repo, check=True, capture_output=True,
                          text=True, env=dict(os.environ, GIT_AUTHOR_NAME="t", GIT_AUTHOR_EMAIL="t@t",
                                              GIT_COMMITTER_NAME="t", GIT_COMMITTER_EMAIL="t@t")).stdout.strip()


class ScenesTableTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        d = self.tmp.name
        work = os.path.join(d, "work")
        os.makedirs(os.path.join(work, "lib"))
        _git(work, "init", "-q")
        for name, text in (("room.mgf", ROOM), ("furn.mgf", FURN)):
            with open(os.path.join(work, "lib", name), "w") as f:
                f.write(text)
        _git(work, "add", "lib")
        _git(work, "commit", "-q", "-m", "scenes")
        self.pinned = _git(work, "rev-parse", "HEAD")
        with open(os.path.join(work, "lib", "room.mgf"), "a") as f:
            f.write("# a later edit\n")
        _git(work, "commit", "-q", "-am", "later")
        self.bare = os.path.join(d, "repo.git")
        _git(d, "clone", "-q", "--bare", work, self.bare, cwd=d)
        self.saved = dict(scenes.SCENES), dict(scenes.SOURCES)
        scenes.SOURCES["test"] = {"url": "file://" + self.bare, "commit": self.pinned, "mirror": self.bare,
                                  "env": "CORPUS_SCENES_TEST_REPO", "option": "--repo"}
        scenes.SCENES.clear()
        scenes.SCENES["two-parts"] = {
            "source": "test", "mgf": "lib/both.mgf", "parts": ["room.mgf", "furn.mgf"], "needs": ["lib"],
            "up": "z", "qcd": 2, "held_out": True, "character": "a test room", "drop": r"^furn/clutter$",
            "yfov": 50.0, "camera": [(0.0, (0.0, 1.0, 5.0), (0.0, 0.0, 0.0)), (1.0, (1.0, 1.0, 5.0), (0.0, 0.0, 0.0))],
            "mover": {"name": "moving_chair", "match": r"^furn/chair$",
                      "triangles_within": ((1.5, 0.0, -1.5), (3.5, 1.0, 0.5)),
                      "keys": [(0.0, (0.0, 0.0, 0.0)), (1.0, (0.5, 0.0, 0.0))]}}

    def tearDown(self):
        scenes.SCENES.clear()
        scenes.SCENES.update(self.saved[0])
        scenes.SOURCES.clear()
        scenes.SOURCES.update(self.saved[1])
        self.tmp.cleanup()

    def convert(self):
        out = os.path.join(self.tmp.name, "out")
        scenes.fetch_and_convert(out, ["two-parts"], {"test": self.bare})
        with open(os.path.join(out, "INDEX.txt")) as f:
            index = f.read()
        with open(os.path.join(out, "two-parts", "two-parts.gltf")) as f:
            return index, json.load(f), out

    def test_pinned_commit_parts_drop_and_mover(self):
        index, g, out = self.convert()
        with open(os.path.join(out, "src", "test", "lib", "room.mgf")) as f:
            self.assertNotIn("a later edit", f.read())  # the pinned commit, not HEAD
        self.assertIn("room.mgf + furn.mgf read in turn", index)
        self.assertIn("1 objects (1 triangles) left out by the table", index)
        self.assertIn("held out of tuning", index)
        nodes = {n["name"]: n for n in g["nodes"] if "mesh" in n}
        self.assertNotIn("furn/clutter", nodes)
        self.assertIn("moving_chair", nodes)  # the copy at x = 2..3 only; the mirrored one stays

        def triangles(name):
            return sum(g["accessors"][p["indices"]]["count"] // 3
                       for p in g["meshes"][nodes[name]["mesh"]]["primitives"])
        self.assertEqual(triangles("moving_chair"), 2)
        self.assertEqual(triangles("furn/chair"), 2)

    def test_digest_is_checked(self):
        index, _, _ = self.convert()
        digest = index.split("(this file); ")[1].split(" ")[0]
        scenes.SCENES["two-parts"]["digest"] = digest
        self.convert()  # the same files: accepted
        scenes.SCENES["two-parts"]["digest"] = "0" * 64
        with self.assertRaisesRegex(scenes.CorpusError, "digest"):
            self.convert()


if __name__ == "__main__":
    unittest.main(verbosity=2)
