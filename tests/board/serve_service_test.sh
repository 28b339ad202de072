#!/usr/bin/env bash
# loomctl serve as a service, from the outside (simulated loom, paced, no telemetry):
#   1. one serve per state directory: a second serve on the same --state-dir (another --socket, the
#      same loom id) refuses to arm, exit 4, naming the first one's pid and socket;
#   2. systemd's protocol spoken to a stand-in receiver ($NOTIFY_SOCKET): READY=1 once armed, WATCHDOG=1
#      while the loop ticks; the loop thread alone is stalled (ptrace-stopped, the rest of the process
#      runs): the pings stop; the stalled serve is killed and restarted as systemd would, and comes back
#      armed and waiting (state idle) at the same counts — never into motion; the control socket's thread
#      alone stalled: the pings stop too (operators would get no answer), and the journal says so;
#   3. one publisher per loom id: a serve with another state directory but the same loom id hears the
#      first one's IDENTITY on the LCM group and refuses to arm, exit 4, naming its host and pid; a serve
#      with another id arms beside it;
#   4. a full disk (a tiny tmpfs, in a private mount namespace): a fresh sim-state file is refused with
#      the reason (no SIGBUS); and when the disk fills while weaving, the row stops with
#      counters_not_saved, `ctl ack` is refused while the save still fails (the fault stays), and once
#      the disk has room the retried save lets the ack through, re-arming at the woven count — never the
#      file's older one; a fault latched on the full disk is kept (the service's reserve of disk room),
#      a restart on the still full disk refuses to arm, and with room again the fault is latched again.
# Usage: serve_service_test.sh LOOMCTL
set -euo pipefail
loomctl=$1
# A private mount namespace for the tmpfs (as root: unshare -m; otherwise a user namespace maps us to root).
if [[ -z ${LOOM_IN_NS:-} ]]; then
  if [[ $(id -u) == 0 ]]; then ns=(unshare -m --propagation private); else ns=(unshare -rm); fi
  LOOM_IN_NS=1 exec "${ns[@]}" "$0" "$@"
