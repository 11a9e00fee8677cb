#!/usr/bin/env bash
# The main job: set-up, build, then a closed-loop stop-scan-go run on the default world (terrain,
# 35 m to the goal past the butte), written to runs/<world>-s<seed>-<time>/ with report.html.
# Extra arguments go to `pitchlab run` (see `build/apps/pitchlab run --help`).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
./build/apps/pitchlab run "$@"
