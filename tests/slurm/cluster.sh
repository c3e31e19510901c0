#!/usr/bin/env bash
# A one-node Slurm cluster for the sweep tests: Debian's slurmctld, slurmd and munge, started in the foreground
# of background processes (no systemd in CI containers), with every file in one state folder.
#   cluster.sh start DIR   writes DIR/slurm.conf, starts munged, slurmctld and slurmd, waits for an idle node
#   cluster.sh stop DIR    stops exactly the daemons start recorded in DIR/*.pid
# Clients find the cluster through SLURM_CONF=DIR/slurm.conf. Needs root (slurmd runs jobs as their user).
set -euo pipefail

usage() { echo "usage: $0 start|stop STATE_DIR" >&2; exit 2; }
[ $# -eq 2 ] || usage
action=$1
state=$(realpath -m "$2")

start() {
  for tool in munged slurmctld slurmd sinfo; do
    command -v "$tool" >/dev/null || { echo "error: $tool is not installed (apt-get install slurmctld slurmd slurm-client munge)" >&2; exit 1; }
  done
  [ "$(id -u)" = 0 ] || { echo "error: the test cluster needs root (slurmd)" >&2; exit 1; }
  mkdir -p "$state"/{ctld,spool,munge}
  chmod 755 "$state"
  # munged refuses a socket folder that others may write or cannot enter, and a key it does not own.
  chown munge:munge "$state/munge"
  chmod 755 "$state/munge"
  if [ ! -s /etc/munge/munge.key ]; then
    dd if=/dev/urandom of=/etc/munge/munge.key bs=1 count=128 status=none
    chown munge:munge /etc/munge/munge.key
    chmod 400 /etc/munge/munge.key
  fi
  local socket="$state/munge/munge.socket"
  local cpus memory_mib
  cpus=$(nproc)
  memory_mib=$(( $(awk '/MemTotal/ {print $2}' /proc/meminfo) / 1024 / 2 ))
  cat >"$state/slurm.conf" <<CONF
ClusterName=mbrltest
SlurmctldHost=localhost(127.0.0.1)
SlurmUser=root
AuthType=auth/munge
AuthInfo=socket=$socket,cred_expire=10
CredType=cred/munge
StateSaveLocation=$state/ctld
SlurmdSpoolDir=$state/spool
SlurmctldPidFile=$state/slurmctld.pid
SlurmdPidFile=$state/slurmd.pid
SlurmctldLogFile=$state/slurmctld.log
SlurmdLogFile=$state/slurmd.log
SlurmctldPort=${MBRL_SLURMCTLD_PORT:-6817}
SlurmdPort=${MBRL_SLURMD_PORT:-6818}
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
MpiDefault=none
ReturnToService=2
JobRequeue=1
MinJobAge=600
NodeName=localnode NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory_mib State=UNKNOWN
PartitionName=test Nodes=localnode Default=YES MaxTime=INFINITE State=UP
CONF
  runuser -u munge -- munged -F --socket="$socket" --pid-file="$state/munge/munged.pid" \
    --log-file="$state/munge/munged.log" --seed-file="$state/munge/munged.seed" >>"$state/munged.out" 2>&1 &
  echo $! >"$state/munged.launcher.pid"
  wait_for "munged socket" test -S "$socket"
  slurmctld -D -i -f "$state/slurm.conf" >>"$state/slurmctld.out" 2>&1 &
  echo $! >"$state/slurmctld.launcher.pid"
  slurmd -D -N localnode -f "$state/slurm.conf" >>"$state/slurmd.out" 2>&1 &
  echo $! >"$state/slurmd.launcher.pid"
  wait_for "an idle Slurm node" node_idle
  echo "Slurm is up: export SLURM_CONF=$state/slurm.conf"
}

node_idle() { SLURM_CONF="$state/slurm.conf" sinfo -h -N -o %t 2>/dev/null | grep -qx idle; }

wait_for() {
  local what=$1; shift
  for _ in $(seq 1 100); do
    "$@" && return 0
    sleep 0.2
  done
  echo "error: no $what after 20 s; logs in $state" >&2
  stop
  exit 1
}

stop() {
  local name pid
  for name in slurmd slurmctld munged; do
    for file in "$state/$name.launcher.pid"; do
      [ -s "$file" ] || continue
      pid=$(cat "$file")
      if kill -0 "$pid" 2>/dev/null; then
        kill "$pid" 2>/dev/null || true
        for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -9 "$pid" 2>/dev/null || true
      fi
      rm -f "$file"
    done
  done
  # runuser passes the signal on to munged; should munged outlive it, its own pid file names it.
  if [ -s "$state/munge/munged.pid" ]; then
    pid=$(cat "$state/munge/munged.pid")
    if kill -0 "$pid" 2>/dev/null && [ "$(cat /proc/"$pid"/comm 2>/dev/null)" = munged ]; then
      kill "$pid" 2>/dev/null || true
    fi
  fi
}

case $action in
  start) start ;;
  stop) stop ;;
  *) usage ;;
esac
