#!/bin/sh
# sinew-rig retarget command line (seed 003 §4.4, tools/sb_retarget_cli.c): --help,
# usage errors, progress lines and summary, the cow's smile on Spot written
# twice as the same bytes (rig file and picture), and refusals (a joint of A
# missing in B, an unknown rig, a bad option value) that exit non-zero and
# write nothing.
BUILD=${BUILD:-build}
RIG=$BUILD/sinew-rig
. tests/scripts/cli_lib.sh
[ -x "$RIG" ] || { echo "FAIL: $RIG not built"; echo "0 passed, 1 failed"; exit 1; }
T=$(mktemp -d "${TMPDIR:-/tmp}/sinew_retarget_cli.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
COW=tools/examples/cow/cow.sinew
SPOT=tools/examples/spot/spot.sinew

"$RIG" retarget --help > "$T/help" 2>&1 && grep -q "usage: sinew-rig retarget" "$T/help" && ok "--help" || bad "--help"
"$RIG" retarget "$COW" > /dev/null 2>&1; [ $? -eq 2 ] && ok "missing arguments: exit 2" || bad "missing arguments"
"$RIG" retarget "$COW" "$SPOT" --rig smile_l -o "$T/x.rig" --w-surf -3 > /dev/null 2>&1; [ $? -eq 2 ] && [ ! -e "$T/x.rig" ] && ok "bad --w-surf: exit 2, nothing written" || bad "bad --w-surf"

"$RIG" retarget "$COW" "$SPOT" --rig smile_l,smile_r --name smile --w-surf 1000 -o "$T/a.rig" --png "$T/a.png" > "$T/a.out" 2>&1 && ok "cow smile -> spot" || { bad "cow smile -> spot"; cat "$T/a.out"; }
grep -q "^retarget: round  1 cost" "$T/a.out" && ok "progress lines (round, cost, |grad|)" || bad "progress lines"
grep -q "^retarget: residuals" "$T/a.out" && grep -q "^retarget: transfer:" "$T/a.out" && ok "summary (residuals, transfer)" || bad "summary"
grep "^retarget: \(map\|residuals\|transfer\|the rig moves\)" "$T/a.out" | sed 's/^/  figure: /'
grep -q "^sinew-rig 1$" "$T/a.rig" && grep -q "^end$" "$T/a.rig" && grep -q "rig_file smile FILE smile" "$T/a.rig" && ok "rig file (sinew-rig 1) with its rig_file line" || bad "rig file"
"$RIG" retarget "$COW" "$SPOT" --rig smile_l,smile_r --name smile --w-surf 1000 -o "$T/b.rig" --png "$T/b.png" --quiet > "$T/b.out" 2>&1
[ ! -s "$T/b.out" ] && ok "--quiet prints nothing" || bad "--quiet printed: $(head -c 200 "$T/b.out")"
cmp -s "$T/a.rig" "$T/b.rig" && cmp -s "$T/a.png" "$T/b.png" && ok "two runs write the same bytes (rig and picture)" || bad "two runs differ"
cmp -s "$T/a.rig" tools/examples/spot/spot_smile.rig && ok "tools/examples/spot/spot_smile.rig is this run's output" ||
    bad "tools/examples/spot/spot_smile.rig differs from a fresh run (regenerate: tools/examples/spot/SOURCE.md)"
# the baked rig (rig_file) in the reference model's static solve moves Spot as the transfer says
want=$(sed -n 's/^retarget: the rig moves the surface by up to .* on A .*, \([0-9.e+-]*\) on B.*/\1/p' "$T/a.out")
"$BUILD/sinew-bake" "$SPOT" --static rest --controls smile=1 -o "$T/st.obj" > "$T/st.out" 2>&1
got=$(sed -n 's/^static: rigs move the surface by up to \([0-9.e+-]*\) mesh units.*/\1/p' "$T/st.out")
echo "  figure: Spot's surface moved by the retargeted smile: $want (transfer), $got (sinew-bake --static, the baked rig file)"
[ -n "$want" ] && [ -n "$got" ] && awk -v a="$want" -v b="$got" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 1e-3 * a) }' &&
    ok "Spot bakes with the rig file; --static moves it as the transfer did (within 0.1%)" || { bad "spot --static with the retargeted rig"; cat "$T/st.out"; }

# B without the tail tip: A's joint tail_tip is missing
mkdir -p "$T/s"; cp tools/examples/spot/spot.obj tools/examples/spot/spot_smile.rig "$T/s/"
grep -v "^joint tail_tip" "$SPOT" > "$T/s/spot.sinew"
"$RIG" retarget "$COW" "$T/s/spot.sinew" --rig smile_l -o "$T/m.rig" > "$T/m.out" 2>&1; rc=$?
[ $rc -ne 0 ] && grep -q "tail_tip" "$T/m.out" && [ ! -e "$T/m.rig" ] && ok "a joint missing in B is named, exit $rc, nothing written" || { bad "missing joint"; cat "$T/m.out"; }
grep "error" "$T/m.out" | sed 's/^/  message: /'
"$RIG" retarget "$COW" "$SPOT" --rig grin -o "$T/g.rig" > "$T/g.out" 2>&1; rc=$?
[ $rc -ne 0 ] && grep -q "grin" "$T/g.out" && [ ! -e "$T/g.rig" ] && ok "an unknown rig is named, nothing written" || { bad "unknown rig"; cat "$T/g.out"; }

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
