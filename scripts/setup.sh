#!/usr/bin/env bash
# Installs what the project needs (Debian 12 packages; idempotent: apt-get runs only when
# something is missing) and builds it.
#
#   scripts/setup.sh                 install, then build Release into build/
#   scripts/setup.sh --no-build      install only
#   scripts/setup.sh --build-dir D   build into D
# Environment: CI=true turns warnings into errors.
set -euo pipefail
cd "$(dirname "$0")/.."

build=1
build_dir=build
while [ $# -gt 0 ]; do
  case "$1" in
    --no-build) build=0 ;;
    --build-dir) build_dir="$2"; shift ;;
    -h|--help) awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
  shift
done

packages=(
  build-essential cmake pkg-config git
  liblcm-dev liblcm-bin liblcm-java libglib2.0-dev libjchart2d-java openjdk-17-jdk-headless
  libeigen3-dev libboost-program-options-dev libgtest-dev libssl-dev nlohmann-json3-dev
  libbox2d-dev libbullet-dev libopencv-dev libosmesa6-dev
  clang-14 libclang-rt-14-dev llvm-14  # fuzz/: clang, libFuzzer and sanitizers, symbolizer
  clang-tidy-14  # scripts/tidy.sh
  iproute2 util-linux procps
  qemu-user  # tests/nn/haswell_test.sh: the binaries on a CPU without AVX-512
  slurm-wlm munge  # tests/cluster: a Slurm cluster in namespaces for the cluster tests
  chromium  # headless: the integration test that renders the report and compare pages
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
fi

if [ "$build" -eq 1 ]; then
  werror=OFF
  [ "${CI:-}" = "true" ] && werror=ON
  cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DRL_WARNINGS_AS_ERRORS="$werror" >/dev/null
  cmake --build "$build_dir" -j"$(nproc)"
  echo "setup: built $build_dir/bin"
fi
