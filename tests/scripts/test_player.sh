#!/bin/sh
# test_player.sh -- the desktop player (sinew-play, sinew-play-float) on bad
# input and on the baked cow: clear messages, non-zero exits, nothing partial
# written, a repeatable --hash, a working float build; clip warnings, chosen
# OBJ frames, sheet size, framing, the health report, --stats-csv, --plot and
# sinew-plot. Usage: sh tests/scripts/test_player.sh [BUILD]
BUILD=${1:-${BUILD:-build}}
PLAY=$BUILD/sinew-play
PLAYF=$BUILD/sinew-play-float
PLOT=$BUILD/sinew-plot
BLOB=$BUILD/examples/cow.blob
BLOBF=$BUILD/examples/cow_float.blob
CLIP=tools/examples/cow/head_turn.clip
TMP=$(mktemp -d "${TMPDIR:-/tmp}/sn_player.XXXXXX") || exit 1
trap 'rm -rf "$TMP"' EXIT
. tests/scripts/cli_lib.sh

need "$PLAY" "$PLAYF" "$PLOT" "$BLOB" "$BLOBF" "$CLIP"

# usage
expect 0 'usage: sinew-play BLOB' "$PLAY" --help
expect 0 'usage: sinew-play-float BLOB' "$PLAYF" --help
expect 2 'usage' "$PLAY"
expect 2 "unknown option '--bogus'" "$PLAY" "$BLOB" --bogus
expect 2 '--frames needs a value' "$PLAY" "$BLOB" --frames
expect 2 "bad number 'x'" "$PLAY" "$BLOB" --frames x
expect nz 'this blob allows 1\.\.' "$PLAY" "$BLOB" --iterations 100000

# segment meshes (seed 004 ch. 3-4): the cow's tail chain is mesh 0 (9 nodes)
expect 2 '--seg-impulse: want MESH:NODE:X,Y,Z' "$PLAY" "$BLOB" --seg-impulse 0:8
expect 2 '--seg-impulse: want MESH:NODE:X,Y,Z' "$PLAY" "$BLOB" --seg-impulse 0:8:0,1,0@0
expect 2 '--seg-floor: want a height' "$PLAY" "$BLOB" --seg-floor nan
expect 2 '--segments: want on or off' "$PLAY" "$BLOB" --segments maybe
expect 1 'no node 9 of mesh 0' "$PLAY" "$BLOB" --frames 1 --seg-impulse 0:9:0,1,0
expect 1 'no node 0 of mesh 64' "$PLAY" "$BLOB" --frames 1 --seg-impulse 64:0:0,1,0
h0=$("$PLAY" "$BLOB" --frames 10 --hash --quiet 2>/dev/null | grep '^hash:')
h1=$("$PLAY" "$BLOB" --frames 10 --hash --quiet --seg-impulse 0:8:0.5,0,0@3 2>/dev/null | grep '^hash:')
h2=$("$PLAY" "$BLOB" --frames 10 --hash --quiet --seg-impulse 0:8:0.5,0,0@3 --segments off 2>/dev/null | grep '^hash:')
[ -n "$h0" ] && [ "$h0" != "$h1" ] && [ "$h1" = "$h2" ] && ok || bad "--seg-impulse moves the tail (hash $h0 -> $h1), drawing off changes nothing ($h2)"
expect 0 'wrote|step:' "$PLAY" "$BLOB" --frames 4 --seg-floor -3.6 --png "$TMP/seg.png"
[ -s "$TMP/seg.png" ] && ok || bad "--seg-floor run wrote no picture"

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

# keys more than 180 degrees apart: a warning naming file:line, joint, both
# key times, the short way and the fix; the clip still plays
printf 'sinew-clip 1\nduration 2\nrot neck 0 0 1 0 0\n# spin\nrot head 0 0 1 0 -10\nrot head 1.5 0 1 0 200\n' > "$TMP/spin.clip"
expect 0 "warning: $TMP/spin.clip:6: joint 'head': keys at 0 s and 1.5 s are 210 degrees apart; the interpolation takes the short way \(a turn of 150 degrees\); add an intermediate key" \
    "$PLAY" "$BLOB" --clip "$TMP/spin.clip" --frames 2 --quiet
expect 0 "warning: $TMP/spin.clip:6: joint 'head'" "$PLAYF" "$BLOBF" --clip "$TMP/spin.clip" --frames 2 --quiet
n=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 2 --quiet 2>&1 | grep -c "warning: $CLIP")
[ "$n" -eq 0 ] && ok || bad "head_turn.clip gives $n warnings, want none"

