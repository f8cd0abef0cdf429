#!/usr/bin/env bash
# Map-light fit benchmark (run by hand; not part of the test suite):
#   bash bench/bench_map_lights.sh [BUILD=build/release] [MAP ...]
# Fits each map's lights as a capture does when its cache has none (`map-lights MAP --no-judge
# --adapter-lights`: the same file, without the held-out and light grid figures) and prints the
# wall and CPU time of each fit against issue 46's budget of a minute a map on two cores, as a
# ratio, with the lights and whether the light grid was fit data. Run it on an otherwise idle
# machine; the figures depend on its cores (say which CPU they came from). The lights files'
# hashes let two builds' fits be compared byte for byte.
set -euo pipefail
build=$(cd "${1:-build/release}" && pwd)
shift || true
maps=("$@")
[[ ${#maps[@]} -gt 0 ]] || maps=(oa_dm1 oa_dm2 oa_dm3 oa_dm4 oa_dm5 oa_dm6 oa_dm7 oa_ctf2 oa_bases3)
dynbench="$build/dynbench"
[[ -x "$dynbench" ]] || { echo "bench_map_lights: $dynbench missing: cmake --build $build" >&2; exit 1; }
work=$(mktemp -d /tmp/dynbench_bench_map_lights.XXXXXX)
trap 'rm -rf "$work"' EXIT
budget=60
printf "%s, %s threads\n" "$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')" "$(nproc)"
printf "%-10s %8s %8s %9s %7s %6s  %s\n" map "wall s" "CPU s" "/ budget" lights grid "lights file SHA-256 (first 16)"
for map in "${maps[@]}"; do
  TIMEFORMAT='%R %U %S'
  { time "$dynbench" map-lights "$map" --no-judge --adapter-lights "$work/$map.txt" >"$work/$map.out" 2>"$work/$map.err"; } 2>"$work/time"
  read -r wall user sys <"$work/time"
  lights=$(sed -nE 's/.* ([0-9]+) lights fitted.*/\1/p' "$work/$map.out")
  grid=$(grep -q "fitted beside the texels" "$work/$map.out" && echo fitted || echo judged)
  sha=$(sha256sum "$work/$map.txt" | cut -c1-16)
  awk -v m="$map" -v w="$wall" -v u="$user" -v s="$sys" -v b="$budget" -v l="$lights" -v g="$grid" -v h="$sha" \
    'BEGIN { printf "%-10s %8.1f %8.1f %8.2fx %7s %6s  %s\n", m, w, u + s, w / b, l, g, h }'
done
