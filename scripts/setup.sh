#!/usr/bin/env bash
# Installs every Debian package pitchlab needs to build and test. Idempotent; run as root.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libmujoco-dev libembree-dev libpcl-dev libgeographiclib-dev
  libyaml-cpp-dev libexpected-dev libpng-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libboost-graph-dev
  libjs-three chromium  # the report's 3D view; its headless-browser test
  slurmctld slurmd slurm-client munge  # scripts/test-slurm.sh
  clang libclang-rt-dev valgrind  # the hw libFuzzer targets in CTest; scripts/sanitize.sh
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

if [ "$(id -u)" -ne 0 ]; then
  echo "setup: missing packages: ${missing[*]}" >&2
  echo "setup: run as root (or with sudo) to install them" >&2
  exit 1
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -q
apt-get install -y -q --no-install-recommends "${missing[@]}"
