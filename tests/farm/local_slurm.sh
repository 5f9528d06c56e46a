# A private single-node Slurm cluster on this machine, for the farm test (source this file).
# slurmctld and slurmd run as the current user (root in the CI container; no systemd needed) with
# a generated slurm.conf in $SLURM_DIR (SLURM_CONF points the client commands to it): free ports,
# auth/none (no MUNGE daemon), proctrack/linuxproc and task/none (no cgroups), no accounting.
#   local_slurm_start DIR CPUS   -> exports SLURM_CONF; fails with the daemons' logs
#   local_slurm_stop             -> stops both daemons (scontrol shutdown, then their PIDs)

_free_port() {
  /usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0))
print(s.getsockname()[1])'
}

local_slurm_start() {
  SLURM_DIR=$1
  local cpus=$2 node ctld_port d_port
  for tool in slurmctld slurmd sbatch squeue scontrol sinfo; do
    if ! command -v "$tool" >/dev/null && [ ! -x "/usr/sbin/$tool" ]; then
      echo "FAIL: $tool not found: run scripts/setup-deps.sh (package slurm-wlm)" >&2
      return 1
    fi
  done
  node=$(hostname -s)
  ctld_port=$(_free_port)
  d_port=$(_free_port)
  mkdir -p "$SLURM_DIR/state" "$SLURM_DIR/spool"
  cat >"$SLURM_DIR/slurm.conf" <<CONF
ClusterName=gdptfarm
SlurmctldHost=$node(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmUser=$(id -un)
SlurmdUser=$(id -un)
AuthType=auth/none
CredType=cred/none
StateSaveLocation=$SLURM_DIR/state
SlurmdSpoolDir=$SLURM_DIR/spool
SlurmctldPidFile=$SLURM_DIR/slurmctld.pid
SlurmdPidFile=$SLURM_DIR/slurmd.pid
SlurmctldLogFile=$SLURM_DIR/slurmctld.log
SlurmdLogFile=$SLURM_DIR/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SwitchType=switch/none
MpiDefault=none
SchedulerType=sched/builtin
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
ReturnToService=2
SlurmdParameters=config_overrides
MinJobAge=3600
NodeName=$node NodeAddr=127.0.0.1 CPUs=$cpus State=UNKNOWN
PartitionName=farm Nodes=$node Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF=$SLURM_DIR/slurm.conf
  PATH=$PATH:/usr/sbin
  slurmctld -D >"$SLURM_DIR/slurmctld.out" 2>&1 &
  SLURMCTLD_PID=$!
  slurmd -D -N "$node" >"$SLURM_DIR/slurmd.out" 2>&1 &
  SLURMD_PID=$!
  local i state
  for i in $(seq 1 60); do
    state=$(sinfo -h -o %T 2>/dev/null || true)
    if [ "$state" = idle ]; then
      echo "local Slurm up: node $node idle, ports $ctld_port/$d_port"
      return 0
    fi
    sleep 0.5
  done
  echo "FAIL: the local Slurm node did not become idle (sinfo: '${state:-no answer}')" >&2
  tail -n 20 "$SLURM_DIR"/slurmctld.log "$SLURM_DIR"/slurmd.log "$SLURM_DIR"/*.out >&2 || true
  return 1
}

local_slurm_stop() {
  if [ -n "${SLURM_CONF:-}" ]; then
    scancel --quiet -u "$(id -un)" >/dev/null 2>&1 || true  # this private cluster's jobs only
    sleep 1
    scontrol shutdown >/dev/null 2>&1 || true
  fi
  local pid i
  for pid in ${SLURMD_PID:-} ${SLURMCTLD_PID:-}; do
    for i in $(seq 1 20); do kill -0 "$pid" 2>/dev/null || break; sleep 0.25; done
    if kill -0 "$pid" 2>/dev/null; then kill "$pid" 2>/dev/null || true; fi
    wait "$pid" 2>/dev/null || true
  done
  SLURMD_PID= SLURMCTLD_PID=
}
