#!/usr/bin/env bash
# Capture overhead benchmark (run by hand; not part of the test suite):
#   bash bench/bench_capture.sh [SECONDS=10] [MAP=colos] [BOTS=6] [BUILD=build/release]
# Plays the same fixed-clock, seeded Cube 2 match twice under Xvfb, once recording
# (DYNBENCH_CAPTURE_RECORD=1) and once not (=0), and prints the wall time of the capture window,
# the time per frame, and their ratio: what recording costs the game.
set -euo pipefail
seconds=${1:-10}
map=${2:-colos}
bots=${3:-6}
build=$(cd "${4:-build/release}" && pwd)
client="$build/cube2/cube2-0.0.20201227+dfsg/sauer_client"
[[ -x "$client" ]] || { echo "bench_capture: $client missing: cmake --build $build --target cube2_client" >&2; exit 1; }
work=$(mktemp -d /tmp/dynbench_bench_capture.XXXXXX)
addbots=$(for ((b = 0; b < bots; b++)); do printf 'addbot 80; '; done)
script="sleep 100 [mode 0; map $map]; sleep 700 [${addbots}spectator 1]; sleep 1200 [nextfollow 1]"
declare -A ms
for record in 0 1; do
  rm -rf "$work/home" "$work/capture"
  mkdir -p "$work/home"
  line=$(cd "$(dirname "$client")" && DYNBENCH_CAPTURE_DIR="$work/capture" DYNBENCH_CAPTURE_DATA_ROOT=/usr/share/games/cube2 \
    DYNBENCH_CAPTURE_SEED=1 DYNBENCH_CAPTURE_WARMUP=2 DYNBENCH_CAPTURE_SECONDS="$seconds" DYNBENCH_CAPTURE_RECORD=$record \
    xvfb-run -a -s "-screen 0 640x360x24" ./sauer_client -q"$work/home" -k/usr/share/games/cube2 -r -t0 -w640 -h360 "-x$script" 2>&1 |
    grep "window of" || true)
  [[ -n "$line" ]] || { echo "bench_capture: the game did not finish (record=$record)" >&2; exit 1; }
  ms[$record]=$(sed -E 's/.* took ([0-9]+) ms.*/\1/' <<<"$line")
  frames=$(sed -E 's/.*window of ([0-9]+) frames.*/\1/' <<<"$line")
done
size=$(du -sh "$work/capture" | cut -f1)
awk -v off="${ms[0]}" -v on="${ms[1]}" -v n="$frames" -v size="$size" -v map="$map" -v bots="$bots" 'BEGIN {
  printf "%s, %d bots, %d frames at a fixed 60 fps clock (640x360, Xvfb + Mesa llvmpipe)\n", map, bots, n
  printf "capture off: %.0f ms, %.2f ms/frame (%.1f fps)\n", off, off / n, 1000 * n / off
  printf "capture on:  %.0f ms, %.2f ms/frame (%.1f fps), capture folder %s\n", on, on / n, 1000 * n / on, size
  printf "overhead: %.3fx (%.2f ms/frame)\n", on / off, (on - off) / n
}'
rm -rf "$work"
