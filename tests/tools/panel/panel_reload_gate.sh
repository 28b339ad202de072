#!/usr/bin/env bash
# "Slot reloaded" through loom-panel's request gate (issue 29 item 3: the panel acknowledges a reload per
# head and slot). A stand-in for the loom's control socket (python, DIR/<id>.sock) records every line
# the panel forwards and answers "ok reload". Checked:
#   1. unpaired (no token cookie): refused by the panel (403, a starting command) and never forwarded;
#   2. paired: forwarded once as "reload head=H slot=S[ knots=K] via=panel client=... token=T";
#   3. a head, slot or knots that is not a number is refused (400) and never forwarded;
#   4. a read-only panel (no --control-dir) refuses it (403).
# Usage: panel_reload_gate.sh <loom-panel>
set -euo pipefail
PANEL=$1
. "$(dirname "$0")/browser_lib.sh"  # fail, panel_work, panel_up
panel_work reload
ID=gate$$
mkdir -p "$WORK/run"
python3 - "$WORK/run/$ID.sock" "$WORK/lines.txt" <<'PY' &
import os, socket, sys
path, out = sys.argv[1], sys.argv[2]
s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
s.bind(path)
s.listen(8)
while True:
    c, _ = s.accept()
    data = b""
    while not data.endswith(b"\n"):
        chunk = c.recv(4096)
        if not chunk:
            break
        data += chunk
    with open(out, "a") as f:
        f.write(data.decode())
    c.sendall(b"ok reload (stand-in)\n")
    c.close()
PY
PIDS+=("$!")
until [[ -S $WORK/run/$ID.sock ]]; do sleep 0.05; done
: >"$WORK/lines.txt"
panel_up panel.log --control-dir "$WORK/run"
TOKEN=0123456789abcdef0123456789abcdef
post() {  # post QUERY [COOKIE] -> prints the HTTP status
  curl -s -o "$WORK/reply.json" -w '%{http_code}' -X POST -H 'X-Loom-Panel: 1' -H 'Content-Length: 0' \
    ${2:+-H "Cookie: loom_token_$ID=$2"} "$PANEL_BASE/api/loom/$ID/ctl/reload$1"
}
[[ $(post '?head=2&slot=3') == 403 ]] || fail "unpaired reload not refused: $(cat "$WORK/reply.json")"
[[ ! -s $WORK/lines.txt ]] || fail "an unpaired reload reached the loom: $(cat "$WORK/lines.txt")"
[[ $(post '?head=2&slot=3' "$TOKEN") == 200 ]] || fail "paired reload: $(cat "$WORK/reply.json")"
[[ $(post '?head=1&slot=1&knots=40' "$TOKEN") == 200 ]] || fail "paired reload with knots: $(cat "$WORK/reply.json")"
for bad in '?head=2' '?slot=3' '?head=x&slot=1' '?head=1&slot=1;stop' '?head=1&slot=1&knots=-4' '?head=123&slot=1'; do
  [[ $(post "$bad" "$TOKEN") == 400 ]] || fail "reload$bad not refused: $(cat "$WORK/reply.json")"
done
mapfile -t lines <"$WORK/lines.txt"
[[ ${#lines[@]} == 2 ]] || fail "want 2 lines forwarded, got: $(cat "$WORK/lines.txt")"
[[ ${lines[0]} == "reload head=2 slot=3 via=panel client=127.0.0.1 token=$TOKEN" ]] || fail "forwarded: ${lines[0]}"
[[ ${lines[1]} == "reload head=1 slot=1 knots=40 via=panel client=127.0.0.1 token=$TOKEN" ]] || fail "forwarded: ${lines[1]}"
kill "$PANEL_PID"
panel_up panel2.log
[[ $(post '?head=2&slot=3' "$TOKEN") == 403 ]] || fail "a read-only panel forwarded a reload"
echo "PASS: reload refused unpaired, forwarded paired as '${lines[0]}', bad numbers refused, read-only refuses"
