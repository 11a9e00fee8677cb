#!/usr/bin/env python3
"""Compares two pitchlab binaries on a bench sweep, interleaved: per world, chunks of a few seeds,
each chunk swept by A and by B back to back (which goes first alternating), each binary resuming
its own bench folder. Prints per world the runs' median wall, the ratio B / A, success and the
false-hazard medians.

A sweep of A then a sweep of B compares the machine's two moments as much as the binaries: on
this shared 2-core machine the physics' CPU per stop of urban runs drifted from 0.15 to 0.23 s
across one sweep (benchmarks/README.md, session 32). Chunks of minutes, interleaved, share the
drift.

    scripts/ab_sweep.py OLD/apps/pitchlab build/apps/pitchlab --out /tmp/abs
    scripts/ab_sweep.py A B --worlds urban --seeds 1..10 --chunk 2 --out /tmp/abs -- --config c.yaml

Exit 0 with the table; 2 on bad arguments; 1 when a bench fails (its output is in OUT/X.log).
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

from ab_args import parse_two_binaries


def parse_seeds(text):
    seeds = []
    for part in text.split(","):
        lo, sep, hi = part.partition("..")
        try:
            seeds += list(range(int(lo), int(hi) + 1)) if sep else [int(lo)]
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a seed list like 1..20 or 1,5,9")
    if not seeds:
        raise argparse.ArgumentTypeError("no seeds")
    return seeds


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("a", help="the first pitchlab binary (the baseline)")
    p.add_argument("b", help="the second pitchlab binary")
    p.add_argument("--worlds", default="office,urban,terrain", help="default office,urban,terrain")
    p.add_argument("--seeds", type=parse_seeds, default=parse_seeds("1..20"),
                   help="A..B or S1,S2,... (default 1..20)")
    p.add_argument("--chunk", type=int, default=5, help="seeds per chunk (default 5)")
    p.add_argument("--jobs", type=int, default=2, help="bench --jobs (default 2)")
    p.add_argument("--out", required=True, help="folder for the two bench folders (a/, b/)")
    p.epilog = "after --: further arguments of `pitchlab bench` (e.g. --config FILE)"
    args, passed = parse_two_binaries(p)
    args.bench_args = passed
    if args.chunk < 1 or args.jobs < 1:
        p.error("--chunk and --jobs must be at least 1")
    if any(a in ("--out", "--worlds", "--seeds", "--jobs") for a in args.bench_args):
        p.error("--out, --worlds, --seeds and --jobs are set by this script")
    return args


def sweep(binary, folder, world, seeds, args):
    cmd = [binary, "bench", "--worlds", world, "--seeds", ",".join(map(str, seeds)),
           "--jobs", str(args.jobs), "--out", folder, *args.bench_args]
    start = time.monotonic()
    with open(folder + ".log", "a") as log:
        done = subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT)
    if done.returncode != 0:
        sys.exit(f"ab_sweep: {' '.join(cmd)} exited {done.returncode}; see {folder}.log")
    return time.monotonic() - start


def records(folder):
    with open(os.path.join(folder, "runs.jsonl")) as f:
        return [json.loads(line) for line in f if line.strip()]


def false_hazard_percent(r):
    cells = r.get("map_cells_compared")
    return 100.0 * r["false_hazard_cells"] / cells if cells else None


def row(name, a, b):
    wa = statistics.median(r["wall_time_s"] for r in a)
    wb = statistics.median(r["wall_time_s"] for r in b)
    fh = []
    for runs in (a, b):
        v = [x for x in map(false_hazard_percent, runs) if x is not None]
        fh.append(f"{statistics.median(v):.4f}" if v else "-")
    ok = [sum(1 for r in runs if r.get("success")) for runs in (a, b)]
    print(f"{name:<10} {len(a):>4} {wa:8.2f} {wb:8.2f} {wb / wa:6.3f} {ok[0]:>4} {ok[1]:>4} "
          f"{fh[0]:>9} {fh[1]:>9}")


def main():
    args = parse_args()
    os.makedirs(args.out, exist_ok=True)
    folders = {"a": os.path.join(args.out, "a"), "b": os.path.join(args.out, "b")}
    binaries = {"a": args.a, "b": args.b}
    spent = {"a": 0.0, "b": 0.0}
    n = 0
    worlds = args.worlds.split(",")
    for world in worlds:
        for k in range(0, len(args.seeds), args.chunk):
            chunk = args.seeds[k:k + args.chunk]
            order = ("a", "b") if n % 2 == 0 else ("b", "a")
            n += 1
            for name in order:
                s = sweep(binaries[name], folders[name], world, chunk, args)
                spent[name] += s
                print(f"{name.upper()} {world} {chunk[0]}..{chunk[-1]}: {s:.1f} s", file=sys.stderr)
    runs = {name: [r for r in records(folders[name]) if r["world"] in worlds
                   and r["seed"] in args.seeds] for name in folders}
    print(f"{'world':<10} {'runs':>4} {'A wall':>8} {'B wall':>8} {'B/A':>6} {'A ok':>4} "
          f"{'B ok':>4} {'A haz %':>9} {'B haz %':>9}  [wall per run, medians]")
    for world in worlds:
        row(world, [r for r in runs["a"] if r["world"] == world],
            [r for r in runs["b"] if r["world"] == world])
    row("all", runs["a"], runs["b"])
    print(f"bench time: A {spent['a']:.1f} s, B {spent['b']:.1f} s, B/A "
          f"{spent['b'] / spent['a']:.3f}; bench folders: {folders['a']} {folders['b']}")


if __name__ == "__main__":
    main()
