"""What the corpus tests share: the MGF text they build their scenes on (a grey 10 x 10 m floor
at z = 0, one object, so that each test adds only what it tests: a luminaire, a mirrored pair),
and their command line (`--bin DIR` for the tools, the rest to unittest)."""

import sys
import unittest

FLOOR_MGF = """
m grey =
\tc
\trd 0.5
v f0 =
\tp -5 -5 0
v f1 =
\tp 5 -5 0
v f2 =
\tp 5 5 0
v f3 =
\tp -5 5 0
o floor
f f0 f1 f2 f3
o
"""


def main(module):
    """Runs `module`'s tests; `--bin DIR` sets its BIN (where the tools are)."""
    args = sys.argv[1:]
    if "--bin" in args:
        i = args.index("--bin")
        module.BIN = args[i + 1]
        del args[i:i + 2]
    unittest.main(module=module, argv=[sys.argv[0]] + args, verbosity=2)
