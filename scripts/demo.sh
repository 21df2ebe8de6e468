#!/usr/bin/env bash
# The demo: installs the dependencies, builds, generates the small synthetic capture of
# configs/synth_demo.yaml (once), refines it with configs/demo.yaml and evaluates the result
# (finecap eval), printing the error against the ground truth and ending with the paths of the
# report (tables, plots, a 3D view of the input and refined meshes) and of a normal render.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
bash scripts/build.sh
if [ ! -d data/demo ]; then
  rm -rf data/demo.partial
  ./build/finecap synth --config configs/synth_demo.yaml --out data/demo.partial
  mv data/demo.partial data/demo
fi
# A fresh output folder each time, so the demo always shows a whole run.
rm -rf out/demo
./build/finecap refine --config configs/demo.yaml
# Eval with its default settings (optical flow by DIS "medium" in all 4 cameras): 5.5 s for the
# 5 frames of 512^2 against 4.5 s with eval.flow_dis_preset: fast (medians of 3, runs alternated);
# the flow is cheap at this size, so the demo keeps the defaults whose figures the README and docs/measurements.md quote.
./build/finecap eval --config configs/demo.yaml
# The last frame: the folds are fully grown there (they ramp up from frame 0).
normals="$(ls out/demo/eval/frame_*.png | tail -n 1)"
echo
echo "demo: open the report (figures, plots, pictures, 3D view of input and refined meshes):"
echo "  $PWD/out/demo/eval/report.html"
echo "demo: the image | normals of the input | normals refined, the detail added:"
echo "  $PWD/$normals"
