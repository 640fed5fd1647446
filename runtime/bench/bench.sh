#!/bin/sh
# make bench (runtime part): step time, memory, callgrind instructions per
# step and per block multiply-add, for the cow blob, fixed and float.
# Never fails on speed; a missing valgrind is reported, not fatal.
BUILD=${1:-build}
STEPS=${BENCH_STEPS:-20}
tmp=$(mktemp -d /tmp/sn_bench.XXXXXX) || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
rc=0
echo "== runtime bench: cow, default CG iterations ($(uname -m), ${CC:-cc}, SIMD=${SIMD:-auto})"
for flav in fixed float; do
    if [ $flav = fixed ]; then bin=$BUILD/bench/sn_bench; blob=$BUILD/examples/cow.blob
    else bin=$BUILD/bench/sn_bench_float; blob=$BUILD/examples/cow_float.blob; fi
    [ -f "$blob" ] || { echo "SKIPPED: $blob missing"; continue; }
    "$bin" "$blob" > "$tmp/out" || rc=1
    grep -v '^  macs:' "$tmp/out"
    macs=$(sed -n 's/^  macs: //p' "$tmp/out")
    if command -v valgrind > /dev/null 2>&1; then
        for n in 0 "$STEPS"; do
            valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$n" "$bin" --steps "$n" "$blob" \
                > /dev/null 2> "$tmp/vg.$n" || { rc=1; cat "$tmp/vg.$n"; }
        done
        i0=$(sed -n 's/^totals: *\([0-9]*\).*/\1/p' "$tmp/cg.0")
        i1=$(sed -n 's/^totals: *\([0-9]*\).*/\1/p' "$tmp/cg.$STEPS")
        awk -v a="$i0" -v b="$i1" -v n="$STEPS" -v m="$macs" -v f="$flav" 'BEGIN {
            per = (b - a) / n
            printf "  figure: %s callgrind: %.0f instructions per step ((%d-step run - 0-step run) / %d), %.1f per block multiply-add\n", f, per, n, n, per / m }'
    else
        echo "  SKIPPED: valgrind not installed (no instruction counts)"
    fi
done
# many instances sharing one blob (issue 15 item 5): per-cow step cost of a
# herd of 1, 10, 100 cows on one core, and the working set against the caches
echo "== herd: N cows sharing one blob, stepped one after another on one core"
for flav in fixed float; do
    if [ $flav = fixed ]; then bin=$BUILD/bench/sn_herd; blob=$BUILD/examples/cow.blob
    else bin=$BUILD/bench/sn_herd_float; blob=$BUILD/examples/cow_float.blob; fi
    [ -f "$blob" ] && [ -x "$bin" ] || { echo "SKIPPED: $bin or $blob missing"; continue; }
    "$bin" "$blob" ${HERD_SIZES:-1 10 100} || rc=1
done
exit $rc
