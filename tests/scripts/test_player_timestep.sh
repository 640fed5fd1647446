#!/bin/sh
# Players never divide by or convert an unbounded timestep (issue 16 item 4).
# The validator accepts any h > 0 (float: up to 32768 s). Clip time is Q16.16
# seconds: h < 2^-17 s rounded to 0 and sinew-play-float died with SIGFPE
# dividing by it; h = 32768 s overflowed the float->int conversion in
# ports/common/sn_clip_pose.c. Now sn_clip_bind refuses such a blob with a
# clear message (exit 1, no signal); the bounds themselves play, and a blob
# with any accepted h plays without a clip.
# Blobs: the baked beam1 with its timestep patched by $BUILD/tests/blob_patch
# (sets the header real, fixes the CRC-32).
BUILD=${BUILD:-build}
PATCH=$BUILD/tests/blob_patch
pass=0; fail=0
ok() { echo "ok   $1"; pass=$((pass + 1)); }
bad() { echo "FAIL $1"; fail=$((fail + 1)); }
for f in "$PATCH" "$BUILD/sinew-play" "$BUILD/sinew-play-float" "$BUILD/examples/beam1.blob" "$BUILD/examples/beam1_float.blob"; do
    [ -e "$f" ] || { echo "FAIL: $f not built"; echo "0 passed, 1 failed"; exit 1; }
done
T=$(mktemp -d "${TMPDIR:-/tmp}/sinew_h.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
printf 'sinew-clip 1\nduration 1\nloop yes\nmove 0 0 0 0\nmove 0.5 0 0.1 0\n' > "$T/c.clip"
MSG="the blob's timestep is outside what clip time \(Q16.16 seconds\) can step: a clip needs 2\^-17 s <= h < 32768 s"

# run NAME WANT_RC REGEX PLAYER BLOB_FLAVOUR H ARGS...: patch h, play, check exit status and stderr
run() {
    name=$1; want=$2; re=$3; play=$4; fl=$5; h=$6; shift 6
    if ! "$PATCH" "$BUILD/examples/beam1$fl.blob" "$T/h.blob" timestep "$h"; then bad "$name: cannot patch"; return; fi
    "$BUILD/$play" "$T/h.blob" --quiet "$@" > "$T/out" 2> "$T/err"
    rc=$?
    if [ "$rc" -ge 128 ]; then bad "$name: killed by signal $((rc - 128))"; sed 's/^/    /' "$T/err"
    elif [ "$rc" -ne "$want" ]; then bad "$name: exit $rc, want $want"; sed 's/^/    /' "$T/err"
    elif [ -n "$re" ] && ! grep -Eq "$re" "$T/err"; then bad "$name: message does not match /$re/"; sed 's/^/    /' "$T/err"
    else ok "$name"; fi
}
run "float h = 1e-6 s with a clip: refused"          1 "$MSG" sinew-play-float _float 1e-6 --clip "$T/c.clip"
run "float h = 7.6e-6 s (rounds to 0) with a clip"   1 "$MSG" sinew-play-float _float 7.6e-6 --clip "$T/c.clip"
run "float h = 32768 s with a clip: refused"         1 "$MSG" sinew-play-float _float 32768 --clip "$T/c.clip"
run "float h = 2^-17 s with a clip: plays"           0 ""     sinew-play-float _float 0.00000762939453125 --clip "$T/c.clip" --frames 3
run "float h = 32767.99 s with a clip: plays"        0 ""     sinew-play-float _float 32767.99 --clip "$T/c.clip" --frames 2
run "float h = 1e-6 s without a clip: plays"         0 ""     sinew-play-float _float 1e-6 --frames 3
run "float h = 32768 s without a clip: plays"        0 ""     sinew-play-float _float 32768 --frames 2
run "fixed h = 1 LSB (2^-16 s) with a clip: plays"   0 ""     sinew-play "" 0.0000152587890625 --clip "$T/c.clip" --frames 3
run "fixed h = 32767.99998 s with a clip: plays"     0 ""     sinew-play "" 32767.99998 --clip "$T/c.clip" --frames 2
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