# unwritable outputs: clear message, non-zero, nothing written anywhere
mkdir "$TMP/out"
expect 1 "cannot write $TMP/nodir/x.png" "$PLAY" "$BLOB" --clip "$CLIP" --frames 2 --png "$TMP/nodir/x.png" --sheet "$TMP/out/s.png"
expect 1 "cannot write $TMP/nodir/s.png" "$PLAY" "$BLOB" --frames 2 --png "$TMP/out/p.png" --sheet "$TMP/nodir/s.png"
expect 1 "cannot write $TMP/nodir/c.png" "$PLAY" "$BLOB" --frames 2 --compare "$TMP/nodir/c.png" --obj-dir "$TMP/out"
expect 1 "cannot write $TMP/nodir/frame_0000.obj" "$PLAY" "$BLOB" --frames 2 --png "$TMP/out/p.png" --obj-dir "$TMP/nodir"
expect 1 "cannot write $TMP/nodir/s.csv" "$PLAY" "$BLOB" --frames 2 --stats-csv "$TMP/nodir/s.csv" --png "$TMP/out/p.png"
expect 1 "cannot write $TMP/nodir/p.png" "$PLAY" "$BLOB" --frames 2 --plot "$TMP/nodir/p.png" --stats-csv "$TMP/out/s.csv"
# bad --obj-frames lists: refused before anything is written
expect 2 "obj-frames: empty item in '1,,2'" "$PLAY" "$BLOB" --frames 40 --obj-dir "$TMP/out" --obj-frames 1,,2
expect 2 "obj-frames: range '30-20' runs backwards" "$PLAY" "$BLOB" --frames 40 --obj-dir "$TMP/out" --obj-frames 0,30-20
expect 2 "obj-frames: bad item 'x'" "$PLAY" "$BLOB" --frames 40 --obj-dir "$TMP/out" --obj-frames 1,x
expect 2 "obj-frames: bad item '-5'" "$PLAY" "$BLOB" --frames 40 --obj-dir "$TMP/out" --obj-frames -5
expect 2 "obj-frames: bad item '5-'" "$PLAY" "$BLOB" --frames 40 --obj-dir "$TMP/out" --obj-frames 5-
expect 2 "obj-frames: empty list" "$PLAY" "$BLOB" --frames 40 --obj-dir "$TMP/out" --obj-frames ''
expect 2 "obj-frames: frame 41 is after the last frame of this run \(40" "$PLAY" "$BLOB" --frames 40 --obj-dir "$TMP/out" --obj-frames 0,41
expect 2 "obj-frames: frame 1000 is after the last frame of this run \\([0-9]+; see --frames" "$PLAY" "$BLOB" --clip "$CLIP" --obj-dir "$TMP/out" --obj-frames 1000
expect 2 "obj-frames needs --obj-dir" "$PLAY" "$BLOB" --frames 40 --obj-frames 1
expect 2 "health: bad number '0'" "$PLAY" "$BLOB" --health 0
expect 2 "size: sheet cells are at most 2048x2048" "$PLAY" "$BLOB" --sheet "$TMP/out/s.png" --size 4000x100
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

# --obj-frames: exactly the chosen frames (0 = before the first step; overlaps are fine)
mkdir "$TMP/sel"
expect 0 'step: median' "$PLAY" "$BLOB" --clip "$CLIP" --frames 40 --obj-dir "$TMP/sel" --obj-frames 0,10,20-30,25,40 --quiet
got=$(cd "$TMP/sel" && ls | tr '\n' ' ')
want="frame_0000.obj frame_0010.obj frame_0020.obj frame_0021.obj frame_0022.obj frame_0023.obj frame_0024.obj frame_0025.obj frame_0026.obj frame_0027.obj frame_0028.obj frame_0029.obj frame_0030.obj frame_0040.obj "
[ "$got" = "$want" ] && ok || bad "--obj-frames 0,10,20-30,25,40 wrote: $got"
cmp -s "$TMP/sel/frame_0020.obj" "$TMP/out/frame_0020.obj" && ok || bad "--obj-frames frame 20 differs from the full run's"
grep -c '^v ' "$TMP/sel/frame_0000.obj" | grep -q '^2903$' && ok || bad "frame_0000.obj does not have 2903 vertices"

