#!/usr/bin/env bash
# Configures and builds finecap. Usage: scripts/build.sh [--sanitize]
# Release build in build/, ASan+UBSan build in build-sanitize/.
set -euo pipefail
cd "$(dirname "$0")/.."

build_dir=build
extra=()
if [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-sanitize
  extra=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DFINECAP_SANITIZE=ON -DFINECAP_BUILD_BENCHMARKS=OFF)
fi
cmake -S . -B "$build_dir" -G Ninja "${extra[@]}" >/dev/null
cmake --build "$build_dir" -j "$(nproc)"
