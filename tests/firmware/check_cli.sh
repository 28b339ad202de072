#!/usr/bin/env bash
# loomctl check prints the objects each kind of node must support, from the machine description: the
# homing objects for the drives referenced by a homing run (and only then), and the I/O module's input and
# output groups widened by the knotting heads' signals when the heads are fitted, and each module's own when the
# loom has several; the knot cycle's servo and which limit binds, and a knotting head whose max_speed
# exceeds its drive refused.
# usage: check_cli.sh LOOMCTL SOURCE_DIR
set -euo pipefail
loomctl=$1
src=$2
fail() { printf 'FAIL: %s\n' "$*" >&2; exit 1; }
expect() {  # expect OUTPUT_FILE TEXT
  grep -qF -- "$2" "$1" || fail "$(basename "$1"): no line with: $2"
}
out=$(mktemp -d "${TMPDIR:-/tmp}/loom_check_cli.XXXXXX")
trap 'rm -rf "$out"' EXIT

"$loomctl" check --config "$src/tests/hil/hil_incremental_loom.toml" >"$out/homing.txt"
expect "$out/homing.txt" "objects the homing drives (nodes 1, 2) must support as well:"
expect "$out/homing.txt" "0x6098 homing method: the configured method"
expect "$out/homing.txt" "0x6060 modes of operation: set to 6 (homing) for the referencing run, then 8"

"$loomctl" check >"$out/default.txt"
! grep -q "homing drives" "$out/default.txt" || fail "the default loom (absolute encoders) was given homing objects"
expect "$out/default.txt" "0x6200:01 write digital outputs, 8-bit: valves, stack light, buzzer"
# The bus load with every term: the cycle's frames, blocking, EMCY headroom, the four nodes' heartbeats.
expect "$out/default.txt" "bus 0 (nodes beat_crank 1, carriage 2, helix 3, I/O 4) load: 11 frames/cycle incl. blocking, EMCY headroom, 4 heartbeats: 1088 nominal / 1311 worst-case bits per 2 ms"
expect "$out/default.txt" "worst-case bits: 11 cyclic frames 1035, blocking 135, EMCY 1 × 135, 4 heartbeats 6"

"$loomctl" check --config "$src/firmware/config/knotting_loom.toml" >"$out/heads.txt"
expect "$out/heads.txt" "0x6200:01..04 write digital outputs, 8-bit: valves, stack light, buzzer, the heads' grippers and cutters"
expect "$out/heads.txt" "0x6000:01..04 read digital inputs, 8-bit: sensors and their second channels, e-stop chain, buttons, the heads' yarn-present switches"
# The knot cycle under the shipped servo's torque-speed line, and which limit binds.
expect "$out/heads.txt" "servo at the output, drives.servo_100w_10to1 (axes.knotter_1.drive): no-load 62.8 rad/s, peak 9.03 N m, continuous 3.04 N m"
expect "$out/heads.txt" "binding: the torque-speed line (each move drives on it and brakes at the peak torque)"
# Today's head: a micro servo asked for 60 rad/s is refused at the axis' max_speed, with the drive's figure.
sed -e 's/^drive = "servo_100w_10to1" .*$/drive = "micro_servo"\nmax_speed = 60.0/' \
  "$src/firmware/config/knotting_loom.toml" >"$out/today.toml"
printf '\n[drives.micro_servo]\nmotor_speed_rpm = 100\nrated_torque_nm = 0.06\npeak_torque_nm = 0.18\nrotor_inertia_kg_m2 = 1.7e-5\n' >>"$out/today.toml"
mkdir -p "$out/designs" && cp "$src/firmware/config/designs/knot_demo.csv" "$out/designs/"
if "$loomctl" check --config "$out/today.toml" >"$out/today.txt" 2>&1; then fail "today's head (60 rad/s on a micro servo) was accepted"; fi
expect "$out/today.txt" "axes.knotter_1.max_speed = 60 rad/s: exceeds the drive's 10.5 rad/s at the output"
echo "check_cli: PASS"

# A second I/O module (the operator panel's, on bus 1): its node, bus and signals, its own bus load, and the
# objects it must support for what it carries (not the valves' or sensors' reasons).
"$loomctl" check --config "$src/tests/hil/hil_four_axis_loom.toml" >"$out/panel.txt"
expect "$out/panel.txt" "I/O modules: io node 4 on bus 0, panel node 6 on bus 1"
expect "$out/panel.txt" "bus 1 (nodes take_up 5, I/O panel 6) load:"
expect "$out/panel.txt" "objects the I/O module io_modules.panel (node 6; signals lamp_green, lamp_amber, lamp_red, buzzer, button_start, button_pause, button_ack) must support:"
expect "$out/panel.txt" "0x6000:01..02 read digital inputs, 8-bit: buttons"
expect "$out/panel.txt" "0x6200:01 write digital outputs, 8-bit: stack light, buzzer"
expect "$out/panel.txt" "0x6000:01..03 read digital inputs, 8-bit: sensors and their second channels, e-stop chain"
! grep -q "0x6401.*panel\|panel.*0x6401" "$out/panel.txt" || fail "the panel module was given the load cell's object"
[[ $(grep -c "0x6401 read analog input" "$out/panel.txt") == 1 ]] || fail "the load cell's object is listed for a module without it"
