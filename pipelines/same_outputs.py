#!/usr/bin/env python3
"""Whether two pipeline OUT folders hold the same outputs, provenance aside: a refactor's check
("no change of behaviour", issue 55).

Container files (.rlh, .rti, .rkw) are compared by their JSON header's kind, metadata and each
array's name, hash, shape and size (formats/container.md: the hash covers the array's bytes);
EXR files (movies, frames) by their pixels, with `oiiotool --diff` at zero tolerance. Other
files (reports, stamps, the mp4) are not compared: they hold times or paths.

    python3 pipelines/same_outputs.py OUT_A OUT_B

Prints each file that differs and a count; exit 1 if any differs or is missing in OUT_B."""
import json
import os
import struct
import subprocess
import sys


def container_summary(path):
    with open(path, "rb") as f:
        preamble = f.read(32)
        (length,) = struct.unpack_from("<Q", preamble, 16)
        header = json.loads(f.read(length))
    arrays = [(a.get("name"), a.get("hash"), a.get("shape"), a.get("nbytes"))
              for a in header.get("arrays", [])]
    return header.get("kind"), header.get("metadata"), arrays


def same(a, b):
    if not os.path.exists(b):
        return False
    if a.endswith((".rlh", ".rti", ".rkw")):
        return container_summary(a) == container_summary(b)
    diff = ["oiiotool", "--fail", "0", "--failpercent", "0", "--warn", "0", a, b, "--diff"]
    return subprocess.run(diff, capture_output=True).returncode == 0


def main():
    if len(sys.argv) != 3 or sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0 if len(sys.argv) == 2 else 2
    first, second = sys.argv[1], sys.argv[2]
    compared = differ = 0
    for root, _, files in os.walk(first):
        for name in sorted(files):
            if not name.endswith((".rlh", ".rti", ".rkw", ".exr")):
                continue
            a = os.path.join(root, name)
            rel = os.path.relpath(a, first)
            compared += 1
            if not same(a, os.path.join(second, rel)):
                print("differs:", rel)
                differ += 1
    print("compared %d files, %d differ" % (compared, differ))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
