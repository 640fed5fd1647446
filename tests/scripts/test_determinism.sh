#!/bin/sh
# Determinism across compilers, optimisation levels, word sizes, endianness
# and bare metal: the fixed-flavour cow after 1000 steps of its clip must give
# the same sn_state_hash on x86-64 (gcc -O0/-O2, clang -O2), i686 (gcc, clang),
# 32-bit ARM Linux and big-endian MIPS (gcc, clang; static, qemu user mode),
# the Cortex-M4 image (QEMU mps2-an386) and the desktop player; and every
# SIMD kernel path: x86-64 scalar/AVX2/AVX-512, aarch64 NEON (gcc, clang) and
# scalar, armhf NEON (qemu user mode), the Cortex-M4 DSP kernels. Float
# flavour: its own desktop-only check (gcc/clang, -O0/-O2, -ffp-contract=off,
# and sinew-play-float).
# The crease, level-of-detail and adaptation scenarios run on every hosted
# platform too (adaptation as a shared instance: sn_step_with's workspace);
# the level-of-detail, adaptation and cut-level ones on the Cortex-M4 too (in
# full under `make determinism`, a slice compared with x86-64 in `make test`;
# big-endian MIPS's and aarch64's level-of-detail and adaptation runs
# likewise, the crease runs of big-endian MIPS and aarch64: CR_SHORT below,
# and the float aarch64 trot: F_SHORT). Details on the
# cut level (50 active, 32 iterations) run on every hosted platform and the
# Cortex-M4 (full in `make determinism`; in `make test` x86-64's full runs
# and short big-endian MIPS, aarch64 and Cortex-M4 runs: DT_SHORT below).
# Every platform must also give the hash committed in tests/expected_hashes.txt
# (update it on purpose with `make update-hashes`).
# Prints "determinism: <platform> <hash>" per platform. A missing toolchain or
# emulator is a loud SKIPPED line (a failure when CI is set).
#
# `make test` runs a slice (DET_SET unset): one build per axis - bare metal
# with the M4 DSP kernels, big-endian, 32-bit ARM with NEON, aarch64 NEON,
# x86-64 gcc -O0 / AVX2 / clang, two float builds and the players - which
# keeps every kernel family, byte order and word size but drops the repeats
# (i686 repeats armhf's 32-bit words, float -O0 the float -O2 path; other
# compilers or levels of the same path; the float aarch64 and armhf NEON
# drivers run the trot alone, MAIN_ONLY below). `make determinism`
# (DET_SET=full) runs all.
. ports/cross/port_lib.sh

STEPS=1000                       # = BM_STEPS, the Cortex-M image's count
COW_CLIP=${COW_CLIP:-tools/examples/cow/trot.clip}; export COW_CLIP
D=$BUILD/cross
L=$D/logs
mkdir -p "$L"; rm -f "$L"/trace_*.log "$L"/rc_* "$L"/run_*
clip_arg=""
if [ -f "$COW_CLIP" ]; then clip_arg="--clip $COW_CLIP"; else echo "note: $COW_CLIP missing, built-in pose sequence"; fi

