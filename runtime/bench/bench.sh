#!/bin/sh
# make bench (runtime part): step time, memory, callgrind instructions per
# step, per stage and per block multiply-add, for the cow, the cow without its
# segment meshes (cow_fem: the model issue 15's goals were set on, before the
# tail and the blanket) and the beast (humanoid), fixed and float; the herd;
# then the issue 15 figure table (every asset), with the Cortex-M4 figures
# of `make bench-baremetal` (run before this by `make bench`) where its log
# exists.
# Never fails on speed; a missing valgrind is reported, not fatal.
BUILD=${1:-build}
STEPS=${BENCH_STEPS:-20}
ASSETS=${BENCH_ASSETS:-cow cow_fem beast}
tmp=$(mktemp -d /tmp/sn_bench.XXXXXX) || exit 1
trap 'rm -rf "$tmp"' EXIT INT TERM
rc=0
for a in $ASSETS; do
echo "== runtime bench: $a, default CG iterations ($(uname -m), ${CC:-cc}, SIMD=${SIMD:-auto})"
dir=$BUILD/examples
if [ "$a" = cow_fem ]; then # baked here: cow.sinew without its chain, sheet and attach lines
    dir=$tmp
    grep -v -E '^(chain|sheet|attach) ' tools/examples/cow/cow.sinew | sed "s#^mesh #mesh $(pwd)/tools/examples/cow/#" > "$tmp/cow_fem.sinew"
    "$BUILD/sinew-bake" "$tmp/cow_fem.sinew" -o "$tmp/cow_fem.blob" --quiet &&
        "$BUILD/sinew-bake" "$tmp/cow_fem.sinew" -o "$tmp/cow_fem_float.blob" --flavour float --quiet || rc=1
