#!/bin/sh
# Runs every test program $BUILD/tests/test_* and every tests/scripts/test_*.sh,
# adds up their closing "N passed, N failed" lines and prints the total.
# A suite that exits non-zero without failures, or prints no closing line,
# counts as one failure.
# The test programs only read what make built, so they run in TEST_JOBS
# lanes at once (default 2: the CI machine's cores); the scripts, several of
# which call make on the same build directory, run one after another.
BUILD=${1:-build}
export BUILD
JOBS=${TEST_JOBS:-2}
total_p=0; total_f=0; bad=""
log_dir="$BUILD/test-logs"; mkdir -p "$log_dir"

# run one suite: its log and a result line "passed failed seconds"
run_one() {
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
    echo "$p $f $((end - start))" > "$log_dir/$name.res"
}
# print a finished suite's line (and its failures and figures), add it up
report() {
    name=$1
    read -r p f secs < "$log_dir/$name.res"
    total_p=$((total_p + p)); total_f=$((total_f + f))
    status=ok; [ "$f" -eq 0 ] || { status=FAILED; bad="$bad $name"; }
    printf '%-28s %5d passed %3d failed  %4ss  %s\n' "$name" "$p" "$f" "$secs" "$status"
    if [ "$f" -ne 0 ]; then sed 's/^/    | /' "$log_dir/$name.log" | grep -E 'FAIL|SKIP|rror|\| *[0-9]+ passed' | head -n 40; fi
    grep -E '^ *(figure|SKIPPED|determinism):' "$log_dir/$name.log" | sed 's/^ */    /'
}

# test programs: lane i takes every JOBS-th program
progs=""
for t in "$BUILD"/tests/test_*; do
    [ -x "$t" ] && progs="$progs $t"
done
lane=0
while [ "$lane" -lt "$JOBS" ]; do
    (
        i=0
        for t in $progs; do
            [ $((i % JOBS)) -eq "$lane" ] && run_one "$(basename "$t")" "$t"
            i=$((i + 1))
        done
    ) &
    lane=$((lane + 1))
done
wait
for t in $progs; do report "$(basename "$t")"; done
for s in tests/scripts/test_*.sh; do
    [ -f "$s" ] || continue
    run_one "$(basename "$s" .sh)" sh "$s"
    report "$(basename "$s" .sh)"
done
echo "logs: $log_dir/"
[ -z "$bad" ] || echo "failed suites:$bad"
echo "$total_p passed, $total_f failed"
[ "$total_f" -eq 0 ]
