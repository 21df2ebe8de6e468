#!/usr/bin/env bash
# Installs the dependencies, builds, and runs every unit test.
# Usage: scripts/test.sh [--sanitize]   (--sanitize: under AddressSanitizer + UBSan)
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
bash scripts/build.sh "$@"
build_dir=build
if [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-sanitize
  export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
fi
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)"
