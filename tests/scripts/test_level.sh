#!/bin/sh
# Level of detail on the cow and the beast, fixed and float
# (tests/test_runtime_level.c; blobs from tests/level.mk). LEVEL_ALL=1
# (make level-all) adds the float cow's adaptation run.
B=${BUILD:-build}
L=$B/level
p=0; f=0
# run one test program, print its output, add its closing "N passed, N failed" line
# (no line, or a non-zero exit without failures, counts as one failure)
suite() {
    title=$1; shift
    out=$("$@" 2>&1); rc=$?
    echo "== $title"
    echo "$out"
    line=$(echo "$out" | grep -E '^[0-9]+ passed, [0-9]+ failed' | tail -n 1)
    if [ -z "$line" ]; then f=$((f + 1)); return; fi
    p=$((p + ${line%% passed*}))
    ff=${line#*passed, }; ff=${ff%% failed*}
    f=$((f + ff))
    [ "$rc" -eq 0 ] || [ "$ff" -ne 0 ] || f=$((f + 1))
}
for fl in "" _float; do
    for c in cow beast; do
        suite "level_runtime$fl $c" "$B/tests/level_runtime$fl" "$B/examples/$c$fl.blob" "$L/${c}_lod$fl.blob"
    done
done
# adaptation (tests/test_runtime_adapt.c, blobs from tests/level.mk): both characters at the runtime's
# iterations (the blob's, at least SN_ADAPT_MIN_ITERATIONS = 16 in a reduced solve, sn_adapt.h);
# float: the beast (its swing overflows A_max, the cow's does not), the cow too with LEVEL_ALL=1
# (make level-all)
for fl in "" _float; do
    chars="cow beast"; [ "$fl" = _float ] && [ "${LEVEL_ALL:-0}" != 1 ] && chars=beast
    for c in $chars; do
        suite "adapt_runtime$fl $c" "$B/tests/adapt_runtime$fl" "$L/${c}_lod$fl.blob" "$L/${c}_adapt$fl.blob"
    done
done
# the cut level (tests/test_runtime_cut.c): the study's held poses (runtime/LEVELS.md §3)
for fl in "" _float; do
    suite "cut_runtime$fl cow" "$B/tests/cut_runtime$fl" "$L/cow_cut$fl.blob" "$L/cow_lod$fl.blob" neck y 90
    suite "cut_runtime$fl beast" "$B/tests/cut_runtime$fl" "$L/beast_cut$fl.blob" "$L/beast_lod$fl.blob" elbow_l y 90
done
# rows on the cut level (tests/test_runtime_cut_rows.c): pins, a sphere, crease on the cow and the crease
# limb, both flavours (fixed also against levels 0 and 1: --compare); the beast's cut level, fixed (its float
# run and the comparisons: runtime/LEVELS.md's commands)
suite "cut_rows cow" "$B/tests/cut_rows" --compare "$L/cow_cut.blob" "$L/cow_lod.blob" "$L/limb_crease_cut.blob"
suite "cut_rows_float cow" "$B/tests/cut_rows_float" "$L/cow_cut_float.blob" "$L/cow_lod_float.blob" "$L/limb_crease_cut_float.blob"
suite "cut_rows beast" "$B/tests/cut_rows" "$L/beast_cut.blob" "$L/beast_lod.blob"
for fl in "" _float; do
    suite "cut_rows_fold$fl limb_crease" "$B/tests/cut_rows_fold$fl" -c "$L/limb_crease_cut$fl.blob"
done
# determinism: the trot with level switches gives the committed hashes (tests/expected_hashes.txt)
for fl in fixed float; do
    if [ $fl = fixed ]; then P=$B/sinew-play; BL=$L/cow_lod.blob; else P=$B/sinew-play-float; BL=$L/cow_lod_float.blob; fi
    got=$("$P" "$BL" --clip tools/examples/cow/trot.clip --frames 1000 --lod 250:1,500:0,750:1 --hash --quiet 2>/dev/null |
          sed -n 's/^hash: \([0-9a-f]\{16\}\)$/\1/p' | tail -n 1)
    want=$(sed -n "s/^lod_$fl \([0-9a-f]\{16\}\).*/\1/p" tests/expected_hashes.txt)
    if [ -n "$got" ] && [ "$got" = "$want" ]; then echo "  ok: lod_$fl hash $got"; p=$((p + 1));
    else echo "FAIL: lod_$fl: hash '$got', tests/expected_hashes.txt says '$want'"; f=$((f + 1)); fi
done
# adaptation: the same trot and switches on the blob baked with 'adapt 0.03 0.01 250'
for fl in fixed float; do
    if [ $fl = fixed ]; then P=$B/sinew-play; BL=$L/cow_adapt.blob; else P=$B/sinew-play-float; BL=$L/cow_adapt_float.blob; fi
    got=$("$P" "$BL" --clip tools/examples/cow/trot.clip --frames 1000 --lod 250:1,500:0,750:1 --hash --quiet 2>/dev/null |
          sed -n 's/^hash: \([0-9a-f]\{16\}\)$/\1/p' | tail -n 1)
    want=$(sed -n "s/^adapt_$fl \([0-9a-f]\{16\}\).*/\1/p" tests/expected_hashes.txt)
    if [ -n "$got" ] && [ "$got" = "$want" ]; then echo "  ok: adapt_$fl hash $got"; p=$((p + 1));
    else echo "FAIL: adapt_$fl: hash '$got', tests/expected_hashes.txt says '$want'"; f=$((f + 1)); fi
done
# the cut level: 200 steps of the trot, level 1 from 100 to 150 (tests/scripts/update_hashes.sh)
for fl in fixed float; do
    if [ $fl = fixed ]; then P=$B/sinew-play; BL=$L/cow_cut.blob; else P=$B/sinew-play-float; BL=$L/cow_cut_float.blob; fi
    got=$("$P" "$BL" --clip tools/examples/cow/trot.clip --frames 200 --lod 100:1,150:0 --hash --quiet 2>/dev/null |
          sed -n 's/^hash: \([0-9a-f]\{16\}\)$/\1/p' | tail -n 1)
    want=$(sed -n "s/^cut_$fl \([0-9a-f]\{16\}\).*/\1/p" tests/expected_hashes.txt)
    if [ -n "$got" ] && [ "$got" = "$want" ]; then echo "  ok: cut_$fl hash $got"; p=$((p + 1));
    else echo "FAIL: cut_$fl: hash '$got', tests/expected_hashes.txt says '$want'"; f=$((f + 1)); fi
done
# the same with colliders and pins: the rows on the cut level (tests/scripts/update_hashes.sh CUT_ROWS)
for fl in fixed float; do
    if [ $fl = fixed ]; then P=$B/sinew-play; BL=$L/cow_cut.blob; else P=$B/sinew-play-float; BL=$L/cow_cut_float.blob; fi
    got=$("$P" "$BL" --clip tools/examples/cow/trot.clip --frames 200 --lod 100:1,150:0 --ground -3.587 \
          --sphere 1,-4.337,0,1@0,0.3,0 --pin 2126,2362,1732 --hash --quiet 2>/dev/null |
          sed -n 's/^hash: \([0-9a-f]\{16\}\)$/\1/p' | tail -n 1)
    want=$(sed -n "s/^cut_contact_$fl \([0-9a-f]\{16\}\).*/\1/p" tests/expected_hashes.txt)
    if [ -n "$got" ] && [ "$got" = "$want" ]; then echo "  ok: cut_contact_$fl hash $got"; p=$((p + 1));
    else echo "FAIL: cut_contact_$fl: hash '$got', tests/expected_hashes.txt says '$want'"; f=$((f + 1)); fi
done
echo "$p passed, $f failed"
[ "$f" -eq 0 ]