# ---- which platforms can run here: "name target runner" (runner - = native) ----
# the slice: DET_SLICE in ports/baremetal/baremetal.mk (make test-build builds it)
SLICE=$(pmake print-det-slice)
dropped=""
sel() {  # name: in this run's set?
    [ "${DET_SET:-slice}" = full ] && return 0
    case " $(echo $SLICE) " in *" $1 "*) return 0 ;; esac
    dropped="$dropped $1"; return 1
}
plats=""
add() { plats="$plats$1 $2 $3
"; }
want() {  # name compiler runner
    sel "$1" || return 0
    if ! have "$2"; then skip "$1: no $2 (make deps)"; return; fi
    if [ "$3" != "-" ] && ! have "$3"; then skip "$1: no $3 (make deps)"; return; fi
    add "$1" "$D/det_$1" "$3"
}
# longest runs first, so two at a time pack well
if ! sel cortex-m4-qemu; then :
elif ! have arm-none-eabi-gcc; then skip "cortex-m4: no arm-none-eabi-gcc (make deps)"
elif ! have qemu-system-arm; then skip "cortex-m4: no qemu-system-arm (make deps)"
else add cortex-m4-qemu "$BUILD/baremetal/sinew_cow.elf" qemu-system-arm; m4=1; fi
# the level-of-detail, adaptation and cut-level scenarios on the Cortex-M4
# (issue 13, ports/baremetal/main_level.c, the cow_lod / cow_adapt / cow_cut C
# arrays): the full runs in `make determinism` (QEMU: ~16 s lod + ~46 s adapt
# + ~2 s cut, whose run is CUT_STEPS/CUT_SW below), checked
# with every other platform and tests/expected_hashes.txt; in the slice a
# short run with earlier switches (print-bm-level) whose hash must equal an
# x86-64 det_main's of the same run, made here (a cross-platform identity).
m4lvl=""
if [ -n "${m4:-}" ] && [ -n "$clip_arg" ]; then
    if [ "${DET_SET:-slice}" = full ]; then m4lvl="level_lod level_adapt level_cut level_details"
    else m4lvl="level_lod_slice level_adapt_slice level_cut_slice level_details_slice"; fi
elif [ -n "${m4:-}" ]; then skip "cortex-m4 level of detail: the images play $COW_CLIP, which is missing"; fi
# shellcheck disable=SC2046
set -- $(pmake print-bm-level); M4_STEPS=$1; M4_SW=$2; M4_SLICE_STEPS=$3; M4_SLICE_SW=$4; M4_CUT_STEPS=$5; M4_CUT_SW=$6
# the details run (baremetal.mk BM_DETAILS_*, one definition for the image and the hosted drivers)
DT_STEPS=$7; DT_SLICE_STEPS=$8; DT_N=$9; DT_ITERS=${10}
# the slice's float aarch64 trot runs short (F_SHORT), its hash equal to an
# x86-64 float det_main's of the same steps (the fref run below): 1000 steps
# cost 7.1 s of qemu CPU (float NEON emulated), 250 steps 1.8 s; 1000 steps
# against tests/expected_hashes.txt in `make determinism` (the x86-64 float
# builds and sinew-play-float run 1000 here). Not the Cortex-M4 cow: its
# contact and blended scenarios (fixed lengths) are most of its 8.8 s
F_SHORT=""; F_SLICE_STEPS=250; [ "${DET_SET:-slice}" = full ] || F_SHORT="float-aarch64-gcc-O2"
want mips-be-gcc-O2  mips-linux-gnu-gcc qemu-mips
# clang cross: needs the cross gcc for headers, crt files and libgcc
if have clang; then want mips-be-clang-O2 mips-linux-gnu-gcc qemu-mips; else skip "mips-be-clang-O2: no clang"; fi
want armhf-gcc-O2    arm-linux-gnueabihf-gcc qemu-arm
want x86_64-gcc-O0   gcc -
want float-gcc-O0   gcc -
want i686-gcc-O2     i686-linux-gnu-gcc -
if have clang; then want i686-clang-O2 i686-linux-gnu-gcc -; else skip "i686-clang-O2: no clang"; fi
want x86_64-gcc-O2   gcc -
# SIMD kernel paths (runtime/src/sn_kernels.h; the plain x86_64 builds are the
# SSE2 baseline): each must give the scalar build's hash. A path this CPU
# cannot run is built and reported skipped with the reason (not a CI
# failure: the runner's CPU decides, not the install).
want x86_64-gcc-O2-scalar gcc -
want_cpu() {  # name compiler cpu-flag...
    n=$1; c=$2; shift 2
    sel "$n" || return 0
    for f in "$@"; do
        if ! grep -qw "$f" /proc/cpuinfo 2>/dev/null; then
            SKIPS=$((SKIPS + 1)); echo "SKIPPED: $n: this CPU has no $f (built only)"
            pmake "$D/det_$n" > "$L/build_$n.log" 2>&1 || bad "$n: build failed (see $L/build_$n.log)"
            return
        fi
    done
    want "$n" "$c" -
}
want_cpu x86_64-gcc-O2-avx2 gcc avx2
want_cpu x86_64-gcc-O0-avx2 gcc avx2
want_cpu x86_64-gcc-O2-avx512 gcc avx512f avx512vl
if have clang; then
    want_cpu x86_64-clang-O2-avx2 clang avx2
    want_cpu x86_64-clang-O2-avx512 clang avx512f avx512vl
    want_cpu float-clang-O2-avx512 clang avx512f avx512vl
fi
want_cpu float-gcc-O2-avx2 gcc avx2
want_cpu float-gcc-O2-avx512 gcc avx512f avx512vl
if have clang; then want_cpu float-clang-O2-avx2 clang avx2; fi
# the float flavour's NEON kernels (aarch64 only) and its scalar reference there
want float-aarch64-gcc-O2 aarch64-linux-gnu-gcc qemu-aarch64
want float-aarch64-gcc-O2-scalar aarch64-linux-gnu-gcc qemu-aarch64
if have clang; then want float-aarch64-clang-O2 aarch64-linux-gnu-gcc qemu-aarch64; fi
want armhf-gcc-O2-neon arm-linux-gnueabihf-gcc qemu-arm
want aarch64-gcc-O2  aarch64-linux-gnu-gcc qemu-aarch64
want aarch64-gcc-O2-scalar aarch64-linux-gnu-gcc qemu-aarch64
if have clang; then want aarch64-clang-O2 aarch64-linux-gnu-gcc qemu-aarch64; else skip "aarch64-clang-O2: no clang"; fi
want x86_64-clang-O2 clang -
want float-gcc-O2   gcc -
want float-clang-O2 clang -

[ -z "$dropped" ] || echo "note: slice (make determinism runs every build); not built here:$dropped"

# ---- build everything in one make -k -j2 ----
targets="$(printf '%s' "$plats" | awk '{print $2}') $(for i in $m4lvl; do echo "$BUILD/baremetal/$i.elf"; done)"
# shellcheck disable=SC2086
pmake -k -j2 $targets > "$L/build.log" 2>&1 || true

# ---- run, two at a time ----
# the slice runs only the trot (no contact or blended scenario) on the float
# aarch64 and armhf NEON drivers: under qemu those two scenarios cost 40 s
# (float NEON emulated) and 22 s of their 50 s and 26 s; the scenarios' code
# is the same C on every target and runs on big-endian MIPS, aarch64, x86-64
# -O0/AVX2/clang and three float builds in the slice, everywhere in `make
# determinism`
MAIN_ONLY=""; [ "${DET_SET:-slice}" = full ] || MAIN_ONLY="float-aarch64-gcc-O2 armhf-gcc-O2-neon"
cmd_for() {  # name target runner -> command line
    _mo=""; case " $MAIN_ONLY " in *" $1 "*) _mo=" --main-only" ;; esac
    _st=$STEPS; case " $F_SHORT " in *" $1 "*) _st=$F_SLICE_STEPS ;; esac
    case $1 in float-*) r=""; [ "$3" = - ] || r="$3 "
                        echo "$r$2 $BUILD/examples/cow_float.blob --steps $_st $clip_arg$_mo"; return ;; esac
    case $3 in
        -) echo "$2 --steps $STEPS $clip_arg$_mo" ;;
        qemu-system-arm) echo "$BM_QEMU_RUN -kernel $2" ;;
        *) echo "$3 $2 --steps $STEPS $clip_arg$_mo" ;;
    esac
}
# launch RCFILE LOG CMD...: run CMD in the background, output to LOG, "rc
# seconds" to RCFILE; at most 2 at once (2 cores): polls for a finished one.
# Every run below (cow, crease, level of detail, players) shares this pool.
pids=""; n_run=0
launch() {
    _rf=$1; _lg=$2; shift 2
    ( t0=$(date +%s); timeout 600 "$@" < /dev/null > "$_lg" 2>&1; echo "$? $(( $(date +%s) - t0 ))" > "$_rf" ) &
    pids="$pids $!"; n_run=$((n_run + 1))
    while [ "$n_run" -ge 2 ]; do
        live=""; n_run=0
        for _p in $pids; do if kill -0 "$_p" 2>/dev/null; then live="$live $_p"; n_run=$((n_run + 1)); fi; done
        pids=$live
        [ "$n_run" -ge 2 ] && sleep 1
    done
}
rc_ok() { [ -f "$1" ] && [ "$(cut -d' ' -f1 "$1")" = 0 ]; }  # RCFILE: the run exited 0
start=$(date +%s)
# the Cortex-M4 level runs first: the full adaptation run is the longest of all
for i in $m4lvl; do
    if pmake -q "$BUILD/baremetal/$i.elf" 2>/dev/null; then
        # shellcheck disable=SC2086
        launch "$L/rc_m4_$i" "$L/run_m4_$i.log" $BM_QEMU_RUN -kernel "$BUILD/baremetal/$i.elf"
    else bad "cortex-m4 $i: build failed (see $L/build.log)"; grep -E 'error|Error' "$L/build.log" | head -n 5; fi
