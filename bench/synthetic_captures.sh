#!/usr/bin/env bash
# Every kind of synthetic capture refined with the default settings (or SET's) and measured
# against its truth, one row each: what a change to the energy or the surface model must be
# measured on (the real captures have bench/temple_heldout.sh and bench/sceaux_heldout.sh).
#
#   bash bench/synthetic_captures.sh              # frames 0-2 of each; FRAMES=0:6 for more
#   SET="energy.consensus.sample_spacing=0" bash bench/synthetic_captures.sh   # a variant
#   FINECAP=other/build/finecap bash bench/synthetic_captures.sh              # another build
#   WORK=DIR bash bench/synthetic_captures.sh     # keeps the captures (made once) and the runs
#
# The captures (configs/): synth_skirt (folds in every frame, frame 0 included), synth_skirt_exact
# (the coarse vertices on the true surface, the detail between them missing), synth_skirt_smoothed
# (the truth Taubin-smoothed), synth_fold_5cm (single 5 cm folds) and synth_textureless (a plain
# band). Prints one "capture_figure: value" a line: rms_input_mm (the coarse mesh as given),
# rms_subdivided_mm, rms_refined_mm, detail_recovered_percent (1 - refined / as given),
# worst_frame_gain_percent (the frame that gained least against its input as given; negative:
# worse than it), band_worst_frame_mm for the textureless band, and seconds (wall time of
# `finecap refine`).
set -euo pipefail
cd "$(dirname "$0")/.."
finecap=${FINECAP:-build/finecap}
frames=${FRAMES:-0:3}
last=${frames#*:}
work=${WORK:-$(mktemp -d)}
[ -n "${WORK:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work"
[ -x "$finecap" ] || bash scripts/build.sh >/dev/null

for capture in synth_skirt synth_skirt_exact synth_skirt_smoothed synth_fold_5cm synth_textureless; do
  data="$work/$capture"
  if [ ! -f "$data/cameras.yaml" ]; then
    "$finecap" synth --config "configs/$capture.yaml" --out "$data" \
      --set "synth.num_frames=$last" >/dev/null 2>"$work/$capture.synth.log"
  fi
  run="$work/run_$capture"
  rm -rf "$run"
  args=(--capture "$data" --out "$run" --frames "$frames")
  start=$(date +%s.%N)
  "$finecap" refine "${args[@]}" --set "${SET:-}" >/dev/null 2>"$work/$capture.refine.log"
  end=$(date +%s.%N)
  python3 - "$capture" "$run/stats.jsonl" "$start" "$end" <<'PY'
import json, math, sys
capture, stats, start, end = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
records = [json.loads(line) for line in open(stats)]
def pooled(key):
    return math.sqrt(sum(r[key] ** 2 for r in records) / len(records))
given, subdivided, refined = (pooled(k) for k in ("rms_coarse_mm", "rms_subdivided_mm", "rms_refined_mm"))
print(f"{capture}_rms_input_mm: {given:.3f}")
print(f"{capture}_rms_subdivided_mm: {subdivided:.3f}")
print(f"{capture}_rms_refined_mm: {refined:.3f}")
print(f"{capture}_detail_recovered_percent: {100 * (1 - refined / given):.1f}")
worst = min(1 - r["rms_refined_mm"] / r["rms_coarse_mm"] for r in records)
print(f"{capture}_worst_frame_gain_percent: {100 * worst:.1f}")
band = [r["rms_textureless_refined_mm"] for r in records if r.get("rms_textureless_refined_mm")]
if band:
    print(f"{capture}_band_worst_frame_mm: {max(band):.2f}")
print(f"{capture}_seconds: {end - start:.1f}")
PY
done
