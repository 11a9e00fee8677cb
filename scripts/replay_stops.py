#!/usr/bin/env python3
"""Replays a run's stops through `pitchlab merge`: each stop's scan with the odometry prior the
mission gave it, so one registration of a mission can be studied, and its settings varied
(`--config`), offline, against the truth the run recorded.

A mission registers stop k against the map, its prior the odometry since stop k-1 applied to
stop k-1's final pose (stops/NNN/registration.json: `odometry` and `estimate`). The stops' scans
(stops/NNN/scan.pcd) carry the TRUE pose as their VIEWPOINT; this script writes copies whose
VIEWPOINT is that prior chain instead, marked `# pose odometry`, which `pitchlab merge` reads as
each scan's odometry. The replayed map starts at the first stop replayed. Each stop is then
compared with the truth in the first replayed stop's frame, beside the mission's own estimate:

    scripts/replay_stops.py RUN --stops 0..6 --out /tmp/replay
    scripts/replay_stops.py RUN --stops 3..9 --out /tmp/r2 --config reg.yaml

Exit 0 with the table (DIR/replay.json holds it too); 2 on bad arguments; 1 when the run's
files are missing or unreadable, or merge wrote no trajectory.
"""
import argparse
import csv
import json
import math
import os
import shutil
import subprocess
import sys

# A 4 x 4 rigid transform as nested lists; the stops' poses are x, y, z [m] and roll, pitch,
# yaw [deg] about the fixed x, y, z axes (R = Rz(yaw) Ry(pitch) Rx(roll)), as registration.json
# writes them.


