# hil-lib.sh — shared steps of the HIL test scripts (sourced, not run): find a real vcan0 or skip with
# exit 77 saying how to run them, keep a candump log per test under BUILD/hil-logs (hil-run counts the
# frames there), wait for frames in it, and tidy up every process a test started.
# Frames are matched on candump -L lines: "(secs.usecs) vcan0 ID#DATA", ID/DATA upper-case hex.

HIL_SKIP=77

# hil_init NAME BUILD_DIR — call first. Sets HIL_NAME, HIL_BUILD, HIL_IFACE, HIL_LOGDIR, HIL_WORK.
hil_init() {
  HIL_NAME=$1
  HIL_BUILD=$(cd "${2:?usage: $0 BUILD_DIR}" && pwd)
  HIL_IFACE=${LOOM_HIL_IFACE:-vcan0}
  HIL_LOGDIR=$HIL_BUILD/hil-logs
  HIL_PIDS=()
  HIL_CANDUMP_PID=""
  mkdir -p "$HIL_LOGDIR"
  # Private scratch on a local filesystem (TMPDIR is the guest's tmpfs in the VM, never the 9p share).
  HIL_WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom-hil-$HIL_NAME.XXXXXX")
  trap hil_cleanup EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
}

hil_cleanup() {
  local pid
  # A test that failed early still leaves its bus record behind for whoever reads the failure.
  if [[ -n $HIL_CANDUMP_PID ]]; then
    kill -INT "$HIL_CANDUMP_PID" 2>/dev/null || true
    wait "$HIL_CANDUMP_PID" 2>/dev/null || true
    cp "$HIL_LOG" "$HIL_LOGDIR/$HIL_NAME.candump.log" 2>/dev/null || true
    HIL_CANDUMP_PID=""
  fi
  for pid in "${HIL_PIDS[@]}"; do
    kill -TERM "$pid" 2>/dev/null || true
  done
  # Spawned programs are disowned (no wait possible): give them 2 s to go, then SIGKILL.
  local i
  for ((i = 0; i < 40; i++)); do
    local alive=0
    for pid in "${HIL_PIDS[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    ((alive)) || break
    sleep 0.05
  done
  for pid in "${HIL_PIDS[@]}"; do
    kill -KILL "$pid" 2>/dev/null || true
  done
  rm -rf "$HIL_WORK"
}

hil_fail() { printf 'FAIL [%s]: %s\n' "$HIL_NAME" "$*" >&2; exit 1; }  # stderr: seen even inside $(...)
hil_note() { printf '[%s] %s\n' "$HIL_NAME" "$*"; }

# Exit 77 (CTest: skipped) unless a real, up CAN interface named HIL_IFACE exists here.
hil_require_vcan() {
  local sys=/sys/class/net/$HIL_IFACE
  if [[ ! -e $sys ]] || [[ $(cat "$sys/type" 2>/dev/null) != 280 ]]; then  # 280 = ARPHRD_CAN
    printf 'SKIP [%s]: no CAN interface %s here (this kernel may have no CAN at all).\n' "$HIL_NAME" "$HIL_IFACE"
    printf 'Run the HIL tests with: tools/loom test   or   tools/vcan/hil-run build\n'
    printf '(hil-run uses a host vcan0 when it can, else boots a qemu VM that has one.)\n'
    exit "$HIL_SKIP"
  fi
  if (( ($(cat "$sys/flags") & 1) == 0 )); then  # IFF_UP
    ip link set up "$HIL_IFACE" 2>/dev/null ||
      { printf 'SKIP [%s]: %s exists but is down and cannot be brought up here.\n' "$HIL_NAME" "$HIL_IFACE"
        printf 'Run: sudo ip link set up %s   (or tools/vcan/hil-run build)\n' "$HIL_IFACE"; exit "$HIL_SKIP"; }
  fi
  local where="this host"
  [[ -n ${LOOM_IN_VCAN_VM:-} ]] && where="the qemu vcan VM"
  local kind
  kind=$(ip -details link show "$HIL_IFACE" 2>/dev/null | grep -oE '^\s+vcan\b' | tr -d ' ' || true)
  hil_note "real CAN interface $HIL_IFACE (${kind:-can}) on $where, kernel $(uname -r)"
}

# hil_need_exec PATH WHAT — the binaries under test must exist: a missing one fails, it does not skip.
hil_need_exec() {
  [[ -x $1 ]] || hil_fail "$2 not found at $1 (build it first: cmake --build $HIL_BUILD)"
}

