#!/usr/bin/env bash
# Memory over a long run: `finecap refine` on a small 300-frame synthetic capture
# (configs/synth_long.yaml), reading each frame's peak resident memory (peak_rss_mb, getrusage's
# high-water mark) from stats.jsonl. Nothing in refine may grow with the frames, so the peak after
# frame 300 must stay within 10 % of the peak after frame 10.
#
#   bash bench/memory_flat.sh            # 300 frames, a few minutes; FRAMES=100 for a quicker look
#
# Prints one "name: value" a line: peak_rss_mb_frame_10, peak_rss_mb_frame_<FRAMES>, ratio (the
# second over the first), seconds_per_frame; exits 1 when the ratio exceeds 1.10.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-300}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

[ -x build/finecap ] || bash scripts/build.sh >/dev/null
build/finecap synth --config configs/synth_long.yaml --out "$work/capture" \
  --set "synth.num_frames=$frames" >/dev/null
start=$(date +%s.%N)
# 4 cameras 90 degrees apart: 50 degrees leaves no point unseen.
build/finecap refine --capture "$work/capture" --out "$work/run" \
  --set visibility.max_view_angle_deg=50 >/dev/null 2>&1
end=$(date +%s.%N)

# peak_rss_mb of the n-th record of stats.jsonl.
peak_of() { sed -n "$1p" "$work/run/stats.jsonl" | grep -o '"peak_rss_mb": [0-9.eE+-]*' | cut -d' ' -f2; }
first=$(peak_of 10)
last=$(peak_of "$frames")
ratio=$(echo "$first $last" | awk '{ printf "%.3f", $2 / $1 }')
echo "peak_rss_mb_frame_10: $first"
echo "peak_rss_mb_frame_$frames: $last"
echo "ratio: $ratio"
echo "seconds_per_frame: $(echo "$start $end" | awk -v f="$frames" '{ printf "%.3f", ($2 - $1) / f }')"
awk -v r="$ratio" 'BEGIN { exit !(r <= 1.10) }' || { echo "memory grew by more than 10 %" >&2; exit 1; }