fi
work=$(mktemp -d /tmp/loom_service_test.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null || true; done
  mountpoint -q "$work/disk" 2>/dev/null && umount "$work/disk"
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; for f in "$work"/*.log; do echo "--- $f" >&2; tail -20 "$f" >&2; done; exit 1; }
ctl() { "$loomctl" ctl --socket "$1" "${@:2}"; }
field() { ctl "$1" status | tr ' ' '\n' | sed -n "s/^$2=//p"; }
# Stops one thread of serve (PTRACE_SEIZE + PTRACE_INTERRUPT stop one thread, not the process) from a
# helper process ($stall, killed at exit) that holds it for 60 s; WHAT names the thread in the failure.
stop_thread() {  # stop_thread TID WHAT
  rm -f "$work/stalled"
  python3 - "$1" "$work/stalled" <<'PY' &
import ctypes, sys, time
libc = ctypes.CDLL(None, use_errno=True)
tid = int(sys.argv[1])
if libc.ptrace(0x4206, tid, 0, 0) != 0 or libc.ptrace(0x4207, tid, 0, 0) != 0:
    sys.exit(f"ptrace: errno {ctypes.get_errno()}")
open(sys.argv[2], "w").close()
time.sleep(60)
PY
  stall=$!
  pids+=("$stall")
  for _ in $(seq 1 200); do [[ -e $work/stalled ]] && break; sleep 0.05; done
  [[ -e $work/stalled ]] || fail "could not stop $2"
}
# Waits are bounded in seconds, not in polls: under a sanitizer on a loaded machine one `ctl status` can
# take longer than a row (0.3 s at --pace 25), so a row count is waited for as "at least" (wait_rows).
wait_for() {  # wait_for SOCKET FIELD VALUE SECONDS
  local end=$((SECONDS + $4))
  while ((SECONDS < end)); do [[ $(field "$1" "$2" 2>/dev/null) == "$3" ]] && return 0; sleep 0.05; done
  fail "waited $4 s for $2=$3: $(ctl "$1" status 2>&1)"
}
wait_rows() {  # wait_rows SOCKET N SECONDS: at least N rows woven
  local end=$((SECONDS + $3)) n
  while ((SECONDS < end)); do
    n=$(field "$1" rows 2>/dev/null)
    [[ -n $n ]] && ((n >= $2)) && return 0
    sleep 0.05
  done
  fail "waited $3 s for rows >= $2: $(ctl "$1" status 2>&1)"
}
serve() {  # serve LOG STATE SOCKET [extra]: starts serve in the background, sets $last (telemetry off
  local log=$1 state=$2 sock=$3; shift 3  # unless the extra arguments give --lcm-url)
  local tm=(--no-telemetry)
  [[ " $* " == *" --lcm-url "* ]] && tm=()
  "$loomctl" serve --state-dir "$state" --socket "$sock" --group "" "${tm[@]}" --pace 25 "$@" >"$work/$log" 2>&1 &
  last=$!
  pids+=("$last")
}
wait_socket() {
  for _ in $(seq 1 200); do ctl "$1" status >/dev/null 2>&1 && return 0; sleep 0.05; done
  fail "no control socket $1"
}

# ---- 1. one serve per state directory ----
serve a.log "$work/state" "$work/a.sock"
a=$last
wait_socket "$work/a.sock"
rc=0
"$loomctl" serve --state-dir "$work/state" --socket "$work/b.sock" --group "" --no-telemetry >"$work/b.log" 2>&1 || rc=$?
[[ $rc == 4 ]] || fail "a second serve on the same state directory exited $rc, not 4"
grep -q "in use by another loomctl serve or weave (pid=$a .*socket=$work/a.sock" "$work/b.log" || fail "the refusal does not name the first serve: $(cat "$work/b.log")"
[[ ! -e $work/b.sock ]] || fail "the refused serve opened a control socket"
[[ $(field "$work/a.sock" state) == idle ]] || fail "the first serve was disturbed"
kill -TERM "$a"; wait "$a" || fail "serve exited $? on SIGTERM"
echo "one serve per state directory: ok"

# ---- 2. READY=1, the watchdog fed only while the loop ticks, a restart that waits ----
notify=$work/notify.sock
python3 - "$notify" >"$work/notify.txt" <<'PY' &
import socket, sys, time
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1])
t0 = time.monotonic()
while True:
    msg = s.recv(4096).decode()
    print(f"{time.monotonic() - t0:.3f} {msg.replace(chr(10), ' ')}", flush=True)
PY
pids+=($!)
for _ in $(seq 1 100); do [[ -S $notify ]] && break; sleep 0.05; done
NOTIFY_SOCKET=$notify WATCHDOG_USEC=1000000 serve w.log "$work/wstate" "$work/w.sock"
w=$last
wait_socket "$work/w.sock"
ctl "$work/w.sock" start >/dev/null
wait_rows "$work/w.sock" 1 30
sleep 1.5
grep -q "READY=1" "$work/notify.txt" || fail "no READY=1: $(cat "$work/notify.txt")"
pings_before=$(grep -c "WATCHDOG=1" "$work/notify.txt" || true)
((pings_before >= 2)) || fail "the watchdog was not fed while the loop ran ($pings_before pings)"
rt=$(grep -l '^loom-rt$' /proc/"$w"/task/*/comm | head -1 | cut -d/ -f5)
[[ -n $rt ]] || fail "no loom-rt thread in serve $w"
stop_thread "$rt" "the loop thread"
for _ in $(seq 1 40); do [[ $(cut -d' ' -f3 /proc/"$w"/task/"$rt"/stat) == t ]] && break; sleep 0.05; done
[[ $(cut -d' ' -f3 /proc/"$w"/task/"$rt"/stat) == t ]] || fail "the loop thread did not stop"
sleep 0.5
n0=$(grep -c "WATCHDOG=1" "$work/notify.txt" || true)
sleep 2.5
n1=$(grep -c "WATCHDOG=1" "$work/notify.txt" || true)
[[ $n1 == "$n0" ]] || fail "the watchdog was fed while the loop thread was stopped ($n0 → $n1 pings)"
kill -0 "$w" || fail "serve died instead of stalling"
rows_at_stall=$(grep -o '"rows":[0-9]*' "$work/wstate/counters.json" | cut -d: -f2)
# What systemd does when WATCHDOG=1 stops coming: kill (SIGABRT, here SIGKILL) and restart.
kill -9 "$w" "$stall" 2>/dev/null || true
wait "$w" 2>/dev/null || true
NOTIFY_SOCKET=$notify WATCHDOG_USEC=1000000 serve w2.log "$work/wstate" "$work/w.sock"
wait_socket "$work/w.sock"
[[ $(field "$work/w.sock" state) == idle ]] || fail "restarted after the stall not waiting: $(ctl "$work/w.sock" status)"
sleep 1
[[ $(field "$work/w.sock" state) == idle ]] || fail "restarted serve moved without a start: $(ctl "$work/w.sock" status)"
[[ $(field "$work/w.sock" rows) == "$rows_at_stall" ]] || fail "restart lost or repeated rows: $(ctl "$work/w.sock" status), file had $rows_at_stall"
(($(grep -c "READY=1" "$work/notify.txt") == 2)) || fail "the restarted serve did not say READY=1"
# The control socket's thread stalled alone (a handler stuck on a hung disk; issue 30: pings went on
# while operators got no answer for 12 s): the pings stop too, and the journal says why.
ctl "$work/w.sock" start >/dev/null
wait_rows "$work/w.sock" $((rows_at_stall + 1)) 30
cth=$(grep -l '^loom-ctl$' /proc/"$last"/task/*/comm | head -1 | cut -d/ -f5)
[[ -n $cth ]] || fail "no loom-ctl thread in serve $last"
stop_thread "$cth" "the control socket's thread"
sleep 1
c0=$(grep -c "WATCHDOG=1" "$work/notify.txt" || true)
sleep 2.5
c1=$(grep -c "WATCHDOG=1" "$work/notify.txt" || true)
[[ $c1 == "$c0" ]] || fail "the watchdog was fed while the control socket's thread was stopped ($c0 → $c1 pings)"
grep -q "the control socket's thread has not come round" "$work/w2.log" || fail "the journal does not say the control thread hung"
kill -9 "$last" "$stall" 2>/dev/null || true
wait "$last" 2>/dev/null || true
echo "watchdog: $pings_before pings while running, none in 2.5 s with the loop stopped, restart waits at row $rows_at_stall;" \
  "none in 2.5 s with the control socket's thread stopped: ok"

# ---- 3. one publisher per loom id (an LCM group of this test's own: host-only, a port per run) ----
url="udpm://239.255.76.93:$((7000 + $$ % 2000))?ttl=0"
serve i1.log "$work/i1" "$work/i1.sock" --lcm-url "$url" --loom-id same
i1=$last
wait_socket "$work/i1.sock"
rc=0
timeout 20 "$loomctl" serve --state-dir "$work/i2" --socket "$work/i2.sock" --group "" --lcm-url "$url" \
  --loom-id same >"$work/i2.log" 2>&1 || rc=$?
[[ $rc == 4 ]] || fail "a second serve with the same loom id exited $rc, not 4"
grep -q "loom id 'same' is already published .* by host $(hostname) (pid $i1," "$work/i2.log" ||
  fail "the refusal does not name the other publisher: $(cat "$work/i2.log")"
serve i3.log "$work/i3" "$work/i3.sock" --lcm-url "$url" --loom-id other
i3=$last
wait_socket "$work/i3.sock"
[[ $(field "$work/i3.sock" state) == idle ]] || fail "a loom with its own id did not arm beside the first"
kill -TERM "$i1" "$i3"; wait "$i1" "$i3" || true
echo "one publisher per loom id: $(grep -o "refusing to arm: loom id.*by host [^;]*" "$work/i2.log"): ok"

# ---- 4. full disk ----
mkdir "$work/disk"
mount -t tmpfs -o size=384k tmpfs "$work/disk"  # the sim-state file (~200 kB), the reserve (64 kB), the counters
fill() { dd if=/dev/zero of="$work/disk/fill" bs=4k status=none 2>/dev/null || true; }
# 3a: a fresh sim-state file on a full disk is refused, not mapped sparse (which died of SIGBUS).
mkdir "$work/disk/full"
# (the service's reserve of disk room already there, as a loom that armed before keeps it: the sim-state file
# is what does not fit)
dd if=/dev/zero of="$work/disk/full/reserve" bs=64k count=1 status=none
fill
rc=0
"$loomctl" serve --state-dir "$work/disk/full" --socket "$work/f.sock" --group "" --no-telemetry >"$work/f.log" 2>&1 || rc=$?
((rc == 4)) || fail "serve on a full disk exited $rc (135 = SIGBUS), not 4"
grep -q "cannot allocate sim state file" "$work/f.log" || fail "no reason given: $(cat "$work/f.log")"
[[ ! -e $work/disk/full/sim-state.bin ]] || fail "an empty sim-state file was left behind"
rm -f "$work/disk/fill"
echo "full disk, fresh sim-state: refused ($(grep -o 'cannot allocate.*' "$work/f.log")): ok"

# 3b: the disk fills while weaving: the ack waits for a successful save and never re-arms from older counts.
serve d.log "$work/disk/state" "$work/d.sock"
d=$last
wait_socket "$work/d.sock"
# Its reserve of disk room used up (as by a fault record on a full disk before): nothing frees room for the
# counters' retries, which fail until the disk has room again. (3c shows the reserve at work.)
rm -f "$work/disk/state/reserve"
ctl "$work/d.sock" start >/dev/null
wait_rows "$work/d.sock" 1 30
# Kept full until a save fails: a fill that lands while a save's temporary file exists leaves the old
# counters' page free once that save renames over them, and the saves could go on in it for ever (seen
# on a loaded host). Each round fills a new file: dd truncating the last one would free its pages first.
keep_full() { local i=0; while :; do dd if=/dev/zero of="$work/disk/fill.$i" bs=4k status=none 2>/dev/null || true; i=$((i + 1)); sleep 0.1; done; }
keep_full &
filler=$!
wait_for "$work/d.sock" fault counters_not_saved 60
kill "$filler" 2>/dev/null || true; wait "$filler" 2>/dev/null || true
woven=$(field "$work/d.sock" rows)
on_disk=$(grep -o '"rows":[0-9]*' "$work/disk/state/counters.json" | cut -d: -f2)
((on_disk < woven)) || fail "the file kept up ($on_disk rows) with the woven $woven: the disk did not fill"
rc=0
reply=$(ctl "$work/d.sock" ack 2>&1) || rc=$?
((rc != 0)) || fail "ctl ack exited 0 while the counters could not be saved: $reply"
[[ $reply == "refused: ack: the counters woven are not on disk yet"* ]] || fail "ctl ack answered '$reply' while the save fails"
sleep 1
[[ $(field "$work/d.sock" state) == fault ]] || fail "ack re-armed while the counters could not be saved: $(ctl "$work/d.sock" status)"
[[ $(field "$work/d.sock" rows) == "$woven" ]] || fail "rows changed from $woven under a refused ack"
rm -f "$work/disk/fill"*
for _ in $(seq 1 60); do
  [[ $(grep -o '"rows":[0-9]*' "$work/disk/state/counters.json" | cut -d: -f2) == "$woven" ]] && break
  sleep 0.1
done
[[ $(grep -o '"rows":[0-9]*' "$work/disk/state/counters.json" | cut -d: -f2) == "$woven" ]] || fail "the save was not retried once the disk had room"
ctl "$work/d.sock" ack >/dev/null
wait_for "$work/d.sock" state idle 10
[[ $(field "$work/d.sock" rows) == "$woven" ]] || fail "re-armed at rows $(field "$work/d.sock" rows), woven $woven"
kill -TERM "$d"; wait "$d" || fail "serve exited $? on SIGTERM"
echo "full disk while weaving: ack refused ('$reply') at $woven woven / $on_disk on disk, accepted after the retried save, re-armed at $woven: ok"

# 3c: a fault latched on a full disk survives a restart: the latched-fault record is written into the room the
# service keeps in reserve (it was lost before: the restart armed idle, fault=none, and started on ctl start).
serve e.log "$work/disk/state" "$work/e.sock"
e=$last
wait_socket "$work/e.sock"
[[ -e $work/disk/state/reserve ]] || fail "serve armed without keeping its reserve"
ctl "$work/e.sock" start >/dev/null
wait_rows "$work/e.sock" $((woven + 1)) 30
keep_full &
filler=$!
wait_for "$work/e.sock" fault counters_not_saved 60
kill "$filler" 2>/dev/null || true; wait "$filler" 2>/dev/null || true
[[ -e $work/disk/state/latched-fault ]] || fail "the fault latched on the full disk was not kept: $(ls "$work/disk/state")"
grep -q "^fault = counters_not_saved" "$work/disk/state/latched-fault" || fail "latched-fault: $(cat "$work/disk/state/latched-fault")"
[[ ! -e $work/disk/state/reserve ]] || fail "the reserve was not the room the record used"
kill -TERM "$e"; wait "$e" || true
# Restarted on the still full disk: refuses to arm (no room to keep a next fault), saying why.
rc=0
"$loomctl" serve --state-dir "$work/disk/state" --socket "$work/e.sock" --group "" --no-telemetry --pace 25 >"$work/e2.log" 2>&1 || rc=$?
((rc == 4)) || fail "serve on the still full disk exited $rc, not 4 (refusing to arm)"
grep -q "refusing to arm: cannot keep .* in reserve" "$work/e2.log" || fail "no reason: $(cat "$work/e2.log")"
# Room again: the restart latches the fault again; start is refused until ack.
rm -f "$work/disk/fill"*
serve e3.log "$work/disk/state" "$work/e.sock"
e=$last
wait_socket "$work/e.sock"
wait_for "$work/e.sock" fault counters_not_saved 10
rc=0
reply=$(ctl "$work/e.sock" start 2>&1) || rc=$?
((rc != 0)) || fail "ctl start after the restart answered '$reply' with the fault latched"
ctl "$work/e.sock" ack >/dev/null
wait_for "$work/e.sock" state idle 10
kill -TERM "$e"; wait "$e" || true
echo "fault latched on a full disk: kept in the reserve, refused to arm while still full, latched again after the restart ('$reply'), cleared by ack: ok"
echo "serve_service_test: ok"
