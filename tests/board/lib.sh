# What the board suite's scripts share; sourced after `set -euo pipefail`.
#   board_work NAME  a temporary folder $work (/tmp/loom_NAME.XXXXXX), removed at exit, with the service
#                    the script started ($pid, when set) killed first; $sock is the control socket in it.
#   fail MESSAGE     FAIL and the service's logs ($work/serve*.log) on stderr, exit 1.
#   ctl ARGS         `$loomctl ctl` through $sock.
board_work() {
  work=$(mktemp -d "/tmp/loom_$1.XXXXXX")
  sock=$work/loom.sock
  pid=
  trap board_cleanup EXIT
}
board_cleanup() {
  [[ -n $pid ]] && kill -9 "$pid" 2>/dev/null || true
  rm -rf "$work"
}
fail() { echo "FAIL: $*" >&2; echo "--- serve log:" >&2; cat "$work"/serve*.log >&2 || true; exit 1; }
ctl() { "$loomctl" ctl --socket "$sock" "$@"; }