def from_pose(p):
    r, q, y = (math.radians(p[k]) for k in ("roll_deg", "pitch_deg", "yaw_deg"))
    cr, sr, cq, sq, cy, sy = math.cos(r), math.sin(r), math.cos(q), math.sin(q), math.cos(y), math.sin(y)
    rot = [[cy * cq, cy * sq * sr - sy * cr, cy * sq * cr + sy * sr],
           [sy * cq, sy * sq * sr + cy * cr, sy * sq * cr - cy * sr],
           [-sq, cq * sr, cq * cr]]
    t = (p["x_m"], p["y_m"], p["z_m"])
    return [rot[i] + [t[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


def from_quaternion(x, y, z, qw, qx, qy, qz):
    rot = [[1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
           [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
           [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]]
    t = (x, y, z)
    return [rot[i] + [t[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


def compose(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(4)) for j in range(4)] for i in range(4)]


def inverse(a):
    rt = [[a[j][i] for j in range(3)] for i in range(3)]
    t = [-sum(rt[i][k] * a[k][3] for k in range(3)) for i in range(3)]
    return [rt[i] + [t[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


def quaternion(m):
    """(qw, qx, qy, qz) of m's rotation, by the largest of the four (Shepperd)."""
    trace = m[0][0] + m[1][1] + m[2][2]
    if trace > 0:
        s = 2 * math.sqrt(1 + trace)
        q = (s / 4, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s)
    elif m[0][0] >= m[1][1] and m[0][0] >= m[2][2]:
        s = 2 * math.sqrt(1 + m[0][0] - m[1][1] - m[2][2])
        q = ((m[2][1] - m[1][2]) / s, s / 4, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s)
    elif m[1][1] >= m[2][2]:
        s = 2 * math.sqrt(1 + m[1][1] - m[0][0] - m[2][2])
        q = ((m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, s / 4, (m[1][2] + m[2][1]) / s)
    else:
        s = 2 * math.sqrt(1 + m[2][2] - m[0][0] - m[1][1])
        q = ((m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, s / 4)
    return q if q[0] >= 0 else tuple(-v for v in q)


def difference(estimate, truth):
    """Translation [m] and rotation [deg] of estimate against truth."""
    d = compose(inverse(truth), estimate)
    cos = max(-1.0, min(1.0, (d[0][0] + d[1][1] + d[2][2] - 1) / 2))
    return math.hypot(d[0][3], d[1][3], d[2][3]), math.degrees(math.acos(cos))


def parse_stops(text):
    try:
        lo, _, hi = text.partition("..")
        first, last = int(lo), int(hi or lo)
    except ValueError:
        raise argparse.ArgumentTypeError(f"'{text}' is not a range A..B of stop numbers")
    if first < 0 or last <= first:
        raise argparse.ArgumentTypeError(f"'{text}': give at least two stops, A..B with 0 <= A < B")
    return list(range(first, last + 1))


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("run", help="a `pitchlab run` output folder (with stops/NNN/)")
    p.add_argument("--stops", type=parse_stops, required=True, help="the stops to replay, A..B")
    p.add_argument("--out", required=True, help="folder for the scans, map and table (new or empty)")
    p.add_argument("--pitchlab", default=shutil.which("pitchlab") or "build/apps/pitchlab",
                   help="the pitchlab binary (default: on PATH, else build/apps/pitchlab)")
    p.add_argument("--config", help="registration settings for merge (its 'registration:' section)")
    args = p.parse_args()
    if os.path.exists(args.out) and os.listdir(args.out):
        p.error(f"--out {args.out} is not empty")
    return args


def read_stop(run, k):
    folder = os.path.join(run, "stops", f"{k:03d}")
    record = os.path.join(folder, "registration.json")
    try:
        with open(record) as f:
            stop = json.load(f)
        for key in ("odometry", "estimate", "truth"):
            from_pose(stop[key])
    except (OSError, ValueError, KeyError, TypeError) as e:
        sys.exit(f"replay_stops: {record}: {e.__class__.__name__}: {e}")
    stop["scan_file"] = os.path.join(folder, "scan.pcd")
    return stop


def with_viewpoint(scan_file, pose, out_file):
    """Copies a PCD with its VIEWPOINT set to `pose` and its pose comment to odometry."""
    try:
        with open(scan_file, "rb") as f:
            data = f.read()
        end = data.index(b"\nDATA ") + 1
    except (OSError, ValueError):
        sys.exit(f"replay_stops: {scan_file}: unreadable, or no PCD header (no DATA line)")
    header = data[:end].decode("ascii", errors="replace").split("\n")
    qw, qx, qy, qz = quaternion(pose)
    viewpoint = f"VIEWPOINT {pose[0][3]:.9f} {pose[1][3]:.9f} {pose[2][3]:.9f} {qw:.12f} {qx:.12f} {qy:.12f} {qz:.12f}"
    lines = [ln for ln in header if not ln.startswith("# pose ")]
    if not any(ln.startswith("VIEWPOINT") for ln in lines):
        sys.exit(f"replay_stops: {scan_file}: no VIEWPOINT line")
    lines = [viewpoint if ln.startswith("VIEWPOINT") else ln for ln in lines]
    lines.insert(1, "# pose odometry")
    with open(out_file, "wb") as f:
        f.write("\n".join(lines).encode("ascii") + data[end:])


def prior_chain(stops):
    """Each stop's odometry pose as the mission used it: the first's as recorded, then each next
    one's odometry relative to the previous stop's final pose, chained."""
    chain = [from_pose(stops[0]["odometry"])]
    for prev, stop in zip(stops, stops[1:]):
        step = compose(inverse(from_pose(prev["estimate"])), from_pose(stop["odometry"]))
        chain.append(compose(chain[-1], step))
    return chain


def read_trajectory(path):
    poses = {}
    with open(path) as f:
        for row in csv.DictReader(f):
            poses[os.path.basename(row["file"])] = from_quaternion(
                *(float(row[k]) for k in ("x_m", "y_m", "z_m", "qw", "qx", "qy", "qz")))
    return poses


def main():
    args = parse_args()
    stops = [read_stop(args.run, k) for k in args.stops]
    os.makedirs(args.out, exist_ok=True)
    files = []
    for k, stop, pose in zip(args.stops, stops, prior_chain(stops)):
        files.append(os.path.join(args.out, f"stop_{k:03d}.pcd"))
        with_viewpoint(stop["scan_file"], pose, files[-1])
    # merge takes one bound for every scan: the widest the mission gave any of these stops.
    bounds = [s.get("prior_bound") or {} for s in stops[1:]]
    bound_m = max(b.get("translation_m", 0.0) for b in bounds)
    bound_deg = max(b.get("rotation_deg", 0.0) for b in bounds)
    cmd = [args.pitchlab, "merge", *files, "--out", os.path.join(args.out, "map.pcd"),
           "--prior-error", f"{bound_m:.6f},{bound_deg:.6f}"]
    if args.config:
        cmd += ["--config", args.config]
    with open(os.path.join(args.out, "merge.log"), "w") as log:
        try:
            subprocess.run(cmd, stdout=log, stderr=subprocess.STDOUT)
        except OSError as e:
            sys.exit(f"replay_stops: cannot run {args.pitchlab}: {e}")
    trajectory = os.path.join(args.out, "map_trajectory.csv")
    if not os.path.exists(trajectory):
        sys.exit(f"replay_stops: merge wrote no trajectory; see {os.path.join(args.out, 'merge.log')}")
    replayed = read_trajectory(trajectory)
    truth0 = inverse(from_pose(stops[0]["truth"]))
    mission0 = inverse(from_pose(stops[0]["estimate"]))
    rows = []
    for k, stop, f in zip(args.stops, stops, files):
        truth = compose(truth0, from_pose(stop["truth"]))
        mission_m, mission_deg = difference(compose(mission0, from_pose(stop["estimate"])), truth)
        row = {"stop": k, "mission_merged": bool(stop.get("merged")),
               "mission_error_m": mission_m, "mission_error_deg": mission_deg,
               "replay_merged": os.path.basename(f) in replayed}
        if row["replay_merged"]:
            row["replay_error_m"], row["replay_error_deg"] = difference(replayed[os.path.basename(f)], truth)
        rows.append(row)
    result = {"run": os.path.abspath(args.run), "command": cmd, "prior_error": [bound_m, bound_deg],
              "frame": f"stop {args.stops[0]}'s base_link", "stops": rows}
    with open(os.path.join(args.out, "replay.json"), "w") as f:
        json.dump(result, f, indent=1)
    print(f"replayed stops {args.stops[0]}..{args.stops[-1]} of {args.run} with prior error "
          f"{bound_m:.3f} m, {bound_deg:.2f} deg; errors against the truth in stop "
          f"{args.stops[0]}'s frame:")
    print(f"{'stop':>5} {'mission':>22} {'replay':>22}")
    for r in rows:
        mission = (f"{r['mission_error_m']:.3f} m {r['mission_error_deg']:.2f} deg"
                   + ("" if r["mission_merged"] else " (odometry)"))
        replay = (f"{r['replay_error_m']:.3f} m {r['replay_error_deg']:.2f} deg"
                  if r["replay_merged"] else "not merged")
        print(f"{r['stop']:>5} {mission:>22} {replay:>22}")
    print(f"merge's log: {os.path.join(args.out, 'merge.log')}")


if __name__ == "__main__":
    main()
