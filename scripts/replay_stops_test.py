#!/usr/bin/env python3
"""replay_stops.py on a hand-made run against a stand-in `pitchlab merge`: the scans' VIEWPOINT is
the mission's prior chain (odometry since the previous stop applied to its final pose), marked
odometry, the points untouched; merge gets the widest bound; the table compares with the truth;
bad input is named. With a pitchlab binary as the argument, also end to end: a real run's stops
replayed through the real merge land where the mission put them."""
import json
import math
import os
import subprocess
import sys
import tempfile

from ab_test_support import write_executable

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import replay_stops  # noqa: E402  (the maths, checked against hand-worked poses below)

# A stand-in merge: records its arguments, and "merges" every scan but the last at its
# VIEWPOINT relative to the first's, as a registration that kept each prior would.
FAKE = """#!/usr/bin/env python3
import json, os, sys
sys.path.insert(0, {here!r})
import replay_stops as r
args = sys.argv[1:]
out = args[args.index('--out') + 1]
files = [a for a in args[1:] if a.endswith('.pcd') and a != out]
json.dump(args, open(os.path.join(os.path.dirname(out), 'args.json'), 'w'))
def viewpoint(f):
    head = open(f, 'rb').read().split(b'DATA ')[0].decode()
    v = [float(x) for x in [l for l in head.split('\\n') if l.startswith('VIEWPOINT')][0].split()[1:]]
    return r.from_quaternion(*v)
first = r.inverse(viewpoint(files[0]))
with open(out[:-4] + '_trajectory.csv', 'w') as t:
    t.write('scan,file,x_m,y_m,z_m,qw,qx,qy,qz\\n')
    for i, f in enumerate(files[:-1]):
        T = r.compose(first, viewpoint(f))
        q = r.quaternion(T)
        t.write(f'{{i}},{{os.path.basename(f)}},{{T[0][3]}},{{T[1][3]}},{{T[2][3]}},{{q[0]}},{{q[1]}},{{q[2]}},{{q[3]}}\\n')
"""

POINTS = bytes(range(256)) * 3  # stands for the binary points: must come through unchanged


def pose(x, y, yaw_deg):
    return {"x_m": x, "y_m": y, "z_m": 0.0, "roll_deg": 0.0, "pitch_deg": 0.0, "yaw_deg": yaw_deg}


def write_run(folder, stops):
    for k, s in enumerate(stops):
        d = os.path.join(folder, "stops", f"{k:03d}")
        os.makedirs(d)
        with open(os.path.join(d, "registration.json"), "w") as f:
            json.dump(s, f)
        with open(os.path.join(d, "scan.pcd"), "wb") as f:
            f.write(b"# .PCD v0.7 - Point Cloud Data file format\n# pose truth\n# world office\n"
                    b"VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 64\n"
                    b"HEIGHT 1\nVIEWPOINT 9 9 9 1 0 0 0\nPOINTS 64\nDATA binary\n" + POINTS)


def replay(*args):
    return subprocess.run([sys.executable, os.path.join(HERE, "replay_stops.py"), *args],
                          capture_output=True, text=True)


def check(condition, message):
    if not condition:
        sys.exit("FAILED: " + message)


