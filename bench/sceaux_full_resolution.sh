#!/usr/bin/env bash
# The Sceaux castle capture (../shared/captures/openmvs_sceaux) at the resolution it was shot at:
# its cameras with the intrinsics scaled back from the 708 x 532 images to the 2832 x 2128 photos
# they were downscaled from (4x, INTER_AREA, pixel centres at integers: x_full = 4 x + 1.5), its
# mesh and heldout.yaml linked, and the photos themselves (images/000NN.jpg of the public OpenMVS
# sample, GitHub cdcseacave/openMVS_sample) linked as images/v000NN/000000.jpg. For
# bench/memory_forecast.sh (SCEAUX_FULL=OUT).
#
#   bash bench/sceaux_full_resolution.sh SAMPLE_IMAGES_DIR OUT
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: $0 SAMPLE_IMAGES_DIR OUT" >&2; exit 2; }
sample=$(realpath "$1")
out=$2
cd "$(dirname "$0")/.."
sceaux=$(realpath "${SCEAUX:-../shared/captures/openmvs_sceaux}")
mkdir -p "$out/meshes"
ln -sfn "$sceaux/meshes/000000.ply" "$out/meshes/000000.ply"
ln -sfn "$sceaux/heldout.yaml" "$out/heldout.yaml"
for camera in "$sceaux"/images/v000*; do
  name=$(basename "$camera")
  photo="$sample/000${name: -2}.jpg"
  [ -f "$photo" ] || { echo "$photo: missing (the OpenMVS sample's photo of camera $name)" >&2; exit 1; }
  mkdir -p "$out/images/$name"
  ln -sfn "$photo" "$out/images/$name/000000.jpg"
done
awk '
  /^ *width:/ { sub(/[0-9]+/, $2 * 4) }
  /^ *height:/ { sub(/[0-9]+/, $2 * 4) }
  /^ *K:/ {
    split(substr($0, index($0, "[") + 1), k, /, */); sub(/\].*/, "", k[9])
    prefix = substr($0, 1, index($0, "K:") - 1)
    $0 = sprintf("%sK: [%.17g, %.17g, %.17g, 0.0, %.17g, %.17g, 0.0, 0.0, 1.0]", prefix,
                 4 * k[1], 4 * k[2], 4 * k[3] + 1.5, 4 * k[5], 4 * k[6] + 1.5)
  }
  { print }' "$sceaux/cameras.yaml" >"$out/cameras.yaml"
echo "$out"
