#!/bin/sh
# demo.sh -- `make demo`: play the cow's clips in both flavours and write
# pictures to $BUILD/demo/. Run from the repository root by the Makefile.
set -e
BUILD=${BUILD:-build}
OUT=$BUILD/demo
CLIPS=tools/examples/cow
PLAY=$BUILD/sinew-play
PLAYF=$BUILD/sinew-play-float
COW=$BUILD/examples/cow.blob
COWF=$BUILD/examples/cow_float.blob
mkdir -p "$OUT"
log=$OUT/timing.txt
: > "$log"

run() {   # label, then player arguments
    label=$1; shift
    echo "== $label: $*" | sed "s|$BUILD/||g"
    "$@" --quiet > "$OUT/run.out" 2>&1 || { cat "$OUT/run.out"; exit 1; }
    cat "$OUT/run.out"
    grep '^step:' "$OUT/run.out" | sed -E 's/^step: median ([0-9.]+) us, p99 ([0-9.]+) us.*\(([a-z]+), ([0-9]+) CG.*CPU time: median ([0-9.]+) us, p99 ([0-9.]+) us.*/\1 \2 \5 \6/' |
        { read wm wp cm cp; printf '  %-38s %9s %9s %9s %9s\n' "$label" "$wm" "$wp" "$cm" "$cp"; } >> "$log"
}

# Camera on the front half of the cow (box in model space: mesh units
# relative to the root joint, the hips).
FRONT="--view 30,30 --frame-box 3,-3.4,-1.7,9.2,3,1.7"

# Head turn (seed 000 fig. 5): whole clip as a sheet; at t = 2.17 s (head
# turned 60 degrees towards the camera) rest | unwarped | warped side by side.
run "head_turn fixed (180 steps)" "$PLAY" "$COW" --clip "$CLIPS/head_turn.clip" --frames 180 \
    --sheet "$OUT/head_turn_sheet.png" --title "head turn (fixed point)"
run "head_turn fixed compare (130 steps)" "$PLAY" "$COW" --clip "$CLIPS/head_turn.clip" --frames 130 \
    --compare "$OUT/head_turn_compare.png" $FRONT
run "head_turn float (180 steps)" "$PLAYF" "$COWF" --clip "$CLIPS/head_turn.clip" --frames 180 --hash
run "head_turn float compare (130 steps)" "$PLAYF" "$COWF" --clip "$CLIPS/head_turn.clip" --frames 130 \
    --compare "$OUT/head_turn_compare_float.png" $FRONT

# Trot in place, then stand: bounce, leg swings, settling flesh. The sheet
# shows the first two strides (12 frames, 0.1 s apart); the timing run plays
# the whole clip.
run "trot fixed (216 steps)" "$PLAY" "$COW" --clip "$CLIPS/trot.clip" --frames 216 --hash
run "trot fixed sheet (72 steps)" "$PLAY" "$COW" --clip "$CLIPS/trot.clip" --frames 72 \
    --sheet "$OUT/trot_sheet.png" --title "trot (fixed point)"
run "trot fixed heat sheet (72 steps)" "$PLAY" "$COW" --clip "$CLIPS/trot.clip" --frames 72 \
    --sheet "$OUT/trot_heat_sheet.png" --heat 0.3 --title "red: 0.3 from rigid skinning"
run "trot fixed lattice (40 steps)" "$PLAY" "$COW" --clip "$CLIPS/trot.clip" --frames 40 \
    --png "$OUT/trot_lattice.png" --lattice --title "trot, control lattice"
run "trot float (216 steps)" "$PLAYF" "$COWF" --clip "$CLIPS/trot.clip" --frames 216 --hash
run "trot float sheet (72 steps)" "$PLAYF" "$COWF" --clip "$CLIPS/trot.clip" --frames 72 \
    --sheet "$OUT/trot_sheet_float.png" --title "trot (float)"
# The README picture.
run "demo picture (head_turn, 130 steps)" "$PLAY" "$COW" --clip "$CLIPS/head_turn.clip" --frames 130 \
    --compare "$OUT/demo.png" --size 400x300 $FRONT

# The beast (tools/examples/beast, 32k surface vertices): baked here if
# missing or stale; walk and violent-motion sheets, and the head turned 90
# degrees about the neck axis: rest | unwarped | warped.
BEAST_SRC=tools/examples/beast
BEAST=$BUILD/examples/beast.blob
for f in "$BEAST_SRC/beast.sinew" "$BEAST_SRC/beast.obj" "$BUILD/sinew-bake"; do
    if [ ! -f "$BEAST" ] || [ "$f" -nt "$BEAST" ]; then
        echo "== bake the beast"
        mkdir -p "$BUILD/examples"
        "$BUILD/sinew-bake" "$BEAST_SRC/beast.sinew" -o "$BEAST" --quiet
        break
    fi
done
BEASTVIEW="--view 25,10 --size 280x300"
run "beast walk sheet (144 steps)" "$PLAY" "$BEAST" --clip "$BEAST_SRC/walk.clip" --frames 144 \
    --sheet "$OUT/beast_walk_sheet.png" --title "beast walk (fixed point)" $BEASTVIEW
run "beast violent sheet (480 steps)" "$PLAY" "$BEAST" --clip "$BEAST_SRC/violent.clip" --frames 480 \
    --sheet "$OUT/beast_violent_sheet.png" --title "head 180 deg in 0.1 s, then 170, chest 170" $BEASTVIEW
run "beast head_turn compare (180 steps)" "$PLAY" "$BEAST" --clip "$BEAST_SRC/head_turn.clip" --frames 180 \
    --compare "$OUT/beast_head_turn_compare.png" --view 50,10 --size 800x600
rm -f "$OUT/run.out"

echo
echo "Time of one sn_step in microseconds on this machine (CPU = thread CPU time,"
echo "unaffected by other processes). The assets:"
"$PLAY" "$COW" --frames 1 2>/dev/null | grep 'lattice vertices' | sed "s|^$BUILD/|  |"
"$PLAY" "$BEAST" --frames 1 2>/dev/null | grep 'lattice vertices' | sed "s|^$BUILD/|  |"
printf '  %-38s %9s %9s %9s %9s\n' "run" "median" "p99" "CPU med" "CPU p99"
cat "$log"
echo
echo "Pictures in $OUT/:"
for f in "$OUT"/*.png; do echo "  $f"; done
