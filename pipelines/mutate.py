#!/usr/bin/env python3
"""Hostile glTF input through the real tools (issue 18): mutants of the bundled scene.

Deterministic (fixed seed) structure and byte mutants of pipelines/scenes/cornell-moving.gltf,
as .gltf (buffer embedded as a data: URI) and as .glb (buffer in the BIN chunk):

  targeted   the issue's cases: JSON nested 100,000 deep, coordinates of 3e38 / translation 1e38,
             emissiveStrength 1e308, baseColor 1, primitive modes 5 and 6, componentType 5121,
             a negative byteOffset, an accessor count of 2^25, a broken data URI, punctual lights
             instead of an emissive material, an animated scale
  structure  one JSON value (any depth, buffers' URIs aside) replaced by a hostile one (negative,
             huge, fractional, wrong type, null, empty), or deleted
  bytes      1-8 bytes of the buffer (or of the whole .glb) overwritten with random bytes

Each mutant goes through `rad-inspect --check` and, when that accepts it, `rad-global` on frames
0-1 (--eps 0.05 --rays 4, one thread). Modes 5 and 6 on the scene's triangle lists are valid
glTF read by the spec (tests/format/gltf_scene_test.cpp): coincident reversed triangles (strip)
and fans through the boxes' insides, which run at the source's speed since the form factors
integrate only the part of a receiver in front of the shooter (they took 35x before).

Asserted for every run: no signal, exit code 0 or 1, one line on stderr when it fails, a
global.rlh without NaN/Inf when it exits 0, and a time (of the run, or of its one retry: the
machine's load spikes) within 10x the source scene's, at least --min-limit (3 s: the source's
0.1 s is mostly process start-up).

usage: mutate.py [--bin DIR] [--out DIR] [--count N] [--seed S] [--check] [--keep]
                 [--default-settings] [--shard K/N]
  --count N  random structure+byte mutants (default 40: the ctest `pipeline_gltf_mutants`);
             the targeted ones always run
  --check    exit 1 when any mutant violates a bound (the summary lists them)
  --default-settings  rad-global at its default eps and rays (the limit is then 10x ~0.6 s)
  --shard K/N         the mutants with index K mod N, to run N of these side by side
"""
import argparse
import base64
import copy
import json
import os
import random
import shutil
import struct
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
SCENE = os.path.join(HERE, "scenes", "cornell-moving.gltf")
GLOBAL_ARGS = ["--frames", "0-1", "--eps", "0.05", "--rays", "4", "--threads", "1"]
# --default-settings: rad-global's own eps and rays (20x the source's time: a long run).
DEFAULT_GLOBAL_ARGS = ["--frames", "0-1", "--threads", "1"]
ERROR_PEAK_MB = 200  # the bound on what a run may take before it refuses its input
HOSTILE = [-1, -8, 0, 1, 2, 5, 6, 5121, 0.5, 2 ** 25, 2 ** 31, 2 ** 32 + 4, 2 ** 63, 1e38, -1e38,
           3e38, 1e308, -1e308, 1e-300, "x", None, True, [], {}, [0] * 5, "A" * 20000]


def split_buffer(g):
    """The scene's one buffer as bytes (decoded from its data: URI)."""
    return bytearray(base64.b64decode(g["buffers"][0]["uri"].split(",", 1)[1]))


def with_buffer(g, data):
    g = copy.deepcopy(g)
    g["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(
        bytes(data)).decode()
    g["buffers"][0]["byteLength"] = len(data)
    return g


def gltf_bytes(g):
    return json.dumps(g).encode()


def glb_bytes(g, data):
    g = copy.deepcopy(g)
    del g["buffers"][0]["uri"]
    js = json.dumps(g).encode()
    js += b" " * (-len(js) % 4)
    data = bytes(data) + b"\0" * (-len(data) % 4)
    total = 12 + 8 + len(js) + 8 + len(data)
    return (struct.pack("<III", 0x46546C67, 2, total) + struct.pack("<II", len(js), 0x4E4F534A) + js
            + struct.pack("<II", len(data), 0x004E4942) + data)


