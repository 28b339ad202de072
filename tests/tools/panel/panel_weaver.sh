#!/usr/bin/env bash
# The weaver answers the knotting heads from the panel (issue 30): `loomctl serve` weaves the six-head
# loom with a broken yarn (sim_hal/scenes/knotting_faults.toml: the heads ask the weaver to tie a knot by
# hand); loom-panel offers buttons through serve's control socket; headless Chromium pairs the page with
# a code from `loomctl ctl pair`, sees the heads' request and a button that answers it (before: only
# Pause and Stop while the heads waited), presses it, and serve's journal says the panel client's `next`
# answered that request. Writes <out>/loom_panel_weaver.png. Exit 77 (skip) without chromium or node.
# Usage: panel_weaver.sh <loomctl> <loom-panel> <source dir> <out dir>
set -euo pipefail
here=$(dirname "$0")
. "$here/browser_lib.sh"  # panel_browser_test, fail, panel_and_serve
panel_browser_test weaver 17 "$@"  # LOOMCTL PANEL SRC OUT, WORK, URL, ID
# The scene's simulated weaver answers a request after weaver_s of machine time (15 s: 3.75 s of wall
# time at --pace 4). Here the panel must answer first, so the test's copy of the scene gives the simulated
# weaver ten minutes: otherwise a loaded CI (the sanitizer build's Chromium) loses the race to it.
sed -e 's/^weaver_s = .*/weaver_s = 600.0/' -e '/^config = /d' "$SRC/sim_hal/scenes/knotting_faults.toml" \
  >"$WORK/knotting_faults.toml"
grep -q '^weaver_s = 600.0$' "$WORK/knotting_faults.toml" || fail "knotting_faults.toml has no weaver_s to slow down"
panel_and_serve --config "$SRC/firmware/config/knotting_loom.toml" --scene "$WORK/knotting_faults.toml" --pace 4
CODE=$("$LOOMCTL" ctl --socket "$SOCK" pair weaver-tablet | sed -n 's/.*code=\([0-9]*\).*/\1/p')
[ -n "$CODE" ] || fail "ctl pair printed no code"
"$LOOMCTL" ctl --socket "$SOCK" start >/dev/null || fail "serve did not take start"
node --experimental-websocket "$here/panel_weaver.mjs" "$CHROMIUM" "$PANEL_BASE" "$ID" "$OUT/loom_panel_weaver.png" 100 \
  "$CODE" 2>&1 | grep -v ExperimentalWarning | grep -v "node --trace-warnings" || fail "browser check failed"
asked=$(sed -n 's/^.*weaver asked: //p' "$WORK/serve.log" | head -1)
[[ -n $asked ]] || fail "serve never logged the heads' request"
grep -q "operator: next by panel client 127.0.0.1 paired as weaver-tablet .*: ok next: answered " "$WORK/serve.log" ||
  fail "serve's journal does not say the panel's next answered the heads' request"
[ -s "$OUT/loom_panel_weaver.png" ] || fail "no screenshot written"
echo "panel_weaver: ok (the heads asked: $asked)"
