# Sourced by the panel's browser tests. Sets CHROMIUM, or exits 77 (skip) when headless Chromium or a
# node with a built-in WebSocket (the DevTools client in cdp.mjs) is missing.
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
[ -n "$CHROMIUM" ] || { echo "SKIP: chromium not installed (tools/deps.sh installs it)"; exit 77; }
command -v node >/dev/null || { echo "SKIP: node not installed"; exit 77; }
# node >= 20.10 with --experimental-websocket, or 22.
node --experimental-websocket -e 'if (typeof WebSocket !== "function") process.exit(1)' 2>/dev/null ||
  node -e 'if (typeof WebSocket !== "function") process.exit(1)' 2>/dev/null ||
  { echo "SKIP: this node ($(node --version)) has no built-in WebSocket"; exit 77; }
