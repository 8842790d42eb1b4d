#!/bin/sh
# A private single-node Slurm on loopback for the tests (docs/orchestrator.md,
# Slurm backend):
#   slurm_cluster.sh start PREFIX   writes PREFIX/slurm.conf, starts munged,
#                                   slurmctld and slurmd; exit 0 once the node is idle
#   slurm_cluster.sh stop PREFIX    stops what start started
# Needs root and the packages slurmctld slurmd slurm-client munge
# (scripts/install-deps.sh with FLOCSIM_WITH_SLURM=1). Prints why when it cannot start.
set -u
action=${1:?start or stop}
prefix=${2:?prefix folder}
conf=$prefix/slurm.conf

stop() {
  if [ -f "$conf" ]; then
    SLURM_CONF=$conf scontrol shutdown >/dev/null 2>&1
    for pidfile in "$prefix/run/slurmctld.pid" "$prefix/run/slurmd.pid"; do
      for _ in 1 2 3 4 5 6 7 8 9 10; do
        [ -f "$pidfile" ] && kill -0 "$(cat "$pidfile")" 2>/dev/null || break
        sleep 0.5
      done
      [ -f "$pidfile" ] && kill -9 "$(cat "$pidfile")" 2>/dev/null
    done
  fi
  if [ -f "$prefix/munge/munged.pid" ]; then
    kill "$(cat "$prefix/munge/munged.pid")" 2>/dev/null
  fi
  return 0
}

if [ "$action" = stop ]; then
  stop
  exit 0
fi

fail() {
  echo "slurm_cluster: $*" >&2
  stop
  exit 1
}

[ "$(id -u)" = 0 ] || fail "needs root to start munged, slurmctld and slurmd"
for prog in munged slurmctld slurmd sinfo sbatch squeue scontrol; do
  command -v $prog >/dev/null 2>&1 || [ -x /usr/sbin/$prog ] ||
    fail "$prog is not installed (FLOCSIM_WITH_SLURM=1 scripts/install-deps.sh)"
done
PATH=$PATH:/usr/sbin
mkdir -p "$prefix/state" "$prefix/spool" "$prefix/log" "$prefix/run" "$prefix/munge"
chown -R slurm:slurm "$prefix/state" "$prefix/log" "$prefix/run" || fail "no slurm user"
chmod 755 "$prefix" "$prefix/run" "$prefix/log"
chown munge:munge "$prefix/munge"
chmod 700 "$prefix/munge"
# At least 2 CPUs, so that the tests' two array tasks run side by side
# (config_overrides lets the node claim more than it has). Not `nproc`: it
# answers OMP_NUM_THREADS, and OMP_NUM_THREADS=1 in the caller's environment
# made the tasks queue one behind the other.
cpus=$(getconf _NPROCESSORS_ONLN 2>/dev/null || echo 1)
[ "$cpus" -ge 2 ] 2>/dev/null || cpus=2
cat >"$conf" <<EOF
ClusterName=flocsimtest
SlurmctldHost=localhost
SlurmctldPort=$((16817 + $$ % 1000))
SlurmdPort=$((17818 + $$ % 1000))
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/filetxt
JobCompLoc=$prefix/log/jobcomp.txt
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SlurmdParameters=config_overrides
SchedulerParameters=batch_sched_delay=0,sched_min_interval=100000
MinJobAge=600
KillWait=5
ReturnToService=2
SlurmUser=slurm
StateSaveLocation=$prefix/state
SlurmdSpoolDir=$prefix/spool
SlurmctldLogFile=$prefix/log/slurmctld.log
SlurmdLogFile=$prefix/log/slurmd.log
SlurmctldPidFile=$prefix/run/slurmctld.pid
SlurmdPidFile=$prefix/run/slurmd.pid
NodeName=localhost NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=1000
PartitionName=debug Nodes=localhost Default=YES MaxTime=INFINITE State=UP
EOF
[ -f /etc/munge/munge.key ] || mungekey --create >/dev/null 2>&1 || fail "cannot create the munge key"
mkdir -p /run/munge && chown munge:munge /run/munge
# A munged of its own, unless one already answers on the default socket.
if ! munge -n </dev/null 2>/dev/null | unmunge >/dev/null 2>&1; then
  runuser -u munge -- munged --pid-file="$prefix/munge/munged.pid" </dev/null >/dev/null 2>&1 ||
    fail "munged did not start"
fi
SLURM_CONF=$conf slurmctld -f "$conf" -c </dev/null >/dev/null 2>&1 || fail "slurmctld did not start (see $prefix/log/slurmctld.log)"
SLURM_CONF=$conf slurmd -f "$conf" -N localhost </dev/null >/dev/null 2>&1 || fail "slurmd did not start (see $prefix/log/slurmd.log)"
for _ in $(seq 1 60); do
  state=$(SLURM_CONF=$conf sinfo -h -N -o %T 2>/dev/null)
  [ "$state" = idle ] && exit 0
  sleep 0.5
done
fail "the node did not become idle within 30 s (state: ${state:-none}; see $prefix/log)"
