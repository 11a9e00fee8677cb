#!/usr/bin/env python3
"""ab_sweep.py against two stand-in binaries that act as `pitchlab bench`, recording one run per
seed with a known wall time: the chunks alternate which binary goes first, each binary's folder
gathers every chunk, the table holds the medians and their ratio, and a failing bench is an error
naming its log."""
import os
import subprocess
import sys
import tempfile

from ab_test_support import write_executable

HERE = os.path.dirname(os.path.abspath(__file__))

# A stand-in `pitchlab bench`: logs its name and seeds (the order of the chunks) and appends a
# record per seed to OUT/runs.jsonl, its wall time the seed times its factor.
FAKE = """#!/usr/bin/env python3
import json, os, sys
arg = lambda k: sys.argv[sys.argv.index(k) + 1]
out, world, seeds = arg('--out'), arg('--worlds'), [int(s) for s in arg('--seeds').split(',')]
os.makedirs(out, exist_ok=True)
with open(os.path.join(os.path.dirname(out), 'order.log'), 'a') as f:
    f.write('{name} ' + world + ' ' + arg('--seeds') + '\\n')
with open(os.path.join(out, 'runs.jsonl'), 'a') as f:
    for s in seeds:
        f.write(json.dumps({{'world': world, 'seed': s, 'wall_time_s': {factor} * s,
                            'success': True, 'false_hazard_cells': s,
                            'map_cells_compared': 1000}}) + '\\n')
"""


def fake(folder, name, factor):
    return write_executable(folder, name, FAKE.format(name=name, factor=factor))


def ab_sweep(*args):
    return subprocess.run([sys.executable, os.path.join(HERE, "ab_sweep.py"), *args],
                          capture_output=True, text=True)


def main():
    with tempfile.TemporaryDirectory() as tmp:
        a, b = fake(tmp, "a", 2.0), fake(tmp, "b", 1.0)
        out = os.path.join(tmp, "abs")
        done = ab_sweep(a, b, "--worlds", "office,urban", "--seeds", "1..5", "--chunk", "2",
                        "--out", out)
        assert done.returncode == 0, done.stderr
        order = [line.split() for line in open(os.path.join(out, "order.log"))]
        assert order == [["a", "office", "1,2"], ["b", "office", "1,2"],
                         ["b", "office", "3,4"], ["a", "office", "3,4"],
                         ["a", "office", "5"], ["b", "office", "5"],
                         ["b", "urban", "1,2"], ["a", "urban", "1,2"],
                         ["a", "urban", "3,4"], ["b", "urban", "3,4"],
                         ["b", "urban", "5"], ["a", "urban", "5"]], order
        rows = {line.split()[0]: line.split() for line in done.stdout.splitlines()}
        # seeds 1..5: median wall 2 * 3 and 1 * 3; false hazards 3 of 1000 cells
        assert rows["office"][1:] == ["5", "6.00", "3.00", "0.500", "5", "5", "0.3000",
                                      "0.3000"], rows["office"]
        assert rows["all"][1:5] == ["10", "6.00", "3.00", "0.500"], rows["all"]
        broken = write_executable(
            tmp, "broken", "#!/bin/sh\necho 'pitchlab bench: error: unknown world' >&2\nexit 2\n")
        done = ab_sweep(broken, b, "--out", os.path.join(tmp, "abs2"))
        assert done.returncode == 1 and "a.log" in done.stderr, done.stderr
        assert "unknown world" in open(os.path.join(tmp, "abs2", "a.log")).read()
        done = ab_sweep("/nonexistent", b, "--out", out)
        assert done.returncode == 2 and "not an executable" in done.stderr, done.stderr
        done = ab_sweep(a, b, "--seeds", "1..x", "--out", out)
        assert done.returncode == 2 and "seed list" in done.stderr, done.stderr
    print("ok")


if __name__ == "__main__":
    main()
