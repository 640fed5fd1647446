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

# External forces (seed 004 ch. 4 on the lattice): the same punch on the
# beast's belly and kick on the cow's flank with a local, a default and a
# global share profile; "rest | no hit | hit" 0.15 s later, the hit panel
# coloured by its distance from the no-hit run (red at 0.5 mesh units for
# the beast, 0.1 for the cow).
# Constraints and contact (issue 12): the trot on a ground plane 0.05 above
# the lowest resting hoof (model space: the hooves rest at y = -3.437, not
# cow.obj's -3.637; tools/examples/cow/ground.clip), a sphere rising into the belly, a belt (the
# surface near x = 2 pinned in y and z) while the cow breathes
run "cow trot on the ground (72 steps)" "$PLAY" "$COW" --clip "$CLIPS/trot.clip" --frames 72 --ground -3.39 \
    --sheet "$OUT/cow_ground.png" --title "trot on a ground plane (sn_set_colliders)"
run "cow sphere in the belly (120 steps)" "$PLAY" "$COW" --frames 120 --sphere 1,-2.6,0,1@0,0.3,0 \
    --sheet "$OUT/cow_sphere.png" --title "a sphere rising into the belly" --view 5,-5 --frame-box -2,-3.8,-2,4,0.5,2
run "cow belt while breathing (180 steps)" "$PLAY" "$COW" --clip "$CLIPS/breathe.clip" --frames 180 --belt 2.0 \
    --sheet "$OUT/cow_belt.png" --heat 0.15 --title "belt at x = 2 (32 pins) while breathing" --view 60,10
run "cow belt float (180 steps)" "$PLAYF" "$COWF" --clip "$CLIPS/breathe.clip" --frames 180 --belt 2.0 --hash

BEAST=$BUILD/examples/beast.blob
for p in local torso global; do
    run "beast punch, profile $p (9 steps)" "$PLAY" "$BEAST" --clip tools/examples/beast/punch_$p.clip --frames 9 \
        --compare-hits "$OUT/beast_punch_$p.png" --heat 0.5
done
for p in local body global; do
    run "cow kick, profile $p (9 steps)" "$PLAY" "$COW" --clip "$CLIPS/hit_$p.clip" --frames 9 \
        --compare-hits "$OUT/cow_kick_$p.png" --heat 0.1 --view 215,10
done

# Segment meshes (seed 004 ch. 3-4). The cow's tail (a chain hanging from the
# tail root) swinging over the trot, seen from behind; its saddle blanket (a
# 5x5 sheet held along its front and back edges) from above.
REAR="--view -55,8 --frame-box -2.6,-3.6,-2.2,2.4,2.4,2.2"
run "cow tail over the trot (72 steps)" "$PLAY" "$COW" --clip "$CLIPS/trot.clip" --frames 72 \
    --sheet "$OUT/cow_tail.png" --title "tail: 8 segments (seed 004 ch. 3)" $REAR
run "cow blanket over the trot (72 steps)" "$PLAY" "$COW" --clip "$CLIPS/trot.clip" --frames 72 \
    --sheet "$OUT/cow_blanket.png" --title "blanket: 5x5 sheet, 2 levels" --view 35,40 --frame-box 0.6,-0.6,-2,5,2.6,2
# The thesis' sheet experiments on a free 9x9 sheet without gravity
# (tools/examples/sheet, variants by make_sheet.sh): one upward impulse at a
# corner (fig. 3.11, 4.9-4.11) and at the centre (fig. 3.12) with all the
# force on the finest level, shared equally by the four levels, or all on the
# coarsest; then the tilted sheet dropped on a floor with gravity (fig.
# 4.13-4.15), beside the box. One second per impulse run (60 steps), 0.6 s per
# drop (36 steps), 12 panels each.
EXS=$BUILD/examples
SHEETVIEW="--view 30,20 --frame-box -6,-1,-6,6,7,6"
for v in fine equal coarse; do
    run "sheet corner $v (60 steps)" "$PLAY" "$EXS/sheet_$v.blob" --frames 60 --seg-impulse 0:0:0,0.08,0 \
        --sheet "$OUT/sheet_corner_$v.png" --title "corner impulse, shares $v" $SHEETVIEW
    run "sheet centre $v (60 steps)" "$PLAY" "$EXS/sheet_$v.blob" --frames 60 --seg-impulse 0:40:0,0.08,0 \
        --sheet "$OUT/sheet_centre_$v.png" --title "centre impulse, shares $v" $SHEETVIEW
    run "sheet floor $v (36 steps)" "$PLAY" "$EXS/sheet_floor_$v.blob" --frames 36 --seg-floor -0.5 \
        --sheet "$OUT/sheet_floor_$v.png" --title "dropped on the floor, shares $v" --view 15,12 --frame-box -6,-0.5,2,6,6.5,12
