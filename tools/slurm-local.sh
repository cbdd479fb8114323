#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, everything under one directory: for trying
# `wingman montecarlo --engine slurm` and for its test (tests/app/batch/test_montecarlo_slurm.cpp).
#   tools/slurm-local.sh start DIR   munged, slurmctld and slurmd, run as root, with their keys,
#                                    config, state, logs and pid files in DIR; waits until the node
#                                    is idle and writes the clients' environment into DIR/env
#                                    (`. DIR/env`, then sbatch, squeue, sinfo talk to this cluster).
#   tools/slurm-local.sh stop DIR    cancels its jobs and stops the daemons it started (by their pid
#                                    files); does nothing when none runs.
# Needs root and Debian's slurm-wlm and munge packages; no systemd, cgroups or slurmdbd. Ports are
# derived from DIR and probed, so clusters in two directories do not collide.
# Exit 0 on success, 1 when the cluster did not come up (the daemons' logs are shown), 2 for bad use.
set -euo pipefail
PATH=$PATH:/usr/sbin:/sbin  # the daemons live in sbin, which a plain user's PATH may lack

usage() { echo "usage: tools/slurm-local.sh start|stop DIR" >&2; exit 2; }
[ $# -eq 2 ] || usage
mode=$1
[ -n "$2" ] || usage
case "$mode" in
  start) mkdir -p "$2" ;;
  stop) [ -d "$2" ] || exit 0 ;;
  *) usage ;;
esac
dir=$(cd "$2" && pwd)
conf=$dir/slurm.conf
pidfiles=("$dir/run/slurmd.pid" "$dir/run/slurmctld.pid" "$dir/munge/munged.pid")
start_timeout=${SLURM_LOCAL_TIMEOUT:-60}

# The pid in a pid file when that process runs and is the named daemon; nothing otherwise.
live_pid() {
  local file=$1 name=$2 pid
  [ -s "$file" ] || return 1
  pid=$(tr -dc 0-9 <"$file")
  [ -n "$pid" ] && [ -r "/proc/$pid/comm" ] && [ "$(cat "/proc/$pid/comm")" = "$name" ] || return 1
  echo "$pid"
}

# TERM to every daemon at once (each takes a second or two to exit), KILL to any still there 10 s on.
stop_daemons() {
  local pids=() name pid
  for f in "${pidfiles[@]}"; do
    name=$(basename "$f" .pid)
    pid=$(live_pid "$f" "$name") && kill -TERM "$pid" 2>/dev/null && pids+=("$pid")
  done
  for pid in "${pids[@]}"; do
    for _ in $(seq 100); do
      [ -d "/proc/$pid" ] || break
      sleep 0.1
    done
    [ -d "/proc/$pid" ] && kill -KILL "$pid" 2>/dev/null || true
  done
  rm -f "${pidfiles[@]}"
}

stop_cluster() {
  # Jobs first: a job's slurmstepd outlives slurmd, so it is cancelled while slurmctld still runs.
  if live_pid "$dir/run/slurmctld.pid" slurmctld >/dev/null && [ -f "$conf" ]; then
    SLURM_CONF=$conf scancel --full --quiet --user=root 2>/dev/null || true
    for _ in $(seq 100); do
      [ -z "$(SLURM_CONF=$conf squeue -h -o %i 2>/dev/null)" ] && break
      sleep 0.1
    done
  fi
  stop_daemons
}

# A TCP port nothing listens on, from $1 upwards.
free_port() {
  local p=$1
  while (exec 3<>"/dev/tcp/127.0.0.1/$p") 2>/dev/null; do p=$((p + 1)); done
  echo "$p"
}

