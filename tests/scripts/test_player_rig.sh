#!/bin/sh
# test_player_rig.sh -- rig controls in the desktop player (sinew-play,
# sinew-play-float; clip format ports/common/CLIP.md "Control tracks"):
# a clip's control track changes the surface, and gives bit for bit the
# surface of --control held at the track's value; --control overrides a
# track; --rigs off equals a run without the track; a control the blob lacks
# is a warning and its keys are ignored; a pose control cannot be keyed or
# held; bad control lines fail with their line; --stats-csv and --plot carry
# the controls (pose controls in degrees); --compare-rigs with and without
# --rig-off-blob. Needs the cow (fixed, float) and limb blobs with their rigs.
# Usage: sh tests/scripts/test_player_rig.sh [BUILD]
BUILD=${1:-${BUILD:-build}}
PLAY=$BUILD/sinew-play
PLAYF=$BUILD/sinew-play-float
BAKE=$BUILD/sinew-bake
COW=$BUILD/examples/cow.blob
COWF=$BUILD/examples/cow_float.blob
LIMB=$BUILD/examples/limb.blob
TMP=$(mktemp -d "${TMPDIR:-/tmp}/sn_player_rig.XXXXXX") || exit 1
trap 'rm -rf "$TMP"' EXIT
. tests/scripts/cli_lib.sh
# hash PLAYER BLOB ARGS...: the state hash line after the run ("" on failure)
hash() { p=$1; b=$2; shift 2; "$p" "$b" --hash --quiet "$@" 2>/dev/null | grep '^hash: '; }

need "$PLAY" "$PLAYF" "$BAKE" "$COW" "$COWF" "$LIMB"
for c in breath smile nostrils; do
    "$PLAY" "$COW" --control "$c=0" --frames 0 --quiet > /dev/null 2>&1 ||
        { echo "FAIL: $COW has no abstract control '$c' (baked before the cow's rigs?)"; echo "0 passed, 1 failed"; exit 1; }
done

# clips: the same head turn with and without a breath track
cat > "$TMP/turn.clip" <<'EOF'
sinew-clip 1
duration 1
rot head 0   0 1 0  0
rot head 0.5 0 1 0 30
EOF
{ cat "$TMP/turn.clip"; echo "control breath 0.25 1   # one key: held at 1 the whole clip"; } > "$TMP/turn_breath.clip"
{ cat "$TMP/turn.clip"; echo "control breath 0 0"; echo "control breath 1 -1"; } > "$TMP/turn_ramp.clip"
{ cat "$TMP/turn_breath.clip"; echo "control bogus 0 1"; } > "$TMP/turn_bogus.clip"

for flav in fixed float; do
    if [ $flav = fixed ]; then P=$PLAY; B=$COW; else P=$PLAYF; B=$COWF; fi
    h0=$(hash "$P" "$B" --clip "$TMP/turn.clip" --frames 45)
    h1=$(hash "$P" "$B" --clip "$TMP/turn_breath.clip" --frames 45)
    h2=$(hash "$P" "$B" --clip "$TMP/turn.clip" --frames 45 --control breath=1)
    h3=$(hash "$P" "$B" --clip "$TMP/turn_ramp.clip" --frames 45 --control breath=1)
    h4=$(hash "$P" "$B" --clip "$TMP/turn_breath.clip" --frames 45 --rigs off)
    h5=$(hash "$P" "$B" --clip "$TMP/turn_ramp.clip" --frames 45)
    h6=$(hash "$P" "$B" --clip "$TMP/turn_bogus.clip" --frames 45)
    [ -n "$h0" ] && [ -n "$h1" ] && [ -n "$h2" ] && ok || bad "$flav: a run failed: '$h0' '$h1' '$h2'"
    [ "$h0" != "$h1" ] && ok || bad "$flav: the breath track does not change the state ($h1)"
    [ "$h1" = "$h2" ] && ok || bad "$flav: breath track held at 1 ($h1) != --control breath=1 ($h2)"
    [ "$h3" = "$h2" ] && ok || bad "$flav: --control breath=1 does not override the clip's ramp ($h3 vs $h2)"
    [ "$h4" = "$h0" ] && ok || bad "$flav: --rigs off with the track ($h4) != no track ($h0)"
    [ "$h5" != "$h1" ] && [ "$h5" != "$h0" ] && ok || bad "$flav: the ramp track gives the same state as a constant or no track"
    [ "$h6" = "$h1" ] && ok || bad "$flav: an unknown control's keys changed the run ($h6 vs $h1)"
    # the surface itself (OBJ of the last frame): track = held, and != no track
    for v in turn turn_breath held; do
        a="--clip $TMP/turn.clip"
        [ $v = turn_breath ] && a="--clip $TMP/turn_breath.clip"
        [ $v = held ] && a="$a --control breath=1"
        mkdir -p "$TMP/obj_${flav}_$v"
        # shellcheck disable=SC2086
        "$P" "$B" $a --frames 45 --obj-dir "$TMP/obj_${flav}_$v" --obj-frames 45 --quiet > /dev/null 2>&1 ||
            bad "$flav: OBJ run $v failed"
    done
    cmp -s "$TMP/obj_${flav}_turn_breath/frame_0045.obj" "$TMP/obj_${flav}_held/frame_0045.obj" && ok ||
        bad "$flav: surface with the track != surface with --control held"
    cmp -s "$TMP/obj_${flav}_turn/frame_0045.obj" "$TMP/obj_${flav}_turn_breath/frame_0045.obj" &&
        bad "$flav: surface with the breath track == surface without it" || ok
