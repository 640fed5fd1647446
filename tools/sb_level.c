/* sb_level.c -- hierarchical basis (seed 000 §3.1, appendix A.1: lazy
 * wavelets over repeated hexahedral subdivision; DESIGN.md "Hierarchical
 * basis"): levels, prolongation, Galerkin matrices. See sb_level.h.
 *
 * Everything is integrated once, on the finest level's cells, by the same
 * routine as the baked lattice (sb_integrate_frac: incompatible-mode element,
 * inside fractions, air weight); every coarser matrix is a Galerkin product
 * P^T K P of those element matrices, so no level has its own quadrature and
 * the hierarchical matrices with every function active are the finest nodal
 * matrices in another basis (tests/test_bake_level.c). */
#include "sb_level.h"
#include "sb_cut.h"
#include "../runtime/src/sn_format.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int sb_level_find(const int *ptr, const int *idx, int i, int j)
{
    int lo = ptr[i], hi = ptr[i + 1] - 1;
    while (lo <= hi) {
        int mid = (lo + hi) / 2;
        if (idx[mid] == j) return mid;
        if (idx[mid] < j) lo = mid + 1; else hi = mid - 1;
    }
    return -1;
}

static void gcoord(const int gn[3], int g, int a[3]) { a[0] = g % gn[0]; a[1] = g / gn[0] % gn[1]; a[2] = g / (gn[0] * gn[1]); }
static int gindex(const int gn[3], const int a[3]) { return a[0] + gn[0] * (a[1] + gn[1] * a[2]); }

double sb_level_hat(const sb_hier *h, int lv, int v, int n)
{
    int a[3], g[3], k, s = 1 << (h->J - lv);
    double w = 1;
    gcoord(h->lev[lv].gn, h->lev[lv].vgrid[v], a);
    gcoord(h->lev[h->J].gn, h->lev[h->J].vgrid[n], g);
    for (k = 0; k < 3; k++) {
        int d = g[k] - s * a[k];
        d = d < 0 ? -d : d;
        if (d >= s) return 0;
        w *= (double)(s - d) / s;   /* 1 - |x - x_v| / c_lv: exact (dyadic) */
    }
    return w;
}

/* block pattern of vertices sharing a cell: ptr (nv+1), idx sorted, diagonal included */
static void pattern(int nv, int nc, const int *cells, int **ptr_out, int **idx_out)
{
    int *cnt = sb_alloc(sizeof(int) * (size_t)(nv + 1)), *start, *fill, *ptr, *idx, c, k, l, v;
    int *lst;
    for (c = 0; c < nc; c++) for (k = 0; k < 8; k++) cnt[cells[8 * c + k]] += 8;
    start = sb_alloc(sizeof(int) * (size_t)(nv + 1));
    for (v = 0; v < nv; v++) start[v + 1] = start[v] + cnt[v];
    lst = sb_alloc(sizeof(int) * (size_t)(start[nv] ? start[nv] : 1));
    fill = sb_alloc(sizeof(int) * (size_t)(nv + 1));
    for (c = 0; c < nc; c++)
        for (k = 0; k < 8; k++)
            for (l = 0; l < 8; l++) { v = cells[8 * c + k]; lst[start[v] + fill[v]++] = cells[8 * c + l]; }
    ptr = sb_alloc(sizeof(int) * (size_t)(nv + 1));
    for (v = 0; v < nv; v++) {   /* sort and deduplicate each row in place */
        int *r = lst + start[v], n = fill[v], x, y;
        for (x = 1; x < n; x++) { int t = r[x]; for (y = x; y > 0 && r[y - 1] > t; y--) r[y] = r[y - 1]; r[y] = t; }
        for (x = 0, y = 0; x < n; x++) if (y == 0 || r[y - 1] != r[x]) r[y++] = r[x];
        fill[v] = y; ptr[v + 1] = ptr[v] + y;
    }
    idx = sb_alloc(sizeof(int) * (size_t)(ptr[nv] ? ptr[nv] : 1));
    for (v = 0; v < nv; v++) memcpy(idx + ptr[v], lst + start[v], sizeof(int) * (size_t)fill[v]);
    free(cnt); free(start); free(lst); free(fill);
    *ptr_out = ptr; *idx_out = idx;
}

/* joint moving a point of the lattice: the bone capturing it (within its radius, the
 * nearest bone wins, as sb_build step 7) or a pin (pins override), else -1 */
static int capture(const sb_desc *d, const sb_model *o, const double p[3], int *bone)
{
    int s, a, best = -1, joint = -1;
    double bd = HUGE_VAL;
    for (s = 0; s < o->nseg; s++) {
        int ch = o->seg_child[s];
        const double *P = o->joints[o->joints[ch].parent].pos, *C = o->joints[ch].pos;
        double ab[3], ap[3], L2 = 0, t = 0, d2 = 0, dd;
        int k;
        for (k = 0; k < 3; k++) { ab[k] = C[k] - P[k]; ap[k] = p[k] - P[k]; L2 += ab[k] * ab[k]; t += ab[k] * ap[k]; }
        t = L2 > 0 ? t / L2 : 0;
        t = t < 0 ? 0 : t > 1 ? 1 : t;
        for (k = 0; k < 3; k++) { double e = ap[k] - t * ab[k]; d2 += e * e; }
        dd = sqrt(d2);
        if (dd <= o->seg_r[s] + 1e-9 * o->c && dd < bd) { bd = dd; best = s; }
    }
    *bone = best;
    if (best >= 0) joint = o->joints[o->seg_child[best]].parent;
    for (a = 0; a < d->npin; a++)
        if (sb_region_has(o, &d->pins[a].r, p)) { joint = o->desc_to_sorted[d->pins[a].joint]; *bone = -2; }
    return joint;
}

