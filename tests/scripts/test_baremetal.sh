#!/bin/sh
# The Cortex-M4 port boots under QEMU mps2-an386 and reports through
# semihosting: a good image plays its asset and exits 0 with a hash, no
# saturation and a stack peak inside its 32 KB; a corrupt blob is rejected on
# target with a message and exit status 1 (SYS_EXIT_EXTENDED carries it).
# The cow image's hash is compared across platforms by test_determinism.sh.
. ports/cross/port_lib.sh
B=$BUILD/baremetal
mkdir -p "$B"
if ! have arm-none-eabi-gcc; then skip "baremetal: no arm-none-eabi-gcc (make deps)"; finish; exit $?; fi
if ! have qemu-system-arm; then skip "baremetal: no qemu-system-arm (make deps)"; finish; exit $?; fi

# error path
if pmake "$B/bad_blob.elf" > "$B/test_build_bad.log" 2>&1; then
    # shellcheck disable=SC2086
    run_log "$B/test_bad.log" 60 $BM_QEMU_RUN -kernel "$B/bad_blob.elf" < /dev/null; rc=$?
    if [ "$rc" -eq 1 ] && grep -q '^FAIL: blob: not a Sinew blob' "$B/test_bad.log"; then
        ok "corrupt blob rejected on target, exit status 1"
    else bad "corrupt blob: rc $rc, log:"; cat "$B/test_bad.log"; fi
else bad "build bad_blob.elf"; tail -n 20 "$B/test_build_bad.log"; fi

# the kernels of sn_kernels.h on the M4 (tests/test_runtime_kernels.c built
# for the image: DSP paths against the portable and double references)
if pmake "$B/test_kernels.elf" > "$B/test_build_kernels.log" 2>&1; then
    # shellcheck disable=SC2086
    run_log "$B/test_kernels.log" 120 $BM_QEMU_RUN -kernel "$B/test_kernels.elf" < /dev/null; rc=$?
    if [ "$rc" -eq 0 ] && grep -q 'path m4' "$B/test_kernels.log" && grep -q '^[1-9][0-9]* passed, 0 failed$' "$B/test_kernels.log"; then
        ok "M4 kernels: $(tail -n 1 "$B/test_kernels.log") (test_runtime_kernels on the image)"
    else bad "M4 kernels: rc $rc, log:"; tail -n 20 "$B/test_kernels.log"; fi
else bad "build test_kernels.elf"; tail -n 20 "$B/test_build_kernels.log"; fi

# good path: the small asset when the tool makes one, else the cow
img=sinew_cow
if pmake -n "$BUILD/examples/limb_blob.c" >/dev/null 2>&1; then img=sinew_limb; fi
if pmake "$B/$img.elf" > "$B/test_build_$img.log" 2>&1; then
    # shellcheck disable=SC2086
    run_log "$B/test_$img.log" 600 $BM_QEMU_RUN -kernel "$B/$img.elf" < /dev/null; rc=$?
    v() { sed -n "s/^$1: //p" "$B/test_$img.log"; }
    if [ "$rc" -eq 0 ] && [ -n "$(hash_of "$B/test_$img.log")" ]; then ok "$img boots, plays $(v steps) steps, exits 0, hash $(hash_of "$B/test_$img.log")"
    else bad "$img: rc $rc"; tail -n 5 "$B/test_$img.log"; fi
    if [ "$(v steps)" = 1000 ]; then ok "$img: 1000 steps"; else bad "$img: steps '$(v steps)'"; fi
    if [ "$(v saturations)" = 0 ]; then ok "$img: no fixed-point saturation"; else bad "$img: saturations '$(v saturations)'"; fi
    s=$(v stack_bytes)
    if [ -n "$s" ] && [ "$s" -lt 32768 ]; then ok "$img: stack peak $s B of 32768"; else bad "$img: stack peak '$s'"; fi
else bad "build $img.elf"; tail -n 20 "$B/test_build_$img.log"; fi
finish
