#!/bin/sh
# bench.sh -- `make bench-baremetal`: cost of Sinew on a Cortex-M4 (QEMU
# mps2-an386 under -icount shift=0, one instruction per virtual ns; the image
# times pose and sn_step with CMSDK timer 0 and converts ticks to
# instructions with a calibration loop of known length), plus flash and RAM.
# Instruction counts are repeatable, not cycles: real M4 cycles add wait
# states and multi-cycle loads/multiplies.
. ports/cross/port_lib.sh
if ! have arm-none-eabi-gcc || ! have qemu-system-arm; then
    echo "SKIPPED: bench-baremetal needs arm-none-eabi-gcc and qemu-system-arm (make deps)"; exit 0
fi
B=$BUILD/baremetal
mkdir -p "$B"   # a fresh build directory has none yet
# cow_fem: the cow without its segment meshes (baked in the build tree,
# baremetal.mk), issue 15's goal model
assets="cow cow_fem"
if pmake -n "$BUILD/examples/limb_blob.c" >/dev/null 2>&1; then
    assets="$assets limb"
fi
rt_text=$(for s in $(pmake print-port-sn-srcs); do echo "$B/obj/${s%.c}.o"; done)
for a in $assets; do
    pmake "$B/sinew_$a.elf" "$B/bench_$a.elf" > "$B/bench_build_$a.log" 2>&1 || {
        echo "bench-baremetal: build of $a failed"; tail -n 20 "$B/bench_build_$a.log"; exit 1; }
    # shellcheck disable=SC2086
    timeout 600 $BM_QEMU_RUN -icount shift=0,sleep=off -kernel "$B/bench_$a.elf" < /dev/null > "$B/bench_$a.log" 2>&1 || {
        echo "bench-baremetal: $a image failed"; cat "$B/bench_$a.log"; exit 1; }
    v() { sed -n "s/^$1: //p" "$B/bench_$a.log"; }
    # flash = text + data (initialised data is stored in flash too); RAM =
    # data + bss (the instance buffer is in .bss) + stack peak
    set -- $(arm-none-eabi-size "$B/sinew_$a.elf" | tail -n 1)
    text=$1; data=$2; bss=$3
    rt=$(arm-none-eabi-size -t $rt_text | tail -n 1 | awk '{print $1}')
    blob=$(arm-none-eabi-nm -S "$B/sinew_$a.elf" | awk -v s="sinew_${a}_blob" '$4 == s {print $2}')
    blob=$((0x${blob:-0}))
    inst=$(v instance_bytes); stack=$(v stack_bytes)
    ips=$(v insns_per_step); nF=$(v free_vertices); nb=$(v offdiag_blocks); it=$(v cg_iterations)
    pose=$( [ "$(v clip)" = 1 ] && echo "clip pose" || echo "built-in pose" )
    echo "bench-baremetal: cortex-m4 $a: $ips instructions per sn_step, $(v insns_per_pose) per $pose (mean of $(v bench_steps) steps, qemu -icount)"
    # block multiply-adds per step: the runtime bench's exact count (sn_bench)
    macs=""; hb=$BUILD/examples/$a.blob
    [ "$a" = cow_fem ] && hb=$(pmake print-blob-cow_fem)
    if pmake "$BUILD/bench/sn_bench" "$hb" > "$B/bench_macs_$a.log" 2>&1; then
        macs=$("$BUILD/bench/sn_bench" "$hb" 2>&1 | sed -n 's/^  macs: //p')
    fi
    if [ -n "$macs" ]; then
        echo "bench-baremetal: cortex-m4 $a: lattice $(v lattice_vertices) vertices ($nF free), $nb off-diagonal blocks, $it CG iterations: $macs block multiply-adds per step (runtime bench count): $((ips / macs)) instructions per block multiply-add, all step work included"
    else
        echo "bench-baremetal: cortex-m4 $a: no block multiply-add count ($BUILD/bench/sn_bench not built)"
    fi
    ipc=$(v insns_per_cg_iteration)
    if [ -n "$ipc" ]; then
        # one CG iteration = matvec + preconditioner + dots/axpys
        echo "bench-baremetal: cortex-m4 $a: $ipc instructions per CG iteration (slope $it -> $(v cg_iterations_more) iterations: $(v insns_per_step_more) per step)"
    fi
    echo "bench-baremetal: cortex-m4 $a: hash $(v hash) after $(v bench_steps) steps$( [ -n "$(v hash-contact)" ] && echo " (contact $(v hash-contact))")"
    echo "bench-baremetal: cortex-m4 $a: flash $((text + data)) B (runtime code $rt B, blob $blob B), RAM $((data + bss + stack)) B (.data+.bss $((data + bss)) B: instance $inst B$( [ "$(v clip)" = 1 ] && echo ", parsed clip $(arm-none-eabi-nm -S "$B/sinew_$a.elf" | awk '$4 == "clip" {print 0 + ("0x" $2)}') B"), pose scratch; stack peak $stack B)"
done
