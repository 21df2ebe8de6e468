#!/usr/bin/env bash
# Sceaux Castle at full resolution: the 8 training photos of the OpenMVS sample at 2832 x 2128
# instead of the shared capture's quarter-resolution copies, refined with the default settings,
# and the result scored in the shared capture's two quarter-resolution held-out views as a mesh
# given as input (no subdivision, no iteration, no sweep), beside the input mesh scored the same
# way. Also the run's memory and time against the forecast `finecap refine` prints before it
# starts.
#
#   SAMPLE=DIR bash bench/sceaux_fullres.sh     # OUT=DIR keeps the runs; SET=... extra settings
#
# SAMPLE is the OpenMVS sample (github.com/cdcseacave/openMVS_sample): a checkout whose
# images/000NN.jpg are the photos, or a git directory of it without a work tree (the photos are
# then read with `git show`). Nothing is written there or into the shared capture: the full-size
# capture (bench/sceaux_full_resolution.sh: the shared one's cameras with focal lengths x 4 and,
# pixel centres being integers, c_full = 4 c + 1.5) is built in a temporary folder, and refined
# with the shared capture's held-out views left out (and scored at full size as well, which the
# run's time includes).
#
# Prints one "name: value" a line: heldout_ncc_input and heldout_ncc_refined (the mean NCC of the
# two held-out views), refine_seconds and refine_peak_mb (wall time and peak resident memory of
# the full-resolution `finecap refine`, /usr/bin/time), forecast_peak_mb and forecast_seconds
# (what it announced) and their ratios measured / forecast.
set -euo pipefail
cd "$(dirname "$0")/.."
capture=$(cd "${CAPTURE:-../shared/captures/openmvs_sceaux}" && pwd)
sample=${SAMPLE:?set SAMPLE to the OpenMVS sample (a checkout or its git directory)}
work=${OUT:-$(mktemp -d)}
[ -n "${OUT:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work"
work=$(cd "$work" && pwd)
rm -rf "$work/full" "$work/run" "$work/scored_input" "$work/scored_refined" "$work/score_"*
[ -x build/finecap ] || bash scripts/build.sh >/dev/null

# The sample's photos as files (from its git directory when it has no work tree), then the
# full-size capture (bench/sceaux_full_resolution.sh).
photos=$sample/images
if [ ! -f "$photos/00000.jpg" ]; then
  photos=$work/photos
  mkdir -p "$photos"
  for camera in "$capture"/images/v000*; do  # The photos of the shared capture's cameras.
    name=000${camera: -2}.jpg
    git -C "$sample" show "HEAD:images/$name" >"$photos/$name"
  done
fi
SCEAUX=$capture bash bench/sceaux_full_resolution.sh "$photos" "$work/full" >/dev/null

/usr/bin/time -f "%e %M" -o "$work/refine.time" build/finecap refine --config "$capture/heldout.yaml" \
  --capture "$work/full" --out "$work/run" --set "${SET:-}" >/dev/null 2>"$work/refine.log"

# Each mesh as given, scored in the held-out views like the input of a capture with every camera.
score() {
  mkdir -p "$work/scored_$1/meshes"
  ln -s "$capture/cameras.yaml" "$work/scored_$1/cameras.yaml"
  ln -s "$capture/images" "$work/scored_$1/images"
  cp "$2" "$work/scored_$1/meshes/000000.ply"
  build/finecap refine --config "$capture/heldout.yaml" --capture "$work/scored_$1" \
    --out "$work/score_$1" \
    --set model.subdivision_levels=0,solver.max_iterations=0,refine.sweep.samples=0 \
    >/dev/null 2>"$work/score_$1.log"
  grep -o '"heldout_ncc_input": [0-9.eE+-]*' "$work/score_$1/stats.jsonl" | awk '{ print $2 }'
}
printf "heldout_ncc_input: %.4f\n" "$(score input "$capture/meshes/000000.ply")"
printf "heldout_ncc_refined: %.4f\n" "$(score refined "$work/run/meshes/000000.ply")"

read -r seconds kilobytes <"$work/refine.time"
# "expected peak memory M MB (up to ... if ...), about T s|min per frame": the peak and time of
# the range the run starts with; the parenthesis is there only when a frame may widen it.
forecast=$(grep -o 'expected peak memory [0-9]* MB.*about [0-9.]* [a-z]* per frame' \
  "$work/refine.log" | head -1)
forecast_mb=$(echo "$forecast" | awk '{ print $4 }')
forecast_seconds=$(echo "$forecast" | awk '{ print ($(NF - 2) ~ /^min/) ? 60 * $(NF - 3) : $(NF - 3) }')
echo "refine_seconds: $seconds"
echo "refine_peak_mb: $((kilobytes / 1024))"
echo "forecast_peak_mb: $forecast_mb"
echo "forecast_seconds: $forecast_seconds"
awk -v m="$kilobytes" -v f="$forecast_mb" 'BEGIN { printf "memory_over_forecast: %.2f\n", m / 1024 / f }'
awk -v s="$seconds" -v f="$forecast_seconds" 'BEGIN { printf "time_over_forecast: %.2f\n", s / f }'
