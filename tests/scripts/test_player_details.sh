#!/bin/sh
# test_player_details.sh -- details on the cut level in the desktop player
# (runtime/LEVELS.md §3 "Details on the cut level"): --details N|all and
# --compare-details FILE (cut level | cut + details | level 1), fixed and
# float. The --details run must give det_main's committed hash
# (tests/expected_hashes.txt details_trot_*: another driver, same steps);
# the comparison's level-1 panel must be the lod blob's level 1 to the bit
# (--level1-blob: the cut bake's level 1 is the 'levels 2' bake's), the
# cut level must differ from it, and every bad input fails with its message.
# Blobs: tests/level.mk (make test-build bakes them).
# Usage: sh tests/scripts/test_player_details.sh [BUILD]
BUILD=${1:-${BUILD:-build}}
PLAY=$BUILD/sinew-play
PLAYF=$BUILD/sinew-play-float
L=$BUILD/level
DET=$L/cow_details.blob
DETF=$L/cow_details_float.blob
TMP=$(mktemp -d "${TMPDIR:-/tmp}/sn_player_details.XXXXXX") || exit 1
trap 'rm -rf "$TMP"' EXIT
. tests/scripts/cli_lib.sh
need "$PLAY" "$PLAYF" "$DET" "$DETF" "$L/cow_lod.blob" "$L/cow_cut.blob" "$BUILD/examples/cow.blob" "$BUILD/examples/limb.blob"
TROT=tools/examples/cow/trot.clip
TURN=tools/examples/cow/head_turn.clip

# the committed hash of det_main's details run (test_determinism.sh: 50 details, 32 iterations, 100 steps)
for fl in fixed float; do
    if [ $fl = fixed ]; then P=$PLAY; B=$DET; else P=$PLAYF; B=$DETF; fi
    got=$("$P" "$B" --clip $TROT --frames 100 --details 50 --iterations 32 --hash --quiet 2>/dev/null | sed -n 's/^hash: //p')
    want=$(sed -n "s/^details_trot_$fl \([0-9a-f]\{16\}\).*/\1/p" tests/expected_hashes.txt)
    if [ -n "$got" ] && [ "$got" = "$want" ]; then ok "details_trot_$fl: --details 50 gives det_main's $got"
    else bad "details_trot_$fl: sinew-play --details 50 hash '$got', tests/expected_hashes.txt says '$want'"; fi
done
# all = the blob's A_max (50), the same run
expect 0 "details: 50 active on the cut level" "$PLAY" "$DET" --frames 1 --details all
a=$("$PLAY" "$DET" --clip $TROT --frames 20 --details all --iterations 32 --hash --quiet 2>/dev/null | sed -n 's/^hash: //p')
b=$("$PLAY" "$DET" --clip $TROT --frames 20 --details 50 --iterations 32 --hash --quiet 2>/dev/null | sed -n 's/^hash: //p')
c=$("$PLAY" "$DET" --clip $TROT --frames 20 --details 49 --iterations 32 --hash --quiet 2>/dev/null | sed -n 's/^hash: //p')
if [ -n "$a" ] && [ "$a" = "$b" ] && [ "$a" != "$c" ]; then ok "--details all = --details 50 ($a), 49 differs ($c)"
else bad "--details all '$a', 50 '$b', 49 '$c'"; fi

# bad input: usage errors (2), blobs that cannot (1)
expect 2 "want N \(1..65535\) or all" "$PLAY" "$DET" --details 0
expect 2 "want N \(1..65535\) or all" "$PLAY" "$DET" --details 5x
expect 2 "--compare-details needs --details" "$PLAY" "$DET" --compare-details "$TMP/x.png"
expect 2 "one at a time" "$PLAY" "$DET" --details 5 --compare-details "$TMP/x.png" --compare "$TMP/y.png"
expect 2 "not with --lod" "$PLAY" "$DET" --details 5 --compare-details "$TMP/x.png" --lod 5:1
expect 2 "--level1-blob needs --compare-details" "$PLAY" "$DET" --details 5 --level1-blob "$L/cow_lod.blob"
expect 1 "takes at most 50" "$PLAY" "$DET" --frames 1 --details 51
expect 1 "has no details" "$PLAY" "$L/cow_cut.blob" --frames 1 --details 1
expect 1 "has no details" "$PLAY" "$BUILD/examples/cow.blob" --frames 1 --details all
expect 1 "is not the character" "$PLAY" "$DET" --frames 1 --details 5 --compare-details "$TMP/x.png" --level1-blob "$BUILD/examples/limb.blob"
[ ! -e "$TMP/x.png" ] && ok "no picture after a failed run" || bad "a failed run left $TMP/x.png"

# the picture: 3 panels of 240x180 (--size 320x240); distances printed
png_size() { od -An -tu1 -j16 -N8 "$1" | awk '{ print $3 * 256 + $4 "x" $7 * 256 + $8 }'; }
for fl in fixed float; do
    if [ $fl = fixed ]; then P=$PLAY; B=$DET; else P=$PLAYF; B=$DETF; fi
    out=$("$P" "$B" --clip $TURN --frames 40 --details all --iterations 32 --compare-details "$TMP/d_$fl.png" \
          --heat 0.05 --size 320x240 2>&1); rc=$?
    if [ $rc -eq 0 ] && [ "$(png_size "$TMP/d_$fl.png" 2>/dev/null)" = 720x180 ]; then ok "$fl: --compare-details wrote a 720x180 picture"
    else bad "$fl: --compare-details rc $rc, size '$(png_size "$TMP/d_$fl.png" 2>/dev/null)': $out"; fi
    cut=$(echo "$out" | sed -n 's/^compare-details: cut level: surface from level 1 max \([^ ]*\) rms \([^ ]*\) .*/\1 \2/p')
    det=$(echo "$out" | sed -n 's/^compare-details: cut + 50 details: surface from level 1 max \([^ ]*\) rms \([^ ]*\) .*/\1 \2/p')
    echo "figure: $fl cow head turn, 40 steps: surface from level 1 (max rms, mesh units): cut level $cut, cut + 50 details $det"
    # the cut level is not level 1: a level-1 panel left on the cut level would give 0
    if [ -n "$cut" ] && awk -v c="$cut" 'BEGIN { split(c, a, " "); exit !(a[1] > 0 && a[2] > 0) }'; then ok "$fl: the cut level differs from level 1 ($cut)"
    else bad "$fl: cut level from level 1 '$cut'"; fi
    # --level1-blob with the lod blob (level 1 by sn_set_lod): the same level 1, the same figures
    if [ $fl = fixed ]; then
        out2=$("$P" "$B" --clip $TURN --frames 40 --details all --iterations 32 --compare-details "$TMP/d2.png" \
               --level1-blob "$L/cow_lod.blob" --size 320x240 2>&1)
        if [ -n "$det" ] && [ "$(echo "$out" | grep '^compare-details:')" = "$(echo "$out2" | grep '^compare-details:')" ]; then
            ok "--level1-blob cow_lod.blob: the same level 1 to the printed digits"
        else bad "--level1-blob cow_lod.blob differs: $(echo "$out2" | grep '^compare-details:')"; fi
    fi
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
