#!/bin/sh
# rigfit.sh -- the rig-fitting examples of issue 11 (seed 003 §4.3, fig. 5-6):
#   1. cow grin: a target for the cow's head made by displacing its static rest
#      shape with a known smooth field (tools/examples/cow/make_grin_target.sh),
#      fitted as a surface rig on an abstract control 'grin', baked through
#      'rig_file' and replayed in the runtime (sinew-play, grin=1). At cell 0.6
#      the field is out of reach of any rig (the head and snout bones carry the
#      middle of the muzzle): the fit IS the best reachable fit (13.8% rms),
#      which sinew-rig prints with the residual; the same field at cell 0.3 fits
#      to 2.9%;
#   2. bent limb: the limb bent 90 degrees at the elbow (static, no rig) with a
#      biceps bulge added (a known field), its pose fitted to 10 feature points,
#      then fitted as an elbow-driven surface rig (tau 0 0 ANGLE 1); the picture
#      rest | unrigged bent | rigged bent | target, and the runtime's flex clip
#      with and without the rig;
#   3. known rigs refitted: the cow's smile (smile=1) and the beast's breathing
#      (breath=1) shapes fitted as new rigs (should come back within 1%).
# Writes everything to OUT (default $BUILD/demo/rigfit) and a summary
# OUT/figures.txt (residuals as fractions of the target displacement,
# iterations, wall times; for every surface rig also the best reachable
# residual, the fit against it and the best with the skeleton vertices freed). Run from the repository root:
#   BUILD=build sh tools/examples/rigfit/rigfit.sh [OUT]
set -e
BUILD=${BUILD:-build}
OUT=${1:-$BUILD/demo/rigfit}
BAKE=$BUILD/sinew-bake
RIG=$BUILD/sinew-rig
PLAY=$BUILD/sinew-play
ROOT=$(pwd)
mkdir -p "$OUT"
FIG=$OUT/figures.txt
: > "$FIG"
note() { echo "$*"; echo "$*" >> "$FIG"; }
# residual A.obj TARGET.obj BASE.obj: rms and max |A - T| over |T - B| (vertices in order)
residual() {
    awk 'FNR == 1 { f++ } $1 == "v" { i[f]++; x[f, i[f]] = $2; y[f, i[f]] = $3; z[f, i[f]] = $4 }
         END { for (k = 1; k <= i[1]; k++) {
                   r = (x[1,k]-x[2,k])^2 + (y[1,k]-y[2,k])^2 + (z[1,k]-z[2,k])^2
                   d = (x[2,k]-x[3,k])^2 + (y[2,k]-y[3,k])^2 + (z[2,k]-z[3,k])^2
                   R += r; D += d; if (r > rm) rm = r; if (d > dm) dm = d }
               printf "rms %.3g%%, max %.3g%% of the target displacement", 100 * sqrt(R / D), 100 * sqrt(rm / dm) }' "$1" "$2" "$3"
}
# dresidual A A0 T T0: the same for displacements, (A - A0) against (T - T0)
# (the runtime's positions are model space and its shape at 600 steps carries
# its own sag: its rig displacement is compared with the target's)
dresidual() {
    awk 'FNR == 1 { f++ } $1 == "v" { i[f]++; x[f, i[f]] = $2; y[f, i[f]] = $3; z[f, i[f]] = $4 }
         END { for (k = 1; k <= i[1]; k++) {
                   ax = x[1,k]-x[2,k]; ay = y[1,k]-y[2,k]; az = z[1,k]-z[2,k]
                   tx = x[3,k]-x[4,k]; ty = y[3,k]-y[4,k]; tz = z[3,k]-z[4,k]
                   r = (ax-tx)^2 + (ay-ty)^2 + (az-tz)^2; d = tx^2 + ty^2 + tz^2
                   R += r; D += d; if (r > rm) rm = r; if (d > dm) dm = d }
               printf "rms %.3g%%, max %.3g%% of the target displacement", 100 * sqrt(R / D), 100 * sqrt(rm / dm) }' "$1" "$2" "$3" "$4"
}
# fit summary lines of sinew-rig's output (fit-surface: the residual, then what
# any rig at the pose could reach: the target's share on bone-carried surface,
# the best fit by the free lattice vertices alone and the fit against it)
fitline() { grep -E '^fit-(surface|pose): ([0-9]|target on|best reachable|the fit against|with the skeleton)' "$1" | sed 's/^/    /'; }

