#!/usr/bin/env bash
# Wake-up latency of loomctl's loop against cyclictest's (Debian rt-tests) on this machine, in one run:
# both at SCHED_FIFO 80, memory locked, a 2 ms period, one after the other (not at once: on a 2-core
# machine they would disturb each other), then the loop's tick cost with LCM telemetry on.
#   tests/board/latency_vs_cyclictest.sh LOOMCTL [ROWS]      ROWS of real-time weaving (default 4, ~30 s)
# Prints one table. As the bench-smoke test it runs briefly (ROWS=1 at 4x pace) to prove it works.
set -euo pipefail
loomctl=$1
rows=${2:-4}
pace=${LOOM_BENCH_PACE:-1}
command -v cyclictest >/dev/null || { echo "cyclictest not installed (apt-get install rt-tests)" >&2; exit 1; }
work=$(mktemp -d /tmp/loom_latency.XXXXXX)
trap 'rm -rf "$work"' EXIT

# The loop: real-time weaving of the simulated loom with telemetry on (udpm on this host only).
"$loomctl" weave --realtime --pace "$pace" --rows "$rows" --quiet >"$work/loop.txt"
line=$(grep '^loop:' "$work/loop.txt")
ticks=$(sed -n 's/^loop: \([0-9]*\) ticks.*/\1/p' <<<"$line")
l50=$(sed -n 's/.*wake-up latency p50 \([0-9]*\) ns.*/\1/p' <<<"$line")
l99=$(sed -n 's/.*wake-up latency p50 [0-9]* ns, p99 \([0-9]*\) ns.*/\1/p' <<<"$line")
lmax=$(sed -n 's/.*wake-up latency .* max \([0-9]*\) ns; loop thread.*/\1/p' <<<"$line")
c50=$(sed -n 's/.*tick cost (the tick.s own work) median \([0-9.]*\) µs.*/\1/p' <<<"$line")
c999=$(sed -n 's/.*tick cost (the tick.s own work) median [0-9.]* µs, p99.9 \([0-9.]*\) µs.*/\1/p' <<<"$line")
policy=$(sed -n 's/.*loop thread \(SCHED_[A-Z]*\( [0-9]*\)\{0,1\}\).*/\1/p' <<<"$line")
[[ -n $l50 && -n $l99 && -n $lmax && -n $c50 && -n $c999 ]] || { echo "cannot parse: $line" >&2; exit 1; }

# cyclictest: the same number of wake-ups at the same period and priority, histogram in µs.
period_us=$((2000 / pace))
cyclictest -m -p 80 -i "$period_us" -l "$ticks" -q -h 20000 >"$work/cyc.txt" 2>&1 ||
  { cat "$work/cyc.txt" >&2; exit 1; }
read -r c_p50 c_p99 c_max < <(awk '
  /^[0-9]+/ { n[$1+0] = $2; total += $2 }
  /# Max Latencies:/ { max = $4 + 0 }
  END {
    s = 0; p50 = -1; p99 = -1
    for (i = 0; i <= 20000; i++) { s += n[i]; if (p50 < 0 && s >= 0.5 * total) p50 = i; if (p99 < 0 && s >= 0.99 * total) p99 = i }
    print p50, p99, max
  }' "$work/cyc.txt")

printf '%-34s %10s %10s %10s\n' "wake-up latency (${ticks} wake-ups)" p50 p99 max
us() { awk -v n="$1" 'BEGIN { printf "%.1f", n / 1000 }'; }
printf '%-34s %8s µs %7s µs %7s µs\n' "loomctl loop ($policy)" "$(us "$l50")" "$(us "$l99")" "$(us "$lmax")"
printf '%-34s %8d µs %7d µs %7d µs\n' "cyclictest -m -p 80 -i $period_us" "$c_p50" "$c_p99" "$c_max"
printf '%-34s %10s %10s\n' "tick cost, telemetry on" p50 p99.9
printf '%-34s %7s µs %7s µs\n' "loomctl loop" "$c50" "$c999"
