#!/usr/bin/env python3
"""Prints the held-out figures of an evaluated run, one "name: value" a line.

  python3 bench/heldout_figures.py RUN_FOLDER [FRAME]

From RUN_FOLDER/eval/metrics.json and the frame's record RUN_FOLDER/frames/FRAME.json (default
000000): per held-out view <camera>_heldout_{ncc,mad}_{input,subdivided,refined} (input: the mesh
as given; subdivided: its subdivision, where refinement starts), the same pooled over the views
(heldout_...), refine_worse (the frame's flag) and heldout_score_seconds (the score's share of
`finecap refine`).
"""
import json
import os
import sys

KEYS = [f"{figure}_{surface}" for figure in ("ncc", "mad")
        for surface in ("input", "subdivided", "refined")]


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    run = sys.argv[1]
    frame = sys.argv[2] if len(sys.argv) == 3 else "000000"
    metrics = json.load(open(os.path.join(run, "eval", "metrics.json")))
    record = json.load(open(os.path.join(run, "frames", frame + ".json")))
    frames = [f for f in metrics["frames"] if f["frame"] == frame]
    if not frames or frames[0]["heldout"] is None:
        sys.exit(f"{run}: frame {frame} has no held-out figures")
    for view in frames[0]["heldout"]["views"]:
        for key in KEYS:
            print(f"{view['camera']}_heldout_{key}: {view[key]:.4f}")
    for key in KEYS:
        print(f"heldout_{key}: {metrics['heldout_' + key]:.4f}")
    print(f"refine_worse: {str(record['worse']).lower()}")
    print(f"heldout_score_seconds: {record['seconds_heldout']:.2f}")


if __name__ == "__main__":
    main()