done
built=""
while read -r name target runner; do
    [ -n "$name" ] || continue
    # -q: a failed build may leave an old binary behind; only an up-to-date one runs
    if ! pmake -q "$target" 2>/dev/null; then
        bad "$name: build failed (see $L/build.log)"; grep -E 'error|Error' "$L/build.log" | head -n 5
        continue
    fi
    built="$built $name"
    c=$(cmd_for "$name" "$target" "$runner")
    # i686: native on an x86-64 kernel with IA-32 support, else qemu-i386
    case $name in i686-*) "$target" --steps 0 >/dev/null 2>&1 || c="qemu-i386 $c" ;; esac
    launch "$L/rc_$name" "$L/run_$name.log" $c
done <<EOF2
$plats
EOF2

# ---- crease collision active (seed 003 §3.4): the limb with its elbow
# crease (limb_crease.blob) folding to 120 degrees and back
# (tools/examples/limb/crease.clip), CR_STEPS steps, on every hosted platform
# (the Cortex-M4 image links the cow only) and sinew-play ----
CR_STEPS=400
CR_CLIP=tools/examples/limb/crease.clip
# the slice runs the crease short on big-endian MIPS and aarch64 (CR_SHORT):
# the clip's contacts all come and go within CR_SLICE_STEPS (the list fills
# from step ~95 and is empty again by step 220: 456 pairs added, 456
# removed; the last 180 steps are the limb at rest, which their trot runs
# cover), the main scenario only (the crease run's blended hash is compared
# nowhere), its hash equal to the x86-64 det_main's of the same run (the
# m4ref runs below): 400 steps and the blended scenario cost 19 s of qemu
# CPU on MIPS, the slice 6 s; the full runs everywhere in `make determinism`
CR_SLICE_STEPS=220
CR_SHORT=""; [ "${DET_SET:-slice}" = full ] || CR_SHORT="mips-be-gcc-O2 aarch64-gcc-O2"
pmake "$BUILD/examples/limb_crease.blob" "$BUILD/examples/limb_crease_float.blob" > "$L/build_crease.log" 2>&1 || \
    { bad "crease: blobs failed to bake"; tail -n 5 "$L/build_crease.log"; }
# ---- level of detail (issue 13, runtime/LEVELS.md): the cow baked with
# 'levels 2', the trot with the level switched up, down and up, on every
# hosted platform; sinew-play's hash is tests/expected_hashes.txt's lod_* ----
LOD_SW=250:1,500:0,750:1
pmake "$BUILD/level/cow_lod.blob" "$BUILD/level/cow_lod_float.blob" > "$L/build_lod.log" 2>&1 || \
    { bad "lod: blobs failed to bake"; tail -n 5 "$L/build_lod.log"; }
