#!/usr/bin/env bash
# The main job: set-up, build, then a full 3D scan of the default world (terrain) written as PCD
# with its summary. Extra arguments go to `pitchlab scan`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
mkdir -p out
./build/apps/pitchlab scan --out out/scan.pcd "$@"
