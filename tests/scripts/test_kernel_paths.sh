#!/bin/sh
# The kernel test on the SIMD paths make test's default build does not
# compile (tests/kernels.mk): x86-64 AVX2, AVX-512 and aarch64 NEON, fixed and float.
# Each must pass its bit-for-bit checks against the portable references
# (fixed: the same integers; float: the reference order's floats).
. ports/cross/port_lib.sh
K=$BUILD/tests/kpaths
L=$K/logs
mkdir -p "$L"
run() {  # name runner(- for none) binary
    if ! pmake "$3" > "$L/build_$1.log" 2>&1; then bad "$1: build failed (see $L/build_$1.log)"; return; fi
    if [ "$2" = - ]; then run_log "$L/$1.log" 120 "$3"; else run_log "$L/$1.log" 300 "$2" "$3"; fi
    if [ $? -eq 0 ] && grep -q ', 0 failed' "$L/$1.log"; then ok "$1: $(head -n 1 "$L/$1.log")"
    else bad "$1 (see $L/$1.log)"; grep FAIL "$L/$1.log" | head -n 5; fi
}
if grep -qw avx2 /proc/cpuinfo 2>/dev/null; then
    run avx2 - "$K/kernels_avx2"
    run avx2_float - "$K/kernels_avx2_float"
else
    SKIPS=$((SKIPS + 1)); echo "SKIPPED: avx2 kernels: this CPU has no avx2"
fi
# AVX-512 (sn_kernels_avx2.c's 512-bit cell products): built here, where run
# (not a make test-build dependency: the runner's CPU decides; ~1 min of CPU)
if grep -qw avx512f /proc/cpuinfo 2>/dev/null && grep -qw avx512vl /proc/cpuinfo 2>/dev/null; then
    run avx512 - "$K/kernels_avx512"
    run avx512_float - "$K/kernels_avx512_float"
else
    SKIPS=$((SKIPS + 1)); echo "SKIPPED: avx512 kernels: this CPU has no avx512f/avx512vl"
fi
if ! have aarch64-linux-gnu-gcc; then skip "aarch64 kernels: no aarch64-linux-gnu-gcc (make deps)"
elif ! have qemu-aarch64; then skip "aarch64 kernels: no qemu-aarch64 (make deps)"
else
    run aarch64 qemu-aarch64 "$K/kernels_aarch64"
    run aarch64_float qemu-aarch64 "$K/kernels_aarch64_float"
fi
finish
