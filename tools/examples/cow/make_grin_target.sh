#!/bin/sh
# A target for the cow's head (sinew-rig fit-surface, seed 003 §4.3): cow.obj
# with every vertex moved by a known smooth field, so the answer is known.
#   d(x) = A w(|x - c| / R) (s (x - c) / R + u),  w(t) = (1 - t^2)^3 for t < 1, else 0
# c = the muzzle (5.3, 0.75, 0), R = 1.6 mesh units, A = 0.25 mesh units,
# s = 0.6 (a swelling of the muzzle) and u = (0, 1, 0) (lifted): the jaw and
# cheeks puff and rise ("grin"). The largest displacement is about A = 0.25
# mesh units (5 cm, 0.2 cells). Faces are copied unchanged.
# The field is smooth but not every rig can show it: on rigfit.sh's lattice
# (cell 0.6) the head and snout bones' chains run along the middle of the
# muzzle, 36.6% of the field's sum |d|^2 sits on surface vertices at least half
# carried by skeleton vertices, and the best any rig can do (the free lattice
# vertices' least-squares fit, which sinew-rig fit-surface prints as "best
# reachable") is rms 13.8%, max 63% of the displacement (3.9%, 5.4% if the
# skeleton vertices were free too); at cell 0.3 it is rms 2.9%, max 6.7%
# (tools/DESCRIPTION.md "Rig fitting").
#   sh tools/examples/cow/make_grin_target.sh tools/examples/cow/cow.obj > grin.obj
awk -v cx=5.3 -v cy=0.75 -v cz=0 -v R=1.6 -v A=0.25 -v s=0.6 '
$1 == "v" {
    dx = ($2 - cx) / R; dy = ($3 - cy) / R; dz = ($4 - cz) / R
    t2 = dx * dx + dy * dy + dz * dz
    if (t2 < 1) { w = (1 - t2) ^ 3; printf "v %.9g %.9g %.9g\n", $2 + A * w * s * dx, $3 + A * w * (s * dy + 1), $4 + A * w * s * dz }
    else print
    next
}
{ print }' "$1"
