#!/bin/sh
# stop-slurm.sh DIR — tears down what start-slurm.sh DIR started, in bounded
# time: cancel every job, wait (at most 15 s) for the queue to empty, SIGTERM
# slurmd, slurmctld and munged, SIGKILL whatever is still alive 5 s later.
set -u
DIR=$1
export SLURM_CONF="$DIR/slurm.conf"
if [ -f "$SLURM_CONF" ]; then
    timeout 10 scancel --full --quiet --user=root 2>/dev/null || true
    for i in $(seq 150); do
        [ -z "$(timeout 5 squeue -h -o %i 2>/dev/null)" ] && break
        sleep 0.1
    done
fi
pids=$(cat "$DIR/pids" 2>/dev/null || true)
for p in $pids; do kill -TERM "$p" 2>/dev/null || true; done
for i in $(seq 50); do
    alive=""
    for p in $pids; do kill -0 "$p" 2>/dev/null && alive="$alive $p"; done
    [ -z "$alive" ] && exit 0
    sleep 0.1
done
for p in $alive; do kill -KILL "$p" 2>/dev/null || true; done
exit 0