def targeted(g0, data0):
    """(name, gltf dict or None, buffer, raw bytes or None) for the issue's cases."""
    out = []

    def add(name, g, data=data0, raw=None):
        out.append((name, g, data, raw))

    text = json.dumps(with_buffer(g0, data0))
    add("deep-extras", None, data0,
        (text[:-1] + ', "extras": ' + "[" * 100000 + "]" * 100000 + "}").encode())
    big = bytearray(data0)
    struct.pack_into("<f", big, 0, 3e38)
    add("position-3e38", g0, big)
    g = copy.deepcopy(g0)
    g["nodes"][7]["translation"] = [1e38, 0, 0]
    add("translation-1e38", g)
    g = copy.deepcopy(g0)
    g["nodes"][8]["translation"] = [0, 0, 1e38]
    add("camera-1e38", g)
    g = copy.deepcopy(g0)
    g["materials"][3]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = 1e308
    add("emissive-1e308", g)
    g = copy.deepcopy(g0)
    for m in g["materials"]:
        m["pbrMetallicRoughness"]["baseColorFactor"] = [1, 1, 1, 1]
    add("basecolor-1", g)
    for mode in (5, 6):
        g = copy.deepcopy(g0)
        for m in g["meshes"]:
            for p in m["primitives"]:
                p["mode"] = mode
        add("mode-%d" % mode, g)
    for acc in (0, 1):
        g = copy.deepcopy(g0)
        g["accessors"][acc]["componentType"] = 5121
        add("accessor%d-ubyte" % acc, g)
    g = copy.deepcopy(g0)
    g["bufferViews"][12]["byteOffset"] = -8
    add("byteoffset-negative", g)
    g = copy.deepcopy(g0)
    g["accessors"][0]["count"] = 2 ** 25
    add("count-2^25", g)
    g = copy.deepcopy(g0)
    del g["materials"][3]["emissiveFactor"]
    g["extensionsUsed"].append("KHR_lights_punctual")
    g["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point"}, {"type": "directional"}]}}
    add("punctual-lights-only", g)
    g = copy.deepcopy(g0)
    g["animations"][0]["channels"][0]["target"]["path"] = "scale"
    add("animated-scale", g)
    broken = json.loads(text)
    broken["buffers"][0]["uri"] = broken["buffers"][0]["uri"][:-4] + "!!!!"
    add("data-uri-broken", None, data0, json.dumps(broken).encode())
    return out


