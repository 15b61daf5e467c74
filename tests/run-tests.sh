#!/bin/sh
# run-tests.sh — runs every test binary given, shows their lines, and ends
# with the totals line "N passed, M failed" (skips are counted apart).
# A binary that dies outside its tests counts as one failure.
log=$(mktemp)
for bin in "$@"; do
    "$bin" >"$log.out" 2>&1
    rc=$?
    cat "$log.out"
    cat "$log.out" >>"$log"
    if [ $rc -ne 0 ] && ! grep -q '^FAIL ' "$log.out"; then
        echo "FAIL $bin (exit $rc outside any test)" | tee -a "$log"
    fi
done
passed=$(grep -c '^PASS ' "$log")
failed=$(grep -c '^FAIL ' "$log")
skipped=$(grep -c '^SKIP ' "$log")
rm -f "$log" "$log.out"
if [ "$skipped" -gt 0 ]; then
    echo "$passed passed, $failed failed, $skipped skipped"
else
    echo "$passed passed, $failed failed"
fi
[ "$failed" -eq 0 ]
