#!/usr/bin/env bash
# Frames per minute at the paper's problem size, beside the paper's 0.8: the synth_skirt capture
# with fewer rows of coarse vertices (64 x 12, about 3k surface Gaussians after one subdivision),
# still 8 cameras of 1004 x 1004, with the paper's sigma_hat of 7 mm (and the k_max the full
# skirt gets, 1.75 x 7 mm) rather than lengths from this coarser mesh; Ceres with its defaults,
# and the paper's gradient ascent with up to the paper's 150 iterations and no function
# tolerance, end to end, run after run in turn.
#
#   bash bench/paper_size.sh      # 10 frames, 3 runs each; FRAMES=5 REPEATS=1 for a quick look
#
# Prints one "name: value" a line: surface_gaussians, the medians over the runs of both solvers'
# frames per minute, paper_frames_per_minute (reported by the paper for 3-4k Gaussians), and the
# RMS errors against the truth (coarse_rms_mm: the input mesh as given; subdivided_rms_mm: its Loop
# subdivision, where refinement starts).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-10}
repeats=${REPEATS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

[ -x build/finecap ] || bash scripts/build.sh >/dev/null
build/finecap synth --config configs/synth_skirt.yaml --out "$work/capture" \
  --set "synth.num_frames=$frames" --set synth.skirt.down=12 \
  >/dev/null

rms_of() {
  grep -o "\"$2\": [0-9.eE+-]*" "$1" | awk '{ s += $2 * $2; n += 1 } END { printf "%.3f", sqrt(s / n) }'
}

median() {
  tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { printf "%.2f", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

run() {  # solver, output folder, overrides...; prints frames per minute
  local solver=$1 dir=$2 start end
  shift 2
  rm -rf "$dir"
  start=$(date +%s.%N)
  build/finecap refine --capture "$work/capture" --out "$dir" --solver "$solver" \
    --set model.sigma_hat=0.007 --set energy.k_max=0.01225 "$@" >/dev/null 2>&1
  end=$(date +%s.%N)
  echo "$start $end" | awk -v f="$frames" '{ printf "%.2f", 60 * f / ($2 - $1) }'
}

ceres_runs="" paper_runs=""
for ((i = 0; i < repeats; ++i)); do
  ceres_runs+=" $(run ceres "$work/ceres")"
  paper_runs+=" $(run gradient-ascent "$work/paper" --set solver.max_iterations=150 \
    --set solver.function_tolerance=0)"
done

echo "runs_each: $repeats"
echo "surface_gaussians: $(grep -o '"surface_gaussians": [0-9]*' "$work/ceres/stats.jsonl" |
  head -1 | awk '{ print $2 }')"
echo "paper_solver_mean_iterations: $(grep -o '"iterations": [0-9]*' "$work/paper/stats.jsonl" |
  awk '{ s += $2; n += 1 } END { printf "%.0f", s / n }')"
echo "ceres_frames_per_minute: $(echo "$ceres_runs" | median)"
echo "paper_solver_150_iterations_frames_per_minute: $(echo "$paper_runs" | median)"
echo "paper_frames_per_minute: 0.8"
echo "ceres_rms_mm: $(rms_of "$work/ceres/stats.jsonl" rms_refined_mm)"
echo "paper_solver_rms_mm: $(rms_of "$work/paper/stats.jsonl" rms_refined_mm)"
echo "coarse_rms_mm: $(rms_of "$work/ceres/stats.jsonl" rms_coarse_mm)"
echo "subdivided_rms_mm: $(rms_of "$work/ceres/stats.jsonl" rms_subdivided_mm)"
