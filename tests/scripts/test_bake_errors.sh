#!/bin/sh
# Bad inputs to sinew-bake: each must fail with a clear message (file:line for
# description mistakes), a non-zero exit and no output file (nor a temp file).
BUILD=${BUILD:-build}
BAKE=$BUILD/sinew-bake
pass=0; fail=0
[ -x "$BAKE" ] || { echo "FAIL: $BAKE not built"; echo "0 passed, 1 failed"; exit 1; }
T=$(mktemp -d "${TMPDIR:-/tmp}/sinew_bake_err.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT
sh tools/examples/make_box.sh -1 -1 -1 5 1 1 6 2 2 > "$T/box.obj"
base() {   # a valid description: a 6x2x2 box with a two-bone chain
    cat <<EOT
mesh box.obj
unit 0.1
cell 1
joint a - 0 0 0
joint b a 2 0 0
joint c b 4 0 0
material flesh 1e5 0.3 1000
EOT
}
# expect NAME MESSAGE_REGEX DESCRIPTION_FILE
expect() {
    name=$1; msg=$2; desc=$3
    rm -f "$T/out.blob" "$T/out.blob.tmp" "$T/out.c"
    "$BAKE" "$desc" -o "$T/out.blob" --c-array "$T/out.c" > "$T/stdout" 2> "$T/stderr"
    rc=$?
    if [ "$rc" -eq 0 ]; then
        echo "FAIL $name: exit status 0"; fail=$((fail + 1))
    elif ! grep -Eq "$msg" "$T/stderr"; then
        echo "FAIL $name: message does not match /$msg/:"; sed 's/^/    /' "$T/stderr"; fail=$((fail + 1))
    elif [ -e "$T/out.blob" ] || [ -e "$T/out.blob.tmp" ] || [ -e "$T/out.c" ] || [ -e "$T/out.c.tmp" ]; then
        echo "FAIL $name: an output file was left behind"; fail=$((fail + 1))
    else
        echo "ok   $name: $(head -n 1 "$T/stderr")"; pass=$((pass + 1))
    fi
}
# the valid base bakes (so the failures below are caused by the edits)
base > "$T/ok.sinew"
if "$BAKE" "$T/ok.sinew" -o "$T/ok.blob" --quiet && [ -s "$T/ok.blob" ]; then echo "ok   base description bakes"; pass=$((pass + 1)); else echo "FAIL base description"; fail=$((fail + 1)); fi

# --- description mistakes: file:line ---
{ base; echo "wobble 3"; } > "$T/d1.sinew";                        expect unknown-keyword "d1.sinew:8: unknown keyword 'wobble'" "$T/d1.sinew"
{ base; echo "timestep"; } > "$T/d2.sinew";                        expect missing-value "d2.sinew:8: missing value" "$T/d2.sinew"
{ base; echo "gravity 0 -9.81"; } > "$T/d3.sinew";                 expect missing-value-3 "d3.sinew:8: missing value" "$T/d3.sinew"
{ base; echo "material soft nan 0.3 1000"; } > "$T/d4.sinew";      expect nan "d4.sinew:8: 'nan' is not a finite number" "$T/d4.sinew"
{ base; echo "rayleigh inf 0"; } > "$T/d5.sinew";                  expect inf "d5.sinew:8: 'inf' is not a finite number" "$T/d5.sinew"
{ base; echo "timestep 0.01x"; } > "$T/d6.sinew";                  expect not-a-number "d6.sinew:8: '0.01x' is not a number" "$T/d6.sinew"
{ base; echo "material soft 0 0.3 1000"; } > "$T/d7.sinew";        expect E-zero "d7.sinew:8: Young's modulus E must be positive" "$T/d7.sinew"
{ base; echo "material soft -5 0.3 1000"; } > "$T/d8.sinew";       expect E-negative "d8.sinew:8: Young's modulus E must be positive" "$T/d8.sinew"
{ base; echo "material soft 1e5 0.3 0"; } > "$T/d9.sinew";         expect density-zero "d9.sinew:8: density must be positive" "$T/d9.sinew"
{ base; echo "material soft 1e5 0.5 1000"; } > "$T/d10.sinew";     expect nu-half "d10.sinew:8: Poisson ratio must be in \(-1, 0.5\)" "$T/d10.sinew"
{ base; echo "material soft 1e5 0.7 1000"; } > "$T/d11.sinew";     expect nu-large "d11.sinew:8: Poisson ratio" "$T/d11.sinew"
{ base; echo "material soft 1e5 -1 1000"; } > "$T/d12.sinew";      expect nu-minus-one "d12.sinew:8: Poisson ratio" "$T/d12.sinew"
{ base; echo "region box 0 0 0 1 1 1 rubber"; } > "$T/d13.sinew";  expect unknown-material "d13.sinew:8: unknown material 'rubber'" "$T/d13.sinew"
{ base; echo "joint d zz 1 0 0"; } > "$T/d14.sinew";               expect unknown-parent "d14.sinew:8: joint 'd': unknown parent 'zz'" "$T/d14.sinew"
{ base; echo "cell -1"; } > "$T/d15.sinew";                        expect cell-negative "d15.sinew:8: cell size must be positive" "$T/d15.sinew"
{ base; echo "iterations 8 300"; } > "$T/d16.sinew";               expect iterations "d16.sinew:8: '300' must be an integer in 1..256" "$T/d16.sinew"
base | sed 's/^joint c b 4 0 0/joint c b 9 0 0/' > "$T/d17.sinew"; expect joint-outside "d17.sinew:6: joint 'c' at \(9, 0, 0\) is 4 outside; nearest surface point \(5, 0, 0\): move it inside, e.g. to \(4.75, 0, 0\)" "$T/d17.sinew"
# every joint outside is listed, each with its line and a point inside
base | sed -e 's/^joint b a 2 0 0/joint b a 2 3 0/' -e 's/^joint c b 4 0 0/joint c b 4 0 -2.5/' > "$T/d18.sinew"
expect joints-outside-all "2 joint\(s\) outside the mesh" "$T/d18.sinew"
grep -q "d18.sinew:5: joint 'b' at (2, 3, 0) is 2 outside" "$T/stderr" && grep -q "d18.sinew:6: joint 'c' at (4, 0, -2.5) is 1.5 outside" "$T/stderr" \
    && { echo "ok   joints-outside-all: both joints named with their line"; pass=$((pass + 1)); } || { echo "FAIL joints-outside-all: not every joint listed"; sed 's/^/    /' "$T/stderr"; fail=$((fail + 1)); }
base | sed 's/^joint a - 0 0 0/joint a b 0 0 0/' > "$T/d20.sinew"; expect no-root "want exactly one root joint" "$T/d20.sinew"
base | sed '/^mesh/d' > "$T/d21.sinew";                            expect no-mesh "missing 'mesh PATH'" "$T/d21.sinew"
base | sed 's/^mesh box.obj/mesh nothere.obj/' > "$T/d22.sinew";   expect mesh-missing "nothere.obj: cannot open mesh" "$T/d22.sinew"
{ base; echo "twist 4e5 0.5"; } > "$T/d23.sinew";                  expect twist-retired "d23.sinew:8: 'twist' is retired: bones now have volume.*'bone JOINT R' or 'bone_radius R'" "$T/d23.sinew"
{ base; echo "bone zz 1"; } > "$T/d24.sinew";                      expect bone-unknown "d24.sinew:8: unknown joint 'zz'" "$T/d24.sinew"
{ base; echo "bone a 1"; } > "$T/d25.sinew";                       expect bone-root "d25.sinew:8: 'a' is the root" "$T/d25.sinew"
{ base; echo "bone b -0.5"; } > "$T/d26.sinew";                    expect bone-negative "d26.sinew:8: bone radius must be >= 0" "$T/d26.sinew"
{ base; echo "bone_radius x"; } > "$T/d27.sinew";                  expect bone-radius-nan "d27.sinew:8: 'x' is not a number" "$T/d27.sinew"
{ base; echo "limit all -1"; } > "$T/d28.sinew";                   expect limit-negative "d28.sinew:8: limit distance must be >= 0" "$T/d28.sinew"
{ base; echo "limit ball 1"; } > "$T/d29.sinew";                   expect limit-region "d29.sinew:8: unknown region 'ball'" "$T/d29.sinew"
{ base; echo "rest_shape flat"; } > "$T/d30.sinew";                expect rest-shape "d30.sinew:8: unknown rest shape 'flat' \(want modelled or sag\)" "$T/d30.sinew"
{ base; echo "bone_radius 9"; } > "$T/d31.sinew";                  expect all-skeleton "no free vertices: the bones .* hold every lattice vertex" "$T/d31.sinew"

# --- what the old construction refused now bakes (undistorted lattice, nearest bone wins) ---
# expect_ok NAME DESCRIPTION_FILE
expect_ok() {
    rm -f "$T/out.blob"
    if "$BAKE" "$2" -o "$T/out.blob" --check --quiet > "$T/stdout" 2> "$T/stderr" && [ -s "$T/out.blob" ] && grep -q ": ok$" "$T/stdout"; then
        echo "ok   $1: bakes and passes --check"; pass=$((pass + 1))
    else
        echo "FAIL $1:"; sed 's/^/    /' "$T/stdout" "$T/stderr"; fail=$((fail + 1))
    fi
}
base | sed 's/^joint c b 4 0 0/joint c b 2.3 0 0/' > "$T/k1.sinew"; expect_ok short-bone "$T/k1.sinew"
base | sed 's/^joint c b 4 0 0/joint c a 3 0 0.4/' > "$T/k2.sinew"; expect_ok bones-share-vertex "$T/k2.sinew"
# two bones whose snapped chains crossed inside one cell (the old construction inverted it)
base | sed -e 's/^joint b a 2 0 0/joint b a 2.4 0.45 0/' -e 's/^joint c b 4 0 0/joint c a 0 0.9 0\njoint d c 2.6 0.55 0/' > "$T/k3.sinew"
expect_ok crossing-bones "$T/k3.sinew"
base | sed 's/^joint c b 4 0 0/joint c b 2.05 0.02 0.01/' > "$T/k4.sinew"; expect_ok joints-in-one-cell "$T/k4.sinew"
expect no-description "cannot open description" "$T/nothere.sinew"

# --- mesh problems ---
base | sed 's/^mesh box.obj/mesh bad.obj/' > "$T/m.sinew"
{ cat "$T/box.obj"; echo "v 1.0 2.0"; } > "$T/bad.obj";                     expect obj-short-vertex "bad.obj:[0-9]+: malformed vertex" "$T/m.sinew"
{ cat "$T/box.obj"; echo "f 1 2 x"; } > "$T/bad.obj";                       expect obj-bad-index "bad.obj:[0-9]+: malformed face" "$T/m.sinew"
{ cat "$T/box.obj"; echo "f 1 2 9999"; } > "$T/bad.obj";                    expect obj-index-range "bad.obj:[0-9]+: malformed face: bad or out-of-range vertex index '9999'" "$T/m.sinew"
{ cat "$T/box.obj"; echo "v 1 nan 2"; } > "$T/bad.obj";                     expect obj-nan "bad.obj:[0-9]+: malformed vertex coordinate 'nan'" "$T/m.sinew"
{ cat "$T/box.obj"; echo "v 1 inf 2"; } > "$T/bad.obj";                     expect obj-inf "bad.obj:[0-9]+: malformed vertex coordinate 'inf'" "$T/m.sinew"
# absurd coordinates (issue 16 item 7): |x| > 1e9 refused with file:line; 1e308 used to reach (int)floor(NaN)
{ cat "$T/box.obj"; echo "v 1e308 0 0"; } > "$T/bad.obj";                   expect obj-1e308 "bad.obj:172: vertex coordinate '1e308' is out of range: \|coordinate\| must be at most 1e\+09" "$T/m.sinew"
# absurd description numbers (issue 16 item 7): refused at their line, before any int conversion
{ base | sed 's/^cell 1$/cell 1e-300/'; } > "$T/n1.sinew";          expect cell-tiny "cell size 1e-300 .*gives a grid of" "$T/n1.sinew"
{ base; echo "origin 1e300 0 0"; } > "$T/n2.sinew";                  expect origin-far "n2.sinew:8: '1e300' is beyond 1e\+09 mesh units" "$T/n2.sinew"
{ base; echo "bone b 1e300"; } > "$T/n3.sinew";                      expect bone-huge "n3.sinew:8: '1e300' is beyond 1e\+09 mesh units" "$T/n3.sinew"
{ base; echo "limit all 1e300"; } > "$T/n4.sinew";                   expect limit-huge "n4.sinew:8: '1e300' is beyond 1e\+09 mesh units" "$T/n4.sinew"
{ base; echo "timestep 1e-7"; } > "$T/n5.sinew";                     expect h-tiny "n5.sinew:8: timestep must be in \[1/65536, 1\] seconds" "$T/n5.sinew"
{ base | sed 's/^unit 0.1$/unit 1e300/'; } > "$T/n6.sinew";          expect unit-huge "n6.sinew:2: unit \(metres per mesh unit\) must be in" "$T/n6.sinew"
{ base; echo "gravity 0 -1e300 0"; } > "$T/n7.sinew";                expect g-huge "n7.sinew:8: gravity component '-1e300' is beyond 1e4" "$T/n7.sinew"
{ base; echo "region box -1e300 0 0 1 1 1 flesh"; } > "$T/n8.sinew"; expect region-far "n8.sinew:8: '-1e300' is beyond 1e\+09 mesh units" "$T/n8.sinew"
{ base; echo "control x"; echo "rig r x bump 0.1  2 0 0 0.5  tau 0 0 20000 1"; } > "$T/n9.sinew"; expect tau-far "n9.sinew:9: tau gamma 20000 out of range \(\|gamma\| <= 16384\)" "$T/n9.sinew"
{ base; echo "control x"; echo "rig r x bump 0.1  2 0 0 1e300"; } > "$T/n10.sinew"; expect rig-radius-huge "n10.sinew:9: '1e300' is beyond 1e\+09 mesh units" "$T/n10.sinew"
# segment meshes (seed 004 ch. 3-4; DESCRIPTION.md "Segment meshes")
{ base; echo "chain t nodes 1 from 5 0 0 to 7 0 0"; } > "$T/s1.sinew"; expect chain-one-node "s1.sinew:8: '1' must be an integer in 2..256" "$T/s1.sinew"
{ base; echo "sheet s side 6 corner 0 1 -1 u 2 0 0 v 0 0 2"; } > "$T/s2.sinew"; expect sheet-side "s2.sinew:8: sheet side 6 is not 2\^n \+ 1" "$T/s2.sinew"
{ base; echo "sheet s side 3 corner 0 1 -1 u 2 0 0 v 0 0 2 levels 3"; } > "$T/s3.sinew"; expect sheet-levels "s3.sinew:8: sheet 's': 3 levels, at most 2 for side 3" "$T/s3.sinew"
{ base; echo "sheet s side 9 corner 0 1 -1 u 2 0 0 v 0 0 2 shares 0.5 0.4"; } > "$T/s4.sinew"; expect sheet-shares "s4.sinew:8: sheet 's': shares sum to 0.9, want 1" "$T/s4.sinew"
{ base; echo "sheet s side 5 corner 0 1 -1 u 2 0 0 v 0 0 3"; } > "$T/s5.sinew"; expect sheet-not-square "s5.sinew:8: sheet 's': edges u and v have lengths 2 and 3" "$T/s5.sinew"
{ base; echo "attach cape first surface"; } > "$T/s6.sinew"; expect attach-unknown "s6.sinew:8: unknown segment mesh 'cape'" "$T/s6.sinew"
{ base; echo "chain t nodes 3 from 2 0 0 to 2 0 -3"; echo "attach t first surface"; } > "$T/s7.sinew"; expect attach-far "s7.sinew:9: chain 't' node 0 at \(2, 0, 0\) is 1 from the nearest surface vertex [0-9]+ at \(2, -1, 0\), more than 0.75 \(half a segment\)" "$T/s7.sinew"
{ base; echo "chain t nodes 3 from 5 0 0 to 7 0 0 gamma 0"; } > "$T/s8.sinew"; expect chain-gamma "s8.sinew:8: gamma \(translation factor\) must be in \(0, 1\]" "$T/s8.sinew"
{ base; echo "chain t nodes 2 from 5 0 0 to 5 0 1000"; } > "$T/s9.sinew"; expect chain-far "s9.sinew:8: chain 't' node 1 lies 1000 mesh units from the root joint" "$T/s9.sinew"
{ base; echo "chain t nodes 2 from 5 0 0 to 7 0 0 mass 1e6"; } > "$T/s10.sinew"; expect chain-mass "s10.sinew:8: chain 't': segment mass 1e\+06 kg is out of range" "$T/s10.sinew"
{ base; echo "chain t nodes 3 from 5 0 0 to 7 0 0"; echo "attach t first joint zz"; } > "$T/s11.sinew"; expect attach-joint "s11.sinew:9: unknown joint 'zz'" "$T/s11.sinew"
{ base; echo "sheet s side 3 corner 0 1 -1 u 2 0 0 v 0 0 2"; echo "attach s corners surface"; echo "attach s node 0 joint a"; } > "$T/s12.sinew"; expect attach-twice "s12.sinew:10: sheet 's': node 0 is already attached \(line 9\)" "$T/s12.sinew"
{ base; echo "chain t nodes 3 from 5 0 0 to 7 0 0 wobble 1"; } > "$T/s13.sinew"; expect chain-option "s13.sinew:8: unknown chain option 'wobble'" "$T/s13.sinew"
{ cat "$T/box.obj"; echo "v 0 -1.5e9 0"; } > "$T/bad.obj";                  expect obj-minus-1.5e9 "bad.obj:172: vertex coordinate '-1.5e9' is out of range" "$T/m.sinew"
# a mesh wider than 32768 mesh units can never bake (a blob holds positions within 16384 of the root)
awk '$1 == "v" && $2 > 0 { $2 = 40000 } { print }' "$T/box.obj" > "$T/bad.obj"; expect obj-extent "bad.obj:[0-9]+: vertex at x = 40000 is 40001 mesh units from the vertex at line [0-9]+ \(x = -1\): a mesh may span at most 32768" "$T/m.sinew"
{ cat "$T/box.obj"; echo "bogus 1 2 3"; } > "$T/bad.obj";                   expect obj-statement "bad.obj:[0-9]+: malformed OBJ: unsupported statement 'bogus'" "$T/m.sinew"
grep -v '^f' "$T/box.obj" > "$T/bad.obj"; grep '^f' "$T/box.obj" | sed 1d >> "$T/bad.obj"; expect mesh-open "bad.obj: mesh is not closed" "$T/m.sinew"
grep -v '^f' "$T/box.obj" > "$T/bad.obj"; grep '^f' "$T/box.obj" | awk '{ print $1, $2, $4, $3 }' >> "$T/bad.obj"; expect mesh-inside-out "bad.obj: mesh encloses a non-positive volume" "$T/m.sinew"

# a valid chain and sheet bake
{ base; echo "chain t nodes 5 from 5 0 0 to 7 0 0"; echo "attach t first surface"; echo "sheet s side 5 corner 0 1 -1 u 2 0 0 v 0 0 2 shares 0.5 0.25 0.25"; echo "attach s row 0 surface within 0.5"; echo "attach s node 24 joint c"; } > "$T/s0.sinew"
expect_ok segments "$T/s0.sinew"

# --- command line ---
"$BAKE" --help > "$T/help" 2>&1 && grep -q "usage: sinew-bake" "$T/help" && { echo "ok   --help"; pass=$((pass + 1)); } || { echo "FAIL --help"; fail=$((fail + 1)); }
"$BAKE" "$T/ok.sinew" > /dev/null 2>&1 && { echo "FAIL missing -o accepted"; fail=$((fail + 1)); } || { echo "ok   missing -o rejected"; pass=$((pass + 1)); }
"$BAKE" "$T/ok.sinew" -o "$T/x.blob" --flavour half > /dev/null 2>&1 || [ -e "$T/x.blob" ] && { echo "FAIL bad flavour"; fail=$((fail + 1)); } || { echo "ok   bad flavour rejected"; pass=$((pass + 1)); }
"$BAKE" "$T/ok.sinew" -o "$T/x.blob" --c-array "$T/x.c" --name "9bad" > /dev/null 2>&1; rc=$?
if [ $rc -ne 0 ] && [ ! -e "$T/x.blob" ] && [ ! -e "$T/x.c" ]; then echo "ok   bad C symbol rejected, no output"; pass=$((pass + 1)); else echo "FAIL bad C symbol"; fail=$((fail + 1)); fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