done

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
# the walk on a ground plane 0.07 above the resting soles (model space:
# relative to the root joint, soles at y = -130.94); contacts yield to the
# bones that carry the feet (runtime/NUMERICS.md "Contacts")
run "beast walk on the ground (144 steps)" "$PLAY" "$BEAST" --clip "$BEAST_SRC/walk.clip" --frames 144 --ground -130.87 \
    --sheet "$OUT/beast_ground.png" --title "beast walk on a ground plane (sn_set_colliders)" $BEASTVIEW
run "beast violent sheet (480 steps)" "$PLAY" "$BEAST" --clip "$BEAST_SRC/violent.clip" --frames 480 \
    --sheet "$OUT/beast_violent_sheet.png" --title "head 180 deg in 0.1 s, then 170, chest 170" $BEASTVIEW
run "beast head_turn compare (180 steps)" "$PLAY" "$BEAST" --clip "$BEAST_SRC/head_turn.clip" --frames 180 \
    --compare "$OUT/beast_head_turn_compare.png" --view 50,10 --size 800x600

# Rig forces (seed 003; rig controls in CLIP.md): rest | rigs off | rigs on,
# the rigs-on flesh coloured by its distance from the rigs-off run (--heat).
# Abstract controls are switched off by holding them at 0; rigs driven by a
# pose control (the biceps follow the elbow) only by a blob baked without
# them: the description with its 'rig' lines removed.
norig() {   # example -> $BUILD/examples/norig/<example>.blob
    src=tools/examples/$1/$1.sinew; dir=$BUILD/examples/norig; out=$dir/$1.blob
    for f in "$src" "tools/examples/$1/$1.obj" "$BUILD/sinew-bake"; do
        if [ ! -f "$out" ] || [ "$f" -nt "$out" ]; then
            echo "== bake $1 without its rigs"
            mkdir -p "$dir"
            sed -e '/^[[:space:]]*rig[[:space:]]/d' -e "s|^mesh .*|mesh $PWD/tools/examples/$1/$1.obj|" "$src" > "$dir/$1.sinew"
            "$BUILD/sinew-bake" "$dir/$1.sinew" -o "$out" --quiet
            break
        fi
    done
}
norig limb
norig beast
LIMB=$BUILD/examples/limb.blob
MUZZLE="--frame-box 8.2,0.4,-1.0,9.8,2.2,1.0"
run "cow breathe in (120 steps)" "$PLAY" "$COW" --clip "$CLIPS/breathe.clip" --frames 120 \
    --compare-rigs "$OUT/cow_breath_in_rigs.png" --heat 0.15 --view 20,20
run "cow breathe out (240 steps)" "$PLAY" "$COW" --clip "$CLIPS/breathe.clip" --frames 240 \
    --compare-rigs "$OUT/cow_breath_out_rigs.png" --heat 0.15 --view 20,20 \
    --plot "$OUT/cow_breathe_plot.png" --size 800x600 --title "cow breathing: breath 0, +1, -1, 0 (breathe.clip)"
run "cow smile (90 steps)" "$PLAY" "$COW" --clip "$CLIPS/smile.clip" --frames 90 \
    --compare-rigs "$OUT/cow_smile_rigs.png" --heat 0.1 --view 40,15 $MUZZLE
run "cow nostrils flared (210 steps)" "$PLAY" "$COW" --clip "$CLIPS/smile.clip" --frames 210 \
    --compare-rigs "$OUT/cow_nostrils_rigs.png" --heat 0.05 --view 75,10 $MUZZLE
run "cow belly held in (60 steps)" "$PLAY" "$COW" --clip "$CLIPS/belly.clip" --frames 60 \
    --compare-rigs "$OUT/cow_belly_rigs.png" --heat 0.1 --view 20,5
run "limb biceps (150 steps)" "$PLAY" "$LIMB" --clip tools/examples/limb/flex.clip --frames 150 \
    --compare-rigs "$OUT/limb_biceps_rigs.png" --rig-off-blob "$BUILD/examples/norig/limb.blob" --heat 0.1 --view 0,10
