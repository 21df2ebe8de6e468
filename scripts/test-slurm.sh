#!/usr/bin/env bash
# Integration test of the Slurm scripts on this machine: installs Slurm and MUNGE (Debian 12:
# slurm-wlm, munge), starts a one-node cluster on localhost (munged, slurmctld, slurmd; 2 CPUs,
# every file under a temporary folder, ports 16817/16818), submits a tiny synthetic capture as
# 4 array tasks plus the dependent check (scripts/slurm/submit.sh), waits at most 5 minutes, and
# checks that the displacements equal those of one `finecap refine` over the whole capture.
#
#   bash scripts/test-slurm.sh
#
# Needs root (or sudo) for the packages and the daemons. When Slurm cannot be installed or
# started it prints "SKIPPED: <reason>" and exits 0; a wrong result exits 1. The daemons it
# started are stopped on exit.
set -euo pipefail
cd "$(dirname "$0")/.."
repo=$(pwd)

skip() { echo "SKIPPED: $*"; exit 0; }
# A command prefix that runs as root. Not a function: a command started in the background through
# it must have the daemon's own pid in $!, to be stopped by it.
as_root=()
[ "$(id -u)" = 0 ] || as_root=(sudo -n)

if [ "$(id -u)" != 0 ] && ! sudo -n true 2>/dev/null; then skip "needs root or sudo"; fi
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null ||
  ! command -v munged >/dev/null || ! command -v sbatch >/dev/null; then
  "${as_root[@]}" apt-get update >/dev/null 2>&1 || skip "apt-get update failed"
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends \
    slurm-wlm munge >/dev/null 2>&1 || skip "cannot install slurm-wlm and munge"
fi
[ -x build/finecap ] || bash scripts/build.sh >/dev/null

work=$(mktemp -d /tmp/finecap-slurm.XXXXXX)
chmod 755 "$work"
pids=()
jobs=""
cleanup() {
  # Jobs still queued or running when the wait ran out, then the daemons.
  for job in $(echo "$jobs" | sed -n 's/^[a-z_]*: //p'); do timeout 5 scancel "$job" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do "${as_root[@]}" kill "$pid" 2>/dev/null || true; done
  for pid in "${pids[@]}"; do
    for _ in $(seq 50); do "${as_root[@]}" kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  done
  "${as_root[@]}" rm -rf "$work"
}
trap cleanup EXIT

# MUNGE, with its own key and socket.
mkdir -p "$work/munge"
chmod 700 "$work/munge"
head -c 1024 /dev/urandom > "$work/munge/munge.key"
chmod 400 "$work/munge/munge.key"
"${as_root[@]}" munged --force --key-file="$work/munge/munge.key" --socket="$work/munge/munge.sock" \
  --pid-file="$work/munge/munged.pid" --log-file="$work/munge/munged.log" \
  --seed-file="$work/munge/munged.seed" || skip "munged does not start: $(cat "$work/munge/munged.log" 2>/dev/null)"
for _ in $(seq 50); do [ -s "$work/munge/munged.pid" ] && break; sleep 0.1; done
pids+=("$(cat "$work/munge/munged.pid")")

# A one-node cluster on this host.
node=$(hostname -s)
mkdir -p "$work/state" "$work/spool" "$work/logs"
export SLURM_CONF=$work/slurm.conf
cat > "$SLURM_CONF" <<CONF
ClusterName=finecap-test
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=16817
SlurmdPort=16818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$work/munge/munge.sock
StateSaveLocation=$work/state
SlurmdSpoolDir=$work/spool
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
MpiDefault=none
ReturnToService=2
MinJobAge=600
NodeName=$node NodeAddr=127.0.0.1 CPUs=2 State=UNKNOWN
PartitionName=test Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
"${as_root[@]}" slurmctld -D -i -f "$SLURM_CONF" > "$work/slurmctld.out" 2>&1 &
pids+=($!)
"${as_root[@]}" slurmd -D -N "$node" -f "$SLURM_CONF" > "$work/slurmd.out" 2>&1 &
pids+=($!)
ready=no
for _ in $(seq 60); do
  if timeout 5 sinfo -h -N -o %t 2>/dev/null | grep -qx idle; then ready=yes; break; fi
  # A daemon that exited will not come back: no point in waiting.
  for pid in "${pids[@]}"; do "${as_root[@]}" kill -0 "$pid" 2>/dev/null || break 2; done
  sleep 1
done
if [ "$ready" != yes ]; then
  tail -n 5 "$work/slurmctld.log" "$work/slurmd.log" "$work/slurmctld.out" "$work/slurmd.out" 2>/dev/null || true
  skip "the node did not become idle within 60 s (logs above)"
fi

# A tiny capture, refined once in one process and once as 4 array tasks.
build/finecap synth --config configs/synth_demo.yaml --out "$work/capture" --set \
  synth.num_frames=6,synth.cameras.width=128,synth.cameras.height=128,synth.cameras.focal=150,synth.skirt.around=24,synth.skirt.down=16,synth.render.supersampling=1 \
  >/dev/null
flags=(--config "$repo/configs/demo.yaml" --capture "$work/capture" --threads 1)
build/finecap refine "${flags[@]}" --out "$work/single" >/dev/null 2>&1
start=$(date +%s)
jobs=$(cd "$work/logs" && FINECAP="$repo/build/finecap" bash "$repo/scripts/slurm/submit.sh" 4 \
  "${flags[@]}" --out "$work/sharded")
check_job=$(echo "$jobs" | sed -n 's/^check_job: //p')
state=PENDING
while [ $(($(date +%s) - start)) -lt 300 ]; do
  state=$(scontrol show job "$check_job" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | cut -d= -f2)
  case "$state" in PENDING | RUNNING | CONFIGURING | COMPLETING | "") sleep 1 ;; *) break ;; esac
done
echo "slurm_seconds: $(($(date +%s) - start))"
if [ "$state" != COMPLETED ]; then
  echo "FAILED: the check job ended $state" >&2
  tail -n 20 "$work"/logs/* >&2 || true
  exit 1
fi
cat "$work"/logs/finecap-check-*.log
if ! diff -r "$work/single/k" "$work/sharded/k" >/dev/null; then
  echo "FAILED: the 4 shards' displacements differ from one process's" >&2
  exit 1
fi
[ "$(wc -l < "$work/sharded/stats.jsonl")" = 6 ] || { echo "FAILED: stats.jsonl lacks frames" >&2; exit 1; }
echo "PASSED: 4 Slurm array tasks and the dependent check equal one process (6 frames)"