def json_paths(node, path=()):
    """Every (path) to a value in the JSON tree but the buffers (the harness embeds them; their
    bytes are the byte mutants' part)."""
    yield path
    if isinstance(node, dict):
        for k, v in node.items():
            if path == () and k == "buffers":
                continue
            yield from json_paths(v, path + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from json_paths(v, path + (i,))


def structure_mutant(g0, rng):
    g = copy.deepcopy(g0)
    paths = [p for p in json_paths(g) if p]
    path = rng.choice(paths)
    parent = g
    for k in path[:-1]:
        parent = parent[k]
    if isinstance(parent, dict) and rng.random() < 0.2:
        del parent[path[-1]]
        return g, "delete " + "/".join(map(str, path))
    value = rng.choice(HOSTILE)
    parent[path[-1]] = value
    shown = json.dumps(value)
    return g, "/".join(map(str, path)) + " = " + (shown[:40] + "..." if len(shown) > 40 else shown)


def byte_mutant(raw, rng, start=0):
    data = bytearray(raw)
    n = rng.randint(1, 8)
    places = []
    for _ in range(n):
        at = rng.randrange(start, len(data))
        data[at] = rng.randrange(256)
        places.append(at)
    return data, "bytes %s" % ",".join(map(str, sorted(places)))


def mutants(count, seed):
    """(name, file extension, bytes): the targeted cases, then `count` random ones."""
    g0 = json.load(open(SCENE))
    data0 = split_buffer(g0)
    out = [("source", ".gltf", gltf_bytes(with_buffer(g0, data0))),
           ("source", ".glb", glb_bytes(g0, data0))]
    for name, g, data, raw in targeted(g0, data0):
        if raw is not None:
            out.append((name, ".gltf", raw))
            continue
        out.append((name, ".gltf", gltf_bytes(with_buffer(g, data))))
        out.append((name, ".glb", glb_bytes(g, data)))
    rng = random.Random(seed)
    for i in range(count):
        kind = i % 4
        if kind == 0:  # JSON structure, .gltf
            g, what = structure_mutant(g0, rng)
            out.append(("structure %s" % what, ".gltf", gltf_bytes(with_buffer(g, data0))))
        elif kind == 1:  # JSON structure, .glb
            g, what = structure_mutant(g0, rng)
            out.append(("structure %s" % what, ".glb", glb_bytes(g, data0)))
        elif kind == 2:  # buffer bytes (both files hold the same buffer)
            data, what = byte_mutant(data0, rng)
            out.append(("buffer %s" % what, ".gltf", gltf_bytes(with_buffer(g0, data))))
        else:  # any byte of the .glb: header, chunk headers, JSON, BIN
            raw, what = byte_mutant(glb_bytes(g0, data0), rng)
            out.append(("glb %s" % what, ".glb", bytes(raw)))
    return out


def run(cmd, timeout):
    """(exit code or "timeout", stderr, seconds, peak resident MB) of one run."""
    t = time.monotonic()
    with tempfile.TemporaryFile() as err:
        p = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err)
        killed = threading.Event()

        def kill():
            killed.set()
            p.kill()
        timer = threading.Timer(timeout, kill)
        timer.start()
        _, status, usage = os.wait4(p.pid, 0)  # its own rusage: the peak of this run only
        timer.cancel()
        p.returncode = os.waitstatus_to_exitcode(status)
        secs = time.monotonic() - t
        err.seek(0)
        text = err.read().decode("utf-8", "replace")
    rc = "timeout" if killed.is_set() else p.returncode
    return rc, text, secs, usage.ru_maxrss / 1024.0


def radiosity_finite(bin_dir, rlh):
    p = subprocess.run([os.path.join(bin_dir, "rad-inspect"), "--json", rlh], capture_output=True)
    if p.returncode != 0:
        return False
    info = json.loads(p.stdout)
    return all(a["stats"].get("non_finite", 0) == 0 for a in info["arrays"])