# ---- adaptation (runtime/LEVELS.md §3): the same trot and switches on the cow
# baked with 'adapt' (tests/level.mk), stepped as a shared instance with
# sn_step_with on its own workspace: every port checks both against the
# own-scratch player's hash (tests/expected_hashes.txt adapt_*) ----
# (not at -O0: the integer path is the same as at -O2, and its 16-iteration
# level-1 steps cost a minute there)
ADAPT_SKIP="x86_64-gcc-O0 float-gcc-O0"
# the slice runs no scenario (crease, lod, adapt, cut) on the float aarch64
# NEON driver (its kernels are checked by its trot hash and by
# test_kernel_paths.sh; its scenarios cost 135 s under qemu, float NEON
# emulated), at -O0 (the -O2 builds' integer path; 31 s) nor on armhf NEON
# (its trot hash stays; the scenarios' 32-bit paths run on big-endian MIPS,
# their NEON kernels on aarch64; 55 s under qemu); all run them in `make
# determinism`
SCEN_SKIP=""; [ "${DET_SET:-slice}" = full ] || SCEN_SKIP="float-aarch64-gcc-O2 x86_64-gcc-O0 armhf-gcc-O2-neon"
# the slice runs big-endian MIPS's level-of-detail and adaptation scenarios
# short, as the Cortex-M4 slice does (print-bm-level: 60 steps, switches
# 20:1,40:0,50:1, so both levels and adaptation's refines and coarsens run),
# its hash equal to the x86-64 det_main's of the same run (the m4ref runs
# below): their 1000 steps cost 18 s and 33 s of qemu CPU; the full runs, with
# tests/expected_hashes.txt, on x86-64 and aarch64 here and everywhere in
# `make determinism`
# aarch64 likewise (its 1000-step adaptation run cost 13.9 s of qemu CPU, level
# of detail 5.9 s; their NEON kernels run 1000 steps in its trot)
SCEN_SHORT=""; [ "${DET_SET:-slice}" = full ] || SCEN_SHORT="mips-be-gcc-O2 aarch64-gcc-O2"
pmake "$BUILD/level/cow_adapt.blob" "$BUILD/level/cow_adapt_float.blob" > "$L/build_adapt.log" 2>&1 || \
    { bad "adapt: blobs failed to bake"; tail -n 5 "$L/build_adapt.log"; }
# ---- the cut level (runtime/LEVELS.md §2 "The cut level"): the cow baked with
# 'levels 2 cut', 200 steps of the trot, level 1 from 100 to 150 (cut_* hashes) ----
CUT_STEPS=200; CUT_SW=100:1,150:0
CUT_MAIN_ONLY=""; [ "${DET_SET:-slice}" = full ] || CUT_MAIN_ONLY="mips-be-gcc-O2"
# the cut run also plays det_main's contact and blended scenarios on the cut
# level (rows weigh points by the cut field, sn_point_weights): their hashes
# must agree across platforms (about 3 s of CPU under qemu; test_level.sh
# checks the players' cut_contact_* lines against tests/expected_hashes.txt)
pmake "$BUILD/level/cow_cut.blob" "$BUILD/level/cow_cut_float.blob" > "$L/build_cut.log" 2>&1 || \
    { bad "cut: blobs failed to bake"; tail -n 5 "$L/build_cut.log"; }
# ---- details on the cut level (runtime/LEVELS.md §3 "Details on the cut
# level"): cow_details.blob (the cut bake plus 'details 50 0.03 0.01'),
# details 0..DT_N-1 active from the first step (sn_details_set) at DT_ITERS
# CG iterations (above the 16 of the floor: accuracy wants 32 for 50),
# DT_STEPS steps of the trot, no switch (details_trot_* hashes). The slice
# runs big-endian MIPS and aarch64 short (DT_SHORT, DT_SLICE_STEPS), as the
# Cortex-M4 slice, their hash equal to the x86-64 det_main's of the same run:
# 100 steps cost 3.2 s (MIPS) and 2.2 s (aarch64) of qemu CPU, 30 steps a
# third; the full runs everywhere in `make determinism`
DT_SHORT=""; [ "${DET_SET:-slice}" = full ] || DT_SHORT="mips-be-gcc-O2 aarch64-gcc-O2"
DT_ARGS="--details $DT_N --iterations $DT_ITERS --main-only"
DA_RUN=0; [ "${DET_SET:-slice}" = full ] && DA_RUN=1
pmake "$BUILD/level/cow_details.blob" "$BUILD/level/cow_details_float.blob" > "$L/build_details.log" 2>&1 || \
    { bad "details: blobs failed to bake"; tail -n 5 "$L/build_details.log"; }
