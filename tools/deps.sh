#!/usr/bin/env bash
# Installs loomctl's build and test dependencies from Debian by package name. Idempotent: packages
# already present are skipped, and apt is only touched when something is missing.
#   tools/deps.sh            build + test dependencies
#   tools/deps.sh --check    exit 1 (listing them) if any are missing, install nothing
# The vcan VM's packages are not installed here: tools/vcan/vm-deps installs them only when the host
# cannot make a vcan itself (see README, "HIL on vcan").
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config
  ccache                        # rebuilds in fresh clones and worktrees
  libeigen3-dev                 # motion/ linear algebra
  liblcm-dev liblcm-bin         # telemetry (lcm-gen, lcm-logger, lcm-logplayer)
  libgtest-dev libgmock-dev     # tests
  libbenchmark-dev              # benchmarks
  libtomlplusplus-dev           # config files with line:column errors
  libcli11-dev                  # command lines
  nlohmann-json3-dev            # run reports (summary.json)
  libnlopt-cxx-dev              # optimiser (balancing)
  iproute2 can-utils            # vcan set-up, candump/cansend for HIL checks
  clang libclang-rt-14-dev llvm # fuzz build: clang++ -fsanitize=fuzzer (libFuzzer), llvm-symbolizer
  libcpp-httplib-dev            # loom-panel's HTTP server
  default-jdk-headless liblcm-java libjchart2d-java  # loomlcm.jar and loom-spy (lcm-spy)
  chromium xvfb xauth imagemagick nodejs  # browser and Xvfb tests of loom-panel and loom-spy
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [[ ${#missing[@]} -eq 0 ]]; then
  exit 0
fi
if [[ "${1:-}" == "--check" ]]; then
  echo "missing packages: ${missing[*]}" >&2
  exit 1
fi

echo "tools/deps.sh: installing ${missing[*]}"
SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "tools/deps.sh: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
