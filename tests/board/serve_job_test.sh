#!/usr/bin/env bash
# serve weaves the carpet job queue of its state directory (simulated knotting loom, paced):
#   1. armed with a queued job: `ctl status` names it (job=1 job_row=1/2 job_state=queued); `ctl start`
#      starts it at the machine (journal: "started at the machine by local user ...");
#   2. the weaver answers the heads' requests — a slot to reload with `ctl reload HEAD SLOT` (audited; the
#      heads go on), the rest with ctl next — and the loom weaves the job's rows and no more (at arming
#      the journal forecast which slots run out in which row):
#      at its last row the journal says "carpet done", status says state=carpet_done, and with nothing
#      queued a start is refused with the reason (exit 1) — the design does not repeat;
#   3. a restart on the same state directory arms standing (carpet_done), a start still refused; the
#      job queue says carpet_done with all its rows.
# Usage: serve_job_test.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
. "$(dirname "$0")/lib.sh"  # board_work, fail, ctl
board_work serve_job
loom=$src/tests/sim/knotting_sample_loom.toml
field() { ctl status | head -1 | tr ' ' '\n' | sed -n "s/^$1=//p"; }
cat >"$work/scene.toml" <<'TOML'
name = "serve_job"
seed = 5
effects = ["ideal", "knotter"]
[knotter]
miss_probability = 0.02
# the simulated weaver would take an hour: the test answers the heads itself
weaver_s = 3600
TOML
start_serve() {
  "$loomctl" serve --config "$loom" --scene "$work/scene.toml" --state-dir "$work/state" --socket "$sock" \
    --group "" --no-telemetry --pace "${LOOM_BOARD_PACE:-40}" >"$work/$1" 2>&1 &
  pid=$!
  local end=$((SECONDS + 20))
  while ((SECONDS < end)); do
    [[ -S $sock ]] && ctl status >/dev/null 2>&1 && return 0
    kill -0 "$pid" 2>/dev/null || fail "serve exited early"
    sleep 0.05
  done
  fail "serve did not open its control socket"
}
mkdir -p "$work/state"
"$loomctl" job add "$src/tests/sim/knot_sample.csv" --config "$loom" --state-dir "$work/state" --rows 2 >/dev/null

# 1. a queued job, started at the machine
start_serve serve1.log
status=$(ctl status | head -1)
[[ $status == *" job=1 job_row=1/2 job_state=queued"* ]] || fail "status does not name the queued job: $status"
ctl start | grep -q '^ok start' || fail "start not accepted"
logged "job 1 (design knot_sample.csv, sha256 [0-9a-f]*\.\.): row 1 of 2 next: started at the machine by local user" \
  "$work/serve1.log" || fail "the job's start is not in the journal"

# 2. the weaver answers the heads until the carpet is done
grep -q "yarn: head [0-9] slot [0-9] (colour ., [0-9]* knots left) runs out in row [0-9]" "$work/serve1.log" ||
  fail "no yarn forecast in the journal at arming"
reloads=0
end=$((SECONDS + 120))
while ((SECONDS < end)); do
  out=$(ctl status)
  [[ $(sed -n 's/.* state=\([a-z_]*\) .*/\1/p' <<<"$out" | head -1) == carpet_done ]] && break
  ask=$(grep '^open: weaver' <<<"$out" || true)
  if [[ $ask =~ "reload colour "[A-Z]" into slot "([0-9])" of head "([0-9]) ]]; then
    head=${BASH_REMATCH[2]} slot=${BASH_REMATCH[1]}
    reply=$(ctl reload "$head" "$slot" 2>&1) || fail "ctl reload $head $slot: $reply"
    [[ $reply == "ok reload head $head slot $slot: full" ]] || fail "ctl reload $head $slot: $reply"
    reloads=$((reloads + 1))
  elif [[ -n $ask ]]; then
    ctl next >/dev/null 2>&1 || true
  fi
  sleep 0.1
done
((reloads > 0)) || fail "no reload was asked for and answered with ctl reload"
ctl faults | grep -q " reload .*: ok reload head [0-9] slot [0-9]: full" || fail "the reload is not audited: $(ctl faults | tail -5)"

status=$(ctl status | head -1)
[[ $status == *" state=carpet_done "* && $status == *" rows=2 "* && $status == *" carpet_done_job=1"* ]] ||
  fail "not carpet_done after the job's 2 rows: $status"
logged "^carpet done: job 1, its last row woven (rows 2)" "$work/serve1.log" || fail "no carpet done line in the journal"
rc=0
reply=$(ctl start 2>&1) || rc=$?
[[ $rc == 1 && $reply == "refused: start: no carpet job to weave: job 1 is carpet_done"* ]] ||
  fail "start with nothing queued: '$reply' (exit $rc)"
sleep 1
[[ $(field rows) == 2 ]] || fail "the loom wove on after the carpet: $(ctl status)"

# 3. a restart stands too
kill -TERM "$pid"; wait "$pid" || fail "serve exited $? on SIGTERM"; pid=
start_serve serve2.log
status=$(ctl status | head -1)
[[ $status == *" state=carpet_done "* ]] || fail "restart does not stand in carpet_done: $status"
rc=0
ctl start >/dev/null 2>&1 || rc=$?
[[ $rc == 1 ]] || fail "start after the restart not refused (exit $rc)"
kill -TERM "$pid"; wait "$pid" || true; pid=
"$loomctl" job list --state-dir "$work/state" | grep -q '^1 .*carpet_done .*all 2 rows woven' ||
  fail "the queue: $("$loomctl" job list --state-dir "$work/state")"
echo "serve_job: ok"