while read -r name target runner; do
    case $name in cortex-*|"") continue ;; esac
    case " $built " in *" $name "*) ;; *) continue ;; esac
    case $name in float-*) b=$BUILD/examples/limb_crease_float.blob; bl=$BUILD/level/cow_lod_float.blob
                           ba=$BUILD/level/cow_adapt_float.blob; bc=$BUILD/level/cow_cut_float.blob
                           bd=$BUILD/level/cow_details_float.blob ;;
                        *) b=$BUILD/examples/limb_crease.blob; bl=$BUILD/level/cow_lod.blob
                           ba=$BUILD/level/cow_adapt.blob; bc=$BUILD/level/cow_cut.blob
                           bd=$BUILD/level/cow_details.blob ;; esac
    case " $SCEN_SKIP " in *" $name "*) continue ;; esac
    r=""; [ "$runner" = - ] || r=$runner
    case $name in i686-*) "$target" --steps 0 >/dev/null 2>&1 || r=qemu-i386 ;; esac
    case " $CR_SHORT " in
        *" $name "*) launch "$L/rc_crease_$name" "$L/run_crease_$name.log" $r "$target" "$b" --steps $CR_SLICE_STEPS \
                         --clip $CR_CLIP --main-only ;;
        *) launch "$L/rc_crease_$name" "$L/run_crease_$name.log" $r "$target" "$b" --steps $CR_STEPS --clip $CR_CLIP ;;
    esac
    st=$STEPS; sw=$LOD_SW
    case " $SCEN_SHORT " in *" $name "*) st=$M4_SLICE_STEPS; sw=$M4_SLICE_SW ;; esac
    launch "$L/rc_lod_$name" "$L/run_lod_$name.log" $r "$target" "$bl" --steps $st $clip_arg --lod $sw --main-only
    # the cut run's contact and blended scenarios: not on big-endian MIPS in the
    # slice (3.8 s of its qemu CPU with them; aarch64 and x86-64 run them)
    cmo=""; case " $CUT_MAIN_ONLY " in *" $name "*) cmo=--main-only ;; esac
    launch "$L/rc_cut_$name" "$L/run_cut_$name.log" $r "$target" "$bc" --steps $CUT_STEPS $clip_arg --lod $CUT_SW $cmo
    dst=$DT_STEPS; case " $DT_SHORT " in *" $name "*) dst=$DT_SLICE_STEPS ;; esac
    # shellcheck disable=SC2086
    launch "$L/rc_details_$name" "$L/run_details_$name.log" $r "$target" "$bd" --steps $dst $clip_arg $DT_ARGS
    # the details chosen by the runtime (stage 3, sn_set_detail_adapt), the set
    # from none: the full matrix only (make test: tests/scripts/test_details_adapt.sh)
    [ "$DA_RUN" = 1 ] && launch "$L/rc_dadapt_$name" "$L/run_dadapt_$name.log" $r "$target" "$bd" --steps $DT_STEPS \
        $clip_arg --detail-adapt --main-only
    case " $ADAPT_SKIP " in *" $name "*) continue ;; esac
    launch "$L/rc_adapt_$name" "$L/run_adapt_$name.log" $r "$target" "$ba" --steps $st $clip_arg --lod $sw \
        --main-only --shared
done <<EOF2
$plats
EOF2
# the x86-64 reference of the Cortex-M4 slice and of SCEN_SHORT: det_main on the same steps and switches
m4ref=""; need_ref=""
case $m4lvl in *_slice*) need_ref=1 ;; esac
for _sn in $SCEN_SHORT $CR_SHORT $DT_SHORT; do case " $built " in *" $_sn "*) need_ref=1 ;; esac; done
# the float aarch64 trot's slice against x86-64's float det_main
fref=""
for _sn in $F_SHORT; do case " $built " in *" $_sn "*)
    for c in float-gcc-O2 float-clang-O2 float-gcc-O2-avx2; do case " $built " in *" $c "*) fref=$c; break ;; esac; done
    if [ -n "$fref" ]; then
        launch "$L/rc_m4ref_fmain" "$L/run_m4ref_fmain.log" "$D/det_$fref" "$BUILD/examples/cow_float.blob" \
            --steps "$F_SLICE_STEPS" $clip_arg --main-only
    else bad "$_sn: no x86-64 float det_main built to compare with"; fi ;; esac
done
case $need_ref in 1)
    for c in x86_64-gcc-O2 x86_64-clang-O2 x86_64-gcc-O2-avx2 x86_64-gcc-O0; do
        case " $built " in *" $c "*) m4ref=$c; break ;; esac
    done
    if [ -n "$m4ref" ]; then
        launch "$L/rc_m4ref_lod" "$L/run_m4ref_lod.log" "$D/det_$m4ref" "$BUILD/level/cow_lod.blob" \
            --steps "$M4_SLICE_STEPS" $clip_arg --lod "$M4_SLICE_SW" --main-only
        launch "$L/rc_m4ref_adapt" "$L/run_m4ref_adapt.log" "$D/det_$m4ref" "$BUILD/level/cow_adapt.blob" \
            --steps "$M4_SLICE_STEPS" $clip_arg --lod "$M4_SLICE_SW" --main-only --shared
        launch "$L/rc_m4ref_cut" "$L/run_m4ref_cut.log" "$D/det_$m4ref" "$BUILD/level/cow_cut.blob" \
            --steps "$M4_SLICE_STEPS" $clip_arg --lod "$M4_SLICE_SW" --main-only
        # shellcheck disable=SC2086
        launch "$L/rc_m4ref_details" "$L/run_m4ref_details.log" "$D/det_$m4ref" "$BUILD/level/cow_details.blob" \
            --steps "$DT_SLICE_STEPS" $clip_arg $DT_ARGS
        [ -z "$CR_SHORT" ] || launch "$L/rc_m4ref_crease" "$L/run_m4ref_crease.log" "$D/det_$m4ref" \
            "$BUILD/examples/limb_crease.blob" --steps "$CR_SLICE_STEPS" --clip "$CR_CLIP" --main-only
    else bad "level and crease slices (cortex-m4, $SCEN_SHORT $CR_SHORT $DT_SHORT): no x86-64 det_main built to compare with"; fi ;;
esac
# the desktop players: the crease and the cow (fixed: the blob file of the
# same bake; float: against the float drivers)
for fl in "" _float; do
    p=$BUILD/sinew-play; [ -n "$fl" ] && p=$BUILD/sinew-play-float   # the float player's name has a dash, the blob's an underscore
    if pmake "$p" "$BUILD/examples/cow$fl.blob" > "$L/build_play$fl.log" 2>&1; then
        launch "$L/rc_crease_play$fl" "$L/run_crease_play$fl.log" "$p" "$BUILD/examples/limb_crease$fl.blob" \
            --clip "$CR_CLIP" --frames "$CR_STEPS" --hash --quiet
        launch "$L/rc_play$fl" "$L/run_play$fl.log" "$p" "$BUILD/examples/cow$fl.blob" $clip_arg --frames "$STEPS" --hash --quiet
    else bad "$(basename "$p"): build failed"; tail -n 10 "$L/build_play$fl.log"; fi
