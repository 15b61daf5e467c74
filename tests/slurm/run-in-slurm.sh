#!/bin/sh
# run-in-slurm.sh CMD [ARGS...] — run inside a private network and pid
# namespace (unshare --pid --fork --net --mount-proc): brings loopback up,
# starts a private Slurm (start-slurm.sh) under a temporary directory, runs
# CMD with SLURM_CONF and MESHCORR_SLURM_DIR set, then stops Slurm
# (stop-slurm.sh) whatever CMD did, and exits with CMD's status. When Slurm
# does not start, CMD still runs with MESHCORR_SLURM_ERROR naming the reason
# (the tests fail with it). The pid namespace ends every process of the
# namespace when this script exits, so nothing outlives the run.
set -u
HERE=$(cd "$(dirname "$0")" && pwd)
ip link set lo up
# glibc's getaddrinfo(AI_ADDRCONFIG) counts 127.0.0.1 alone as "no IPv4
# configured" and Slurm then resolves nothing: one more loopback address fixes it.
ip addr add 127.0.0.2/8 dev lo
DIR=$(mktemp -d /tmp/meshcorr-slurm-XXXXXX)
export MESHCORR_SLURM_DIR="$DIR"
if ! "$HERE/start-slurm.sh" "$DIR" 2>"$DIR/start-slurm.err"; then
    MESHCORR_SLURM_ERROR="Slurm did not start: $(tail -c 1500 "$DIR/start-slurm.err" | tr '\n' ' ')"
    export MESHCORR_SLURM_ERROR
fi
export SLURM_CONF="$DIR/slurm.conf"
"$@"
rc=$?
"$HERE/stop-slurm.sh" "$DIR"
exit $rc
