#!/usr/bin/env bash
# Installs every Debian package pitchlab needs to build and test. Idempotent; run as root.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev libmujoco-dev libembree-dev libpcl-dev libgeographiclib-dev
  libyaml-cpp-dev libexpected-dev libpng-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libboost-graph-dev
  libcli11-dev  # the pitchlab command's option parsing (apps/cli_args.cpp)
  libceres-dev  # the pose graph (mapping/src/pose_graph.cpp)
  libgdal-dev  # raster DEMs, GeoTIFF and the rest: headers, and the library dlopen loads
  libjs-three chromium  # the report's 3D view; its headless-browser test
  slurmctld slurmd slurm-client munge  # scripts/test-slurm.sh
  clang libclang-rt-dev valgrind  # the hw libFuzzer targets in CTest; scripts/sanitize.sh
  python3  # scripts/check_function_size.py in CTest
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
# Installing slurmctld/slurmd/munge must not start the system's daemons: pitchlab's tests start
# private ones, and slurmctld without /etc/slurm/slurm.conf fails to start, which can fail the
# install. policy-rc.d exit 101 is Debian's "do not start services" (invoke-rc.d(8)); ours is
# removed afterwards, an existing one is left alone.
policy=/usr/sbin/policy-rc.d
if [ ! -e "$policy" ]; then
  printf '#!/bin/sh\nexit 101\n' > "$policy"
  chmod +x "$policy"
  trap 'rm -f "$policy"' EXIT
fi
apt-get update -q
apt-get install -y -q --no-install-recommends "${missing[@]}"
