#!/usr/bin/env bash
# Sceaux Castle (the OpenMVS sample: real photos and the mesh a full photogrammetry pipeline made
# from them, an input that is good already) refined with the default settings and the two views of
# its heldout.yaml left out, then measured in those views by `finecap eval`: the held-out NCC
# (7x7 windows, the 4 nearest training views warped in) and MAD of the input mesh as given, of its
# subdivision (where refinement starts) and of the refined mesh.
#
#   bash bench/sceaux_heldout.sh        # CAPTURE=DIR for a copy elsewhere; OUT=DIR keeps the runs
#   SET="model.subdivision_levels=2" bash bench/sceaux_heldout.sh     # extra settings (--set)
#   OPENMVS_BIN=DIR bash bench/sceaux_heldout.sh   # also OpenMVS RefineMesh on the same 8 views
#
# With OPENMVS_BIN (a folder holding InterfaceCOLMAP and RefineMesh, e.g. from
# ../shared/tools/build_openmvs.sh) OpenMVS refines the same mesh from the same training views, as
# ../shared/tools/README.md prescribes: a training copy of the capture without the held-out
# cameras (a temporary folder of symlinks: nothing is written into the capture) is converted by
# ../shared/tools/finecap_capture_to_colmap.py, InterfaceCOLMAP imports it, RefineMesh refines the
# mesh with its topology fixed, and its output is scored as given: as the input mesh of a capture
# with the held-out cameras, refined with no subdivision, no iteration and no sweep.
#
# Prints one "name: value" a line: per held-out view heldout_ncc_input/subdivided/refined and
# heldout_mad_input/subdivided/refined (input: the mesh as given), the same over both views,
# refine_worse (the frame's flag), heldout_score_seconds (the score's share of refine),
# refine_seconds and refine_peak_mb (wall time and peak resident
# memory of `finecap refine`, /usr/bin/time) and eval_seconds; then input_as_given_heldout_ncc
# and _mad, refined_as_given_heldout_ncc and _mad (the input and finecap's refined mesh, each
# scored as given in a run of its own, as every other mesh below is); with OPENMVS_BIN also
# openmvs_heldout_ncc, openmvs_heldout_mad (its mesh as given, the same views and score),
# openmvs_seconds (InterfaceCOLMAP and RefineMesh, wall time), openmvs_peak_mb, and
# openmvs_then_finecap_heldout_ncc, _mad and _seconds (finecap's defaults, with SET, refining
# RefineMesh's mesh: the two tools one after the other).
# A run scores its surfaces over the pixels all of them cover: finecap's refine run scores the
# input, its subdivision and the refined surface over the same pixels, and a mesh scored as given
# in a run of its own is scored over its own pixels, which differ a little (the refined mesh:
# heldout_ncc_refined 0.8424 in its run, 0.8391 as given).
set -euo pipefail
cd "$(dirname "$0")/.."
capture=${CAPTURE:-../shared/captures/openmvs_sceaux}
if [ ! -f "$capture/cameras.yaml" ] || [ ! -f "$capture/heldout.yaml" ]; then
  echo "SKIPPED: no Sceaux capture (cameras.yaml and heldout.yaml) at $capture" >&2
  exit 0
fi
capture=$(cd "$capture" && pwd)
tools=${TOOLS:-$(dirname "$capture")/../tools}
work=${OUT:-$(mktemp -d)}
[ -n "${OUT:-}" ] || trap 'rm -rf "$work"' EXIT
mkdir -p "$work"
work=$(cd "$work" && pwd)
rm -rf "$work/run" "$work/openmvs" "$work"/input* "$work"/scored*

[ -x build/finecap ] || bash scripts/build.sh >/dev/null

# capture_with_mesh MESH DIR: a capture at DIR of the cameras and images of $capture (symlinks;
# nothing is written into the capture) with MESH as its mesh.
capture_with_mesh() {
  mkdir -p "$2/meshes"
  ln -s "$capture/cameras.yaml" "$2/cameras.yaml"
  ln -s "$capture/images" "$2/images"
  cp "$1" "$2/meshes/000000.ply"
}

# seconds_since START: wall time from START (date +%s.%N) to now, one decimal.
seconds_since() {
  awk -v e="$(date +%s.%N)" -v s="$1" 'BEGIN { printf "%.1f", e - s }'
}

# score_as_given MESH DIR NAME: prints NAME_heldout_ncc and NAME_heldout_mad of MESH as given:
# the input of a capture at DIR (capture_with_mesh), refined with no subdivision, iteration or
# sweep; the refine run's own record holds the held-out score of its input.
score_as_given() {
  local mesh=$1 dir=$2 name=$3
  capture_with_mesh "$mesh" "$dir"
  build/finecap refine --config "$capture/heldout.yaml" --capture "$dir" --out "$dir.run" \
    --set model.subdivision_levels=0,solver.max_iterations=0,refine.sweep.samples=0 \
    >/dev/null 2>"$dir.refine.log"
  python3 - "$dir.run/stats.jsonl" "$name" <<'PY'
import json, sys
record = json.loads(open(sys.argv[1]).readline())
print(f"{sys.argv[2]}_heldout_ncc: {record['heldout_ncc_input']:.4f}")
print(f"{sys.argv[2]}_heldout_mad: {record['heldout_mad_input']:.4f}")
PY
}

