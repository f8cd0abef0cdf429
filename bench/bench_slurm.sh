#!/usr/bin/env bash
# Scheduling overhead of `dynbench render --slurm` on a single-node Slurm of this machine
# (scripts/slurm-local.sh, in a folder and on ports of its own), against render time per frame,
# and the wall time of a 24-frame array (2 concurrent 1-CPU tasks) against one local 2-thread
# render of the same frames. Prints its figures; run by hand (CONTRIBUTING.md).
#
#   bench/bench_slurm.sh [DATASET]        # default: examples/orbit/orbit.gltf
#   RES=160x90 SPP=64 FRAMES_PER_TASK=4 bench/bench_slurm.sh
#
# Per task: submit to start = the task log's start line minus the job script's write time (the
# script is written just before sbatch); start to first frame = the task's first sidecar's write
# time minus its start. Both to the nanosecond clock of this machine.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
exe=${DYNBENCH:-$root/build/release/dynbench}
dataset=$(realpath "${1:-$root/examples/orbit/orbit.gltf}")
res=${RES:-160x90}
spp=${SPP:-64}
per_task=${FRAMES_PER_TASK:-4}
frames=24
work=$(mktemp -d /tmp/bench_slurm.XXXXXX)

export DYNBENCH_SLURM_DIR=$work/cluster DYNBENCH_SLURM_CTLD_PORT=26837 DYNBENCH_SLURM_SLURMD_PORT=26838
"$root/scripts/slurm-local.sh" start >/dev/null
trap '"$root/scripts/slurm-local.sh" stop >/dev/null; rm -rf "$work"' EXIT
export SLURM_CONF=$work/cluster/slurm.conf

options=(--frames 0:$((frames - 1)) --res "$res" --spp "$spp")
now() { date +%s.%N; }
calc() { awk "BEGIN { printf \"%.9f\", ($*) }"; }  # awk, not bc: bc is not in every Debian install
mtime() { stat -c %.9Y "$1"; }

echo "dataset $dataset, $frames frames at $res, $spp spp; $(nproc) CPUs"

# Render time per frame, one thread (what one task renders with).
t0=$(now)
"$exe" render "$dataset" -o "$work/one" --frames 0:3 --res "$res" --spp "$spp" --threads 1 >/dev/null
t1=$(now)
frame_seconds=$(calc "($t1 - $t0) / 4")

# One local render of all frames with 2 threads.
t0=$(now)
"$exe" render "$dataset" -o "$work/local" "${options[@]}" --threads 2 >/dev/null
t1=$(now)
local_seconds=$(calc "$t1 - $t0")

# The same frames as an array of 1-CPU tasks (2 run at once on 2 CPUs).
t0=$(now)
"$exe" render "$dataset" -o "$work/slurm" "${options[@]}" --slurm --frames-per-task "$per_task" --cpus-per-task 1 >"$work/slurm.out"
t1=$(now)
slurm_seconds=$(calc "$t1 - $t0")
job=$(grep -o 'Slurm job [0-9]*' "$work/slurm.out" | awk '{print $3}')
submitted=$(mtime "$work/slurm/slurm/render.sbatch")
# The last task's end, from the files: the newest sidecar.
last_frame=$(for f in "$work"/slurm/frame_*.json; do mtime "$f"; done | sort -n | tail -n 1)
array_seconds=$(calc "$last_frame - $submitted")

same=yes
for f in "$work"/local/frame_*; do cmp -s "$f" "$work/slurm/$(basename "$f")" || same=no; done

printf '\nper task (submit to start, start to first frame; seconds):\n'
tasks=$(( (frames + per_task - 1) / per_task ))
sum_queue=0; sum_first=0
for ((k = 0; k < tasks; k++)); do
  log=$work/slurm/slurm/task-${job}_$k.log
  start=$(grep -o 'started [0-9T:.-]*' "$log" | head -n 1 | awk '{print $2}')
  start_s=$(date -u -d "$start" +%s.%N)
  first=$(mtime "$work/slurm/$(printf 'frame_%05d.json' $((k * per_task)))")
  queue=$(calc "$start_s - $submitted")
  to_first=$(calc "$first - $start_s")
  printf '  task %d: %.3f, %.3f\n' "$k" "$queue" "$to_first"
  sum_queue=$(calc "$sum_queue + $queue"); sum_first=$(calc "$sum_first + $to_first")
done
# A CPU's idle time between one task's last frame and the next task's start on it (tasks k and k+2
# share a CPU here): Slurm schedules the next task some time after the last one ends.
gaps=0; gap_count=0
for ((k = 0; k + 2 < tasks; k++)); do
  last=$(( (k + 1) * per_task - 1 ))
  end=$(mtime "$work/slurm/$(printf 'frame_%05d.json' "$last")")
  next_log=$work/slurm/slurm/task-${job}_$((k + 2)).log
  next_start=$(date -u -d "$(grep -o 'started [0-9T:.-]*' "$next_log" | head -n 1 | awk '{print $2}')" +%s.%N)
  gaps=$(calc "$gaps + $next_start - $end"); gap_count=$((gap_count + 1))
done
gap=$(calc "$gap_count > 0 ? $gaps / $gap_count : 0")
# The first task's wait is the pure scheduling delay; later ones also wait for a free CPU.
first_log=$work/slurm/slurm/task-${job}_0.log
first_start=$(date -u -d "$(grep -o 'started [0-9T:.-]*' "$first_log" | head -n 1 | awk '{print $2}')" +%s.%N)
schedule=$(calc "$first_start - $submitted")
to_first0=$(calc "$(mtime "$work/slurm/frame_00000.json") - $first_start")
startup=$(calc "$to_first0 - $frame_seconds")   # loading the dataset, the first frame's own render time taken out
# In steady state a task costs its CPU the idle gap before it and its start-up.
overhead=$(calc "($gap_count > 0 ? $gap : $schedule) + $startup")
printf '\nrender time per frame, 1 thread:       %.3f s\n' "$frame_seconds"
printf 'submit to start of task 0:             %.3f s\n' "$schedule"
printf 'start to first frame of task 0:        %.3f s (of which rendering the frame %.3f s)\n' "$to_first0" "$frame_seconds"
printf 'CPU idle between a task and the next:  %.3f s (mean of %d)\n' "$gap" "$gap_count"
printf 'start-up (loading, before rendering):  %.3f s\n' "$startup"
printf 'overhead per task (idle + start-up):   %.3f s = %.1f frames\n' "$overhead" "$(calc "$overhead / $frame_seconds")"
printf 'local render, 2 threads:               %.2f s\n' "$local_seconds"
printf 'array of %d 1-CPU tasks, submit to last frame: %.2f s (%.2fx the local render)\n' "$tasks" "$array_seconds" \
  "$(calc "$array_seconds / $local_seconds")"
printf 'dynbench render --slurm, command to exit (polls every 2 s): %.2f s\n' "$slurm_seconds"
printf 'frames identical to the local render: %s\n' "$same"
# Overhead at most 5 % of a task: frames per task >= 19 x overhead / frame time.
printf 'frames per task for overhead <= 5 %%: %d\n' "$(awk "BEGIN { n = 19 * $overhead / $frame_seconds; print (n == int(n)) ? n : int(n) + 1 }")"
