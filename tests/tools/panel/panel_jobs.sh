#!/usr/bin/env bash
# The job queue's buttons in a real browser (issue 29): `loomctl serve` (the narrow sample knotting loom of
# tests/sim at 10x real time) weaves a 1-row job while headless Chromium checks, on the loom's page
# (panel_jobs.mjs says how), that an unpaired device sees Start over / Remove / Add job disabled and that its
# forced POSTs are refused by the panel (403); then, paired with `ctl pair` and the page's pairing field, it
# adds a job (a design file and a length), removes it, and starts over the carpet_done job, each with the
# loom's reply shown. Here: serve's journal has exactly those three `operator: job` lines, from the paired
# panel client, and none of the unpaired attempts (they never reached the loom); `ctl faults` audits the
# three; GET /jobs reads the queue as rows; a malformed POST is refused with the reason. Writes
# <out>/loom_panel_jobs.png. Exit 77 (skip) without chromium or node.
# Usage: panel_jobs.sh <loomctl> <loom-panel> <source dir> <out dir>
set -euo pipefail
here=$(dirname "$0")
. "$here/browser_lib.sh"  # panel_browser_test, fail, panel_and_serve
panel_browser_test jobs 19 "$@"  # LOOMCTL PANEL SRC OUT, WORK, URL, ID
LOOM=$SRC/tests/sim/knotting_sample_loom.toml
DESIGN=$WORK/rug.csv
cp "$SRC/tests/sim/knot_sample.csv" "$DESIGN"
# The simulated weaver answers the heads' requests (reloads) itself after 0.3 s.
cat >"$WORK/scene.toml" <<'TOML'
name = "panel_jobs"
seed = 29
effects = ["ideal", "knotter"]
[knotter]
miss_probability = 0.0
weaver_s = 0.3
TOML
mkdir -p "$WORK/state"
"$LOOMCTL" job add "$DESIGN" --config "$LOOM" --state-dir "$WORK/state" --rows 1 >/dev/null || fail "job add"
panel_and_serve --config "$LOOM" --scene "$WORK/scene.toml" --pace 10
ctl() { "$LOOMCTL" ctl --socket "$SOCK" "$@"; }
# Job 1 is woven (one row, at the machine) while the page is checked unpaired.
ctl start >/dev/null || fail "serve did not take start"
CODE=$(ctl pair job-tablet | sed -n 's/.*code=\([0-9]*\).*/\1/p')
[[ -n $CODE ]] || fail "ctl pair printed no code"

node --experimental-websocket "$here/panel_jobs.mjs" "$CHROMIUM" "$PANEL_BASE" "$ID" "$OUT/loom_panel_jobs.png" 80 \
  "$CODE" "$DESIGN" 2>&1 | grep -v ExperimentalWarning | grep -v "node --trace-warnings" || fail "browser check failed"

# The journal: the three changes from the paired client, nothing of the unpaired ones.
journal=$(grep "operator: job " "$WORK/serve.log" || true)
[[ $(grep -c . <<<"$journal") == 3 ]] || fail "serve's journal has not exactly 3 job lines: $journal"
for pair in "add|ok job add: job 2: rug.csv" "remove|ok job remove: job 2 removed" \
  "start-over|ok job start-over: job 1 starts over at row 1"; do
  verb=${pair%%|*} said=${pair#*|}
  grep -q "operator: job $verb by panel client 127.0.0.1 paired as job-tablet .*: $said" <<<"$journal" ||
    fail "serve's journal lacks job $verb from the paired panel client: $journal"
  ctl faults | grep -q " command $ID job $verb .*: by panel client 127.0.0.1 paired as job-tablet .*: $said" ||
    fail "ctl faults does not audit job $verb: $(ctl faults | tail -5)"
done
# The queue as rows (GET, anyone), and one job's text.
curl -sf -m 5 "$PANEL_BASE/api/loom/$ID/jobs" | python3 -c '
import json, sys
d = json.load(sys.stdin)
got = [(j["id"], j["state"], j["design"]) for j in d["jobs"]]
want = [(1, "queued", "rug.csv"), (2, "removed", "rug.csv")]
sys.exit(0 if got == want else "GET /jobs: %r, want %r" % (got, want))' || fail "GET /jobs"
curl -sf -m 5 "$PANEL_BASE/api/loom/$ID/jobs?id=1" | grep -q '"text":"job 1: queued' || fail "GET /jobs?id=1"
# A malformed request is refused by the panel with the reason (400), before the pairing is even looked at.
post() { curl -s -m 5 -o "$WORK/reply.json" -w '%{http_code}' -X POST -H 'X-Loom-Panel: 1' --data "$2" "$PANEL_BASE/api/loom/$ID/job/$1"; }
[[ $(post add "design=rug.csv") == 400 ]] && grep -q "an absolute path" "$WORK/reply.json" ||
  fail "a relative design path: $(cat "$WORK/reply.json")"
[[ $(post add "design=/x.csv%20token=0&rows=1") == 400 ]] || fail "a path with a space: $(cat "$WORK/reply.json")"
[[ $(post start "id=1") == 400 ]] || fail "job start from the panel: $(cat "$WORK/reply.json")"
[[ $(grep -c "operator: job " "$WORK/serve.log") == 3 ]] || fail "a malformed POST reached the loom"
[ -s "$OUT/loom_panel_jobs.png" ] || fail "no screenshot written"
echo "panel_jobs: ok"
