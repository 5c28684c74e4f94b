#!/usr/bin/env bash
# A private single-node Slurm cluster on this machine, for the tests and for
# trying `blendtool batch --slurm` (docs/batch.md):
#   slurm-cluster.sh start DIR   munged, slurmctld and slurmd with DIR/slurm.conf
#   slurm-cluster.sh stop DIR    stop them (by their pid files)
#   slurm-cluster.sh env DIR     print the SLURM_CONF line to eval
# Nothing in /etc/slurm changes: every command needs SLURM_CONF=DIR/slurm.conf.
# Start is idempotent: a running cluster with the same DIR is reused. Its two
# ports (slurmctld, slurmd) are free ports picked at the first start and
# recorded in DIR/ports, so clusters in different folders (the test suite's
# and a user's) run side by side. The packages (slurm-wlm, munge) come from
# scripts/install-deps.sh.
set -euo pipefail
cmd=${1:-}
dir=${2:-}
if [ -z "$cmd" ] || [ -z "$dir" ]; then
  echo "usage: slurm-cluster.sh start|stop|env DIR" >&2
  exit 2
fi
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
conf="$dir/slurm.conf"
export SLURM_CONF="$conf"

alive() { [ -f "$1" ] && kill -0 "$(cat "$1")" 2>/dev/null; }
node_up() { timeout 3 sinfo -h -o %T 2>/dev/null | grep -qE 'idle|mixed|alloc'; }
stop_slurm() {
  for p in slurmd slurmctld; do
    if alive "$dir/$p.pid"; then kill "$(cat "$dir/$p.pid")" || true; fi
  done
  for _ in $(seq 50); do
    alive "$dir/slurmd.pid" || alive "$dir/slurmctld.pid" || break
    sleep 0.1
  done
}

case "$cmd" in
env)
  echo "export SLURM_CONF=$conf"
  ;;
stop)
  stop_slurm
  if alive "$dir/munged.pid"; then kill "$(cat "$dir/munged.pid")" || true; fi
  ;;
start)
  for t in slurmctld slurmd munged sbatch; do
    command -v "$t" >/dev/null || PATH="$PATH:/usr/sbin"
    command -v "$t" >/dev/null || { echo "slurm-cluster: $t missing: run scripts/install-deps.sh" >&2; exit 1; }
  done
  host=$(hostname -s)
  cpus=$(nproc)
  mem=$(awk '/MemTotal/ {print int($2 / 1024 * 0.8)}' /proc/meminfo)
  mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
  # the ports: the recorded ones while this cluster runs (or they are still
  # free), else two free ones that the kernel hands out, recorded
  ports=""
  if [ -f "$dir/ports" ]; then
    ports=$(cat "$dir/ports")
    if ! { alive "$dir/slurmctld.pid" && alive "$dir/slurmd.pid"; } &&
       ! python3 -c 'import socket, sys
for p in sys.argv[1:]:
    s = socket.socket(); s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1); s.bind(("", int(p))); s.close()' $ports 2>/dev/null; then
      ports=""
    fi
  fi
  if ! [[ "$ports" =~ ^[0-9]+\ [0-9]+$ ]]; then
    ports=$(python3 -c 'import socket
a, b = socket.socket(), socket.socket()
a.bind(("", 0)); b.bind(("", 0))
print(a.getsockname()[1], b.getsockname()[1])')
    echo "$ports" > "$dir/ports"
  fi
  ctld_port=${ports% *}
  d_port=${ports#* }
  cat > "$conf.new" <<EOF
ClusterName=libblend
SlurmctldHost=$host
SlurmUser=root
AuthType=auth/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SchedulerParameters=bf_interval=1,sched_min_interval=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
  if alive "$dir/slurmctld.pid" && alive "$dir/slurmd.pid" && cmp -s "$conf" "$conf.new" && node_up; then
    rm -f "$conf.new"
    echo "slurm-cluster: running ($conf)"
    exit 0
  fi
  mv "$conf.new" "$conf"
  # munge: the package made /etc/munge/munge.key; the daemon runs as munge
  if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    mkdir -p /run/munge
    chown munge: /run/munge
    runuser -u munge -- /usr/sbin/munged --pid-file=/run/munge/munged.pid
    cp /run/munge/munged.pid "$dir/munged.pid" 2>/dev/null || true
    for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
  fi
  munge -n | unmunge >/dev/null || { echo "slurm-cluster: munge does not work" >&2; exit 1; }
  stop_slurm
  slurmctld -i
  slurmd
  for _ in $(seq 100); do
    if node_up; then
      echo "slurm-cluster: up ($conf)"
      exit 0
    fi
    sleep 0.2
  done
  echo "slurm-cluster: the node did not come up; see $dir/slurmctld.log and $dir/slurmd.log" >&2
  exit 1
  ;;
*)
  echo "usage: slurm-cluster.sh start|stop|env DIR" >&2
  exit 2
  ;;
esac
