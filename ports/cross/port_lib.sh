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