/* trilinear weights W[k][kc] of the parent-level cell's corner kc at corner k of a
 * descendant cell whose corner 0 sits at offset off (grid units of the descendant's
 * level) inside a parent cell of s descendant edges */
static void descend_weights(const int off[3], int s, double W[8][8])
{
    int k, kc, a;
    for (k = 0; k < 8; k++)
        for (kc = 0; kc < 8; kc++) {
            double w = 1;
            for (a = 0; a < 3; a++) {
                double t = (double)(off[a] + (k >> a & 1)) / s;
                w *= (kc >> a & 1) ? t : 1.0 - t;
            }
            W[k][kc] = w;
        }
}

/* Me += W^T me W, Se += (W x I3)^T se (W x I3), with W (8 x nl) */
static void galerkin_add(const double *me, const double *se, const double (*W)[32], int nl, double *Me, double *Se, int ld)
{
    static double T[24][96];
    int a, b, i, j, A, B;
    double mt[8][32];
    for (a = 0; a < 8; a++)
        for (B = 0; B < nl; B++) {
            double s = 0;
            for (b = 0; b < 8; b++) s += me[8 * a + b] * W[b][B];
            mt[a][B] = s;
        }
    for (A = 0; A < nl; A++)
        for (B = 0; B < nl; B++) {
            double s = 0;
            for (a = 0; a < 8; a++) s += W[a][A] * mt[a][B];
            Me[ld * A + B] += s;
        }
    for (a = 0; a < 24; a++)
        for (B = 0; B < nl; B++)
            for (j = 0; j < 3; j++) {
                double s = 0;
                for (b = 0; b < 8; b++) s += se[24 * a + 3 * b + j] * W[b][B];
                T[a][3 * B + j] = s;
            }
    for (A = 0; A < nl; A++)
        for (i = 0; i < 3; i++)
            for (B = 0; B < 3 * nl; B++) {
                double s = 0;
                for (a = 0; a < 8; a++) s += W[a][A] * T[3 * a + i][B];
                Se[3 * ld * (3 * A + i) + B] += s;
            }
}

static int cmp_i64(const void *a, const void *b)
{
    long long x = *(const long long *)a, y = *(const long long *)b;
    return x < y ? -1 : x > y;
}