# One --set each: of several, finecap keeps the last.
args=(--config "$capture/heldout.yaml" --capture "$capture" --out "$work/run")
/usr/bin/time -f "%e %M" -o "$work/refine.time" \
  build/finecap refine "${args[@]}" --set "${SET:-}" >/dev/null 2>"$work/refine.log"
start=$(date +%s.%N)
build/finecap eval "${args[@]}" --set "eval.flow=none${SET:+,$SET}" >/dev/null 2>"$work/eval.log"
eval_seconds=$(seconds_since "$start")

python3 bench/heldout_figures.py "$work/run"
read -r seconds kilobytes < "$work/refine.time"
echo "refine_seconds: $seconds"
echo "refine_peak_mb: $((kilobytes / 1024))"
echo "eval_seconds: $eval_seconds"
score_as_given "$capture/meshes/000000.ply" "$work/input" input_as_given
score_as_given "$work/run/meshes/000000.ply" "$work/scored" refined_as_given

if [ -z "${OPENMVS_BIN:-}" ]; then
  echo "openmvs: skipped (set OPENMVS_BIN to a folder with InterfaceCOLMAP and RefineMesh)" >&2
  exit 0
fi
for tool in InterfaceCOLMAP RefineMesh; do
  [ -x "$OPENMVS_BIN/$tool" ] || { echo "$OPENMVS_BIN/$tool: not found" >&2; exit 1; }
done
[ -f "$tools/finecap_capture_to_colmap.py" ] ||
  { echo "$tools/finecap_capture_to_colmap.py: not found (TOOLS=DIR)" >&2; exit 1; }

# The training capture: the cameras without the held-out ones; images and mesh are symlinks.
mvs="$work/openmvs"
mkdir -p "$mvs/train/images" "$mvs/train/meshes"
python3 - "$capture" "$mvs/train" <<'PY'
import os, re, sys
capture, train = sys.argv[1], sys.argv[2]
held_out = re.search(r"cameras:\s*\[([^\]]*)\]", open(os.path.join(capture, "heldout.yaml")).read())
held_out = {name.strip().strip("'\"") for name in held_out.group(1).split(",") if name.strip()}
# One block per camera: "  - name: ..." and the lines that follow it.
text = open(os.path.join(capture, "cameras.yaml")).read()
head, *blocks = re.split(r"(?m)^(?=\s*- name:)", text)
kept = [b for b in blocks if re.match(r"\s*- name:\s*(\S+)", b).group(1).strip("'\"") not in held_out]
if len(kept) != len(blocks) - len(held_out):
    sys.exit(f"{capture}/cameras.yaml: not every held-out camera of heldout.yaml was found")
open(os.path.join(train, "cameras.yaml"), "w").write(head + "".join(kept))
for block in kept:
    name = re.match(r"\s*- name:\s*(\S+)", block).group(1).strip("'\"")
    os.symlink(os.path.join(capture, "images", name), os.path.join(train, "images", name))
os.symlink(os.path.join(capture, "meshes", "000000.ply"),
           os.path.join(train, "meshes", "000000.ply"))
print(f"openmvs_training_views: {len(kept)}")
PY
python3 "$tools/finecap_capture_to_colmap.py" "$mvs/train" "$mvs/colmap" >"$mvs/colmap.log"
start=$(date +%s.%N)
(
  cd "$mvs"
  /usr/bin/time -f "%e %M" -o interface.time "$OPENMVS_BIN/InterfaceCOLMAP" -i colmap/ \
    -o scene.mvs --image-folder colmap/images/ >interface.log 2>&1
  /usr/bin/time -f "%e %M" -o refine.time "$OPENMVS_BIN/RefineMesh" -i scene.mvs \
    --mesh-file train/meshes/000000.ply -o refined.ply \
    --resolution-level 0 --min-resolution 640 --max-views 8 --scales 2 --scale-step 0.5 \
    --decimate 1 --max-face-area 0 --close-holes 0 --ensure-edge-size 0 \
    --planar-vertex-ratio 0 --max-threads 0 >refine.log 2>&1
)
openmvs_seconds=$(seconds_since "$start")
[ -f "$mvs/refined.ply" ] || { echo "RefineMesh wrote no $mvs/refined.ply ($mvs/refine.log)" >&2; exit 1; }

score_as_given "$mvs/refined.ply" "$mvs/scored" openmvs
echo "openmvs_seconds: $openmvs_seconds"
peak=$(cat "$mvs/interface.time" "$mvs/refine.time" | awk '$2 > m { m = $2 } END { print m }')
echo "openmvs_peak_mb: $((peak / 1024))"

# The two tools one after the other: finecap refining RefineMesh's mesh, from a capture whose
# mesh it is (the held-out cameras still held out).
after="$mvs/after"
capture_with_mesh "$mvs/refined.ply" "$after"
start=$(date +%s.%N)
build/finecap refine --config "$capture/heldout.yaml" --capture "$after" --out "$after.run" \
  --set "${SET:-}" >/dev/null 2>"$after.log"
after_seconds=$(seconds_since "$start")
score_as_given "$after.run/meshes/000000.ply" "$mvs/after_scored" openmvs_then_finecap
echo "openmvs_then_finecap_seconds: $after_seconds"
