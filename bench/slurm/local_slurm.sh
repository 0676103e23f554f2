#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, in a folder of its own: slurmctld and slurmd on
# 127.0.0.1 with AuthType=auth/none (no munge), their configuration, state, logs and pids in DIR
# (slurmd's spool in /tmp/fm-slurmd.*). For trying bench/slurm/ before using a real cluster, and
# for the test that runs a sharded sweep through sbatch. auth/none trusts every local user: never on a shared machine.
#
#   bench/slurm/local_slurm.sh start DIR [CTLD_PORT SLURMD_PORT [OWNER_PID]]
#   export SLURM_CONF=DIR/slurm.conf     # then sbatch, squeue, sinfo talk to it
#   bench/slurm/local_slurm.sh stop DIR
#
# start returns once the node is idle (or fails within 90 s, printing the daemons' logs). With
# OWNER_PID, a watchdog stops the cluster when that process ends. stop cancels the jobs and ends the
# two daemons by their recorded process ids. Needs Debian's slurm-wlm (scripts/install-deps.sh).
set -euo pipefail
export PATH=$PATH:/usr/sbin:/sbin
usage="usage: local_slurm.sh start|stop DIR [CTLD_PORT SLURMD_PORT [OWNER_PID]]"
cmd=${1:?$usage}
dir=${2:?$usage}
node=fleetmap-node

log_tails() {
  for f in "$dir"/log/*; do
    [[ -f $f ]] || continue
    echo "---- $f (last lines)" >&2
    tail -n 15 "$f" >&2 || true
  done
}

alive() { [[ -f $1 ]] && kill -0 "$(cat "$1")" 2>/dev/null; }

stop_daemon() {  # pid file
  alive "$1" || return 0
  local pid
  pid=$(cat "$1")
  kill -TERM "$pid" 2>/dev/null || true
  for _ in $(seq 1 100); do
    kill -0 "$pid" 2>/dev/null || return 0
    sleep 0.1
  done
  kill -KILL "$pid" 2>/dev/null || true
}

stop_cluster() {
  if alive "$dir/slurmctld.pid"; then
    SLURM_CONF=$dir/slurm.conf timeout 10 scancel --partition=local >/dev/null 2>&1 || true
    for _ in $(seq 1 100); do  # running job steps end before slurmd goes
      [[ -z $(SLURM_CONF=$dir/slurm.conf timeout 5 squeue -h -o %i 2>/dev/null) ]] && break
      sleep 0.2
    done
  fi
  stop_daemon "$dir/slurmd.pid"
  stop_daemon "$dir/slurmctld.pid"
  if [[ -f $dir/watchdog.pid ]]; then
    local w
    w=$(cat "$dir/watchdog.pid")
    [[ $w != "${BASHPID:-$$}" ]] && kill -TERM "$w" 2>/dev/null || true
    rm -f "$dir/watchdog.pid"
  fi
  if [[ -f $dir/spool.path ]]; then
    local spool
    spool=$(cat "$dir/spool.path")
    [[ $spool == /tmp/fm-slurmd.* ]] && rm -rf "$spool"
    rm -f "$dir/spool.path"
  fi
}

case $cmd in
  start)
    for tool in slurmctld slurmd sbatch sinfo squeue scontrol scancel; do
      if ! command -v "$tool" >/dev/null; then
        echo "local_slurm.sh: '$tool' not found: install Debian's slurm-wlm (scripts/install-deps.sh does)" >&2
        exit 3
      fi
    done
    ctld_port=${3:-6817}
    slurmd_port=${4:-6818}
    owner=${5:-}
    mkdir -p "$dir"/state "$dir"/log
    dir=$(cd "$dir" && pwd)
    # slurmd's step sockets live in its spool folder and a Unix socket path holds at most 108
    # bytes, so the spool is a short folder of its own under /tmp (removed by stop).
    spool=$(mktemp -d /tmp/fm-slurmd.XXXXXX)
    echo "$spool" >"$dir/spool.path"
    user=$(id -un)
    host=$(uname -n)
    host=${host%%.*}
    cat >"$dir/slurm.conf" <<EOF
# Written by bench/slurm/local_slurm.sh: a one-node cluster on 127.0.0.1, without munge.
ClusterName=fleetmap-local
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/none
CredType=cred/none
SlurmUser=$user
SlurmdUser=$user
StateSaveLocation=$dir/state
SlurmdSpoolDir=$spool
SlurmctldPidFile=$dir/slurmctld.pidfile
SlurmdPidFile=$dir/slurmd.pidfile
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SchedulerParameters=kill_invalid_depend
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
MinJobAge=600
KillWait=5
InactiveLimit=0
NodeName=$node NodeHostname=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=local Nodes=$node Default=YES MaxTime=INFINITE State=UP
EOF
    export SLURM_CONF=$dir/slurm.conf
    slurmctld -D -c -i -f "$SLURM_CONF" </dev/null >"$dir/log/slurmctld.out" 2>&1 &
    echo $! >"$dir/slurmctld.pid"
    up=""
    for _ in $(seq 1 300); do
      if ! alive "$dir/slurmctld.pid"; then break; fi
      if timeout 5 scontrol ping 2>/dev/null | grep -q "UP"; then up=1 && break; fi
      sleep 0.1
    done
    if [[ -z $up ]]; then
      echo "local_slurm.sh: slurmctld did not come up on 127.0.0.1:$ctld_port within 30 s" >&2
      log_tails
      stop_cluster
      exit 1
    fi
    slurmd -D -N "$node" -f "$SLURM_CONF" </dev/null >"$dir/log/slurmd.out" 2>&1 &
    echo $! >"$dir/slurmd.pid"
    state=""
    for _ in $(seq 1 600); do
      if ! alive "$dir/slurmd.pid"; then break; fi
      state=$(timeout 5 sinfo -h -n "$node" -o %T 2>/dev/null || true)
      [[ $state == idle ]] && break
      if [[ $state == down* || $state == drain* ]]; then
        timeout 5 scontrol update NodeName="$node" State=RESUME >/dev/null 2>&1 || true
      fi
      sleep 0.1
    done
    if [[ $state != idle ]]; then
      echo "local_slurm.sh: node $node is '${state:-not registered}', not idle, 60 s after slurmd started" >&2
      log_tails
      stop_cluster
      exit 1
    fi
    if [[ -n $owner ]]; then
      (
        trap - TERM
        while kill -0 "$owner" 2>/dev/null; do sleep 1; done
        stop_cluster
      ) </dev/null >/dev/null 2>&1 &
      echo $! >"$dir/watchdog.pid"
    fi
    echo "export SLURM_CONF=$SLURM_CONF"
    ;;
  stop)
    [[ -d $dir ]] || exit 0
    dir=$(cd "$dir" && pwd)
    stop_cluster
    ;;
  *)
    echo "$usage" >&2
    exit 2
    ;;
esac
