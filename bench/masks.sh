#!/usr/bin/env bash
# Foreground masks against a background that differs between cameras: synth_skirt refined on its
# plain background without and with the masks synth wrote, on a textured wall of its own in every
# camera without masks, and on those walls with the masks. One "variant_figure: value" a line: rms_input_mm (the coarse
# mesh as given), rms_refined_mm and detail_recovered_percent (1 - refined / as given), pooled
# over the frames.
#
#   bash bench/masks.sh                 # frames 0-2; FRAMES=0:6 for more
#   WORK=DIR bash bench/masks.sh        # keeps the captures (made once) and the runs
set -euo pipefail
cd "$(dirname "$0")/.."
finecap=${FINECAP:-build/finecap}
frames=${FRAMES:-0:3}
if [ -z "${WORK:-}" ]; then
  WORK=$(mktemp -d)
  trap 'rm -rf "$WORK"' EXIT
fi
work=$WORK

synth() {  # synth OUT SET
  [ -f "$1/cameras.yaml" ] && return
  mkdir -p "$(dirname "$1")"
  "$finecap" synth --config configs/synth_skirt.yaml --out "$1" \
    --set "synth.num_frames=${frames#*:},$2" >/dev/null 2>"$1.synth.log"
}
synth "$work/plain" "synth.background=plain"
synth "$work/plain_masked" "synth.background=plain,synth.write_masks=true"
synth "$work/walls_masked" "synth.background=per_camera,synth.write_masks=true"
# The same images without their masks.
mkdir -p "$work/walls"
for part in cameras.yaml images meshes gt; do ln -sfn "$work/walls_masked/$part" "$work/walls/$part"; done

for variant in plain plain_masked walls walls_masked; do
  run="$work/run_$variant"
  rm -rf "$run"
  "$finecap" refine --capture "$work/$variant" --out "$run" --frames "$frames" \
    >/dev/null 2>"$work/$variant.refine.log"
  python3 - "$variant" "$run/stats.jsonl" <<'PY'
import json, math, sys
variant, stats = sys.argv[1], sys.argv[2]
records = [json.loads(line) for line in open(stats)]
def pooled(key):
    return math.sqrt(sum(r[key] ** 2 for r in records) / len(records))
given, refined = pooled("rms_coarse_mm"), pooled("rms_refined_mm")
print(f"{variant}_rms_input_mm: {given:.3f}")
print(f"{variant}_rms_refined_mm: {refined:.3f}")
print(f"{variant}_detail_recovered_percent: {100 * (1 - refined / given):.1f}")
PY
done
