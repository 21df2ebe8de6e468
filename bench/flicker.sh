#!/usr/bin/env bash
# Flicker against error on synth_noisy (10 frames, the defaults or SET's): the RMS over the
# refined vertices of the change of the signed error since the frame before (the flicker), and
# the error itself, each pooled over the frames from the per-frame records of stats.jsonl, for
# the refined surface and for the input as given. One "figure: value" a line.
#
#   bash bench/flicker.sh
#   SET="energy.w_reg=3e-6" bash bench/flicker.sh            # a variant, the same capture
#   WORK=DIR bash bench/flicker.sh                           # keeps the capture (made once)
set -euo pipefail
cd "$(dirname "$0")/.."
finecap=${FINECAP:-build/finecap}
work=${WORK:-$(mktemp -d)}
[ -n "${WORK:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work"
[ -x "$finecap" ] || bash scripts/build.sh >/dev/null

data="$work/synth_noisy"
if [ ! -f "$data/cameras.yaml" ]; then
  "$finecap" synth --config configs/synth_noisy.yaml --out "$data" >/dev/null 2>"$work/synth.log"
fi
run="$work/run_noisy"
rm -rf "$run"
"$finecap" refine --capture "$data" --out "$run" --set "${SET:-}" >/dev/null 2>"$work/refine.log"
python3 - "$run/stats.jsonl" <<'PY'
import json, math, sys
records = [json.loads(line) for line in open(sys.argv[1])]
def pooled(key):
    values = [r[key] for r in records if r.get(key) is not None and r[key] == r[key]]
    return math.sqrt(sum(v * v for v in values) / len(values))
for surface, error_key, flicker_key in (("input", "rms_coarse_mm", "flicker_coarse_mm"),
                                        ("refined", "rms_refined_mm", "flicker_refined_mm")):
    error, flicker = pooled(error_key), pooled(flicker_key)
    print(f"{surface}_error_mm: {error:.3f}")
    print(f"{surface}_flicker_mm: {flicker:.3f}")
    print(f"{surface}_flicker_over_error: {flicker / error:.3f}")
PY
