#!/usr/bin/env bash
# A full disk while the heads knot: `weave --counters` on a tiny tmpfs (a private mount namespace) that fills
# up mid-row. The knot cycles' write-ahead waits for a save that cannot happen; the wait has a deadline
# (timing.row_save_timeout_s), so the run ends in the latched fault counters_not_saved — red lamp, quick stop,
# exit 3 — within it, instead of standing mid-row for ever with the heads holding. weave retries the save
# meanwhile (a disk that frees up in time lets the loom weave on: the second half).
# Usage: weave_full_disk.sh LOOMCTL CONFIG
set -euo pipefail
loomctl=$1
config=$2
if [[ -z ${LOOM_IN_NS:-} ]]; then
  if [[ $(id -u) == 0 ]]; then ns=(unshare -m --propagation private); else ns=(unshare -rm); fi
  LOOM_IN_NS=1 exec "${ns[@]}" "$0" "$@"
fi
work=$(mktemp -d /tmp/loom_weave_full_disk.XXXXXX)
cleanup() {
  kill -9 "${pid:-}" "${filler:-}" 2>/dev/null || true
  mountpoint -q "$work/disk" 2>/dev/null && umount "$work/disk"
  rm -rf "$work"
}
trap cleanup EXIT
mkdir "$work/disk"
mount -t tmpfs -o size=64k tmpfs "$work/disk"
scene=$work/scene.toml
printf 'name = "full_disk"\nseed = 7\neffects = ["ideal", "knotter"]\n[knotter]\nmiss_probability = 0.0\n' >"$scene"

# Runs weave paced at 10x with the state on the tmpfs; fills the disk once the heads have knotted a while.
# $1: how long the disk stays full (s; "forever" keeps it full).
run() {
  rm -rf "${work:?}/disk/"*
  "$loomctl" weave --config "$config" --scene "$scene" --rows 2 --realtime --pace 10 --allow-degraded \
    --no-telemetry --quiet --counters "$work/disk/counters.json" >"$work/out" 2>&1 &
  pid=$!
  # Fill once a knot cycle's start has been written ahead (the heads are knotting row 1).
  for _ in $(seq 1 400); do grep -q '"knot_cycles_started":[1-9]' "$work/disk/counters.json" 2>/dev/null && break; sleep 0.025; done
  grep -q '"knot_cycles_started":[1-9]' "$work/disk/counters.json" || { echo "FAIL: the heads never started"; cat "$work/out"; exit 1; }
  rm -f "$work/stop-filling"
  (i=0; while [[ ! -e $work/stop-filling ]]; do dd if=/dev/zero of="$work/disk/fill.$i" bs=4k status=none 2>/dev/null || true; i=$((i + 1)); sleep 0.05; done) &
  filler=$!
  if [[ $1 != forever ]]; then
    sleep "$1"
    touch "$work/stop-filling"; wait "$filler" 2>/dev/null || true
    rm -f "$work/disk/fill".*
  fi
  local t0=$SECONDS
  set +e
  wait "$pid"
  rc=$?
  set -e
  elapsed=$((SECONDS - t0))
  touch "$work/stop-filling"; wait "$filler" 2>/dev/null || true
  rm -f "$work/disk/fill".*
}

# 1. Full for good: counters_not_saved within the time-out (5 s of machine time = 0.5 s at 10x; the first save
# that fails may be a knot's, a pick's or the row's), exit 3, never standing mid-row.
run forever
cat "$work/out"
[[ $rc == 3 ]] || { echo "FAIL: weave exited $rc on a full disk, expected 3 (a latched fault)"; exit 1; }
grep -q '^FAULT counters_not_saved' "$work/out" || { echo "FAIL: no counters_not_saved fault"; exit 1; }
grep -q 'counters not saved: .*retrying' "$work/out" || { echo "FAIL: the failed save was not said"; exit 1; }
((elapsed <= 20)) || { echo "FAIL: took $elapsed s of wall time to stop"; exit 1; }
echo "full disk for good: counters_not_saved, exit 3, $elapsed s after the disk filled: ok"

# 2. Full for a moment, mid-knotting (0.2 s of wall time = 2 s of machine time, within the 5 s time-out): the
# retried save gets through and both rows are woven.
run 0.2
[[ $rc == 0 ]] || { echo "FAIL: weave exited $rc after the disk was full for 0.2 s"; cat "$work/out"; ls -la "$work/disk"; df "$work/disk"; exit 1; }
grep -q 'counters saved again' "$work/out" || { echo "FAIL: no retried save"; cat "$work/out"; exit 1; }
grep -q '^woven 2 ' "$work/out" || { echo "FAIL: the two rows were not woven"; cat "$work/out"; exit 1; }
echo "full disk for 0.2 s mid-knotting: the retried save went through, both rows woven: ok"
echo "PASS"
