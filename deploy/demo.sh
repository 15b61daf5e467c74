#!/bin/sh
# demo.sh BUILD — the main job through a real meshcorrd, on meshes every
# Debian machine with libcgal-demo has: cow -> camel. Extracts the two meshes
# from Debian's CGAL data archive into BUILD/demo/, starts BUILD/meshcorrd
# (a fresh state in BUILD/demo/state, Unix socket BUILD/demo/meshcorrd.sock,
# one local worker), submits the job with the landmark pairs in deploy/demo/,
# watches it, fetches the maps and the deformed cow, evaluates them with
# coloured PLYs and a PNG picture, and stops the daemon (also when a step
# fails). Installs nothing.
set -eu
build=${1:-build}
here=$(dirname "$0")
archive=/usr/share/doc/libcgal-dev/data.tar.gz
out="$build/demo"
sock="$out/meshcorrd.sock"
server="unix:$sock"
mkdir -p "$out"
if [ ! -f "$archive" ]; then
    echo "demo: $archive is missing: run deploy/install-deps.sh (package libcgal-demo)" >&2
    exit 1
fi
tar -xzf "$archive" -C "$out" --strip-components=2 data/meshes/cow.off data/meshes/camel.off
"$build/meshcorr" info "$out/cow.off"
"$build/meshcorr" info "$out/camel.off"

daemon=""
stop_daemon() {
    if [ -n "$daemon" ]; then
        kill -TERM "$daemon" 2>/dev/null || true
        wait "$daemon" || true
        daemon=""
        echo "demo: meshcorrd stopped"
    fi
}
trap stop_daemon EXIT
trap 'exit 130' INT TERM

# A fresh state each run (an interrupted demo leaves its job queued there);
# the daemon in its own session, so that a Ctrl-C reaches this script, which
# stops the daemon, and not the daemon alone.
rm -rf "$out/state" "$sock"
mkdir -p "$out/state"
# meshcorrd refuses to run as root: as root, it runs as the system user
# meshcorr that deploy/install-deps.sh adds (the state directory becomes its).
as_user=""
if [ "$(id -u)" -eq 0 ]; then
    as_user="--user meshcorr"
fi
# shellcheck disable=SC2086
setsid "$build/meshcorrd" $as_user --state-dir "$out/state" --listen "$server" --workers 1 2>"$out/meshcorrd.log" &
daemon=$!
tries=0
until "$build/meshcorr" stats --server "$server" >/dev/null 2>&1; do
    tries=$((tries + 1))
    if [ "$tries" -gt 100 ] || ! kill -0 "$daemon" 2>/dev/null; then
        echo "demo: meshcorrd did not start; its log:" >&2
        cat "$out/meshcorrd.log" >&2
        exit 1
    fi
    sleep 0.1
done
echo "demo: meshcorrd (pid $daemon) listens on $server"

id=$("$build/meshcorr" submit "$out/cow.off" "$out/camel.off" --server "$server" \
    --landmarks "$here/demo/cow-camel.landmarks" --label "demo cow -> camel")
echo "demo: submitted job $id"
"$build/meshcorr" watch "$id" --server "$server"
"$build/meshcorr" result "$id" --server "$server" \
    --out "$out/cow-camel.map" --out-reverse "$out/camel-cow.map" --out-deformed "$out/cow-deformed.ply"
"$build/meshcorr" eval "$out/cow.off" "$out/camel.off" "$out/cow-camel.map" --reverse "$out/camel-cow.map" \
    --out-colors "$out/cow-camel" --out-png "$out/cow-camel.png"
stop_daemon

echo "demo: maps in $out/cow-camel.map (cow -> camel) and $out/camel-cow.map (camel -> cow);"
echo "demo: the cow deformed onto the camel in $out/cow-deformed.ply;"
echo "demo: colours to compare: $out/cow-camel.target.ply (the camel coloured by position)"
echo "demo: and $out/cow-camel.source.ply (the cow coloured through the map);"
echo "demo: the same as a picture in $out/cow-camel.png (left the cow, right the camel; front, back);"
echo "demo: the daemon's log in $out/meshcorrd.log, its state in $out/state"
