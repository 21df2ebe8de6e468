#!/usr/bin/env bash
# Whether the search range (energy.k_max) limits a result: every capture refined with its automatic
# range R (the scene's, widened per frame where the plane sweep finds it limiting and narrowed
# where the sweep finds it far wider than the frame needs) and with R / 2 and 2 R set explicitly,
# each as a starting range (`--set energy.k_max=...`). The real captures
# are scored by their held-out NCC (heldout_ncc_refined), the synthetic ones by their RMS against
# the truth (frames 0-2 pooled) and the share of the detail recovered.
#
#   bash bench/search_range.sh              # WORK=DIR keeps the synthetic captures (made once)
#   CAPTURES="temple synth_skirt" bash bench/search_range.sh   # some of them
#   SET="refine.sweep.window_sigmas=0" bash bench/search_range.sh   # extra settings (--set)
#
# Prints one line a capture and range, "capture range: figure" with the range the run started
# from and the widest one a frame was solved in (k_max_mm of stats.jsonl), then per capture the
# relative change of the figure at R / 2 and at 2 R against R, in per cent.
set -euo pipefail
cd "$(dirname "$0")/.."
finecap=${FINECAP:-build/finecap}
captures=${CAPTURES:-"temple sceaux synth_skirt synth_skirt_exact synth_skirt_smoothed"}
shared=${SHARED:-../shared/captures}
work=${WORK:-$(mktemp -d)}
[ -n "${WORK:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work"
[ -x "$finecap" ] || bash scripts/build.sh >/dev/null

# The arguments of `finecap refine` for a capture, without --out; empty when it is missing.
capture_args() {
  case $1 in
    temple)
      [ -f "$shared/middlebury_temple/cameras.yaml" ] || return 0
      echo "--config configs/temple.yaml --capture $shared/middlebury_temple" ;;
    sceaux)
      [ -f "$shared/openmvs_sceaux/heldout.yaml" ] || return 0
      echo "--config $shared/openmvs_sceaux/heldout.yaml --capture $shared/openmvs_sceaux" ;;
    *)
      if [ ! -f "$work/$1/cameras.yaml" ]; then
        "$finecap" synth --config "configs/$1.yaml" --out "$work/$1" --set synth.num_frames=3 \
          >/dev/null 2>"$work/$1.synth.log"
      fi
      echo "--capture $work/$1 --frames 0:3" ;;
  esac
}

# Refines into $work/run_$1_$2 with energy.k_max=$3 (empty: automatic) and prints
# "figure started_mm widest_mm".
refine() {
  local run="$work/run_$1_$2" set=${SET:-}
  [ -z "$3" ] || set="${set:+$set,}energy.k_max=$3"
  rm -rf "$run"
  # shellcheck disable=SC2046
  "$finecap" refine $(capture_args "$1") --out "$run" --set "$set" >/dev/null 2>"$run.log"
  python3 - "$run/stats.jsonl" "$run.log" <<'PY'
import json, math, re, sys
records = [json.loads(line) for line in open(sys.argv[1])]
if records[0].get("heldout_ncc_refined") is not None:
    figure = sum(r["heldout_ncc_refined"] for r in records) / len(records)
else:
    figure = math.sqrt(sum(r["rms_refined_mm"] ** 2 for r in records) / len(records))
    given = math.sqrt(sum(r["rms_coarse_mm"] ** 2 for r in records) / len(records))
started = re.search(r"energy\.k_max ([0-9.e+-]+) (mm|m)", open(sys.argv[2]).read())
started = float(started.group(1)) * (1000.0 if started.group(2) == "m" else 1.0)
print(f"{figure:.6f} {started:.4g} {max(r['k_max_mm'] for r in records):.4g}")
PY
}

for capture in $captures; do
  [ -n "$(capture_args "$capture")" ] || { echo "$capture: SKIPPED (no capture)" >&2; continue; }
  read -r auto started widest < <(refine "$capture" auto "")
  name=$([ "$capture" = temple ] || [ "$capture" = sceaux ] && echo heldout_ncc || echo rms_mm)
  echo "$capture R ($started mm, widest solved in $widest mm) $name: $auto"
  metres=$(awk -v mm="$started" 'BEGIN { printf "%.6g", mm / 1000 }')
  for factor in 0.5 2; do
    k=$(awk -v m="$metres" -v f="$factor" 'BEGIN { printf "%.6g", m * f }')
    read -r figure started widest < <(refine "$capture" "x$factor" "$k")
    change=$(awk -v a="$figure" -v b="$auto" 'BEGIN { printf "%+.2f", 100 * (a - b) / b }')
    echo "$capture ${factor}R ($started mm, widest solved in $widest mm) $name: $figure ($change %)"
  done
done
