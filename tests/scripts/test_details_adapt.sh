#!/bin/sh
# Details on the cut level chosen by the runtime (stage 3, runtime/LEVELS.md §3
# "Stage 3"; sn_set_detail_adapt) across builds: the determinism driver on
# cow_details.blob, the set chosen from none, DA_STEPS steps of the trot
# (det_main --detail-adapt --main-only), x86-64 gcc own and shared instances
# and the float build against tests/expected_hashes.txt's details_adapt_trot_*
# (make update-hashes writes them), clang -O2 too, and big-endian MIPS and
# aarch64 under qemu and the Cortex-M4 image (level_dadapt_slice.elf) on
# DA_SLICE_STEPS steps against x86-64's same run. Uses
# the drivers `make test-build` built (nothing is built here: the suites run
# in parallel); a missing one is skipped. About 4 s of CPU.
B=${BUILD:-build}
DA_STEPS=100
DA_SLICE_STEPS=30
CLIP=tools/examples/cow/trot.clip
p=0; f=0
ok() { p=$((p + 1)); echo "  ok: $*"; }
bad() { f=$((f + 1)); echo "FAIL: $*"; }
hash_of() { sed -n 's/^hash: \([0-9a-f]\{16\}\)$/\1/p' | tail -n 1; }
want() { sed -n "s/^$1 \\([0-9a-f]\\{16\\}\\)\$/\\1/p" tests/expected_hashes.txt | tail -n 1; }
run() { # run [RUNNER] DRIVER BLOB STEPS [ARGS]: the hash
    r=""; if [ "$1" = qemu-mips ] || [ "$1" = qemu-aarch64 ]; then r=$1; shift; fi
    d=$1; bl=$2; st=$3; shift 3
    $r "$d" "$bl" --clip $CLIP --steps "$st" --detail-adapt --main-only "$@" 2>&1 | hash_of
}
# the x86-64 drivers make test-build builds (baremetal.mk DET_SLICE) or update-hashes does
X=""
for n in x86_64-gcc-O2 x86_64-clang-O2 x86_64-gcc-O2-avx2; do [ -z "$X" ] && [ -x "$B/cross/det_$n" ] && X=$B/cross/det_$n; done
FL=$B/cross/det_float-gcc-O2
BD=$B/level/cow_details.blob
BF=$B/level/cow_details_float.blob
wf=$(want details_adapt_trot_fixed); wl=$(want details_adapt_trot_float)
[ -n "$wf" ] && [ -n "$wl" ] || bad "tests/expected_hashes.txt has no details_adapt_trot_fixed/float line (make update-hashes)"
if [ -n "$X" ] && [ -f "$BD" ]; then
    xn=${X##*/det_}
    h=$(run "$X" "$BD" $DA_STEPS); [ "$h" = "$wf" ] && ok "$xn $h" || bad "$xn $h, expected $wf"
    h=$(run "$X" "$BD" $DA_STEPS --shared); [ "$h" = "$wf" ] && ok "$xn shared $h" || bad "$xn shared $h, expected $wf"
    C=$B/cross/det_x86_64-clang-O2
    if [ -x "$C" ] && [ "$C" != "$X" ]; then h=$(run "$C" "$BD" $DA_STEPS); [ "$h" = "$wf" ] && ok "x86_64-clang-O2 $h" || bad "x86_64-clang-O2 $h, expected $wf"
    else echo "  skip: x86_64-clang-O2 (no driver, or the reference)"; fi
    ref=$(run "$X" "$BD" $DA_SLICE_STEPS)
    for t in mips-be-gcc-O2:qemu-mips aarch64-gcc-O2:qemu-aarch64; do
        n=${t%%:*}; q=${t#*:}; d=$B/cross/det_$n
        if [ -x "$d" ] && command -v "$q" > /dev/null 2>&1; then
            h=$(run "$q" "$d" "$BD" $DA_SLICE_STEPS)
            [ -n "$h" ] && [ "$h" = "$ref" ] && ok "$n $DA_SLICE_STEPS steps $h" || bad "$n $DA_SLICE_STEPS steps $h, x86-64 $ref"
        else echo "  skip: $n (no driver or $q)"; fi
    done
    # the Cortex-M4 (main_level.c SN_BM_DETAIL_ADAPT, the slice image make test-build builds)
    M=$B/baremetal/level_dadapt_slice.elf
    if [ -f "$M" ] && command -v qemu-system-arm > /dev/null 2>&1; then
        q=$(sed -n 's/^BM_QEMU_RUN="\(.*\)"$/\1/p' ports/cross/port_lib.sh)   # the one QEMU command line
        # shellcheck disable=SC2086
        timeout 300 $q -kernel "$M" < /dev/null > "$B/baremetal/test_dadapt_slice.log" 2>&1
        h=$(hash_of < "$B/baremetal/test_dadapt_slice.log")
        a=$(sed -n 's/^adapt_on: //p' "$B/baremetal/test_dadapt_slice.log")
        r=$(sed -n 's/^adapt_refines: //p' "$B/baremetal/test_dadapt_slice.log")
        s=$(sed -n 's/^saturations: //p' "$B/baremetal/test_dadapt_slice.log")
        if [ -n "$h" ] && [ "$h" = "$ref" ] && [ "$a" = 1 ] && [ "${r:-0}" -gt 0 ] && [ "$s" = 0 ]; then
            ok "cortex-m4 $DA_SLICE_STEPS steps $h (adapt_on $a, refines $r)"
        else bad "cortex-m4 $DA_SLICE_STEPS steps '$h', x86-64 $ref (adapt_on '$a', refines '$r', saturations '$s')"; fi
    else echo "  skip: cortex-m4 (no $M or qemu-system-arm)"; fi
else bad "no x86-64 driver or no $BD (make test-build)"; fi
if [ -x "$FL" ] && [ -f "$BF" ]; then
    h=$(run "$FL" "$BF" $DA_STEPS); [ "$h" = "$wl" ] && ok "float-gcc-O2 $h" || bad "float-gcc-O2 $h, expected $wl"
else bad "no $FL or $BF (make test-build)"; fi
echo "$p passed, $f failed"
[ "$f" -eq 0 ]
