#!/usr/bin/env bash
# End-to-end test of scripts/slurm/: starts a private one-node Slurm on this machine (its own
# munged, slurmctld and slurmd, config, ports, state and logs under a temporary folder), submits a
# 4-shard sweep with scripts/slurm/submit.sh, runs the same sweep locally with `pitchlab bench`,
# checks that the merged summary and every run's record equal the local ones, and shuts it all
# down again (also on failure or interruption).
#
#   bash scripts/test-slurm.sh PITCHLAB_BINARY
#
# Exit 0 pass, 1 fail, 77 skipped (Slurm or munge not installed, or not root: the daemons must
# run as their own users). Ports: PITCHLAB_SLURMCTLD_PORT / PITCHLAB_SLURMD_PORT (defaults 6817 /
# 6818; free ones are picked when those are taken, so parallel CI jobs do not collide).
# PITCHLAB_SLURM_KEEP=1 keeps the temporary folder for a look at the logs.
set -euo pipefail

readonly SKIP=77
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/.." && pwd)
started_at=$SECONDS

say() { echo "test-slurm: $*"; }
fail() {
  echo "test-slurm: FAIL: $*" >&2
  exit 1
}

[ $# -eq 1 ] || { echo "usage: $0 PITCHLAB_BINARY" >&2; exit 2; }
pitchlab=$(cd "$(dirname "$1")" && pwd)/$(basename "$1")
[ -x "$pitchlab" ] || fail "'$1' is not an executable pitchlab binary"

# ---- skip when this machine cannot host a Slurm ------------------------------------------------
for tool in slurmctld slurmd sbatch squeue scancel sinfo munged mungekey munge unmunge runuser; do
  if ! command -v "$tool" >/dev/null; then
    echo "SKIP: $tool not installed (scripts/setup.sh installs slurmctld slurmd slurm-client munge)"
    exit $SKIP
  fi
done
if [ "$(id -u)" -ne 0 ]; then
  echo "SKIP: not root (munged and slurmctld run as their own users, slurmd as root)"
  exit $SKIP
fi
id munge >/dev/null 2>&1 || { echo "SKIP: no 'munge' user (the munge package creates it)"; exit $SKIP; }
# The comparison reads JSON with python3 (on these machines through libpcl-dev's VTK).
command -v python3 >/dev/null || fail "python3 is needed to compare the summaries"

# Slurm's daemons run as the 'slurm' user the package creates (as on a real cluster); root works too.
slurm_user=slurm
id "$slurm_user" >/dev/null 2>&1 || slurm_user=root

# ---- a private folder, and a marker to find every process this test started --------------------
tmp=$(mktemp -d /tmp/pitchlab-slurm.XXXXXX)
chmod 0755 "$tmp"  # munge and slurm must reach their folders inside
marker="PITCHLAB_SLURM_TEST=$tmp"
munge_dir=$tmp/munge
socket=$munge_dir/munge.socket
slurmctld_pid=""
slurmd_pid=""

# Pids of processes whose environment carries the marker: the daemons, slurmstepd and the jobs.
marked_pids() {
  local f pid
  for f in /proc/[0-9]*/environ; do
    pid=${f#/proc/}
    pid=${pid%/environ}
    [ "$pid" = $$ ] && continue
    # Processes come and go while we read: a vanished one is not ours to kill.
    tr '\0' '\n' 2>/dev/null <"$f" | grep -qxF "$marker" && echo "$pid"
  done
  return 0
}

# Sends TERM to a pid and waits up to $2 s for it to end, then KILLs it.
stop_pid() {
  local pid=$1 grace=$2 i
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 0
  kill -TERM "$pid" 2>/dev/null || true
  for ((i = 0; i < grace * 10; i++)); do
    kill -0 "$pid" 2>/dev/null || return 0
    sleep 0.1
  done
  kill -KILL "$pid" 2>/dev/null || true
}

cleanup() {
  local status=$?
  set +e
  trap - EXIT INT TERM HUP
  if [ -n "$slurmctld_pid" ] && kill -0 "$slurmctld_pid" 2>/dev/null; then
    # Jobs first, so slurmd still ends their steps cleanly.
    local jobs
    jobs=$(squeue -h -o %i 2>/dev/null | tr '\n' ' ')
    if [ -n "${jobs// /}" ]; then
      say "cancelling jobs $jobs"
      scancel $jobs 2>/dev/null
      for ((i = 0; i < 150; i++)); do
        [ -z "$(squeue -h -o %i 2>/dev/null)" ] && break
        sleep 0.2
      done
    fi
  fi
  # Slurm before munged: the daemons authenticate their last messages through it.
  stop_pid "$slurmd_pid" 15
  stop_pid "$slurmctld_pid" 15
  [ -f "$munge_dir/munged.pid" ] && stop_pid "$(cat "$munge_dir/munged.pid")" 10
  # Anything of ours still alive (a slurmstepd, a job's bench) goes too.
  local left
  left=$(marked_pids)
  if [ -n "$left" ]; then
    say "killing leftover processes $(echo $left)"
    kill -KILL $left 2>/dev/null
  fi
  if [ $status -ne 0 ] && [ $status -ne $SKIP ] && [ -d "$tmp/slurm/log" ]; then
    for log in "$tmp"/slurm/log/*.log "$tmp"/cluster/slurm/*.out "$munge_dir/munged.log"; do
      [ -f "$log" ] || continue
      echo "---- last lines of $log" >&2
      tail -n 25 "$log" >&2
    done
  fi
  if [ "${PITCHLAB_SLURM_KEEP:-0}" = 1 ]; then
    say "kept $tmp"
  else
    rm -rf "$tmp"
  fi
  exit $status
}
trap cleanup EXIT
trap 'exit 130' INT TERM HUP  # through cleanup

# Waits up to $1 s (wall clock: one try of a Slurm command can itself take seconds) for the
# command after it to succeed.
wait_for() {
  local deadline=$((SECONDS + $1))
  shift
  while [ $SECONDS -lt $deadline ]; do
    "$@" >/dev/null 2>&1 && return 0
    sleep 0.2
  done
  return 1
}

port_busy() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
# The wanted port when nothing listens on it, else (or for 0) a free one below the ephemeral range.
pick_port() {
  local port=$1 avoid=$2 i
  if [ "$port" != 0 ] && ! port_busy "$port" && [ "$port" != "$avoid" ]; then
    echo "$port"
    return
  fi
  for ((i = 0; i < 200; i++)); do
    port=$((20000 + RANDOM % 12000))
    if ! port_busy "$port" && [ "$port" != "$avoid" ]; then
      echo "$port"
      return
    fi
  done
  fail "no free TCP port found for Slurm"
}
ctld_port=$(pick_port "${PITCHLAB_SLURMCTLD_PORT:-6817}" "")
slurmd_port=$(pick_port "${PITCHLAB_SLURMD_PORT:-6818}" "$ctld_port")

# ---- munged with its own key and socket (the system's /etc/munge and /run/munge stay untouched) -
mkdir -p "$munge_dir"
chown munge:munge "$munge_dir"
chmod 0755 "$munge_dir"  # clients (root, slurm) connect to the socket in it
runuser -u munge -- mungekey --create --keyfile="$munge_dir/munge.key" ||
  fail "mungekey could not create a key in $munge_dir"
env "$marker" runuser -u munge -- munged --key-file="$munge_dir/munge.key" --socket="$socket" \
  --pid-file="$munge_dir/munged.pid" --log-file="$munge_dir/munged.log" \
  --seed-file="$munge_dir/munged.seed" ||
  fail "munged did not start (see $munge_dir/munged.log)"
wait_for 20 bash -c "munge -n -S '$socket' | unmunge -S '$socket'" ||
  fail "munged does not answer on $socket"

# ---- slurmctld and slurmd ------------------------------------------------------------------------
sdir=$tmp/slurm
mkdir -p "$sdir/state" "$sdir/spool" "$sdir/log" "$sdir/run"
chown "$slurm_user" "$sdir/state" "$sdir/log" "$sdir/run"  # slurmctld writes there as SlurmUser
chmod 0755 "$sdir" "$sdir/log" "$sdir/run"
memory=$(slurmd -C | sed -n 's/.*RealMemory=\([0-9]*\).*/\1/p')
[ -n "$memory" ] || fail "slurmd -C did not report this machine's memory"
cpus=$(nproc)

export SLURM_CONF=$sdir/slurm.conf  # every Slurm command of this test reads this config
write_conf() {
  cat >"$SLURM_CONF" <<CONF
# A one-node cluster for scripts/test-slurm.sh, private to $tmp.
ClusterName=pitchlabtest
SlurmctldHost=localhost
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
SlurmUser=$slurm_user
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$socket
StateSaveLocation=$sdir/state
SlurmdSpoolDir=$sdir/spool
SlurmctldPidFile=$sdir/run/slurmctld.pid
SlurmdPidFile=$sdir/run/slurmd.pid
SlurmctldLogFile=$sdir/log/slurmctld.log
SlurmdLogFile=$sdir/log/slurmd.log
MailProg=/bin/true
# No systemd and no cgroup hierarchy of our own here: with cgroup plugins every job fails while
# Slurm records it COMPLETED with exit 0, hence linuxproc/none (and the output checks below).
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SwitchType=switch/none
# Cores, not whole nodes, are allocated: several array tasks run at once on the one node.
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/backfill
# Start batch jobs without delay and forget ended ones soon, so sbatch --wait returns quickly.
SchedulerParameters=batch_sched_delay=0
MinJobAge=5
ReturnToService=2
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory State=UNKNOWN
PartitionName=test Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
  chmod 0644 "$SLURM_CONF"
}

# Starts slurmctld and slurmd on the chosen ports; 1 when one of them died at once (most
# likely a port taken between our check and its bind, e.g. by a parallel CI job).
start_slurm() {
  write_conf
  say "starting slurmctld (port $ctld_port) and slurmd (port $slurmd_port) in $tmp"
  env "$marker" slurmctld -c -D >"$sdir/log/slurmctld.stderr" 2>&1 &
  slurmctld_pid=$!
  wait_for 30 dead_or "$slurmctld_pid" scontrol ping || true
  kill -0 "$slurmctld_pid" 2>/dev/null || return 1
  scontrol ping >/dev/null 2>&1 || fail "slurmctld does not answer (see $sdir/log/slurmctld.log)"
  env "$marker" slurmd -D -N localhost >"$sdir/log/slurmd.stderr" 2>&1 &
  slurmd_pid=$!
  wait_for 60 dead_or "$slurmd_pid" node_idle || true
  kill -0 "$slurmd_pid" 2>/dev/null || return 1
  node_idle ||
    fail "node localhost is not idle: $(sinfo -h -N -o '%N %T %E' 2>&1) (see $sdir/log/slurmd.log)"
}
node_idle() { [ "$(sinfo -h -n localhost -o %T)" = idle ]; }
# Succeeds when the pid has ended or the command after it succeeds: a daemon that died at start
# ends the wait at once instead of after the whole timeout.
dead_or() {
  local pid=$1
  shift
  kill -0 "$pid" 2>/dev/null || return 0
  "$@"
}

for attempt in 1 2 3; do
  start_slurm && break
  [ $attempt -lt 3 ] || fail "Slurm did not start: $(tail -q -n 3 "$sdir"/log/*.stderr)"
  say "a daemon died at start ($(tail -q -n 1 "$sdir"/log/*.stderr | tr '\n' ' ')); other ports"
  stop_pid "$slurmd_pid" 15
  stop_pid "$slurmctld_pid" 15
  slurmd_pid="" slurmctld_pid=""
  ctld_port=$(pick_port 0 "")
  slurmd_port=$(pick_port 0 "$ctld_port")
done
say "one-node Slurm up in $((SECONDS - started_at)) s: $cpus CPU(s)"

# ---- the sweep on Slurm, then the same sweep here --------------------------------------------------
# Four short runs in the small yard world (one per shard, ~20 s each); the whole sweep is
# spelled once so both sides run exactly the same thing.
sweep=(--worlds "$repo/tests/data/worlds/yard.xml" --seeds 1..4 --timeout-s 120)
cluster=$tmp/cluster
local_dir=$tmp/local

t0=$SECONDS
status=0
# Long commands run in the background with `wait`: bash runs a trap only once the foreground
# command ends, but interrupts `wait` at once, so a stopped test cleans up without delay.
env "$marker" PITCHLAB="$pitchlab" timeout 600 bash "$repo/scripts/slurm/submit.sh" \
  --out "$cluster" --shards 4 --wait -- "${sweep[@]}" &
wait $! || status=$?
say "Slurm sweep took $((SECONDS - t0)) s"
[ $status -eq 0 ] || fail "submit.sh --wait exited $status (the merge job failed or never ran)"

# Slurm's exit codes are not the whole story (a job that never ran its script can still be
# COMPLETED 0): every task must have left its own output and its shard's record.
for k in 1 2 3 4; do
  shard=$cluster/shard-$k-of-4
  [ -f "$shard/runs.jsonl" ] || fail "shard $k wrote no $shard/runs.jsonl"
  records=$(grep -c . "$shard/runs.jsonl")
  [ "$records" -eq 1 ] || fail "shard $k recorded $records runs, expected 1 of the 4"
  out=$(ls "$cluster"/slurm/bench-*_"$k".out 2>/dev/null | head -n 1)
  [ -n "$out" ] || fail "no Slurm output file for array task $k in $cluster/slurm"
  grep -q "shard $k/4" "$out" || fail "array task $k did not run shard $k/4: $(tail -n 3 "$out")"
done
summary_out=$(ls "$cluster"/slurm/summarize-*.out 2>/dev/null | head -n 1)
[ -n "$summary_out" ] || fail "the merge job left no output in $cluster/slurm"
grep -q "merging 4 shards" "$summary_out" || fail "the merge job did not merge: $(cat "$summary_out")"
[ -f "$cluster/summary.json" ] || fail "the merge job wrote no $cluster/summary.json"

t0=$SECONDS
env "$marker" timeout 600 "$pitchlab" bench "${sweep[@]}" --jobs "$cpus" --quiet \
  --out "$local_dir" >/dev/null &
wait $! || status=$?
[ $status -eq 0 ] || fail "the local sweep exited $status (124: over 600 s)"
say "local sweep took $((SECONDS - t0)) s"

# ---- merged == local, run by run --------------------------------------------------------------------
# Equal except what depends on the machine's load or on where the files are: wall times, the
# real-time factor, the shard a run was in and the folders.
compare() {
  python3 - "$@" <<'PY'
import json, sys

merged_dir, local_dir = sys.argv[1], sys.argv[2]
VOLATILE_RECORD = {"wall_time_s", "run_wall_time_s", "real_time_factor", "shard", "bench_dir"}
VOLATILE_ROW = {"median_wall_time_s", "max_wall_time_s", "median_real_time_factor"}

def records(folder):
    with open(folder + "/runs.jsonl") as f:
        rows = [json.loads(line) for line in f if line.strip()]
    return {f'{r["world"]}-s{r["seed"]}': {k: v for k, v in r.items() if k not in VOLATILE_RECORD}
            for r in rows}

def summary(folder):
    with open(folder + "/summary.json") as f:
        s = json.load(f)
    strip = lambda row: {k: v for k, v in row.items() if k not in VOLATILE_ROW}
    return {"worlds": [strip(r) for r in s["worlds"]], "total": strip(s["total"]),
            "duplicates_ignored": s["duplicates_ignored"]}

problems = []
m, l = records(merged_dir), records(local_dir)
if sorted(m) != sorted(l):
    problems.append(f"runs differ: merged {sorted(m)}, local {sorted(l)}")
for run in sorted(set(m) & set(l)):
    for key in sorted(set(m[run]) | set(l[run])):
        if m[run].get(key, "<missing>") != l[run].get(key, "<missing>"):
            problems.append(f"{run} {key}: merged {m[run].get(key, '<missing>')!r}, "
                            f"local {l[run].get(key, '<missing>')!r}")
ms, ls = summary(merged_dir), summary(local_dir)
if ms != ls:
    problems.append("summaries differ:\n  merged " + json.dumps(ms, sort_keys=True) +
                    "\n  local  " + json.dumps(ls, sort_keys=True))
for p in problems:
    print("  " + p)
total = ls["total"]
if not problems:
    print(f"  {len(l)} runs equal, {total['successes']} of {total['runs']} succeeded")
sys.exit(1 if problems else 0)
PY
}

say "merged summary vs local sweep:"
compare "$cluster" "$local_dir" || fail "the Slurm sweep's merged summary differs from the local sweep"
runs=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["total"]["runs"])' \
  "$cluster/summary.json")
[ "$runs" -eq 4 ] || fail "the merged summary counts $runs runs, expected 4"

# The comparison itself must see a lost shard: a merge of three shards has to differ.
"$pitchlab" bench --summarize --out "$tmp/three" "$cluster"/shard-{1,2,3}-of-4 >/dev/null ||
  fail "merging three shards by hand exited $?"
if compare "$tmp/three" "$local_dir" >/dev/null; then
  fail "the comparison did not notice a merge missing shard 4"
fi

say "PASS in $((SECONDS - started_at)) s"
