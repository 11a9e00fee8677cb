#!/usr/bin/env bash
# Submits a `pitchlab bench` sweep to Slurm: a job array of N shards (bench.sbatch) and a job
# that merges them once every shard has finished (summarize.sbatch, --dependency=afterok).
#
#   scripts/slurm/submit.sh --out DIR [--shards N] [--sbatch OPTION]... [--wait] \
#       [--] [pitchlab bench options: --worlds ... --seeds ... --config ... --timeout-s ...]
#
# Prints both job ids. DIR must be on a file system every node sees; it gets shard-K-of-N/ per
# task, slurm/ with the jobs' output, and runs.jsonl + summary.json when the merge is done.
# --sbatch OPTION goes to the array's sbatch (e.g. --sbatch --cpus-per-task=4 --sbatch
# --time=2:00:00); SBATCH_PARTITION, SBATCH_ACCOUNT, SBATCH_QOS... apply to both jobs.
# --wait returns only when the merge job has ended, with its exit code (for scripts and CI).
# PITCHLAB: the pitchlab binary (default: this checkout's build/apps/pitchlab, else `pitchlab`).
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
repo=$(cd "$here/../.." && pwd)

usage() {
  sed -n '2,13p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}
die() {
  echo "submit.sh: $*" >&2
  exit 2
}

out=""
shards=4
wait=0
array_options=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) [ $# -ge 2 ] || die "--out needs a folder"; out=$2; shift 2 ;;
    --out=*) out=${1#--out=}; shift ;;
    --shards) [ $# -ge 2 ] || die "--shards needs a number"; shards=$2; shift 2 ;;
    --shards=*) shards=${1#--shards=}; shift ;;
    --sbatch) [ $# -ge 2 ] || die "--sbatch needs an sbatch option"; array_options+=("$2"); shift 2 ;;
    --wait) wait=1; shift ;;
    -h | --help) usage; exit 0 ;;
    --) shift; break ;;
    *) break ;;  # the first option we do not know starts the bench options
  esac
done
[ -n "$out" ] || die "--out DIR is required (the sweep folder, on a file system every node sees)"
case "$shards" in '' | *[!0-9]* | 0) die "--shards '$shards' is not a number >= 1" ;; esac
command -v sbatch >/dev/null || die "sbatch not found: run this on a Slurm login node"

if [ -z "${PITCHLAB:-}" ]; then
  if [ -x "$repo/build/apps/pitchlab" ]; then
    PITCHLAB="$repo/build/apps/pitchlab"
  else
    PITCHLAB=$(command -v pitchlab) || die "no pitchlab binary: build it or set PITCHLAB"
  fi
fi
[ -x "$PITCHLAB" ] || die "PITCHLAB '$PITCHLAB' is not an executable file"
PITCHLAB=$(cd "$(dirname "$PITCHLAB")" && pwd)/$(basename "$PITCHLAB")
export PITCHLAB  # sbatch passes the environment on to the jobs (--export=ALL)

# The folder and the shard are per task; the bench options themselves are checked by the
# first task to start (bad input exits 2 there, and the merge job is then cancelled).
for arg in "$@"; do
  case "$arg" in
    --out | --out=* | --shard | --shard=* | --summarize | --merge)
      die "'$arg' is set per task; give the folder with --out before the bench options" ;;
  esac
done

mkdir -p "$out/slurm"
out=$(cd "$out" && pwd)

# --parsable prints "jobid[;cluster]"; the job id is what the dependency needs.
array_id=$(sbatch --parsable --array="1-$shards" --chdir="$out" \
  --output="$out/slurm/bench-%A_%a.out" "${array_options[@]}" \
  "$here/bench.sbatch" "$out" "$@")
array_id=${array_id%%;*}
echo "submit.sh: array job $array_id: $shards shard(s) of pitchlab bench $* into $out/shard-K-of-$shards"

summary_options=(--parsable --dependency="afterok:$array_id" --kill-on-invalid-dep=yes
  --chdir="$out" --output="$out/slurm/summarize-%j.out")
if [ $wait -eq 0 ]; then
  summary_id=$(sbatch "${summary_options[@]}" "$here/summarize.sbatch" "$out" "$shards")
  echo "submit.sh: summary job ${summary_id%%;*}: after every shard succeeds, merges them into $out/summary.json"
  echo "submit.sh: watch with: squeue -j $array_id,${summary_id%%;*}"
else
  # sbatch --wait prints the id only once the job ends, so announce the job from the output file.
  echo "submit.sh: summary job: after every shard succeeds, merges them into $out/summary.json; waiting"
  status=0
  summary_id=$(sbatch --wait "${summary_options[@]}" "$here/summarize.sbatch" "$out" "$shards") ||
    status=$?
  echo "submit.sh: summary job ${summary_id%%;*} ended with exit code $status"
  exit $status
fi