run "beast flex and breathe (150 steps)" "$PLAY" "$BEAST" --clip "$BEAST_SRC/flex.clip" --frames 150 \
    --compare-rigs "$OUT/beast_rigs.png" --rig-off-blob "$BUILD/examples/norig/beast.blob" --heat 3 --view 10,10 --size 600x450
# Self-collision near the elbow crease (seed 003 §3.4, fig. 2): the limb at
# 120 degrees (crease.clip at 3 s) without crease data (the same lattice),
# and with it: the contacts the runtime lists (red dots) enforced by the
# constraint projection: the flesh bulges instead of interpenetrating.
run "limb 120 deg, no crease data (180 steps)" "$PLAY" "$BUILD/examples/limb_crease_none.blob" --clip tools/examples/limb/crease.clip \
    --frames 180 --png "$OUT/limb_crease_without.png" --view 0,5 --title "limb at 120 deg: no crease collision"
run "limb 120 deg, crease collision (180 steps)" "$PLAY" "$BUILD/examples/limb_crease.blob" --clip tools/examples/limb/crease.clip \
    --frames 180 --png "$OUT/limb_crease_with.png" --view 0,5 --crease-marks \
    --title "limb at 120 deg: crease collision (contacts red)"
# The beast's elbows at 120 degrees (tools/examples/beast/crease.clip at
# 3 s), its left arm from the front: without crease data (beast.blob) and
# with it (beast_crease.blob: beast.sinew + crease.lines), contacts red.
run "beast elbows 120 deg, no crease data (180 steps)" "$PLAY" "$BUILD/examples/beast.blob" --clip tools/examples/beast/crease.clip \
    --frames 180 --png "$OUT/beast_crease_without.png" --view 60,20 --frame-box 30,20,-10,130,110,90 --title "beast elbows at 120 deg: no crease collision"
run "beast elbows 120 deg, crease collision (180 steps)" "$PLAY" "$BUILD/examples/beast_crease.blob" --clip tools/examples/beast/crease.clip \
    --frames 180 --png "$OUT/beast_crease_with.png" --view 60,20 --frame-box 30,20,-10,130,110,90 --crease-marks \
    --title "beast elbows at 120 deg: crease collision (contacts red)"
rm -f "$OUT/run.out"

# Rig fitting (issue 11, seed 003 fig. 5-6): sinew-rig fits surface rigs to
# target shapes; pictures and figures in $OUT/rigfit/ (figures.txt).
if [ -x "$BUILD/sinew-rig" ]; then
    echo "== rig fitting: tools/examples/rigfit/rigfit.sh"
    BUILD=$BUILD sh tools/examples/rigfit/rigfit.sh "$OUT/rigfit" > "$OUT/rigfit.log" 2>&1 || { cat "$OUT/rigfit.log"; exit 1; }
    cat "$OUT/rigfit/figures.txt"
fi

# Retargeting (seed 003 §4.4): the cow's two-bump smile carried to Spot
# (tools/examples/spot): A rest | A rigged | B rest | B rigged (static
# equilibria at rest) | the cow's surface under the map, framed on the heads.
echo "== retarget the cow's smile onto spot"
"$BUILD/sinew-rig" retarget tools/examples/cow/cow.sinew tools/examples/spot/spot.sinew --rig smile_l,smile_r --name smile \
    --w-surf 1000 -o "$OUT/spot_smile.rig" --png "$OUT/retarget_spot_smile.png" --view-a 50,10 --view-b 140,10 \
    --frame-a 3.3,-0.8,-1.5,6.2,2.8,1.5 --frame-b -0.5,-0.2,-0.75,0.5,1.0,0.0 > "$OUT/retarget.log" 2>&1 ||
    { cat "$OUT/retarget.log"; exit 1; }
grep -v "^retarget: round " "$OUT/retarget.log"

echo
echo "Time of one sn_step in microseconds on this machine (CPU = thread CPU time,"
echo "unaffected by other processes). The assets:"
"$PLAY" "$COW" --frames 1 2>/dev/null | grep 'lattice vertices' | sed "s|^$BUILD/|  |"
"$PLAY" "$BEAST" --frames 1 2>/dev/null | grep 'lattice vertices' | sed "s|^$BUILD/|  |"
printf '  %-38s %9s %9s %9s %9s\n' "run" "median" "p99" "CPU med" "CPU p99"
cat "$log"
echo
echo "Pictures in $OUT/:"
for f in "$OUT"/*.png "$OUT"/rigfit/*.png; do [ -e "$f" ] && echo "  $f"; done
