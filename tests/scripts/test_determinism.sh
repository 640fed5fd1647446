#!/bin/sh
# Determinism across compilers, optimisation levels, word sizes, endianness
# and bare metal: the fixed-flavour cow after STEPS steps of its clip must give
# the same sn_state_hash on x86-64 (gcc -O0/-O2, clang -O2), i686, 32-bit ARM
# Linux and big-endian MIPS (qemu user mode), and the Cortex-M4 image (QEMU
# mps2-an386), and agree with the desktop player. Float flavour: its own
# desktop-only check (gcc/clang, -O0/-O2, -ffp-contract=off).
# Prints "determinism: <platform> <hash>" per platform.
. ports/cross/port_lib.sh
port_ready_or_exit

STEPS=${SN_DET_STEPS:-1000}
CLIP=tools/examples/cow/trot.clip
D=$BUILD/cross
mkdir -p "$D/logs"
clip_arg=""
if [ -f "$CLIP" ]; then clip_arg="--clip $CLIP"; else echo "note: $CLIP missing, built-in pose sequence"; fi
hashes=""   # "platform hash" lines

record() {  # platform log
    h=$(hash_of "$2")
    if [ -z "$h" ]; then bad "$1: no hash (log $2)"; sed 's/^/    /' "$2" | tail -n 5; return; fi
    echo "determinism: $1 $h"
    hashes="$hashes$1 $h
"
}

# platform compiler runner (runner "-" = native)
hosted() {
    plat=$1; cc=$2; runner=$3
    if ! have "$cc"; then skip "$plat: no $cc (make deps)"; return; fi
    if [ "$runner" != "-" ] && ! have "$runner"; then skip "$plat: no $runner (make deps: qemu-user)"; return; fi
    if ! pmake "$D/det_$plat" > "$D/logs/build_$plat.log" 2>&1; then
        bad "$plat: build failed"; tail -n 20 "$D/logs/build_$plat.log"; return
    fi
    if [ "$runner" = "-" ]; then set -- "$D/det_$plat"; else set -- "$runner" "$D/det_$plat"; fi
    # shellcheck disable=SC2086
    if ! run_log "$D/logs/run_$plat.log" 600 "$@" --steps "$STEPS" $clip_arg; then
        bad "$plat: run failed"; tail -n 5 "$D/logs/run_$plat.log"; return
    fi
    record "$plat" "$D/logs/run_$plat.log"
}

hosted x86_64-gcc-O0   gcc -
hosted x86_64-gcc-O2   gcc -
hosted x86_64-clang-O2 clang -
# i686 static binaries run natively on an x86-64 kernel with IA-32 support,
# else under qemu-i386
i686_runner=-
if have i686-linux-gnu-gcc && pmake "$D/det_i686-gcc-O2" > "$D/logs/build_i686.log" 2>&1 \
   && ! "$D/det_i686-gcc-O2" --steps 0 >/dev/null 2>&1; then i686_runner=qemu-i386; fi
hosted i686-gcc-O2     i686-linux-gnu-gcc "$i686_runner"
hosted armhf-gcc-O2    arm-linux-gnueabihf-gcc qemu-arm
hosted mips-be-gcc-O2  mips-linux-gnu-gcc qemu-mips

# Cortex-M4, bare metal (image steps = BM_STEPS, set to ours)
if ! have arm-none-eabi-gcc; then skip "cortex-m4: no arm-none-eabi-gcc (make deps)"
elif ! have qemu-system-arm; then skip "cortex-m4: no qemu-system-arm (make deps)"
elif ! pmake BM_STEPS="$STEPS" "$BUILD/baremetal/sinew_cow.elf" > "$D/logs/build_cm4.log" 2>&1; then
    bad "cortex-m4: build failed"; tail -n 20 "$D/logs/build_cm4.log"
else
    # shellcheck disable=SC2086
    if run_log "$D/logs/run_cm4.log" 600 $BM_QEMU_RUN -kernel "$BUILD/baremetal/sinew_cow.elf" < /dev/null; then
        record cortex-m4-qemu "$D/logs/run_cm4.log"
    else
        bad "cortex-m4: image failed (rc $?)"; tail -n 5 "$D/logs/run_cm4.log"
    fi
fi

# Desktop player, when it and the cow blob file exist
if [ -x "$BUILD/sinew-play" ] && [ -f "$CLIP" ]; then
    blobfile=$(ls "$BUILD"/examples/cow.snb "$BUILD"/examples/cow.blob 2>/dev/null | head -n 1)
    if [ -n "$blobfile" ] && run_log "$D/logs/run_play.log" 600 "$BUILD/sinew-play" "$blobfile" \
            --clip "$CLIP" --frames "$STEPS" --hash; then
        record sinew-play "$D/logs/run_play.log"
    else
        bad "sinew-play: run failed or no cow blob file"; tail -n 5 "$D/logs/run_play.log" 2>/dev/null
    fi
else
    echo "note: $BUILD/sinew-play not built, desktop player not compared"
fi

n=$(printf '%s' "$hashes" | grep -c .)
distinct=$(printf '%s' "$hashes" | awk '{print $2}' | sort -u | grep -c .)
if [ "$n" -ge 2 ] && [ "$distinct" -eq 1 ]; then
    ok "fixed flavour: $n platforms agree after $STEPS steps"
elif [ "$n" -lt 2 ]; then
    bad "fixed flavour: only $n platform(s) produced a hash"
else
    bad "fixed flavour: hashes differ:"; printf '%s' "$hashes" | sed 's/^/    /'
fi

# Float flavour (desktop only)
fh=""
for plat in float-gcc-O0 float-gcc-O2 float-clang-O2; do
    if ! pmake "$D/det_$plat" > "$D/logs/build_$plat.log" 2>&1; then
        echo "note: $plat not built (no float blob yet?)"; tail -n 3 "$D/logs/build_$plat.log"; continue
    fi
    if run_log "$D/logs/run_$plat.log" 600 "$D/det_$plat" --steps "$STEPS" $clip_arg; then
        h=$(hash_of "$D/logs/run_$plat.log"); echo "determinism: $plat $h"; fh="$fh$h
"
    else
        bad "$plat: run failed"; tail -n 5 "$D/logs/run_$plat.log"
    fi
done
fn=$(printf '%s' "$fh" | grep -c .)
fd=$(printf '%s' "$fh" | sort -u | grep -c .)
if [ "$fn" -ge 2 ] && [ "$fd" -eq 1 ]; then ok "float flavour: $fn builds agree"
elif [ "$fn" -ge 2 ]; then bad "float flavour: hashes differ"
fi
finish
