/* sb_lattice_geom.c -- the lattice's geometry and lookups: trilinear shape
 * functions and cell points, the cube check of the build (step 9), distances
 * to the bones, description regions, the block pattern's search. */
#include "sb.h"
#include "sb_lattice_int.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sb_shape(const double t[3], double N[8], double dN[8][3])
{
    int k, a;
    for (k = 0; k < 8; k++) {
        double f[3], df[3];
        for (a = 0; a < 3; a++) {
            int bit = (k >> a) & 1;
            f[a] = bit ? t[a] : 1.0 - t[a];
            df[a] = bit ? 1.0 : -1.0;
        }
        N[k] = f[0] * f[1] * f[2];
        if (dN) {
            dN[k][0] = df[0] * f[1] * f[2];
            dN[k][1] = f[0] * df[1] * f[2];
            dN[k][2] = f[0] * f[1] * df[2];
        }
    }
}

static void corners_point(const double *const xc[8], const double t[3], double p[3], double J[3][3])
{
    double N[8], dN[8][3];
    int k, a, b;
    sb_shape(t, N, dN);
    for (a = 0; a < 3; a++) {
        p[a] = 0;
        for (b = 0; b < 3; b++) J[a][b] = 0;
    }
    for (k = 0; k < 8; k++)
        for (a = 0; a < 3; a++) {
            p[a] += N[k] * xc[k][a];
            for (b = 0; b < 3; b++) J[a][b] += xc[k][a] * dN[k][b];
        }
}

void sb_cell_point(const sb_model *o, int ci, const double t[3], double p[3])
{
    const double *xc[8];
    double J[3][3];
    int k;
    for (k = 0; k < 8; k++) xc[k] = o->x + 3 * o->cells[8 * ci + k];
    corners_point(xc, t, p, J);
}

static double det3(double J[3][3])
{
    return J[0][0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) +
           J[0][2] * (J[1][0] * J[2][1] - J[1][1] * J[2][0]);
}

/* distance from p to segment a-b */
double sb_seg_dist(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3], L2 = 0, s = 0, d2 = 0;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ap[k] = p[k] - a[k]; L2 += ab[k] * ab[k]; s += ab[k] * ap[k]; }
    s = L2 > 0 ? s / L2 : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    for (k = 0; k < 3; k++) { double e = ap[k] - s * ab[k]; d2 += e * e; }
    return sqrt(d2);
}

/* Segment distances for region/frame rules: nearest segment index, or -1. */
int sb_nearest_seg(const sb_model *o, const double p[3], double *dist)
{
    int s, best = -1;
    double bd = HUGE_VAL;
    for (s = 0; s < o->nseg; s++) {
        int c = o->seg_child[s];
        double dd = sb_seg_dist(p, o->joints[o->joints[c].parent].pos, o->joints[c].pos);
        if (dd < bd) { bd = dd; best = s; }
    }
    if (dist) *dist = bd;
    return best;
}

/* does region r (joint indices in sorted order) contain p? */
int sb_region_has(const sb_model *o, const sb_region *r, const double p[3])
{
    int k;
    double d2 = 0;
    switch (r->kind) {
    case SB_RG_ALL: return 1;
    case SB_RG_BOX:
        for (k = 0; k < 3; k++) if (p[k] < r->a[k] || p[k] > r->a[k + 3]) return 0;
        return 1;
    case SB_RG_SPHERE:
        for (k = 0; k < 3; k++) d2 += (p[k] - r->a[k]) * (p[k] - r->a[k]);
        return d2 <= r->a[3] * r->a[3];
    case SB_RG_BONE: {
        int s = sb_nearest_seg(o, p, NULL);
        return s >= 0 && o->seg_child[s] == o->desc_to_sorted[r->bone];
    }
    }
    return 0;
}

int sb_pattern_find(const sb_model *o, int i, int j)
{
    int lo = o->nbptr[i], hi = o->nbptr[i + 1] - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        if (o->nb[mid] == j) return mid;
        if (o->nb[mid] < j) lo = mid + 1; else hi = mid - 1;
    }
    return -1;
}

/* step 9 of sb_build: every kept cell is an undistorted cube (Jacobian c^3 at its
 * centre and corners); the grid is never moved, so a failure is an internal error */
int sb_lattice_cubes(const sb_desc *d, sb_model *o)
{
    double c = o->c;
    int a, k;
    o->min_jac = HUGE_VAL;
    for (a = 0; a < o->nc; a++) {
        const double *xc[8];
        for (k = 0; k < 8; k++) xc[k] = o->x + 3 * o->cells[8 * a + k];
        for (k = 0; k < 9; k++) {
            double t[3], p[3], J[3][3], D;
            int e;
            for (e = 0; e < 3; e++) t[e] = k == 8 ? 0.5 : (k >> e & 1);
            corners_point(xc, t, p, J);
            D = det3(J) / (c * c * c);
            if (D < o->min_jac) o->min_jac = D;
            if (!(fabs(D - 1) < 1e-6)) { sb_fail("%s: internal error: lattice cell %d is not a cube (Jacobian %g of c^3)", d->path, a, D); return -1; }
        }
    }
    return 0;
}
