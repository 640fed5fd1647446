#!/bin/sh
# Level of detail on the cow and the beast, fixed and float
# (tests/test_runtime_level.c; blobs from tests/level.mk).
B=${BUILD:-build}
L=$B/level
p=0; f=0
for fl in "" _float; do
    for c in cow beast; do
        out=$("$B/tests/level_runtime$fl" "$B/examples/$c$fl.blob" "$L/${c}_lod$fl.blob" 2>&1)
        rc=$?
        echo "== level_runtime$fl $c"
        echo "$out"
        line=$(echo "$out" | grep -E '^[0-9]+ passed, [0-9]+ failed' | tail -n 1)
        if [ -z "$line" ]; then f=$((f + 1)); continue; fi
        p=$((p + ${line%% passed*}))
        ff=${line#*passed, }; ff=${ff%% failed*}
        f=$((f + ff))
        [ "$rc" -eq 0 ] || [ "$ff" -ne 0 ] || f=$((f + 1))
    done
done
echo "$p passed, $f failed"
[ "$f" -eq 0 ]
