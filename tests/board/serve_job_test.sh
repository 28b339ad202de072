#!/usr/bin/env bash
# serve weaves the carpet job queue of its state directory (simulated knotting loom, paced):
#   1. armed with a queued job: `ctl status` names it (job=1 job_row=1/2 job_state=queued); `ctl start`
#      starts it at the machine (journal: "started at the machine by local user ...");
#   2. the weaver answers the heads' requests — a slot to reload with `ctl reload HEAD SLOT` (audited; the
#      heads go on), the rest with ctl next — and the loom weaves the job's rows and no more (at arming
#      the journal forecast which slots run out in which row):
#      at its last row the journal says "carpet done", status says state=carpet_done, and with nothing
#      queued a start is refused with the reason (exit 1) — the design does not repeat;
#   3. a restart on the same state directory arms standing (carpet_done), a start still refused;
#   4. the queue through serve's socket (the offline `loomctl job add` is refused while serve runs): ctl job
#      list; ctl job add (a relative path, made absolute) arms the standing loom with it, without a start;
#      ctl job remove of that armed job arms it standing again; ctl job start-over 1 queues the finished
#      carpet again (weaving 2) and the loom arms it; while it weaves, start-over and remove of it are
#      refused with the reason; every change is audited (ctl faults); the queue on disk says so after.
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

# 2. the weaver answers the heads until the carpet is done. The forecast is said when the arming ends, which
# may come after the start: a start sent while the service arms is taken once it is armed.
logged "yarn: head [0-9] slot [0-9] (colour ., [0-9]* knots left) runs out in row [0-9]" "$work/serve1.log" ||
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
# The socket answers while the service still arms (the status then says idle); once armed it stands in
# carpet_done (read once, right after the socket opened, it failed once in a full suite: state=idle).
end=$((SECONDS + 20))
until status=$(ctl status | head -1) && [[ $status == *" state=carpet_done "* ]]; do
  ((SECONDS < end)) || fail "restart does not stand in carpet_done: $status"
  sleep 0.05
done
rc=0
ctl start >/dev/null 2>&1 || rc=$?
[[ $rc == 1 ]] || fail "start after the restart not refused (exit $rc)"

# 4. the job queue through serve's socket
rc=0
out=$("$loomctl" job add "$src/tests/sim/knot_sample.csv" --config "$loom" --state-dir "$work/state" 2>&1) || rc=$?
[[ $rc == 2 && $out == *"loomctl ctl job add"* ]] || fail "offline job add while serve runs: '$out' (exit $rc)"
ctl job list | grep -q '^1 .*carpet_done .*all 2 rows woven' || fail "ctl job list: $(ctl job list)"
# Wait until status shows `want` (the re-arm after a change takes a moment).
status_has() {
  local end=$((SECONDS + 30))
  while ((SECONDS < end)); do
    [[ $(ctl status | head -1) == *"$1"* ]] && return 0
    sleep 0.05
  done
  fail "status never showed '$1': $(ctl status | head -1)"
}
reply=$(cd "$src/tests/sim" && ctl job add knot_sample.csv --rows 1) || fail "ctl job add: $reply"
[[ $reply == "ok job add: job 2: knot_sample.csv (sha256 "*"), 1 row, queued; the loom arms it (start it at the machine)" ]] ||
  fail "ctl job add: $reply"
status_has " job=2 job_row=1/1 job_state=queued"
logged "the job queue changed while the loom stood: arming again from it" "$work/serve2.log" ||
  fail "no re-arm after job add"
[[ $(field state) == idle && $(field rows) == 2 ]] || fail "job add moved the loom: $(ctl status | head -1)"
ctl job show 2 | grep -q "^  file        $src/tests/sim/knot_sample.csv$" || fail "ctl job show 2: $(ctl job show 2)"
reply=$(ctl job remove 2) || fail "ctl job remove 2: $reply"
[[ $reply == "ok job remove: job 2 removed from the queue (its record stays)" ]] || fail "ctl job remove 2: $reply"
status_has " state=carpet_done "
rc=0
reply=$(ctl job remove 2 2>&1) || rc=$?
[[ $rc == 1 && $reply == "refused: job remove: "* ]] || fail "remove of a removed job: '$reply' (exit $rc)"
reply=$(ctl job start-over 1) || fail "ctl job start-over 1: $reply"
[[ $reply == "ok job start-over: job 1 starts over at row 1 (queued, weaving 2)" ]] || fail "start-over: $reply"
status_has " job=1 job_row=1/2 job_state=queued"
# At once: the start goes with the re-arm (it is not refused for the carpet_done the loom armed with).
reply=$(ctl start 2>&1) || fail "start of the job started over not accepted: $reply; $(ctl status | head -1)"
end=$((SECONDS + 30))
while [[ $(field state) == idle || $(field state) == done ]]; do
  ((SECONDS < end)) || fail "the job started over does not weave: $(ctl status | head -1)"
  sleep 0.05
done
status_has " job=1 job_row=1/2"
for verb in start-over remove; do
  rc=0
  reply=$(ctl job "$verb" 1 2>&1) || rc=$?
  [[ $rc == 1 && $reply == "refused: job $verb: the loom is weaving job 1 (state "*"): stop it at the row end first (ctl stop)" ]] ||
    [[ $rc == 1 && $verb == remove && $reply == "refused: job remove: "*"current"* ]] ||
    fail "ctl job $verb 1 while weaving: '$reply' (exit $rc)"
done
ctl faults | grep -q " job add .*: ok job add: job 2" || fail "job add not audited: $(ctl faults | tail -5)"
ctl faults | grep -q " job start-over .*: ok job start-over: job 1" || fail "start-over not audited"
logged "operator: job remove by local user .*: refused: job remove" "$work/serve2.log" ||
  fail "the refused remove is not in the journal"
kill -TERM "$pid"; wait "$pid" || true; pid=
queue=$("$loomctl" job list --state-dir "$work/state")
grep -q '^1 .*current ' <<<"$queue" && grep -q '^2 .*removed ' <<<"$queue" || fail "the queue: $queue"
"$loomctl" job show 1 --state-dir "$work/state" | grep -q "^  weaving     2 " || fail "job 1 is not in its weaving 2"
echo "serve_job: ok"