# Start `candump -L` on the interface and return once it is receiving (a sentinel frame 7FF with no
# data — unused by CANopen — has come back through it). The live log sits in HIL_WORK: written to the
# 9p share frame by frame, candump falls behind under the VM and its socket drops frames, so the
# record would be incomplete. -d makes any drop visible; hil_stop_candump fails on one.
hil_start_candump() {
  HIL_LOG=$HIL_WORK/$HIL_NAME.candump.log
  : >"$HIL_LOG"
  # The recorder must never starve: loomctl's SCHED_FIFO loop saturates the VM's one CPU once it falls
  # behind, and a starved candump that is then stopped loses what waited in its socket (a log that ended
  # at the moment of interest). It runs above the loop, like the simulated nodes, where that is allowed.
  local rt=()
  chrt -f 85 true 2>/dev/null && rt=(chrt -f 85)
  "${rt[@]}" stdbuf -oL candump -L -d -r 8388608 "$HIL_IFACE" >"$HIL_LOG" &
  HIL_CANDUMP_PID=$!
  local i
  for ((i = 0; i < 50; i++)); do
    cansend "$HIL_IFACE" '7FF#'
    if grep -q " 7FF#$" "$HIL_LOG"; then return 0; fi
    sleep 0.1
  done
  hil_fail "candump on $HIL_IFACE did not log a sentinel frame within 5 s"
}

# Stop candump and keep its log as HIL_LOGDIR/NAME.candump.log (HIL_LOG then names the kept copy).
hil_stop_candump() {
  [[ -n $HIL_CANDUMP_PID ]] || return 0
  sleep 0.2  # let the last frames reach the log
  kill -INT "$HIL_CANDUMP_PID" 2>/dev/null || true
  wait "$HIL_CANDUMP_PID" 2>/dev/null || true
  HIL_CANDUMP_PID=""
  local kept=$HIL_LOGDIR/$HIL_NAME.candump.log drops
  drops=$(grep -m1 'DROPCOUNT' "$HIL_LOG" || true)
  grep -v 'DROPCOUNT' "$HIL_LOG" >"$kept" || true
  HIL_LOG=$kept
  [[ -z $drops ]] || hil_fail "candump lost frames, so the bus record is incomplete: $drops"
}

# Lines in the log so far: a mark to look for frames "after this point".
hil_mark() { wc -l <"$HIL_LOG"; }

# hil_frames_after MARK REGEX — candump lines after MARK whose "ID#DATA" matches ^REGEX$.
hil_frames_after() {
  tail -n "+$(($1 + 1))" "$HIL_LOG" | awk '{ print $3 }' | grep -E "^($2)\$" || true
}

# hil_expect MARK REGEX TIMEOUT_S WHAT — wait for a matching frame after MARK; print it (ID#DATA).
hil_expect() {
  local mark=$1 re=$2 timeout_s=$3 what=$4 deadline hit
  deadline=$((SECONDS + timeout_s))
  while :; do
    hit=$(hil_frames_after "$mark" "$re" | head -n1)
    if [[ -n $hit ]]; then printf '%s\n' "$hit"; return 0; fi
    ((SECONDS < deadline)) ||
      hil_fail "no $what (frame matching $re) within ${timeout_s} s; log: $HIL_LOGDIR/$HIL_NAME.candump.log"
    sleep 0.05
  done
}

# Start a program in the background with output to WORK/NAME.out; remembers it for clean-up.
# Sets HIL_LAST_PID. Disowned, so a test's deliberate SIGKILL prints no job-control "Killed" noise.
hil_spawn() {
  local name=$1; shift
  "$@" >"$HIL_WORK/$name.out" 2>&1 &
  HIL_LAST_PID=$!
  disown "$HIL_LAST_PID"
  HIL_PIDS+=("$HIL_LAST_PID")
}

# hil_forget_pid PID — drop PID (exactly: not every pid that contains its digits) from the processes the
# cleanup kills, once the test has ended it itself.
hil_forget_pid() {
  local kept=() p
  for p in "${HIL_PIDS[@]}"; do [[ $p == "$1" ]] || kept+=("$p"); done
  HIL_PIDS=("${kept[@]}")
}

# The closing line every HIL test prints; hil-run adds the per-test logs up.
hil_report_frames() {
  if [[ -x $HIL_BUILD/bin/loom-hil-canlog ]]; then
    "$HIL_BUILD/bin/loom-hil-canlog" summary "$HIL_LOG" | sed "s|^|[$HIL_NAME] |"
  fi
  hil_note "$(wc -l <"$HIL_LOG") CAN frames exchanged on real $HIL_IFACE; log kept in $HIL_LOG"
}

# Value of a top-level integer key in a flat JSON object (loomctl's counters file), or empty.
hil_json_int() {
  grep -oE "\"$2\"[[:space:]]*:[[:space:]]*-?[0-9]+" "$1" | head -n1 | grep -oE -- '-?[0-9]+$'
}