done
# how far breath 1 moved the surface after 45 steps (largest vertex distance)
d=$(paste -d' ' "$TMP/obj_float_turn/frame_0045.obj" "$TMP/obj_float_turn_breath/frame_0045.obj" 2>/dev/null |
    awk '$1 == "v" { dx = $2 - $6; dy = $3 - $7; dz = $4 - $8; e = sqrt(dx*dx + dy*dy + dz*dz); if (e > m) m = e } END { printf "%.4g", m }')
echo "  figure: cow, breath 1 vs no rig after 45 steps of a head turn (float): surface moved by up to $d mesh units"
awk -v d="$d" 'BEGIN { exit !(d != "" && d > 0.01) }' && ok || bad "breath 1 moved the surface by only '$d' mesh units"

# unknown control in a clip: a warning naming it and the blob's controls, exit 0
expect 0 "warning: .*turn_bogus.clip: control 'bogus' is not in .*controls: breath smile nostrils belly.*ignored" \
    "$PLAY" "$COW" --clip "$TMP/turn_bogus.clip" --frames 2 --quiet
# --control: unknown name, pose control, syntax
expect 1 "--control bogus=1: .* has no control 'bogus' \(controls: breath smile nostrils belly\)" "$PLAY" "$COW" --control bogus=1 --frames 1
expect 1 "'elbow_bend' is a pose control" "$PLAY" "$LIMB" --control elbow_bend=45 --frames 1
expect 2 "--control: want NAME=VALUE" "$PLAY" "$COW" --control breath
expect 2 "--control: want NAME=VALUE" "$PLAY" "$COW" --control =1
expect 2 "the value must be a decimal" "$PLAY" "$COW" --control breath=lots
expect 2 "the value must be a decimal" "$PLAY" "$COW" --control breath=1e3
expect 2 "the value must be a decimal" "$PLAY" "$COW" --control breath=40000
expect 2 "--rigs: want on or off" "$PLAY" "$COW" --rigs maybe
expect 2 "cannot go with --control" "$PLAY" "$COW" --rigs off --control breath=1
expect 2 "--rig-off-blob needs --compare-rigs" "$PLAY" "$COW" --rig-off-blob "$COW"
expect 2 "one at a time" "$PLAY" "$COW" --compare "$TMP/a.png" --compare-rigs "$TMP/b.png"
expect 0 "step: median" "$PLAY" "$COW" --rigs on --frames 1
# a clip keying a pose control: the bind fails, naming it
printf 'sinew-clip 1\nduration 1\ncontrol elbow_bend 0 45\n' > "$TMP/pose.clip"
expect 1 "does not fit .*clip control 'elbow_bend' is a pose control" "$PLAY" "$LIMB" --clip "$TMP/pose.clip"
# bad control lines: the parse error with its line
printf 'sinew-clip 1\nduration 1\n\ncontrol breath 0\n' > "$TMP/bad1.clip"
expect 1 "bad1.clip: line 4: usage: control <name> <time> <value>" "$PLAY" "$COW" --clip "$TMP/bad1.clip"
printf 'sinew-clip 1\nduration 1\ncontrol breath 0 1\ncontrol breath 0.5 deep\n' > "$TMP/bad2.clip"
expect 1 "bad2.clip: line 4: control value is not a number: 'deep'" "$PLAY" "$COW" --clip "$TMP/bad2.clip"
printf 'sinew-clip 1\nduration 1\ncontrol breath 0.5 1\ncontrol breath 0.5 0\n' > "$TMP/bad3.clip"
expect 1 "bad3.clip: line 4: key times of a channel must strictly increase" "$PLAY" "$COW" --clip "$TMP/bad3.clip"
printf 'sinew-clip 1\nduration 1\ncontrol breath 2 1\n' > "$TMP/bad4.clip"
expect 1 "bad4.clip: line 3: key time is after the clip duration" "$PLAYF" "$COWF" --clip "$TMP/bad4.clip"

# --stats-csv: one column per control; the track's values step by step
"$PLAY" "$COW" --clip "$TMP/turn_ramp.clip" --frames 60 --stats-csv "$TMP/ramp.csv" --quiet > /dev/null 2>&1
head -1 "$TMP/ramp.csv" | grep -q ',limit_clamps,ctl_breath,ctl_smile,ctl_nostrils,ctl_belly$' && ok ||
    bad "stats csv header: $(head -1 "$TMP/ramp.csv")"
