#!/usr/bin/env bash
# Installs dynbench from BUILD_DIR into a fresh prefix, builds tests/install/sdk_example.c against
# the installed capture SDK twice (pkg-config; CMake find_package), runs both, and checks both
# captures with the installed `dynbench capture-check`, run from another folder.
# With a third argument `python`, also imports the installed Python package.
# Usage: install_test.sh BUILD_DIR WORK_DIR [python]
set -euo pipefail
build=$(cd "$1" && pwd)
work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"
mkdir -p "$work"
work=$(cd "$work" && pwd)
prefix=$work/prefix

cmake --install "$build" --prefix "$prefix" >/dev/null
for f in bin/dynbench lib/libdynbench_capture.so include/dynbench/capture.h lib/pkgconfig/dynbench-capture.pc \
         lib/cmake/dynbench/dynbench-config.cmake lib/dynbench/libdynbench_image.so share/dynbench/blender/render_cycles.py; do
  [[ -e "$prefix/$f" ]] || { echo "install_test: $prefix/$f was not installed"; exit 1; }
done

# 1. pkg-config
PKG_CONFIG_PATH=$prefix/lib/pkgconfig cc -o "$work/example_pkgconfig" "$here/sdk_example.c" \
  $(PKG_CONFIG_PATH=$prefix/lib/pkgconfig pkg-config --cflags --libs dynbench-capture) -lm
# 2. CMake
cmake -S "$here/cmake_consumer" -B "$work/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/consumer" >/dev/null

mkdir -p "$work/elsewhere"
cd "$work/elsewhere"  # not the build tree, not the prefix
for example in "$work/example_pkgconfig" "$work/consumer/sdk_example"; do
  capture=$work/capture_$(basename "$(dirname "$example")")_$(basename "$example")
  "$example" "$capture"
  "$prefix/bin/dynbench" capture-check "$capture" --json "$capture.json"
  grep -q '"frames": 12' "$capture.json" || { echo "install_test: $capture.json does not count 12 frames"; cat "$capture.json"; exit 1; }
done
# The installed executable finds its own run-time files: convert writes the dataset's sky through
# the image module, which must be the installed one, not the build tree's.
LD_DEBUG=libs "$prefix/bin/dynbench" convert "$work/capture_consumer_sdk_example" -o "$work/dataset/crate.gltf" 2>"$work/ld.log" >/dev/null
grep -q "calling init: $prefix/lib/dynbench/libdynbench_image.so" "$work/ld.log" ||
  { echo "install_test: the installed dynbench did not load $prefix/lib/dynbench/libdynbench_image.so"; grep image "$work/ld.log"; exit 1; }
"$prefix/bin/dynbench" stats "$work/dataset/crate.gltf" | grep -q "| crate.gltf " || { echo "install_test: stats of the converted dataset failed"; exit 1; }
# OpenArena's installed game modules: the installed `capture openarena` finds them, and they load
# the installed SDK (a real engine linked with the SDK as installed).
if [[ -e "$prefix/lib/dynbench/openarena/cgamex86_64.so" && -x /usr/lib/ioquake3/ioquake3 ]]; then
  mkdir -p "$work/ld_oa"
  LD_DEBUG=libs LD_DEBUG_OUTPUT="$work/ld_oa/ld" "$prefix/bin/dynbench" capture openarena -o "$work/oa" --seconds 1 --bots 2 --game-cpu host >"$work/oa.log" 2>&1 ||
    { echo "install_test: the installed capture openarena failed"; tail "$work/oa.log"; exit 1; }
  cat "$work"/ld_oa/ld.* >"$work/ld_oa.log"
  grep -q "calling init: .*/baseoa/cgamex86_64.so" "$work/ld_oa.log" &&
    grep -q "calling init: $prefix/lib/libdynbench_capture.so" "$work/ld_oa.log" ||
    { echo "install_test: the installed game module did not load the installed SDK"; grep "calling init: .*\(cgame\|dynbench_capture\)" "$work/ld_oa.log"; exit 1; }
  "$prefix/bin/dynbench" capture-check "$work/oa" | grep -q "frames: *50 " || { echo "install_test: the OpenArena capture is not 50 frames"; exit 1; }
fi
# The installed Python package (docs/python.md), imported from here with PYTHONPATH into the
# prefix: its stats equal the installed CLI's, and it reads images through the installed image module.
if [[ "${3:-}" == python ]]; then
site=$prefix/$(/usr/bin/python3 -c "import sys; print('lib/python%d.%d/dist-packages' % sys.version_info[:2])")
[[ -f "$site/dynbench/__init__.py" ]] || { echo "install_test: the Python package is not in $site/dynbench"; exit 1; }
sky=$(find "$work/dataset" -name '*.exr' -o -name '*.hdr' | head -n 1)
[[ -n "$sky" ]] || { echo "install_test: the converted dataset has no HDR image to read"; ls -R "$work/dataset"; exit 1; }
"$prefix/bin/dynbench" stats "$work/dataset/crate.gltf" --json "$work/stats_cli.json" >/dev/null
LD_DEBUG=libs PYTHONPATH=$site /usr/bin/python3 - "$work/dataset/crate.gltf" "$work/stats_cli.json" "$sky" 2>"$work/ld_python.log" <<'PYTHON'
import json, os, sys
import dynbench
dataset, cli, sky = sys.argv[1:]
assert dynbench.__file__.startswith(os.environ["PYTHONPATH"]), f"imported {dynbench.__file__}, not the installed package"
assert dynbench.stats([dataset]) == json.load(open(cli)), "the installed module's stats differ from the installed CLI's"
assert dynbench.compare(sky, sky)["images"][0]["flip"]["mean"] == 0.0
PYTHON
grep -q "calling init: $prefix/lib/dynbench/libdynbench_image.so" "$work/ld_python.log" ||
  { echo "install_test: the installed Python module did not load $prefix/lib/dynbench/libdynbench_image.so"; grep -i "image\|Error" "$work/ld_python.log" | tail; exit 1; }
fi
echo "install_test: both SDK builds wrote captures the installed dynbench accepts"
