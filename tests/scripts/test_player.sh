#!/bin/sh
# test_player.sh -- the desktop player (sinew-play, sinew-play-float) on bad
# input and on the baked cow: clear messages, non-zero exits, nothing partial
# written, a repeatable --hash, a working float build.
BUILD=${BUILD:-build}
PLAY=$BUILD/sinew-play
PLAYF=$BUILD/sinew-play-float
BLOB=$BUILD/examples/cow.blob
BLOBF=$BUILD/examples/cow_float.blob
CLIP=tools/examples/cow/head_turn.clip
TMP=$(mktemp -d "${TMPDIR:-/tmp}/sn_player.XXXXXX") || exit 1
trap 'rm -rf "$TMP"' EXIT
pass=0; fail=0

ok()  { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*"; }
# expect STATUS PATTERN CMD...: exit status STATUS ("nz" = any non-zero) and
# PATTERN (grep -E) in stdout+stderr.
expect() {
    want=$1; pat=$2; shift 2
    out=$("$@" 2>&1); rc=$?
    if [ "$want" = nz ]; then [ "$rc" -ne 0 ] || { bad "$* exited 0, want non-zero"; return; }
    else [ "$rc" -eq "$want" ] || { bad "$* exited $rc, want $want: $out"; return; }; fi
    echo "$out" | grep -Eq -e "$pat" || { bad "$*: output lacks /$pat/: $out"; return; }
    ok
}

for f in "$PLAY" "$PLAYF" "$BLOB" "$BLOBF" "$CLIP"; do
    [ -e "$f" ] || { echo "FAIL: missing $f (run make first)"; echo "0 passed, 1 failed"; exit 1; }
done

# usage
expect 0 'usage: sinew-play BLOB' "$PLAY" --help
expect 0 'usage: sinew-play-float BLOB' "$PLAYF" --help
expect 2 'usage' "$PLAY"
expect 2 "unknown option '--bogus'" "$PLAY" "$BLOB" --bogus
expect 2 '--frames needs a value' "$PLAY" "$BLOB" --frames
expect 2 "bad number 'x'" "$PLAY" "$BLOB" --frames x
expect nz 'this blob allows 1\.\.' "$PLAY" "$BLOB" --iterations 100000

# blobs: missing, empty, truncated, corrupt, wrong flavour
expect 1 "cannot read $TMP/none.blob" "$PLAY" "$TMP/none.blob"
expect 1 "cannot read $TMP: not a regular file" "$PLAY" "$TMP"
: > "$TMP/empty.blob"
expect 1 'invalid blob: blob is shorter' "$PLAY" "$TMP/empty.blob"
head -c 1000 "$BLOB" > "$TMP/trunc.blob"
expect 1 'invalid blob: blob is shorter' "$PLAY" "$TMP/trunc.blob"
# flip one byte in the middle: the checksum must catch it
size=$(wc -c < "$BLOB")
cp "$BLOB" "$TMP/corrupt.blob"
printf '\377' | dd of="$TMP/corrupt.blob" bs=1 seek=$((size / 2)) conv=notrunc 2>/dev/null
cmp -s "$BLOB" "$TMP/corrupt.blob" && printf '\000' | dd of="$TMP/corrupt.blob" bs=1 seek=$((size / 2)) conv=notrunc 2>/dev/null
expect 1 'invalid blob: blob checksum mismatch' "$PLAY" "$TMP/corrupt.blob"
printf 'XXXX' | dd of="$TMP/corrupt.blob" bs=1 seek=0 conv=notrunc 2>/dev/null
expect 1 'invalid blob: not a Sinew blob' "$PLAY" "$TMP/corrupt.blob"
expect 1 'flavour.*use sinew-play-float' "$PLAY" "$BLOBF"
expect 1 'flavour.*use sinew-play for fixed' "$PLAYF" "$BLOB"

# clips: missing, malformed (line number), for another skeleton
expect 1 "cannot read $TMP/none.clip" "$PLAY" "$BLOB" --clip "$TMP/none.clip"
printf 'sinew-clip 1\nduration 1\nrot head 0 0 1 0 five\n' > "$TMP/bad.clip"
expect 1 "bad.clip: line 3: angle is not a number: 'five'" "$PLAY" "$BLOB" --clip "$TMP/bad.clip"
printf 'sinew-clip 1\nduration 1\nrot left_wing 0 0 1 0 5\n' > "$TMP/bird.clip"
expect 1 "does not fit .*clip joint 'left_wing' is not in the blob's skeleton" "$PLAY" "$BLOB" --clip "$TMP/bird.clip"

# unwritable outputs: clear message, non-zero, nothing written anywhere
mkdir "$TMP/out"
expect 1 "cannot write $TMP/nodir/x.png" "$PLAY" "$BLOB" --clip "$CLIP" --frames 2 --png "$TMP/nodir/x.png" --sheet "$TMP/out/s.png"
expect 1 "cannot write $TMP/nodir/s.png" "$PLAY" "$BLOB" --frames 2 --png "$TMP/out/p.png" --sheet "$TMP/nodir/s.png"
expect 1 "cannot write $TMP/nodir/c.png" "$PLAY" "$BLOB" --frames 2 --compare "$TMP/nodir/c.png" --obj-dir "$TMP/out"
expect 1 "cannot write $TMP/nodir/frame_0000.obj" "$PLAY" "$BLOB" --frames 2 --png "$TMP/out/p.png" --obj-dir "$TMP/nodir"
if [ -z "$(ls -A "$TMP/out")" ]; then ok; else bad "failed runs left files: $(ls "$TMP/out")"; fi

# good runs
expect 0 'step: median [0-9.]+ us, p99 [0-9.]+ us' "$PLAY" "$BLOB" --clip "$CLIP" --frames 20 --obj-dir "$TMP/out" --png "$TMP/out/p.png" --sheet "$TMP/out/s.png"
n=$(ls "$TMP/out"/frame_*.obj 2>/dev/null | wc -l)
[ "$n" -eq 20 ] && ok || bad "--obj-dir wrote $n frames, want 20"
grep -c '^v ' "$TMP/out/frame_0020.obj" | grep -q '^2903$' && ok || bad "frame_0020.obj does not have 2903 vertices"
for p in p s; do
    [ "$(head -c 8 "$TMP/out/$p.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] && ok || bad "$p.png is not a PNG"
done
# same run twice: byte-identical OBJ frames and pictures
mkdir "$TMP/again"
"$PLAY" "$BLOB" --clip "$CLIP" --frames 20 --obj-dir "$TMP/again" --png "$TMP/again/p.png" --quiet > /dev/null 2>&1
cmp -s "$TMP/out/frame_0020.obj" "$TMP/again/frame_0020.obj" && ok || bad "OBJ frame 20 differs between identical runs"
cmp -s "$TMP/out/p.png" "$TMP/again/p.png" && ok || bad "PNG differs between identical runs"

# compare (two instances) with the lattice overlay and a framing box
expect 0 "wrote $TMP/out/c.png" "$PLAY" "$BLOB" --clip "$CLIP" --frames 10 --compare "$TMP/out/c.png" \
    --lattice --view 20,30 --frame-box 0,-3,-2,9,3,2 --size 320x240
[ "$(head -c 24 "$TMP/out/c.png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a0000000d49484452000002d0000000b4 ] \
    && ok || bad "compare picture is not a 720x180 PNG"
# fewer steps than sheet panels (some panels show the rest state)
expect 0 "wrote $TMP/out/s3.png" "$PLAY" "$BLOB" --frames 3 --sheet "$TMP/out/s3.png"
# heat colouring (distance from rigid skinning), both flavours
expect 0 "wrote $TMP/out/h.png" "$PLAY" "$BLOB" --clip "$CLIP" --frames 5 --png "$TMP/out/h.png" --heat 0.2 --size 160x120
expect 0 "wrote $TMP/out/hf.png" "$PLAYF" "$BLOBF" --clip "$CLIP" --frames 5 --compare "$TMP/out/hf.png" --heat 0.2
expect 2 'heat: want a distance' "$PLAY" "$BLOB" --heat -1
expect 2 'frame-box: want' "$PLAY" "$BLOB" --frame-box 1,2,3
expect 2 'size: want WxH' "$PLAY" "$BLOB" --size 10x10
ls "$TMP/out" | grep -q 'tmp\|probe' && bad "temp files left: $(ls "$TMP/out")" || ok

# --hash: same line twice; differs with a different mode; float player runs
h1=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --hash --quiet | grep '^hash: ')
h2=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --hash --quiet | grep '^hash: ')
echo "$h1" | grep -Eq '^hash: [0-9a-f]{16}$' && ok || bad "hash line malformed: '$h1'"
[ "$h1" = "$h2" ] && ok || bad "hash differs between runs: '$h1' vs '$h2'"
h3=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --hash --quiet --unwarped | grep '^hash: ')
[ "$h1" != "$h3" ] && ok || bad "--unwarped gives the same hash as warped"
echo "  determinism: sinew-play head_turn 30 steps $h1"
expect 0 'step: median .*\(float' "$PLAYF" "$BLOBF" --clip "$CLIP" --frames 20 --hash
f1=$("$PLAYF" "$BLOBF" --clip "$CLIP" --frames 20 --hash --quiet | grep '^hash: ')
f2=$("$PLAYF" "$BLOBF" --clip "$CLIP" --frames 20 --hash --quiet | grep '^hash: ')
[ -n "$f1" ] && [ "$f1" = "$f2" ] && ok || bad "float hash not repeatable: '$f1' vs '$f2'"