int sb_level_build(const sb_desc *d, const sb_mesh *m, const sb_model *o, int J, sb_hier *h)
{
    int j, k, c, v, n, *vmap[SB_LEVEL_MAX + 1], *vjoint[SB_LEVEL_MAX + 1], sub = d->subdiv, npt = sub * sub * sub * 8;
    int rc = -1, *fidx = NULL, nsurf = 0, ngcJ;
    double *frac = NULL;
    sb_lev *L;
    sb_model *fm = &h->fine;
    sb_inside in;

    memset(h, 0, sizeof *h);
    memset(vmap, 0, sizeof vmap); memset(vjoint, 0, sizeof vjoint);
    if (J < 1 || J > SB_LEVEL_MAX) return sb_fail("%s: levels: %d levels above the coarse one asked for, 1..%d allowed", d->path, J, SB_LEVEL_MAX);
    h->J = J;
    sb_inside_init(&in, m);

    /* level 0: the baked lattice */
    L = &h->lev[0];
    memcpy(L->gn, o->gn, sizeof L->gn); L->c = o->c; L->nv = o->nv; L->nc = o->nc;
    L->vgrid = sb_alloc(sizeof(int) * (size_t)o->nv); memcpy(L->vgrid, o->v_grid, sizeof(int) * (size_t)o->nv);
    L->x = sb_alloc(sizeof(double) * 3 * (size_t)o->nv); memcpy(L->x, o->x, sizeof(double) * 3 * (size_t)o->nv);
    L->cells = sb_alloc(sizeof(int) * 8 * (size_t)o->nc); memcpy(L->cells, o->cells, sizeof(int) * 8 * (size_t)o->nc);
    L->cell_parent = sb_alloc(sizeof(int) * (size_t)o->nc);
    L->cell_in = sb_alloc((size_t)o->nc);
    L->vold = sb_alloc(sizeof(int) * (size_t)o->nv);
    L->skel = sb_alloc((size_t)o->nv);
    L->vbone = sb_alloc(sizeof(int) * (size_t)o->nv);
    vjoint[0] = sb_alloc(sizeof(int) * (size_t)o->nv);
    vmap[0] = sb_alloc(sizeof(int) * (size_t)o->gn[0] * o->gn[1] * o->gn[2]);
    for (v = 0; v < o->gn[0] * o->gn[1] * o->gn[2]; v++) vmap[0][v] = -1;
    for (c = 0; c < o->nc; c++) L->cell_parent[c] = -1;
    for (v = 0; v < o->nv; v++) {
        L->vold[v] = -1; L->skel[v] = v >= o->nf; L->vbone[v] = o->vseg[v];
        vjoint[0][v] = o->gjoint[o->v_grid[v]];
        vmap[0][o->v_grid[v]] = v;
    }

    /* levels 1..J: every cell split into 8 */
    for (j = 1; j <= J; j++) {
        sb_lev *P = &h->lev[j - 1];
        int ngv;
        L = &h->lev[j];
        for (k = 0; k < 3; k++) L->gn[k] = 2 * (P->gn[k] - 1) + 1;
        L->c = 0.5 * P->c;
        ngv = L->gn[0] * L->gn[1] * L->gn[2];
        if ((double)L->gn[0] * L->gn[1] * L->gn[2] > 6e7 || (double)P->nc * 8 > 4e6)
            { sb_fail("%s: levels: level %d has %d cells (grid %dx%dx%d): too many; use fewer levels", d->path, j, 8 * P->nc, L->gn[0], L->gn[1], L->gn[2]); goto done; }
        vmap[j] = sb_alloc(sizeof(int) * (size_t)ngv);
        for (v = 0; v < ngv; v++) vmap[j][v] = -1;
        L->nc = 8 * P->nc;
        L->cells = sb_alloc(sizeof(int) * 8 * (size_t)L->nc);
        L->cell_parent = sb_alloc(sizeof(int) * (size_t)L->nc);
        L->cell_in = sb_alloc((size_t)L->nc);
        for (c = 0; c < P->nc; c++) {
            int a0[3], ch;
            gcoord(P->gn, P->vgrid[P->cells[8 * c]], a0);
            for (ch = 0; ch < 8; ch++) {
                int cc = 8 * c + ch;
                L->cell_parent[cc] = c;
                for (k = 0; k < 8; k++) {
                    int g[3], gi;
                    for (n = 0; n < 3; n++) g[n] = 2 * a0[n] + (ch >> n & 1) + (k >> n & 1);
                    gi = gindex(L->gn, g);
                    if (vmap[j][gi] < 0) vmap[j][gi] = L->nv++;
                    L->cells[8 * cc + k] = vmap[j][gi];
                }
            }
        }
        L->vgrid = sb_alloc(sizeof(int) * (size_t)L->nv);
        L->x = sb_alloc(sizeof(double) * 3 * (size_t)L->nv);
        L->vold = sb_alloc(sizeof(int) * (size_t)L->nv);
        L->skel = sb_alloc((size_t)L->nv);
        L->vbone = sb_alloc(sizeof(int) * (size_t)L->nv);
        vjoint[j] = sb_alloc(sizeof(int) * (size_t)L->nv);
        for (v = 0; v < ngv; v++)
            if (vmap[j][v] >= 0) L->vgrid[vmap[j][v]] = v;
        for (v = 0; v < L->nv; v++) {
            int g[3];
            gcoord(L->gn, L->vgrid[v], g);
            for (k = 0; k < 3; k++) L->x[3 * v + k] = o->gorg[k] + g[k] * L->c;
            L->vold[v] = -1;
            if (!(g[0] & 1) && !(g[1] & 1) && !(g[2] & 1)) {
                int gp[3] = {g[0] / 2, g[1] / 2, g[2] / 2};
                L->vold[v] = vmap[j - 1][gindex(P->gn, gp)];
                if (L->vold[v] < 0) { sb_fail("%s: levels: internal error: an even vertex of level %d has no parent", d->path, j); goto done; }
            }
            if (L->vold[v] >= 0) {   /* the same point: the same joint */
                L->skel[v] = P->skel[L->vold[v]]; L->vbone[v] = P->vbone[L->vold[v]]; vjoint[j][v] = vjoint[j - 1][L->vold[v]];
            } else {
                vjoint[j][v] = capture(d, o, L->x + 3 * v, &L->vbone[v]);
                L->skel[v] = vjoint[j][v] >= 0;
                if (!L->skel[v]) L->vbone[v] = -1;
            }
        }
    }

    /* the finest level as a flat lattice: inside fractions (as sb_build step 3) and integrals */
    L = &h->lev[J];
    memset(fm, 0, sizeof *fm);
    fm->quiet = 1; fm->unit = o->unit; fm->c = L->c;
    memcpy(fm->gn, L->gn, sizeof fm->gn); memcpy(fm->gorg, o->gorg, sizeof fm->gorg);
    fm->nj = o->nj; fm->joints = o->joints; fm->desc_to_sorted = o->desc_to_sorted; fm->nseg = o->nseg; fm->seg_child = o->seg_child;   /* borrowed */
    fm->nv = L->nv; fm->nc = L->nc;
    fm->x = L->x; fm->cells = L->cells;   /* borrowed */
    ngcJ = (L->gn[0] - 1) * (L->gn[1] - 1) * (L->gn[2] - 1);
    fm->gpos = sb_alloc(sizeof(double) * 3 * (size_t)L->gn[0] * L->gn[1] * L->gn[2]);
    for (v = 0; v < L->gn[0] * L->gn[1] * L->gn[2]; v++) {
        int g[3];
        gcoord(L->gn, v, g);
        for (k = 0; k < 3; k++) fm->gpos[3 * v + k] = o->gorg[k] + g[k] * L->c;
    }
    fm->cell_grid = sb_alloc(sizeof(int) * (size_t)L->nc);
    fidx = sb_alloc(sizeof(int) * (size_t)ngcJ);
    for (c = 0; c < ngcJ; c++) fidx[c] = -1;
    {
        int nx = L->gn[0] - 1, ny = L->gn[1] - 1, t;
        for (c = 0; c < L->nc; c++) {
            int g[3];
            gcoord(L->gn, L->vgrid[L->cells[8 * c]], g);
            fm->cell_grid[c] = g[0] + nx * (g[1] + ny * g[2]);
            fidx[fm->cell_grid[c]] = -3;   /* a lattice cell, not yet classified */
        }
        for (t = 0; t < m->nt; t++) {   /* cells in a triangle's bounding box: ray fractions */
            int lo3[3], hi3[3], x, y, z;
            for (k = 0; k < 3; k++) {
                const double *v0 = m->v + 3 * m->tri[3 * t], *v1 = m->v + 3 * m->tri[3 * t + 1], *v2 = m->v + 3 * m->tri[3 * t + 2];
                double lo = fmin(v0[k], fmin(v1[k], v2[k])), hi = fmax(v0[k], fmax(v1[k], v2[k]));
                lo3[k] = (int)floor((lo - o->gorg[k]) / L->c - 1e-9); hi3[k] = (int)floor((hi - o->gorg[k]) / L->c + 1e-9);
                lo3[k] = lo3[k] < 0 ? 0 : lo3[k]; hi3[k] = hi3[k] > L->gn[k] - 2 ? L->gn[k] - 2 : hi3[k];
            }
            for (z = lo3[2]; z <= hi3[2]; z++) for (y = lo3[1]; y <= hi3[1]; y++) for (x = lo3[0]; x <= hi3[0]; x++) {
                int gc = x + nx * (y + ny * z);
                if (fidx[gc] == -3) fidx[gc] = -4;
            }
        }
        for (c = 0; c < L->nc; c++) {
            int gc = fm->cell_grid[c];
            if (fidx[gc] == -4) fidx[gc] = nsurf++;
            else if (fidx[gc] == -3) {
                double p[3];
                for (k = 0; k < 3; k++) p[k] = L->x[3 * L->cells[8 * c] + k] + 0.5 * L->c;
                fidx[gc] = sb_inside_test(&in, p) ? -2 : -1;
            }
        }
    }
    frac = sb_alloc(sizeof(double) * (size_t)npt * (size_t)(nsurf ? nsurf : 1));
    sb_box_fractions(fm, m, &in, sub, fidx, frac, -1);
    for (c = 0; c < L->nc; c++) {
        int gc = fm->cell_grid[c], q;
        if (fidx[gc] >= 0) {
            double *f = frac + (size_t)fidx[gc] * (size_t)npt, s = 0;
            for (q = 0; q < npt; q++) { f[q] = f[q] > 1 ? 1 : f[q]; s += f[q]; }
            L->cell_in[c] = s > 0;
        } else L->cell_in[c] = fidx[gc] == -2;
    }
    for (j = J; j > 0; j--)   /* a cell holds interior if a child does */
        for (c = 0; c < h->lev[j].nc; c++) if (h->lev[j].cell_in[c]) h->lev[j - 1].cell_in[h->lev[j].cell_parent[c]] = 1;
    pattern(fm->nv, fm->nc, fm->cells, &fm->nbptr, &fm->nb);
    fm->M = sb_alloc(sizeof(double) * (size_t)fm->nbptr[fm->nv]);
    fm->S = sb_alloc(sizeof(double) * 9 * (size_t)fm->nbptr[fm->nv]);
    fm->Se = sb_alloc(sizeof(double) * 576 * (size_t)fm->nc);
    fm->Me = sb_alloc(sizeof(double) * 64 * (size_t)fm->nc);
    if (sb_integrate_frac(d, fm, frac, fidx)) goto done;
    h->mass = fm->mass;

    /* each level's nodal matrices: Galerkin products of the finest cells' elements */
    for (j = 0; j <= J; j++) {
        sb_lev *Lj = &h->lev[j];
        int s = 1 << (J - j), f;
        Lj->Me = sb_alloc(sizeof(double) * 64 * (size_t)Lj->nc);
        Lj->Se = sb_alloc(sizeof(double) * 576 * (size_t)Lj->nc);
        for (f = 0; f < L->nc; f++) {
            int C = f, l, off[3], gf[3], gC[3];
            double W[8][32];
            double W8[8][8];
            for (l = J; l > j; l--) C = h->lev[l].cell_parent[C];
            gcoord(L->gn, L->vgrid[L->cells[8 * f]], gf);
            gcoord(Lj->gn, Lj->vgrid[Lj->cells[8 * C]], gC);
            for (k = 0; k < 3; k++) off[k] = gf[k] - s * gC[k];
            descend_weights(off, s, W8);
            for (k = 0; k < 8; k++) for (l = 0; l < 8; l++) W[k][l] = W8[k][l];
            galerkin_add(fm->Me + 64 * (size_t)f, fm->Se + 576 * (size_t)f, (const double (*)[32])W, 8, Lj->Me + 64 * (size_t)C, Lj->Se + 576 * (size_t)C, 8);
        }
        pattern(Lj->nv, Lj->nc, Lj->cells, &Lj->nbptr, &Lj->nb);
        Lj->M = sb_alloc(sizeof(double) * (size_t)Lj->nbptr[Lj->nv]);
        Lj->S = sb_alloc(sizeof(double) * 9 * (size_t)Lj->nbptr[Lj->nv]);
        for (c = 0; c < Lj->nc; c++)
            for (k = 0; k < 8; k++)
                for (n = 0; n < 8; n++) {
                    int e = sb_level_find(Lj->nbptr, Lj->nb, Lj->cells[8 * c + k], Lj->cells[8 * c + n]), a, b;
                    Lj->M[e] += Lj->Me[64 * (size_t)c + (size_t)(8 * k + n)];
                    for (a = 0; a < 3; a++)
                        for (b = 0; b < 3; b++) Lj->S[9 * (size_t)e + (size_t)(3 * a + b)] += Lj->Se[576 * (size_t)c + (size_t)(24 * (3 * k + a) + 3 * n + b)];
                }
    }

    /* hierarchical functions: level-0 vertices, then each level's new vertices */
    {
        int *hid[SB_LEVEL_MAX + 1];
        memset(hid, 0, sizeof hid);
        h->nh = 0;
        for (j = 0; j <= J; j++) for (v = 0; v < h->lev[j].nv; v++) h->nh += j == 0 || h->lev[j].vold[v] < 0;
        h->hlev = sb_alloc(sizeof(int) * (size_t)h->nh);
        h->hvert = sb_alloc(sizeof(int) * (size_t)h->nh);
        h->in_b = sb_alloc((size_t)h->nh);
        for (j = 0, n = 0; j <= J; j++) {
            sb_lev *Lj = &h->lev[j];
            unsigned char *touch = sb_alloc((size_t)Lj->nv);
            hid[j] = sb_alloc(sizeof(int) * (size_t)Lj->nv);
            for (c = 0; c < Lj->nc; c++) if (Lj->cell_in[c]) for (k = 0; k < 8; k++) touch[Lj->cells[8 * c + k]] = 1;
            for (v = 0; v < Lj->nv; v++) {
                hid[j][v] = -1;
                if (j > 0 && Lj->vold[v] >= 0) continue;
                hid[j][v] = n; h->hlev[n] = j; h->hvert[n] = v;
                h->in_b[n] = j == 0 || (touch[v] && !Lj->skel[v]);
                h->nb_fun += h->in_b[n]; h->nb_lev[j] += h->in_b[n];
                if (j > 0 && Lj->skel[v]) {   /* does interpolation from level j-1 give the bone's motion? */
                    sb_lev *Pj = &h->lev[j - 1];
                    int g[3], lo[3], hi[3], x, y, z, same = 1;
                    h->skel_new[j]++;
                    gcoord(Lj->gn, Lj->vgrid[v], g);
                    for (k = 0; k < 3; k++) { lo[k] = g[k] / 2; hi[k] = (g[k] + 1) / 2; }
                    for (z = lo[2]; z <= hi[2]; z++) for (y = lo[1]; y <= hi[1]; y++) for (x = lo[0]; x <= hi[0]; x++) {
                        int gp[3] = {x, y, z}, pv = vmap[j - 1][gindex(Pj->gn, gp)];
                        if (pv < 0 || vjoint[j - 1][pv] != vjoint[j][v]) same = 0;
                    }
                    h->skel_differ[j] += !same;
                }
                n++;
            }
            free(touch);
        }
        /* prolongation rows: the finest vertex's value of every function non-zero there */
        h->pptr = sb_alloc(sizeof(int) * (size_t)(L->nv + 1));
        h->pidx = sb_alloc(sizeof(int) * (size_t)L->nv * 8 * (size_t)(J + 1));
        h->pval = sb_alloc(sizeof(double) * (size_t)L->nv * 8 * (size_t)(J + 1));
        for (n = 0; n < L->nv; n++) {
            int g[3], e = h->pptr[n];
            gcoord(L->gn, L->vgrid[n], g);
            for (j = 0; j <= J; j++) {
                int s = 1 << (J - j), lo[3], hi[3], x, y, z;
                for (k = 0; k < 3; k++) { lo[k] = g[k] / s; hi[k] = (g[k] + s - 1) / s; }
                for (z = lo[2]; z <= hi[2]; z++) for (y = lo[1]; y <= hi[1]; y++) for (x = lo[0]; x <= hi[0]; x++) {
                    int gv[3] = {x, y, z}, lv = vmap[j][gindex(h->lev[j].gn, gv)];
                    double w;
                    if (lv < 0) { sb_fail("%s: levels: internal error: a level-%d vertex is missing", d->path, j); goto hid_done; }
                    if (hid[j][lv] < 0) continue;   /* an old vertex: its function belongs to a coarser level */
                    w = sb_level_hat(h, j, lv, n);
                    if (w == 0) continue;
                    h->pidx[e] = hid[j][lv]; h->pval[e] = w; e++;
                }
            }
            h->pptr[n + 1] = e;
        }
        rc = 0;
    hid_done:
        for (j = 0; j <= J; j++) free(hid[j]);
        if (rc) goto done;
        rc = -1;
    }

    /* hierarchical Galerkin matrices: per finest cell, P_c^T K_e P_c over the functions on it */
    {
        long long *keys, nk = 0, e2;
        int f, maxl = 8 + 7 * J, ne;   /* per finest cell: the 8 coarse hats, at most 7 new vertices per level */
        int *lf = sb_alloc(sizeof(int) * (size_t)maxl);
        double (*W)[32] = sb_alloc(sizeof(double) * 8 * 32);
        double *Ml = sb_alloc(sizeof(double) * 32 * 32), *Sl = sb_alloc(sizeof(double) * 96 * 96);
        keys = sb_alloc(sizeof(long long) * (size_t)L->nc * (size_t)maxl * (size_t)maxl);
        for (f = 0; f < L->nc; f++) {   /* pass 1: the pattern */
            int nl = 0, a, b, e;
            for (k = 0; k < 8; k++)
                for (e = h->pptr[L->cells[8 * f + k]]; e < h->pptr[L->cells[8 * f + k] + 1]; e++) {
                    for (a = 0; a < nl && lf[a] != h->pidx[e]; a++) {}
                    if (a == nl) lf[nl++] = h->pidx[e];
                }
            for (a = 0; a < nl; a++) for (b = 0; b < nl; b++) keys[nk++] = (long long)lf[a] * h->nh + lf[b];
        }
        qsort(keys, (size_t)nk, sizeof *keys, cmp_i64);
        h->hbptr = sb_alloc(sizeof(int) * (size_t)(h->nh + 1));
        for (e2 = 0, ne = 0; e2 < nk; e2++) if (e2 == 0 || keys[e2] != keys[e2 - 1]) keys[ne++] = keys[e2];
        h->hb = sb_alloc(sizeof(int) * (size_t)ne);
        for (e2 = 0; e2 < ne; e2++) { h->hb[e2] = (int)(keys[e2] % h->nh); h->hbptr[keys[e2] / h->nh + 1]++; }
        for (n = 0; n < h->nh; n++) h->hbptr[n + 1] += h->hbptr[n];
        free(keys);
        h->Mh = sb_alloc(sizeof(double) * (size_t)ne);
        h->Sh = sb_alloc(sizeof(double) * 9 * (size_t)ne);
        h->gh = sb_alloc(sizeof(double) * (size_t)h->nh);
        for (f = 0; f < L->nc; f++) {   /* pass 2: the products */
            int nl = 0, a, b, e;
            memset(W, 0, sizeof(double) * 8 * 32);
            for (k = 0; k < 8; k++)
                for (e = h->pptr[L->cells[8 * f + k]]; e < h->pptr[L->cells[8 * f + k] + 1]; e++) {
                    for (a = 0; a < nl && lf[a] != h->pidx[e]; a++) {}
                    if (a == nl) lf[nl++] = h->pidx[e];
                    W[k][a] = h->pval[e];
                }
            memset(Ml, 0, sizeof(double) * 32 * 32); memset(Sl, 0, sizeof(double) * 96 * 96);
            galerkin_add(fm->Me + 64 * (size_t)f, fm->Se + 576 * (size_t)f, (const double (*)[32])W, nl, Ml, Sl, 32);
            for (a = 0; a < nl; a++) {
                double row = 0;
                for (k = 0; k < 8; k++) for (b = 0; b < 8; b++) row += W[k][a] * fm->Me[64 * (size_t)f + (size_t)(8 * k + b)];
                h->gh[lf[a]] += row;   /* int rho phi_a dV = phi_a^T M_e 1: the finest hats sum to 1 */
                for (b = 0; b < nl; b++) {
                    int i, jj, pe = sb_level_find(h->hbptr, h->hb, lf[a], lf[b]);
                    h->Mh[pe] += Ml[32 * a + b];
                    for (i = 0; i < 3; i++) for (jj = 0; jj < 3; jj++) h->Sh[9 * (size_t)pe + (size_t)(3 * i + jj)] += Sl[96 * (3 * a + i) + 3 * b + jj];
                }
            }
        }
        rc = 0;
        free(lf); free(W); free(Ml); free(Sl);
    }
done:
    for (j = 0; j <= SB_LEVEL_MAX; j++) { free(vmap[j]); free(vjoint[j]); }
    free(fidx); free(frac);
    sb_inside_free(&in);
    return rc;
}

