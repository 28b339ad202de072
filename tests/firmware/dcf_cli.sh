#!/usr/bin/env bash
# loomctl check and loomctl dcf on a machine description that names its nodes' EDS files: check prints
# each node's findings with the EDS's file:line and refuses a node that lacks what the loom needs; dcf
# writes one DCF per node (read back by the reader in tests/firmware/eds_keys_test.cpp) and writes
# nothing when a node is refused.
# usage: dcf_cli.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
fail() { printf 'FAIL: %s\n' "$*" >&2; exit 1; }
expect() {  # expect OUTPUT_FILE TEXT
  grep -qF -- "$2" "$1" || fail "$(basename "$1"): no line with: $2"
}
out=$(mktemp -d "${TMPDIR:-/tmp}/loom_dcf_cli.XXXXXX")
trap 'rm -rf "$out"' EXIT
eds="$src/tests/drivers/eds"
cp "$eds/acme_ax400_dynamic.eds" "$eds/brick_bx2_fixed.eds" "$eds/tecto_io16.eds" "$out/"

cat >"$out/good.toml" <<'TOML'
extends = "default"
[axes.beat_crank]
eds = "acme_ax400_dynamic.eds"
[axes.helix]
eds = "brick_bx2_fixed.eds"
TOML
"$loomctl" check --config "$out/good.toml" >"$out/good.txt"
expect "$out/good.txt" "axes.helix (node 3)"
expect "$out/good.txt" "brick_bx2_fixed.eds:124: note: axes.helix (node 3): RPDO1 carries {0x6040:00/16, 0x607A:00/32} (fixed mapping, read back at bring-up)"
expect "$out/good.txt" "check: OK"
"$loomctl" dcf --config "$out/good.toml" --out "$out/dcf" >"$out/dcf.txt"
[ -s "$out/dcf/axes_beat_crank.dcf" ] || fail "no axes_beat_crank.dcf"
[ -s "$out/dcf/axes_helix.dcf" ] || fail "no axes_helix.dcf"
grep -q '^NodeID=1$' "$out/dcf/axes_beat_crank.dcf" || fail "axes_beat_crank.dcf: no NodeID=1"
grep -q '^NodeID=3$' "$out/dcf/axes_helix.dcf" || fail "axes_helix.dcf: no NodeID=3"

# The I/O module with two 8-bit input groups cannot carry the default wiring's third.
cat >"$out/io.toml" <<'TOML'
extends = "default"
[io]
eds = "tecto_io16.eds"
TOML
rc=0
"$loomctl" check --config "$out/io.toml" >"$out/io.txt" 2>"$out/io.err" || rc=$?
[ "$rc" = 2 ] || fail "check of a module lacking 0x6000:03 exited $rc, not 2"
expect "$out/io.txt" "tecto_io16.eds:425: error: io (node 4): 0x6000:03 read digital inputs, 8-bit has no sub-index 3"
expect "$out/io.err" "1 node(s) lack what the loom needs"
rc=0
"$loomctl" dcf --config "$out/io.toml" --out "$out/none" >/dev/null 2>"$out/dcf.err" || rc=$?
[ "$rc" = 2 ] || fail "dcf of a refused node exited $rc, not 2"
[ ! -e "$out/none" ] || fail "dcf wrote a folder for a refused configuration"
expect "$out/dcf.err" "no DCF written"
echo "dcf_cli: PASS"
