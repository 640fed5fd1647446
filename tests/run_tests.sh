#!/bin/sh
# Runs every test program $BUILD/tests/test_* and every tests/scripts/test_*.sh,
# adds up their closing "N passed, N failed" lines and prints the total.
# A suite that exits non-zero without failures, or prints no closing line,
# counts as one failure.
# Work is shared by TEST_JOBS lanes (default 2: the CI machine's cores)
# through a queue: each lane takes the next unclaimed suite (an atomic
# mkdir claims it), the slowest first, so no lane idles while another still
# has a long list. `make test-build` builds everything the suites run (the
# port scripts' cross drivers and images too), so their make calls only
# check; a script that still builds into $BUILD belongs in SERIAL (one after
# another as a single queue item). Reports print in a fixed order at the end.
# $BUILD/test-logs/NAME.res: "passed failed wall-seconds cpu-seconds" (cpu: user+sys
# of the suite and its children, from /usr/bin/time; "-" without it).
BUILD=${1:-build}
export BUILD
JOBS=${TEST_JOBS:-2}
total_p=0; total_f=0; bad=""
log_dir="$BUILD/test-logs"; mkdir -p "$log_dir"
rm -rf "$log_dir/claims"; mkdir -p "$log_dir/claims"

# scripts that build into $BUILD: never two at once (none: test-build builds for them)
SERIAL=""
# the slowest suites (seconds on a 2-core machine), queued first
SLOW="test_integration test_determinism test_runtime_fuzz test_level test_runtime_fuzz_range test_runtime_fuzz_float
      test_runtime_rules test_physics_cantilever test_fuzz test_physics_runtime test_physics_runtime_float
      test_bake_sweep test_physics_vibration test_runtime_fuzz_ck test_nonlinear
      test_physics_longrun test_physics_longrun_float test_physics_cantilever_float test_physics_blended
      test_physics_blended_float test_physics_vibration_float test_physics_held test_physics_held_float"

# run one suite: its log and a result line "passed failed seconds"
run_one() {
    name=$1; shift
    start=$(date +%s)
    rm -f "$log_dir/$name.cpu"
    # CPU seconds (user+sys of the suite and everything it waited for) when
    # /usr/bin/time is there: wall seconds mislead on a shared machine
    if [ -x /usr/bin/time ]; then
        /usr/bin/time -f '%U %S' -o "$log_dir/$name.cpu" "$@" > "$log_dir/$name.log" 2>&1
    else
        "$@" > "$log_dir/$name.log" 2>&1
    fi
    rc=$?
    end=$(date +%s)
    cpu=-
    [ ! -s "$log_dir/$name.cpu" ] || cpu=$(tail -n 1 "$log_dir/$name.cpu" | awk '{ printf "%.1f", $1 + $2 }')
    line=$(grep -E '^([A-Za-z]+: )?[0-9]+ passed, [0-9]+ failed' "$log_dir/$name.log" | tail -n 1)
    p=$(echo "$line" | sed -E 's/^([A-Za-z]+: )?([0-9]+) passed, ([0-9]+) failed.*/\2/')
    f=$(echo "$line" | sed -E 's/^([A-Za-z]+: )?([0-9]+) passed, ([0-9]+) failed.*/\3/')
    [ -n "$line" ] || { p=0; f=1; }
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
    echo "$p $f $((end - start)) $cpu" > "$log_dir/$name.res"
}
# print a finished suite's line (and its failures and figures), add it up
report() {
    name=$1
    if [ ! -f "$log_dir/$name.res" ]; then echo "0 1 0" > "$log_dir/$name.res"; echo "no result" >> "$log_dir/$name.log"; fi
    read -r p f secs cpu < "$log_dir/$name.res"
    total_p=$((total_p + p)); total_f=$((total_f + f))
    status=ok; [ "$f" -eq 0 ] || { status=FAILED; bad="$bad $name"; }
    printf '%-28s %5d passed %3d failed  %4ss %6s cpu-s  %s\n' "$name" "$p" "$f" "$secs" "${cpu:--}" "$status"
    if [ "$f" -ne 0 ]; then sed 's/^/    | /' "$log_dir/$name.log" | grep -E 'FAIL|SKIP|rror|\| *[0-9]+ passed' | head -n 40; fi
    grep -E '^ *(figure|SKIPPED|determinism):' "$log_dir/$name.log" | sed 's/^ */    /'
}
is_in() { case " $(echo $2) " in *" $1 "*) return 0;; esac; return 1; }

progs=""; scripts=""; serial=""; rest=""
for t in "$BUILD"/tests/test_*; do
    [ -x "$t" ] && progs="$progs $(basename "$t")"
done
for s in tests/scripts/test_*.sh; do
    [ -f "$s" ] || continue
    n=$(basename "$s" .sh); scripts="$scripts $n"
    if is_in "$n" "$SERIAL"; then serial="$serial $n"; else rest="$rest $n"; fi
done
# the queue: the serial chain, the slow suites, then everything else
queue=""; [ -z "$serial" ] || queue="@serial"
for n in $SLOW; do is_in "$n" "$progs $rest" && queue="$queue $n"; done
for n in $progs $rest; do is_in "$n" "$queue" || queue="$queue $n"; done

run_item() {
    case "$1" in
        @serial) for n in $serial; do run_one "$n" sh "tests/scripts/$n.sh"; done ;;
        *) if [ -x "$BUILD/tests/$1" ]; then run_one "$1" "$BUILD/tests/$1"; else run_one "$1" sh "tests/scripts/$1.sh"; fi ;;
    esac
}
lane=0
while [ "$lane" -lt "$JOBS" ]; do
    (
        for item in $queue; do
            mkdir "$log_dir/claims/$item" 2>/dev/null && run_item "$item"
        done
    ) &
    lane=$((lane + 1))
done
wait
for n in $progs $scripts; do report "$n"; done
cpu_all=$(for n in $progs $scripts; do cat "$log_dir/$n.res"; done | awk '$4 != "-" { t += $4 } END { printf "%.0f", t }')
echo "logs: $log_dir/ (suites' CPU: $cpu_all s)"
[ -z "$bad" ] || echo "failed suites:$bad"
echo "$total_p passed, $total_f failed"
[ "$total_f" -eq 0 ]