# --size sets the sheet's cells (4x3 of them); default 320x240
ihdr() { head -c 24 "$1" | od -An -tx1 | tr -d ' \n' | cut -c33-48; }
"$PLAY" "$BLOB" --frames 3 --sheet "$TMP/out/sz.png" --size 160x100 --quiet > /dev/null 2>&1
[ "$(ihdr "$TMP/out/sz.png")" = 000002800000012c ] && ok || bad "--size 160x100 sheet is not 640x300: $(ihdr "$TMP/out/sz.png")"
"$PLAY" "$BLOB" --frames 3 --sheet "$TMP/out/sd.png" --quiet > /dev/null 2>&1
[ "$(ihdr "$TMP/out/sd.png")" = 00000500000002d0 ] && ok || bad "default sheet is not 1280x720: $(ihdr "$TMP/out/sd.png")"

# the default camera frames the character over the whole clip: a clip that
# lifts the root 4 units raises the camera box's top by at least that
printf 'sinew-clip 1\nduration 1\nmove 0 0 0 0\nmove 0.5 0 4 0\nmove 1 0 0 0\n' > "$TMP/lift.clip"
top() { "$@" 2>&1 | sed -n 's/^camera box: [^,]*,[^,]*,[^,]*,[^,]*,\([^,]*\),.*/\1/p'; }
t0=$(top "$PLAY" "$BLOB" --frames 60 --png "$TMP/out/l0.png" --size 64x48)
t1=$(top "$PLAY" "$BLOB" --clip "$TMP/lift.clip" --frames 60 --png "$TMP/out/l1.png" --size 64x48)
awk -v a="$t0" -v b="$t1" 'BEGIN { exit !(a != "" && b != "" && b - a >= 3.99) }' && ok || bad "camera box top $t0 at rest, $t1 with a 4-unit lift"
echo "  figure: camera box top at rest $t0, with the root lifted 4 units $t1"

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
h1=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --hash --quiet 2>/dev/null | grep '^hash: ')
h2=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --hash --quiet 2>/dev/null | grep '^hash: ')
echo "$h1" | grep -Eq '^hash: [0-9a-f]{16}$' && ok || bad "hash line malformed: '$h1'"
[ "$h1" = "$h2" ] && ok || bad "hash differs between runs: '$h1' vs '$h2'"
h3=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --hash --quiet --unwarped 2>/dev/null | grep '^hash: ')
[ "$h1" != "$h3" ] && ok || bad "--unwarped gives the same hash as warped"
h4=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --hash --quiet --mode unwarped 2>/dev/null | grep '^hash: ')
[ "$h3" = "$h4" ] && ok || bad "--mode unwarped differs from --unwarped: '$h4' vs '$h3'"
h5=$("$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --hash --quiet --mode blended 2>/dev/null | grep '^hash: ')
echo "$h5" | grep -Eq '^hash: [0-9a-f]{16}$' && [ "$h5" != "$h1" ] && [ "$h5" != "$h3" ] && ok || bad "--mode blended: '$h5' (warped '$h1', unwarped '$h3')"
expect 2 'mode: want warped, unwarped or blended' "$PLAY" "$BLOB" --mode bent
echo "  determinism: sinew-play head_turn 30 steps $h1"
expect 0 'step: median .*\(float' "$PLAYF" "$BLOBF" --clip "$CLIP" --frames 20 --hash
f1=$("$PLAYF" "$BLOBF" --clip "$CLIP" --frames 20 --hash --quiet | grep '^hash: ')
f2=$("$PLAYF" "$BLOBF" --clip "$CLIP" --frames 20 --hash --quiet | grep '^hash: ')
[ -n "$f1" ] && [ "$f1" = "$f2" ] && ok || bad "float hash not repeatable: '$f1' vs '$f2'"

# health: one closing line in both flavours; --health N every N steps;
# --stats-csv one row per step; --plot a picture of --size
for p in "$PLAY $BLOB" "$PLAYF $BLOBF"; do
    set -- $p
    expect 0 '^health: saturations [0-9]+, bound steps [0-9]+, limit clamps [0-9]+ \(last step; [0-9]+ steps with clamps\), largest displacement [-0-9.e+]+ cells, largest energy [-0-9.e+]+ J' \
        "$1" "$2" --clip "$CLIP" --frames 5 --quiet
    out=$("$1" "$2" --clip "$CLIP" --frames 25 --health 10 --quiet --stats-csv "$TMP/out/h.csv" 2>&1)
    n=$(echo "$out" | grep -cE '^health frame (10|20): t [0-9.]+ s, disp [-0-9.e+]+ cells, energy [-0-9.e+]+ J, saturations [0-9]+$')
    [ "$n" -eq 2 ] && ok || bad "$1 --health 10 over 25 steps: $n lines, want 2: $out"
    # then one ctl_NAME column per rig control of the blob (test_player_rig.sh)
    case "$(head -n 1 "$TMP/out/h.csv")" in
        frame,t_s,disp_cells,energy_J,saturations,bound_steps,limit_clamps|frame,t_s,disp_cells,energy_J,saturations,bound_steps,limit_clamps,ctl_*) ok ;;
        *) bad "$1 CSV header: $(head -n 1 "$TMP/out/h.csv")" ;;
    esac
    rows=$(awk -F, 'NR == 1 { nf = NF } NR > 1 && NF == nf && NF >= 7 && $1 == NR - 1' "$TMP/out/h.csv" | wc -l)
    [ "$rows" -eq 25 ] && [ "$(wc -l < "$TMP/out/h.csv")" -eq 26 ] && ok || bad "$1 --stats-csv: $rows good rows of $(wc -l < "$TMP/out/h.csv") lines, want 25 + header"