def hand_made(tmp):
    # Three stops along x, the last turned 90 deg. The mission's final poses (estimate) are the
    # truth; odometry put stop 1 at x 1.1 (0.1 m off) and stop 2 1.05 m and 92 deg on from
    # stop 1's final pose: its prior chain is 0.1 + 0.05 m off along x and 2 deg off in yaw.
    truth = [pose(0, 0, 0), pose(1, 0, 0), pose(2, 0, 90)]
    odometry = [pose(0, 0, 0), pose(1.1, 0, 0), pose(2.05, 0, 92)]
    stops = [{"truth": t, "estimate": t, "odometry": o, "merged": True,
              "prior_bound": {"translation_m": 0.2 + 0.1 * k, "rotation_deg": 2.0 - 0.5 * k}}
             for k, (t, o) in enumerate(zip(truth, odometry))]
    run = os.path.join(tmp, "run")
    write_run(run, stops)
    fake = write_executable(tmp, "pitchlab", FAKE.format(here=HERE))
    out = os.path.join(tmp, "replay")
    done = replay(run, "--stops", "0..2", "--out", out, "--pitchlab", fake)
    check(done.returncode == 0, f"exit {done.returncode}: {done.stderr}")
    with open(os.path.join(out, "stop_002.pcd"), "rb") as f:
        data = f.read()
    head = data.split(b"DATA binary\n")[0].decode()
    check(data.endswith(b"DATA binary\n" + POINTS), "the points changed")
    check("# pose odometry" in head and "# pose truth" not in head, "pose comment: " + head)
    v = [float(x) for x in [ln for ln in head.split("\n") if ln.startswith("VIEWPOINT")][0].split()[1:]]
    check(abs(v[0] - 2.15) < 1e-9 and abs(v[1]) < 1e-9, f"stop 2's prior at {v[:3]}, not (2.15, 0)")
    yaw = math.degrees(2 * math.atan2(v[6], v[3]))
    check(abs(yaw - 92) < 1e-6, f"stop 2's prior yaw {yaw}, not 92 deg")
    with open(os.path.join(out, "args.json")) as f:
        args = json.load(f)
    bound = args[args.index("--prior-error") + 1]
    check(bound == "0.400000,1.500000", f"merge's bound {bound}: the widest is 0.4 m, 1.5 deg")
    with open(os.path.join(out, "replay.json")) as f:
        rows = json.load(f)["stops"]
    check(abs(rows[1]["replay_error_m"] - 0.1) < 1e-9, f"stop 1: {rows[1]}")
    check(abs(rows[1]["mission_error_m"]) < 1e-9, f"stop 1: {rows[1]}")
    check(not rows[2]["replay_merged"] and "not merged" in done.stdout, "stop 2 was not merged")
    # Bad input: a stop without its record, an out folder in use, a range of one stop.
    os.remove(os.path.join(run, "stops", "001", "registration.json"))
    done = replay(run, "--stops", "0..2", "--out", os.path.join(tmp, "r2"), "--pitchlab", fake)
    check(done.returncode == 1 and "stops/001/registration.json" in done.stderr, done.stderr)
    check(replay(run, "--stops", "0..2", "--out", out).returncode == 2, "a used --out is exit 2")
    done = replay(run, "--stops", "3", "--out", os.path.join(tmp, "r3"))
    check(done.returncode == 2 and "at least two stops" in done.stderr, done.stderr)


def end_to_end(tmp, pitchlab):
    run = os.path.join(tmp, "office")
    subprocess.run([pitchlab, "run", "--world", "office", "--seed", "1", "--out", run, "--quiet"],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    out = os.path.join(tmp, "office_replay")
    done = replay(run, "--stops", "0..4", "--out", out, "--pitchlab", pitchlab)
    check(done.returncode == 0, f"exit {done.returncode}: {done.stderr}")
    with open(os.path.join(out, "replay.json")) as f:
        rows = json.load(f)["stops"]
    merged = [r for r in rows if r["mission_merged"] and r["replay_merged"]]
    check(len(merged) >= 4, f"only {len(merged)} of 5 stops merged in both: {rows}")
    # The same scans, priors and registration: where the mission put each stop, to the mm.
    for r in merged:
        check(abs(r["replay_error_m"] - r["mission_error_m"]) < 1e-3 and
              abs(r["replay_error_deg"] - r["mission_error_deg"]) < 0.02, f"stop {r}")


def main():
    # The maths against a hand-worked case: a quaternion round trip, and an inverse.
    a = replay_stops.from_pose({"x_m": 1, "y_m": -2, "z_m": 0.5, "roll_deg": 170, "pitch_deg": -30,
                                "yaw_deg": -120})
    b = replay_stops.from_quaternion(1, -2, 0.5, *replay_stops.quaternion(a))
    check(max(abs(a[i][j] - b[i][j]) for i in range(4) for j in range(4)) < 1e-12, "quaternion")
    i = replay_stops.compose(a, replay_stops.inverse(a))
    check(max(abs(i[r][c] - (r == c)) for r in range(4) for c in range(4)) < 1e-12, "inverse")
    with tempfile.TemporaryDirectory() as tmp:
        hand_made(tmp)
        if len(sys.argv) > 1:
            end_to_end(tmp, sys.argv[1])
    print("replay_stops: all checks passed")


if __name__ == "__main__":
    main()