void sb_hier_free(sb_hier *h)
{
    int j;
    for (j = 0; j <= SB_LEVEL_MAX; j++) {
        sb_lev *L = &h->lev[j];
        free(L->vgrid); free(L->x); free(L->cells); free(L->cell_parent); free(L->cell_in); free(L->vold); free(L->skel); free(L->vbone);
        free(L->nbptr); free(L->nb); free(L->M); free(L->S); free(L->Me); free(L->Se);
    }
    /* the fine model borrows x, cells and the skeleton from the levels and the coarse model */
    free(h->fine.gpos); free(h->fine.cell_grid); free(h->fine.nbptr); free(h->fine.nb); free(h->fine.M); free(h->fine.S);
    free(h->fine.Se); free(h->fine.Me);
    free(h->hlev); free(h->hvert); free(h->in_b); free(h->pptr); free(h->pidx); free(h->pval);
    free(h->hbptr); free(h->hb); free(h->Mh); free(h->Sh); free(h->gh);
    memset(h, 0, sizeof *h);
}

/* ---- level of detail: the finer level as a complete blob (sb_bake_file, 'levels 2') ---- */

/* each point in a kept cell of L: the grid cell holding it (a point on a cell face may take
 * the kept neighbour), else the nearest kept cell with t clamped to it; {cell, t Q15} x n.
 * Returns the points that needed the nearest cell. */
