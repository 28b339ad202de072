#!/usr/bin/env bash
# The amd64 .deb, checked from the outside: cpack builds it from the install rules; its control data
# (name, version, architecture, conffiles, postinst) and its files are what a board needs; every shared
# library the packaged binaries load belongs to a Debian package named in Depends (looked up with
# dpkg -S, not copied from the CMake file); the systemd unit passes `systemd-analyze verify`; and the
# loomctl extracted into a clean root (dpkg-deb -x) serves: starts, waits, weaves a row in simulation
# on `ctl start`, stops on `ctl stop`, exits on SIGTERM.
# Usage: package_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
work=$(mktemp -d /tmp/loom_pkg_test.XXXXXX)
pid=
cleanup() {
  [[ -n $pid ]] && kill -9 "$pid" 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; cat "$work/serve.log" >&2 2>/dev/null || true; exit 1; }

# ---- build the package ----
(cd "$build" && cpack -G DEB -B "$work/pk" >"$work/cpack.log" 2>&1) || { cat "$work/cpack.log"; fail "cpack"; }
version=$(sed -n 's/^project(loomctl VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")
deb=$work/pk/loomctl_${version}_amd64.deb
[[ -f $deb ]] || fail "no $deb (got: $(ls "$work/pk"))"

# ---- control data ----
[[ $(dpkg-deb -f "$deb" Package) == loomctl ]] || fail "package name"
[[ $(dpkg-deb -f "$deb" Architecture) == amd64 ]] || fail "architecture"
[[ $(dpkg-deb -f "$deb" Version) == "$version" ]] || fail "version"
depends=$(dpkg-deb -f "$deb" Depends)
dpkg-deb -e "$deb" "$work/control"
grep -qx /etc/loomctl/loom.toml "$work/control/conffiles" || fail "loom.toml is not a conffile"
[[ -x $work/control/postinst ]] || fail "no executable postinst"
grep -q "addgroup --system loom" "$work/control/postinst" || fail "postinst does not create the loom group"

# ---- files ----
root=$work/root
dpkg-deb -x "$deb" "$root"
for f in usr/bin/loomctl usr/bin/loom-monitor etc/loomctl/loom.toml etc/default/loomctl \
         lib/systemd/system/loomctl.service usr/share/loomctl/lcmtypes/status_t.lcm; do
  [[ -e $root/$f ]] || fail "missing /$f"
done
cmp -s "$root/etc/loomctl/loom.toml" "$src/firmware/config/default_loom.toml" || fail "/etc/loomctl/loom.toml differs from the embedded default"
for k in LimitRTPRIO= LimitMEMLOCK=infinity RuntimeDirectory=loomctl StateDirectory=loomctl "ExecStart=/usr/bin/loomctl serve"; do
  grep -q "^$k" "$root/lib/systemd/system/loomctl.service" || fail "unit lacks $k"
done

# ---- every NEEDED library comes from a package in Depends ----
ld_cache=$(ldconfig -p)  # read once: awk exiting early on a pipe would SIGPIPE ldconfig under pipefail
for bin in "$root"/usr/bin/*; do
  for lib in $(objdump -p "$bin" | awk '/NEEDED/ {print $2}'); do
    path=$(awk -v l="$lib" '$1 == l && /x86-64/ {print $NF; exit}' <<<"$ld_cache")
    [[ -n $path ]] || fail "$lib (needed by $(basename "$bin")) not found on this machine"
    real=$(readlink -f "$path")
    pkg=$(dpkg -S "$real" 2>/dev/null || dpkg -S "$path" 2>/dev/null || true)
    pkg=${pkg%%:*}
    [[ -n $pkg ]] || fail "no package owns $path"
    [[ ", $depends," == *", $pkg "* || ", $depends," == *", $pkg,"* ]] || fail "$lib comes from $pkg, which Depends ($depends) does not name"
  done
done

# ---- the unit, offline ----
if command -v systemd-analyze >/dev/null; then
  sed "s|/usr/bin/loomctl|$root/usr/bin/loomctl|" "$root/lib/systemd/system/loomctl.service" >"$work/loomctl.service"
  out=$(systemd-analyze verify "$work/loomctl.service" 2>&1) || fail "systemd-analyze verify: $out"
  [[ -z $out ]] || fail "systemd-analyze verify complains: $out"
else
  echo "systemd-analyze not installed: unit not verified"
fi

# ---- the extracted loomctl serves ----
"$root/usr/bin/loomctl" --version | grep -qx "loomctl $version" || fail "--version"
sock=$work/loom.sock
ctl() { "$root/usr/bin/loomctl" ctl --socket "$sock" "$@"; }
field() { ctl status | tr ' ' '\n' | sed -n "s/^$1=//p"; }
wait_for() {
  for _ in $(seq 1 $(($3 * 20))); do [[ $(field "$1") == "$2" ]] && return 0; sleep 0.05; done
  fail "waited $3 s for $1=$2: $(ctl status)"
}
"$root/usr/bin/loomctl" serve --config "$root/etc/loomctl/loom.toml" --state-dir "$work/state" --socket "$sock" \
  --group "" --no-telemetry --pace 25 >"$work/serve.log" 2>&1 &
pid=$!
for _ in $(seq 1 200); do [[ -S $sock ]] && break; sleep 0.05; done
[[ -S $sock ]] || fail "no control socket"
sleep 0.3
[[ $(field state) == idle ]] || fail "not waiting: $(ctl status)"
ctl start >/dev/null
wait_for rows 1 30
ctl stop >/dev/null
wait_for state done 30
kill -TERM "$pid"
wait "$pid" || fail "serve exited $? on SIGTERM"
pid=
echo "package_test: ok ($deb, Depends: $depends)"
