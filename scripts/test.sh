#!/usr/bin/env bash
# Set-up, build, then every test (GoogleTest suites and checks, through CTest).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
ctest --test-dir build --output-on-failure -j"$(nproc)"
