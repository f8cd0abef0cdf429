#!/usr/bin/env bash
# OpenArena capture overhead benchmark (run by hand; not part of the test suite):
#   bash bench/bench_capture_openarena.sh [SECONDS=10] [MAP=oa_dm1] [BOTS=4] [BUILD=build/release] [GAME_CPU=emulated]
# Plays the same fixed-clock, seeded OpenArena match twice with `dynbench capture openarena`, once
# recording and once not (--no-record), and prints the wall time of the recorded window (the
# adapter's clock), the time per frame and their ratio: what recording costs the game. The window
# starts after the warm-up, so the adapter's one-off work at load (the map's BSP, shader scripts
# and textures) is outside it; the models it meets during the window (each MD3 once) are inside.
set -euo pipefail
seconds=${1:-10}
map=${2:-oa_dm1}
bots=${3:-4}
build=$(cd "${4:-build/release}" && pwd)
game_cpu=${5:-emulated}  # host: the game on the host's own CPU (capture openarena --game-cpu)
dynbench="$build/dynbench"
[[ -x "$dynbench" ]] || { echo "bench_capture_openarena: $dynbench missing: cmake --build $build" >&2; exit 1; }
work=$(mktemp -d /tmp/dynbench_bench_capture_oa.XXXXXX)
off=$("$dynbench" capture openarena -o "$work/off" --map "$map" --bots "$bots" --seconds "$seconds" --seed 1 --game-cpu "$game_cpu" --no-record)
on=$("$dynbench" capture openarena -o "$work/on" --map "$map" --bots "$bots" --seconds "$seconds" --seed 1 --game-cpu "$game_cpu")
off_s=$(sed -E 's/.*took ([0-9.]+) s.*/\1/' <<<"$off")
on_s=$(sed -E 's/.*the recorded window ([0-9.]+) s.*/\1/' <<<"$on")
frames=$(sed -E 's/.*window of ([0-9]+) frames.*/\1/' <<<"$off")
size=$(du -sh "$work/on" | cut -f1)
awk -v off="$off_s" -v on="$on_s" -v n="$frames" -v size="$size" -v map="$map" -v bots="$bots" -v cpu="$game_cpu" 'BEGIN {
  printf "%s, %d bots, %d frames at a fixed 50 fps clock (game CPU %s; 384x216, Xvfb + Mesa llvmpipe)\n", map, bots, n, cpu
  printf "capture off: %.3f s, %.2f ms/frame (%.1f fps)\n", off, 1000 * off / n, n / off
  printf "capture on:  %.3f s, %.2f ms/frame (%.1f fps), capture folder %s\n", on, 1000 * on / n, n / on, size
  printf "overhead: %.3fx (%.2f ms/frame)\n", on / off, 1000 * (on - off) / n
}'
rm -rf "$work"
