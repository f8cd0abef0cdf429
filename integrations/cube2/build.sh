#!/usr/bin/env bash
# Takes the Cube 2: Sauerbraten engine source that scripts/setup.sh fetched from Debian (source
# package `cube2`, the December 2020 release, zlib licence), applies dynbench's capture hooks
# (capture-hooks.patch and src/dynbench_capture.cpp) and builds the client against Debian's
# libraries and dynbench's capture SDK:
#   bash integrations/cube2/build.sh [BUILD_DIR=build/cube2] [DYNBENCH_BUILD=build/release]
# Prints the client's path. Needs scripts/setup.sh run first (the source tarball and libsdl2-dev,
# libsdl2-image-dev, libsdl2-mixer-dev, libenet-dev, zlib1g-dev, libgl-dev) and dynbench built
# (libdynbench_capture_engine.a: the SDK as engines link it, without sanitizers); running it needs
# cube2-data and xvfb.
set -euo pipefail

build_dir=${1:-build/cube2}
dynbench_build=$(cd "${2:-build/release}" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
version=0.0.20201227+dfsg
orig=cube2_${version}.orig.tar.xz
mkdir -p "$build_dir"
build_dir=$(cd "$build_dir" && pwd)

# scripts/setup.sh fetches the tarball (apt-get source, with the deb-src entry it needs) into this
# cache; fetching lives there only, so this script never touches apt.
cache=${DYNBENCH_CUBE2_CACHE:-/var/cache/dynbench/cube2}
if [[ ! -f "$build_dir/$orig" ]]; then
  [[ -f "$cache/$orig" ]] || { echo "cube2: $cache/$orig missing: run scripts/setup.sh (it fetches the engine source)" >&2; exit 1; }
  cp "$cache/$orig" "$build_dir/$orig"
fi

src="$build_dir/cube2-$version"
# A fresh tree whenever the patch changes; the adapter is copied in every time.
if ! cmp -s "$here/capture-hooks.patch" "$src/.dynbench-patch" 2>/dev/null; then
  rm -rf "$src"
  tar -xf "$build_dir/$orig" -C "$build_dir"
  patch -d "$src" -p1 --quiet < "$here/capture-hooks.patch"
  cp "$here/capture-hooks.patch" "$src/.dynbench-patch"
fi
# The game's Makefile does not know these files: a changed adapter drops the objects that include it.
for f in dynbench_capture.h dynbench_capture.cpp dynbench_models.h; do
  if ! cmp -s "$here/src/$f" "$src/engine/$f"; then
    cp "$here/src/$f" "$src/engine/$f"
    rm -f "$src"/engine/{main,dynlight,rendermodel,dynbench_capture}.o
  fi
done
# Nor the SDK's header: a changed dbc_mesh (a field added) read by objects compiled with the old one
# crashed the client; those objects are dropped when the header changes.
if ! cmp -s "$repo/include/dynbench/capture.h" "$src/.dynbench-capture.h"; then
  rm -f "$src"/engine/{main,dynlight,rendermodel,dynbench_capture}.o
  cp "$repo/include/dynbench/capture.h" "$src/.dynbench-capture.h"
fi
for lib in libdynbench_capture_engine.a; do
  [[ -f "$dynbench_build/$lib" ]] || { echo "cube2: $dynbench_build/$lib missing: build dynbench first (cmake --build build/release)" >&2; exit 1; }
done
# The game's Makefile does not know the SDK library either: relink when it is newer than the client.
if [[ -f "$src/sauer_client" && "$dynbench_build/libdynbench_capture_engine.a" -nt "$src/sauer_client" ]]; then
  rm -f "$src/sauer_client"
fi
# The tarball ships without the bundled enet: an empty enet/ with a no-op Makefile satisfies the
# game's Makefile, and -lenet then finds Debian's libenet.
mkdir -p "$src/enet/include"
printf 'all:\n\t@true\n' > "$src/enet/Makefile"
# The game's own flags, and no reciprocal estimates: under -ffast-math GCC computes x/y and
# 1/sqrt(x) from RCPPS/RSQRTPS estimates (273 of them in the client, its collision code among
# them), whose bits the x86 ISA leaves to the implementation, so Intel and AMD round them
# differently: the same build and seed played another match on an Intel Xeon than on an AMD EPYC
# (integrations/cube2/README.md). -mno-recip alone leaves 1/sqrtf to RSQRTSS (GCC's manual says so);
# -fno-reciprocal-math as well leaves none. Objects and the precompiled header made with other
# flags are dropped.
cxxflags="-O3 -fomit-frame-pointer -ffast-math -mno-recip -fno-reciprocal-math"
if [[ "$(cat "$src/.dynbench-cxxflags" 2>/dev/null)" != "$cxxflags" ]]; then
  find "$src" \( -name '*.o' -o -name '*.gch' \) -delete
  rm -f "$src/sauer_client"
  echo "$cxxflags" >"$src/.dynbench-cxxflags"
fi
make -C "$src" -j"$(nproc)" client CXXFLAGS="$cxxflags" \
  DYNBENCH_INCLUDES="-I$repo/include" \
  DYNBENCH_LIBS="$dynbench_build/libdynbench_capture_engine.a -lfmt" \
  >"$build_dir/build.log" 2>&1 || { tail -20 "$build_dir/build.log" >&2; exit 1; }
echo "$src/sauer_client"