fi
for flav in fixed float; do
    if [ $flav = fixed ]; then bin=$BUILD/bench/sn_bench; blob=$dir/$a.blob
    else bin=$BUILD/bench/sn_bench_float; blob=$dir/${a}_float.blob; fi
    [ -f "$blob" ] || { echo "SKIPPED: $blob missing"; continue; }
    "$bin" "$blob" > "$tmp/out" || rc=1
    grep -v '^  macs:' "$tmp/out"
    macs=$(sed -n 's/^  macs: //p' "$tmp/out")
    sed -n "s/^  figure: $flav step time: median \([0-9.]*\) us.*/\1/p" "$tmp/out" > "$tmp/t_${a}_$flav"
    sed -n 's/^  blob .*: \([0-9]*\) B blob, \([0-9]*\) B instance.*/\1 \2/p' "$tmp/out" > "$tmp/m_${a}_$flav"
    sed -n 's/^  figure: .* memory: .* or \([0-9]*\) B persistent state + a \([0-9]*\) B workspace.*/\1 \2/p' "$tmp/out" > "$tmp/w_${a}_$flav"
    if command -v valgrind > /dev/null 2>&1; then
        for n in 0 "$STEPS"; do
            valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$n" "$bin" --steps "$n" "$blob" \
                > /dev/null 2> "$tmp/vg.$n" || { rc=1; cat "$tmp/vg.$n"; }
        done
        i0=$(sed -n 's/^totals: *\([0-9]*\).*/\1/p' "$tmp/cg.0")
        i1=$(sed -n 's/^totals: *\([0-9]*\).*/\1/p' "$tmp/cg.$STEPS")
        awk -v a="$i0" -v b="$i1" -v n="$STEPS" -v m="$macs" -v f="$flav" 'BEGIN {
            per = (b - a) / n
            printf "  figure: %s callgrind: %.0f instructions per step ((%d-step run - 0-step run) / %d), %.1f per block multiply-add\n", f, per, n, n, per / m }' \
            | tee "$tmp/cgline"
        sed -n 's/.*callgrind: \([0-9]*\) instructions per step.*/\1/p' "$tmp/cgline" > "$tmp/c_${a}_$flav"
        if command -v callgrind_annotate > /dev/null 2>&1; then # per stage, inclusive (issue 15 item 6)
            for n in 0 "$STEPS"; do
                callgrind_annotate --inclusive=yes --threshold=100 "$tmp/cg.$n" 2> /dev/null | grep ' \[' > "$tmp/ann.$n"
            done
            printf '  figure: %s callgrind per step by stage (inclusive):' "$flav"
            for fn in sn_skeleton sn_frames sn_solve sn_rhs matvec sn_precond sn_k_dot sn_k_axpy sn_segments_step sn_health; do
                awk -v fn="$fn" -v n="$STEPS" -v f0="$tmp/ann.0" -v f1="$tmp/ann.$STEPS" '
                    function sum(file,   t, line, name) { t = 0
                        while ((getline line < file) > 0) { k = split(line, w, " "); name = ""
                            for (i = 2; i < k; i++) if (w[i + 1] ~ /^\[/) name = w[i]
                            sub(/^.*:/, "", name)
                            sub(/\..*$/, "", name); if (name == fn) { gsub(",", "", w[1]); t += w[1] } }
                        close(file); return t }
                    BEGIN { d = (sum(f1) - sum(f0)) / n; if (d > 0) printf " %s %.0f", fn, d }'
            done
            echo
        fi
    else
        echo "  SKIPPED: valgrind not installed (no instruction counts)"
    fi
done
# the blob an engine that keeps its own index buffer ships (sinew-bake --no-triangles)
desc=tools/examples/$a/$a.sinew
if [ -x "$BUILD/sinew-bake" ] && [ -f "$desc" ] && "$BUILD/sinew-bake" "$desc" -o "$tmp/nt.blob" --no-triangles --quiet 2> /dev/null; then
    wc -c < "$tmp/nt.blob" | tr -d ' ' > "$tmp/nt_$a"
fi
done
# many instances sharing one blob (issue 15 item 5): per-cow step cost of a
# herd of 1, 10, 100 cows on one core, and the working set against the caches
echo "== herd: N cows sharing one blob, stepped one after another on one core"
for flav in fixed float; do
    if [ $flav = fixed ]; then bin=$BUILD/bench/sn_herd; blob=$BUILD/examples/cow.blob
    else bin=$BUILD/bench/sn_herd_float; blob=$BUILD/examples/cow_float.blob; fi
    [ -f "$blob" ] && [ -x "$bin" ] || { echo "SKIPPED: $bin or $blob missing"; continue; }
    "$bin" "$blob" ${HERD_SIZES:-1 10 100} || rc=1
done
# ---- the figure table (issue 15 "Goals"; README's figure table comes from it) ----
v() { if [ -s "$tmp/$1" ]; then head -n 1 "$tmp/$1"; else echo "-"; fi; }
m4() { # asset -> Cortex-M4 instructions per step from the bench-baremetal log
    f=$BUILD/baremetal/bench_$1.log
    if [ -f "$f" ]; then sed -n 's/^insns_per_step: //p' "$f"; else echo "-"; fi
}
mem() { [ -s "$tmp/m_$1_$2" ] && awk -v k="$3" '{print $k}' "$tmp/m_$1_$2" || echo "-"; }
echo "== figures (one run; kernels: see the 'kernels' field above; µs are medians of 400 steps on a shared machine)"
printf '| figure |'; for a in $ASSETS; do printf ' %s |' "$a"; done; printf '\n|---|'; for a in $ASSETS; do printf -- '---|'; done; echo
row() { printf '| %s |' "$1"; shift; for x in "$@"; do printf ' %s |' "$x"; done; echo; }
# shellcheck disable=SC2046
row "desktop fixed step, median µs" $(for a in $ASSETS; do v "t_${a}_fixed"; done)
row "desktop float step, median µs" $(for a in $ASSETS; do v "t_${a}_float"; done)
row "callgrind fixed instructions per step" $(for a in $ASSETS; do v "c_${a}_fixed"; done)
row "callgrind float instructions per step" $(for a in $ASSETS; do v "c_${a}_float"; done)
row "Cortex-M4 instructions per step (fixed)" $(for a in $ASSETS; do m4 "$a"; done)
row "instance bytes (fixed)" $(for a in $ASSETS; do mem "$a" fixed 2; done)
wmem() { [ -s "$tmp/w_$1_$2" ] && awk -v k="$3" '{print $k}' "$tmp/w_$1_$2" || echo "-"; }
row "instance bytes, shared workspace: persistent state per instance (fixed)" $(for a in $ASSETS; do wmem "$a" fixed 1; done)
row "workspace bytes, one per thread (fixed)" $(for a in $ASSETS; do wmem "$a" fixed 2; done)
row "blob bytes (fixed)" $(for a in $ASSETS; do mem "$a" fixed 1; done)
row "blob bytes (fixed, --no-triangles)" $(for a in $ASSETS; do v "nt_$a"; done)
row "blob bytes (float)" $(for a in $ASSETS; do mem "$a" float 1; done)
echo "(Cortex-M4: the images of make bench-baremetal, cow and limb; '-' where none ran)"
exit $rc
