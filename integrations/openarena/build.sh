#!/usr/bin/env bash
# Builds OpenArena's game modules with dynbench's capture hooks: the game code from Debian's
# source package `openarena` (0.8.8+dfsg, GPL-2), patched by capture-hooks.patch, with the adapter
# (src/dynbench_oa*.{c,h}) in the client game module, linked with the capture SDK *as installed*
# (found with pkg-config, like any engine outside dynbench's build):
#   bash integrations/openarena/build.sh BUILD_DIR SDK_PREFIX
# SDK_PREFIX is where `cmake --install BUILD --component sdk --prefix SDK_PREFIX` put the SDK (the
# CMake target openarena_modules does both). Prints the folder holding cgamex86_64.so and
# qagamex86_64.so, which Debian's ioquake3 loads in place of the game's own (vm_cgame 0,
# vm_game 0; src/capture/openarena.cpp). Needs scripts/setup.sh run first (the source tarball).
set -euo pipefail

build_dir=${1:-build/openarena}
sdk=$(cd "${2:?the SDK prefix}" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
version=0.8.8+dfsg
orig=openarena_${version}.orig.tar.xz
mkdir -p "$build_dir"
build_dir=$(cd "$build_dir" && pwd)

# scripts/setup.sh fetches the tarball (apt-get source) into this cache; this script never touches apt.
cache=${DYNBENCH_OPENARENA_CACHE:-/var/cache/dynbench/openarena}
if [[ ! -f "$build_dir/$orig" ]]; then
  [[ -f "$cache/$orig" ]] || { echo "openarena: $cache/$orig missing: run scripts/setup.sh --all (it fetches the game code)" >&2; exit 1; }
  cp "$cache/$orig" "$build_dir/$orig"
fi

export PKG_CONFIG_PATH="$sdk/lib/pkgconfig"
pkg-config --exists dynbench-capture || { echo "openarena: no dynbench-capture.pc under $sdk/lib/pkgconfig: install the SDK first" >&2; exit 1; }
cflags=$(pkg-config --cflags dynbench-capture)
# Run paths: first the installed layout's (PREFIX/lib/dynbench/openarena holds the modules,
# PREFIX/lib the SDK), so that installed modules load the installed SDK; then the SDK's own
# (pkg-config's), for the modules in the build folder. OpenGL: the adapter reads the game's own
# frames back (capture openarena --game-frames).
libs="-Wl,-rpath,'\$\$ORIGIN/../..' $(pkg-config --libs dynbench-capture) -lGL"

src="$build_dir/oa-0.8.8"
# A fresh tree whenever the patch changes; the adapter is copied in every time.
if ! cmp -s "$here/capture-hooks.patch" "$src/.dynbench-patch" 2>/dev/null; then
  rm -rf "$src"
  tar -xf "$build_dir/$orig" -C "$build_dir"
  patch -d "$src" -p1 --quiet < "$here/capture-hooks.patch"
  cp "$here/capture-hooks.patch" "$src/.dynbench-patch"
fi
for f in dynbench_oa.h dynbench_oa_internal.h dynbench_oa.c dynbench_oa_assets.c dynbench_oa_bsp.c dynbench_oa_md3.c; do
  cmp -s "$here/src/$f" "$src/code/cgame/$f" || cp "$here/src/$f" "$src/code/cgame/$f"
done
out="$src/build/release-linux-x86_64/baseq3"
# The game's Makefile does not know the adapter's headers, the SDK or this script's link flags:
# rebuild the client module when any of them is newer.
for dep in "$src/code/cgame/dynbench_oa.h" "$src/code/cgame/dynbench_oa_internal.h" "$sdk/lib/libdynbench_capture.so" "$here/build.sh"; do
  [[ -f "$out/cgamex86_64.so" && "$dep" -nt "$out/cgamex86_64.so" ]] && rm -f "$out/cgamex86_64.so" "$out"/cgame/*.o
done
# ioquake3's x86_64 release flags, and no reciprocal estimates: under -ffast-math GCC computes x/y
# and 1/sqrt(x) from RCPPS/RSQRTPS estimates, whose bits differ between Intel and AMD (the x86 ISA
# leaves them to the implementation); the client module had 9 (the adapter's normals and poses
# among them). The same cause made Cube 2's matches differ between the two
# (integrations/cube2/README.md). Modules built with other flags are rebuilt. Debian's engine
# binary (ioquake3) keeps 8 RSQRTSS of its own: not ours to rebuild.
optimize="-O3 -fomit-frame-pointer -ffast-math -funroll-loops -falign-loops=2 -falign-jumps=2 -falign-functions=2 -fstrength-reduce -mno-recip -fno-reciprocal-math"
if [[ "$(cat "$src/.dynbench-optimize" 2>/dev/null)" != "$optimize" ]]; then
  rm -rf "$src/build"
  echo "$optimize" >"$src/.dynbench-optimize"
fi
make -C "$src" -j"$(nproc)" release BUILD_GAME_QVM=0 BUILD_MISSIONPACK=0 OPTIMIZE="$optimize" \
  DYNBENCH_CFLAGS="$cflags" DYNBENCH_LIBS="$libs" \
  >"$build_dir/build.log" 2>&1 || { tail -20 "$build_dir/build.log" >&2; exit 1; }
for m in cgamex86_64.so qagamex86_64.so; do
  [[ -f "$out/$m" ]] || { echo "openarena: $out/$m was not built (see $build_dir/build.log)" >&2; exit 1; }
done
echo "$out"
