#!/bin/sh
# Issue 15 study: the cow's tail and blanket baked alone (the other mesh's
# lines removed: the meshes do not act on the flesh or on each other, so each
# one's gap is its own) at a range of sweep counts, fixed and float; prints
# tests/seg_study's line per variant. Usage: BUILD=dir sh tests/scripts/seg_study.sh [extra sed on the mesh line]
set -e
B=${BUILD:-build}
D=$B/seg_study
mkdir -p "$D"
SRC=tools/examples/cow/cow.sinew
for mesh in tail blanket; do
    other=blanket; [ $mesh = blanket ] && other=tail
    for n in ${SEG_SWEEPS:-4 8 12 16 24 32 48 64}; do
        f=$D/${mesh}_$n
        grep -v -E "^(chain|sheet|attach) $other( |$)" "$SRC" |
            sed -E "s|^mesh cow.obj|mesh $PWD/tools/examples/cow/cow.obj|;/^(chain|sheet) $mesh /s/sweeps [0-9]+/sweeps $n/${SEG_SED:+;$SEG_SED}" > "$f.sinew"
        "$B/sinew-bake" "$f.sinew" -o "$f.blob" --quiet
        "$B/sinew-bake" "$f.sinew" -o "${f}_float.blob" --flavour float --quiet
        "$B/tests/seg_study" "$f.blob"
        "$B/tests/seg_study_float" "${f}_float.blob"
    done
done