# ---------------------------------------------------------------------------------------------------
# loomctl against simulated drives (weave-row.sh, heartbeat-loss.sh)
# ---------------------------------------------------------------------------------------------------
HIL_NODES=1,2,3
HIL_IO_NODE=4
# Drive personality of loom-sim-drive: standard (writable mappings, 0x1016) or fixed (read-only
# mappings, no TPDO3/4, no 0x1016, slow boot and switch to operational).
HIL_PERSONALITY=${LOOM_HIL_PERSONALITY:-standard}
HIL_PERIOD_MS=${LOOM_HIL_PERIOD_MS:-4}  # the VM is not real-time: 4 ms cycles lost no replies there (tools/vcan/README.md)

# Where these scripts (and the HIL loom config) live.
HIL_SRC=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

# Locate loomctl, loom-sim-drive and the judge (LOOM_HIL_LOOMCTL / LOOM_HIL_SIM_DRIVE override).
hil_find_binaries() {
  HIL_LOOMCTL=${LOOM_HIL_LOOMCTL:-$HIL_BUILD/bin/loomctl}
  HIL_SIM=${LOOM_HIL_SIM_DRIVE:-$HIL_BUILD/bin/loom-sim-drive}
  HIL_CANLOG=$HIL_BUILD/bin/loom-hil-canlog
  hil_need_exec "$HIL_LOOMCTL" loomctl
  hil_need_exec "$HIL_SIM" loom-sim-drive
  hil_need_exec "$HIL_CANLOG" loom-hil-canlog
}