def check_one(bin_dir, path, limit, global_args):
    """Problems of one mutant (empty: fine) and what ran."""
    problems, summary = [], []
    rc, err, secs, mb = run([os.path.join(bin_dir, "rad-inspect"), "--check", path], limit)
    summary.append("inspect %s %.2fs" % (rc, secs))
    stages = [("rad-inspect", rc, err, secs, mb)]
    if rc == 0:
        rlh = path + ".rlh"
        rc, err, secs, mb = run([os.path.join(bin_dir, "rad-global"), path, "-o", rlh] + global_args,
                                limit)
        summary.append("global %s %.2fs" % (rc, secs))
        stages.append(("rad-global", rc, err, secs, mb))
        if rc == 0 and not radiosity_finite(bin_dir, rlh):
            problems.append("rad-global exit 0 with non-finite values in global.rlh")
    for tool, rc, err, secs, mb in stages:
        if rc == 1 and mb > ERROR_PEAK_MB:
            problems.append("%s peaked at %.0f MB before its error (limit %d MB)" %
                            (tool, mb, ERROR_PEAK_MB))
        if rc == "timeout" or secs > limit:
            problems.append("%s took %.1f s (limit %.1f s)" % (tool, secs, limit))
        elif rc < 0:
            problems.append("%s killed by signal %d" % (tool, -rc))
        elif rc not in (0, 1):
            problems.append("%s exit %d: %s" % (tool, rc, err.strip()[:200]))
        lines = [l for l in err.splitlines() if l.startswith(tool + ": ")]
        if rc == 1 and (len(lines) != 1 or len(lines[0]) > 1000):
            problems.append("%s: error is not one bounded line (%d lines, %d bytes)" %
                            (tool, len(lines), max([len(l) for l in lines] or [0])))
    return problems, ", ".join(summary), stages


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin"))
    ap.add_argument("--out", default=os.path.join(ROOT, "out", "mutants"))
    ap.add_argument("--count", type=int, default=40)
    ap.add_argument("--seed", type=int, default=18)
    ap.add_argument("--check", action="store_true")
    ap.add_argument("--keep", action="store_true", help="keep every mutant file, not only failures")
    ap.add_argument("--min-limit", type=float, default=3.0,
                    help="least time limit per run, s (the source's 0.1 s is mostly start-up, and "
                    "a shared machine's load varies by more than 10x that)")
    ap.add_argument("--default-settings", action="store_true",
                    help="run rad-global at its default eps and rays, not the coarse ones")
    ap.add_argument("--shard", default="0/1",
                    help="K/N: only the mutants whose index is K mod N (N runs side by side)")
    a = ap.parse_args()
    global_args = DEFAULT_GLOBAL_ARGS if a.default_settings else GLOBAL_ARGS
    try:
        shard, shards = (int(x) for x in a.shard.split("/"))
    except ValueError:
        shard, shards = -1, 0
    if not 0 <= shard < shards:
        sys.exit("mutate.py: --shard %s: expected K/N with 0 <= K < N" % a.shard)
    shutil.rmtree(a.out, ignore_errors=True)
    os.makedirs(a.out)
    cases = mutants(a.count, a.seed)
    # The source's time: the fastest of 2 runs of each file kind.
    base = []
    for name, ext, raw in cases[:2]:
        path = os.path.join(a.out, "source" + ext)
        open(path, "wb").write(raw)
        for _ in range(2):
            rc, err, secs, _ = run([os.path.join(a.bin, "rad-global"), path, "-o", path + ".rlh"] +
                                global_args, 60)
            if rc != 0:
                sys.exit("mutate.py: the source scene fails: " + err.strip())
            base.append(secs)
    limit = max(10 * min(base), a.min_limit)
    todo = [i for i in range(len(cases)) if i % shards == shard]
    print("source: rad-global %.2f s (%s); limit per run %.2f s; %d mutants" %
          (min(base), " ".join(global_args), limit, len(todo)))
    bad, exits, slowest, error_peak = [], {}, (0.0, ""), (0.0, "")
    t0 = time.monotonic()
    for i in todo:
        name, ext, raw = cases[i]
        path = os.path.join(a.out, "m%04d%s" % (i, ext))
        open(path, "wb").write(raw)
        problems, summary, stages = check_one(a.bin, path, limit, global_args)
        if problems and all(" took " in p for p in problems):
            # A shared machine's load spikes: a time over the limit counts when it repeats.
            problems, summary, stages = check_one(a.bin, path, limit, global_args)
        for tool, rc, err, secs, mb in stages:
            exits[(tool, rc)] = exits.get((tool, rc), 0) + 1
            what = "%s %s (%s)" % (tool, os.path.basename(path), name[:80])
            if tool == "rad-global" and secs > slowest[0]:
                slowest = (secs, what)
            if rc == 1 and mb > error_peak[0]:
                error_peak = (mb, what)
        if problems:
            bad.append(path)
            print("FAIL %s (%s): %s [%s]" % (os.path.basename(path), name[:80], "; ".join(problems),
                                             summary))
        elif not a.keep:
            for f in (path, path + ".rlh"):
                if os.path.exists(f):
                    os.remove(f)
    print("exit codes: " + ", ".join("%s %s: %d" % (t, rc, n) for (t, rc), n in sorted(
        exits.items(), key=lambda kv: (kv[0][0], str(kv[0][1])))))
    print("slowest rad-global: %.2f s, %.1fx the source's, %s" %
          (slowest[0], slowest[0] / min(base), slowest[1]))
    print("largest peak before an error: %.0f MB, %s" % error_peak)
    print("%d mutants, %d violations, %.1f s" % (len(todo), len(bad), time.monotonic() - t0))
    if a.check and bad:
        sys.exit(1)


if __name__ == "__main__":
    main()
