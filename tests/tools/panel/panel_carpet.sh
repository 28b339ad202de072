#!/usr/bin/env bash
# The panel's carpet view in a real browser (issue 29): `loomctl serve` weaves a small knotted carpet job
# (the narrow sample loom of tests/sim, its 90 x 4 sample design, 6 rows; a second job queued behind it)
# at 10x real time; loom-panel listens to its JOB and CARPET telemetry; headless Chromium checks the job
# queue, the carpet canvas's pixels against the design file (woven rows in their colours, the rest grey),
# rows and ETA advancing, and the yarn levels against magazines.txt (panel_carpet.mjs says how); a second
# panel started late gets the job and the whole knot map within the 10 s repeat. Writes
# <out>/loom_panel_carpet.png. Exit 77 (skip) without chromium or node.
# Usage: panel_carpet.sh <loomctl> <loom-panel> <source dir> <out dir>
set -euo pipefail
here=$(dirname "$0")
. "$here/browser_lib.sh"  # panel_browser_test, fail, panel_and_serve
panel_browser_test carpet 17 "$@"  # LOOMCTL PANEL SRC OUT, WORK, URL, ID
DESIGN=$WORK/rug.csv
cp "$SRC/tests/sim/knot_sample.csv" "$DESIGN"
# The narrow sample loom with a longer deadline for the counters' saves: the deadline is machine time, and at
# 10x real time the default 5 s leaves a sanitizer build's reporter, beside a loaded CI, half a second of
# wall time for each knot cycle's write-ahead (a counters_not_saved there is the machine's rule working,
# not what this test is about).
LOOM=$WORK/loom.toml
cp "$SRC/tests/sim/knot_sample.csv" "$WORK/knot_sample.csv"  # the loom file's recipe.design, beside it
{ cat "$SRC/tests/sim/knotting_sample_loom.toml"; printf '\n[timing]\nrow_save_timeout_s = 60.0\n'; } >"$LOOM"
# A second design (other content, so another job): the sample with its rows in the other order.
{ grep '^palette,' "$DESIGN"; grep -v '^palette,' "$DESIGN" | grep -v '^#' | tac; } >"$WORK/other.csv"
# The simulated weaver answers the heads' requests (misses, reloads) itself after 0.3 s.
cat >"$WORK/scene.toml" <<'TOML'
name = "panel_carpet"
seed = 29
effects = ["ideal", "knotter"]
[knotter]
miss_probability = 0.01
weaver_s = 0.3
TOML
mkdir -p "$WORK/run" "$WORK/state"
"$LOOMCTL" job add "$DESIGN" --config "$LOOM" --state-dir "$WORK/state" --rows 6 >/dev/null || fail "job add"
"$LOOMCTL" job add "$WORK/other.csv" --config "$LOOM" --state-dir "$WORK/state" --rows 2 >/dev/null || fail "job add 2"

panel_and_serve --config "$LOOM" --scene "$WORK/scene.toml" --pace 10

# A panel that joins late (serve armed and standing, nothing changes): JOB and the whole knot map reach it
# within the 10 s repeat.
FIRST_BASE=$PANEL_BASE
panel_up late.log --lcm-url "$URL"
LATE_BASE=$PANEL_BASE
PANEL_BASE=$FIRST_BASE
late_ok=
for _ in $(seq 1 150); do
  if curl -s -m 2 "$LATE_BASE/api/loom/$ID" | python3 -c '
import json, sys
d = json.load(sys.stdin)
sys.exit(0 if d.get("job") and d["job"]["id"] == 1 and d.get("carpet") and d["carpet"]["rows_heard"] == 4 else 1)' 2>/dev/null
  then late_ok=1; break; fi
  sleep 0.1
done
[[ -n $late_ok ]] || fail "a panel started late did not get JOB and the whole knot map within 15 s"
echo "a panel started late got JOB and the 4-row knot map"

# The weaver's answers, should the simulated weaver leave one open (ctl next, as a weaver at the loom).
( while sleep 0.5; do
    "$LOOMCTL" ctl --socket "$SOCK" status 2>/dev/null | grep -q '^open: weaver' &&
      "$LOOMCTL" ctl --socket "$SOCK" next >/dev/null 2>&1 || true
  done ) &
PIDS+=("$!")

node --experimental-websocket "$here/panel_carpet.mjs" "$CHROMIUM" "$PANEL_BASE" "$ID" "$OUT/loom_panel_carpet.png" 170 \
  "$LOOMCTL" "$SOCK" "$DESIGN" "$WORK/state" 6 2>&1 | grep -v ExperimentalWarning | grep -v "node --trace-warnings" ||
  fail "browser check failed"
[ -s "$OUT/loom_panel_carpet.png" ] || fail "no screenshot written"
