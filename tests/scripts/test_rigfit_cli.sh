#!/bin/sh
# sinew-rig command line (issue 11): --help; fit-surface, fit-pose,
# fit-points and export are deterministic (same inputs, same bytes); the
# rig file it writes bakes through 'rig_file' and another character refuses
# it; bad input (missing files, a target with another vertex count,
# non-finite coordinates, unknown control/command/option) fails with a clear
# message and exit 2, writing nothing.
BUILD=${BUILD:-build}
RIG=$BUILD/sinew-rig
BAKE=$BUILD/sinew-bake
. tests/scripts/cli_lib.sh
for f in "$RIG" "$BAKE"; do [ -x "$f" ] || { echo "FAIL: $f not built"; echo "0 passed, 1 failed"; exit 1; }; done
T=$(mktemp -d "${TMPDIR:-/tmp}/sinew_rig_cli.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
ROOT=$(pwd)

expect 0 'fit-surface' "$RIG" --help
expect 2 'unknown command' "$RIG" fit-everything tools/examples/limb/limb.sinew

# the limb without its biceps (thin bones), and a target made by its biceps
sed -e "s|^mesh limb.obj|mesh $ROOT/tools/examples/limb/limb.obj|" tools/examples/limb/limb.sinew > "$T/limb.sinew"
sed -e '/^rig biceps/d' "$T/limb.sinew" > "$T/limb_fit.sinew"
"$BAKE" "$T/limb.sinew" --static elbow:0,0,1,90 -o "$T/target.obj" --quiet || bad "target"
"$BAKE" "$T/limb_fit.sinew" --static elbow:0,0,1,90 -o "$T/unrigged.obj" --quiet || bad "unrigged"

# fit-surface twice (into two directories): same bytes
for k in 1 2; do
    mkdir -p "$T/run$k"
    "$RIG" fit-surface "$T/limb_fit.sinew" --target "$T/target.obj" --pose elbow:0,0,1,90 --control elbow_bend \
        -o "$T/run$k/fit.rig" --png "$T/run$k/fit.png" > "$T/fit$k.out" 2> "$T/fit$k.err" || bad "fit-surface run $k"
    cp "$T/run$k/fit.rig" "$T/fit$k.rig"
done
cmp -s "$T/run1/fit.rig" "$T/run2/fit.rig" && cmp -s "$T/run1/fit.png" "$T/run2/fit.png" && ok "fit-surface: two runs write the same rig file and picture" || bad "fit-surface not deterministic"
grep -q '^fit-surface: iter ' "$T/fit1.err" && ok "progress lines (iteration, cost, gradient norm) on stderr" || bad "no progress lines"
grep -Eq 'residual rms [0-9.e-]+%, max [0-9.e-]+%' "$T/fit1.out" && ok "summary line with the residual" || bad "no summary: $(cat "$T/fit1.out")"
grep -q '^rig_file elbow_bend .* elbow_bend tau 0 0  90 1' "$T/fit1.out" && ok "prints the rig_file line (tau 0 0 90 1)" || bad "rig_file line: $(grep rig_file "$T/fit1.out")"
max=$(sed -n 's/.*residual rms [0-9.e-]*%, max \([0-9.e-]*\)%.*/\1/p' "$T/fit1.out")
awk -v m="$max" 'BEGIN { exit !(m <= 1) }' && ok "a target made by a known rig comes back within 1% (max $max%)" || bad "residual max $max% > 1%"
# the rig file bakes through rig_file and gives the target's shape
cp "$T/fit1.rig" "$T/biceps.rig"
{ cat "$T/limb_fit.sinew"; echo "rig_file biceps biceps.rig elbow_bend tau 0 0 90 1"; } > "$T/limb_rf.sinew"
"$BAKE" "$T/limb_rf.sinew" -o "$T/limb_rf.blob" --quiet && ok "rig_file bakes" || bad "rig_file bake"
"$BAKE" "$T/limb_rf.sinew" --static elbow:0,0,1,90 -o "$T/rf.obj" --quiet || bad "rig_file static"
r=$(awk 'FNR == 1 { f++ } $1 == "v" { i[f]++; x[f, i[f]] = $2; y[f, i[f]] = $3; z[f, i[f]] = $4 }
     END { for (k = 1; k <= i[1]; k++) { r = (x[1,k]-x[2,k])^2 + (y[1,k]-y[2,k])^2 + (z[1,k]-z[2,k])^2
                                         d = (x[2,k]-x[3,k])^2 + (y[2,k]-y[3,k])^2 + (z[2,k]-z[3,k])^2
                                         if (r > rm) rm = r; if (d > dm) dm = d }
           printf "%.6f", sqrt(rm / dm) }' "$T/rf.obj" "$T/target.obj" "$T/unrigged.obj")
awk -v r="$r" 'BEGIN { exit !(r <= 0.01) }' && ok "baked rig file reproduces the target within 1% ($r)" || bad "baked rig file: $r of the displacement"
# re-baking with other bones: the file is keyed by rest positions, so it still applies; forces on
# vertices the thicker bones now carry are dropped with a warning
{ cat "$T/limb_fit.sinew"; printf 'bone elbow 0.3\nbone wrist 0.3\n'; } > "$T/limb_thin.sinew"
"$RIG" fit-surface "$T/limb_thin.sinew" --target "$T/target.obj" --pose elbow:0,0,1,90 --control elbow_bend -o "$T/thin.rig" --quiet
{ cat "$T/limb_fit.sinew"; echo "rig_file biceps thin.rig elbow_bend tau 0 0 90 1"; } > "$T/limb_rethick.sinew"
expect 0 "warning: .*rig 'biceps': [0-9]+ of the [0-9]+ forces of '.*thin.rig' fall on no free lattice vertex" "$BAKE" "$T/limb_rethick.sinew" -o "$T/rethick.blob" --quiet
# another character refuses it
sed -e "s|^mesh cow.obj|mesh $ROOT/tools/examples/cow/cow.obj|" tools/examples/cow/cow.sinew > "$T/cow.sinew"
{ cat "$T/cow.sinew"; echo "rig_file biceps $T/biceps.rig smile"; } > "$T/cow_rf.sinew"
expect 1 'fitted to another character: its mesh has 322 vertices' "$BAKE" "$T/cow_rf.sinew" -o "$T/cow_rf.blob" --quiet
[ ! -e "$T/cow_rf.blob" ] && ok "nothing written for the wrong character" || bad "blob written for the wrong character"

# several targets at several control values -> tau samples (the cow's smile at 0.5 and 1, refitted on a new control)
{ cat "$T/cow.sinew"; echo "control smile2"; } > "$T/cow2.sinew"
"$BAKE" "$T/cow2.sinew" --static rest --controls smile=1 -o "$T/smile1.obj" --quiet
"$BAKE" "$T/cow2.sinew" --static rest --controls smile=0.5 -o "$T/smile05.obj" --quiet
"$RIG" fit-surface "$T/cow2.sinew" --target "$T/smile05.obj@0.5" --target "$T/smile1.obj@1" --control smile2 -o "$T/smile2.rig" --quiet > "$T/smile2.out" 2>&1
tau=$(sed -n 's/^use: rig_file smile2 smile2.rig smile2 tau //p; s/^# use: rig_file smile2 smile2.rig smile2 tau //p' "$T/smile2.rig")
echo "$tau" | awk '{ exit !($1 == 0 && $2 == 0 && $3 == 0.5 && $4 > 0.499 && $4 < 0.501 && $5 == 1 && $6 == 1) }' \
    && ok "two targets at smile2 = 0.5 and 1 give tau samples ($tau)" || bad "tau samples: '$tau' $(cat "$T/smile2.out")"

# fit-pose and fit-points: deterministic
for k in 1 2; do
    "$RIG" fit-pose "$T/limb_fit.sinew" --target "$T/unrigged.obj" --features 54,224,234,84,244,169,294,184,304,219 \
        --joints elbow -o "$T/pose$k.txt" --quiet || bad "fit-pose $k"
done
cmp -s "$T/pose1.txt" "$T/pose2.txt" && ok "fit-pose: same bytes" || bad "fit-pose not deterministic"
grep -q '^elbow:' "$T/pose1.txt" && ok "fit-pose writes a pose --static takes ($(cat "$T/pose1.txt"))" || bad "pose file: $(cat "$T/pose1.txt")"
"$BAKE" "$T/limb_fit.sinew" --static "$(cat "$T/pose1.txt")" -o "$T/p.obj" --quiet && ok "the fitted pose is accepted by --static" || bad "--static rejects the fitted pose"
printf '# vertex x y z\n139 %s\n' "$(awk '$1 == "v" { n++; if (n == 140) print $2, $3 + 0.1, $4 }' "$T/target.obj")" > "$T/points.txt"
for k in 1 2; do
    "$RIG" fit-points "$T/limb.sinew" --pose elbow:0,0,1,90 --points "$T/points.txt" --rigs biceps -o "$T/pts$k.sinew" --quiet || bad "fit-points $k"
done
cmp -s "$T/pts1.sinew" "$T/pts2.sinew" && ok "fit-points: same bytes" || bad "fit-points not deterministic"
grep -q '^rig biceps elbow_bend muscle [0-9.]* ' "$T/pts1.sinew" && ok "fit-points writes the rig line with its fitted strength" || bad "fit-points output: $(cat "$T/pts1.sinew")"
# --geometry: the biceps moved 0.4 along the arm, thicker and weaker, found again from 41 dragged vertices
sed 's/^rig biceps elbow_bend muscle 2.5   2.0 0.3 0   5.5 0.3 0   1.5 0.2/rig biceps elbow_bend muscle 2.0   2.4 0.3 0   5.9 0.3 0   1.8 0.2/' "$T/limb.sinew" > "$T/limb_geo.sinew"
"$BAKE" "$T/limb_geo.sinew" --static elbow:0,0,1,90 -o "$T/geo.obj" --quiet
awk '$1 == "v" { n++; if ((n - 1) % 8 == 0) print n - 1, $2, $3, $4 }' "$T/geo.obj" > "$T/geo_pts.txt"
"$RIG" fit-points "$T/limb.sinew" --pose elbow:0,0,1,90 --points "$T/geo_pts.txt" --rigs biceps --geometry --lambda 0 -o "$T/geo.sinew" --quiet
awk '$1 == "rig" { exit !($5 > 1.999 && $5 < 2.001 && $6 > 2.399 && $6 < 2.401 && $9 > 5.899 && $9 < 5.901 && $12 > 1.799 && $12 < 1.801) }' "$T/geo.sinew" \
    && ok "fit-points --geometry finds the moved biceps ($(grep '^rig' "$T/geo.sinew" | cut -c1-90))" || bad "--geometry: $(cat "$T/geo.sinew")"
# export: a template rig as a rig file, baked back
"$RIG" export "$T/limb.sinew" biceps -o "$T/exp.rig" --quiet && grep -q '^forces ' "$T/exp.rig" && ok "export writes a rig file" || bad "export"

# bad input: clear message, exit 2, nothing written
expect 2 "cannot open description" "$RIG" fit-surface "$T/missing.sinew" --target "$T/target.obj" --control elbow_bend -o "$T/x.rig"
expect 2 "cannot open target '$T/missing.obj'" "$RIG" fit-surface "$T/limb_fit.sinew" --target "$T/missing.obj" --control elbow_bend -o "$T/x.rig"
"$BAKE" tools/examples/cow/cow.sinew --static rest -o "$T/cow.obj" --quiet
expect 2 "has 2903 vertices, the character's mesh has 322" "$RIG" fit-surface "$T/limb_fit.sinew" --target "$T/cow.obj" --control elbow_bend -o "$T/x.rig"
sed '5s/^v .*/v 0.5 nan 1/' "$T/target.obj" > "$T/nan.obj"
expect 2 "nan.obj:5: non-finite vertex coordinate" "$RIG" fit-surface "$T/limb_fit.sinew" --target "$T/nan.obj" --control elbow_bend -o "$T/x.rig"
sed '5s/^v .*/v 0.5 1e999 1/' "$T/target.obj" > "$T/inf.obj"
expect 2 "inf.obj:5: non-finite vertex coordinate" "$RIG" fit-pose "$T/limb_fit.sinew" --target "$T/inf.obj" --features 1,2,3 -o "$T/x.txt"
expect 2 "no control 'grin'" "$RIG" fit-surface "$T/limb_fit.sinew" --target "$T/target.obj" --control grin -o "$T/x.rig"
expect 2 "unknown joint 'knee'" "$RIG" fit-pose "$T/limb_fit.sinew" --target "$T/target.obj" --features 1,2,3 --joints knee -o "$T/x.txt"
expect 2 "vertex 999 out of range" "$RIG" fit-pose "$T/limb_fit.sinew" --target "$T/target.obj" --features 1,999 -o "$T/x.txt"
printf '139 1 nan 0\n' > "$T/badpts.txt"
expect 2 "badpts.txt:1: non-finite" "$RIG" fit-points "$T/limb.sinew" --points "$T/badpts.txt" --rigs biceps -o "$T/x.sinew"
expect 2 "no rig 'triceps'" "$RIG" fit-points "$T/limb.sinew" --points "$T/points.txt" --rigs triceps -o "$T/x.sinew"
expect 2 "unknown option '--fast'" "$RIG" fit-surface "$T/limb_fit.sinew" --fast
[ ! -e "$T/x.rig" ] && [ ! -e "$T/x.txt" ] && [ ! -e "$T/x.sinew" ] && ok "nothing written on bad input" || bad "a failed run wrote output"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
