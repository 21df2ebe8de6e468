#!/usr/bin/env bash
# Whole-run speed and accuracy of `finecap refine` on synth_skirt (8 cameras of 1004 x 1004,
# ~10k surface Gaussians), end to end (image Gaussians, visibility, solve, writing): the Ceres
# path against the paper's gradient ascent on the same energy, in one run on the same machine.
#
#   bash bench/refine_speed.sh            # 30 frames; FRAMES=10 for a quicker look
#
# Prints one "name: value" a line: ceres_frames_per_minute, paper_solver_frames_per_minute,
# ceres_rms_mm, paper_solver_rms_mm, coarse_rms_mm (RMS over frames of the per-frame RMS error of
# k against the truth, textured region), and the ratio of the two speeds.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-30}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

[ -x build/finecap ] || bash scripts/build.sh >/dev/null
build/finecap synth --config configs/synth_skirt.yaml --out "$work/capture" \
  --set "synth.num_frames=$frames" >/dev/null

# RMS over frames of a per-frame figure in stats.jsonl.
rms_of() {
  grep -o "\"$2\": [0-9.eE+-]*" "$1" | awk '{ s += $2 * $2; n += 1 } END { printf "%.3f", sqrt(s / n) }'
}

run() {  # solver, output folder, extra overrides
  local start end
  start=$(date +%s.%N)
  build/finecap refine --capture "$work/capture" --out "$2" --solver "$1" ${3:+--set "$3"} \
    2>/dev/null >/dev/null
  end=$(date +%s.%N)
  echo "$start $end" | awk -v f="$frames" '{ printf "%.2f", 60 * f / ($2 - $1) }'
}

ceres_fpm=$(run ceres "$work/ceres")
paper_fpm=$(run gradient-ascent "$work/paper" "solver.max_iterations=150")
echo "ceres_frames_per_minute: $ceres_fpm"
echo "paper_solver_frames_per_minute: $paper_fpm"
echo "ceres_rms_mm: $(rms_of "$work/ceres/stats.jsonl" rms_refined_mm)"
echo "paper_solver_rms_mm: $(rms_of "$work/paper/stats.jsonl" rms_refined_mm)"
echo "coarse_rms_mm: $(rms_of "$work/ceres/stats.jsonl" rms_coarse_mm)"
echo "ceres_to_paper_solver_speed_ratio: $(echo "$ceres_fpm $paper_fpm" | awk '{ printf "%.2f", $1 / $2 }')"
