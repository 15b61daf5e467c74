#!/bin/sh
# install-deps.sh — installs the Debian 12 packages meshcorr builds, tests and
# demos with, and adds the system user the tests and the demo run meshcorrd
# as (below).
# Idempotent and non-interactive; fetches nothing but Debian packages. Must
# not build or configure anything of the project itself.
set -eu

PACKAGES="
build-essential pkg-config g++
libembree-dev
libdraco-dev draco
libsuitesparse-dev liblapack-dev liblapacke-dev libarpack2-dev
libopenmesh-dev
libcgal-demo
ocl-icd-opencl-dev opencl-c-headers pocl-opencl-icd clinfo xxd
libuv1-dev
libsqlite3-dev
libmodbus-dev libmicrohttpd-dev mbpoll
slurmctld slurmd slurm-client munge
libsystemd-dev systemd
libgnutls28-dev gnutls-bin
libseccomp-dev
mandoc man-db python3-prometheus-client
libpng-dev
python3 python3-numpy python3-setuptools python3-pip python3-venv python3-wheel
"

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi

missing=""
for p in $PACKAGES; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $p"
    fi
done

if [ -n "$missing" ]; then
    echo "install-deps: installing:$missing"
    export DEBIAN_FRONTEND=noninteractive
    $SUDO apt-get update -qq
    # shellcheck disable=SC2086
    $SUDO apt-get install -y -qq --no-install-recommends $missing
else
    echo "install-deps: all packages present"
fi

# Started as root, meshcorrd runs as --user meshcorr (it refuses root
# without --user): the tests (tests/support/testdaemon.c) and make demo
# (deploy/demo.sh) do so. A system user with no home and no login shell.
if ! getent passwd meshcorr >/dev/null; then
    echo "install-deps: adding the system user meshcorr"
    $SUDO useradd --system --no-create-home --home-dir /nonexistent --shell /usr/sbin/nologin meshcorr
fi
