#!/usr/bin/env bash
# Installs everything dynbench needs on Debian bookworm (run as root, or with sudo available).
# Idempotent: when every package is already installed it only checks and returns.
set -euo pipefail

# Keep this list in step with docs/dependencies in README.md.
packages=(
  # build
  build-essential cmake ninja-build pkg-config git
  # libraries
  nlohmann-json3-dev libassimp-dev libglm-dev
  libcli11-dev libfmt-dev libspdlog-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev googletest libbenchmark-dev zlib1g-dev
  # plots
  gnuplot-nox
  # test data: FBX / DAE models with skeletons, cameras and lights
  assimp-testmodels
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [[ $(id -u) -eq 0 ]] || SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
else
  echo "setup: all ${#packages[@]} Debian packages present"
fi