# ---------------- 1. cow grin ----------------
# The fit copy of the cow: a finer lattice (0.6 instead of 1.2 mesh units)
# and thin head bones, so the face has free lattice vertices to move.
sed -e "s|^mesh cow.obj|mesh $ROOT/tools/examples/cow/cow.obj|" -e 's/^cell 1.2 .*/cell 0.6/' \
    tools/examples/cow/cow.sinew > "$OUT/cow_grin.sinew"
printf '\n# sinew-rig example: a fitted surface rig on an abstract control\nbone head 0.3\nbone snout 0.3\ncontrol grin\n' >> "$OUT/cow_grin.sinew"
"$BAKE" "$OUT/cow_grin.sinew" --static rest -o "$OUT/cow_grin_static.obj" --quiet
sh tools/examples/cow/make_grin_target.sh "$OUT/cow_grin_static.obj" > "$OUT/cow_grin_target.obj"
t0=$(date +%s.%N 2>/dev/null || date +%s)
"$RIG" fit-surface "$OUT/cow_grin.sinew" --target "$OUT/cow_grin_target.obj" --control grin -o "$OUT/cow_grin.rig" \
    --png "$OUT/cow_grin_fit.png" --view 60,15 --progress 200 > "$OUT/cow_grin_fit.txt"
cat "$OUT/cow_grin_fit.txt"
note "cow grin (known smooth field on the muzzle, 0.257 mesh units at most; cell 0.6, out of reach: the fit is the best reachable):"
fitline "$OUT/cow_grin_fit.txt" >> "$FIG"
# replay: bake the rig file into the character and hold grin = 1 in the runtime
{ cat "$OUT/cow_grin.sinew"; echo "rig_file grin cow_grin.rig grin"; } > "$OUT/cow_grin_rigged.sinew"
"$BAKE" "$OUT/cow_grin_rigged.sinew" -o "$OUT/cow_grin_rigged.blob" --quiet
"$BAKE" "$OUT/cow_grin_rigged.sinew" --static rest --controls grin=1 -o "$OUT/cow_grin_rigged_static.obj" --quiet
note "    baked rig_file, static (double) at grin=1 vs target: $(residual "$OUT/cow_grin_rigged_static.obj" "$OUT/cow_grin_target.obj" "$OUT/cow_grin_static.obj")"
if [ -x "$PLAY" ]; then
    for g in 0 1; do
        rm -rf "$OUT/cow_grin_frames$g"; mkdir -p "$OUT/cow_grin_frames$g"
        "$PLAY" "$OUT/cow_grin_rigged.blob" --control grin=$g --frames 600 --quiet --obj-dir "$OUT/cow_grin_frames$g" --obj-frames 600 > /dev/null
    done
    "$PLAY" "$OUT/cow_grin_rigged.blob" --control grin=1 --frames 600 --quiet \
        --compare-rigs "$OUT/cow_grin_runtime.png" --heat 0.25 --view 40,15 --frame-box 3,-3.4,-1.7,9.2,3,1.7 > /dev/null
    note "    runtime (fixed point, sinew-play --control grin=1 vs grin=0, 600 steps): $(dresidual "$OUT/cow_grin_frames1/frame_0600.obj" \
        "$OUT/cow_grin_frames0/frame_0600.obj" "$OUT/cow_grin_target.obj" "$OUT/cow_grin_static.obj")"
fi

# The same field on a lattice twice as fine (cell 0.3): at 0.6 the head and snout
# bones' rasterized chains (one grid vertex per bone sample, whatever the
# radius) run along the middle of a muzzle about one cell thick, so the
# surface there hangs on skeleton vertices and the field is out of reach
# (the best reachable fit is the fit itself; fit only, no replay).
sed -e 's/^cell 0.6$/cell 0.3/' "$OUT/cow_grin.sinew" > "$OUT/cow_grin_fine.sinew"
"$BAKE" "$OUT/cow_grin_fine.sinew" --static rest -o "$OUT/cow_grin_fine_static.obj" --quiet
sh tools/examples/cow/make_grin_target.sh "$OUT/cow_grin_fine_static.obj" > "$OUT/cow_grin_fine_target.obj"
"$RIG" fit-surface "$OUT/cow_grin_fine.sinew" --target "$OUT/cow_grin_fine_target.obj" --control grin -o "$OUT/cow_grin_fine.rig" \
    --png "$OUT/cow_grin_fine_fit.png" --view 60,15 --progress 500 > "$OUT/cow_grin_fine_fit.txt"
cat "$OUT/cow_grin_fine_fit.txt"
note "cow grin on a lattice twice as fine (cell 0.3 instead of 0.6; fit only):"
fitline "$OUT/cow_grin_fine_fit.txt" >> "$FIG"

