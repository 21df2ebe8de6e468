#!/usr/bin/env bash
# The demo: installs the dependencies, builds, generates the small synthetic capture of
# configs/synth_demo.yaml (once) and refines it with configs/demo.yaml, printing where the
# results are and their error against the ground truth.
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
