/* sb_lattice.c -- automatic control lattice (seed 000 §3.1): a regular grid of
 * cubes covering the mesh, bones realised as chains of lattice edges whose
 * vertices are moved exactly onto the bone (condition ii), kept cells = those
 * meeting the interior, free/skeleton split, frames (seed 003 §3.3), surface
 * embedding by inverse trilinear map. */
#include "sb.h"
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

/* Newton on x(t) = q; returns 1 if q is in the cell (t in [0,1]^3 up to round-off). */
static int inverse_trilinear(const double *const xc[8], const double q[3], double c, double t[3])
{
    int it, a;
    double p[3], J[3][3], r[3], dt[3], D;
    t[0] = t[1] = t[2] = 0.5;
    for (it = 0; it < 40; it++) {
        corners_point(xc, t, p, J);
        for (a = 0; a < 3; a++) r[a] = p[a] - q[a];
        D = det3(J);
        if (!(fabs(D) > 1e-300)) return 0;
        /* Cramer's rule: J dt = r */
        dt[0] = (r[0] * (J[1][1] * J[2][2] - J[1][2] * J[2][1]) - J[0][1] * (r[1] * J[2][2] - J[1][2] * r[2]) + J[0][2] * (r[1] * J[2][1] - J[1][1] * r[2])) / D;
        dt[1] = (J[0][0] * (r[1] * J[2][2] - J[1][2] * r[2]) - r[0] * (J[1][0] * J[2][2] - J[1][2] * J[2][0]) + J[0][2] * (J[1][0] * r[2] - r[1] * J[2][0])) / D;
        dt[2] = (J[0][0] * (J[1][1] * r[2] - r[1] * J[2][1]) - J[0][1] * (J[1][0] * r[2] - r[1] * J[2][0]) + r[0] * (J[1][0] * J[2][1] - J[1][1] * J[2][0])) / D;
        for (a = 0; a < 3; a++) t[a] -= dt[a];
        if (fabs(t[0]) > 10 || fabs(t[1]) > 10 || fabs(t[2]) > 10) return 0;
        if (fabs(dt[0]) + fabs(dt[1]) + fabs(dt[2]) < 1e-15) break;
    }
    corners_point(xc, t, p, J);
    for (a = 0; a < 3; a++) if (fabs(p[a] - q[a]) > 1e-9 * c) return 0;
    for (a = 0; a < 3; a++) if (t[a] < -1e-9 || t[a] > 1 + 1e-9) return 0;
    for (a = 0; a < 3; a++) t[a] = t[a] < 0 ? 0 : t[a] > 1 ? 1 : t[a];
    return 1;
}

/* distance from p to segment a-b */
static double seg_dist(const double p[3], const double a[3], const double b[3])
{
    double ab[3], ap[3], L2 = 0, s = 0, d2 = 0;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ap[k] = p[k] - a[k]; L2 += ab[k] * ab[k]; s += ab[k] * ap[k]; }
    s = L2 > 0 ? s / L2 : 0;
    s = s < 0 ? 0 : s > 1 ? 1 : s;
    for (k = 0; k < 3; k++) { double e = ap[k] - s * ab[k]; d2 += e * e; }
    return sqrt(d2);
}

static int gidx(const sb_model *o, int i, int j, int k) { return i + o->gn[0] * (j + o->gn[1] * k); }

