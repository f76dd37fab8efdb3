#!/usr/bin/env bash
# Installs, from Debian's archive, the packages sonarbench needs, and only those that are missing,
# so it is cheap to call before every build. `run`: what builds the sonarbench program (and lets
# CMake configure the tests beside it); `slurm`: the one-node cluster of ci/test-slurm.sh; `curl`
# and `node`: what ci/install-three.sh and ci/install-npm.sh fetch with; no argument: everything
# the tests, the sanitizers and the Python module use too.
# Needs root (or sudo).
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  libeigen3-dev liboctomap-dev libopencv-dev libembree-dev libyaml-cpp-dev
  libcli11-dev libmatio-dev zlib1g-dev libzstd-dev nlohmann-json3-dev libabsl-dev libassimp-dev
  libssl-dev libgtest-dev libbenchmark-dev
)
case "${1:-all}" in
  run) ;;
  slurm) packages=(slurmctld slurmd slurm-client munge python3) ;;
  curl) packages=(curl ca-certificates) ;;
  node) packages=(nodejs npm) ;;
  all) packages+=(libxml2-utils pybind11-dev python3-dev python3-numpy python3-matplotlib
                  python3-pytest chromium
                  clang libclang-rt-14-dev libomp-14-dev) ;;
  *) echo "ci/install-deps.sh: expected run, slurm, curl, node or nothing, got '$1'" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "ci/install-deps.sh: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -q
$sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
