#!/usr/bin/env bash
# The demo: installs the dependencies, builds, generates the small synthetic capture of
# configs/synth_demo.yaml (8 cameras of 512 x 512, 3 frames, folds in every frame; again only when
# that file changes), refines it with configs/demo.yaml (the defaults) and evaluates the result
# (finecap eval). It ends with a summary of what ran (similarity, solver, cameras, frames) and the
# error against the ground truth, and the paths of the report and of a normal render.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
bash scripts/build.sh
# The capture is generated once and kept with the hash of the config it was made from: a changed
# configs/synth_demo.yaml makes it again.
stamp="$(sha256sum configs/synth_demo.yaml | cut -d' ' -f1)"
if [ "$(cat data/demo/synth_demo.sha256 2>/dev/null)" != "$stamp" ]; then
  rm -rf data/demo data/demo.partial
  ./build/finecap synth --config configs/synth_demo.yaml --out data/demo.partial
  echo "$stamp" >data/demo.partial/synth_demo.sha256
  mv data/demo.partial data/demo
fi
# A fresh output folder each time, so the demo always shows a whole run.
rm -rf out/demo
./build/finecap refine --config configs/demo.yaml
# Eval with its default settings (optical flow by DIS "medium" in every camera).
./build/finecap eval --config configs/demo.yaml

# The value of `key` in the first JSON object of `file` that has it (a string or a number).
json_value() {
  grep -o "\"$1\": *\"\?[^,\"}]*" "$2" | head -n 1 | sed 's/.*: *"\?//'
}
stats=out/demo/stats.jsonl
metrics=out/demo/eval/metrics.json
cameras="$(find data/demo/images -mindepth 1 -maxdepth 1 -type d | wc -l)"
width="$(grep -m 1 -E '^ +width: *[0-9]+' data/demo/cameras.yaml | grep -o '[0-9]*$')"
height="$(grep -m 1 -E '^ +height: *[0-9]+' data/demo/cameras.yaml | grep -o '[0-9]*$')"
frames="$(wc -l <"$stats")"
recovered="$(json_value detail_recovered "$metrics")"
normals="$(ls out/demo/eval/frame_*.png | tail -n 1)"
echo
echo "demo: refined $frames frames of data/demo ($cameras cameras of $width x $height, folds in every frame)"
echo "demo:   with configs/demo.yaml: similarity $(json_value similarity "$stats")," \
  "solver $(json_value solver "$stats") (the defaults)"
printf 'demo: RMS error against the truth %.3f mm as given -> %.3f mm refined:' \
  "$(json_value rms_coarse_mm "$metrics")" "$(json_value rms_refined_mm "$metrics")"
awk -v r="$recovered" 'BEGIN { printf " %.1f %% of the detail recovered\n", 100 * r }'
# Refine's own measure, from the training images alone: how much of the surface enough cameras see
# well enough for the images to decide it (the rest is held near the input).
grep -o '"confident_share": *[0-9.]*' "$stats" | sed 's/.*: *//' |
  awk '{ sum += $1; n += 1 } END { printf "demo: %.0f %% of the vertices refined with confidence (mean over the frames)\n", 100 * sum / n }'
echo "demo: open the report (figures; 3D view of the input, the refined mesh coloured by its error,"
echo "demo:   the truth and the refined mesh coloured by its confidence; plots; pictures):"
echo "  $PWD/out/demo/eval/report.html"
echo "demo: the image | normals of the input | normals refined, the detail added:"
echo "  $PWD/$normals"