/* corner grid vertices of grid cell (i,j,k) */
static void cell_corners(const sb_model *o, int gc, int g[8])
{
    int nx = o->gn[0] - 1, ny = o->gn[1] - 1;
    int i = gc % nx, j = (gc / nx) % ny, k = gc / (nx * ny), c;
    for (c = 0; c < 8; c++) g[c] = gidx(o, i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
}

/* Segment distances for region/frame rules: nearest segment index, or -1. */
int sb_nearest_seg(const sb_model *o, const double p[3], double *dist)
{
    int s, best = -1;
    double bd = HUGE_VAL;
    for (s = 0; s < o->nseg; s++) {
        int c = o->seg_child[s];
        double dd = seg_dist(p, o->joints[o->joints[c].parent].pos, o->joints[c].pos);
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

static void progress(const sb_model *o, double t0, const char *what, int done, int total)
{
    if (!o->quiet && sb_now() - t0 > 1.0 && total > 0)
        fprintf(stderr, "\rsinew-bake: %s %3d%%", what, (int)(100.0 * done / total));
}

int sb_build(const sb_desc *d, const sb_mesh *m, sb_model *o, int quiet)
{
    sb_inside in;
    int i, j, k, a, nj = d->nj, ngv, ngc, n = d->subdiv, npt = n * n * n * 8;
    int *gsnap = NULL, *gclaim = NULL, *keep = NULL, *order;
    unsigned char *inbits = NULL;
    double c = d->cell, t0 = sb_now(), *mindet = NULL;
    int rc = -1;

    memset(o, 0, sizeof *o);
    o->quiet = quiet;
    o->unit = d->unit; o->h = d->h; o->alpha = d->alpha; o->beta = d->beta; o->cg_def = d->cg_def; o->cg_max = d->cg_max;
    for (k = 0; k < 3; k++) o->g[k] = d->g[k];
    {
        double dd = 0;
        for (k = 0; k < 3; k++) dd += (m->hi[k] - m->lo[k]) * (m->hi[k] - m->lo[k]);
        o->bbox_diag = sqrt(dd);
    }
    sb_inside_init(&in, m);

    /* 1. joints sorted so parents precede children (stable in description order) */
    o->nj = nj;
    o->joints = sb_alloc(sizeof(sb_joint) * (size_t)nj);
    o->desc_to_sorted = sb_alloc(sizeof(int) * (size_t)nj);
    order = sb_alloc(sizeof(int) * (size_t)nj);
    for (i = 0; i < nj; i++) o->desc_to_sorted[i] = -1;
    for (k = 0; k < nj;) {
        for (i = 0; i < nj; i++)
            if (o->desc_to_sorted[i] < 0 && (d->joints[i].parent < 0 || o->desc_to_sorted[d->joints[i].parent] >= 0)) {
                o->desc_to_sorted[i] = k; order[k++] = i;
            }
    }
    for (k = 0; k < nj; k++) {
        o->joints[k] = d->joints[order[k]];
        o->joints[k].parent = d->joints[order[k]].parent < 0 ? -1 : o->desc_to_sorted[d->joints[order[k]].parent];
    }
    free(order);
    for (k = 0; k < nj; k++)
        if (!sb_inside_test(&in, o->joints[k].pos)) {
            sb_fail("%s:%d: joint '%s' at (%g, %g, %g) is outside the mesh", d->path, o->joints[k].line, o->joints[k].name,
                    o->joints[k].pos[0], o->joints[k].pos[1], o->joints[k].pos[2]);
            goto done;
        }
    o->seg_child = sb_alloc(sizeof(int) * (size_t)nj);
    for (k = 1; k < nj; k++) o->seg_child[o->nseg++] = k;

    /* 2. grid: cubes of edge c aligned to the origin (default: the root joint), one cell of margin */
    o->c = c;
    {
        double org[3];
        for (k = 0; k < 3; k++) {
            int lo, hi;
            org[k] = d->has_origin ? d->origin[k] : o->joints[0].pos[k];
            lo = (int)floor((m->lo[k] - org[k]) / c) - 1;
            hi = (int)ceil((m->hi[k] - org[k]) / c) + 1;
            o->gorg[k] = org[k] + lo * c;
            o->gn[k] = hi - lo + 1;
        }
    }
    if ((double)o->gn[0] * o->gn[1] * o->gn[2] > 4e6) { sb_fail("%s: cell size %g is too small for this mesh (grid over 4 million vertices)", d->path, c); goto done; }
    ngv = o->gn[0] * o->gn[1] * o->gn[2];
    ngc = (o->gn[0] - 1) * (o->gn[1] - 1) * (o->gn[2] - 1);
    o->gpos = sb_alloc(sizeof(double) * 3 * (size_t)ngv);
    o->gjoint = sb_alloc(sizeof(int) * (size_t)ngv);
    o->gvert = sb_alloc(sizeof(int) * (size_t)ngv);
    gclaim = sb_alloc(sizeof(int) * (size_t)ngv);
    for (k = 0; k < o->gn[2]; k++)
        for (j = 0; j < o->gn[1]; j++)
            for (i = 0; i < o->gn[0]; i++) {
                int g = gidx(o, i, j, k);
                o->gpos[3 * g] = o->gorg[0] + i * c;
                o->gpos[3 * g + 1] = o->gorg[1] + j * c;
                o->gpos[3 * g + 2] = o->gorg[2] + k * c;
                o->gjoint[g] = -1; o->gvert[g] = -1; gclaim[g] = -1;
            }

    /* 3. bones as lattice edge chains: snap joints to the nearest grid vertex,
     * walk grid edges staying closest to the segment, move the chain onto it */
    gsnap = sb_alloc(sizeof(int) * (size_t)nj);
    if (o->nseg > 0) {
        for (j = 0; j < nj; j++) {
            int gi[3];
            for (k = 0; k < 3; k++) gi[k] = (int)floor((o->joints[j].pos[k] - o->gorg[k]) / c + 0.5);
            gsnap[j] = gidx(o, gi[0], gi[1], gi[2]);
            for (i = 0; i < j; i++)
                if (gsnap[i] == gsnap[j]) {
                    int pc = o->joints[j].parent == i;
                    double L = 0;
                    for (k = 0; k < 3; k++) L += (o->joints[j].pos[k] - o->joints[i].pos[k]) * (o->joints[j].pos[k] - o->joints[i].pos[k]);
                    if (pc) sb_fail("%s:%d: bone '%s'->'%s' (length %g) is too short for cell size %g: both ends snap to the same lattice vertex; use a cell below %g",
                                    d->path, o->joints[j].line, o->joints[i].name, o->joints[j].name, sqrt(L), c, sqrt(L) * 0.7);
                    else sb_fail("%s:%d: joints '%s' and '%s' snap to the same lattice vertex (distance %g, cell size %g); move one or use a smaller cell",
                                 d->path, o->joints[j].line, o->joints[i].name, o->joints[j].name, sqrt(L), c);
                    goto done;
                }
            /* a joint's vertex moves with its parent (the bone ending there), the root with itself */
            o->gjoint[gsnap[j]] = o->joints[j].parent < 0 ? 0 : o->joints[j].parent;
            gclaim[gsnap[j]] = -2 - j;
            memcpy(o->gpos + 3 * gsnap[j], o->joints[j].pos, sizeof(double) * 3);
        }
        for (a = 0; a < o->nseg; a++) {
            int ch = o->seg_child[a], pa = o->joints[ch].parent, cur[3], tgt[3], path[4096], L = 0, p;
            double spos[4096];
            const double *P = o->joints[pa].pos, *C = o->joints[ch].pos;
            cur[0] = gsnap[pa] % o->gn[0]; cur[1] = (gsnap[pa] / o->gn[0]) % o->gn[1]; cur[2] = gsnap[pa] / (o->gn[0] * o->gn[1]);
            tgt[0] = gsnap[ch] % o->gn[0]; tgt[1] = (gsnap[ch] / o->gn[0]) % o->gn[1]; tgt[2] = gsnap[ch] / (o->gn[0] * o->gn[1]);
            path[L++] = gsnap[pa];
            while (cur[0] != tgt[0] || cur[1] != tgt[1] || cur[2] != tgt[2]) {
                int bestax = -1;
                double bd = HUGE_VAL;
                for (k = 0; k < 3; k++) {
                    double q[3], dd;
                    int nx[3] = {cur[0], cur[1], cur[2]}, gn;
                    if (cur[k] == tgt[k]) continue;
                    nx[k] += tgt[k] > cur[k] ? 1 : -1;
                    gn = gidx(o, nx[0], nx[1], nx[2]);
                    q[0] = o->gorg[0] + nx[0] * c; q[1] = o->gorg[1] + nx[1] * c; q[2] = o->gorg[2] + nx[2] * c;
                    dd = seg_dist(q, P, C);
                    /* steer around vertices other bones already own (a large penalty, not a ban:
                     * if every step is taken the conflict is reported below) */
                    if (gn != gsnap[ch] && gclaim[gn] != -1) dd += 1e6 * c;
                    if (dd < bd - 1e-12 * c) { bd = dd; bestax = k; }
                }
                cur[bestax] += tgt[bestax] > cur[bestax] ? 1 : -1;
                if (L >= 4095) { sb_fail("%s: bone too long for the lattice", d->path); goto done; }
                path[L++] = gidx(o, cur[0], cur[1], cur[2]);
            }
            {   /* where the chain's vertices go on the segment: the projection of each grid vertex
                 * (smallest moves, so the least cell distortion), kept strictly increasing with a
                 * minimum gap of a quarter of the even spacing */
                double L2 = 0, gap = 0.25 / (double)(L - 1);
                for (k = 0; k < 3; k++) L2 += (C[k] - P[k]) * (C[k] - P[k]);
                spos[0] = 0; spos[L - 1] = 1;
                for (p = 1; p < L - 1; p++) {
                    double dp = 0;
                    for (k = 0; k < 3; k++) dp += (o->gpos[3 * path[p] + k] - P[k]) * (C[k] - P[k]);
                    spos[p] = dp / L2;
                    if (spos[p] < spos[p - 1] + gap) spos[p] = spos[p - 1] + gap;
                    if (spos[p] > 1 - (double)(L - 1 - p) * gap) spos[p] = 1 - (double)(L - 1 - p) * gap;
                }
            }
            for (p = 1; p < L - 1; p++) {
                int g = path[p];
                if (gclaim[g] != -1) {
                    const char *other = gclaim[g] <= -2 ? o->joints[-2 - gclaim[g]].name : o->joints[o->seg_child[gclaim[g]]].name;
                    sb_fail("%s:%d: bone '%s'->'%s' and %s '%s' claim the same lattice vertex near (%g, %g, %g); move a joint or change the cell size (now %g)",
                            d->path, o->joints[ch].line, o->joints[pa].name, o->joints[ch].name, gclaim[g] <= -2 ? "joint" : "the bone ending at",
                            other, o->gpos[3 * g], o->gpos[3 * g + 1], o->gpos[3 * g + 2], c);
                    goto done;
                }
                gclaim[g] = a;
                o->gjoint[g] = pa;
                for (k = 0; k < 3; k++) o->gpos[3 * g + k] = P[k] + (C[k] - P[k]) * spos[p];
            }
        }
    }

    /* 4. which quadrature points of each grid cell are inside the mesh */
    inbits = sb_alloc((size_t)ngc * (size_t)npt);
    mindet = sb_alloc(sizeof(double) * (size_t)ngc);
    o->cell_fill = sb_alloc(sizeof(double) * (size_t)ngc);
    keep = sb_alloc(sizeof(int) * (size_t)ngc);
    for (a = 0; a < ngc; a++) {
        int g[8], q = 0, sx, sy, sz, gp;
        const double *xc[8];
        double vin = 0, vall = 0;
        static const double gp2[2] = {0.21132486540518711775, 0.78867513459481288225};  /* 2-point Gauss on [0,1] */
        cell_corners(o, a, g);
        for (k = 0; k < 8; k++) xc[k] = o->gpos + 3 * g[k];
        mindet[a] = HUGE_VAL;
        /* inversion check independent of the quadrature: Jacobian on a 9x9x9 grid including the corners */
        for (k = 0; k < 729; k++) {
            double t[3], p[3], J[3][3], D;
            t[0] = (k % 9) / 8.0; t[1] = (k / 9 % 9) / 8.0; t[2] = (k / 81) / 8.0;
            corners_point(xc, t, p, J);
            D = det3(J);
            if (D < mindet[a]) mindet[a] = D;
        }
        for (sz = 0; sz < n; sz++) for (sy = 0; sy < n; sy++) for (sx = 0; sx < n; sx++)
            for (gp = 0; gp < 8; gp++, q++) {
                double t[3], p[3], J[3][3], D;
                t[0] = (sx + gp2[gp & 1]) / n; t[1] = (sy + gp2[(gp >> 1) & 1]) / n; t[2] = (sz + gp2[(gp >> 2) & 1]) / n;
                corners_point(xc, t, p, J);
                D = det3(J);
                if (D < mindet[a]) mindet[a] = D;
                inbits[(size_t)a * (size_t)npt + (size_t)q] = (unsigned char)sb_inside_test(&in, p);
                vall += D;
                if (inbits[(size_t)a * (size_t)npt + (size_t)q]) vin += D;
            }
        o->cell_fill[a] = vall > 0 ? vin / vall : 0;
        keep[a] = vin > 0 && o->cell_fill[a] >= d->min_fill;
        if ((a & 63) == 0) progress(o, t0, "inside test", a, ngc);
    }

    /* 5. surface embedding: each mesh vertex in a (preferably kept) cell */
    o->ns = m->nv;
    o->emb_cell = sb_alloc(sizeof(int) * (size_t)m->nv);
    o->emb_t = sb_alloc(sizeof(double) * 3 * (size_t)m->nv);
    for (i = 0; i < m->nv; i++) {
        const double *q = m->v + 3 * i;
        int gi[3], found = -1, pass, di, dj, dk;
        double t[3], tf[3] = {0, 0, 0};
        for (k = 0; k < 3; k++) gi[k] = (int)floor((q[k] - o->gorg[k]) / c);
        /* pass 0: kept cells nearby, pass 1: any cell nearby, pass 2: any cell within 2 (bone snapping
         * moves vertices by up to ~0.9 cell) */
        for (pass = 0; pass < 3 && found < 0; pass++)
            for (dk = 0; dk < 5 && found < 0; dk++) for (dj = 0; dj < 5 && found < 0; dj++) for (di = 0; di < 5 && found < 0; di++) {
                static const int off[5] = {0, -1, 1, -2, 2};
                int ci = gi[0] + off[di], cj = gi[1] + off[dj], ck = gi[2] + off[dk], gc, g[8];
                if ((pass < 2) && (di > 2 || dj > 2 || dk > 2)) continue;
                const double *xc[8];
                if (ci < 0 || cj < 0 || ck < 0 || ci >= o->gn[0] - 1 || cj >= o->gn[1] - 1 || ck >= o->gn[2] - 1) continue;
                gc = ci + (o->gn[0] - 1) * (cj + (o->gn[1] - 1) * ck);
                if ((pass == 0) != (keep[gc] != 0) && pass < 2) continue;
                cell_corners(o, gc, g);
                for (k = 0; k < 8; k++) xc[k] = o->gpos + 3 * g[k];
                if (inverse_trilinear((const double *const *)xc, q, c, t)) { found = gc; memcpy(tf, t, sizeof t); }
            }
        if (found < 0) {
            sb_fail("%s: mesh vertex %d at (%g, %g, %g) lies in no lattice cell: the lattice folds there after moving vertices onto "
                    "the bones; try another cell size (e.g. %g or %g) or move the joints nearer lattice vertices",
                    d->mesh_path, i + 1, q[0], q[1], q[2], c * 0.8, c * 1.2);
            goto done;
        }
        keep[found] = 1;
        o->emb_cell[i] = found;   /* grid cell for now; renumbered below */
        memcpy(o->emb_t + 3 * i, tf, sizeof tf);
    }

    /* 6. kept cells must not be inverted by the bone snapping */
    for (a = 0; a < ngc; a++)
        /* a zero Jacobian at a corner is expected where a bone chain turns (three chain vertices
         * on one straight segment are corners of one face): only a negative one beyond round-off fails */
        if (keep[a] && !(mindet[a] > -1e-9 * c * c * c)) {
            int g[8];
            double ctr[3] = {0, 0, 0};
            cell_corners(o, a, g);
            for (k = 0; k < 8; k++) for (j = 0; j < 3; j++) ctr[j] += o->gpos[3 * g[k] + j] / 8;
            sb_fail("%s: lattice cell near (%.3g, %.3g, %.3g) is inverted after moving skeleton vertices onto the bones "
                    "(Jacobian %.3g <= 0 inside the cell); try another cell size (e.g. %g or %g) or move the joints nearer lattice vertices",
                    d->path, ctr[0], ctr[1], ctr[2], mindet[a], c * 0.8, c * 1.2);
            goto done;
        }

    o->min_jac = HUGE_VAL;
    for (a = 0; a < ngc; a++) if (keep[a] && mindet[a] / (c * c * c) < o->min_jac) o->min_jac = mindet[a] / (c * c * c);

    /* 7. lattice vertices, pins, free-first order */
    {
        unsigned char *used = sb_alloc((size_t)ngv);
        int nskel = 0, nfree = 0, *cellno = sb_alloc(sizeof(int) * (size_t)ngc);
        for (a = 0; a < ngc; a++)
            if (keep[a]) { int g[8]; cell_corners(o, a, g); for (k = 0; k < 8; k++) used[g[k]] = 1; }
        for (i = 0; i < ngv; i++)
            if (gclaim[i] != -1 && !used[i]) {
                sb_fail("%s: a bone passes through (%g, %g, %g), which is outside the mesh's lattice; keep bones inside the mesh",
                        d->path, o->gpos[3 * i], o->gpos[3 * i + 1], o->gpos[3 * i + 2]);
                free(used); free(cellno); goto done;
            }
        for (a = 0; a < d->npin; a++)
            for (i = 0; i < ngv; i++)
                if (used[i] && gclaim[i] == -1) {
                    sb_region r = d->pins[a].r;
                    if (sb_region_has(o, &r, o->gpos + 3 * i)) o->gjoint[i] = o->desc_to_sorted[d->pins[a].joint];
                }
        for (i = 0; i < ngv; i++) if (used[i]) { if (o->gjoint[i] < 0) nfree++; else nskel++; }
        if (nfree + nskel > 65535) { sb_fail("%s: %d lattice vertices (max 65535); use a larger cell", d->path, nfree + nskel); free(used); free(cellno); goto done; }
        if (nskel == 0) { sb_fail("%s: no skeleton vertices: add a bone (two joints) or a 'pin' region", d->path); free(used); free(cellno); goto done; }
        if (nfree == 0) { sb_fail("%s: no free vertices: every lattice vertex is on the skeleton", d->path); free(used); free(cellno); goto done; }
        o->nv = nfree + nskel; o->nf = nfree;
        o->v_grid = sb_alloc(sizeof(int) * (size_t)o->nv);
        o->x = sb_alloc(sizeof(double) * 3 * (size_t)o->nv);
        nfree = 0; nskel = o->nf;
        for (i = 0; i < ngv; i++)
            if (used[i]) {
                int v = o->gjoint[i] < 0 ? nfree++ : nskel++;
                o->gvert[i] = v; o->v_grid[v] = i;
                memcpy(o->x + 3 * v, o->gpos + 3 * i, sizeof(double) * 3);
            }
        for (a = 0; a < ngc; a++) if (keep[a]) o->nc++;
        o->cells = sb_alloc(sizeof(int) * 8 * (size_t)o->nc);
        o->cell_grid = sb_alloc(sizeof(int) * (size_t)o->nc);
        for (a = 0, j = 0; a < ngc; a++)
            if (keep[a]) {
                int g[8];
                cell_corners(o, a, g);
                for (k = 0; k < 8; k++) o->cells[8 * j + k] = o->gvert[g[k]];
                o->cell_grid[j] = a; cellno[a] = j; j++;
            }
        for (i = 0; i < m->nv; i++) o->emb_cell[i] = cellno[o->emb_cell[i]];
        {   /* inside fraction per kept cell (was per grid cell) */
            double *fill = sb_alloc(sizeof(double) * (size_t)o->nc);
            for (j = 0; j < o->nc; j++) fill[j] = o->cell_fill[o->cell_grid[j]];
            free(o->cell_fill);
            o->cell_fill = fill;
        }
        free(used); free(cellno);
    }

    /* 8. frames (seed 003 §3.3): two nearest bone-moving joints, blend weight from distances */
    o->fb1 = sb_alloc(sizeof(int) * (size_t)o->nv);
    o->fb2 = sb_alloc(sizeof(int) * (size_t)o->nv);
    o->fw = sb_alloc(sizeof(double) * (size_t)o->nv);
    {
        double *jd = sb_alloc(sizeof(double) * (size_t)nj), B = d->blend > 0 ? d->blend : c;
        for (i = 0; i < o->nv; i++) {
            const double *p = o->x + 3 * i;
            int g = o->v_grid[i], b1 = 0, b2 = 0;
            double d1 = HUGE_VAL, d2 = HUGE_VAL, w = 0;
            if (i >= o->nf) { o->fb1[i] = o->fb2[i] = o->gjoint[g]; o->fw[i] = 0; continue; }
            for (j = 0; j < nj; j++) jd[j] = HUGE_VAL;
            for (a = 0; a < o->nseg; a++) {
                int ch = o->seg_child[a], pa = o->joints[ch].parent;
                double dd = seg_dist(p, o->joints[pa].pos, o->joints[ch].pos);
                if (dd < jd[pa]) jd[pa] = dd;
            }
            for (j = 0; j < nj; j++) {
                if (jd[j] < d1) { d2 = d1; b2 = b1; d1 = jd[j]; b1 = j; }
                else if (jd[j] < d2) { d2 = jd[j]; b2 = j; }
            }
            if (d2 < HUGE_VAL) {
                /* w = 1/2 at equal distance, falling smoothly (smoothstep) to 0 when the
                 * second bone is B farther than the first: continuous across the switch */
                double s = 1.0 - (d2 - d1) / B;
                s = s < 0 ? 0 : s > 1 ? 1 : s;
                w = 0.5 * s * s * (3 - 2 * s);
            } else b2 = b1;
            if (w == 0) b2 = b1;
            for (a = 0; a < d->nfr; a++)
                if (sb_region_has(o, &d->frules[a].r, p)) {
                    b1 = o->desc_to_sorted[d->frules[a].j1]; b2 = o->desc_to_sorted[d->frules[a].j2]; w = d->frules[a].w;
                }
            o->fb1[i] = b1; o->fb2[i] = b2; o->fw[i] = w;
        }
        free(jd);
    }

    /* 9. block sparsity pattern: vertices sharing a cell */
    {
        int *cnt = sb_alloc(sizeof(int) * (size_t)(o->nv + 1)), *tmp = sb_alloc(sizeof(int) * 27 * 8 * (size_t)o->nv);
        int *vc = sb_alloc(sizeof(int) * 8 * (size_t)o->nv);   /* cells per vertex (<= 8) */
        int *nvc = sb_alloc(sizeof(int) * (size_t)o->nv);
        for (a = 0; a < o->nc; a++) for (k = 0; k < 8; k++) { int v = o->cells[8 * a + k]; vc[8 * v + nvc[v]++] = a; }
        o->nbptr = sb_alloc(sizeof(int) * (size_t)(o->nv + 1));
        for (i = 0; i < o->nv; i++) {
            int nn = 0, *lst = tmp + 27 * 8 * i, x, y;
            for (a = 0; a < nvc[i]; a++) for (k = 0; k < 8; k++) lst[nn++] = o->cells[8 * vc[8 * i + a] + k];
            for (x = 1; x < nn; x++) { int v = lst[x]; for (y = x; y > 0 && lst[y - 1] > v; y--) lst[y] = lst[y - 1]; lst[y] = v; }
            for (x = 0, y = 0; x < nn; x++) if (y == 0 || lst[y - 1] != lst[x]) lst[y++] = lst[x];
            cnt[i] = y;
            o->nbptr[i + 1] = o->nbptr[i] + y;
        }
        o->nb = sb_alloc(sizeof(int) * (size_t)o->nbptr[o->nv]);
        for (i = 0; i < o->nv; i++) memcpy(o->nb + o->nbptr[i], tmp + 27 * 8 * i, sizeof(int) * (size_t)cnt[i]);
        free(cnt); free(tmp); free(vc); free(nvc);
    }
    o->M = sb_alloc(sizeof(double) * (size_t)o->nbptr[o->nv]);
    o->S = sb_alloc(sizeof(double) * 9 * (size_t)o->nbptr[o->nv]);
    o->T = sb_alloc(sizeof(double) * (size_t)o->nbptr[o->nv]);

    /* 10. integrals */
    if (sb_integrate(d, o, inbits)) goto done;

    o->nt = m->nt;
    o->tri = sb_alloc(sizeof(int) * 3 * (size_t)m->nt);
    memcpy(o->tri, m->tri, sizeof(int) * 3 * (size_t)m->nt);
    rc = 0;
done:
    if (!quiet && sb_now() - t0 > 1.0) fprintf(stderr, "\n");
    sb_inside_free(&in);
    free(gsnap); free(gclaim); free(keep); free(inbits); free(mindet);
    return rc;
}

void sb_model_free(sb_model *o)
{
    free(o->joints); free(o->desc_to_sorted); free(o->seg_child); free(o->gpos); free(o->gjoint); free(o->gvert);
    free(o->v_grid); free(o->x); free(o->cells); free(o->cell_grid); free(o->cell_fill); free(o->fb1); free(o->fb2); free(o->fw);
    free(o->nbptr); free(o->nb); free(o->M); free(o->S); free(o->T); free(o->emb_cell); free(o->emb_t); free(o->tri);
    memset(o, 0, sizeof *o);
}
