#!/usr/bin/env python3
"""Paired timings of two whole commands, for the speed ratios in docs/results.md.

    python3 pipelines/paired_runs.py [-n RUNS] [--warmup W] [--pin CPUS] [--timeout S] \
        [--vs 'COMMAND_B'] -- COMMAND_A [ARG ...]

A and B run in turn (A B A B ...) after W unmeasured warm-up runs of each, so that a drift of the
machine's speed (other work starting or stopping) falls on both alike; the ratio A / B is taken
pair by pair and reported as min, median and max. Each run's user and system seconds and its peak
resident memory are the kernel's accounting of the finished child (os.wait4, as /usr/bin/time -v
reads them; a peak cannot read below the launcher's own, about 15 MiB, which the child
inherits until it starts its program); wall seconds a monotonic clock around it. 'cpu' is user + system. Quote medians.
A command is split as a shell splits words and run without a shell; its output is discarded.
"""
import argparse
import os
import shlex
import statistics
import subprocess
import sys
import time


def run_once(argv, cpus, deadline):
    """Runs argv to its end; returns (wall, user, sys, peak MiB, exit code)."""
    start = time.monotonic()
    preexec = (lambda: os.sched_setaffinity(0, cpus)) if cpus else None
    child = subprocess.Popen(argv, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL, preexec_fn=preexec)
    while True:
        pid, status, usage = os.wait4(child.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() > deadline:
            child.kill()
            os.wait4(child.pid, 0)
            raise TimeoutError
        time.sleep(0.01)
    wall = time.monotonic() - start
    return wall, usage.ru_utime, usage.ru_stime, usage.ru_maxrss / 1024.0, os.waitstatus_to_exitcode(status)


def spread(values, fmt="{:.3f}"):
    return "{} ({}-{})".format(fmt.format(statistics.median(values)), fmt.format(min(values)),
                               fmt.format(max(values)))


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("-n", type=int, default=5, help="measured runs of each command")
    parser.add_argument("--warmup", type=int, default=1, help="unmeasured runs of each first")
    parser.add_argument("--pin", default="", help="processors, e.g. 1 or 0,1")
    parser.add_argument("--timeout", type=float, default=3600, help="bound on the whole call, s")
    parser.add_argument("--vs", default="", help="command B, one string")
    parser.add_argument("command", nargs=argparse.REMAINDER, help="-- command A and its arguments")
    args = parser.parse_args()
    a = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not a or args.n < 1:
        parser.error("a command after -- and -n >= 1 are needed")
    commands = {"A": a}
    if args.vs:
        commands["B"] = shlex.split(args.vs)
    cpus = {int(c) for c in args.pin.split(",")} if args.pin else None
    deadline = time.monotonic() + args.timeout
    runs = {name: [] for name in commands}
    try:
        for i in range(args.warmup + args.n):
            for name, argv in commands.items():
                result = run_once(argv, cpus, deadline)
                if i >= args.warmup:
                    runs[name].append(result)
    except TimeoutError:
        print("paired_runs: the time bound ended the call; the finished runs follow", file=sys.stderr)
    for name, results in runs.items():
        if not results:
            continue
        print("{}: {} runs, exit codes {}".format(name, len(results), sorted({r[4] for r in results})))
        print("  wall s {}  cpu s {}  peak MiB {}".format(
            spread([r[0] for r in results]), spread([r[1] + r[2] for r in results]),
            spread([r[3] for r in results], "{:.1f}")))
    if "B" in runs:
        pairs = list(zip(runs["A"], runs["B"]))
        if pairs:
            print("A/B over {} pairs: cpu {}  user {}  wall {}".format(
                len(pairs), spread([(x[1] + x[2]) / (y[1] + y[2]) for x, y in pairs]),
                spread([x[1] / y[1] for x, y in pairs]), spread([x[0] / y[0] for x, y in pairs])))


if __name__ == "__main__":
    main()
