# port_lib.sh -- shared helpers of tests/scripts/test_{determinism,baremetal,nofloat}.sh
# (POSIX sh: run_tests.sh runs the scripts with sh). Source it from the repo root.
BUILD=${BUILD:-build}
PASS=0; FAIL=0; SKIPS=0

ok()   { PASS=$((PASS + 1)); echo "ok: $*"; }
bad()  { FAIL=$((FAIL + 1)); echo "FAIL: $*"; }
# A missing toolchain or emulator is a loud skip; under CI it is a failure,
# because CI installs everything (.ci/install-deps.sh).
skip() {
    SKIPS=$((SKIPS + 1))
    echo "SKIPPED: $*"
    if [ -n "${CI:-}" ]; then bad "skip under CI: $*"; fi
}
finish() {
    echo "$PASS passed, $FAIL failed, $SKIPS skipped"
    [ "$FAIL" -eq 0 ]
}
have() { command -v "$1" >/dev/null 2>&1; }
pmake() { make -s --no-print-directory BUILD="$BUILD" "$@"; }

# run_log LOG TIMEOUT CMD... : run with a time limit, output to LOG; returns rc.
run_log() {
    log=$1; t=$2; shift 2
    timeout "$t" "$@" > "$log" 2>&1
}
hash_of() { sed -n 's/^hash: \([0-9a-f]\{16\}\)$/\1/p' "$1" | tail -n 1; }
hashc_of() { sed -n 's/^hash-contact: \([0-9a-f]\{16\}\)$/\1/p' "$1" | tail -n 1; }  # the constrained scenario
hashb_of() { sed -n 's/^hash-blended: \([0-9a-f]\{16\}\)$/\1/p' "$1" | tail -n 1; }  # the blended scenario

# qemu-system-arm command for the mps2-an386 board
BM_QEMU_RUN="qemu-system-arm -M mps2-an386 -nographic -monitor none -serial none -semihosting-config enable=on,target=native"

# bm_level_check NAME LOG SWITCHES ADAPT [DETAILS]: the checks of a main_level.c image's
# log (the level-of-detail / adaptation scenario on the Cortex-M4, issue 13):
# no step refused, no saturation, stack peak inside the 32 KB stack, one
# "switch:" line per K:L of SWITCHES with level 1's lattice larger than level
# 0's (the switch acted), and with ADAPT=1 adaptation on at the end with
# vertices both joining and leaving the solve; with DETAILS, the image's
# "details:" line must say that many were set.
bm_level_check() {
    _lg=$2
    _v() { sed -n "s/^$1: //p" "$_lg" | tail -n 1; }
    _fails=$FAIL
    [ "$(_v refused)" = 0 ] || bad "$1: refused steps '$(_v refused)'"
    [ "$(_v saturations)" = 0 ] || bad "$1: saturations '$(_v saturations)'"
    _s=$(_v stack_bytes)
    { [ -n "$_s" ] && [ "$_s" -lt 32768 ]; } || bad "$1: stack peak '$_s'"
    _want=$(echo "$3" | tr ',' '\n' | grep -c .)
    _sw=$(awk -v want="$3" '
        BEGIN { n = split(want, w, ",") }
        /^switch: / { i++; split(w[i], kl, ":")
                      if ($3 != kl[1] || $5 != kl[2]) bad = 1
                      if ($5 == 1) v1 = $7; else v0 = $7 }
        END { print (i == n && !bad && v1 > v0 && v0 > 0) ? "ok" : "bad" }' "$_lg")
    # no SWITCHES (the details run, no switch): none may have happened
    if [ -z "$3" ]; then [ "$(grep -c '^switch: ' "$_lg")" = 0 ] || bad "$1: switch lines in a run without switches"
    else [ "$_sw" = ok ] || bad "$1: the $_want level switches ($3) did not all act (switch: lines below)"; fi
    if [ "$4" = 1 ]; then
        { [ "$(_v adapt_on)" = 1 ] && [ "$(_v adapt_refines)" -gt 0 ] && [ "$(_v adapt_coarsens)" -gt 0 ]; } 2>/dev/null || \
            bad "$1: adaptation did not act (on '$(_v adapt_on)', refines '$(_v adapt_refines)', coarsens '$(_v adapt_coarsens)')"
    fi
    [ -z "${5:-}" ] || [ "$(_v details)" = "$5" ] || bad "$1: details '$(_v details)', want $5"
    if [ "$FAIL" -eq "$_fails" ]; then
        ok "$1: $(_v steps) steps$( [ -n "${5:-}" ] && echo ", $5 details at $(_v iterations) iterations"), $( [ -z "$3" ] && echo "no level switch" || echo "$_want level switches acted ($(grep '^switch: ' "$_lg" | awk '{printf "%s%s:%s=%s", s, $3, $5, $7; s=" "}') lattice vertices)")$( [ "$4" = 1 ] && echo ", adaptation: $(_v adapt_refines) vertices in, $(_v adapt_coarsens) out"), no saturation, none refused, stack peak $_s B of 32768"
    else sed 's/^/    /' "$_lg"; fi
}
