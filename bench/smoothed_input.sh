#!/usr/bin/env bash
# The smoothed-input benchmark (the paper's section 7): a detailed mesh sequence is the truth, its
# Taubin-smoothed copies are the coarse input, and refinement with the default config should
# bring the detail back. `finecap synth` renders the sequence in the studio of
# configs/synth_skirt_smoothed.yaml (8 cameras of 1004 x 1004 around it, the procedural cloth
# print), `finecap refine` refines it with the defaults, `finecap eval` measures it.
#
#   bash bench/smoothed_input.sh [MESH_FOLDER]
#
# MESH_FOLDER: per-frame meshes of one topology (.ply, .obj, .off, .stl, in name order), metres,
# world y up, no comma in the path. The sequence itself is the truth (synth.truth_refinement 1,
# no procedural folds). Without it, the built-in skirt with its procedural folds
# (configs/synth_skirt_smoothed.yaml).
# Environment: FRAMES (default 10), ITERATIONS (synth.smoothing.iterations, default the
# preset's), KEEP=1 to keep the capture and the run (printed), FINECAP (default build/finecap),
# SET (extra settings of the refinement, --set).
#
# Prints a line per frame, "frame <name>: input_rms_mm A subdivided_rms_mm S refined_rms_mm B
# recovered_percent C" (RMS distance to the truth over every refined vertex of the coarse mesh as
# given, of its Loop subdivision and of the refined mesh; C = 100 (1 - B / A), against the input as
# given), then one "name: value" a line: the same pooled over the sequence (pooled_input_rms_mm,
# pooled_subdivided_rms_mm, pooled_refined_rms_mm, pooled_recovered_percent) and the seconds taken
# by synth, refine and eval.
set -euo pipefail
cd "$(dirname "$0")/.."
meshes=${1:-}
frames=${FRAMES:-10}
finecap=${FINECAP:-build/finecap}
work=$(mktemp -d)
if [ "${KEEP:-0}" = 1 ]; then echo "work_folder: $work"; else trap 'rm -rf "$work"' EXIT; fi

[ -x "$finecap" ] || bash scripts/build.sh >/dev/null
overrides="synth.num_frames=$frames"
if [ -n "$meshes" ]; then
  [ -d "$meshes" ] || { echo "$meshes: not a folder of meshes" >&2; exit 1; }
  case "$meshes" in *,*) echo "$meshes: the path may not contain a comma" >&2; exit 1 ;; esac
  overrides+=",synth.subject=mesh,synth.mesh_path=$(cd "$meshes" && pwd)"
  overrides+=",synth.truth_refinement=1,synth.folds=[]"
  echo "subject: $meshes"
else
  echo "subject: built-in skirt (configs/synth_skirt_smoothed.yaml)"
fi
[ -n "${ITERATIONS:-}" ] && overrides+=",synth.smoothing.iterations=$ITERATIONS"

seconds_since() { echo "$1 $(date +%s.%N)" | awk '{ printf "%.1f", $2 - $1 }'; }

start=$(date +%s.%N)
"$finecap" synth --config configs/synth_skirt_smoothed.yaml --out "$work/capture" \
  --set "$overrides" >/dev/null
synth_seconds=$(seconds_since "$start")
start=$(date +%s.%N)
"$finecap" refine --capture "$work/capture" --out "$work/run" --set "${SET:-}" >/dev/null \
  2>"$work/refine.log"
refine_seconds=$(seconds_since "$start")
# Only the figures against the truth are printed: the optical flow is left out to save time.
start=$(date +%s.%N)
"$finecap" eval --capture "$work/capture" --out "$work/run" --set eval.flow=none >/dev/null \
  2>"$work/eval.log"
eval_seconds=$(seconds_since "$start")

metrics="$work/run/eval/metrics.json"
# One line per frame in metrics.json: {"frame": "000000", ..., "figures": {"all": {"vertices": N,
# "rms_coarse_mm": X, "rms_subdivided_mm": S, "rms_refined_mm": Y, ...
grep '^    {"frame": ' "$metrics" |
  sed -E 's/.*"frame": "([^"]*)".*"figures": \{"all": \{[^}]*"rms_coarse_mm": ([^,]*), "rms_subdivided_mm": ([^,]*), "rms_refined_mm": ([^,]*),.*/\1 \2 \3 \4/' |
  awk '{ printf "frame %s: input_rms_mm %.3f subdivided_rms_mm %.3f refined_rms_mm %.3f recovered_percent %.1f\n", $1, $2, $3, $4, 100 * (1 - $4 / $2) }'
top() { grep -m1 -o "^  \"$1\": [^,]*" "$metrics" | awk '{ print $2 }'; }
echo "pooled_input_rms_mm: $(top rms_coarse_mm)"
echo "pooled_subdivided_rms_mm: $(top rms_subdivided_mm)"
echo "pooled_refined_rms_mm: $(top rms_refined_mm)"
echo "pooled_recovered_percent: $(top detail_recovered | awk '{ printf "%.1f", 100 * $1 }')"
echo "synth_seconds: $synth_seconds"
echo "refine_seconds: $refine_seconds"
echo "eval_seconds: $eval_seconds"
