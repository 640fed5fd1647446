#!/bin/sh
# test_gltf.sh -- glTF in and out through the tools (issue 17 items 2-5):
#  * the cow written as a glTF by test_bake_gltf_cow (its joints as a skin, an
#    animation "test" with LINEAR and STEP rotations, a LINEAR root translation
#    and a scale channel, and "spline" with CUBICSPLINE) bakes with 'gltf', and
#    writes BLOB.gltfmap beside the blob;
#  * sinew-play --gltf-anim plays "test" to the same state hash as hand.clip,
#    the hand-written clip of the same motion (one key per step); by index too;
#  * --out-gltf: the .glb checked by tests/scripts/gltf_check.py (chunk
#    lengths, accessor bounds, min/max of every POSITION, targets, the weights
#    animation, the base frame against the source glTF through the map) and
#    re-read by our own reader (test_bake_gltf_cow --read);
#  * --apng: decoded by gltf_check.py (CRCs, acTL frame count, fcTL delays and
#    sequence numbers, every frame inflated by zlib to its size), and by
#    ffprobe / identify when present;
#  * the Blender-exported examples (tools/examples/*_gltf) bake and play.
# Usage: sh tests/scripts/test_gltf.sh [BUILD]
BUILD=${1:-${BUILD:-build}}
BAKE=$BUILD/sinew-bake
PLAY=$BUILD/sinew-play
GEN=$BUILD/tests/test_bake_gltf_cow
PY=${PYTHON:-python3}
CHECK=tests/scripts/gltf_check.py
TMP=$(mktemp -d "${TMPDIR:-/tmp}/sn_gltf.XXXXXX") || exit 1
trap 'rm -rf "$TMP"' EXIT
pass=0; fail=0
ok()  { pass=$((pass + 1)); }
bad() { fail=$((fail + 1)); echo "FAIL: $*"; }
for f in "$BAKE" "$PLAY" "$GEN"; do
    [ -x "$f" ] || { echo "test_gltf: build $f first (make BUILD=$BUILD all tests)"; echo "0 passed, 1 failed"; exit 1; }
done

# the generated cow (test_bake_gltf_cow writes it into $TMP/test_bake_gltf_cow.d)
BUILD=$TMP "$GEN" > "$TMP/gen.log" 2>&1 || bad "test_bake_gltf_cow: $(tail -3 "$TMP/gen.log")"
D=$TMP/test_bake_gltf_cow.d
"$BAKE" "$D/cow_gltf.sinew" -o "$D/cow.blob" --quiet && ok || bad "bake cow_gltf.sinew"
head -1 "$D/cow.blob.gltfmap" 2>/dev/null | grep -q '^sinew-gltf-map 1' && ok || bad "no cow.blob.gltfmap"

# the glTF animation and its hand-written twin: the same hash
h1=$("$PLAY" "$D/cow.blob" --gltf-anim "$D/cow.gltf:test" --hash --quiet 2>"$TMP/anim.err" | sed -n 's/^hash: //p')
h2=$("$PLAY" "$D/cow.blob" --clip "$D/hand.clip" --hash --quiet 2>/dev/null | sed -n 's/^hash: //p')
h3=$("$PLAY" "$D/cow.blob" --gltf-anim "$D/cow.gltf:0" --hash --quiet 2>/dev/null | sed -n 's/^hash: //p')
[ -n "$h1" ] && [ "$h1" = "$h2" ] && ok || bad "--gltf-anim hash '$h1' != hand.clip hash '$h2'"
[ "$h1" = "$h3" ] && ok || bad "by index: hash '$h3' != by name '$h1'"
echo "  figure: cow, 60 steps: --gltf-anim cow.gltf:test and --clip hand.clip both hash $h1"
grep -q '1 scale channel(s) that scale ignored' "$TMP/anim.err" && ok || bad "no warning for the scale channel: $(cat "$TMP/anim.err")"
"$PLAY" "$D/cow.blob" --gltf-anim "$D/cow.gltf:spline" --clip-out "$TMP/spline.clip" --quiet > /dev/null 2>&1 && \
    grep -q '^rot neck' "$TMP/spline.clip" && grep -q '^move' "$TMP/spline.clip" && ok || bad "CUBICSPLINE animation"
out=$("$PLAY" "$D/cow.blob" --gltf-anim "$D/cow.gltf:walk" --quiet 2>&1) && bad "unknown animation accepted" || \
    { echo "$out" | grep -q 'none named "walk"' && ok || bad "unknown animation: $out"; }
out=$("$PLAY" "$D/cow.blob" --gltf-anim "$D/cow.gltf" --clip "$D/hand.clip" 2>&1) && bad "--gltf-anim with --clip accepted" || ok

# outputs: .glb and APNG, checked independently; the .glb re-read by our reader
"$PLAY" "$D/cow.blob" --gltf-anim "$D/cow.gltf:test" --frames 30 --out-gltf "$TMP/out.glb" --apng "$TMP/out.png" --quiet \
    > "$TMP/out.log" 2>&1 || bad "--out-gltf/--apng run: $(cat "$TMP/out.log")"
r=$($PY $CHECK glb "$TMP/out.glb" 30 "$D/cow.gltf"); echo "  $r"; case $r in ok:*) ok;; *) bad "glb: $r";; esac
r=$($PY $CHECK apng "$TMP/out.png" 30 100 6000); echo "  $r"; case $r in ok:*) ok;; *) bad "apng: $r";; esac
r=$("$GEN" --read "$TMP/out.glb")
case $r in "read: 5806 5804 1 "*) ok;; *) bad "our reader on out.glb: $r";; esac
if command -v ffprobe > /dev/null 2>&1; then
    n=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames -of csv=p=0 "$TMP/out.png" 2>/dev/null)
    [ "$n" = 30 ] && ok || bad "ffprobe counts '$n' frames, want 30"
elif command -v identify > /dev/null 2>&1; then
    n=$(identify "apng:$TMP/out.png" 2>/dev/null | wc -l)
    [ "$n" = 30 ] && ok || bad "identify counts '$n' frames, want 30"
else echo "  (ffprobe and identify absent: the APNG is checked by gltf_check.py only)"; fi
# a blob without a map: the runtime surface's order
cp "$D/cow.blob" "$TMP/nomap.blob"
"$PLAY" "$TMP/nomap.blob" --frames 3 --out-gltf "$TMP/nomap.glb" --quiet > /dev/null 2>&1 && \
    $PY $CHECK glb "$TMP/nomap.glb" 3 > /dev/null && ok || bad "--out-gltf without a map"

# the Blender exports (tools/blender/make_gltf.py) bake and play their walk
for c in cow beast; do
    "$BAKE" "tools/examples/${c}_gltf/${c}_gltf.sinew" -o "$TMP/$c.blob" --quiet && ok || bad "bake ${c}_gltf.sinew"
    "$PLAY" "$TMP/$c.blob" --gltf-anim "tools/examples/${c}_gltf/$c.glb:walk" --frames 10 --hash --quiet > "$TMP/$c.log" 2>&1 && \
        grep -q '^hash:' "$TMP/$c.log" && ok || bad "play $c walk: $(tail -2 "$TMP/$c.log")"
done
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
