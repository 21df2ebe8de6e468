#!/usr/bin/env bash
# Whole-run speed and accuracy of `finecap refine` on synth_skirt (8 cameras of 1004 x 1004,
# ~10k surface Gaussians), end to end (image Gaussians, visibility, solve, writing): the Ceres
# path against the paper's gradient ascent on the same energy, on the same machine, run after
# run in turn so that a load from elsewhere falls on both alike.
#
#   bash bench/refine_speed.sh      # 30 frames, 3 runs each; FRAMES=10 REPEATS=1 for a quick look
#
# Prints one "name: value" a line: ceres_frames_per_minute and paper_solver_frames_per_minute
# (medians over the runs), the median over the runs of the ratio of the two speeds, ceres_rms_mm,
# paper_solver_rms_mm, coarse_rms_mm and subdivided_rms_mm (RMS over frames of the per-frame RMS
# error against the truth, textured region; coarse: the input mesh as given, subdivided: its Loop
# subdivision, where refinement starts), and the same accuracy for the paper's own E_sim with the paper's
# settings (configs/paper.yaml) with both solvers: paper_esim_ceres_rms_mm,
# paper_esim_paper_solver_rms_mm.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-30}
repeats=${REPEATS:-3}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

[ -x build/finecap ] || bash scripts/build.sh >/dev/null
build/finecap synth --config configs/synth_skirt.yaml --out "$work/capture" \
  --set "synth.num_frames=$frames" >/dev/null

# RMS over frames of a per-frame figure in stats.jsonl.
rms_of() {
  grep -o "\"$2\": [0-9.eE+-]*" "$1" | awk '{ s += $2 * $2; n += 1 } END { printf "%.3f", sqrt(s / n) }'
}

median() {
  tr ' ' '\n' | grep . | sort -g | awk '{ v[NR] = $1 } END { printf "%.2f", (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'
}

run() {  # solver, output folder, extra overrides, config; prints frames per minute
  local start end
  rm -rf "$2"
  start=$(date +%s.%N)
  build/finecap refine ${4:+--config "$4"} --capture "$work/capture" --out "$2" --solver "$1" \
    ${3:+--set "$3"} 2>/dev/null >/dev/null
  end=$(date +%s.%N)
  echo "$start $end" | awk -v f="$frames" '{ printf "%.2f", 60 * f / ($2 - $1) }'
}

paper_solver="solver.max_iterations=150"
ceres_runs="" paper_runs="" ratios=""
for ((i = 0; i < repeats; ++i)); do
  ceres=$(run ceres "$work/ceres")
  paper=$(run gradient-ascent "$work/paper" "$paper_solver")
  ceres_runs+=" $ceres" paper_runs+=" $paper"
  ratios+=" $(echo "$ceres $paper" | awk '{ printf "%.3f", $1 / $2 }')"
done
run ceres "$work/esim_ceres" "" configs/paper.yaml >/dev/null
run gradient-ascent "$work/esim_paper" "" configs/paper.yaml >/dev/null

echo "runs_each: $repeats"
echo "ceres_frames_per_minute: $(echo "$ceres_runs" | median)"
echo "paper_solver_frames_per_minute: $(echo "$paper_runs" | median)"
echo "ceres_to_paper_solver_speed_ratio: $(echo "$ratios" | median)"
echo "ceres_rms_mm: $(rms_of "$work/ceres/stats.jsonl" rms_refined_mm)"
echo "paper_solver_rms_mm: $(rms_of "$work/paper/stats.jsonl" rms_refined_mm)"
echo "coarse_rms_mm: $(rms_of "$work/ceres/stats.jsonl" rms_coarse_mm)"
echo "subdivided_rms_mm: $(rms_of "$work/ceres/stats.jsonl" rms_subdivided_mm)"
echo "paper_esim_ceres_rms_mm: $(rms_of "$work/esim_ceres/stats.jsonl" rms_refined_mm)"
echo "paper_esim_paper_solver_rms_mm: $(rms_of "$work/esim_paper/stats.jsonl" rms_refined_mm)"
