#!/bin/sh
# demo.sh BUILD — the main job on meshes every Debian machine with
# libcgal-demo has: cow -> bull. Extracts the two meshes from Debian's CGAL
# data archive into BUILD/demo/ and runs meshcorr on them. Installs nothing.
set -eu
build=${1:-build}
archive=/usr/share/doc/libcgal-dev/data.tar.gz
out="$build/demo"
mkdir -p "$out"
if [ ! -f "$archive" ]; then
    echo "demo: $archive is missing: run deploy/install-deps.sh (package libcgal-demo)" >&2
    exit 1
fi
tar -xzf "$archive" -C "$out" --strip-components=2 data/meshes/cow.off data/meshes/bull.off
"$build/meshcorr" info "$out/cow.off"
"$build/meshcorr" info "$out/bull.off"
