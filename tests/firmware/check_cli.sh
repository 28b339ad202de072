#!/usr/bin/env bash
# loomctl check prints the objects each kind of node must support, from the machine description: the
# homing objects for the drives referenced by a homing run (and only then), and the I/O module's input and
# output groups widened by the knotting heads' signals when the heads are fitted.
# usage: check_cli.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
fail() { printf 'FAIL: %s\n' "$*" >&2; exit 1; }
expect() {  # expect OUTPUT_FILE TEXT
  grep -qF -- "$2" "$1" || fail "$(basename "$1"): no line with: $2"
}
out=$(mktemp -d "${TMPDIR:-/tmp}/loom_check_cli.XXXXXX")
trap 'rm -rf "$out"' EXIT

"$loomctl" check --config "$src/tests/hil/hil_incremental_loom.toml" >"$out/homing.txt"
expect "$out/homing.txt" "objects the homing drives (nodes 1, 2) must support as well:"
expect "$out/homing.txt" "0x6098 homing method: the configured method"
expect "$out/homing.txt" "0x6060 modes of operation: set to 6 (homing) for the referencing run, then 8"

"$loomctl" check >"$out/default.txt"
! grep -q "homing drives" "$out/default.txt" || fail "the default loom (absolute encoders) was given homing objects"
expect "$out/default.txt" "0x6200:01 write digital outputs, 8-bit: valves, stack light, buzzer"

"$loomctl" check --config "$src/firmware/config/knotting_loom.toml" >"$out/heads.txt"
expect "$out/heads.txt" "0x6200:01..04 write digital outputs, 8-bit: valves, stack light, buzzer, the heads' grippers and cutters"
expect "$out/heads.txt" "0x6000:01..04 read digital inputs, 8-bit: sensors and their second channels, e-stop chain, buttons, the heads' yarn-present switches"
echo "check_cli: PASS"
