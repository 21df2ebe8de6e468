#!/usr/bin/env bash
# Ceres against the paper's gradient ascent to the same accuracy on synth_skirt (8 cameras of
# 1004 x 1004, ~10k surface Gaussians, the default energy), by the time of a frame on the run's
# thread (stats.jsonl "seconds", so that a run's one-off start does not dilute the ratio: both
# passes of the solve, writing, and waiting for the frame's preparation and sweep, which run
# beside the solve of the frame before), and by the solve alone ("seconds_solve"). Ceres with
# its defaults; the ascent with no function
# tolerance and a ladder of iteration budgets; run after run in turn, so that a load from
# elsewhere falls on all alike. The ascent's speed at Ceres' accuracy is read off the ladder:
# the time per frame interpolated between the last budget that ends above Ceres' RMS error and
# the first that ends at or below it.
#
#   bash bench/same_accuracy.sh   # 8 frames, 3 runs each; FRAMES=4 REPEATS=1 for a quick look;
#                                 # BUDGETS="25 30 35 40 45 50 100 200 400" (most iterations
#                                 # per solve)
#
# The ladder is fine where the ascent meets Ceres' error on synth_skirt (between 25 and 50
# iterations a pass): its error falls steeply there and then levels off, so a coarse ladder
# (25, then 50) interpolated in the error took the ascent's time at Ceres' error as ~48
# iterations' when ~39 reach it.
#
# Prints one "name: value" a line: ceres_frames_per_minute and ceres_rms_mm; per budget N
# ascent_N_frames_per_minute and ascent_N_rms_mm; ascent_frames_per_minute_at_ceres_rms ("not
# reached" when no budget gets there) and ceres_to_ascent_speed_ratio; ceres_solve_seconds,
# ascent_solve_seconds_at_ceres_rms and ceres_to_ascent_solve_ratio. Frames per minute are 60
# over the median over the runs of the mean seconds per frame; RMS is over frames of the
# per-frame RMS error of k against the truth. Then where Ceres' solve goes:
# ceres_iterations_per_frame, ceres_similarity_seconds (the similarity's shared work a frame),
# ceres_own_seconds (the rest: Ceres' pass over the residual blocks, linear solver and steps),
# ceres_ms_per_iteration, and per budget ascent_N_ms_per_evaluation. And what the frame ratio
# tends to on a machine whose cores are all busy, the CPU a frame costs (stats.jsonl
# "cpu_seconds", medians over the runs of the means over the frames): ceres_cpu_seconds_per_frame,
# ascent_cpu_seconds_per_frame_at_ceres_rms, ceres_to_ascent_cpu_ratio,
# frame_without_iterations_cpu_seconds (the ascent with no iteration: reading, preparing, the
# sweep, the energy at both ends and writing, which both solvers spend alike) and
# ceres_to_ascent_cpu_ratio_if_ceres_evaluations_cost_the_ascents (Ceres' frame with each of its
# evaluations costing one of the ascent's: the most its own work could leave the ratio at).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-8}
repeats=${REPEATS:-3}
budgets=${BUDGETS:-25 30 35 40 45 50 100 200 400}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

[ -x build/finecap ] || bash scripts/build.sh >/dev/null
build/finecap synth --config configs/synth_skirt.yaml --out "$work/capture" \
  --set "synth.num_frames=$frames" >/dev/null

rms_of() {  # stats.jsonl; RMS over frames of rms_refined_mm
  grep -o '"rms_refined_mm": [0-9.eE+-]*' "$1" |
    awk '{ s += $2 * $2; n += 1 } END { printf "%.4f", sqrt(s / n) }'
}

