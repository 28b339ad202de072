#!/usr/bin/env bash
# The .deb installed the way a board gets it: into a clean Debian bookworm root (debootstrap minbase,
# cached under BUILD_DIR/packaging/bookworm-root.tar — made once, a few minutes; reused after), with
# apt resolving its Depends from the Debian mirror (the .debs apt fetched are cached beside it). Then,
# in that root: postinst created the loom group and the loomctl user, /var/lib/loomctl owned by them,
# and a unique loom id in /etc/loomctl/loom-id (printed); the unit's ExecStartPre refuses to start
# while /etc/default/loomctl does not say what the board drives (exit 2, naming LOOMCTL_HAL); with
# LOOMCTL_HAL=sim the unit's own ExecStart line, run as the loomctl user the way systemd runs it, arms,
# waits, weaves a row on `ctl start` from a member of group loom (a `weaver` account (Debian has a system group `operator`) joined to it with
# `adduser weaver loom`, running `loomctl ctl status` exactly as the READMEs write it, no --socket: ctl
# finds the board's id), a user outside the group is told to `adduser USER loom`, and the service stops
# on SIGTERM; the default loom
# id is refused on hardware; remove runs prerm/postrm and purge leaves the production counters.
# Skips (exit 77) when not root, or without debootstrap or network for a first cache.
# Usage: package_install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
src=$2
[[ $(id -u) == 0 ]] || { echo "SKIP: needs root (chroot)"; exit 77; }
cache=$build/packaging
mkdir -p "$cache/apt-archives"
tarball=$cache/bookworm-root.tar
work=$(mktemp -d /tmp/loom_pkg_install.XXXXXX)
root=$work/root
pid=
cleanup() {
  [[ -n $pid ]] && kill -9 "$pid" 2>/dev/null || true
  for m in proc dev/pts dev; do mountpoint -q "$root/$m" 2>/dev/null && umount -l "$root/$m"; done
  rm -rf "$work"
}
trap cleanup EXIT
fail() { echo "FAIL: $*" >&2; cat "$work"/*.log >&2 2>/dev/null || true; exit 1; }

# ---- the clean root (cached) ----
if [[ ! -s $tarball ]]; then
  command -v debootstrap >/dev/null || { echo "SKIP: debootstrap not installed (apt install debootstrap)"; exit 77; }
  t0=$(date +%s)
  debootstrap --variant=minbase bookworm "$work/new" http://deb.debian.org/debian >"$work/debootstrap.log" 2>&1 ||
    { echo "SKIP: debootstrap could not fetch bookworm (no mirror?): $(tail -1 "$work/debootstrap.log")"; exit 77; }
  tar -C "$work/new" -cf "$tarball.tmp" . && mv "$tarball.tmp" "$tarball"
  rm -rf "$work/new"
  echo "clean root cached in $tarball ($(($(date +%s) - t0)) s)"
fi
mkdir "$root"
tar -C "$root" -xf "$tarball"
mount --bind /dev "$root/dev"
mount -t proc proc "$root/proc"
in_root() { chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin LANG=C.UTF-8 "$@"; }

# ---- install with apt (Depends resolved from the mirror, fetched .debs cached) ----
(cd "$build" && cpack -G DEB -B "$work/pk" >"$work/cpack.log" 2>&1) || fail "cpack"
deb=$(ls "$work"/pk/loomctl_*_amd64.deb)
cp "$deb" "$root/tmp/loomctl.deb"
cp "$cache"/apt-archives/*.deb "$root/var/cache/apt/archives/" 2>/dev/null || true
cp /etc/resolv.conf "$root/etc/resolv.conf"
t0=$(date +%s)
in_root apt-get update -qq >"$work/apt.log" 2>&1 || fail "apt-get update in the clean root"
DEBIAN_FRONTEND=noninteractive in_root apt-get install -y -q --no-install-recommends /tmp/loomctl.deb \
  >"$work/install.log" 2>&1 || fail "apt-get install loomctl.deb: $(tail -5 "$work/install.log")"
cp "$root"/var/cache/apt/archives/*.deb "$cache/apt-archives/" 2>/dev/null || true
echo "installed and configured in the clean root in $(($(date +%s) - t0)) s"
grep -q "loomctl: this board's loom id is loom-" "$work/install.log" || fail "postinst did not print the loom id"

# ---- what postinst did ----
in_root getent group loom >/dev/null || fail "no loom group"
[[ $(in_root id -gn loomctl) == loom ]] || fail "no loomctl user in group loom"
[[ $(in_root stat -c %U:%G /var/lib/loomctl) == loomctl:loom ]] || fail "/var/lib/loomctl not owned by loomctl:loom"
id_line=$(grep '^LOOMCTL_LOOM_ID=' "$root/etc/loomctl/loom-id") || fail "no /etc/loomctl/loom-id"
loom_id=${id_line#LOOMCTL_LOOM_ID=}
[[ $loom_id =~ ^loom-[0-9a-f]{8}$ ]] || fail "derived loom id '$loom_id'"
# Every program runs (its libraries come from the Depends apt installed).
for bin in "$root"/usr/bin/loom*; do
  [[ $(basename "$bin") == loom-spy ]] && continue  # a Java viewer: Recommends, not installed here
  in_root "/usr/bin/$(basename "$bin")" --help >/dev/null 2>&1 || fail "$(basename "$bin") --help fails in the clean root"
done

# ---- the unit, as systemd would run it ----
unit=$root/lib/systemd/system/loomctl.service
pre=$(sed -n 's/^ExecStartPre=//p' "$unit")
exec_start=$(sed -n 's/^ExecStart=//p' "$unit")
run_unit_line() {  # run_unit_line LINE: with the unit's environment files, as loomctl:loom (execs: call it
                   # in a subshell or with &)
  exec chroot "$root" /usr/bin/env -i PATH=/usr/sbin:/usr/bin:/sbin:/bin /bin/sh -c \
    "set -a; . /etc/default/loomctl; . /etc/loomctl/loom-id; LOOMCTL_HAL=\${TEST_HAL:-\$LOOMCTL_HAL}; set +a;
     exec setpriv --reuid=loomctl --regid=loom --init-groups $1"
}
rc=0
(run_unit_line "$pre") >"$work/pre.log" 2>&1 || rc=$?
[[ $rc == 2 ]] || fail "ExecStartPre with the shipped defaults exited $rc, not 2"
grep -q "LOOMCTL_HAL is not set" "$work/pre.log" || fail "ExecStartPre does not say why: $(cat "$work/pre.log")"
install -d -m 0750 -o "$(in_root id -u loomctl)" -g "$(in_root getent group loom | cut -d: -f3)" "$root/run/loomctl"
sed -i 's/^LOOMCTL_HAL=$/LOOMCTL_HAL=sim/' "$root/etc/default/loomctl"
sed -i 's/^LOOMCTL_ARGS=""$/LOOMCTL_ARGS="--pace 25 --no-telemetry"/' "$root/etc/default/loomctl"
(run_unit_line "$pre") || fail "ExecStartPre refuses LOOMCTL_HAL=sim"
run_unit_line "$exec_start" >"$work/serve.log" 2>&1 &
pid=$!
sock=/run/loomctl/$loom_id.sock
# The operator, made a member of group loom the way the package's README says, runs `loomctl ctl status`
# exactly as the READMEs write it: no --socket, no --loom-id (ctl reads the board's id from
# /etc/loomctl/loom-id).
in_root adduser --disabled-password --gecos "" weaver >"$work/adduser.log" 2>&1 || fail "adduser weaver"
in_root adduser weaver loom >>"$work/adduser.log" 2>&1 || fail "adduser weaver loom: $(cat "$work/adduser.log")"
as_operator() { chroot "$root" setpriv --reuid=weaver --regid=weaver --init-groups "$@"; }
ctl() { as_operator /usr/bin/loomctl ctl "$@"; }
field() { ctl status | tr ' ' '\n' | sed -n "s/^$1=//p"; }
for _ in $(seq 1 200); do [[ -S $root$sock ]] && break; sleep 0.05; done
[[ -S $root$sock ]] || fail "no control socket $sock"
sleep 0.3
[[ $(field loom) == "$loom_id" ]] || fail "serving as '$(field loom)', not the derived id $loom_id: $(ctl status 2>&1)"
# Outside group loom: the refusal says which group, and how to join it.
rc=0
chroot "$root" setpriv --reuid=nobody --regid=nogroup --clear-groups /usr/bin/loomctl ctl status >"$work/nobody.log" 2>&1 || rc=$?
[[ $rc == 1 ]] && grep -q "Members of group loom may command the loom: sudo adduser nobody loom" "$work/nobody.log" ||
  fail "a user outside group loom is not told how to join it (exit $rc): $(cat "$work/nobody.log")"
[[ $(field state) == idle ]] || fail "not waiting: $(ctl status)"
ctl start >/dev/null
for _ in $(seq 1 600); do [[ $(field rows) == 1 ]] && break; sleep 0.05; done
[[ $(field rows) == 1 ]] || fail "no row woven: $(ctl status)"
[[ $(stat -c %U "$root/var/lib/loomctl/counters.json") == "$(stat -c %U "$root/var/lib/loomctl")" ]] ||
  fail "counters.json not written by the service user"
kill -TERM "$pid"
wait "$pid" || fail "serve exited $? on SIGTERM"
pid=
# On hardware the default id is refused (a board installed without the derived id).
rc=0
in_root setpriv --reuid=loomctl --regid=loom --init-groups /usr/bin/loomctl serve --config /etc/loomctl/loom.toml \
  --state-dir /tmp/hw --hal socketcan --iface can0 >"$work/hw.log" 2>&1 || rc=$?
[[ $rc == 2 ]] && grep -q "loom id 'loom1' is the default" "$work/hw.log" || fail "default id on hardware: exit $rc $(cat "$work/hw.log")"

# ---- remove, purge ----
DEBIAN_FRONTEND=noninteractive in_root apt-get purge -y -q loomctl >"$work/purge.log" 2>&1 || fail "purge"
[[ ! -e $root/usr/bin/loomctl && ! -e $root/etc/loomctl/loom-id ]] || fail "purge left the program or the loom id"
[[ -f $root/var/lib/loomctl/counters.json ]] || fail "purge removed the production counters"
echo "package_install_test: ok (loom id $loom_id; $(grep -c '^Get:' "$work/install.log" || true) packages fetched)"
