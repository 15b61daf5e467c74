#!/bin/sh
# start-slurm.sh DIR — starts a private single-node Slurm (munged, slurmctld,
# slurmd as plain background processes) with every file under DIR, for the
# Slurm backend's tests. Meant to run inside a fresh network namespace
# (tests/slurm/run-in-slurm.sh): the daemons listen on loopback only. Writes
# DIR/env (SLURM_CONF=...) for the callers and DIR/pids for stop-slurm.sh.
# Exits non-zero, with the reason on stderr, when Slurm does not come up
# within 30 s. Never touches the system's own Slurm or munge configuration.
set -eu
DIR=$1
mkdir -p "$DIR/munge" "$DIR/ctld" "$DIR/slurmd" "$DIR/log"
# clients need search permission to reach the socket, and read slurm.conf:
# a root test runs meshcorrd (and so sbatch, squeue) as another user
chmod 755 "$DIR" "$DIR/munge"
: > "$DIR/pids"

# munge: its own key and socket
dd if=/dev/urandom of="$DIR/munge/munge.key" bs=1024 count=1 2>/dev/null
chmod 400 "$DIR/munge/munge.key"
SOCK="$DIR/munge/munge.socket"
munged --force --key-file="$DIR/munge/munge.key" --socket="$SOCK" \
       --pid-file="$DIR/munge/munged.pid" --log-file="$DIR/log/munged.log" \
       --seed-file="$DIR/munge/munge.seed" --num-threads=2
for i in $(seq 50); do [ -S "$SOCK" ] && break; sleep 0.1; done
cat "$DIR/munge/munged.pid" >> "$DIR/pids"

CPUS=${SLURM_TEST_CPUS:-4}
cat > "$DIR/slurm.conf" <<CONF
ClusterName=meshcorrtest
SlurmctldHost=localhost(127.0.0.1)
SlurmctldPort=6817
SlurmdPort=6818
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$SOCK
StateSaveLocation=$DIR/ctld
SlurmdSpoolDir=$DIR/slurmd
SlurmctldPidFile=$DIR/slurmctld.pid
SlurmdPidFile=$DIR/slurmd.pid
SlurmctldLogFile=$DIR/log/slurmctld.log
SlurmdLogFile=$DIR/log/slurmd.log
SlurmctldDebug=info
SlurmdDebug=info
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SchedulerType=sched/builtin
SchedulerParameters=batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SlurmdParameters=config_overrides
MpiDefault=none
ReturnToService=2
OverTimeLimit=0
KillWait=5
MinJobAge=600
InactiveLimit=0
SlurmctldTimeout=30
SlurmdTimeout=30
NodeName=mcnode NodeHostname=localhost NodeAddr=127.0.0.1 CPUs=$CPUS RealMemory=4000 State=UNKNOWN
PartitionName=debug Nodes=mcnode Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$DIR/slurm.conf"
echo "SLURM_CONF=$SLURM_CONF" > "$DIR/env"

slurmctld -c -f "$SLURM_CONF" -L "$DIR/log/slurmctld.log" 2>>"$DIR/log/start.err"
for i in $(seq 100); do [ -s "$DIR/slurmctld.pid" ] && break; sleep 0.1; done
[ -s "$DIR/slurmctld.pid" ] && cat "$DIR/slurmctld.pid" >> "$DIR/pids"
slurmd -N mcnode -f "$SLURM_CONF" -L "$DIR/log/slurmd.log" 2>>"$DIR/log/start.err"
for i in $(seq 100); do [ -s "$DIR/slurmd.pid" ] && break; sleep 0.1; done
[ -s "$DIR/slurmd.pid" ] && cat "$DIR/slurmd.pid" >> "$DIR/pids"

# up when the node is idle and accepts jobs
for i in $(seq 300); do
    state=$(timeout 5 sinfo -h -N -o %t 2>/dev/null || true)
    case "$state" in idle*|mix*|alloc*) exit 0 ;; esac
    sleep 0.1
done
echo "start-slurm: node not idle after 30 s (state '$state'); logs in $DIR/log:" >&2
tail -n 20 "$DIR/log/slurmctld.log" "$DIR/log/slurmd.log" "$DIR/log/start.err" >&2 2>/dev/null || true
exit 1
