#!/usr/bin/env bash
# `loomctl commission` on the simulated loom: the machine is left where a run stopped (--sim-state);
# commissioning brings it up with every drive disabled (nothing moves: the state file's positions are the
# same after it), prints the positions and inputs, and --capture park,home,left --write puts exactly those
# positions into the three calibration lines of the config — every other byte unchanged, the file still
# a valid loom. Bad requests exit 2 and leave the file alone, and so does a pose the sensors contradict
# (issue 22: "left" captured while shuttle_at_right=1).
# Usage: commission_cli.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
work=$(mktemp -d /tmp/loom_commission.XXXXXX)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
cp "$src/firmware/config/default_loom.toml" "$work/loom.toml"
# One row (one pick) leaves the shuttle at the right selvedge: "left" is refused, the file untouched.
"$loomctl" weave --config "$work/loom.toml" --rows 1 --no-telemetry --quiet --sim-state "$work/right.bin" >/dev/null
cp "$work/loom.toml" "$work/before.toml"
set +e
"$loomctl" commission --config "$work/loom.toml" --sim-state "$work/right.bin" --capture park,left --write \
  >"$work/right.txt" 2>&1; rc=$?
set -e
[[ $rc == 2 ]] || fail "left captured with the shuttle at the right (exit $rc): $(cat "$work/right.txt")"
grep -q 'left refused: .*shuttle_at_right=1' "$work/right.txt" || fail "no reason: $(cat "$work/right.txt")"
cmp -s "$work/loom.toml" "$work/before.toml" || fail "a refused capture changed the file"
# Two rows bring it back to the left, where the carrier's pose is confirmed.
"$loomctl" weave --config "$work/loom.toml" --rows 2 --no-telemetry --quiet --sim-state "$work/state.bin" >/dev/null

"$loomctl" commission --config "$work/loom.toml" --sim-state "$work/state.bin" --io-once >"$work/once.txt"
pos=$(grep '^positions:' "$work/once.txt")
[[ $pos == *"beat_crank="*"(switch_on_disabled)"*"carriage="*"helix="* ]] || fail "positions line: $pos"
[[ $(grep -o 'operation_enabled' "$work/once.txt" | wc -l) == 0 ]] || fail "a drive was enabled: $pos"
grep -q '^inputs: piston_a_extended=[01] .* estop_ok=1 ' "$work/once.txt" || fail "inputs line: $(cat "$work/once.txt")"
crank=$(sed -n 's/.*beat_crank=\([-0-9.]*\) .*/\1/p' <<<"$pos")
carriage=$(sed -n 's/.*carriage=\([-0-9.]*\) .*/\1/p' <<<"$pos")
helix=$(sed -n 's/.*helix=\([-0-9.]*\) .*/\1/p' <<<"$pos")

"$loomctl" commission --config "$work/loom.toml" --sim-state "$work/state.bin" --capture park,home,left --write \
  >"$work/write.txt"
grep -q "loom.toml:29: beatup.crank_park_position_rad = $crank (was 0.0)" "$work/write.txt" || fail "$(cat "$work/write.txt")"
# Exactly three lines changed, each to the position the machine reads; nothing else moved.
diff "$work/before.toml" "$work/loom.toml" | grep '^>' >"$work/changed.txt" || true
[[ $(wc -l <"$work/changed.txt") == 3 ]] || fail "changed lines: $(cat "$work/changed.txt")"
grep -q "^> crank_park_position_rad = $crank # crank axis reading" "$work/changed.txt" || fail "crank: $(cat "$work/changed.txt")"
grep -q "^> home_position_m = $carriage" "$work/changed.txt" || fail "carriage: $(cat "$work/changed.txt")"
grep -q "^> left_position_rad = $helix" "$work/changed.txt" || fail "helix: $(cat "$work/changed.txt")"
[[ $(wc -l <"$work/before.toml") == $(wc -l <"$work/loom.toml") ]] || fail "line count changed"
"$loomctl" check --config "$work/loom.toml" >/dev/null || fail "the written config does not check"
# Nothing moved: commissioning again reads the same positions.
"$loomctl" commission --config "$work/loom.toml" --sim-state "$work/state.bin" --io-once | grep -qF "$pos" ||
  fail "positions changed while commissioning"

# Refusals: exit 2, file untouched.
cp "$work/loom.toml" "$work/kept.toml"
set +e
"$loomctl" commission --config "$work/loom.toml" --capture elbow 2>/dev/null; rc1=$?
"$loomctl" commission --config "$work/loom.toml" --write 2>/dev/null; rc2=$?
"$loomctl" commission --config "$work/none.toml" --io-once 2>/dev/null; rc3=$?
"$loomctl" commission --config "$work/loom.toml" --iface can0 --io-once 2>/dev/null; rc4=$?
set -e
[[ $rc1 == 2 && $rc2 == 2 && $rc3 == 2 && $rc4 == 2 ]] || fail "refusal exits $rc1 $rc2 $rc3 $rc4, want 2 2 2 2"
cmp -s "$work/loom.toml" "$work/kept.toml" || fail "a refused request changed the file"
echo "commission_cli: ok (crank $crank rad, carriage $carriage m, helix $helix rad written; 3 lines changed)"