# ---------------- 2. bent limb (seed 003 fig. 5-6) ----------------
# The limb without its biceps template, with thin bones (the automatic 1.25
# cells make the middle of every face a skeleton vertex, which no force moves);
# the elbow's bend angle drives the fitted rig.
sed -e "s|^mesh limb.obj|mesh $ROOT/tools/examples/limb/limb.obj|" -e '/^rig biceps/d' tools/examples/limb/limb.sinew > "$OUT/limb_fit.sinew"
printf '\n# sinew-rig example: thin bones (only the centre line is carried)\nbone elbow 0.3\nbone wrist 0.3\n' >> "$OUT/limb_fit.sinew"
"$BAKE" "$OUT/limb_fit.sinew" --static elbow:0,0,1,90 -o "$OUT/limb_bent.obj" --quiet
# the target: the bent static shape plus a biceps bulge on the upper arm's top
# near the elbow: d = A w(|x - c| / R) (0, 1, 0), c = (2.6, 1, 0), R = 1.6, A = 0.3
awk -v cx=2.6 -v cy=1 -v cz=0 -v R=1.6 -v A=0.3 '
$1 == "v" { dx = ($2 - cx) / R; dy = ($3 - cy) / R; dz = ($4 - cz) / R; t2 = dx*dx + dy*dy + dz*dz
            if (t2 < 1) { w = (1 - t2) ^ 3; printf "v %.9g %.9g %.9g\n", $2, $3 + A * w, $4 } else print; next }
{ print }' "$OUT/limb_bent.obj" > "$OUT/limb_target.obj"
FEAT=54,224,234,84,244,169,294,184,304,219   # on three faces, away from the elbow and the bulge
"$RIG" fit-pose "$OUT/limb_fit.sinew" --target "$OUT/limb_target.obj" --features $FEAT --joints shoulder,elbow \
    -o "$OUT/limb_pose.txt" --progress 50 > "$OUT/limb_pose_fit.txt"
cat "$OUT/limb_pose_fit.txt"
note "bent limb: pose from 10 feature points (shoulder and elbow free; true pose elbow:0,0,1,90):"
fitline "$OUT/limb_pose_fit.txt" >> "$FIG"
note "    $(grep '^pose ' "$OUT/limb_pose_fit.txt")"
"$RIG" fit-surface "$OUT/limb_fit.sinew" --target "$OUT/limb_target.obj" --features $FEAT --joints shoulder,elbow \
    --control elbow_bend --name biceps_fit -o "$OUT/limb_biceps.rig" --png "$OUT/limb_fit.png" --view 0,10 --progress 200 > "$OUT/limb_fit.txt"
cat "$OUT/limb_fit.txt"
note "bent limb surface rig (elbow-driven):"
fitline "$OUT/limb_fit.txt" >> "$FIG"
tau=$(sed -n 's/^rig_file [^ ]* [^ ]* [^ ]* tau //p' "$OUT/limb_fit.txt")
{ cat "$OUT/limb_fit.sinew"; echo "rig_file biceps_fit limb_biceps.rig elbow_bend tau $tau"; } > "$OUT/limb_rigged.sinew"
"$BAKE" "$OUT/limb_rigged.sinew" -o "$OUT/limb_rigged.blob" --quiet
"$BAKE" "$OUT/limb_fit.sinew" -o "$OUT/limb_norig.blob" --quiet
"$BAKE" "$OUT/limb_rigged.sinew" --static "$(cat "$OUT/limb_pose.txt")" -o "$OUT/limb_rigged_static.obj" --quiet
note "    baked rig_file, static at the fitted pose vs target: $(residual "$OUT/limb_rigged_static.obj" "$OUT/limb_target.obj" "$OUT/limb_bent.obj")"
"$RIG" fit-surface "$OUT/limb_fit.sinew" --target "$OUT/limb_target.obj" --pose elbow:0,0,1,90 \
    --control elbow_bend -o "$OUT/limb_biceps_truepose.rig" --progress 1000 > "$OUT/limb_fit_truepose.txt"
note "bent limb surface rig at the true pose (elbow:0,0,1,90, no pose fit):"
fitline "$OUT/limb_fit_truepose.txt" >> "$FIG"
"$BAKE" "$OUT/limb_rigged.sinew" --static elbow:0,0,1,45 -o "$OUT/limb_rigged_45.obj" --png "$OUT/limb_rigged_45.png" --quiet
if [ -x "$PLAY" ]; then
    "$PLAY" "$OUT/limb_rigged.blob" --clip tools/examples/limb/flex.clip --frames 150 --quiet \
        --compare-rigs "$OUT/limb_runtime.png" --rig-off-blob "$OUT/limb_norig.blob" --heat 0.3 --view 0,10 > /dev/null