done
"$PLAYF" "$BLOBF" --clip "$CLIP" --frames 30 --stats-csv "$TMP/out/f.csv" --quiet > /dev/null 2>&1
expect 0 "wrote $TMP/out/pl.png" "$PLAY" "$BLOB" --clip "$CLIP" --frames 30 --plot "$TMP/out/pl.png" --size 400x300
[ "$(ihdr "$TMP/out/pl.png")" = 000001900000012c ] && ok || bad "--plot --size 400x300: $(ihdr "$TMP/out/pl.png")"
expect 0 "wrote $TMP/out/pd.png" "$PLAYF" "$BLOBF" --frames 3 --plot "$TMP/out/pd.png"
[ "$(ihdr "$TMP/out/pd.png")" = 00000320000001f4 ] && ok || bad "--plot default is not 800x500: $(ihdr "$TMP/out/pd.png")"
expect 2 "size: the plot needs at least 240x180" "$PLAY" "$BLOB" --frames 3 --plot "$TMP/out/tiny.png" --size 200x100

# sinew-plot: CSV files overlaid; clear errors
expect 0 "wrote $TMP/out/ba.png" "$PLOT" --out "$TMP/out/ba.png" "$TMP/out/h.csv" "$TMP/out/f.csv" --labels fixed,float --title "energy" --log
[ "$(ihdr "$TMP/out/ba.png")" = 00000320000001f4 ] && ok || bad "sinew-plot default is not 800x500"
expect 0 "wrote $TMP/out/one.png" "$PLOT" --out "$TMP/out/one.png" "$TMP/out/f.csv" --columns energy_J --size 320x200
expect 1 "no column 'nope'" "$PLOT" --out "$TMP/out/x.png" "$TMP/out/f.csv" --columns nope
expect 1 "cannot read $TMP/none.csv" "$PLOT" --out "$TMP/out/x.png" "$TMP/none.csv"
printf 'frame,t_s,disp_cells,energy_J\n1,0.1,x,2\n' > "$TMP/bad.csv"
expect 1 "bad.csv:2: a field is missing or not a number" "$PLOT" --out "$TMP/out/x.png" "$TMP/bad.csv"
expect 2 "labels: want 2 labels" "$PLOT" --out "$TMP/out/x.png" "$TMP/out/f.csv" "$TMP/out/h.csv" --labels a
expect 2 'usage: sinew-plot' "$PLOT" "$TMP/out/f.csv"
[ ! -e "$TMP/out/x.png" ] && ok || bad "sinew-plot wrote a picture after an error"

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

