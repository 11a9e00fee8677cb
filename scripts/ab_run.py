#!/usr/bin/env python3
"""Compares two pitchlab binaries on one run, alternating A, B, A, B, ... and prints the medians
of each stage's wall and CPU seconds (metrics.json's `stages`) side by side.

Alternating is what makes the comparison fair on a shared or virtual machine: its speed drifts
(session 22 measured the same binary at 14.9-19.1 s on the default run within an hour), so runs
of A then runs of B compare the machine's two moments, not the binaries.

    scripts/ab_run.py OLD/apps/pitchlab build/apps/pitchlab
    scripts/ab_run.py A B --runs 5 --out /tmp/ab -- --world urban --seed 3

Exit 0 with the table; 2 on bad arguments; 1 when a run fails (its folder is kept).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile

from ab_args import parse_two_binaries


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("a", help="the first pitchlab binary (the baseline)")
    p.add_argument("b", help="the second pitchlab binary")
    p.add_argument("--runs", type=int, default=3, help="runs of each binary (default 3)")
    p.add_argument("--out", help="folder for the run folders (default: a new temporary one)")
    p.epilog = "after --: arguments of `pitchlab run` (default: --world terrain --seed 1)"
    args, passed = parse_two_binaries(p)
    args.run_args = passed
    if args.runs < 1:
        p.error("--runs must be at least 1")
    if any(a in ("--out", "--quiet") for a in args.run_args):
        p.error("--out and --quiet are set by this script")
    return args


def run(binary, folder, run_args):
    cmd = [binary, "run", *run_args, "--out", folder, "--quiet"]
    done = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    metrics = os.path.join(folder, "metrics.json")
    if not os.path.exists(metrics):
        said = (done.stderr.strip().splitlines() or [""])[-1]
        sys.exit(f"ab_run: {' '.join(cmd)} wrote no metrics.json (exit {done.returncode}): {said}")
    with open(metrics) as f:
        return json.load(f)


def main():
    args = parse_args()
    run_args = args.run_args or ["--world", "terrain", "--seed", "1"]
    out = args.out or tempfile.mkdtemp(prefix="pitchlab_ab_")
    os.makedirs(out, exist_ok=True)
    results = {"a": [], "b": []}
    for i in range(args.runs):
        for name, binary in (("a", args.a), ("b", args.b)):
            folder = os.path.join(out, f"{name}{i + 1}")
            if os.path.exists(folder):
                sys.exit(f"ab_run: {folder} exists: give another --out")
            m = run(binary, folder, run_args)
            results[name].append(m)
            print(f"{name}{i + 1}: {m['wall_time_s']:.2f} s wall, {m['real_time_factor']:.1f}x, "
                  f"{m['reason']}", file=sys.stderr)
    stages = sorted(set().union(*(m["stages"].keys() for m in results["a"] + results["b"])))
    med = lambda name, stage, key: statistics.median(  # noqa: E731
        m["stages"].get(stage, {}).get(key, 0.0) for m in results[name])
    print(f"{'stage':<18} {'A wall':>8} {'A cpu':>8} {'B wall':>8} {'B cpu':>8}  [s, medians of {args.runs}]")
    for s in stages:
        print(f"{s:<18} {med('a', s, 'wall_s'):8.2f} {med('a', s, 'cpu_s'):8.2f} "
              f"{med('b', s, 'wall_s'):8.2f} {med('b', s, 'cpu_s'):8.2f}")
    for name in ("a", "b"):
        ms = results[name]
        print(f"{name.upper()}: real time factor {[round(m['real_time_factor'], 1) for m in ms]}, "
              f"simulated {[round(m['sim_time_s']) for m in ms]} s, "
              f"outcome {sorted(set(m['reason'] for m in ms))}")
    print(f"run folders: {out}")


if __name__ == "__main__":
    main()