fi

# ---------------- 3. known rigs refitted ----------------
sed -e "s|^mesh cow.obj|mesh $ROOT/tools/examples/cow/cow.obj|" tools/examples/cow/cow.sinew > "$OUT/cow_refit.sinew"
printf '\ncontrol smile2\n' >> "$OUT/cow_refit.sinew"
"$BAKE" "$OUT/cow_refit.sinew" --static rest --controls smile=1 -o "$OUT/cow_smile_target.obj" --quiet
"$BAKE" "$OUT/cow_refit.sinew" --static rest -o "$OUT/cow_rest_static.obj" --quiet
"$RIG" fit-surface "$OUT/cow_refit.sinew" --target "$OUT/cow_smile_target.obj" --control smile2 -o "$OUT/cow_smile2.rig" \
    --png "$OUT/cow_smile_refit.png" --view 60,15 --progress 500 > "$OUT/cow_smile_refit.txt"
note "cow smile (smile=1 of the template bumps) refitted as a surface rig:"
fitline "$OUT/cow_smile_refit.txt" >> "$FIG"
sed -e "s|^mesh beast.obj|mesh $ROOT/tools/examples/beast/beast.obj|" tools/examples/beast/beast.sinew > "$OUT/beast_refit.sinew"
printf '\ncontrol inhale\n' >> "$OUT/beast_refit.sinew"
"$BAKE" "$OUT/beast_refit.sinew" --static rest --controls breath=1 -o "$OUT/beast_breath_target.obj" --quiet
"$RIG" fit-surface "$OUT/beast_refit.sinew" --target "$OUT/beast_breath_target.obj" --control inhale -o "$OUT/beast_inhale.rig" \
    --png "$OUT/beast_breath_refit.png" --view 20,10 --progress 500 > "$OUT/beast_breath_refit.txt"
note "beast breathing (breath=1 of the ring template) refitted as a surface rig:"
fitline "$OUT/beast_breath_refit.txt" >> "$FIG"
# the humanoid: its left arm's pose (shoulder 20 deg about z, elbow 60 deg about its bend axis)
# from 10 feature vertices on the arm, on the static shape and on the skinned one
BPOSE="shoulder_l:0,0,1,20+elbow_l:-0.35,-0.93,-0.07,60"
BFEAT=10281,11930,13385,14064,15810,17653,19787,21145,22988,24055
"$BAKE" "$OUT/beast_refit.sinew" --static "$BPOSE" -o "$OUT/beast_pose_target.obj" --png "$OUT/beast_pose_target.png" --quiet
note "beast left arm pose from 10 feature points (true: $BPOSE):"
for mode in static skinned; do
    flag=; [ $mode = skinned ] && flag=--pose-skinned
    "$RIG" fit-pose "$OUT/beast_refit.sinew" --target "$OUT/beast_pose_target.obj" --features $BFEAT --joints shoulder_l,elbow_l $flag \
        -o "$OUT/beast_pose_$mode.txt" --progress 1000 > "$OUT/beast_pose_$mode.out"
    note "    on the $mode shape: $(sed -n 's/^fit-pose: //p' "$OUT/beast_pose_$mode.out")"
    note "        $(grep '^pose ' "$OUT/beast_pose_$mode.out")"
done
# the humanoid's biceps (elbow-driven template, tau 0 0 90 1) at that pose refitted as a surface rig on a new pose control
{ cat "$OUT/beast_refit.sinew"; echo "control flex_l angle elbow_l -0.35 -0.93 -0.07"; } > "$OUT/beast_flex.sinew"
"$BAKE" "$OUT/beast_flex.sinew" --static "$BPOSE" -o "$OUT/beast_flex_target.obj" --quiet
"$RIG" fit-surface "$OUT/beast_flex.sinew" --target "$OUT/beast_flex_target.obj" --pose "$BPOSE" \
    --rigs-off --control flex_l -o "$OUT/beast_flex.rig" --png "$OUT/beast_flex_fit.png" --view 10,10 --progress 1000 > "$OUT/beast_flex_fit.txt"
note "beast biceps (template, 2/3 on at 60 deg) refitted at the pose as a surface rig on a new pose control flex_l (the description's rigs off):"
fitline "$OUT/beast_flex_fit.txt" >> "$FIG"
note "    $(grep '^rig_file' "$OUT/beast_flex_fit.txt")"

echo
echo "rigfit: figures in $FIG; pictures in $OUT"
