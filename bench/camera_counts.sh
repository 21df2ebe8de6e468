#!/usr/bin/env bash
# Detail recovered against the number of cameras: synth_skirt (1004 x 1004 cameras) and synth_demo
# (512 x 512) with folds at full amplitude from frame 0 (synth.fold_ramp_frames=0), and the
# smoothed skirt (configs/synth_skirt_smoothed.yaml), each made with 3, 4, 6, 8 and 12 cameras
# evenly spaced on the configuration's ring and refined with the default settings (or SET's) on
# frames 0-2.
#
#   bash bench/camera_counts.sh
#   COUNTS="4 6" FRAMES=0:6 bash bench/camera_counts.sh
#   SET="energy.w_reg=0.5" bash bench/camera_counts.sh     # a variant, the same captures
#   WORK=DIR bash bench/camera_counts.sh                   # keeps the captures (made once) and runs
#
# Prints one table: a row per capture, a column per camera count, each cell the detail recovered
# (1 - RMS refined / RMS of the coarse mesh as given, over the frames run, per cent; negative:
# the refined surface is further from the truth than the input) and, in brackets, the worst frame's
# gain against its own input as given. Then the count of cells whose refined surface is worse than
# the input, pooled or in any frame: what a refinement on a sparse rig must bring to 0.
set -euo pipefail
cd "$(dirname "$0")/.."
finecap=${FINECAP:-build/finecap}
counts=${COUNTS:-3 4 6 8 12}
frames=${FRAMES:-0:3}
last=${frames#*:}
work=${WORK:-$(mktemp -d)}
[ -n "${WORK:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work"
[ -x "$finecap" ] || bash scripts/build.sh >/dev/null

# name, configuration, synth settings beside the camera count and frames.
captures=(
  "synth_skirt configs/synth_skirt.yaml synth.fold_ramp_frames=0"
  "synth_demo configs/synth_demo.yaml synth.fold_ramp_frames=0"
  "synth_skirt_smoothed configs/synth_skirt_smoothed.yaml synth.fold_ramp_frames=0"
  "synth_skirt_print configs/synth_skirt.yaml synth.fold_ramp_frames=0,synth.texture.pattern=print"
)

results=$work/results.tsv
: >"$results"
for entry in "${captures[@]}"; do
  read -r name config settings <<<"$entry"
  for count in $counts; do
    data=$work/${name}_$count
    if [ ! -f "$data/cameras.yaml" ]; then
      "$finecap" synth --config "$config" --out "$data" \
        --set "$settings,synth.num_frames=$last,synth.cameras.count=$count" \
        >/dev/null 2>"$data.synth.log"
    fi
    run=$work/run_${name}_$count
    rm -rf "$run"
    "$finecap" refine --capture "$data" --out "$run" --frames "$frames" --set "${SET:-}" \
      >/dev/null 2>"$run.log" || { tail -3 "$run.log" >&2; exit 1; }
    printf "%s\t%s\t%s\n" "$name" "$count" "$run/stats.jsonl" >>"$results"
  done
done

python3 - "$results" <<'PY'
import json, math, sys
rows, counts = {}, []
for line in open(sys.argv[1]):
    name, count, stats = line.rstrip("\n").split("\t")
    records = [json.loads(r) for r in open(stats)]
    pooled = lambda key: math.sqrt(sum(r[key] ** 2 for r in records) / len(records))
    recovered = 100.0 * (1.0 - pooled("rms_refined_mm") / pooled("rms_coarse_mm"))
    worst = min(100.0 * (1.0 - r["rms_refined_mm"] / r["rms_coarse_mm"]) for r in records)
    rows.setdefault(name, {})[count] = (recovered, worst)
    if count not in counts:
        counts.append(count)
print("detail recovered, % (worst frame's gain), defaults")
print(f"{'capture':<22}" + "".join(f"{c + ' cameras':>20}" for c in counts))
worse = 0
for name, cells in rows.items():
    line = f"{name:<22}"
    for count in counts:
        recovered, worst = cells[count]
        line += f"{f'{recovered:.1f} ({worst:.1f})':>20}"
        worse += recovered < 0 or worst < 0
    print(line)
print(f"worse_than_input_cells: {worse}")
PY
