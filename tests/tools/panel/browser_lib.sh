# Sourced by the panel's tests (it defines functions and runs nothing):
#   fail MESSAGE — FAIL and the last 20 lines of every WORK/*.log, exit 1; a test that defined its own
#                  fail before sourcing this keeps it.
#   panel_work NAME — WORK (a scratch folder ${TMPDIR:-/tmp}/loom_panel_NAME.XXXXXX) and PIDS, with a
#                  cleanup at exit that stops every PIDS process, waits for it and removes WORK.
#   panel_lcm_url MULT — PORT and URL, an LCM udpm group on a port of this test's own (20000 + PID × MULT
#                  mod 20000: tests that run side by side do not hear each other).
#   have_browser — sets CHROMIUM; false, saying why, when headless Chromium or a node with a built-in
#                  WebSocket (the DevTools client in cdp.mjs) is missing. Browser tests: `have_browser || exit 77`.
#   panel_browser_test NAME MULT LOOMCTL PANEL SRC OUT — a browser test's start, from its own arguments:
#                  LOOMCTL, PANEL, SRC, OUT set, exit 77 without a browser, OUT made, panel_work NAME,
#                  panel_lcm_url MULT, ID=NAME<pid> (the loom id).
#   panel_up, panel_serve_up — start loom-panel / `loomctl serve` and wait until they answer.
#   panel_and_serve [serve args...] — both, as the knotting tests run them: loom-panel with its operator
#                  buttons on WORK/run, `loomctl serve` as loom ID on WORK/run/ID.sock (sets SOCK) with its
#                  state in WORK/state, both on URL.
# The two start helpers need from the caller: WORK (a scratch folder, their output goes there), PIDS (an
# array the caller's cleanup kills), fail (prints and exits), and PANEL / LOOMCTL (the programs). Their
# names are their own (panel_history.sh and serve_test.sh have a start_panel / start_serve of their own).
# The waits are long enough for a loaded machine (`ctest -j2` beside a build): they end as soon as the
# program answers, and fail at once, with its output, when it exits instead.

declare -F fail >/dev/null ||
  fail() { echo "FAIL: $*" >&2; for f in "$WORK"/*.log; do echo "--- $f" >&2; tail -20 "$f" >&2; done; exit 1; }

panel_browser_test() {
  LOOMCTL=$3 PANEL=$4 SRC=$5 OUT=$6
  have_browser || exit 77
  mkdir -p "$OUT"
  panel_work "$1"
  panel_lcm_url "$2"
  ID="$1$$"
}

panel_work() {
  WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom_panel_$1.XXXXXX")
  PIDS=()
  trap panel_cleanup EXIT
}
panel_cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  for p in "${PIDS[@]}"; do wait "$p" 2>/dev/null || true; done  # serve writes its state until it exits
  rm -rf "$WORK" || true
}

panel_lcm_url() {
  PORT=$((20000 + ($$ * $1) % 20000))
  URL="udpm://239.255.76.67:${PORT}?ttl=0"
}

have_browser() {
  CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
  [[ -n $CHROMIUM ]] || { echo "SKIP: chromium not installed (tools/deps.sh installs it)"; return 1; }
  command -v node >/dev/null || { echo "SKIP: node not installed"; return 1; }
  # node >= 20.10 with --experimental-websocket, or 22.
  node --experimental-websocket -e 'if (typeof WebSocket !== "function") process.exit(1)' 2>/dev/null ||
    node -e 'if (typeof WebSocket !== "function") process.exit(1)' 2>/dev/null ||
    { echo "SKIP: this node ($(node --version)) has no built-in WebSocket"; return 1; }
}

# panel_up LOG [loom-panel args...] — starts `$PANEL --port 0 ARGS` (stderr in WORK/LOG) and returns once
# it serves HTTP (or HTTPS with --tls-cert), at most PANEL_UP_S (30) s. Sets PANEL_BASE (http[s]://ADDR:PORT),
# PANEL_HTTP_PORT, PANEL_PID.
panel_up() {
  local log=$1 deadline=$((SECONDS + ${PANEL_UP_S:-30}))
  shift
  "$PANEL" --port 0 "$@" 2>"$WORK/$log" &
  PANEL_PID=$!
  PIDS+=("$PANEL_PID")
  until grep -qE "serving https?://" "$WORK/$log" 2>/dev/null; do
    kill -0 "$PANEL_PID" 2>/dev/null || fail "loom-panel exited at start: $(tail -5 "$WORK/$log")"
    ((SECONDS < deadline)) || fail "loom-panel did not serve within ${PANEL_UP_S:-30} s"
    sleep 0.05
  done
  PANEL_BASE=$(sed -n 's|.*serving \(https\{0,1\}://[0-9.]*:[0-9]*\)/.*|\1|p' "$WORK/$log")
  [[ -n $PANEL_BASE ]] || fail "loom-panel did not say where it serves: $(tail -5 "$WORK/$log")"
  PANEL_HTTP_PORT=${PANEL_BASE##*:}
}

# panel_serve_up SOCKET LOG [serve args...] — starts `$LOOMCTL serve --socket SOCKET --group "" ARGS`
# (output in WORK/LOG) and returns once `ctl status` answers on SOCKET, at most SERVE_UP_S (60) s.
# Sets SERVE_PID.
panel_serve_up() {
  local sock=$1 log=$2 deadline=$((SECONDS + ${SERVE_UP_S:-60}))
  shift 2
  "$LOOMCTL" serve --socket "$sock" --group "" "$@" >"$WORK/$log" 2>&1 &
  SERVE_PID=$!
  PIDS+=("$SERVE_PID")
  until [[ -S $sock ]] && "$LOOMCTL" ctl --socket "$sock" status >/dev/null 2>&1; do
    kill -0 "$SERVE_PID" 2>/dev/null || fail "serve exited at start: $(tail -5 "$WORK/$log")"
    ((SECONDS < deadline)) || fail "serve's control socket did not answer within ${SERVE_UP_S:-60} s"
    sleep 0.05
  done
}

panel_and_serve() {
  mkdir -p "$WORK/run"
  panel_up panel.log --lcm-url "$URL" --control-dir "$WORK/run"
  SOCK="$WORK/run/$ID.sock"
  panel_serve_up "$SOCK" serve.log --state-dir "$WORK/state" --loom-id "$ID" --lcm-url "$URL" "$@"
}
