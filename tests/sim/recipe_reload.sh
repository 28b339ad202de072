#!/usr/bin/env bash
# A new recipe while the loom weaves: the config file is edited (each position beaten twice) and
# loomctl gets SIGHUP after row 1. The loop never stops; a later row adopts the new recipe at a row
# boundary (twice the beats), the row in progress finishes on the old one, and the run completes.
set -euo pipefail
loomctl=$1
work=$(mktemp -d)
trap 'kill %1 2>/dev/null || true; rm -rf "$work"' EXIT
cfg=$work/loom.toml
printf 'extends = "default"\n[loom]\nwidth_m = 0.4\n\n[recipe]\nbeats_per_position = 1\n' >"$cfg"
"$loomctl" weave --config "$cfg" --rows 4 --realtime --pace 8 --no-telemetry --quiet >"$work/out" 2>&1 &
pid=$!
for _ in $(seq 1 200); do grep -q '^row 1/4' "$work/out" && break; sleep 0.05; done
grep -q '^row 1/4' "$work/out" || { echo "FAIL: row 1 never completed"; cat "$work/out"; exit 1; }
printf 'extends = "default"\n[loom]\nwidth_m = 0.4\n\n[recipe]\nbeats_per_position = 2\n' >"$cfg"
kill -HUP "$pid"
wait "$pid" || { echo "FAIL: loomctl exited $?"; cat "$work/out"; exit 1; }
cat "$work/out"
grep -q 'reloaded; the loom adopts it at the next row' "$work/out" || { echo "FAIL: reload not acknowledged"; exit 1; }
grep -q '^row 1/4: .*, 5 beats' "$work/out" || { echo "FAIL: row 1 should have 5 beats"; exit 1; }
grep -q '^row 4/4: .*, 10 beats' "$work/out" || { echo "FAIL: the last row should beat each position twice"; exit 1; }
echo "PASS: recipe adopted between rows without stopping the loop"
