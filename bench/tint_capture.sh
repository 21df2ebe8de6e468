#!/usr/bin/env bash
# A capture whose white balance drifts over the sequence, to measure colours that follow it
# (model.follow_colors): a copy of CAPTURE whose frame t has its red channel multiplied by
# 1 + RED t and its blue one by 1 - BLUE t (defaults 0.012 and 0.008: 1.35 and 0.77 at frame 29
# of synth_skirt). Cameras, meshes and ground truth are linked, not copied. Needs ImageMagick.
#
#   bash bench/tint_capture.sh CAPTURE OUT
#   finecap compare --config configs/compare_colors.yaml --capture OUT --out RUNS
#   bash bench/colors_drift.sh RUNS
set -euo pipefail
src=${1:?usage: bash bench/tint_capture.sh CAPTURE OUT}
dst=${2:?usage: bash bench/tint_capture.sh CAPTURE OUT}
red=${RED:-0.012}
blue=${BLUE:-0.008}
convert=$(command -v /usr/bin/convert || command -v convert || true)
[ -n "$convert" ] || { echo "bench/tint_capture.sh: needs ImageMagick's convert" >&2; exit 1; }
[ -d "$src/images" ] || { echo "$src: no images/ folder of per-camera frames" >&2; exit 1; }
[ ! -e "$dst" ] || { echo "$dst: exists; give a new folder" >&2; exit 1; }
mkdir -p "$dst/images"
for entry in "$src"/*; do
  [ "$(basename "$entry")" = images ] || ln -s "$(realpath "$entry")" "$dst/"
done
for camera in "$src"/images/*/; do
  name=$(basename "$camera")
  mkdir -p "$dst/images/$name"
  frame=0
  for image in "$camera"*; do
    r=$(awk -v t="$frame" -v g="$red" 'BEGIN { print 1 + g * t }')
    b=$(awk -v t="$frame" -v g="$blue" 'BEGIN { print 1 - g * t }')
    "$convert" "$image" -channel R -evaluate multiply "$r" -channel B -evaluate multiply "$b" \
      +channel "$dst/images/$name/$(basename "$image")"
    frame=$((frame + 1))
  done
done
echo "tinted capture: $dst"
