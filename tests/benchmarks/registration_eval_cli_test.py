#!/usr/bin/env python3
"""registration_eval's command line: --tilt and mistakes.

--tilt DEG gives every prior the truth's roll and pitch as measured within DEG (what a mission's
attitude sensor gives its registrations); the output says which tolerance it ran with, and a
correct pair registers as it does without. A mistake on the command line (a value that is not a
number, a tolerance out of range, an unknown option) is exit 2 with a message naming the option,
and nothing on stdout.

usage: registration_eval_cli_test.py REGISTRATION_EVAL
"""
import json
import subprocess
import sys

ONE_PAIR = ["--worlds", "corridor", "--targets", "1", "--noise", "0.005", "--levels", "1:15",
            "--baseline-pairs", "0", "--table1-pairs", "0", "--sequence-scans", "0"]


def run(exe, *extra):
    return subprocess.run([exe, *extra], capture_output=True, text=True)


def main():
    exe = sys.argv[1]
    plain = run(exe, *ONE_PAIR)
    tilted = run(exe, *ONE_PAIR, "--tilt", "0.5")
    assert plain.returncode == 0 and tilted.returncode == 0, (plain.stderr, tilted.stderr)
    a, b = json.loads(plain.stdout), json.loads(tilted.stdout)
    assert a["prior_tilt_tolerance_deg"] is None, a["prior_tilt_tolerance_deg"]
    assert b["prior_tilt_tolerance_deg"] == 0.5, b["prior_tilt_tolerance_deg"]
    assert len(a["pairs"]) == len(b["pairs"]) == 1
    pa, pb = a["pairs"][0]["ours"], b["pairs"][0]["ours"]
    assert pa["outcome"] == pb["outcome"] == "success", (pa["reason"], pb["reason"])
    assert pb["within_target"], pb

    for args, named in [(["--tilt", "0"], "--tilt"), (["--tilt", "x"], "--tilt"),
                        (["--targets", "3x"], "--targets"), (["--levels", "1:a"], "--levels"),
                        (["--bogus"], "--bogus")]:
        r = run(exe, *args)
        assert r.returncode == 2, (args, r.returncode, r.stderr)
        assert named in r.stderr, (args, r.stderr)
        assert r.stdout == "", (args, r.stdout)
    print("ok")


if __name__ == "__main__":
    main()
