#!/usr/bin/env bash
# The 1080p path of a suite on a cluster (issue 48): suites/slurm-1080p.json (one dataset, a
# 2-frame window at 1920x1080) run as `suite --slurm` on the local single-node Slurm
# (scripts/slurm-local.sh), then `suite verify` on what the jobs wrote. Prints the time of each.
#
#   bench/suite_1080p_slurm.sh OUT [FRAMES_PER_TASK]
set -euo pipefail
out=$1 per_task=${2:-2}
root=$(cd "$(dirname "$0")/.." && pwd)
dynbench=${DYNBENCH:-$root/build/release/dynbench}
eval "$("$root/scripts/slurm-local.sh" start | grep '^export')"
trap '"$root/scripts/slurm-local.sh" stop > /dev/null' EXIT
start=$(date +%s)
"$dynbench" suite "$root/suites/slurm-1080p.json" -o "$out" --slurm --frames-per-task "$per_task"
mid=$(date +%s)
"$dynbench" suite verify "$out"
end=$(date +%s)
echo "suite --slurm: $((mid - start)) s; verify: $((end - mid)) s; $(du -sh "$out" | cut -f1) in $out"
