#!/usr/bin/env bash
# Installs what dynbench needs on Debian bookworm (run as root, or with sudo available).
#   bash scripts/setup.sh         what the main job needs: the build, its libraries, Cube 2 (the
#                                 demo's game), ffmpeg and gnuplot (the report)
#   bash scripts/setup.sh --all   everything: the above, and what the test suite and the other
#                                 engines use (Blender, Chromium, Slurm, clang, OpenArena, qemu,
#                                 the glTF validator)
# Idempotent: when every package is already installed it only checks and returns.
set -euo pipefail

all=0
for arg in "$@"; do
  case "$arg" in
    --all) all=1 ;;
    *) echo "setup: unknown option '$arg' (expected --all or nothing)" >&2; exit 2 ;;
  esac
done

SUDO=""
[[ $(id -u) -eq 0 ]] || SUDO="sudo"

# Keep these lists in step with ../shared/ARCHITECTURE.md §4 and CONTRIBUTING.md.
packages=(
  # build
  build-essential cmake ninja-build pkg-config git
  # libraries
  nlohmann-json3-dev libassimp-dev libglm-dev libopenimageio-dev
  libembree-dev libtbb-dev libhwy-dev
  # the game archives (.pk3) that `map-lights` reads (src/maplight/pak.cpp)
  libzip-dev
  libcli11-dev libfmt-dev libspdlog-dev
  # SHA-256 of a suite's datasets and frames (core/checksum.cpp)
  libssl-dev
  # tests and benchmarks: small header packages that configuring the build needs
  libgtest-dev libgmock-dev googletest libbenchmark-dev zlib1g-dev
  # plots
  gnuplot-nox
  # the magma colour map of FLIP heatmaps, read from matplotlib's tables at build time
  # (tools/colormap/magma_header.py). python3-munkres meets matplotlib's python3-fonttools, which
  # needs "python3-scipy | python3-munkres": named here, it keeps SciPy out, and with it pythran,
  # Boost's headers and OpenBLAS (about 20,000 of a fresh setup's 65,000 files; nothing of
  # dynbench imports SciPy)
  python3-matplotlib python3-munkres
  # the Python module (docs/python.md): pybind11 with its nlohmann::json bridge
  pybind11-dev pybind11-json-dev python3-dev
  # ffmpeg: `dynbench report` encodes each run's video (VP9 WebM) with it
  ffmpeg
  # Cube 2: Sauerbraten (`dynbench capture cube2`, the demo's game): the engine's build needs, its
  # game data, and a virtual X server with Mesa's software OpenGL to run it headless
  libsdl2-dev libsdl2-image-dev libsdl2-mixer-dev libenet-dev libgl-dev cube2-data xvfb xauth
  libgl1-mesa-dri
)
if ((all)); then
  packages+=(
    # test data: FBX / DAE models with skeletons, cameras and lights
    assimp-testmodels
    # Blender: `render --engine cycles` (the thesis's renderer) and the tests that check dynbench's
    # datasets with Blender's glTF importer and its P/N buffers against Cycles
    blender python3-numpy
    # the Python module's tests run pytest and compare frames with OpenImageIO's own Python binding
    python3-pytest python3-openimageio
    # headless Chromium: the tests open `dynbench report`'s HTML in a real browser
    chromium
    # Slurm and munge: `--slurm` job arrays, tried and tested on a single-node cluster on localhost
    # (scripts/slurm-local.sh; docs/cluster.md)
    slurm-wlm munge
    # fuzzing the readers of untrusted input (the `fuzz` preset, CONTRIBUTING.md): clang 16 and its
    # libFuzzer runtime
    clang-16 libclang-rt-16-dev
    # OpenArena (`dynbench capture openarena`): Debian's ioquake3 engine and the game's data; its
    # game code is rebuilt from the source package with the capture hooks (below); qemu-user runs
    # the engine on an emulated CPU, so that a seed plays the same match on every host
    # (integrations/openarena/README.md, "Across CPUs")
    openarena qemu-user
  )
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  # --force-unsafe-io: dpkg skips its fsync after every file it unpacks, which was most of a fresh
  # machine's setup (dpkg unpacked and configured 677 packages in 277 of setup's 292 s on a 2-core
  # AMD EPYC; Debian's own container images set the same). A machine that loses power mid-install
  # may keep a half-written file; apt-get install --reinstall mends it.
  $SUDO apt-get install -y -qq --no-install-recommends -o Dpkg::Options::=--force-unsafe-io "${missing[@]}"
else
  echo "setup: all ${#packages[@]} Debian packages present"
fi

# Game source code from Debian's source packages, fetched once into caches that the CMake build
# reads: Cube 2's engine (integrations/cube2/build.sh) and OpenArena's game code
# (integrations/openarena/build.sh). apt-get source needs a deb-src entry for bookworm.
fetch_source() {  # NAME PACKAGE=VERSION ORIG_TARBALL
  local name=$1 package=$2 orig=$3
  local cache=/var/cache/dynbench/$name
  if [[ -f "$cache/$orig" ]]; then
    echo "setup: $name source present"
    return
  fi
  if ! grep -rqs "^Types: deb-src\|^deb-src" /etc/apt/sources.list /etc/apt/sources.list.d/; then
    echo "setup: adding a deb-src entry for bookworm (game source packages)"
    $SUDO tee /etc/apt/sources.list.d/dynbench-src.sources >/dev/null <<'SOURCES'
Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
SOURCES
    $SUDO apt-get update -qq
  fi
  $SUDO mkdir -p "$cache"
  # The mirror has the .orig tarballs but not always Debian's packaging tarballs, and apt-get then
  # exits 100 after fetching the one we need: judge by the file, not the exit status.
  (cd "$cache" && $SUDO apt-get source --download-only "$package" >/dev/null 2>&1 || true)
  if [[ ! -f "$cache/$orig" ]]; then
    echo "setup: could not fetch $orig with apt-get source (is deb.debian.org reachable?)" >&2
    exit 1
  fi
  echo "setup: $name source in $cache"
}
fetch_source cube2 "cube2=0.0.20201227+dfsg-2" cube2_0.0.20201227+dfsg.orig.tar.xz
((all)) || exit 0
fetch_source openarena "openarena=0.8.8+dfsg-6" openarena_0.8.8+dfsg.orig.tar.xz

# The Khronos glTF validator (npm), which the tests run on every dataset dynbench writes.
# Node.js comes from Debian when the machine has none.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "setup: installing nodejs and npm"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends -o Dpkg::Options::=--force-unsafe-io nodejs npm
fi
here=$(cd "$(dirname "$0")/.." && pwd)
validator="$here/tools/gltf-validator"
if [[ ! -f "$validator/node_modules/gltf-validator/package.json" ]] ||
   ! grep -q '"version": "2.0.0-dev.3.10"' "$validator/node_modules/gltf-validator/package.json"; then
  echo "setup: installing the Khronos glTF validator (npm ci)"
  (cd "$validator" && npm ci --no-audit --no-fund --loglevel=error)
else
  echo "setup: glTF validator present"
fi

