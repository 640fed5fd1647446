# cli_lib.sh -- shared helpers of the command-line test scripts
# (test_player*.sh, test_bake_cli.sh, test_rigfit_cli.sh, test_retarget_cli.sh).
# POSIX sh; source it from the repo root. The script prints
# "$pass passed, $fail failed" at the end.
pass=0; fail=0

ok()  { pass=$((pass + 1)); [ -z "${1:-}" ] || echo "ok   $1"; }
bad() { fail=$((fail + 1)); echo "FAIL: $*"; }
# expect STATUS PATTERN CMD...: exit status STATUS ("nz" = any non-zero) and
# PATTERN (grep -E) in stdout+stderr.
expect() {
    want=$1; pat=$2; shift 2
    out=$("$@" 2>&1); rc=$?
    if [ "$want" = nz ]; then [ "$rc" -ne 0 ] || { bad "$* exited 0, want non-zero"; return; }
    else [ "$rc" -eq "$want" ] || { bad "$* exited $rc, want $want: $out"; return; }; fi
    echo "$out" | grep -Eq -e "$pat" || { bad "$*: output lacks /$pat/: $out"; return; }
    ok "exit $want /$pat/: $*"
}
# need FILE...: every input exists, or the script fails at once
need() {
    for f in "$@"; do
        [ -e "$f" ] || { echo "FAIL: missing $f (run make first)"; echo "0 passed, 1 failed"; exit 1; }
    done
}
