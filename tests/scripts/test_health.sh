#!/bin/sh
# Health report, distance limits and rest shape on the cow, fixed and float
# (tests/test_runtime_health.c; blobs from tests/health.mk).
B=${BUILD:-build}
H=$B/health
p=0; f=0
for fl in "" _float; do
    out=$("$B/tests/health_runtime$fl" "$B/examples/cow$fl.blob" "$H/cow_limit$fl.blob" \
          "$H/cow_farlimit$fl.blob" "$H/cow_rest$fl.blob" 2>&1)
    rc=$?
    echo "== health_runtime$fl"
    echo "$out"
    line=$(echo "$out" | grep -E '^[0-9]+ passed, [0-9]+ failed' | tail -n 1)
    if [ -z "$line" ]; then f=$((f + 1)); continue; fi
    p=$((p + ${line%% passed*}))
    ff=${line#*passed, }; ff=${ff%% failed*}
    f=$((f + ff))
    [ "$rc" -eq 0 ] || [ "$ff" -ne 0 ] || f=$((f + 1))
done
echo "$p passed, $f failed"
[ "$f" -eq 0 ]