median() {
  tr ' ' '\n' | grep . | sort -g |
    awk '{ v[NR] = $1 } END { printf "%.3f", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

mean_of() {  # stats.jsonl key, stats file; the mean over the frames
  grep -o "\"$1\": [0-9.eE+-]*" "$2" | awk '{ s += $2; n += 1 } END { printf "%.4f", s / n }'
}

# Output folder, then the refine arguments; appends the run's mean seconds per frame and mean
# solve seconds per frame to seconds[$key] and solve[$key].
run() {
  local key=$1 dir=$2
  shift 2
  rm -rf "$dir"
  build/finecap refine --capture "$work/capture" --out "$dir" "$@" >/dev/null 2>&1
  seconds[$key]+=" $(mean_of seconds "$dir/stats.jsonl")"
  solve[$key]+=" $(mean_of seconds_solve "$dir/stats.jsonl")"
  similarity[$key]+=" $(mean_of seconds_similarity "$dir/stats.jsonl")"
  cpu[$key]+=" $(mean_of cpu_seconds "$dir/stats.jsonl")"
}

declare -A seconds solve similarity cpu
for ((i = 0; i < repeats; ++i)); do
  run ceres "$work/ceres" --solver ceres
  # No iteration: what a frame costs besides its solve's iterations (reading, preparing, the
  # sweep, the energy at both ends, writing), the same for both solvers.
  run base "$work/base" --solver gradient-ascent --set "solver.max_iterations=0"
  for n in $budgets; do
    run "$n" "$work/ascent_$n" --solver gradient-ascent \
      --set "solver.max_iterations=$n,solver.function_tolerance=0"
  done
done

ceres_seconds=$(echo "${seconds[ceres]}" | median)
ceres_solve=$(echo "${solve[ceres]}" | median)
ceres_rms=$(rms_of "$work/ceres/stats.jsonl")
echo "frames: $frames"
echo "runs_each: $repeats"
echo "ceres_frames_per_minute: $(echo "$ceres_seconds" | awk '{ printf "%.1f", 60 / $1 }')"
echo "ceres_rms_mm: $ceres_rms"
ladder=""
for n in $budgets; do
  s=$(echo "${seconds[$n]}" | median)
  rms=$(rms_of "$work/ascent_$n/stats.jsonl")
  echo "ascent_${n}_frames_per_minute: $(echo "$s" | awk '{ printf "%.1f", 60 / $1 }')"
  echo "ascent_${n}_rms_mm: $rms"
  ladder+="$s $(echo "${solve[$n]}" | median) $rms $(echo "${cpu[$n]}" | median)"$'\n'
done
# Column $1 of the ladder (seconds per frame, solve seconds, or CPU seconds per frame: columns 1,
# 2 and 4) where it first reaches Ceres' RMS, interpolated in RMS.
at_target() {
  printf '%s' "$ladder" | awk -v target="$ceres_rms" -v c="$1" '
    $3 <= target {
      if (NR == 1 || previous_rms <= $3) { print $c; found = 1; exit }
      print previous + ($c - previous) * (previous_rms - target) / (previous_rms - $3)
      found = 1; exit
    }
    { previous = $c; previous_rms = $3 }
    END { if (!found) print "none" }'
}
frame_at_target=$(at_target 1)
solve_at_target=$(at_target 2)
if [ "$frame_at_target" = none ]; then
  echo "ascent_frames_per_minute_at_ceres_rms: not reached"
else
  echo "ascent_frames_per_minute_at_ceres_rms: $(echo "$frame_at_target" | awk '{ printf "%.1f", 60 / $1 }')"
  echo "ceres_to_ascent_speed_ratio: $(echo "$frame_at_target $ceres_seconds" | awk '{ printf "%.2f", $1 / $2 }')"
  # The solves alone: the preparation both share runs beside the frame before's solve.
  echo "ceres_solve_seconds: $ceres_solve"
  echo "ascent_solve_seconds_at_ceres_rms: $(echo "$solve_at_target" | awk '{ printf "%.3f", $1 }')"
  echo "ceres_to_ascent_solve_ratio: $(echo "$solve_at_target $ceres_solve" | awk '{ printf "%.2f", $1 / $2 }')"
  # Both cores busy, a frame's time follows its CPU: the CPU ratio is what the frame ratio tends to.
  cpu_at_target=$(at_target 4)
  ceres_cpu=$(echo "${cpu[ceres]}" | median)
  base_cpu=$(echo "${cpu[base]}" | median)
  echo "ceres_cpu_seconds_per_frame: $ceres_cpu"
  echo "ascent_cpu_seconds_per_frame_at_ceres_rms: $(echo "$cpu_at_target" | awk '{ printf "%.3f", $1 }')"
  echo "ceres_to_ascent_cpu_ratio: $(echo "$cpu_at_target $ceres_cpu" | awk '{ printf "%.2f", $1 / $2 }')"
  echo "frame_without_iterations_cpu_seconds: $base_cpu"
  # The ratio Ceres would reach if each of its evaluations cost the CPU of one of the ascent's
  # (the similarity's work alone, none of Ceres' own), from the largest budget's CPU per evaluation.
  last=${budgets##* }
  ascent_evaluations=$(mean_of evaluations "$work/ascent_$last/stats.jsonl")
  ceres_evaluations=$(mean_of evaluations "$work/ceres/stats.jsonl")
  base_evaluations=$(mean_of evaluations "$work/base/stats.jsonl")
  echo "ceres_to_ascent_cpu_ratio_if_ceres_evaluations_cost_the_ascents: $(echo \
    "$cpu_at_target $base_cpu $(echo "${cpu[$last]}" | median) $ascent_evaluations $ceres_evaluations $base_evaluations" |
    awk '{ per = ($3 - $2) / ($4 - $6); printf "%.2f", $1 / ($2 + ($5 - $6) * per) }')"
fi
# Where Ceres' solve goes: its iterations, and of its time the similarity's shared work (what an
# iteration of the ascent is, nearly all) against Ceres' own (its pass over the residual blocks,
# the linear solver, its steps).
ceres_iterations=$(mean_of iterations "$work/ceres/stats.jsonl")
ceres_similarity=$(echo "${similarity[ceres]}" | median)
echo "ceres_iterations_per_frame: $(echo "$ceres_iterations" | awk '{ printf "%.1f", $1 }')"
echo "ceres_similarity_seconds: $ceres_similarity"
echo "ceres_own_seconds: $(echo "$ceres_solve $ceres_similarity" | awk '{ printf "%.3f", $1 - $2 }')"
echo "ceres_ms_per_iteration: $(echo "$ceres_solve $ceres_iterations" | awk '{ printf "%.1f", 1000 * $1 / $2 }')"
for n in $budgets; do
  s=$(echo "${solve[$n]}" | median)
  evaluations=$(mean_of evaluations "$work/ascent_$n/stats.jsonl")
  echo "ascent_${n}_ms_per_evaluation: $(echo "$s $evaluations" | awk '{ printf "%.1f", 1000 * $1 / $2 }')"
done
