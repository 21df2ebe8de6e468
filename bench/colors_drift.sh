#!/usr/bin/env bash
# Drift of the colours over a sequence: for every variant of a `finecap compare` folder (e.g. of
# configs/compare_colors.yaml), the refined error per frame against the ground truth, pooled, and
# how it moves with the frame index. Colours that drift make later frames worse than earlier ones.
#
#   finecap compare --config configs/compare_colors.yaml --capture data/synth_skirt --out OUT
#   bash bench/colors_drift.sh OUT
#
# Prints, per variant, one line:
#   <variant>: frames N pooled_recovered_percent P first_third_mm A last_third_mm B
#              slope_mm_per_10_frames S worst_frame_mm W
# (RMS of k - k_true in the textured region, from OUT/<variant>/stats.jsonl; pooled: the root mean
# square of the per-frame figures, P = 100 (1 - refined / input); the slope of a least-squares
# line through the per-frame refined RMS), then with PER_FRAME=1 a line per frame and variant.
set -euo pipefail
out=${1:?usage: bash bench/colors_drift.sh COMPARE_OUTPUT_FOLDER}
PER_FRAME=${PER_FRAME:-0} python3 - "$out" <<'PY'
import json, math, os, sys

out = sys.argv[1]
variants = sorted(d for d in os.listdir(out) if os.path.isfile(os.path.join(out, d, "stats.jsonl")))
if not variants:
    sys.exit(f"{out}: no variant folder with a stats.jsonl")
for name in variants:
    rows = [json.loads(line) for line in open(os.path.join(out, name, "stats.jsonl")) if line.strip()]
    rows = [r for r in rows if r.get("rms_refined_mm") is not None]
    if not rows:
        print(f"{name}: no frame with ground truth")
        continue
    n = len(rows)
    refined = [r["rms_refined_mm"] for r in rows]
    coarse = [r["rms_coarse_mm"] for r in rows]
    pooled = math.sqrt(sum(x * x for x in refined) / n)
    pooled_input = math.sqrt(sum(x * x for x in coarse) / n)
    third = max(1, n // 3)
    first, last = sum(refined[:third]) / third, sum(refined[-third:]) / third
    mean_t, mean_e = (n - 1) / 2, sum(refined) / n
    var_t = sum((t - mean_t) ** 2 for t in range(n))
    slope = sum((t - mean_t) * (e - mean_e) for t, e in enumerate(refined)) / var_t if var_t else 0.0
    print(f"{name}: frames {n} pooled_recovered_percent {100 * (1 - pooled / pooled_input):.1f} "
          f"first_third_mm {first:.2f} last_third_mm {last:.2f} "
          f"slope_mm_per_10_frames {10 * slope:+.3f} worst_frame_mm {max(refined):.2f}")
    if os.environ.get("PER_FRAME") == "1":
        for r in rows:
            print(f"  {name} frame {r['frame']}: input_rms_mm {r['rms_coarse_mm']:.2f} "
                  f"refined_rms_mm {r['rms_refined_mm']:.2f} worse {str(r['worse']).lower()}")
PY
