#!/usr/bin/env bash
# The amd64 .deb, checked from the outside: cpack builds it from the install rules; its control data
# (name, version, architecture, maintainer, conffiles, postinst/prerm/postrm) and its files are what a
# board needs (every program with its manual page, loom-panel and loom-spy with the jar, copyright and
# changelog); every shared library the packaged binaries load belongs to a Debian package named in
# Depends (looked up with dpkg -S, not copied from the CMake file); the service unit runs as its own
# user, is Type=notify with a watchdog, ships no hardware default, passes `systemd-analyze verify` and
# rates below 5 in `systemd-analyze security` (offline); lintian reports no error and no warning; and
# the loomctl extracted (dpkg-deb -x) serves: starts, waits, weaves a row in simulation on `ctl start`,
# stops on `ctl stop`, exits on SIGTERM. (Installing it into a clean Debian root with apt, the
# maintainer scripts run: package_install_test.sh.)
# Usage: package_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
. "$(dirname "$0")/lib.sh"  # board_work
board_work pkg_test
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
grep -q "adduser --system --ingroup loom" "$work/control/postinst" || fail "postinst does not create the loomctl user"
for s in prerm postrm; do [[ -x $work/control/$s ]] || fail "no executable $s"; done
grep -q "stop loomctl.service" "$work/control/prerm" || fail "prerm does not stop the service on removal"
maintainer=$(dpkg-deb -f "$deb" Maintainer)
[[ $maintainer != *@localhost* && $maintainer == *@*.* ]] || fail "maintainer '$maintainer' is not a real address"
[[ ", $depends," == *", adduser,"* ]] || fail "Depends lacks adduser (postinst): $depends"

# ---- files ----
root=$work/root
dpkg-deb -x "$deb" "$root"
for f in usr/bin/loomctl usr/bin/loom-monitor usr/bin/loom-panel usr/bin/loom-spy usr/share/loomctl/loomlcm.jar \
         etc/loomctl/loom.toml etc/default/loomctl etc/default/loom-panel lib/systemd/system/loomctl.service \
         lib/systemd/system/loom-panel.service usr/share/loomctl/lcmtypes/status_t.lcm \
         usr/share/loomctl/lcmtypes/identity_t.lcm usr/share/doc/loomctl/copyright usr/share/doc/loomctl/changelog.gz; do
  [[ -e $root/$f ]] || fail "missing /$f"
done
for bin in "$root"/usr/bin/*; do
  [[ -f $root/usr/share/man/man1/$(basename "$bin").1.gz ]] || fail "no manual page for $(basename "$bin")"
done
grep -qx /etc/default/loom-panel "$work/control/conffiles" || fail "/etc/default/loom-panel is not a conffile"
cmp -s "$root/etc/loomctl/loom.toml" "$src/firmware/config/default_loom.toml" || fail "/etc/loomctl/loom.toml differs from the embedded default"
for k in LimitRTPRIO= LimitMEMLOCK=infinity RuntimeDirectory=loomctl StateDirectory=loomctl "ExecStart=/usr/bin/loomctl serve" \
         User=loomctl Group=loom Type=notify WatchdogSec= "CapabilityBoundingSet=CAP_SYS_NICE CAP_IPC_LOCK" \
         SystemCallFilter=@system-service; do
  grep -q "^$k" "$root/lib/systemd/system/loomctl.service" || fail "unit lacks $k"
done
# No hardware default: the service waits for the builder to say what the board drives.
grep -q '^LOOMCTL_HAL=$' "$root/etc/default/loomctl" || fail "/etc/default/loomctl sets LOOMCTL_HAL"
! grep -q '^[^#]*--hal sim' "$root/etc/default/loomctl" || fail "/etc/default/loomctl arms a simulated loom"
grep -q '^\[Install\]' "$root/lib/systemd/system/loom-panel.service" || fail "loom-panel.service cannot be enabled"
# (postinst may make the panel's TLS certificate; it never enables or starts the panel)
! grep -qE "(systemctl|deb-systemd-helper|deb-systemd-invoke|enable|start).*loom-panel" "$work/control/postinst" ||
  fail "postinst enables or starts loom-panel (it is off by default)"

# ---- every NEEDED library comes from a package in Depends ----
ld_cache=$(ldconfig -p)  # read once: awk exiting early on a pipe would SIGPIPE ldconfig under pipefail
for bin in "$root"/usr/bin/*; do
  [[ $(head -c 4 "$bin") == $'\x7fELF' ]] || continue  # loom-spy is a script
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
  # verify also runs `man` on each Documentation=man:... page: point it at the package's pages.
  for u in loomctl loom-panel; do
    sed "s|/usr/bin/|$root/usr/bin/|" "$root/lib/systemd/system/$u.service" >"$work/$u.service"
    out=$(MANPATH="$root/usr/share/man" systemd-analyze verify "$work/$u.service" 2>&1) || fail "systemd-analyze verify $u: $out"
    [[ -z $out ]] || fail "systemd-analyze verify $u complains: $out"
  done
  exposure=$(systemd-analyze security --offline=true "$root/lib/systemd/system/loomctl.service" 2>/dev/null |
             sed -n 's/.*Overall exposure level for loomctl.service: \([0-9.]*\).*/\1/p')
  [[ -n $exposure ]] || fail "systemd-analyze security gave no exposure level"
  awk -v e="$exposure" 'BEGIN { exit !(e < 5.0) }' || fail "loomctl.service exposure $exposure is not below 5"
  echo "systemd-analyze security loomctl.service: exposure $exposure"
else
  echo "systemd-analyze not installed: unit not verified"
fi

# ---- lintian: no error, no warning (what remains is explained in firmware/packaging/README.md) ----
if command -v lintian >/dev/null; then
  lintian --no-tag-display-limit "$deb" >"$work/lintian.txt" 2>&1 || true
  if grep -q '^[EW]: ' "$work/lintian.txt"; then
    fail "lintian: $(grep -c '^E: ' "$work/lintian.txt") errors, $(grep -c '^W: ' "$work/lintian.txt") warnings:
$(grep '^[EW]: ' "$work/lintian.txt")"
  fi
  echo "lintian: no errors or warnings ($(grep -c '^[IPN]: ' "$work/lintian.txt") info/pedantic notes)"
else
  echo "lintian not installed (apt install lintian): not linted"
fi

# ---- the extracted loomctl serves ----
"$root/usr/bin/loomctl" --version | grep -qx "loomctl $version" || fail "--version"
ctl() { "$root/usr/bin/loomctl" ctl --socket "$sock" "$@"; }
field() { ctl status | tr ' ' '\n' | sed -n "s/^$1=//p"; }
wait_for() {  # bounded in seconds; rows counted as "at least" (a row may pass between two polls)
  local end=$((SECONDS + $3)) v
  while ((SECONDS < end)); do
    v=$(field "$1")
    [[ $v == "$2" ]] && return 0
    [[ $1 == rows && -n $v ]] && ((v >= $2)) && return 0
    sleep 0.05
  done
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