static int embed_points(const sb_model *L, const double *pts, int n, uint16_t *out)
{
    int nx = L->gn[0] - 1, ny = L->gn[1] - 1, ngc = nx * ny * (L->gn[2] - 1), i, k, c, far = 0;
    int *g2c = sb_alloc(sizeof(int) * (size_t)ngc);
    for (c = 0; c < ngc; c++) g2c[c] = -1;
    for (c = 0; c < L->nc; c++) g2c[L->cell_grid[c]] = c;
    for (i = 0; i < n; i++) {
        const double *p = pts + 3 * i;
        double u[3], t[3];
        int lo[3], hi[3], best = -1, x, y, z;
        for (k = 0; k < 3; k++) {
            double r;
            u[k] = (p[k] - L->gorg[k]) / L->c;
            r = floor(u[k] + 0.5);
            if (fabs(u[k] - r) < 1e-9) { lo[k] = (int)r - 1; hi[k] = (int)r; }   /* on a grid plane: either side */
            else lo[k] = hi[k] = (int)floor(u[k]);
        }
        for (z = lo[2]; z <= hi[2] && best < 0; z++)
            for (y = lo[1]; y <= hi[1] && best < 0; y++)
                for (x = lo[0]; x <= hi[0] && best < 0; x++)
                    if (x >= 0 && y >= 0 && z >= 0 && x < nx && y < ny && z < L->gn[2] - 1 && g2c[x + nx * (y + ny * z)] >= 0)
                        best = g2c[x + nx * (y + ny * z)];
        if (best < 0) {   /* outside every kept cell: the nearest one */
            double bd = HUGE_VAL;
            far++;
            for (c = 0; c < L->nc; c++) {
                const double *x0 = L->x + 3 * L->cells[8 * c];
                double dd = 0;
                for (k = 0; k < 3; k++) {
                    double e = p[k] < x0[k] ? x0[k] - p[k] : p[k] > x0[k] + L->c ? p[k] - x0[k] - L->c : 0;
                    dd += e * e;
                }
                if (dd < bd) { bd = dd; best = c; }
            }
        }
        for (k = 0; k < 3; k++) {
            t[k] = (p[k] - L->x[3 * L->cells[8 * best] + k]) / L->c;
            t[k] = t[k] < 0 ? 0 : t[k] > 1 ? 1 : t[k];
        }
        out[4 * i] = (uint16_t)best;
        for (k = 0; k < 3; k++) out[4 * i + 1 + k] = (uint16_t)floor(t[k] * 32768.0 + 0.5);
    }
    free(g2c);
    return far;
}