done
wait
echo "note: runs took $(( $(date +%s) - start ))s wall"

fixed=""; float=""; fixedc=""; floatc=""; fixedb=""; floatb=""
while read -r name target runner; do
    [ -n "$name" ] && [ -f "$L/rc_$name" ] || continue
    set -- $(cat "$L/rc_$name"); rc=$1; secs=$2
    h=$(hash_of "$L/run_$name.log")
    hc=$(hashc_of "$L/run_$name.log")
    hb=$(hashb_of "$L/run_$name.log")
    if [ "$rc" -ne 0 ] || [ -z "$h" ]; then
        bad "$name: run failed (rc $rc)"; tail -n 5 "$L/run_$name.log" | sed 's/^/    /'; continue
    fi
    echo "determinism: $name $h contact ${hc:-none} blended ${hb:-none} (${secs}s)"
    # the slice's short float run: equal to x86-64 det_main's same run, not in the 1000-step list
    case " $F_SHORT " in *" $name "*)
        r=$(hash_of "$L/run_m4ref_fmain.log")
        if [ -n "$r" ] && [ "$h" = "$r" ]; then ok "$name: hash $h = $fref det_main's ($F_SLICE_STEPS steps)"
        else bad "$name: hash $h, $fref det_main ${r:-none} ($F_SLICE_STEPS steps)"; fi
        continue ;;
    esac
    case $name in float-*) [ -n "$hb" ] && floatb="$floatb$name $hb
" ;; *) [ -n "$hb" ] && fixedb="$fixedb$name $hb
" ;; esac
    case $name in float-*) float="$float$name $h
"; [ -n "$hc" ] && floatc="$floatc$name $hc
" ;; *) fixed="$fixed$name $h
"; [ -n "$hc" ] && fixedc="$fixedc$name $hc
" ;; esac
done <<EOF2
$plats
EOF2

# the crease and level-of-detail runs: "fixed"/"float" lists per scenario
# A short run (SCENARIO NAME HASH WHAT): its hash must equal x86-64 det_main's
# run of the same steps made in this run (run_m4ref_SCENARIO.log)
short_eq() {
    echo "determinism: $1 $2 $3 ($4)"
    r=$(hash_of "$L/run_m4ref_$1.log")
    if [ -n "$r" ] && [ "$3" = "$r" ]; then ok "$1 $2: hash $3 = $m4ref det_main's ($4)"
    else bad "$1 $2: hash $3, x86-64 det_main ${r:-none} ($4)"; fi
}
dtfixed=""; dtfloat=""; dafixed=""; dafloat=""; crfixed=""; crfloat=""; lodfixed=""; lodfloat=""; adfixed=""; adfloat=""; cutfixed=""; cutfloat=""; cutcfixed=""; cutcfloat=""
while read -r name target runner; do
    case $name in cortex-*|"") continue ;; esac
    case " $built " in *" $name "*) ;; *) continue ;; esac
    case " $SCEN_SKIP " in *" $name "*) continue ;; esac
    for sc in crease lod adapt cut details dadapt; do
        case $sc:" $ADAPT_SKIP " in adapt:*" $name "*) continue ;; esac
        [ $sc != dadapt ] || [ "$DA_RUN" = 1 ] || continue
        if rc_ok "$L/rc_${sc}_$name" && h=$(hash_of "$L/run_${sc}_$name.log") && [ -n "$h" ]; then
            case "$sc: $SCEN_SHORT " in lod:*" $name "*|adapt:*" $name "*)
                short_eq "$sc" "$name" "$h" "$M4_SLICE_STEPS steps, switches $M4_SLICE_SW"; continue ;;
            esac
            case "$sc: $CR_SHORT " in crease:*" $name "*)
                short_eq crease "$name" "$h" "$CR_SLICE_STEPS steps"; continue ;;
            esac
            case "$sc: $DT_SHORT " in details:*" $name "*)
                short_eq details "$name" "$h" "$DT_SLICE_STEPS steps, $DT_N details, $DT_ITERS iterations"; continue ;;
            esac
            echo "determinism: $sc $name $h"
            if [ $sc = cut ] && hc=$(hashc_of "$L/run_cut_$name.log") && [ -n "$hc" ]; then
                hb=$(hashb_of "$L/run_cut_$name.log")
                echo "determinism: cut contact $name $hc blended ${hb:-none}"
                case $name in float-*) cutcfloat="$cutcfloat$name $hc/$hb
" ;; *) cutcfixed="$cutcfixed$name $hc/$hb
" ;; esac
            fi
            case $sc-$name in
                crease-float-*) crfloat="$crfloat$name $h
" ;;            crease-*) crfixed="$crfixed$name $h
" ;;            lod-float-*) lodfloat="$lodfloat$name $h
" ;;            lod-*) lodfixed="$lodfixed$name $h
" ;;            cut-float-*) cutfloat="$cutfloat$name $h
" ;;            cut-*) cutfixed="$cutfixed$name $h
" ;;            dadapt-float-*) dafloat="$dafloat$name $h
" ;;            dadapt-*) dafixed="$dafixed$name $h
" ;;            details-float-*) dtfloat="$dtfloat$name $h
" ;;            details-*) dtfixed="$dtfixed$name $h
" ;;            adapt-float-*) adfloat="$adfloat$name $h
" ;;            *) adfixed="$adfixed$name $h
" ;;        esac
        else bad "$sc $name: run failed"; tail -n 5 "$L/run_${sc}_$name.log" | sed 's/^/    /'; fi
    done
