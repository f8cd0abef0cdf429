#!/usr/bin/env bash
# Each temporal method on the jittered and on the still input (issue 48): a window of a dataset
# rendered once as the reference (converged, v1's budget) and twice as input (4 paths a pixel from
# the pixel centre, seed 2: once with the jitter, once without), every method evaluated on each.
# Prints each method's mean HDR-ꟻLIP on both and its ratio to `none` on the same input.
#
#   bench/method_inputs.sh DATASET.gltf OUT [WIDTHxHEIGHT] [FRAMES]
#   bench/method_inputs.sh dynbench-demo/datasets/colos_bot.gltf /tmp/inputs 320x180 40:47
set -euo pipefail
dataset=$1 out=$2 res=${3:-320x180} frames=${4:-40:47}
dynbench=${DYNBENCH:-$(dirname "$0")/../build/release/dynbench}
common=(--res "$res" --frames "$frames" --bounces 2 --fps 24)
"$dynbench" render "$dataset" -o "$out/frames" "${common[@]}" --spp 16 --converge --max-spp 128 --tolerance 0.5 --seed 1 > /dev/null
"$dynbench" render "$dataset" -o "$out/input" "${common[@]}" --spp 4 --pixel-filter centre --jitter --seed 2 > /dev/null
"$dynbench" render "$dataset" -o "$out/input-still" "${common[@]}" --spp 4 --pixel-filter centre --seed 2 > /dev/null
for input in input input-still; do
  "$dynbench" evaluate "$out/$input" --reference "$out/frames" --json "$out/$input.json" > /dev/null
done
/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
scores = {i: {m["name"]: m["mean"]["flip"]["mean"] for m in json.load(open(f"{out}/{i}.json"))["methods"]} for i in ("input", "input-still")}
print(f"{'method':<11} {'jittered':>9} {'/none':>6} {'still':>9} {'/none':>6}   (mean HDR-FLIP over the window)")
for m in scores["input"]:
    j, s = scores["input"][m], scores["input-still"][m]
    print(f"{m:<11} {j:9.4f} {j / scores['input']['none']:6.3f} {s:9.4f} {s / scores['input-still']['none']:6.3f}")
PY