static uint32_t inst_bytes(const sb_model *o, int nV, int nF, int nC, int nFP)
{
    return SN_INSTANCE_BYTES((uint32_t)nV, (uint32_t)nF, (uint32_t)o->nj, (uint32_t)nC, (uint32_t)o->nctl, (uint32_t)o->max_forces,
                             sb_segment_state_bytes(o) + (o->crease ? SN_CREASE_STATE_BYTES(o->ns, o->cr_list) : 0u) +
                                 (uint32_t)nFP * SN_FPAIR_BYTES,
                             (o->max_cons || o->max_cols || o->max_contacts || o->crease)
                                 ? SN_CONS_BYTES(o->max_cons, o->max_cols, SN_ROWS_CAP(o->max_cons, o->max_contacts, o->crease ? o->cr_active : 0))
                                 : 0u);
}

void sb_level_desc(const sb_desc *d, const sb_model *o, sb_desc *d2)
{
    int i;
    *d2 = *d;   /* shallow: only cell, origin, blend and crease differ */
    d2->cell = 0.5 * o->c;
    d2->has_origin = 1;
    for (i = 0; i < 3; i++) d2->origin[i] = o->gorg[i];   /* the coarse grid's corner: every coarse vertex is a fine one */
    d2->blend = d->blend > 0 ? d->blend : d->cell;        /* the same frames */
    d2->ncrease = 0;                                      /* the crease data is the surface's: shared */
    d2->lod_level = 1;
}

