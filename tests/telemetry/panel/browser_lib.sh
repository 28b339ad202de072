# Sourced by the panel's browser tests. Sets CHROMIUM, or exits 77 (skip) when headless Chromium or a
# node with a built-in WebSocket (the DevTools client in cdp.mjs) is missing.
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
[ -n "$CHROMIUM" ] || { echo "SKIP: chromium not installed (tools/deps.sh installs it)"; exit 77; }
command -v node >/dev/null || { echo "SKIP: node not installed"; exit 77; }
# node >= 20.10 with --experimental-websocket, or 22.
node --experimental-websocket -e 'if (typeof WebSocket !== "function") process.exit(1)' 2>/dev/null ||
  node -e 'if (typeof WebSocket !== "function") process.exit(1)' 2>/dev/null ||
  { echo "SKIP: this node ($(node --version)) has no built-in WebSocket"; exit 77; }

# start_panel URL — loom-panel ($PANEL) on an ephemeral port listening to LCM at URL, its control sockets in
# $WORK/run, its log in $WORK/panel.log; appends its pid to PIDS and sets BASE (http://host:port), or fails.
start_panel() {
  mkdir -p "$WORK/run"
  "$PANEL" --port 0 --lcm-url "$1" --control-dir "$WORK/run" 2>"$WORK/panel.log" &
  PIDS+=($!)
  for _ in $(seq 1 100); do
    grep -q "serving http" "$WORK/panel.log" 2>/dev/null && break
    sleep 0.05
  done
  BASE=$(sed -n 's|.*serving \(http://[0-9.]*:[0-9]*\)/.*|\1|p' "$WORK/panel.log")
  [ -n "$BASE" ] || fail "loom-panel did not start"
}
