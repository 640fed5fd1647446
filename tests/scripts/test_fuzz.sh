#!/bin/sh
# libFuzzer harnesses (tests/fuzz/fuzz.mk, issue 16 item 5): each runs for
# FUZZ_SECONDS (default 6) from its seeds (tests/fuzz/corpus/<harness>/ and
# the generated $BUILD/fuzz/seeds/<harness>/) under ASan + UBSan. A harness
# passes when libFuzzer ends without a finding; a finding is saved as
# $BUILD/fuzz/artifacts/<harness>-crash-* (replay: $BUILD/fuzz/<harness> FILE).
# Prints executions and exec/s per harness as "figure:" lines.
#
#   sh tests/scripts/test_fuzz.sh [harness ...]    (default: all six)
#   env FUZZ_SECONDS=N   seconds per harness
#   env FUZZ_KEEP=1      keep new inputs in $BUILD/fuzz/work/<harness>/ across
#                        runs (make fuzz); otherwise a fresh temp dir each run
# Without clang the harnesses are not built: SKIPPED, a failure under CI=true.
BUILD=${BUILD:-build}
FD=$BUILD/fuzz
SECS=${FUZZ_SECONDS:-6}
NAMES=${*:-fuzz_blob_fixed fuzz_blob_float fuzz_clip fuzz_desc fuzz_obj fuzz_gltf}
pass=0; fail=0

if ! command -v "${FUZZ_CC:-clang}" > /dev/null 2>&1; then
    if [ "${CI:-}" = true ]; then
        echo "FAIL: clang not found: the fuzz harnesses must run under CI (.ci/install-deps.sh installs clang libclang-rt-14-dev)"
        echo "0 passed, 1 failed"; exit 1
    fi
    echo "SKIPPED: fuzz harnesses: install clang and libclang-rt-14-dev (libFuzzer) to run them"
    echo "0 passed, 0 failed"; exit 0
fi

mkdir -p "$FD/artifacts"
TMPW=$(mktemp -d "${TMPDIR:-/tmp}/sinew_fuzz.XXXXXX") || exit 1
trap 'rm -rf "$TMPW"' EXIT
for h in $NAMES; do
    bin=$FD/$h
    if [ ! -x "$bin" ]; then
        echo "FAIL $h: $bin not built (make BUILD=$BUILD fuzz-bins)"; fail=$((fail + 1)); continue
    fi
    case $h in
        fuzz_blob_*) maxlen=262144 ;;
        *) maxlen=16384 ;;
    esac
    if [ "${FUZZ_KEEP:-0}" = 1 ]; then work=$FD/work/$h; else work=$TMPW/$h; fi
    mkdir -p "$work"
    seeds=""
    for d in "tests/fuzz/corpus/$h" "$FD/seeds/$h"; do [ -d "$d" ] && seeds="$seeds $d"; done
    log=$FD/$h.log
    # -max_total_time bounds the whole run (seed loading included); -timeout
    # flags a single input slower than 25 s; one process, as the budget assumes
    SN_LF_BLOB=$BUILD/examples/cow.blob "$bin" -max_total_time="$SECS" -max_len=$maxlen -timeout=25 \
        -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$FD/artifacts/$h-" \
        "$work" $seeds > "$log" 2>&1
    rc=$?
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -n 1)
    cov=$(grep -E '^#[0-9]+' "$log" | tail -n 1 | sed -n 's/.*cov: \([0-9]*\).*corp: \([0-9]*\).*/cov \1, corpus \2/p')
    echo "  figure: fuzz $h: ${execs:-?} executions in ${SECS} s, ${rate:-?} exec/s, ${cov:-?}"
    if [ "$rc" -eq 0 ] && [ -n "$execs" ]; then
        echo "ok   $h"; pass=$((pass + 1))
    else
        echo "FAIL $h: libFuzzer exit $rc (log $log):"
        grep -E 'ERROR|SUMMARY|runtime error|requirement failed|Test unit written|lf_' "$log" | head -n 15 | sed 's/^/    /'
        fail=$((fail + 1))
    fi
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
