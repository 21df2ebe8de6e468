#!/usr/bin/env bash
# What each process-wide setting of the finecap executable is worth (finecap/util/process.h):
# `finecap refine` on synth_skirt with the defaults, and with each setting in turn set back to
# glibc's or libgomp's default: --one_malloc_arena=false, --huge_page_heap_mb=0 and
# OMP_WAIT_POLICY=active. The variants run in turn, REPEATS times, so that a change in the
# machine's load reaches them all alike.
#
#   bash bench/process_settings.sh                 # 10 frames, 3 repeats
#   FRAMES=5 REPEATS=5 bash bench/process_settings.sh
#   BUSY=1 bash bench/process_settings.sh          # with one core kept busy by another process
#
# Prints a row per variant: the median wall seconds of the run, frames per minute, the median
# peak resident memory (MB) and CPU seconds, and the ratios of time and memory to the defaults'.
set -euo pipefail
cd "$(dirname "$0")/.."
frames=${FRAMES:-10}
repeats=${REPEATS:-3}
work=$(mktemp -d)
busy_pid=
cleanup() {
  [ -z "$busy_pid" ] || kill "$busy_pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
[ -x build/finecap ] || bash scripts/build.sh >/dev/null
build/finecap synth --config configs/synth_skirt.yaml --out "$work/capture" \
  --set "synth.num_frames=$frames" >/dev/null
if [ -n "${BUSY:-}" ]; then
  (while :; do :; done) &
  busy_pid=$!
fi

names=(defaults glibc_arenas no_huge_pages spinning_workers)
run_variant() {  # name output_folder
  local flags=() env=()
  case $1 in
    glibc_arenas) flags=(--one_malloc_arena=false) ;;
    no_huge_pages) flags=(--huge_page_heap_mb=0) ;;
    spinning_workers) env=(OMP_WAIT_POLICY=active) ;;
  esac
  env "${env[@]}" /usr/bin/time -f "%e %M %U %S" -o "$2.time" build/finecap refine \
    --capture "$work/capture" --out "$2" "${flags[@]}" >/dev/null 2>&1
  awk '{ printf "%s %.1f %.2f\n", $1, $2 / 1024, $3 + $4 }' "$2.time"
}
for ((r = 0; r < repeats; ++r)); do
  for name in "${names[@]}"; do
    run_variant "$name" "$work/run_${name}_$r" >>"$work/$name.txt"
  done
done

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
column_median() { awk -v c="$2" '{ print $c }' "$work/$1.txt" | median; }
base_seconds=$(column_median defaults 1)
base_mb=$(column_median defaults 2)
echo "synth_skirt, $frames frames, median of $repeats runs${BUSY:+, one core kept busy}"
printf "%-18s %9s %7s %9s %8s %11s %10s\n" variant seconds fpm peak_mb cpu_s time_ratio mem_ratio
for name in "${names[@]}"; do
  seconds=$(column_median "$name" 1)
  mb=$(column_median "$name" 2)
  cpu=$(column_median "$name" 3)
  awk -v n="$name" -v s="$seconds" -v m="$mb" -v c="$cpu" -v f="$frames" -v bs="$base_seconds" \
    -v bm="$base_mb" 'BEGIN { printf "%-18s %9.2f %7.1f %9.1f %8.2f %11.3f %10.3f\n", n, s,
      60 * f / s, m, c, s / bs, m / bm }'
done
