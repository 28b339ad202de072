# What the board suite's scripts share; sourced after `set -euo pipefail`.
#   board_work NAME  a temporary folder $work (/tmp/loom_NAME.XXXXXX), removed at exit, with the service
#                    the script started ($pid, when set) killed first; $sock is the control socket in it.
#   fail MESSAGE     FAIL and the service's logs ($work/serve*.log) on stderr, exit 1.
#   ctl ARGS         `$loomctl ctl` through $sock.
#   logged PATTERN FILE [SECONDS]
#                    true once FILE has a line matching PATTERN (grep, basic regex), within SECONDS (default 10):
#                    the journal is written by the service's reporter thread, a moment after the state the
#                    status already shows, so a line is waited for, never looked up once.
board_work() {
  work=$(mktemp -d "/tmp/loom_$1.XXXXXX")
  sock=$work/loom.sock
  pid=
  trap board_cleanup EXIT
}
board_cleanup() {
  [[ -n $pid ]] && kill -9 "$pid" 2>/dev/null || true
  [[ -n ${KEEP:-} ]] || rm -rf "$work"  # KEEP=1: leave it, to read the serve logs after a run
}
fail() { echo "FAIL: $*" >&2; echo "--- serve log:" >&2; cat "$work"/serve*.log >&2 || true; exit 1; }
ctl() { "$loomctl" ctl --socket "$sock" "$@"; }
logged() {
  local pattern=$1 file=$2 deadline=$((SECONDS + ${3:-10}))
  until grep -q -- "$pattern" "$file" 2>/dev/null; do
    ((SECONDS < deadline)) || return 1
    sleep 0.1
  done
}
