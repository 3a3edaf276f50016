#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# A single-node Slurm cluster on this host, everything in a state folder this script owns:
#   scripts/slurm_local.sh start [DIR]   munge key and daemon, slurm.conf for this host's name,
#                                        CPUs and memory, slurmctld and slurmd; waits until the
#                                        node takes jobs and prints `export SLURM_CONF=DIR/slurm.conf`
#   scripts/slurm_local.sh stop [DIR]    stops the daemons it started (by their pid files) and
#                                        removes DIR
#   scripts/slurm_local.sh status [DIR]  exit 0 when the cluster in DIR takes jobs
# DIR defaults to $MSF_SLURM_DIR or /tmp/msf_slurm. Ports: $MSF_SLURM_PORT (slurmctld) and the
# next one (slurmd), 6817 by default. Needs root (slurmd runs jobs as their user) and Debian's
# slurm-wlm and munge (make deps). Client commands find the cluster through SLURM_CONF.
set -euo pipefail

command=${1:-}
dir=${2:-${MSF_SLURM_DIR:-/tmp/msf_slurm}}
port=${MSF_SLURM_PORT:-6817}
die() { echo "slurm_local.sh: error: $*" >&2; exit 1; }

# The script only ever removes a folder it made: it carries this marker.
marker="$dir/.msf_slurm_local"

# Alive and not a zombie (where nothing reaps the detached daemons, a stopped one stays a zombie).
running() { kill -0 "$1" 2>/dev/null && ! grep -qE '^[0-9]+ \(.*\) Z' "/proc/$1/stat" 2>/dev/null; }

stop_daemon() { # pid file
  local pid_file=$1 pid
  [ -f "$pid_file" ] || return 0
  pid=$(cat "$pid_file" 2>/dev/null || true)
  [ -n "$pid" ] && running "$pid" || return 0
  kill "$pid" 2>/dev/null || true
  for _ in $(seq 50); do running "$pid" || return 0; sleep 0.1; done
  kill -9 "$pid" 2>/dev/null || true
}

# Jobs still queued or running are cancelled first: slurmd stopped under a running job would
# leave its processes (slurmstepd and the job's own) behind.
cancel_jobs() {
  local conf=$dir/slurm.conf
  [ -f "$conf" ] && [ -f "$dir/slurmctld.pid" ] && kill -0 "$(cat "$dir/slurmctld.pid")" 2>/dev/null || return 0
  SLURM_CONF=$conf timeout 10 scancel --full --quiet --partition=local >/dev/null 2>&1 || true
  for _ in $(seq 100); do
    [ -z "$(SLURM_CONF=$conf timeout 10 squeue -h -o %A 2>/dev/null)" ] && return 0
    sleep 0.2
  done
  echo "slurm_local.sh: jobs still queued after 20 s; stopping the daemons anyway" >&2
}

failed_start() {
  local log
  for log in "$dir"/*.log; do
    [ -f "$log" ] && { echo "--- $log (last lines)" >&2; tail -n 20 "$log" >&2; }
  done
  stop
}

stop() {
  [ -e "$dir" ] || return 0
  [ -f "$marker" ] || die "'$dir' was not made by slurm_local.sh (no $marker): not touching it"
  cancel_jobs
  stop_daemon "$dir/slurmd.pid"
  stop_daemon "$dir/slurmctld.pid"
  stop_daemon "$dir/munged.pid"
  rm -rf "$dir"
}

node_ready() {
  SLURM_CONF="$dir/slurm.conf" timeout 10 sinfo -h -N -o '%t' 2>/dev/null | grep -Eq '^(idle|mix|alloc)'
}

write_conf() {
  local host cpus mem_mb
  host=$(hostname -s)
  cpus=$(nproc)
  # What jobs may ask for: the host's memory less 512 MiB for the system and the daemons.
  mem_mb=$(( $(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo) - 512 ))
  cat > "$dir/slurm.conf" <<EOF
# Written by scripts/slurm_local.sh: a single-node cluster on $host.
ClusterName=msflocal
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$port
SlurmdPort=$((port + 1))
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
# cred_expire: how long a requeued job waits before it starts again (120 s by default).
AuthInfo=socket=$dir/munge/munge.socket,cred_expire=10
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
MpiDefault=none
SwitchType=switch/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
# Finished jobs stay visible to scontrol for 10 minutes (tests read their restart counts).
MinJobAge=600
DefMemPerCPU=1024
SchedulerParameters=bf_interval=1,sched_interval=1
InactiveLimit=0
KillWait=5
Waittime=0
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP OverSubscribe=NO
EOF
}

start() {
  [ "$(id -u)" -eq 0 ] || die "needs root: slurmd runs each job as its user"
  for tool in munged slurmctld slurmd sinfo sbatch; do
    command -v "$tool" >/dev/null || die "'$tool' not found: install Debian's slurm-wlm and munge (make deps)"
  done
  if [ -e "$dir" ]; then
    if [ -f "$marker" ] && node_ready; then
      echo "export SLURM_CONF=$dir/slurm.conf"
      return 0
    fi
    stop
  fi
  mkdir -p "$dir"
  touch "$marker"
  # A start that fails shows the daemons' logs, stops what it started and removes its folder.
  trap 'failed_start' EXIT
  chmod 755 "$dir"
  mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
  chmod 700 "$dir/munge"
  dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
  chmod 400 "$dir/munge/munge.key"
  # Daemons say nothing on stdout, which callers read with eval.
  munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket" \
         --pid-file="$dir/munged.pid" --log-file="$dir/munged.log" --seed-file="$dir/munge/munged.seed" >&2 \
    || die "munged did not start (the daemons' logs follow)"
  write_conf
  export SLURM_CONF="$dir/slurm.conf"
  # -i: a fresh state (no jobs of an earlier cluster).
  slurmctld -i -f "$SLURM_CONF" >&2 || die "slurmctld did not start (the daemons' logs follow)"
  slurmd -f "$SLURM_CONF" >&2 || die "slurmd did not start (the daemons' logs follow)"
  for _ in $(seq 60); do
    if node_ready; then
      trap - EXIT
      echo "export SLURM_CONF=$SLURM_CONF"
      return 0
    fi
    sleep 0.5
  done
  die "the node did not come up in 30 s (the daemons' logs follow)"
}

case "$command" in
  start) start ;;
  stop) stop ;;
  status) node_ready ;;
  *) die "usage: slurm_local.sh start|stop|status [DIR]" ;;
esac
