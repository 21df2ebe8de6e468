#!/usr/bin/env bash
# The memory forecast against the measurement: `finecap refine` on each given capture (its first
# frame by default), reading the "expected peak memory" it prints before the run and the peak
# resident memory it reached (peak_rss_mb, getrusage's high-water mark, from stats.jsonl).
#
#   bash bench/memory_forecast.sh CAPTURE [CAPTURE ...]
#   SET=energy.k_max=0.01 FRAMES=0:2 CONFIG=configs/demo.yaml bash bench/memory_forecast.sh DIR
#
# With no capture given it makes synth_demo and a 2-frame synth_skirt in a temporary folder and
# adds the Middlebury temple (TEMPLE=DIR, default ../shared/captures/middlebury_temple). One row per
# capture: forecast MB, measured MB (the peak over the frames run), measured / forecast, the
# forecast and measured seconds of the first frame; exits 1 when a ratio lies outside [0.8, 1.25].
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-0:1}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

[ -x build/finecap ] || bash scripts/build.sh >/dev/null
captures=("$@")
if [ ${#captures[@]} -eq 0 ]; then
  build/finecap synth --config configs/synth_demo.yaml --out "$work/synth_demo" >/dev/null
  build/finecap synth --config configs/synth_skirt.yaml --out "$work/synth_skirt" \
    --set synth.num_frames=2 >/dev/null
  captures=("$work/synth_demo" "$work/synth_skirt")
  temple=${TEMPLE:-../shared/captures/middlebury_temple}
  [ -d "$temple" ] && captures+=("$temple")
fi

args=()
[ -n "${CONFIG:-}" ] && args+=(--config "$CONFIG")
[ -n "${SET:-}" ] && args+=(--set "$SET")

status=0
printf "%-40s %12s %12s %8s %12s %12s\n" capture forecast_mb measured_mb ratio forecast_s measured_s
for capture in "${captures[@]}"; do
  out="$work/run_$(basename "$capture")"
  build/finecap refine --capture "$capture" --out "$out" --frames "$frames" "${args[@]}" \
    >"$work/stdout" 2>"$work/stderr" || { cat "$work/stderr" >&2; exit 1; }
  forecast=$(grep -o 'expected peak memory [0-9]*' "$work/stderr" | awk '{ print $4 }')
  forecast_s=$(grep -o 'MB, about [0-9.]* [a-z]*' "$work/stderr" |
    awk '{ print ($4 == "min") ? $3 * 60 : $3 }')
  # The run's peak: the largest high-water mark of its frames; the first frame's time.
  measured=$(grep -o '"peak_rss_mb": [0-9.eE+-]*' "$out/stats.jsonl" |
    awk '{ if ($2 > m) m = $2 } END { print m }')
  seconds=$(head -n 1 "$out/stats.jsonl" | grep -o '"seconds": [0-9.eE+-]*' | cut -d' ' -f2)
  ratio=$(echo "$forecast $measured" | awk '{ printf "%.2f", $2 / $1 }')
  printf "%-40s %12s %12.0f %8s %12s %12.1f\n" "$(basename "$capture")" "$forecast" "$measured" \
    "$ratio" "$forecast_s" "$seconds"
  awk -v r="$ratio" 'BEGIN { exit !(r >= 0.8 && r <= 1.25) }' || status=1
done
exit $status
