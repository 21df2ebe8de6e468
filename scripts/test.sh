#!/usr/bin/env bash
# Installs the dependencies, builds, and runs every test: the unit tests and the quality tests
# (ctest label `quality`: end-to-end figures against today's, about 1.5 min on 2 cores).
# Usage: scripts/test.sh [--sanitize]   (--sanitize: under AddressSanitizer + UBSan, without the
# quality tests, which would take several times longer there and check figures, not memory)
# A skipped test (its capture, tool or library missing) is listed at the end; with
# FINECAP_NO_SKIPS=1 (as CI sets it) it fails the run, except the huge-pages test, whose skip
# depends on the kernel's setting rather than on anything the machine can install.
set -euo pipefail
cd "$(dirname "$0")/.."

bash scripts/install-deps.sh
bash scripts/build.sh "$@"
build_dir=build
labels=()
if [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-sanitize
  labels=(-LE quality)
  export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
fi
log=$(mktemp)
trap 'rm -f "$log"' EXIT
ctest --test-dir "$build_dir" --output-on-failure -j "$(nproc)" "${labels[@]}" | tee "$log"

# CTest counts a test that skipped (gtest's "[  SKIPPED ]") as passed and lists it under "The
# following tests did not run", one "<number> - <name> (Skipped)" a line.
skipped=$(grep -E '^\s*[0-9]+ - .* \(Skipped\)$' "$log" |
  grep -v 'BackHeapWithHugePagesTest\.' || true)
if [ -n "$skipped" ]; then
  echo "test.sh: tests skipped (see why with: ctest --test-dir $build_dir -V -R NAME):" >&2
  echo "$skipped" >&2
  if [ "${FINECAP_NO_SKIPS:-0}" = "1" ]; then
    echo "test.sh: FINECAP_NO_SKIPS=1: a skipped test fails the run" >&2
    exit 1
  fi
fi