done <<EOF2
$plats
EOF2
# the Cortex-M4 level runs: the image's own checks (bm_level_check), then
# its hash joins the full run's lists, or must equal the x86-64 slice's
case $m4lvl in level_lod*) [ "$M4_SW" = "$LOD_SW" ] || bad "cortex-m4: BM_LEVEL_LOD $M4_SW (baremetal.mk) is not LOD_SW $LOD_SW" ;; esac
case " $m4lvl " in *" level_cut "*) [ "$M4_CUT_SW" = "$CUT_SW" ] && [ "$M4_CUT_STEPS" = "$CUT_STEPS" ] || \
    bad "cortex-m4: BM_CUT_STEPS/BM_LEVEL_CUT $M4_CUT_STEPS $M4_CUT_SW (baremetal.mk) are not CUT_STEPS/CUT_SW $CUT_STEPS $CUT_SW" ;; esac
for i in $m4lvl; do
    case $i in level_adapt*) sc=adapt; ad=1; ;; level_cut*) sc=cut; ad=0 ;; level_details*) sc=details; ad=0 ;; *) sc=lod; ad=0 ;; esac
    case $i in level_details_slice) sw=""; n=$DT_SLICE_STEPS ;; level_details) sw=""; n=$DT_STEPS ;;
               *_slice) sw=$M4_SLICE_SW; n=$M4_SLICE_STEPS ;; level_cut) sw=$M4_CUT_SW; n=$M4_CUT_STEPS ;; *) sw=$M4_SW; n=$M4_STEPS ;; esac
    dn=""; [ $sc = details ] && dn=$DT_N
    [ -f "$L/rc_m4_$i" ] || continue   # build failed: reported above
    if rc_ok "$L/rc_m4_$i" && h=$(hash_of "$L/run_m4_$i.log") && [ -n "$h" ]; then
        echo "determinism: $sc cortex-m4-qemu $h ($n steps, switches ${sw:-none}, $(cut -d' ' -f2 "$L/rc_m4_$i")s)"
        bm_level_check "cortex-m4 $i" "$L/run_m4_$i.log" "$sw" "$ad" "$dn"
        case $i in
            level_lod) lodfixed="${lodfixed}cortex-m4-qemu $h
" ;;        level_adapt) adfixed="${adfixed}cortex-m4-qemu $h
" ;;        level_cut) cutfixed="${cutfixed}cortex-m4-qemu $h
" ;;        level_details) dtfixed="${dtfixed}cortex-m4-qemu $h
" ;;        *) if rc_ok "$L/rc_m4ref_$sc" && r=$(hash_of "$L/run_m4ref_$sc.log") && [ -n "$r" ]; then
                   if [ "$h" = "$r" ]; then ok "cortex-m4 $i: hash $h = $m4ref det_main's ($n steps, switches ${sw:-none})"
                   else bad "cortex-m4 $i: hash $h, $m4ref det_main $r ($n steps, switches ${sw:-none})"; fi
               elif [ -n "$m4ref" ]; then bad "cortex-m4 $i: $m4ref det_main reference run failed"; tail -n 5 "$L/run_m4ref_$sc.log" | sed 's/^/    /'
               fi ;;
        esac
    else bad "cortex-m4 $i: run failed (rc $(cut -d' ' -f1 "$L/rc_m4_$i" 2>/dev/null))"; tail -n 5 "$L/run_m4_$i.log" | sed 's/^/    /'; fi
done
for fl in "" _float; do
    [ -f "$L/rc_play$fl" ] || continue   # build failed: reported above
    p=sinew-play; [ -n "$fl" ] && p=sinew-play-float
    if rc_ok "$L/rc_crease_play$fl" && h=$(hash_of "$L/run_crease_play$fl.log") && [ -n "$h" ]; then
        echo "determinism: crease $p $h"
        if [ -z "$fl" ]; then crfixed="${crfixed}sinew-play $h
"; else crfloat="${crfloat}sinew-play-float $h
"; fi
    else bad "crease $p: run failed"; tail -n 5 "$L/run_crease_play$fl.log" | sed 's/^/    /'; fi
    if rc_ok "$L/rc_play$fl" && h=$(hash_of "$L/run_play$fl.log") && [ -n "$h" ]; then
        echo "determinism: $p $h"
        if [ -z "$fl" ]; then fixed="${fixed}sinew-play $h
"; else float="${float}sinew-play-float $h
"; fi
    else bad "$p: run failed"; tail -n 5 "$L/run_play$fl.log" | sed 's/^/    /'; fi
done