# Start the simulated drives and the simulated I/O node and wait until each has announced itself.
# Sets HIL_SIM_PID; the I/O node's e-stop/buttons/silence follow the words in HIL_IO_CONTROL.
# The fixed personality boots after 300 ms and switches to operational after 400 ms (loomctl's
# default operational window is 1 s).
HIL_SIM_EXTRA=()  # more loom-sim-drive arguments (e.g. --initial-position)
hil_start_sim_drives() {
  local mark n
  mark=$(hil_mark)
  HIL_IO_CONTROL=$HIL_WORK/io-control
  : >"$HIL_IO_CONTROL"
  # The simulated nodes stand for separate hardware: loomctl's SCHED_FIFO loop (which overruns in the VM)
  # must not starve them, so they run at a higher real-time priority where that is allowed.
  local rt=()
  chrt -f 90 true 2>/dev/null && rt=(chrt -f 90)
  # HIL_SIM_EDS: the drives built from that EDS instead of a built-in personality.
  local kind=(--personality "$HIL_PERSONALITY")
  [[ -z ${HIL_SIM_EDS:-} ]] || kind=(--eds "$HIL_SIM_EDS")
  hil_spawn sim "${rt[@]}" "$HIL_SIM" --iface "$HIL_IFACE" --nodes "$HIL_NODES" --io-node "$HIL_IO_NODE" \
    --io-control "$HIL_IO_CONTROL" --width-m 0.6 "${kind[@]}" \
    --plant-cycle-ms "$HIL_PERIOD_MS" "${HIL_SIM_EXTRA[@]}"
  HIL_SIM_PID=$HIL_LAST_PID
  for n in ${HIL_NODES//,/ } $HIL_IO_NODE; do
    hil_expect "$mark" "$(printf '%03X' $((0x700 + n)))#00" 10 "boot-up of simulated node $n" >/dev/null
  done
  hil_note "loom-sim-drive up (${HIL_SIM_EDS:+drives from }${HIL_SIM_EDS:-$HIL_PERSONALITY drives}): nodes $HIL_NODES and I/O node $HIL_IO_NODE booted (pid $HIL_SIM_PID)"
}

# hil_io_control WORDS... — what the simulated I/O node's e-stop chain and buttons see from now on.
hil_io_control() { printf '%s\n' "$*" >"$HIL_IO_CONTROL.tmp" && mv "$HIL_IO_CONTROL.tmp" "$HIL_IO_CONTROL"; }

# hil_sim_took_controls WHAT WORDS — loom-sim-drive has applied the control file's WORDS (it echoes what
# it applied and names every word it ignored): a misspelt word fails here, not as a fault that never came.
hil_sim_took_controls() {
  local deadline=$((SECONDS + 5)) sim_out=$HIL_WORK/sim.out
  until grep -qF "I/O controls now: $2" "$sim_out"; do
    ((SECONDS < deadline)) || hil_fail "$1: loom-sim-drive did not apply '$2' within 5 s: $(tail -n 3 "$sim_out")"
    sleep 0.02
  done
  ! grep -F -- '--io-control:' "$sim_out" || hil_fail "$1: loom-sim-drive ignored io-control words (above)"
}

# hil_weave_until_armed WHAT ROWS COUNTERS_FILE — start loomctl (hil_weave_cmd) in the background and
# return once drive 1 has been commanded to Operation Enabled (RPDO1 controlword 0x000F, from candump)
# and it has woven LOOM_HIL_FAULT_AFTER_S (2) more seconds. Sets HIL_LOOM_PID and HIL_LOOM_OUT.
hil_weave_until_armed() {
  local what=$1
  HIL_LOOM_OUT=$HIL_WORK/$what.loomctl.out
  hil_weave_cmd "$2" "$3"
  "${HIL_CMD[@]}" >"$HIL_LOOM_OUT" 2>&1 &
  HIL_LOOM_PID=$!
  HIL_PIDS+=("$HIL_LOOM_PID")
  local deadline=$((SECONDS + 30))
  until [[ -n $(hil_frames_after 0 '201#0F00[0-9A-F]{8}' | head -n1) ]]; do
    kill -0 "$HIL_LOOM_PID" 2>/dev/null ||
      { sed 's/^/  loomctl| /' "$HIL_LOOM_OUT"; hil_fail "$what: loomctl exited during bring-up"; }
    ((SECONDS < deadline)) || hil_fail "$what: drives not enabled within 30 s"
    sleep 0.05
  done
  sleep "${LOOM_HIL_FAULT_AFTER_S:-2}"
  hil_loom_alive "$what" "before the fault"
}

# hil_loom_alive WHAT WHEN — loomctl (hil_weave_until_armed) is still weaving, else fail showing its output.
hil_loom_alive() {
  kill -0 "$HIL_LOOM_PID" 2>/dev/null ||
    { sed 's/^/  loomctl| /' "$HIL_LOOM_OUT"; hil_fail "$1: loomctl ended $2"; }
}

# hil_expect_fault WHAT REGEX COUNTERS_FILE — loomctl (hil_weave_until_armed) stops by itself within 20 s
# with exit 3 and a first FAULT line matching REGEX (in HIL_FAULT_LINE); the counters file is kept. Stops
# candump (HIL_LOG then names the kept log).
hil_expect_fault() {
  local what=$1 deadline=$((SECONDS + 20)) status=0
  while kill -0 "$HIL_LOOM_PID" 2>/dev/null && ((SECONDS < deadline)); do sleep 0.05; done
  if kill -0 "$HIL_LOOM_PID" 2>/dev/null; then
    kill -TERM "$HIL_LOOM_PID" 2>/dev/null || true
    sleep 1
    sed 's/^/  loomctl| /' "$HIL_LOOM_OUT"
    hil_stop_candump
    hil_fail "$what: loomctl still running 20 s after the fault (stopped with SIGTERM; its output above, bus: $HIL_LOG)"
  fi
  wait "$HIL_LOOM_PID" || status=$?
  hil_forget_pid "$HIL_LOOM_PID"
  sed 's/^/  loomctl| /' "$HIL_LOOM_OUT"
  cp "$HIL_LOOM_OUT" "$HIL_LOGDIR/$HIL_NAME.loomctl.out"
  hil_stop_candump
  ((status == 3)) || hil_fail "$what: loomctl exited with $status, expected 3 (fault)"
  HIL_FAULT_LINE=$(grep '^FAULT' "$HIL_LOOM_OUT" | head -n1 || true)
  grep -qE "$2" <<<"$HIL_FAULT_LINE" || hil_fail "$what: first fault line does not match /$2/: $HIL_FAULT_LINE"
  [[ -f $3 ]] || hil_fail "$what: no counters file kept"
  cp "$3" "$HIL_LOGDIR/$HIL_NAME.counters.json"
  hil_note "$what: exit 3, $HIL_FAULT_LINE"
}


# hil_run_weave TIMEOUT_S — run HIL_CMD (hil_weave_cmd) with a time limit, show its output and keep it
# as HIL_LOGDIR/NAME.loomctl.out; its exit status in HIL_STATUS (124/137 = timed out).
hil_run_weave() {
  hil_note "running: ${HIL_CMD[*]}"
  HIL_STATUS=0
  timeout -k 5 "$1" "${HIL_CMD[@]}" >"$HIL_WORK/loomctl.out" 2>&1 || HIL_STATUS=$?
  sed 's/^/  loomctl| /' "$HIL_WORK/loomctl.out"
  cp "$HIL_WORK/loomctl.out" "$HIL_LOGDIR/$HIL_NAME.loomctl.out"
}

# hil_weave_cmd ROWS COUNTERS_FILE — the loomctl command line under test, into HIL_CMD. HIL_CONFIG (a
# loom file) and HIL_IFACES ("vcan0,vcan1" for a loom on two buses) change what it weaves.
hil_weave_cmd() {
  HIL_CMD=("$HIL_LOOMCTL" weave --hal socketcan --iface "${HIL_IFACES:-$HIL_IFACE}" --rows "$1"
           --period-ms "$HIL_PERIOD_MS" --allow-degraded --counters "$2" --config "${HIL_CONFIG:-$HIL_SRC/hil_loom.toml}"
           --io can)
}
