#!/usr/bin/env bash
# install-deps.sh -- Debian 12 packages the build and the test suite need.
# Installs only what is missing (a re-run on a ready box takes a second).
# Used by .ci/run and `make deps`. Non-interactive; needs root (or sudo -n).
set -euo pipefail

# Debian 12 names. gcc-multilib is NOT here: it conflicts with the
# gcc-12-arm-linux-gnueabihf / gcc-12-mips-linux-gnu cross compilers, so i686
# uses the i686-linux-gnu cross compiler (runs natively on x86-64).
# The libc6-dev-*-cross packages are only Recommends of the cross gcc packages
# and --no-install-recommends would leave the cross compilers without headers.
# cmake, pkg-config, g++ and clang (ThreadSanitizer: libclang-rt-14-dev) are
# for tests/scripts/test_integration.sh (CMake package, pkg-config, C++, threads).
# clang + libclang-rt-14-dev (libFuzzer, ASan/UBSan runtimes) + llvm
# (llvm-symbolizer: readable sanitizer reports): tests/fuzz/fuzz.mk's libFuzzer
# harnesses, which must run under CI (tests/scripts/test_fuzz.sh).
# python3: tests/scripts/gltf_check.py, the independent GLB and APNG decoder.
# time: /usr/bin/time, each suite's CPU seconds in tests/run_tests.sh's report.
PKGS=(
    make gcc g++ binutils clang valgrind libclang-rt-14-dev llvm
    cmake pkg-config
    python3 time
    gcc-arm-none-eabi binutils-arm-none-eabi libnewlib-arm-none-eabi
    qemu-system-arm qemu-user
    gcc-arm-linux-gnueabihf libc6-dev-armhf-cross
    gcc-mips-linux-gnu libc6-dev-mips-cross
    gcc-i686-linux-gnu libc6-dev-i386-cross
    gcc-aarch64-linux-gnu libc6-dev-arm64-cross
)

missing=()
for p in "${PKGS[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
        missing+=("$p")
    fi
done
if [ ${#missing[@]} -eq 0 ]; then
    echo "deps: all ${#PKGS[@]} packages present"
    exit 0
fi

SUDO=
if [ "$(id -u)" -ne 0 ]; then
    command -v sudo >/dev/null && SUDO="sudo -n" || { echo "deps: need root to install: ${missing[*]}" >&2; exit 1; }
fi
export DEBIAN_FRONTEND=noninteractive
echo "deps: installing ${missing[*]}"
$SUDO apt-get update -q < /dev/null
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}" < /dev/null
echo "deps: done"