agree() {  # label list min [run]: run names the steps where every build runs the same count
    n=$(printf '%s' "$2" | grep -c .)
    d=$(printf '%s' "$2" | awk '{print $2}' | sort -u | grep -c .)
    if [ "$n" -ge "$3" ] && [ "$d" -eq 1 ]; then ok "$1: $n builds agree${4:+ $4}"
    elif [ "$n" -lt "$3" ]; then bad "$1: only $n build(s) gave a hash"
    else bad "$1: hashes differ:"; printf '%s' "$2" | sed 's/^/    /'; fi
}
agree "fixed flavour" "$fixed" 2 "after $STEPS steps"
# on a mismatch, locate it: the first step (traced every 10) where a hosted
# build leaves the trace of a build with the most common hash
major=$(printf '%s' "$fixed" | awk '{print $2}' | sort | uniq -c | sort -rn | awk 'NR==1 {print $2}')
if [ "$(printf '%s' "$fixed" | awk '{print $2}' | sort -u | grep -c .)" -gt 1 ]; then
    for pass in ref odd; do
        while read -r name target runner; do
            case $name in float-*|cortex-*|"") continue ;; esac
            h=$(hash_of "$L/run_$name.log")
            [ -n "$h" ] || continue
            c=$(cmd_for "$name" "$target" "$runner")
            if [ "$pass" = ref ] && [ "$runner" = - ] && [ "$h" = "$major" ] && [ ! -f "$L/trace_ref.log" ]; then
                timeout 600 $c --trace 10 < /dev/null > "$L/trace_ref.log" 2>&1; echo "    trace reference: $name"
            elif [ "$pass" = odd ] && [ "$h" != "$major" ] && [ -f "$L/trace_ref.log" ]; then
                timeout 600 $c --trace 10 < /dev/null > "$L/trace_$name.log" 2>&1
                echo "    $name: first differing trace line: $(diff "$L/trace_ref.log" "$L/trace_$name.log" | grep '^>' | head -n 1)"
            fi
        done <<EOF2
$plats
EOF2
    done
    rm -f "$L/trace_ref.log"
fi
agree "float flavour" "$float" 3
# the constrained scenario (issue 12: ground, sphere, pins), every driver but the players
agree "fixed flavour, constraints and contact" "$fixedc" 2
agree "float flavour, constraints and contact" "$floatc" 2
agree "fixed flavour, blended mode" "$fixedb" 2
agree "float flavour, blended mode" "$floatb" 2
agree "crease, fixed flavour" "$crfixed" 2
agree "crease, float flavour" "$crfloat" 2
agree "level of detail, fixed flavour" "$lodfixed" 2
agree "level of detail, float flavour" "$lodfloat" 2
agree "adaptation (shared workspace), fixed flavour" "$adfixed" 2
agree "adaptation (shared workspace), float flavour" "$adfloat" 2
agree "cut level, fixed flavour" "$cutfixed" 2
agree "cut level, float flavour" "$cutfloat" 2
agree "cut level, contact/blended scenarios, fixed flavour" "$cutcfixed" 2
agree "cut level, contact/blended scenarios, float flavour" "$cutcfloat" 2
agree "details on the cut level, fixed flavour" "$dtfixed" 2
agree "details on the cut level, float flavour" "$dtfloat" 2
if [ "$DA_RUN" = 1 ]; then
    agree "details chosen by the runtime, fixed flavour" "$dafixed" 2
    agree "details chosen by the runtime, float flavour" "$dafloat" 2
fi

# ---- the committed hashes (tests/expected_hashes.txt): platforms agreeing
# with each other is not enough; a change that alters every platform alike
# must be made on purpose (`make update-hashes`, commit the file) ----
expect_hash() {  # label list key
    want=$(sed -n "s/^$3 \([0-9a-f]\{16\}\).*/\1/p" tests/expected_hashes.txt 2>/dev/null)
    got=$(printf '%s' "$2" | awk '{print $2}' | sort | uniq -c | sort -rn | awk 'NR==1 {print $2}')
    if [ -z "$want" ]; then bad "$1: no '$3' hash in tests/expected_hashes.txt (make update-hashes)"
    elif [ -z "$got" ]; then bad "$1: no hash to compare with the committed $want"
    elif [ "$got" = "$want" ]; then ok "$1: hash $got = tests/expected_hashes.txt"
    else bad "$1: every platform gives $got, tests/expected_hashes.txt says $want: if the change is meant to alter the simulation, run 'make update-hashes' and commit tests/expected_hashes.txt with it"; fi
}
if [ "$COW_CLIP" = tools/examples/cow/trot.clip ] && [ -n "$clip_arg" ]; then
    expect_hash "fixed flavour" "$fixed" fixed
    expect_hash "float flavour" "$float" float
    expect_hash "fixed flavour, constraints and contact" "$fixedc" fixed-contact
    expect_hash "float flavour, constraints and contact" "$floatc" float-contact
    expect_hash "fixed flavour, blended mode" "$fixedb" fixed-blended
    expect_hash "float flavour, blended mode" "$floatb" float-blended
    expect_hash "crease, fixed flavour" "$crfixed" crease_fixed
    expect_hash "crease, float flavour" "$crfloat" crease_float
    expect_hash "level of detail, fixed flavour" "$lodfixed" lod_fixed
    expect_hash "level of detail, float flavour" "$lodfloat" lod_float
    expect_hash "adaptation (shared workspace), fixed flavour" "$adfixed" adapt_fixed
    expect_hash "adaptation (shared workspace), float flavour" "$adfloat" adapt_float
    expect_hash "cut level, fixed flavour" "$cutfixed" cut_fixed
    expect_hash "cut level, float flavour" "$cutfloat" cut_float
    expect_hash "details on the cut level, fixed flavour" "$dtfixed" details_trot_fixed
    expect_hash "details on the cut level, float flavour" "$dtfloat" details_trot_float
    if [ "$DA_RUN" = 1 ]; then
        expect_hash "details chosen by the runtime, fixed flavour" "$dafixed" details_adapt_trot_fixed
        expect_hash "details chosen by the runtime, float flavour" "$dafloat" details_adapt_trot_float
    fi
else
    echo "note: COW_CLIP=$COW_CLIP: the committed hashes are for tools/examples/cow/trot.clip; not compared"
fi
finish
