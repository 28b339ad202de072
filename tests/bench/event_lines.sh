#!/usr/bin/env bash
# What a weave said, per scene: the telemetry events (BEAT, FAULT, ROW, WEAVER channels, read back from an
# LCM log file with loom-monitor, wall-clock stamps removed) and the reporter's lines (loomctl weave's
# output without its timing line), one hash each. tick_digests.sh covers every tick's inputs, outputs and
# snapshot, not the events; a change to how events are found must leave this output unchanged:
#
#   tests/bench/event_lines.sh --bin old/bin > before.txt
#   tests/bench/event_lines.sh > after.txt && diff before.txt after.txt
#
# Cases: the default scene and the fault scenes on the default loom (3 rows), the knotting scenes on
# firmware/config/knotting_loom.toml (2 rows). loom-monitor always comes from build/bin (the same reader
# for both builds).
#     --bin DIR     build/bin with loomctl (default: build/bin)
#     --keep DIR    keep the logs and the lines here (default: a temporary folder, removed)
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
root=$(cd "$here/../.." && pwd)
bin=$root/build/bin
keep=""
while [[ $# -gt 0 ]]; do
  case $1 in
    --bin) bin=$2; shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    -h|--help) sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "event_lines.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
loomctl=$bin/loomctl
monitor=$root/build/bin/loom-monitor
[[ -x $loomctl ]] || { echo "event_lines.sh: $loomctl not built" >&2; exit 2; }
[[ -x $monitor ]] || { echo "event_lines.sh: $monitor not built" >&2; exit 2; }
if [[ -z $keep ]]; then
  keep=$(mktemp -d)
  trap 'rm -rf "$keep"' EXIT
fi
mkdir -p "$keep"
scenes=$root/sim_hal/scenes
for name in default drive_fault emcy estop heartbeat_loss bus_off loop_stall stuck_piston air_loss shuttle_slip \
            load_cell knotting knotting_faults; do
  cfg=() rows=3
  case $name in knotting*) cfg=(--config "$root/firmware/config/knotting_loom.toml"); rows=2 ;; esac
  log=$keep/$name.lcmlog
  rm -f "$log"
  "$loomctl" weave --scene "$scenes/$name.toml" "${cfg[@]}" --rows "$rows" --quiet \
    --lcm-url "file://$log?mode=w" >"$keep/$name.out" 2>&1 || true  # a fault ends the weave non-zero
  "$monitor" --lcm-url "file://$log?mode=r&speed=0" --channel beat,fault,row,weaver --timeout-s 5 2>/dev/null |
    sed -E 's/utime=[0-9-]+ ?//g' >"$keep/$name.events" || true
  grep -v '^loop:' "$keep/$name.out" >"$keep/$name.report" || true
  printf '%s events %s (%s lines) report %s (%s lines)\n' "$name" \
    "$(sha1sum <"$keep/$name.events" | cut -c1-12)" "$(wc -l <"$keep/$name.events")" \
    "$(sha1sum <"$keep/$name.report" | cut -c1-12)" "$(wc -l <"$keep/$name.report")"
done
