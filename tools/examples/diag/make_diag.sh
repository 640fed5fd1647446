#!/bin/sh
# make_diag.sh [SPACING] > diag.obj
# Writes the synthetic character of diag.sinew: a union of capsules around an
# A-pose skeleton whose bones run at 30, 45 and 60 degrees to the axes (and one
# along (1,1,1)), as a closed, consistently oriented triangle mesh: marching
# tetrahedra (6 Kuhn tetrahedra per grid cube, so neighbours share faces) on
# f(p) = min over capsules (distance to the segment - radius), f < 0 inside.
# Triangles are ordered from each tetrahedron's orientation (exact, in grid
# indices), normals outward. Plain POSIX sh + awk. Default spacing 0.45.
awk -v h="${1:-0.45}" '
function cap(ax, ay, az, bx, by, bz, r) { n++; A[n,0] = ax; A[n,1] = ay; A[n,2] = az; B[n,0] = bx; B[n,1] = by; B[n,2] = bz; R[n] = r }
function f(x, y, z,   i, best, abx, aby, abz, t, L2, dx, dy, dz, d) {
    best = 1e30
    for (i = 1; i <= n; i++) {
        abx = B[i,0] - A[i,0]; aby = B[i,1] - A[i,1]; abz = B[i,2] - A[i,2]
        L2 = abx * abx + aby * aby + abz * abz
        t = L2 > 0 ? ((x - A[i,0]) * abx + (y - A[i,1]) * aby + (z - A[i,2]) * abz) / L2 : 0
        t = t < 0 ? 0 : t > 1 ? 1 : t
        dx = x - A[i,0] - t * abx; dy = y - A[i,1] - t * aby; dz = z - A[i,2] - t * abz
        d = sqrt(dx * dx + dy * dy + dz * dz) - R[i]
        if (d < best) best = d
    }
    if (best > -1e-9 && best < 1e-9) best = 1e-9   # no zero at a grid point: the surface stays a manifold
    return best
}
# vertex on grid edge (p, q), shared by every tetrahedron that has that edge
function ev(p, q,   key, t) {
    key = p < q ? p "," q : q "," p
    if (!(key in vid)) {
        vid[key] = ++nv
        t = F[p] / (F[p] - F[q])
        printf "v %.7g %.7g %.7g\n", PX[p] + t * (PX[q] - PX[p]), PY[p] + t * (PY[q] - PY[p]), PZ[p] + t * (PZ[q] - PZ[p])
    }
    return vid[key]
}
function tri(a, b, c) { T[++nt] = a " " b " " c }
BEGIN {
    # skeleton (diag.sinew) and flesh radii
    cap(0, 9, 0,  0, 13, 0,  2.2)                  # pelvis -> chest (torso)
    cap(0, 13, 0, 0, 16.5, 0, 0.8)                 # chest -> head (neck)
    cap(0, 17, 0, 0, 17, 0, 1.6)                   # head
    cap(0, 16.5, 0, 1.732, 18.232, 1.732, 0.5)     # head -> horn along (1,1,1)
    cap(0, 13, 0, 1.8, 13.5, 0, 1.0)               # chest -> shoulder_l
    cap(1.8, 13.5, 0, 5.264, 11.5, 0, 0.75)        # upper arm l: 30 degrees below the x axis
    cap(5.264, 11.5, 0, 7.739, 9.025, 0, 0.6)      # forearm l: 45 degrees
    cap(0, 13, 0, -1.8, 13.5, 0, 1.0)              # chest -> shoulder_r
    cap(-1.8, 13.5, 0, -3.8, 10.036, 0, 0.75)      # upper arm r: 60 degrees to the x axis
    cap(-3.8, 10.036, 0, -5.55, 8.286, 2.475, 0.6) # forearm r: 60, 60, 45 degrees to x, y, z
    cap(0, 9, 0, 1.2, 9, 0, 1.2)                   # pelvis -> hip_l
    cap(1.2, 9, 0, 3.5, 5.016, 0, 1.0)             # thigh l: 60 degrees to the x axis
    cap(3.5, 5.016, 0, 1.2, 1.032, 0, 0.75)        # shin l: 30 degrees to the y axis
    cap(0, 9, 0, -1.2, 9, 0, 1.2)                  # pelvis -> hip_r
    cap(-1.2, 9, 0, -3.5, 5.747, 2.3, 1.0)         # thigh r: 60, 45, 60 degrees to x, y, z
    cap(-3.5, 5.747, 2.3, -3.5, 1.25, 2.3, 0.75)   # shin r: vertical
    cap(0, 9, 0, 0, 6.172, -2.828, 0.55)           # tail: 45 degrees to y and z
    x0 = -9; x1 = 10; y0 = -0.5; y1 = 19.5; z0 = -4.5; z1 = 4.5
    nx = int((x1 - x0) / h + 0.5); ny = int((y1 - y0) / h + 0.5); nz = int((z1 - z0) / h + 0.5)
    print "# synthetic diagonal-bone character, tools/examples/diag/make_diag.sh " h
    for (k = 0; k <= nz; k++) for (j = 0; j <= ny; j++) for (i = 0; i <= nx; i++) {
        p = i + (nx + 1) * (j + (ny + 1) * k)
        PX[p] = x0 + i * h; PY[p] = y0 + j * h; PZ[p] = z0 + k * h
        F[p] = f(PX[p], PY[p], PZ[p])
    }
    # Kuhn tetrahedra of the unit cube (corner bits x=1, y=2, z=4), each (0, e_a, e_a+e_b, 7)
    split("1 3 1 5 2 3 2 6 4 5 4 6", K, " ")
    for (k = 0; k < nz; k++) for (j = 0; j < ny; j++) for (i = 0; i < nx; i++) {
        for (c = 0; c < 8; c++) {
            ci = i + (c % 2); cj = j + int(c / 2) % 2; ck = k + int(c / 4)
            G[c] = ci + (nx + 1) * (cj + (ny + 1) * ck); CX[c] = c % 2; CY[c] = int(c / 2) % 2; CZ[c] = int(c / 4)
        }
        any = 0; all = 1
        for (c = 0; c < 8; c++) if (F[G[c]] < 0) any = 1; else all = 0
        if (!any || all) continue
        for (t = 0; t < 6; t++) {
            v[0] = 0; v[1] = K[2 * t + 1]; v[2] = K[2 * t + 2]; v[3] = 7
            # positive orientation (exact, in unit-cube coordinates)
            ux = CX[v[1]] - CX[v[0]]; uy = CY[v[1]] - CY[v[0]]; uz = CZ[v[1]] - CZ[v[0]]
            wx = CX[v[2]] - CX[v[0]]; wy = CY[v[2]] - CY[v[0]]; wz = CZ[v[2]] - CZ[v[0]]
            qx = CX[v[3]] - CX[v[0]]; qy = CY[v[3]] - CY[v[0]]; qz = CZ[v[3]] - CZ[v[0]]
            det = ux * (wy * qz - wz * qy) - uy * (wx * qz - wz * qx) + uz * (wx * qy - wy * qx)
            if (det < 0) { s = v[2]; v[2] = v[3]; v[3] = s }
            nin = 0; nout = 0
            for (e = 0; e < 4; e++) if (F[G[v[e]]] < 0) I[nin++] = e; else O[nout++] = e
            if (nin == 0 || nin == 4) continue
            # permutation (isolated / inside first) of positions 0..3, made even by swapping the last two
            if (nin == 1 || nin == 3) {
                a = nin == 1 ? I[0] : O[0]; m = 0
                for (e = 0; e < 4; e++) if (e != a) P[++m] = e
                P[0] = a
            } else { P[0] = I[0]; P[1] = I[1]; P[2] = O[0]; P[3] = O[1] }
            inv = 0
            for (e = 0; e < 4; e++) for (g = e + 1; g < 4; g++) if (P[e] > P[g]) inv++
            if (inv % 2) { s = P[2]; P[2] = P[3]; P[3] = s }
            for (e = 0; e < 4; e++) W[e] = G[v[P[e]]]
            if (nin == 1) tri(ev(W[0], W[1]), ev(W[0], W[2]), ev(W[0], W[3]))          # normal away from the inside vertex
            else if (nin == 3) tri(ev(W[0], W[1]), ev(W[0], W[3]), ev(W[0], W[2]))     # towards the outside vertex
            else {                                                                       # quad ac ad bd bc, outward
                tri(ev(W[0], W[2]), ev(W[0], W[3]), ev(W[1], W[3]))
                tri(ev(W[0], W[2]), ev(W[1], W[3]), ev(W[1], W[2]))
            }
        }
    }
    for (t = 1; t <= nt; t++) print "f " T[t]
}'
