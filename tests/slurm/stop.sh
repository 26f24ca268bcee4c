#!/usr/bin/env bash
# Stop the single-node Slurm tests/slurm/start.sh brought up (slurmd, slurmctld, munged of
# $STF_LAB_SLURM_DIR, default /tmp/stf-lab-slurm), by the pids in that folder only.
# `stop.sh --clean` also removes the folder (key, state, logs): the next start is a fresh one.
set -uo pipefail

dir=${STF_LAB_SLURM_DIR:-/tmp/stf-lab-slurm}

stop() {
  local pidfile=$dir/$1.pid pid
  [[ -f $pidfile ]] || return 0
  pid=$(cat "$pidfile")
  if kill -0 "$pid" 2>/dev/null; then
    kill "$pid"
    for ((i = 0; i < 50; i++)); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.2
    done
    kill -0 "$pid" 2>/dev/null && kill -9 "$pid"
  fi
  rm -f "$pidfile"
}

stop slurmd
stop slurmctld
stop munged
if [[ ${1:-} == --clean ]]; then
  rm -rf "$dir"
  echo "Slurm stopped; $dir removed"
else
  echo "Slurm stopped (its files stay in $dir)"
fi
