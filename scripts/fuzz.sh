#!/usr/bin/env bash
# Builds the libFuzzer targets of tests/fuzz with clang (ASan + UBSan) in build-fuzz/ and runs each
# for a bounded time from its seed corpus; fails when any target finds a crash, a sanitizer
# report, an exception other than finecap::Error, a timeout or an out-of-memory.
# Usage: scripts/fuzz.sh [seconds per target, default 60]
# Crashing inputs are saved in build-fuzz/fuzz-artifacts/; the corpus grows in build-fuzz/corpus/.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
build_dir=build-fuzz

bash scripts/install-deps.sh
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S . -B "$build_dir" -G Ninja -DCMAKE_CXX_COMPILER=clang++-14 -DFINECAP_FUZZ=ON \
  -DFINECAP_BUILD_TESTS=OFF -DFINECAP_BUILD_BENCHMARKS=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "${launcher[@]}" >/dev/null
cmake --build "$build_dir" --target fuzzers -j "$(nproc)"

# Seeds that are generated rather than committed: the configs we ship and a binary PLY.
generated="$build_dir/generated-seeds"
mkdir -p "$generated/config" "$generated/ply"
cp configs/*.yaml "$generated/config/"
{
  printf 'ply\nformat binary_little_endian 1.0\nelement vertex 3\n'
  printf 'property float x\nproperty float y\nproperty float z\n'
  printf 'element face 1\nproperty list uchar int vertex_indices\nend_header\n'
  # (0,0,0) (1,0,0) (0,1,0) as little-endian floats, then the face 3 0 1 2.
  printf '\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f\0\0\0\0\0\0\0\0\0\0\0\0\0\0\x80\x3f\0\0\0\0'
  printf '\x03\0\0\0\0\x01\0\0\0\x02\0\0\0'
} >"$generated/ply/triangle_binary.ply"

export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
mkdir -p "$build_dir/fuzz-artifacts"
failed=()
for fuzzer in "$build_dir"/tests/fuzz/*_fuzzer; do
  name="$(basename "$fuzzer" _fuzzer)"
  corpus="$build_dir/corpus/$name"
  mkdir -p "$corpus"
  seeds=(tests/fuzz/corpus/"$name")
  if [ -d "$generated/$name" ]; then seeds+=("$generated/$name"); fi
  options=()
  if [ -f "tests/fuzz/$name.dict" ]; then options+=(-dict="tests/fuzz/$name.dict"); fi
  echo "fuzz: $name for ${seconds} s"
  if ! "$fuzzer" "$corpus" "${seeds[@]}" "${options[@]}" -max_total_time="$seconds" -rss_limit_mb=2048 \
    -timeout=10 -max_len=8192 -artifact_prefix="$build_dir/fuzz-artifacts/$name-" \
    -print_final_stats=1 >"$build_dir/fuzz-$name.log" 2>&1; then
    tail -n 40 "$build_dir/fuzz-$name.log"
    failed+=("$name")
  fi
  grep -E "^stat::number_of_executed_units|^stat::new_units_added" "$build_dir/fuzz-$name.log" |
    sed "s/^stat::/  $name: /"
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: FAILED: ${failed[*]} (inputs in $build_dir/fuzz-artifacts/)" >&2
  exit 1
fi
echo "fuzz: every target ran ${seconds} s without a finding"
