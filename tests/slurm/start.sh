#!/usr/bin/env bash
# Bring up a single-node Slurm on this machine for tests/campaign_slurm.rs: munged and
# slurmctld/slurmd of Debian's `munge` and `slurm-wlm`, every file (key, configuration, state,
# spool, logs, sockets) under one folder, nothing written elsewhere. Run as root (slurmd
# starts jobs as their users). Idempotent: when the daemons of that folder already answer,
# it says so and exits 0.
#
#   tests/slurm/start.sh            # folder: $STF_LAB_SLURM_DIR, default /tmp/stf-lab-slurm
#   export SLURM_CONF=/tmp/stf-lab-slurm/slurm.conf   # what the client commands need
#   tests/slurm/stop.sh
#
# Ports: $STF_LAB_SLURM_PORT (slurmctld, default 6817) and the next one (slurmd).
# MaxArraySize is written as Slurm's default, 1001 (array task indices below it).
# Waits at most $STF_LAB_SLURM_WAIT seconds (default 60) for the node to be idle; on failure
# it prints why and the daemons' logs, and exits 1.
set -euo pipefail

dir=${STF_LAB_SLURM_DIR:-/tmp/stf-lab-slurm}
port=${STF_LAB_SLURM_PORT:-6817}
wait_s=${STF_LAB_SLURM_WAIT:-60}
export SLURM_CONF=$dir/slurm.conf

fail() {
  echo "tests/slurm/start.sh: $*" >&2
  for log in "$dir"/munged.log "$dir"/slurmctld.log "$dir"/slurmd.log; do
    if [[ -f $log ]]; then
      echo "---- $log (last 40 lines)" >&2
      tail -n 40 "$log" >&2
    fi
  done
  exit 1
}

for tool in munged mungekey slurmctld slurmd sinfo scontrol; do
  command -v "$tool" >/dev/null ||
    fail "$tool is not installed: apt-get install -y slurm-wlm munge"
done
[[ $(id -u) -eq 0 ]] || fail "run as root (slurmd starts jobs as their users)"

# A daemon of ours is alive when its pid file names a live process.
alive() { [[ -f $1 ]] && kill -0 "$(cat "$1")" 2>/dev/null; }

# The node's line: "idle", "mixed", … or nothing when slurmctld does not answer.
node_state() { timeout 10 sinfo -h -N -o %T 2>/dev/null | head -n 1 || true; }

if alive "$dir/munged.pid" && alive "$dir/slurmctld.pid" && alive "$dir/slurmd.pid"; then
  case $(node_state) in
    idle* | mixed* | allocated* | completing*)
      echo "Slurm already up in $dir (SLURM_CONF=$SLURM_CONF)"
      exit 0
      ;;
  esac
fi
# Something is half up: stop what is left and start afresh (the key is kept).
"$(dirname "$0")/stop.sh" >/dev/null 2>&1 || true

mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
chmod 0755 "$dir"
chmod 0755 "$dir/munge"

# munged: our own key, socket and files.
if [[ ! -s $dir/munge/munge.key ]]; then
  mungekey --create --keyfile="$dir/munge/munge.key" --force
fi
chmod 0600 "$dir/munge/munge.key"
munged --force \
  --key-file="$dir/munge/munge.key" \
  --socket="$dir/munge/munge.socket" \
  --pid-file="$dir/munged.pid" \
  --log-file="$dir/munged.log" \
  --seed-file="$dir/munge/munged.seed" ||
  fail "munged did not start"

# slurm.conf: one node, this machine, its CPUs and memory as slurmd reads them.
host=$(hostname -s)
read -r -a node < <(slurmd -C | head -n 1)
[[ ${node[0]:-} == NodeName=* ]] || fail "slurmd -C did not describe this machine"
cat >"$dir/slurm.conf.new" <<CONF
# Written by tests/slurm/start.sh: a single-node Slurm for tests, every file under $dir.
ClusterName=stflab
SlurmctldHost=$host(127.0.0.1)
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
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
JobCompType=jobcomp/none
MpiDefault=none
MailProg=/bin/true
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
DefMemPerCPU=1024
ReturnToService=2
MinJobAge=600
MaxArraySize=1001
SlurmdTimeout=60
${node[*]} NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=debug Nodes=${node[0]#NodeName=} Default=YES MaxTime=INFINITE State=UP
CONF
mv "$dir/slurm.conf.new" "$dir/slurm.conf"

slurmctld -i -f "$SLURM_CONF" || fail "slurmctld did not start"
slurmd -f "$SLURM_CONF" || fail "slurmd did not start"

for ((i = 0; i < wait_s; i++)); do
  case $(node_state) in
    idle*)
      echo "Slurm up in $dir: node ${node[0]#NodeName=} idle (SLURM_CONF=$SLURM_CONF)"
      exit 0
      ;;
  esac
  sleep 1
done
fail "the node is not idle after ${wait_s} s (sinfo: $(node_state))"