write_conf() {
  local host=$1 ctld_port=$2 slurmd_port=$3 cpus mem_mib
  cpus=$(nproc)
  mem_mib=$(awk '/^MemTotal:/ { printf "%d", $2 / 1024 * 0.9 }' /proc/meminfo)
  cat >"$conf" <<EOF
# Written by tools/slurm-local.sh: a one-node cluster, daemons run as root, no accounting.
ClusterName=wingmanlocal
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
AuthInfo=socket=$dir/munge/munge.socket.2
CredType=cred/munge
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/run/slurmctld.pid
SlurmdPidFile=$dir/run/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true  # none installed; slurmctld logs an error at every start without one
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
ReturnToService=2
# The node as configured here, whatever hwloc finds (a container may show more than nproc).
SlurmdParameters=config_overrides
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$mem_mib State=UNKNOWN
PartitionName=local Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
}

start_munged() {
  # munged wants its key private and every directory above its socket searchable by all; --force
  # lets it run under a private one (mkdtemp's 0700): only root, which passes anyway, uses it here.
  # --force would also take the socket over from a live munged: refuse that one instead.
  if munge -n -S "$dir/munge/munge.socket.2" >/dev/null 2>&1; then
    echo "slurm-local: a munged this script did not start serves $dir/munge/munge.socket.2; stop it first" >&2
    exit 2
  fi
  mkdir -p "$dir/munge"
  chmod 0755 "$dir/munge"
  if [ ! -s "$dir/munge/munge.key" ]; then
    (umask 077 && head -c 1024 /dev/urandom >"$dir/munge/munge.key")
  fi
  chmod 0400 "$dir/munge/munge.key"
  munged --force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.socket.2" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
    --seed-file="$dir/munge/munged.seed"
}

fail_start() {
  echo "slurm-local: $1; the daemons' logs:" >&2
  for log in "$dir/munge/munged.log" "$dir/log/slurmctld.log" "$dir/log/slurmd.log"; do
    [ -f "$log" ] && { echo "== $log" >&2; tail -n 20 "$log" >&2; }
  done
  stop_cluster
  exit 1
}

start_cluster() {
  [ "$(id -u)" -eq 0 ] || { echo "slurm-local: must run as root (the daemons run as root)" >&2; exit 2; }
  for cmd in munged slurmctld slurmd sinfo sbatch squeue scancel; do
    command -v "$cmd" >/dev/null || { echo "slurm-local: $cmd not found; install slurm-wlm and munge" >&2; exit 2; }
  done
  for f in "${pidfiles[@]}"; do
    if live_pid "$f" "$(basename "$f" .pid)" >/dev/null; then
      echo "slurm-local: $dir already holds a running cluster ($(basename "$f" .pid)); stop it first" >&2
      exit 2
    fi
  done
  mkdir -p "$dir/state" "$dir/spool" "$dir/log" "$dir/run"
  local host base ctld_port slurmd_port
  host=$(hostname -s)
  base=$((10000 + $(printf '%s' "$dir" | cksum | cut -d' ' -f1) % 10000 * 2))
  ctld_port=$(free_port "$base")
  slurmd_port=$(free_port $((ctld_port + 1)))
  write_conf "$host" "$ctld_port" "$slurmd_port"
  printf 'export SLURM_CONF=%q\n' "$conf" >"$dir/env"

  start_munged || fail_start "munged did not start"
  slurmctld -f "$conf" || fail_start "slurmctld did not start"
  slurmd -f "$conf" || fail_start "slurmd did not start"
  local state=""
  for _ in $(seq $((start_timeout * 5))); do
    state=$(SLURM_CONF=$conf sinfo -h -N -o %T 2>/dev/null || true)
    [ "$state" = idle ] && break
    sleep 0.2
  done
  [ "$state" = idle ] || fail_start "node $host not idle after ${start_timeout} s (sinfo: '${state:-no answer}')"
  echo "slurm-local: one-node cluster up in $dir (node $host, $(nproc) CPUs, ports $ctld_port/$slurmd_port)" >&2
  cat "$dir/env"
}

case "$mode" in
  start) start_cluster ;;
  stop) stop_cluster ;;
  *) usage ;;
esac
