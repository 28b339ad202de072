#!/usr/bin/env bash
# A new recipe while the loom weaves: the config file is edited (each position beaten twice) and
# loomctl gets SIGHUP early in row 2. The loop never stops; row 2 finishes on the old recipe and row 3 —
# the next row, as the message says — adopts the new one (twice the beats): with a counters file the
# sequencer waits at each row boundary for the reporter, which takes the reload before it confirms the
# save.
set -euo pipefail
loomctl=$1
work=$(mktemp -d)
trap 'kill %1 2>/dev/null || true; rm -rf "$work"' EXIT
cfg=$work/loom.toml
printf 'extends = "default"\n[loom]\nwidth_m = 0.4\n\n[recipe]\nbeats_per_position = 1\n' >"$cfg"
"$loomctl" weave --config "$cfg" --rows 4 --realtime --pace 8 --no-telemetry --quiet --counters "$work/counters.json" \
  >"$work/out" 2>&1 &
pid=$!
for _ in $(seq 1 200); do grep -q '^row 1/4' "$work/out" && break; sleep 0.05; done
grep -q '^row 1/4' "$work/out" || { echo "FAIL: row 1 never completed"; cat "$work/out"; exit 1; }
printf 'extends = "default"\n[loom]\nwidth_m = 0.4\n\n[recipe]\nbeats_per_position = 2\n' >"$cfg"
kill -HUP "$pid"
wait "$pid" || { echo "FAIL: loomctl exited $?"; cat "$work/out"; exit 1; }
cat "$work/out"
grep -q 'reloaded; the loom adopts it at the next row' "$work/out" || { echo "FAIL: reload not acknowledged"; exit 1; }
grep -q '^row 1/4: .*, 5 beats' "$work/out" || { echo "FAIL: row 1 should have 5 beats"; exit 1; }
grep -q '^row 2/4: .*, 5 beats' "$work/out" || { echo "FAIL: row 2 (in progress at the reload) should finish on the old recipe"; exit 1; }
grep -q '^row 3/4: .*, 10 beats' "$work/out" || { echo "FAIL: the next row (3) should beat each position twice"; exit 1; }
grep -q '^row 4/4: .*, 10 beats' "$work/out" || { echo "FAIL: the last row should beat each position twice"; exit 1; }
echo "PASS: recipe adopted between rows without stopping the loop"
