#!/usr/bin/env bash
# The weaver's panel in knotting mode, end to end: `loomctl serve` weaves the simulated loom (4x real
# time) with a knotting recipe and a test design; loom-panel listens to its LCM telemetry and offers
# operator buttons through serve's control socket; headless Chromium checks that the page shows design
# row 1's colour codes while the loom waits, presses "Row knotted", and sees row 1 woven and design
# row 2 shown. Writes <out>/loom_panel_knotting.png. Exit 77 (skip) without chromium or node.
# Usage: panel_knotting.sh <loomctl> <loom-panel> <design csv> <out dir>
set -euo pipefail
LOOMCTL=$1
PANEL=$2
DESIGN=$3
OUT=$4
here=$(dirname "$0")
. "$(dirname "$0")/browser_lib.sh"  # fail, have_browser, panel_work, panel_lcm_url, panel_and_serve
have_browser || exit 77
mkdir -p "$OUT"
panel_work knotting
panel_lcm_url 11
ID="knot$$"
cp "$DESIGN" "$WORK/$(basename "$DESIGN")"
printf 'extends = "default"\n[knotting]\nmode = "weaver"\n[recipe]\ndesign = "%s"\n' "$(basename "$DESIGN")" >"$WORK/loom.toml"

# What the page must show: design row 1 is the file's last grid line, row 2 the one above it.
rows_json=$(grep -v '^[[:space:]]*#' "$DESIGN" | grep -v '^palette,' | grep -v '^[[:space:]]*$' | tac | head -2 |
  sed 's/[[:space:]]//g; s/,/","/g; s/^/["/; s/$/"]/' | paste -sd, | sed 's/^/[/; s/$/]/')
height=$(grep -v '^[[:space:]]*#' "$DESIGN" | grep -v '^palette,' | grep -vc '^[[:space:]]*$')

panel_and_serve --config "$WORK/loom.toml" --pace 4
"$LOOMCTL" ctl --socket "$SOCK" start >/dev/null || fail "serve did not take start"
# "Row knotted" starts motion: the panel offers it only to a device paired at the loom.
CODE=$("$LOOMCTL" ctl --socket "$SOCK" pair knot-test | sed -n 's/.*code=\([0-9]*\).*/\1/p')
[ -n "$CODE" ] || fail "ctl pair printed no code"

node --experimental-websocket "$here/panel_knotting.mjs" "$CHROMIUM" "$PANEL_BASE" "$ID" "$OUT/loom_panel_knotting.png" 80 \
  "$rows_json" "$height" "$CODE" 2>&1 | grep -v ExperimentalWarning | grep -v "node --trace-warnings" ||
  fail "browser check failed"
grep -q "$ID next by 127.0.0.1 (token) -> ok next" "$WORK/panel.log" || fail "the panel did not log the button it sent"
grep -q 'operator: next by panel client 127.0.0.1 paired as knot-test' "$WORK/serve.log" ||
  fail "serve did not receive the panel's next naming the paired client"
[ -s "$OUT/loom_panel_knotting.png" ] || fail "no screenshot written"
