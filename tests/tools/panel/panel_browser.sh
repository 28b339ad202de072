#!/usr/bin/env bash
# loom-panel in a real browser: a simulated loom weaves in real time (4x) on a private LCM URL, the
# panel listens on it, and headless Chromium (driven over the DevTools protocol by panel_browser.mjs)
# must see the row count advance and every beat force of the row drawn in the 80-100 N band.
# Writes <build>/panel/loom_panel.png and loom_panel_hall.png. Exit 77 (skip) when chromium or node is missing.
# Usage: panel_browser.sh <loomctl> <loom-panel> <out dir>
set -euo pipefail
LOOMCTL=$1
PANEL=$2
OUT=$3
fail() { echo "FAIL: $*" >&2; exit 1; }
. "$(dirname "$0")/browser_lib.sh"
have_browser || exit 77
mkdir -p "$OUT"
WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom_panel_browser.XXXXXX")
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  rm -rf "$WORK"
}
trap cleanup EXIT

PORT=$((20000 + ($$ * 7) % 20000))
URL="udpm://239.255.76.67:${PORT}?ttl=0"
ID="panel$$"

panel_up panel.err --lcm-url "$URL"

# 3 rows at 4x real time: about 6 s of wall time per 3 rows... a row every ~1.9 s.
"$LOOMCTL" weave --rows 6 --realtime --pace 4 --lcm-url "$URL" --loom-id "$ID" --quiet >"$WORK/weave.out" 2>&1 &
PIDS+=($!)

node --experimental-websocket "$(dirname "$0")/panel_browser.mjs" "$CHROMIUM" "$PANEL_BASE" "$ID" \
  "$OUT/loom_panel.png" 60 2>&1 | grep -v ExperimentalWarning | grep -v "node --trace-warnings" || fail "browser check failed"
[ -s "$OUT/loom_panel.png" ] || fail "no screenshot written"