# Clip colliders and pins (CLIP.md "Colliders and pins"): a clip's collider
# and pin lines step exactly as the flags with the same values (the player
# sets them through the same sn_set_colliders / sn_set_constraints, the
# flags' first). Fixed flavour: clip Q16.16 and the flags' rounding agree
# bit for bit; float: the static sphere (values exact in Q16.16) too.
hg=$("$PLAY" "$BLOB" --clip tools/examples/cow/ground.clip --frames 72 --hash --quiet 2>/dev/null | grep '^hash: ')
hf=$("$PLAY" "$BLOB" --clip tools/examples/cow/trot.clip --ground -3.39 --frames 72 --hash --quiet 2>/dev/null | grep '^hash: ')
hn=$("$PLAY" "$BLOB" --clip tools/examples/cow/trot.clip --frames 72 --hash --quiet 2>/dev/null | grep '^hash: ')
[ -n "$hg" ] && [ "$hg" = "$hf" ] && [ "$hg" != "$hn" ] && ok "ground.clip = trot.clip --ground -3.39 ($hg), differs without the ground ($hn)" ||
    bad "ground.clip '$hg' vs --ground -3.39 '$hf' (no ground '$hn')"
printf 'sinew-clip 1\nduration 2\ncollider ball 0 sphere 1 -2.5 0 1\n' > "$TMP/sph.clip"
printf 'sinew-clip 1\nduration 2\ncollider ball 0 sphere 1 -2.5 0 1 vel 0 0.25 0\n' > "$TMP/sphv.clip"
printf 'sinew-clip 1\nduration 2\ncollider ground 0 plane 0 -3.39 0 0 1 0\ncollider ball 0 sphere 1 -2.5 0 1\n' > "$TMP/both.clip"
printf 'sinew-clip 1\nduration 2\npin a 0 surface 1000 hold\npin b 0 surface 1342 hold\n' > "$TMP/pin.clip"
same() {   # same LABEL PLAYER BLOB "ARGS A" "ARGS B" [FRAMES]: equal hashes, and not the no-collider one
    ha=$("$2" "$3" $4 --frames ${6:-60} --hash --quiet 2>/dev/null | grep '^hash: ')
    hb=$("$2" "$3" $5 --frames ${6:-60} --hash --quiet 2>/dev/null | grep '^hash: ')
    h0=$("$2" "$3" --frames ${6:-60} --hash --quiet 2>/dev/null | grep '^hash: ')
    [ -n "$ha" ] && [ "$ha" = "$hb" ] && [ "$ha" != "$h0" ] && ok "$1: $4 = $5 ($ha)" || bad "$1: '$ha' vs '$hb' (none '$h0')"
}
same "sphere" "$PLAY" "$BLOB" "--clip $TMP/sph.clip" "--sphere 1,-2.5,0,1"
same "moving sphere" "$PLAY" "$BLOB" "--clip $TMP/sphv.clip" "--sphere 1,-2.5,0,1@0,0.25,0"
same "sphere, float" "$PLAYF" "$BLOBF" "--clip $TMP/sph.clip" "--sphere 1,-2.5,0,1"
same "flags first, then the clip" "$PLAY" "$BLOB" "--clip $TMP/both.clip" "--clip $TMP/sph.clip --ground -3.39" 100
same "pins held where they are" "$PLAY" "$BLOB" "--clip $TMP/pin.clip" "--pin 1000,1342" 30
# errors: the blob's maxima (cow: colliders 4, constraints 32), flags and clip together
printf 'sinew-clip 1\nduration 1\n' > "$TMP/many.clip"
for n in 1 2 3 4 5; do echo "collider c$n 0 off" >> "$TMP/many.clip"; done
expect 1 "many.clip does not fit .*cow.blob: the clip has more collider channels than the blob's max_colliders" "$PLAY" "$BLOB" --clip "$TMP/many.clip" --frames 1
expect 1 "--ground/--sphere and .*sph.clip: 4 flag collider\(s\) and 1 clip collider channel\(s\) exceed the blob's max_colliders 4" \
    "$PLAY" "$BLOB" --clip "$TMP/sph.clip" --ground 0 --sphere 0,0,0,1 --sphere 0,0,0,1 --sphere 0,0,0,1 --frames 1
printf 'sinew-clip 1\nduration 1\npin p 0 surface 2903 hold\n' > "$TMP/far.clip"
expect 1 "far.clip does not fit .*: clip pin 'p' names surface vertex 2903, but the blob has 2903 surface vertices" "$PLAY" "$BLOB" --clip "$TMP/far.clip" --frames 1
printf 'sinew-clip 1\nduration 1\npin p 0 surface 12 1 2\n' > "$TMP/short.clip"
expect 1 'short.clip: line 3: usage: pin <name> <time> surface\|lattice <vertex>' "$PLAY" "$BLOB" --clip "$TMP/short.clip" --frames 1

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
