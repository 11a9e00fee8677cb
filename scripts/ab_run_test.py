#!/usr/bin/env python3
"""ab_run.py against two stand-in binaries that write known metrics.json files: the runs
alternate (A, B, A, B, ...), the table holds each stage's medians, and a binary that writes no
metrics is an error naming what it said."""
import os
import subprocess
import sys
import tempfile

from ab_test_support import write_executable

HERE = os.path.dirname(os.path.abspath(__file__))

# A stand-in `pitchlab run`: appends its name to a log (the order of the runs), and writes a
# metrics.json whose registration wall time is the run's number times its factor.
FAKE = """#!/usr/bin/env python3
import json, os, sys
out = sys.argv[sys.argv.index('--out') + 1]
log = os.path.join(os.path.dirname(out), 'order.log')
with open(log, 'a') as f: f.write('{name}\\n')
n = sum(1 for line in open(log) if line.strip() == '{name}')
os.makedirs(out)
stages = {{'registration': {{'wall_s': {factor} * n, 'cpu_s': 2.0}}, 'run': {{'wall_s': 10.0, 'cpu_s': 12.0}}}}
json.dump({{'wall_time_s': 10.0, 'real_time_factor': 40.0, 'reason': 'goal reached',
           'sim_time_s': 400.0, 'stages': stages}}, open(os.path.join(out, 'metrics.json'), 'w'))
"""


def fake(folder, name, factor):
    return write_executable(folder, name, FAKE.format(name=name, factor=factor))


def main():
    with tempfile.TemporaryDirectory() as tmp:
        a, b = fake(tmp, "a", 1.0), fake(tmp, "b", 10.0)
        out = os.path.join(tmp, "runs")
        done = subprocess.run([sys.executable, os.path.join(HERE, "ab_run.py"), a, b, "--runs", "3",
                               "--out", out], capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        order = open(os.path.join(out, "order.log")).read().split()
        assert order == ["a", "b"] * 3, order
        row = next(line for line in done.stdout.splitlines() if line.startswith("registration"))
        # medians of 1, 2, 3 and of 10, 20, 30
        assert row.split()[1:] == ["2.00", "2.00", "20.00", "2.00"], row
        broken = write_executable(
            tmp, "broken", "#!/bin/sh\necho 'pitchlab run: error: unknown world' >&2\nexit 2\n")
        done = subprocess.run([sys.executable, os.path.join(HERE, "ab_run.py"), broken, b,
                               "--out", os.path.join(tmp, "runs2")], capture_output=True, text=True)
        assert done.returncode == 1 and "unknown world" in done.stderr, done.stderr
        done = subprocess.run([sys.executable, os.path.join(HERE, "ab_run.py"), "/nonexistent", b],
                              capture_output=True, text=True)
        assert done.returncode == 2 and "not an executable" in done.stderr, done.stderr
    print("ok")


if __name__ == "__main__":
    main()
