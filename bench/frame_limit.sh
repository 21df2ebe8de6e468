#!/usr/bin/env bash
# How close a synth_skirt frame (8 cameras of 1004 x 1004, ~10k surface Gaussians) comes to its
# lower bound on this machine. The bound: the evaluations the solve needs, each one pass over the
# pairs with Jacobians (build/energy_benchmark, all threads), plus reading the frame's images
# (decoding and undistortion, one thread). The bound prices every evaluation at the surface
# Gaussians' cost; one_detail_pass_ms is what an evaluation of the detail stage (the images read at
# their own resolution; about half of a frame's evaluations) costs instead. Beside it the measured
# per-stage times of `finecap refine` (medians over the frames of stats.jsonl).
#
#   bash bench/frame_limit.sh            # 10 frames; FRAMES=5 for a quicker look
#   SOLVER=gradient-ascent bash bench/frame_limit.sh
#   BEFORE=../main/build/finecap RUNS=3 bash bench/frame_limit.sh
#
# With BEFORE (another build's finecap), both builds refine the same frames in turn, RUNS times
# (default 3), and the before_ lines give the other build's figures beside this one's.
# Figures are medians over the runs (whole runs) or over all the runs' frames (stages).
#
# Prints one "name: value" a line, seconds per frame unless the name says otherwise.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-10}
solver=${SOLVER:-ceres}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

[ -x build/finecap ] && [ -x build/energy_benchmark ] || bash scripts/build.sh >/dev/null
build/finecap synth --config configs/synth_skirt.yaml --out "$work/capture" \
  --set "synth.num_frames=$frames" >/dev/null
runs=${RUNS:-1}
before=${BEFORE:-}

# Refines the capture with finecap binary $1 into $2; prints the run's frames per minute.
refine_run() {
  local start end
  start=$(date +%s.%N)
  "$1" refine --capture "$work/capture" --out "$2" --solver "$solver" >/dev/null 2>&1
  end=$(date +%s.%N)
  echo "$start $end" | awk -v f="$frames" '{ printf "%.1f\n", 60 * f / ($2 - $1) }'
}
for run in $(seq "$runs"); do
  if [ -n "$before" ]; then refine_run "$before" "$work/before_$run" >>"$work/before_fpm"; fi
  refine_run build/finecap "$work/out_$run" >>"$work/fpm"
done

median() {
  sort -g | awk '{ v[NR] = $1 } END { printf "%.3f", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}
# A figure $1 of every frame of the runs with prefix $2 (default: this build's) in stats.jsonl.
values_of() { cat "$work/${2:-out}"_*/stats.jsonl | grep -o "\"$1\": [0-9.eE+-]*" | awk '{ print $2 }'; }
median_of() { values_of "$@" | median; }
# The runs' largest peak resident memory, MB.
peak_of() { values_of peak_rss_mb "$@" | sort -g | tail -1; }

# Medians of 5 repetitions, milliseconds.
bench=$(build/energy_benchmark --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_filter='BM_EnergyAndGradient/consensus/0|BM_DetailBlockSummaries/0|BM_ReadFrame|BM_PrepareFrame' 2>/dev/null)
ms_of() { echo "$bench" | awk -v n="$1" '$1 ~ n && $1 ~ /_median$/ { print $2; exit }'; }
evaluation_ms=$(ms_of 'BM_EnergyAndGradient/consensus/0')
detail_evaluation_ms=$(ms_of 'BM_DetailBlockSummaries/0')
read_ms=$(ms_of 'BM_ReadFrame')
prepare_ms=$(ms_of 'BM_PrepareFrame')

evaluations=$(median_of evaluations)
total=$(median_of seconds)
echo "solver: $solver"
echo "frames: $frames"
echo "evaluations_per_frame: $evaluations"
echo "one_pass_with_jacobians_ms: $evaluation_ms"
echo "one_detail_pass_ms: $detail_evaluation_ms"
echo "reading_a_frame_ms: $read_ms"
echo "preparing_a_frame_ms: $prepare_ms"
bound=$(awk -v e="$evaluations" -v p="$evaluation_ms" -v r="$read_ms" \
  'BEGIN { printf "%.3f", (e * p + r) / 1000 }')
echo "lower_bound_s: $bound"
echo "measured_frame_s: $total"
echo "measured_preparation_s: $(median_of seconds_preparation)"
echo "measured_solve_s: $(median_of seconds_solve)"
echo "measured_evaluation_s: $(median_of seconds_evaluation)"
echo "measured_linear_solver_s: $(median_of seconds_linear_solver)"
echo "measured_run_frames_per_minute: $(median <"$work/fpm" | awk '{ printf "%.1f", $1 }')"
echo "measured_rms_refined_mm: $(median_of rms_refined_mm)"
echo "measured_peak_rss_mb: $(peak_of)"
echo "frame_over_bound: $(awk -v t="$total" -v b="$bound" 'BEGIN { printf "%.2f", t / b }')"
if [ -n "$before" ]; then
  echo "before_frame_s: $(median_of seconds before)"
  echo "before_preparation_s: $(median_of seconds_preparation before)"
  echo "before_solve_s: $(median_of seconds_solve before)"
  echo "before_evaluation_s: $(median_of seconds_evaluation before)"
  echo "before_linear_solver_s: $(median_of seconds_linear_solver before)"
  echo "before_run_frames_per_minute: $(median <"$work/before_fpm" | awk '{ printf "%.1f", $1 }')"
  echo "before_rms_refined_mm: $(median_of rms_refined_mm before)"
  echo "before_peak_rss_mb: $(peak_of before)"
fi
