#!/bin/sh
# update_hashes.sh -- rewrite tests/expected_hashes.txt, the committed state
# hashes tests/scripts/test_determinism.sh checks every platform against
# (`make update-hashes`). Run it only for a change meant to alter the
# simulation (blob format, arithmetic, baked matrices, the clip), after
# checking the new motion, and commit the file with that change; the suite
# then catches any later change that alters every platform alike.
# The hashes are the desktop players' (sinew-play, sinew-play-float) on the
# cow and its trot clip for 1000 steps: test_determinism.sh requires every
# platform to agree with them. (Not named test_*.sh: the suite does not run it.)
BUILD=${BUILD:-build}
STEPS=1000
CLIP=${COW_CLIP:-tools/examples/cow/trot.clip}
OUT=tests/expected_hashes.txt
hash_of() { sed -n 's/^hash: \([0-9a-f]\{16\}\)$/\1/p' "$1" | tail -n 1; }
T=$(mktemp "${TMPDIR:-/tmp}/sinew_hash.XXXXXX") || exit 1
trap 'rm -f "$T"' EXIT
"$BUILD/sinew-play" "$BUILD/examples/cow.blob" --clip "$CLIP" --frames $STEPS --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
fixed=$(hash_of "$T")
"$BUILD/sinew-play-float" "$BUILD/examples/cow_float.blob" --clip "$CLIP" --frames $STEPS --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
float=$(hash_of "$T")
[ -n "$fixed" ] && [ -n "$float" ] || { echo "update_hashes: a player printed no hash"; exit 1; }
# the constrained scenario (sn_det_contact: ground, sphere, pins; issue 12)
# from the determinism driver, which every platform runs
hashc_of() { sed -n 's/^hash-contact: \([0-9a-f]\{16\}\)$/\1/p' "$1" | tail -n 1; }
hashb_of() { sed -n 's/^hash-blended: \([0-9a-f]\{16\}\)$/\1/p' "$1" | tail -n 1; }
"$BUILD/cross/det_x86_64-gcc-O2" --steps $STEPS --clip "$CLIP" > "$T" 2>&1 || { cat "$T"; exit 1; }
fixedc=$(hashc_of "$T"); fixedb=$(hashb_of "$T")
"$BUILD/cross/det_float-gcc-O2" "$BUILD/examples/cow_float.blob" --steps $STEPS --clip "$CLIP" > "$T" 2>&1 || { cat "$T"; exit 1; }
floatc=$(hashc_of "$T"); floatb=$(hashb_of "$T")
[ -n "$fixedc" ] && [ -n "$floatc" ] || { echo "update_hashes: the determinism driver printed no contact hash"; exit 1; }
[ -n "$fixedb" ] && [ -n "$floatb" ] || { echo "update_hashes: the determinism driver printed no blended hash"; exit 1; }
CR_CLIP=tools/examples/limb/crease.clip
"$BUILD/sinew-play" "$BUILD/examples/limb_crease.blob" --clip "$CR_CLIP" --frames 400 --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
crfixed=$(hash_of "$T")
"$BUILD/sinew-play-float" "$BUILD/examples/limb_crease_float.blob" --clip "$CR_CLIP" --frames 400 --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
crfloat=$(hash_of "$T")
[ -n "$fixed" ] && [ -n "$float" ] && [ -n "$crfixed" ] && [ -n "$crfloat" ] || { echo "update_hashes: a player printed no hash"; exit 1; }
# level of detail (tests/level.mk: the cow baked with 'levels 2'): the trot with
# switches up, down and up again (sinew-play --lod)
LOD_SW=250:1,500:0,750:1
"$BUILD/sinew-play" "$BUILD/level/cow_lod.blob" --clip "$CLIP" --frames $STEPS --lod $LOD_SW --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
lodfixed=$(hash_of "$T")
"$BUILD/sinew-play-float" "$BUILD/level/cow_lod_float.blob" --clip "$CLIP" --frames $STEPS --lod $LOD_SW --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
lodfloat=$(hash_of "$T")
[ -n "$lodfixed" ] && [ -n "$lodfloat" ] || { echo "update_hashes: a player printed no level-of-detail hash"; exit 1; }
"$BUILD/sinew-play" "$BUILD/level/cow_adapt.blob" --clip "$CLIP" --frames $STEPS --lod $LOD_SW --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
adfixed=$(hash_of "$T")
"$BUILD/sinew-play-float" "$BUILD/level/cow_adapt_float.blob" --clip "$CLIP" --frames $STEPS --lod $LOD_SW --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
adfloat=$(hash_of "$T")
[ -n "$adfixed" ] && [ -n "$adfloat" ] || { echo "update_hashes: a player printed no adaptation hash"; exit 1; }
# the cut level (runtime/LEVELS.md §2 "The cut level"; tests/level.mk): 200 steps of the trot, up at 100, down at 150
CUT_STEPS=200; CUT_SW=100:1,150:0
"$BUILD/sinew-play" "$BUILD/level/cow_cut.blob" --clip "$CLIP" --frames $CUT_STEPS --lod $CUT_SW --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
cutfixed=$(hash_of "$T")
"$BUILD/sinew-play-float" "$BUILD/level/cow_cut_float.blob" --clip "$CLIP" --frames $CUT_STEPS --lod $CUT_SW --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
cutfloat=$(hash_of "$T")
[ -n "$cutfixed" ] && [ -n "$cutfloat" ] || { echo "update_hashes: a player printed no cut-level hash"; exit 1; }
# the same with colliders and pins: the rows on the cut level (and on level 1 from 100 to 150)
CUT_ROWS="--ground -3.587 --sphere 1,-4.337,0,1@0,0.3,0 --pin 2126,2362,1732"
# shellcheck disable=SC2086
"$BUILD/sinew-play" "$BUILD/level/cow_cut.blob" --clip "$CLIP" --frames $CUT_STEPS --lod $CUT_SW $CUT_ROWS --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
cutcfixed=$(hash_of "$T")
# shellcheck disable=SC2086
"$BUILD/sinew-play-float" "$BUILD/level/cow_cut_float.blob" --clip "$CLIP" --frames $CUT_STEPS --lod $CUT_SW $CUT_ROWS --hash --quiet > "$T" 2>&1 || { cat "$T"; exit 1; }
cutcfloat=$(hash_of "$T")
[ -n "$cutcfixed" ] && [ -n "$cutcfloat" ] || { echo "update_hashes: a player printed no cut-level contact hash"; exit 1; }
# details on the cut level (tests/test_runtime_dstep.c): the ramp with the 50 largest details active
# and the runtime choosing them (stage 3, sn_set_detail_adapt), the same ramp
BUILD="$BUILD" "$BUILD/tests/test_runtime_dstep" > "$T" 2>&1
dfixed=$(sed -n 's/^  hash: details50_fixed \([0-9a-f]\{16\}\).*/\1/p' "$T")
dafixed=$(sed -n 's/^  hash: details_adapt_fixed \([0-9a-f]\{16\}\).*/\1/p' "$T")
BUILD="$BUILD" "$BUILD/tests/test_runtime_dstep_float" > "$T" 2>&1
dfloat=$(sed -n 's/^  hash: details50_float \([0-9a-f]\{16\}\).*/\1/p' "$T")
dafloat=$(sed -n 's/^  hash: details_adapt_float \([0-9a-f]\{16\}\).*/\1/p' "$T")
[ -n "$dfixed" ] && [ -n "$dfloat" ] && [ -n "$dafixed" ] && [ -n "$dafloat" ] || { echo "update_hashes: test_runtime_dstep printed no hash"; exit 1; }
# the same blob on the trot (test_determinism.sh's details scenario, every platform): the
# determinism driver, details 0..N-1 active from the first step (the players cannot set details)
# shellcheck disable=SC2046
set -- $(MAKEFLAGS='' make -s --no-print-directory BUILD="$BUILD" print-bm-level); DT_STEPS=$7; DT_N=$9; DT_ITERS=${10}
[ -n "$DT_ITERS" ] || { echo "update_hashes: print-bm-level gave no details run"; exit 1; }
details_pair() {  # ARGS...: "FIXED FLOAT", det_main's hashes on the cow's details blobs (both flavours)
    "$BUILD/cross/det_x86_64-gcc-O2" "$BUILD/level/cow_details.blob" "$@" > "$T" 2>&1 || { cat "$T" >&2; return 1; }
    _fx=$(hash_of "$T")
    "$BUILD/cross/det_float-gcc-O2" "$BUILD/level/cow_details_float.blob" "$@" > "$T" 2>&1 || { cat "$T" >&2; return 1; }
    _fl=$(hash_of "$T")
    [ -n "$_fx" ] && [ -n "$_fl" ] || { echo "update_hashes: the determinism driver printed no details hash ($*)" >&2; return 1; }
    echo "$_fx $_fl"
}
DT_ARGS="--steps $DT_STEPS --clip $CLIP --details $DT_N --iterations $DT_ITERS --main-only"
# shellcheck disable=SC2086
r=$(details_pair $DT_ARGS) || exit 1
dtfixed=${r% *}; dtfloat=${r#* }
# the same blob and trot with the runtime choosing the details from none (tests/scripts/test_details_adapt.sh)
DA_ARGS="--steps 100 --clip $CLIP --detail-adapt --main-only"
# shellcheck disable=SC2086
r=$(details_pair $DA_ARGS) || exit 1
dafixed_t=${r% *}; dafloat_t=${r#* }
old_fixed=$(sed -n 's/^fixed \([0-9a-f]*\).*/\1/p' "$OUT" 2>/dev/null)
old_float=$(sed -n 's/^float \([0-9a-f]*\).*/\1/p' "$OUT" 2>/dev/null)
cat > "$OUT" <<EOT
# Expected sn_state_hash of the cow (tools/examples/cow/cow.sinew) after
# $STEPS steps of tools/examples/cow/trot.clip, checked by
# tests/scripts/test_determinism.sh on every platform (fixed: x86-64, i686,
# armhf, big-endian MIPS, Cortex-M4, sinew-play; float: the desktop builds
# and sinew-play-float). A change that alters every platform alike fails
# there until this file is updated on purpose: \`make update-hashes\`
# (tests/scripts/update_hashes.sh), then commit it with the change.
fixed $fixed
float $float
# The constrained scenario (ports/cross/sn_det.c sn_det_contact: after the
# run above, back to rest, a ground plane, a rising sphere and four pinned
# surface points, 200 steps of the same clip), printed as hash-contact.
fixed-contact $fixedc
float-contact $floatc
# The blended scenario (ports/cross/sn_det.c sn_det_blended: after the
# above, back to rest in SN_MODE_BLENDED, 200 steps of the same clip),
# printed as hash-blended.
fixed-blended $fixedb
float-blended $floatb
# The limb with crease collision active (tools/examples/limb/limb_crease.sinew)
# after 400 steps of tools/examples/limb/crease.clip (the elbow folding to 120
# degrees and back), checked on every hosted platform and sinew-play.
crease_fixed $crfixed
crease_float $crfloat
# The cow baked with 'levels 2' (tests/level.mk), the same 1000 steps of the
# trot with the level switched up, down and up (sinew-play --lod $LOD_SW),
# checked by tests/scripts/test_level.sh.
lod_fixed $lodfixed
lod_float $lodfloat
# The same on the cow baked with 'levels 2' and 'adapt 0.03 0.01 250' (adaptation
# on level 1, runtime/LEVELS.md §3), checked by tests/scripts/test_level.sh.
adapt_fixed $adfixed
adapt_float $adfloat
# The cow baked with 'levels 2 cut' (the cut level, runtime/LEVELS.md §2; tests/level.mk),
# $CUT_STEPS steps of the trot, level 1 from step 100 to 150 (--lod $CUT_SW), checked by
# tests/scripts/test_level.sh and tests/scripts/test_determinism.sh.
cut_fixed $cutfixed
cut_float $cutfloat
# The same run with a ground plane under the feet, a rising sphere under the belly and
# three pinned surface points (sinew-play $CUT_ROWS):
# constraint and contact rows on the cut level, checked by tests/scripts/test_level.sh.
cut_contact_fixed $cutcfixed
cut_contact_float $cutcfloat
# The cow baked with 'levels 2 cut' and 'details 50 0.03 0.01', its 50 largest details active
# (tests/test_runtime_dstep.c: the neck turned 90 degrees in 12 steps, held to 48; 32 iterations),
# checked by test_runtime_dstep.
details50_fixed $dfixed
details50_float $dfloat
# The same ramp with the runtime choosing the details from none (stage 3: sn_set_detail_adapt on,
# the blob's A_max 50 and thresholds 0.03 / 0.01; 32 iterations), checked by test_runtime_dstep.
details_adapt_fixed $dafixed
details_adapt_float $dafloat
# The same blob, details 0..$((DT_N - 1)) active from the first step, $DT_ITERS CG iterations, $DT_STEPS steps
# of the trot, no level switch (ports/cross det_main BLOB $DT_ARGS),
# checked by tests/scripts/test_determinism.sh on every platform and the Cortex-M4.
details_trot_fixed $dtfixed
details_trot_float $dtfloat
# The same blob and trot, 100 steps, the runtime choosing the details from none (det_main BLOB $DA_ARGS),
# checked by tests/scripts/test_details_adapt.sh (x86-64, clang, float; MIPS, aarch64, Cortex-M4 on 30 steps),
# make determinism on every hosted build and make determinism-m4.
details_adapt_trot_fixed $dafixed_t
details_adapt_trot_float $dafloat_t
EOT
echo "update_hashes: fixed ${old_fixed:-none} -> $fixed, float ${old_float:-none} -> $float, contact $fixedc / $floatc ($OUT)"
