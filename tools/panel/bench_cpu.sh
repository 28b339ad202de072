#!/usr/bin/env bash
# loom-panel's CPU cost with a hall of looms: N simulated looms (loomctl weave --realtime, each its own
# loom id, default telemetry decimation) publish on one private LCM URL while the panel serves the
# hall page and one loom page to live event-stream clients. Prints the panel's CPU time over the
# measuring window as a percentage of one core (from /proc/<pid>/stat), and exits 1 above the limit.
#   tools/panel/bench_cpu.sh [build dir] [looms=20] [seconds=10] [limit %=5]
set -euo pipefail
BUILD=${1:-build}
N=${2:-20}
SECONDS_MEASURED=${3:-10}
LIMIT=${4:-5}
PANEL=$BUILD/bin/loom-panel
LOOMCTL=$BUILD/bin/loomctl
[ -x "$PANEL" ] && [ -x "$LOOMCTL" ] || { echo "bench_cpu: build loom-panel and loomctl first" >&2; exit 2; }
WORK=$(mktemp -d "${TMPDIR:-/tmp}/loom_panel_bench.XXXXXX")
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$WORK"
}
trap cleanup EXIT
PORT=$((20000 + ($$ * 11) % 20000))
URL="udpm://239.255.76.67:${PORT}?ttl=0"

"$PANEL" --port 0 --lcm-url "$URL" 2>"$WORK/panel.err" &
PANEL_PID=$!
PIDS+=("$PANEL_PID")
for _ in $(seq 1 100); do grep -q "serving http" "$WORK/panel.err" 2>/dev/null && break; sleep 0.05; done
BASE=$(sed -n 's|.*serving \(http://[0-9.]*:[0-9]*\)/.*|\1|p' "$WORK/panel.err")
[ -n "$BASE" ] || { cat "$WORK/panel.err" >&2; exit 1; }

for i in $(seq 1 "$N"); do
  "$LOOMCTL" weave --rows 1000 --realtime --lcm-url "$URL" --loom-id "hall$i" --quiet >/dev/null 2>&1 &
  PIDS+=($!)
done
# Two open pages: the hall and one loom, as a browser would hold them.
curl -sN "$BASE/events" >/dev/null &
PIDS+=($!)
curl -sN "$BASE/events?loom=hall1" >/dev/null &
PIDS+=($!)
sleep 3  # every loom armed and publishing

ticks() { awk '{ print $14 + $15 }' "/proc/$PANEL_PID/stat"; }
HZ=$(getconf CLK_TCK)
t0=$(ticks)
s0=$(date +%s.%N)
sleep "$SECONDS_MEASURED"
t1=$(ticks)
s1=$(date +%s.%N)
heard=$(curl -s "$BASE/api/hall" | grep -o '"id":"hall[0-9]*"' | wc -l)
pct=$(awk -v a="$t0" -v b="$t1" -v hz="$HZ" -v s0="$s0" -v s1="$s1" 'BEGIN { printf "%.2f", 100 * (b - a) / hz / (s1 - s0) }')
echo "loom-panel: $heard of $N looms heard; CPU $pct % of one core over ${SECONDS_MEASURED} s (limit $LIMIT %)"
[ "$heard" -eq "$N" ] || { echo "bench_cpu: the hall did not hear every loom" >&2; exit 1; }
awk -v p="$pct" -v l="$LIMIT" 'BEGIN { exit !(p < l) }'
