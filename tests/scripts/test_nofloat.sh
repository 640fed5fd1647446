#!/bin/sh
# The fixed build uses no floating point: the linked Cortex-M4 image
# (-mfloat-abi=soft, so any float would need a helper call) defines or
# references no soft-float helper (__aeabi_f*/d*, i2f/f2i..., libgcc
# __addsf3...), no libm function and no VFP instruction. Positive control:
# the float flavour of a runtime object (sn_math.c) does reference such helpers,
# so the check can see them. Host too: the x86-64 fixed library has no SSE/x87
# float arithmetic (integer SIMD is fine), the float library has.
. ports/cross/port_lib.sh

FLOAT_RE='__aeabi_([fd][a-z0-9]+|[ui]2[fd]|u?l2[fd])$|__(add|sub|mul|div|neg)[sdt]f3$|__float(un)?[sdt]i[sdt]f$|__fix(uns)?[sdt]f[sdt]i$|__extendsfdf2$|__truncdfsf2$|__(eq|ne|lt|le|gt|ge|un|cmp)[sd]f2$'
LIBM_RE='^(sqrtf?|sinf?|cosf?|tanf?|atan2f?|atanf?|acosf?|asinf?|expf?|logf?|powf?|fabsf?|floorf?|ceilf?|fmodf?|roundf?|lrintf?)$'
ELF=$BUILD/baremetal/sinew_cow.elf
L=$BUILD/baremetal/nofloat
mkdir -p "$L"

if ! have arm-none-eabi-gcc || ! have arm-none-eabi-nm; then
    skip "nofloat: no arm-none-eabi-gcc/nm (make deps)"; finish; exit $?
fi
if ! pmake "$ELF" > "$L/build.log" 2>&1; then
    bad "build $ELF"; tail -n 20 "$L/build.log"; finish; exit $?
fi

arm-none-eabi-nm "$ELF" | awk '{print $NF}' > "$L/syms.txt"
hits=$(grep -E "$FLOAT_RE" "$L/syms.txt" | sort -u)
if [ -z "$hits" ]; then ok "image links no soft-float helper"; else bad "image links soft-float helpers:" $hits; fi
hits=$(grep -E "$LIBM_RE" "$L/syms.txt" | sort -u)
if [ -z "$hits" ]; then ok "image links no libm function"; else bad "image links libm:" $hits; fi
vfp=$(arm-none-eabi-objdump -d "$ELF" | awk -F'\t' '$3 ~ /^v[a-z]/ {print $3}' | sort -u | head -n 5)
if [ -z "$vfp" ]; then ok "image has no VFP instruction"; else bad "VFP instructions:" $vfp; fi

# runtime objects alone (fixed): no float helper referenced
objs=$(for s in $(pmake print-port-sn-srcs); do echo "$BUILD/baremetal/obj/${s%.c}.o"; done)
hits=$(arm-none-eabi-nm -u $objs 2>/dev/null | awk '{print $NF}' | grep -E "$FLOAT_RE" | sort -u)
if [ -n "$objs" ] && [ -z "$hits" ]; then ok "fixed runtime objects reference no float helper"
else bad "fixed runtime objects reference:" $hits; fi

# positive control: the float flavour must show up
if pmake bm-float-objs > "$L/build_float.log" 2>&1; then
    fobjs=$(for s in $(pmake print-bm-float-control); do echo "$BUILD/baremetal/obj-float/${s%.c}.o"; done)
    n=$(arm-none-eabi-nm -u $fobjs 2>/dev/null | awk '{print $NF}' | grep -E "$FLOAT_RE" | sort -u | wc -l)
    if [ "$n" -gt 0 ]; then ok "control: float flavour references $n float helpers (the check sees them)"
    else bad "control: float flavour shows no float helper; the check is blind"; fi
else
    bad "control: float flavour build failed"; tail -n 20 "$L/build_float.log"
fi
# host (x86-64) fixed library: no float arithmetic instructions
X86_FP_RE='[[:space:]](add|sub|mul|div|sqrt|min|max|cvt[a-z0-9]*|u?comi|rcp|rsqrt)(ss|sd|ps|pd)[[:space:]]|[[:space:]]f(add|sub|mul|div|ld|st|sqrt|comi)[a-z]*[[:space:]]'
if have objdump && [ "$(uname -m)" = x86_64 ]; then
    libs=$(pmake print-sn-libs)
    if pmake $libs > "$L/build_host.log" 2>&1; then
        set -- $libs
        n=$(objdump -d "$1" | grep -cE "$X86_FP_RE")
        c=$(objdump -d "$2" | grep -cE "$X86_FP_RE")
        if [ "$n" -eq 0 ]; then ok "x86-64 fixed library: no float instruction"; else bad "x86-64 fixed library: $n float instructions"; fi
        if [ "$c" -gt 0 ]; then ok "control: x86-64 float library: $c float instructions"; else bad "control: x86-64 float library shows none; the check is blind"; fi
    else bad "build $libs"; tail -n 20 "$L/build_host.log"; fi
else echo "note: not on x86-64, host library check left out"; fi
finish
