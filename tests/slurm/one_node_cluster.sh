#!/usr/bin/env bash
# A one-node Slurm cluster on 127.0.0.1, without systemd, as root (Debian 12: slurm-wlm,
# munge; .ci/setup installs them). Everything lives in DIR (slurm.conf, state, spool, logs,
# pid files); /etc/slurm is left alone: point Slurm's commands at it with
# SLURM_CONF=DIR/slurm.conf.
#
#   bash tests/slurm/one_node_cluster.sh start DIR   # munged (unless one runs), slurmctld, slurmd
#   bash tests/slurm/one_node_cluster.sh stop DIR    # stops what `start` started, by PID
#
# Exit 77 when Slurm or munge is not installed or not root (tests skip on it). Only loopback
# traffic is sent (slurmctld still listens on 0.0.0.0:6817). Not inside `unshare -n`: the
# daemons cannot resolve the host name there and retry for minutes.
set -euo pipefail

usage() { echo "usage: $0 start|stop DIR" >&2; exit 2; }
[ $# -eq 2 ] || usage
action=$1
dir=$(realpath -m "$2")

# Kills PID (when alive) and waits up to 15 s for it to go.
stop_pid() {
  local pid=$1 name=$2
  [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null || return 0
  kill "$pid" 2>/dev/null || true
  for _ in $(seq 150); do
    kill -0 "$pid" 2>/dev/null || { echo "one_node_cluster: stopped $name ($pid)"; return 0; }
    sleep 0.1
  done
  echo "one_node_cluster: $name ($pid) still running after 15 s" >&2
}

case $action in
start)
  for p in munged munge unmunge slurmctld slurmd sbatch sinfo; do
    if ! command -v "$p" >/dev/null && [ ! -x "/usr/sbin/$p" ]; then
      echo "one_node_cluster: $p not installed (apt-get install slurm-wlm munge, or .ci/setup)" >&2
      exit 77
    fi
  done
  [ "$(id -u)" -eq 0 ] || { echo "one_node_cluster: needs root (slurmd runs jobs as any user)" >&2; exit 77; }
  mkdir -p "$dir/state" "$dir/spool" "$dir/log"
  host=$(hostname)
  node=$(/usr/sbin/slurmd -C | head -n 1)  # NodeName=HOST CPUs=... RealMemory=...
  cat > "$dir/slurm.conf" <<CONF
ClusterName=onenode
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CommunicationParameters=NoInAddrAny
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
ReturnToService=2
$node NodeAddr=127.0.0.1
PartitionName=debug Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  # munged: one already answering is used (and left running at stop); else started here.
  if ! munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
    mkdir -p /run/munge && chown munge:munge /run/munge && chmod 755 /run/munge
    runuser -u munge -- /usr/sbin/munged
    for _ in $(seq 50); do munge -n 2>/dev/null | unmunge >/dev/null 2>&1 && break; sleep 0.1; done
    cat /run/munge/munged.pid > "$dir/munged.started"
  fi
  export SLURM_CONF=$dir/slurm.conf
  /usr/sbin/slurmctld -c
  /usr/sbin/slurmd
  for _ in $(seq 300); do
    state=$(sinfo -h -o %t 2>/dev/null || true)
    [ "$state" = "idle" ] && { echo "one_node_cluster: up ($host, SLURM_CONF=$dir/slurm.conf)"; exit 0; }
    sleep 0.2
  done
  echo "one_node_cluster: the node is not idle after 60 s (state '${state:-}'; logs in $dir/log)" >&2
  exit 1
  ;;
stop)
  stop_pid "$(cat "$dir/slurmd.pid" 2>/dev/null || true)" slurmd
  stop_pid "$(cat "$dir/slurmctld.pid" 2>/dev/null || true)" slurmctld
  if [ -f "$dir/munged.started" ]; then
    stop_pid "$(cat "$dir/munged.started")" munged
    rm -f "$dir/munged.started"
  fi
  ;;
*) usage ;;
esac