int sb_level_model(const sb_desc *d, const sb_desc *d2, const sb_mesh *m, sb_model *o2)
{
    /* bones: given radii stay; automatic ones are re-derived at the finer cell (at least 1.25 cells, so a
     * thin limb keeps free flesh: with the coarse radii, rigs on thin parts touch no free vertex) */
    if (sb_build(d2, m, o2, 1) || sb_rig_build(d2, m, o2) || sb_force_build(d2, o2) || sb_segment_build(d2, m, o2)) {
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", sb_error());
        return sb_fail("%s:%d: levels 2: the subdivided lattice (cell %g): %s", d->path, d->levels_line, d2->cell, msg);
    }
    return 0;
}

int sb_level_bake(const sb_desc *d, const sb_mesh *m, sb_model *o, int flavour, int quiet, sb_blob *b, sb_lodinfo *info)
{
    sb_desc d2;
    sb_model o2;
    sb_blob b0, b1;
    sb_cut cut;
    uint16_t *up = NULL, *down = NULL;
    int rc = -1, nF, nS, nC, np0, np1;
    memset(&o2, 0, sizeof o2); memset(&b0, 0, sizeof b0); memset(&b1, 0, sizeof b1); memset(&cut, 0, sizeof cut);
    sb_level_desc(d, o, &d2);
    if (sb_level_model(d, &d2, m, &o2)) goto done;
    if (d->levels_cut) {   /* level 0 becomes the cut level: its hats cut at level 1's skeleton (sb_cut.c) */
        /* surface points, segment attachments and the constraint, contact and crease rows follow the cut field
         * (sn_surface_point, sn_point_weights); adaptation's coarse field is trilinear: refused */
        if (d->adapt_line) { sb_fail("%s:%d: levels 2 cut: adaptation ('adapt') is not supported on the cut level (remove it or 'cut')", d->path, d->levels_line); goto done; }
        if (sb_cut_build(o, &o2, d->air, &cut)) goto done;
        sb_cut_apply(d, o, &o2, &cut);
        info->cut_nx = cut.nx; info->cut_freed = cut.nfreed; info->cut_air = cut.nair; info->cut_lost = cut.nlost;
    }
    /* shared surface data */
    o2.crease = o->crease; o2.cr_nD = o->cr_nD; o2.cr_pairs = o->cr_pairs; o2.cr_kv = o->cr_kv; o2.cr_kt = o->cr_kt; o2.cr_nq = o->cr_nq;
    o2.cr_vnbr = o->cr_vnbr; o2.cr_tnbr = o->cr_tnbr; o2.cr_list = o->cr_list; o2.cr_active = o->cr_active;
    o2.cr_depth = o->cr_depth; o2.cr_push = o->cr_push; o2.cr_exclude = o->cr_exclude;
    if (sb_blob_make(&o2, flavour, &b1) || sb_blob_make(o, flavour, &b0)) goto done;
    if (b0.len_shift != b1.len_shift) {   /* one length unit for both: the state is carried between them */
        o->lshift_set = o2.lshift_set = 1;
        o->lshift = o2.lshift = b0.len_shift > b1.len_shift ? b0.len_shift : b1.len_shift;
        sb_blob_free(&b1);
        if (sb_blob_make(&o2, flavour, &b1)) goto done;
    }
    up = sb_alloc(sizeof(uint16_t) * 4 * (size_t)o2.nv);
    down = sb_alloc(sizeof(uint16_t) * 4 * (size_t)o->nv);
    info->up_far = embed_points(o, o2.x, o2.nv, up);
    info->down_far = embed_points(&o2, o->x, o->nv, down);
    info->nv1 = o2.nv; info->nf1 = o2.nf; info->nc1 = o2.nc; info->size1 = (uint32_t)b1.size;
    nF = o->nf > o2.nf ? o->nf : o2.nf;
    nS = o->nv - o->nf > o2.nv - o2.nf ? o->nv - o->nf : o2.nv - o2.nf;
    nC = o->nc > o2.nc ? o->nc : o2.nc;
    o->lod_blob = b1.bytes; o->lod_size = (uint32_t)b1.size; o->lod_nv1 = (uint32_t)o2.nv;
    o->lod_up = up; o->lod_down = down;
    np0 = sb_frame_refs(o, NULL, NULL); np1 = sb_frame_refs(&o2, NULL, NULL);   /* the frame pairs' scratch: the larger level's */
    o->lod_inst_bytes = inst_bytes(o, nF + nS, nF, nC, np0 > np1 ? np0 : np1);
    info->inst0 = inst_bytes(o, o->nv, o->nf, o->nc, np0); info->inst1 = inst_bytes(&o2, o2.nv, o2.nf, o2.nc, np1);
    info->inst = o->lod_inst_bytes;
    if (d->adapt_line) {   /* adaptation of level 1 (sn_adapt.c): A_max within its free vertices, thresholds in level-0 cells */
        if (o->nv > o2.nf) {
            sb_fail("%s:%d: adapt: level 0's %d vertices exceed level 1's %d free vertices (the runtime's scratch)", d->path, d->adapt_line, o->nv, o2.nf);
            goto done;
        }
        o->ad_on = 1; o->ad_max = d->adapt_max < o2.nf ? d->adapt_max : o2.nf; /* at most every free vertex */
        o->ad_refine = d->adapt_refine * o->c; o->ad_coarsen = d->adapt_coarsen * o->c;
    }
    if (d->details_line && d->levels_cut) {   /* the cut level's details (sb_cut.h): A_max within them, thresholds in level-0 cells */
        if (cut.nd == 0) { sb_fail("%s:%d: details: the cut level has none (no free level-1 vertex inside a level-0 cell)", d->path, d->details_line); goto done; }
        o->det_on = 1; o->det_max = d->details_max < cut.nd ? d->details_max : cut.nd;
        o->det_refine = d->details_refine * o->c; o->det_coarsen = d->details_coarsen * o->c;
        info->cut_nd = cut.nd;
    }
    rc = sb_blob_make(o, flavour, b);
    o->lod_blob = NULL; o->lod_size = 0; o->lod_up = o->lod_down = NULL; o->ad_on = 0; o->det_on = 0;
    (void)quiet;
done:
    o2.cr_pairs = NULL; o2.cr_vnbr = o2.cr_tnbr = NULL; o2.crease = 0;   /* borrowed */
    sb_model_free(&o2);
    sb_blob_free(&b0); sb_blob_free(&b1);
    o->cut = NULL; sb_cut_free(&cut);
    free(up); free(down);
    return rc;
}