# breath = -t up to 1 s, then -1 (the clip holds its end); smile, nostrils 0
awk -F, 'NR > 1 { w = $2 < 1 ? -$2 : -1; e = $8 - w; if (e < -1e-3 || e > 1e-3 || $9 != 0 || $10 != 0) bad = 1; n++ }
         END { exit !(n == 60 && !bad) }' "$TMP/ramp.csv" && ok || bad "stats csv control values: $(sed -n '31p;61p' "$TMP/ramp.csv")"
# the limb's pose control follows the elbow: ~90 degrees at the end of flex.clip
"$PLAY" "$LIMB" --clip tools/examples/limb/flex.clip --frames 120 --stats-csv "$TMP/limb.csv" \
    --plot "$TMP/limb_plot.png" --quiet > /dev/null 2>&1
head -1 "$TMP/limb.csv" | grep -q ',ctl_elbow_bend$' && ok || bad "limb csv header: $(head -1 "$TMP/limb.csv")"
tail -1 "$TMP/limb.csv" | awk -F, '{ exit !($8 > 89.9 && $8 < 90.1) }' && ok || bad "limb elbow_bend at the end: $(tail -1 "$TMP/limb.csv")"
sed -n 31p "$TMP/limb.csv" | awk -F, '{ exit !($8 > 44.5 && $8 < 45.5) }' && ok || bad "limb elbow_bend at 0.5 s (want 45): $(sed -n 31p "$TMP/limb.csv")"
[ -s "$TMP/limb_plot.png" ] && ok || bad "--plot with controls wrote nothing"

# --compare-rigs: same blob (abstract controls 0), and a blob baked without rigs
expect 0 "wrote $TMP/cmp.png" "$PLAY" "$COW" --clip "$TMP/turn_breath.clip" --frames 10 --compare-rigs "$TMP/cmp.png" --heat 0.1 --size 320x240
[ -s "$TMP/cmp.png" ] && ok || bad "--compare-rigs wrote nothing"
sed -e '/^[[:space:]]*rig[[:space:]]/d' -e "s|^mesh .*|mesh $PWD/tools/examples/limb/limb.obj|" tools/examples/limb/limb.sinew > "$TMP/limb.sinew"
if "$BAKE" "$TMP/limb.sinew" -o "$TMP/limb_norig.blob" --quiet; then
    expect 0 "wrote $TMP/cmp_limb.png" "$PLAY" "$LIMB" --clip tools/examples/limb/flex.clip --frames 20 \
        --compare-rigs "$TMP/cmp_limb.png" --rig-off-blob "$TMP/limb_norig.blob" --size 320x240
    # without --rig-off-blob the pose rig stays on: a note says so
    expect 0 "note: .*pose controls \(elbow_bend\) stay on" "$PLAY" "$LIMB" --frames 2 --compare-rigs "$TMP/cmp2.png" --size 320x240
    # the rig-free limb differs from the limb with its biceps once the elbow bends
    a=$(hash "$PLAY" "$LIMB" --clip tools/examples/limb/flex.clip --frames 60)
    b=$(hash "$PLAY" "$TMP/limb_norig.blob" --clip tools/examples/limb/flex.clip --frames 60)
    [ -n "$a" ] && [ "$a" != "$b" ] && ok || bad "limb with and without the biceps rig: same state ($a, $b)"
else
    bad "cannot bake the limb without its rig lines"
fi
expect 1 "is not .* without its rigs" "$PLAY" "$COW" --frames 1 --compare-rigs "$TMP/x.png" --rig-off-blob "$LIMB"

# clip impulses and --compare-hits (issue 14): the hit changes the state, the no-hit panel's instance does not
expect 0 "wrote $TMP/hit.png" "$PLAY" "$COW" --clip tools/examples/cow/hit_global.clip --frames 9 --compare-hits "$TMP/hit.png" --heat 0.1 --size 320x240
[ -s "$TMP/hit.png" ] && ok || bad "--compare-hits wrote nothing"
expect 2 "needs a --clip" "$PLAY" "$COW" --frames 2 --compare-hits "$TMP/x.png"
expect 2 "one at a time" "$PLAY" "$COW" --clip tools/examples/cow/hit_local.clip --compare "$TMP/a.png" --compare-hits "$TMP/b.png"
printf 'sinew-clip 1\nduration 1\nimpulse 0.05 1000 0 0 25\n' > "$TMP/hit_only.clip"
printf 'sinew-clip 1\nduration 1\n' > "$TMP/nohit.clip"
a=$(hash "$PLAY" "$COW" --clip "$TMP/hit_only.clip" --frames 10)
b=$(hash "$PLAY" "$COW" --clip "$TMP/nohit.clip" --frames 10)
[ -n "$a" ] && [ "$a" != "$b" ] && ok || bad "a clip impulse changes the state ($a, $b)"
printf 'sinew-clip 1\nduration 1\nimpulse 0.05 1000 0 0 25 9\n' > "$TMP/badprof.clip"
expect 1 "profile 9 is not in the blob" "$PLAY" "$COW" --clip "$TMP/badprof.clip" --frames 2

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
