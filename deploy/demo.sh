#!/bin/sh
# demo.sh BUILD — the main job on meshes every Debian machine with
# libcgal-demo has: cow -> camel. Extracts the two meshes from Debian's CGAL
# data archive into BUILD/demo/, checks them, and runs the elastic matching
# from the landmark pairs in deploy/demo/. Installs nothing.
set -eu
build=${1:-build}
here=$(dirname "$0")
archive=/usr/share/doc/libcgal-dev/data.tar.gz
out="$build/demo"
mkdir -p "$out"
if [ ! -f "$archive" ]; then
    echo "demo: $archive is missing: run deploy/install-deps.sh (package libcgal-demo)" >&2
    exit 1
fi
tar -xzf "$archive" -C "$out" --strip-components=2 data/meshes/cow.off data/meshes/camel.off
"$build/meshcorr" info "$out/cow.off"
"$build/meshcorr" info "$out/camel.off"
"$build/meshcorr" match "$out/cow.off" "$out/camel.off" \
    --landmarks "$here/demo/cow-camel.landmarks" \
    --out "$out/cow-camel.map" --out-reverse "$out/camel-cow.map" \
    --out-deformed "$out/cow-deformed.ply" --out-remeshed "$out/camel-remeshed.ply"
echo "demo: maps in $out/cow-camel.map and $out/camel-cow.map;"
echo "demo: the cow deformed onto the camel in $out/cow-deformed.ply,"
echo "demo: the camel remeshed with the cow's connectivity in $out/camel-remeshed.ply"
