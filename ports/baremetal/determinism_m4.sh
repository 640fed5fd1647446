#!/bin/sh
# determinism_m4.sh -- `make determinism-m4`: the full level-of-detail and
# adaptation scenarios on the Cortex-M4 alone (QEMU mps2-an386; issue 13):
# level_lod.elf and level_adapt.elf, 1000 steps of the trot with switches
# BM_LEVEL_LOD, must give tests/expected_hashes.txt's lod_fixed and
# adapt_fixed, and level_cut.elf, the cut level's BM_CUT_STEPS with switches
# BM_LEVEL_CUT, its cut_fixed, and level_details.elf, BM_DETAILS_STEPS with
# BM_DETAILS_N details active at BM_DETAILS_ITERS iterations, details_trot_fixed
# (the desktop player's and det_main's hashes), and level_dadapt.elf, the same
# steps with the details chosen by the runtime, details_adapt_trot_fixed (`make
# determinism` also compares them with every other platform). Prints each
# run's QEMU wall time.
# Not part of make test (about a minute of QEMU); make test runs a slice.
. ports/cross/port_lib.sh
if ! have arm-none-eabi-gcc || ! have qemu-system-arm; then
    skip "determinism-m4: needs arm-none-eabi-gcc and qemu-system-arm (make deps)"; finish; exit $?
fi
B=$BUILD/baremetal
mkdir -p "$B"
# shellcheck disable=SC2046
set -- $(pmake print-bm-level); steps=$1; sw=$2; cut_steps=$5; cut_sw=$6; dt_steps=$7; dt_n=$9
pmake -j2 "$B/level_lod.elf" "$B/level_adapt.elf" "$B/level_cut.elf" "$B/level_details.elf" "$B/level_dadapt.elf" > "$B/determinism_m4_build.log" 2>&1 || {
    bad "determinism-m4: build failed"; tail -n 20 "$B/determinism_m4_build.log"; finish; exit $?; }
run() {  # i: level_$i.elf, its log and "rc seconds"
    # shellcheck disable=SC2086
    t0=$(date +%s); timeout 600 $BM_QEMU_RUN -kernel "$B/level_$1.elf" < /dev/null > "$B/determinism_m4_$1.log" 2>&1
    echo "$? $(( $(date +%s) - t0 ))" > "$B/determinism_m4_$1.rc"
}
# two at once (2 cores): the cut (~2 s) and details (~6 s) runs after the lod one (~16 s)
( run lod; run cut; run details ) &
( run adapt; run dadapt ) &
wait
for i in lod adapt cut details dadapt; do
    dn=""; key=$i
    case $i in cut) n=$cut_steps; isw=$cut_sw ;; details) n=$dt_steps; isw=""; dn=$dt_n; key=details_trot ;;
             dadapt) n=$dt_steps; isw=""; key=details_adapt_trot ;; *) n=$steps; isw=$sw ;; esac
    read -r rc secs < "$B/determinism_m4_$i.rc"
    h=$(hash_of "$B/determinism_m4_$i.log")
    want=$(sed -n "s/^${key}_fixed \([0-9a-f]\{16\}\).*/\1/p" tests/expected_hashes.txt)
    if [ "$rc" -ne 0 ] || [ -z "$h" ]; then bad "cortex-m4 level_$i: rc $rc"; tail -n 5 "$B/determinism_m4_$i.log"; continue; fi
    echo "determinism-m4: $i $h ($n steps, switches ${isw:-none}, ${secs}s of QEMU wall)"
    bm_level_check "cortex-m4 level_$i" "$B/determinism_m4_$i.log" "$isw" "$([ $i = adapt ] && echo 1 || echo 0)" "$dn"
    if [ "${COW_CLIP:-tools/examples/cow/trot.clip}" != tools/examples/cow/trot.clip ]; then
        echo "note: COW_CLIP=$COW_CLIP: the committed hashes are for the trot; not compared"
    elif [ "$h" = "$want" ]; then ok "cortex-m4 level_$i: hash $h = tests/expected_hashes.txt ${key}_fixed"
    else bad "cortex-m4 level_$i: hash $h, tests/expected_hashes.txt ${key}_fixed '$want'"; fi
done
finish
