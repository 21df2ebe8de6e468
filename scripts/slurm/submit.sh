#!/usr/bin/env bash
# Submits a `finecap refine` run to Slurm as N array tasks (one shard each) and a check that runs
# after all of them succeeded (--dependency=afterok) and fails when any frame is missing.
#
#   scripts/slurm/submit.sh N [finecap refine flags...]
#   scripts/slurm/submit.sh 8 --config configs/demo.yaml --capture data/demo --out out/demo
#
# Environment: FINECAP, the binary (default build/finecap of this checkout); LOG_DIR, where the
# jobs' logs go (default: the current folder); SBATCH_ARGS, extra sbatch options for both jobs
# (e.g. "--partition=gpu --time=02:00:00"). Prints "array_job: ID" and "check_job: ID".
# Rerunning it after a failure resumes: every shard skips the frames already done.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
if [ $# -lt 1 ] || ! [[ $1 =~ ^[1-9][0-9]*$ ]]; then
  echo "usage: $0 N [finecap refine flags...]   (N >= 1 shards)" >&2
  exit 2
fi
shards=$1
shift
finecap=$(realpath "${FINECAP:-$here/../../build/finecap}")
[ -x "$finecap" ] || { echo "$0: no finecap binary at $finecap (build it or set FINECAP)" >&2; exit 1; }
log_dir=$(realpath "${LOG_DIR:-.}")
read -r -a extra <<< "${SBATCH_ARGS:-}"

array_job=$(sbatch --parsable "${extra[@]}" --export="ALL,FINECAP=$finecap" \
  --array="0-$((shards - 1))" --output="$log_dir/finecap-refine-%A_%a.log" \
  "$here/finecap-array.sbatch" "$shards" "$@")
array_job=${array_job%%;*}
check_job=$(sbatch --parsable "${extra[@]}" --export="ALL,FINECAP=$finecap" \
  --dependency="afterok:$array_job" --kill-on-invalid-dep=yes \
  --output="$log_dir/finecap-check-%j.log" "$here/finecap-check.sbatch" "$@")
echo "array_job: $array_job"
echo "check_job: ${check_job%%;*}"
