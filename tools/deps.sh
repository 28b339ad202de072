#!/usr/bin/env bash
# Installs loomctl's build and test dependencies from Debian by package name. Idempotent: packages
# already present are skipped, and apt is only touched when something is missing.
#   tools/deps.sh            build + test dependencies
#   tools/deps.sh --check    exit 1 (listing them) if any are missing, install nothing
#   tools/deps.sh --arm64    also what the arm64 cross build needs (only when asked: it adds the arm64
#                            architecture to dpkg): Debian's cross compiler, qemu-user, the multiarch
#                            :arm64 dev packages, and a sysroot of LCM's arm64 .debs (LCM is not
#                            multi-arch: installing liblcm-dev:arm64 would remove the host's LCM) in
#                            ~/.cache/loomctl/arm64-sysroot (LOOM_ARM64_SYSROOT), extracted, not installed.
# The vcan VM's packages are not installed here: tools/vcan/vm-deps installs them only when the host
# cannot make a vcan itself (see tests/README.md, "HIL on vcan").
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  clang-format                  # the format check (tests/style)
  ccache                        # rebuilds in fresh clones and worktrees
  libeigen3-dev                 # motion/ linear algebra
  liblcm-dev liblcm-bin         # telemetry (lcm-gen, lcm-logger, lcm-logplayer)
  libgtest-dev libgmock-dev     # tests
  libbenchmark-dev              # benchmarks
  libtomlplusplus-dev           # config files with line:column errors
  libcli11-dev                  # command lines
  nlohmann-json3-dev            # run reports (summary.json)
  libnlopt-cxx-dev              # optimiser (balancing)
  libpng-dev                    # carpet designs drawn as PNGs (one pixel per knot)
  libsqlite3-dev                # the production record (firmware/record)
  libssl-dev                    # SHA-256 of a job's design file (OpenSSL EVP, firmware/job)
  iproute2 can-utils            # vcan set-up, candump/cansend for HIL checks
  clang libclang-rt-14-dev llvm # fuzz build: clang++ -fsanitize=fuzzer (libFuzzer), llvm-symbolizer
  libcpp-httplib-dev            # loom-panel's HTTP server
  libssl-dev openssl            # loom-panel over TLS (cpp-httplib's SSLServer); test certificates
  default-jdk-headless liblcm-java libjchart2d-java  # loomlcm.jar and loom-spy (lcm-spy)
  chromium xvfb xauth imagemagick nodejs  # browser and Xvfb tests of loom-panel and loom-spy
  rt-tests                      # cyclictest: the latency floor the loop is compared with
  valgrind                      # callgrind: the tick's cost in instructions (tests/bench/tick_instructions.sh)
  help2man lintian debootstrap  # the .deb: manual pages from --help, its lint, a clean root to install it in
)

arm64=0
[[ "${1:-}" == "--arm64" ]] && arm64=1
if [[ $arm64 == 1 ]]; then
  packages+=(
    g++-aarch64-linux-gnu qemu-user-static dpkg-dev
    libtomlplusplus-dev:arm64 libgtest-dev:arm64 libgmock-dev:arm64 libbenchmark-dev:arm64
    libnlopt-cxx-dev:arm64 libpng-dev:arm64 libsqlite3-dev:arm64 libssl-dev:arm64
  )
fi

SUDO=""
if [[ $(id -u) -ne 0 ]] && command -v sudo >/dev/null; then SUDO="sudo"; fi
if [[ $arm64 == 1 ]] && ! dpkg --print-foreign-architectures | grep -qx arm64; then
  echo "tools/deps.sh: adding the arm64 architecture to dpkg (multiarch)"
  $SUDO dpkg --add-architecture arm64
  $SUDO apt-get update -qq
fi

missing=()
for p in "${packages[@]}"; do
  # An :arm64 name is checked as such; a bare name is the host's (an arm64 package of the same name
  # must not satisfy it).
  q=$p
  [[ $q == *:* ]] || q="$q:$(dpkg --print-architecture)"
  if ! dpkg-query -W -f='${Status}' "$q" 2>/dev/null | grep -q "install ok installed" &&
     ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# LCM for arm64: downloaded and extracted into a folder, never installed.
arm64_sysroot() {
  local root=${LOOM_ARM64_SYSROOT:-$HOME/.cache/loomctl/arm64-sysroot}
  [[ -f $root/.complete ]] && return 0
  echo "tools/deps.sh: extracting LCM's arm64 .debs into $root"
  local dl
  dl=$(mktemp -d)
  (cd "$dl" && apt-get download -qq liblcm-dev:arm64 liblcm1:arm64 libglib2.0-0:arm64 libpcre2-8-0:arm64 \
     libffi8:arm64 libmount1:arm64 libselinux1:arm64 libblkid1:arm64)
  mkdir -p "$root"
  for d in "$dl"/*.deb; do dpkg-deb -x "$d" "$root"; done
  rm -rf "$dl"
  touch "$root/.complete"
}

if [[ ${#missing[@]} -eq 0 ]]; then
  [[ $arm64 == 1 ]] && arm64_sysroot
  exit 0
fi
if [[ "${1:-}" == "--check" ]]; then
  echo "missing packages: ${missing[*]}" >&2
  exit 1
fi

echo "tools/deps.sh: installing ${missing[*]}"
if [[ $(id -u) -ne 0 && -z $SUDO ]]; then
  echo "tools/deps.sh: need root or sudo to install: ${missing[*]}" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
[[ $arm64 == 1 ]] && arm64_sysroot
exit 0