# fixed and float players agree on the trot: surface of frame 60.
# Tolerance 2e-3 mesh units (0.02% of the cow's 10.5-unit length): fixed point
# keeps lengths in Q22 of 4-unit internal units (1e-6 mesh units per LSB) and
# OBJ text has 6 significant digits (<= 5e-6); measured ~1e-4.
mkdir "$TMP/fx" "$TMP/fl"
"$PLAY" "$BLOB" --clip tools/examples/cow/trot.clip --frames 60 --obj-dir "$TMP/fx" --quiet > /dev/null 2>&1
"$PLAYF" "$BLOBF" --clip tools/examples/cow/trot.clip --frames 60 --obj-dir "$TMP/fl" --quiet > /dev/null 2>&1
worst=$(paste -d' ' "$TMP/fx/frame_0060.obj" "$TMP/fl/frame_0060.obj" | awk '$1 == "v" {
    d = ($2 - $6) ^ 2 + ($3 - $7) ^ 2 + ($4 - $8) ^ 2; if (d > m) m = d } END { printf "%.6f", sqrt(m) }')
echo "  figure: fixed vs float surface after 60 trot steps: max distance $worst mesh units"
awk -v w="$worst" 'BEGIN { exit !(w != "" && w <= 0.002) }' && ok || bad "fixed vs float differ by $worst mesh units (> 2e-3)"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
