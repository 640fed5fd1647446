#!/bin/sh
# Lattice robustness sweep: every character bakes at 10 cell sizes from H/40
# to H/6 (geometric steps; H = the character's height) and passes
# sinew-bake --check: interior volume within 1% of the mesh volume (= mass
# within 1% at uniform density), surface embedding error <= 1e-5 of the bbox
# diagonal, rigid translations and rotations in the null space of the elastic
# stiffness. Columns: lattice counts, "mass ratio" = interior volume / mesh
# volume (= mass / rho V at one density), embedding error / bbox diagonal, bake
# time (CPU). Characters: cow (H = y extent), limb (a limb lying along x:
# H = its length), diag (bones at 30/45/60 degrees, H = y extent) and the
# beast (humanoid, H = y extent) when tools/examples/beast/beast.sinew exists.
BUILD=${BUILD:-build}
BAKE=$BUILD/sinew-bake
pass=0; fail=0
[ -x "$BAKE" ] || { echo "FAIL: $BAKE not built"; echo "0 passed, 1 failed"; exit 1; }
T=$(mktemp -d "${TMPDIR:-/tmp}/sinew_bake_sweep.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT

# extent of an OBJ along axis 1 (x), 2 (y) or 3 (z)
extent() { awk -v a="$2" '$1 == "v" { v = $(a + 1) + 0; if (n++ == 0 || v < lo) lo = v; if (n == 1 || v > hi) hi = v } END { printf "%.9g", hi - lo }' "$1"; }

printf '%-6s %9s %8s %8s %8s %7s %10s %10s %7s  %s\n' char cell vertices free skeleton cells "mass ratio" embedding time result
sweep() {   # NAME DESCRIPTION AXIS
    name=$1; desc=$2; axis=$3
    dir=$(cd "$(dirname "$desc")" && pwd)
    mesh=$(awk '$1 == "mesh" { print $2; exit }' "$desc")
    case "$mesh" in /*) ;; *) mesh="$dir/$mesh" ;; esac
    H=$(extent "$mesh" "$axis")
    i=0
    while [ $i -lt 10 ]; do
        c=$(awk -v H="$H" -v i=$i 'BEGIN { printf "%.4g", H / 40 * exp(log(40 / 6) * i / 9) }')
        sed -e "s|^mesh .*|mesh $mesh|" -e "s|^cell .*|cell $c|" "$desc" > "$T/s.sinew"
        if "$BAKE" "$T/s.sinew" --check --quiet > "$T/out" 2> "$T/err" && grep -q ": ok$" "$T/out"; then
            res=ok; pass=$((pass + 1))
        else
            res=FAIL; fail=$((fail + 1))
        fi
        line=$(grep "^check:" "$T/out")
        if [ -n "$line" ]; then
            echo "$line" | sed -E 's/^check: cell ([^:]*): lattice ([0-9]+) vertices \(([0-9]+) free, ([0-9]+) skeleton\), ([0-9]+) cells; volume ratio ([0-9.]+); embedding ([0-9.e+-]+); .*; ([0-9.]+) s: .*$/\1 \2 \3 \4 \5 \6 \7 \8/' |
                { read -r cc nv nf ns nc vr emb tm; printf '%-6s %9s %8s %8s %8s %7s %10s %10s %6ss  %s\n' "$name" "$cc" "$nv" "$nf" "$ns" "$nc" "$vr" "$emb" "$tm" "$res"; }
        else
            printf '%-6s %9s  %s\n' "$name" "$c" "FAIL: $(grep -m1 error "$T/err")"
        fi
        if [ "$res" = FAIL ]; then sed 's/^/    | /' "$T/err" | head -n 8; fi
        i=$((i + 1))
    done
}
sweep cow tools/examples/cow/cow.sinew 2
sweep limb tools/examples/limb/limb.sinew 1
sweep diag tools/examples/diag/diag.sinew 2
if [ -f tools/examples/beast/beast.sinew ]; then
    sweep beast tools/examples/beast/beast.sinew 2
else
    echo "note: tools/examples/beast/beast.sinew is absent: the beast is not swept"
fi
echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
