#!/bin/sh
# Runs every test program $BUILD/tests/test_* and every tests/scripts/test_*.sh,
# adds up their closing "N passed, N failed" lines and prints the total.
# A suite that exits non-zero without failures, or prints no closing line,
# counts as one failure.
BUILD=${1:-build}
export BUILD
total_p=0; total_f=0; bad=""
log_dir="$BUILD/test-logs"; mkdir -p "$log_dir"
run_suite() {
    name=$1; shift
    start=$(date +%s)
    "$@" > "$log_dir/$name.log" 2>&1
    rc=$?
    end=$(date +%s)
    line=$(grep -E '^([A-Za-z]+: )?[0-9]+ passed, [0-9]+ failed' "$log_dir/$name.log" | tail -n 1)
    p=$(echo "$line" | sed -E 's/^([A-Za-z]+: )?([0-9]+) passed, ([0-9]+) failed.*/\2/')
    f=$(echo "$line" | sed -E 's/^([A-Za-z]+: )?([0-9]+) passed, ([0-9]+) failed.*/\3/')
    [ -n "$line" ] || { p=0; f=1; }
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
    total_p=$((total_p + p)); total_f=$((total_f + f))
    status=ok; [ "$f" -eq 0 ] || { status=FAILED; bad="$bad $name"; }
    printf '%-28s %5d passed %3d failed  %4ss  %s\n' "$name" "$p" "$f" "$((end - start))" "$status"
    if [ "$f" -ne 0 ]; then sed 's/^/    | /' "$log_dir/$name.log" | grep -E 'FAIL|SKIP|rror|\| *[0-9]+ passed' | head -n 40; fi
    grep -E '^ *(figure|SKIPPED|determinism):' "$log_dir/$name.log" | sed 's/^ */    /'
}
for t in "$BUILD"/tests/test_*; do
    [ -x "$t" ] || continue
    run_suite "$(basename "$t")" "$t"
done
for s in tests/scripts/test_*.sh; do
    [ -f "$s" ] || continue
    run_suite "$(basename "$s" .sh)" sh "$s"
done
echo "logs: $log_dir/"
[ -z "$bad" ] || echo "failed suites:$bad"
echo "$total_p passed, $total_f failed"
[ "$total_f" -eq 0 ]
