#!/usr/bin/env bash
# The panel's knotting-heads view in a real browser: `loomctl serve` weaves the simulated loom with its six
# heads (firmware/config/knotting_loom.toml, scene sim_hal/scenes/knotting.toml, 4x real time); loom-panel
# listens to its telemetry; headless Chromium watches the row being tied knot by knot (the cycle and the
# tied knots advance, the knot in progress outlined) and every head's magazine levels going down, as the
# loom's own counters say. Writes <out>/loom_panel_heads.png. Exit 77 (skip) without chromium or node.
# Usage: panel_heads.sh <loomctl> <loom-panel> <source dir> <out dir>
set -euo pipefail
here=$(dirname "$0")
. "$here/browser_lib.sh"  # panel_browser_test, fail, panel_and_serve
panel_browser_test heads 13 "$@"  # LOOMCTL PANEL SRC OUT, WORK, URL, ID
panel_and_serve --config "$SRC/firmware/config/knotting_loom.toml" --scene "$SRC/sim_hal/scenes/knotting.toml" \
  --pace 4
"$LOOMCTL" ctl --socket "$SOCK" start >/dev/null || fail "serve did not take start"

# (130 s in all: each of its two waits may take 60 s on a loaded machine; the test's limit is 150 s)
node --experimental-websocket "$here/panel_heads.mjs" "$CHROMIUM" "$PANEL_BASE" "$ID" "$OUT/loom_panel_heads.png" 130 \
  2>&1 | grep -v ExperimentalWarning | grep -v "node --trace-warnings" || fail "browser check failed"
[ -s "$OUT/loom_panel_heads.png" ] || fail "no screenshot written"
