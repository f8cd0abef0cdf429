#!/usr/bin/env bash
# Invariance benchmark (run by hand; not part of the test suite): is Table 6.7 a property of the
# dataset rather than of the render? Captures the seeded segment (colos, 4 bots, 3 s, seed 1),
# renders frames 40-47 converged at 160x90, 320x180 and 640x360, and once more with the whole
# scene in other units (its root scaled by 10, point and spot intensities by 100 and ranges by
# 10, the cameras' clip planes by 10: the same scene in decimetres), and prints each Table 6.7 row.
#   bench/bench_invariance.sh [WORKDIR] [RESOLUTIONS...]
# Environment: DYNBENCH (default build/release/dynbench), TOLERANCE (0.5), MAX_SPP (512).
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
dynbench=${DYNBENCH:-$here/build/release/dynbench}
work=${1:-/tmp/dynbench-invariance}
shift || true
resolutions=("$@")
((${#resolutions[@]})) || resolutions=(160x90 320x180 640x360)
tolerance=${TOLERANCE:-0.5}
max_spp=${MAX_SPP:-512}
mkdir -p "$work"
cd "$work"

if [[ ! -f ds/colos.gltf ]]; then
  "$dynbench" capture cube2 -o cap --map colos --bots 4 --seconds 3 --seed 1
  "$dynbench" convert cap -o ds/colos.gltf
fi

# The same dataset in decimetres.
if [[ ! -f ds/colos_x10.gltf ]]; then
  python3 - ds/colos.gltf ds/colos_x10.gltf <<'PY'
import json, sys
src, dst = sys.argv[1], sys.argv[2]
doc = json.load(open(src))
scene = doc["scenes"][doc.get("scene", 0)]
doc["nodes"].append({"name": "units_x10", "scale": [10, 10, 10], "children": scene["nodes"]})
scene["nodes"] = [len(doc["nodes"]) - 1]
for light in doc.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", []):
    if light["type"] in ("point", "spot"):
        light["intensity"] = light.get("intensity", 1.0) * 100.0
        if "range" in light:
            light["range"] *= 10.0
for camera in doc.get("cameras", []):
    p = camera.get("perspective", {})
    for key in ("znear", "zfar"):
        if key in p:
            p[key] *= 10.0
json.dump(doc, open(dst, "w"))
PY
fi

render_and_discard() {  # DATASET RES NAME
  local out="frames_$3"
  local started=$SECONDS
  "$dynbench" render "$1" -o "$out" --res "$2" --frames 40:47 --bounces 2 --converge --tolerance "$tolerance" --max-spp "$max_spp" >/dev/null
  "$dynbench" discard "$out" --json "discard_$3.json" >/dev/null
  python3 - "discard_$3.json" "$3" $((SECONDS - started)) <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))["mean"]
iv = j.get("interval", {})
def radiance(key):
    low, high = iv.get(key, [j[key], j[key]])
    return "%.2f ± %.2f" % (j[key], (high - low) / 2)
print("| %s | %.2f | %.2f | %.2f | %s | %s | %s s |" % (sys.argv[2], j["frustum"], j["world_position"], j["shading_normal"],
      radiance("direct_radiance"), radiance("indirect_radiance"), sys.argv[3]))
PY
}

echo "| render | frustum | world pos. | normal | direct | indirect | time |"
echo "|---|---:|---:|---:|---:|---:|---:|"
for res in "${resolutions[@]}"; do render_and_discard ds/colos.gltf "$res" "$res"; done
render_and_discard ds/colos_x10.gltf "${resolutions[0]}" "${resolutions[0]}_units_x10"
