#!/usr/bin/env bash
# Set-up, build, then every test (GoogleTest suites and checks, through CTest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
# The tests' scratch folders (TMPDIR) go under one root per run, removed when the run ends. A run
# killed outright (SIGKILL, a CI timeout) cannot clean up after itself: its root, named by the
# process that made it, is removed by the next run once that process is gone.
for stale in /tmp/pitchlab-ctest.*; do
  [ -d "$stale" ] || continue
  kill -0 "${stale##*.}" 2>/dev/null || rm -rf -- "$stale"
done
export TMPDIR="/tmp/pitchlab-ctest.$$"
mkdir -p "$TMPDIR"
trap 'rm -rf -- "$TMPDIR"' EXIT
ctest --test-dir build --output-on-failure -j"$(nproc)"
