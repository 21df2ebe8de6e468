#!/usr/bin/env bash
# The Middlebury temple (real photos, no ground truth) refined with the default settings and
# templeSR0003, 0007, 0011 and 0015 held out (configs/temple.yaml), then measured in those views
# by `finecap eval`: the held-out NCC (7x7 windows, the 4 nearest training views warped in) and
# MAD of the visual hull as given (input), of its subdivision and of the refined mesh.
#
#   bash bench/temple_heldout.sh            # CAPTURE=DIR for a copy elsewhere; OUT=DIR keeps the run
#   SET="energy.confidence_prior=0" bash bench/temple_heldout.sh   # extra settings (--set)
#
# Prints one "name: value" a line: per held-out view heldout_ncc_input/subdivided/refined and
# heldout_mad_input/subdivided/refined, the same over all views, refine_worse (the frame's flag),
# heldout_score_seconds (the score's share of refine), refine_seconds and refine_peak_mb (wall
# time and peak resident memory of the whole `finecap refine`, /usr/bin/time), and eval_seconds.
set -euo pipefail
cd "$(dirname "$0")/.."
capture=${CAPTURE:-../shared/captures/middlebury_temple}
if [ ! -f "$capture/cameras.yaml" ]; then
  echo "SKIPPED: no temple capture at $capture" >&2
  exit 0
fi
work=${OUT:-$(mktemp -d)}
[ -n "${OUT:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work"
rm -rf "$work/run"

[ -x build/finecap ] || bash scripts/build.sh >/dev/null
args=(--config configs/temple.yaml --capture "$capture" --out "$work/run")
/usr/bin/time -f "%e %M" -o "$work/refine.time" build/finecap refine "${args[@]}" \
  --set "${SET:-}" >/dev/null
start=$(date +%s.%N)
build/finecap eval "${args[@]}" --set "eval.flow=none${SET:+,$SET}" >/dev/null
end=$(date +%s.%N)

python3 bench/heldout_figures.py "$work/run"
read -r seconds kilobytes < "$work/refine.time"
echo "refine_seconds: $seconds"
echo "refine_peak_mb: $((kilobytes / 1024))"
echo "eval_seconds: $(echo "$end - $start" | bc)"
