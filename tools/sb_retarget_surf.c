/* sb_retarget_surf.c -- rig retargeting (seed 003 §4.4): closest points on a
 * triangle surface (a bucket grid searched in shells) and the mapped surface's
 * point terms, rebuilt between rounds (sb_rt_update_surface). */
#include "sb_retarget_int.h"
#include "sb_lbfgsb.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------- closest points ---------------- */

/* closest point of triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5):
 * barycentric weights out, returns the squared distance */
static double closest_tri(const double *p, const double *a, const double *b, const double *c, double bw[3])
{
    double ab[3], ac[3], ap[3], bp[3], cp[3], d1, d2, d3, d4, d5, d6, va, vb, vc, v, w, q[3];
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ac[k] = c[k] - a[k]; ap[k] = p[k] - a[k]; }
    d1 = dot3(ab, ap); d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) { bw[0] = 1; bw[1] = 0; bw[2] = 0; goto done; }
    for (k = 0; k < 3; k++) bp[k] = p[k] - b[k];
    d3 = dot3(ab, bp); d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) { bw[0] = 0; bw[1] = 1; bw[2] = 0; goto done; }
    vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) { v = d1 / (d1 - d3); bw[0] = 1 - v; bw[1] = v; bw[2] = 0; goto done; }
    for (k = 0; k < 3; k++) cp[k] = p[k] - c[k];
    d5 = dot3(ab, cp); d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) { bw[0] = 0; bw[1] = 0; bw[2] = 1; goto done; }
    vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) { w = d2 / (d2 - d6); bw[0] = 1 - w; bw[1] = 0; bw[2] = w; goto done; }
    va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        w = (d4 - d3) / ((d4 - d3) + (d5 - d6)); bw[0] = 0; bw[1] = 1 - w; bw[2] = w; goto done;
    }
    {
        double den = 1 / (va + vb + vc);
        v = vb * den; w = vc * den; bw[0] = 1 - v - w; bw[1] = v; bw[2] = w;
    }
done:
    for (k = 0; k < 3; k++) q[k] = bw[0] * a[k] + bw[1] * b[k] + bw[2] * c[k] - p[k];
    return dot3(q, q);
}

static int gclamp(int v, int n) { return v < 0 ? 0 : v >= n ? n - 1 : v; }

void sb_rt_tri_index_make(tri_index *x, const double *P, const int *tri, int nt)
{
    double hi[3], ext = 0, vol = 1;
    int t, k, a, ncell, *cnt;
    memset(x, 0, sizeof *x);
    x->nt = nt; x->tri = tri; x->P = P;
    x->box = sb_alloc(sizeof(double) * 6 * (size_t)nt);
    for (a = 0; a < 3; a++) { x->lo[a] = 1e300; hi[a] = -1e300; }
    for (t = 0; t < nt; t++)
        for (a = 0; a < 3; a++) {
            double lo = 1e300, hh = -1e300;
            for (k = 0; k < 3; k++) { double v = P[3 * tri[3 * t + k] + a]; if (v < lo) lo = v; if (v > hh) hh = v; }
            x->box[6 * t + a] = lo; x->box[6 * t + 3 + a] = hh;
            if (lo < x->lo[a]) x->lo[a] = lo;
            if (hh > hi[a]) hi[a] = hh;
        }
    for (a = 0; a < 3; a++) { ext = fmax(ext, hi[a] - x->lo[a]); vol *= fmax(hi[a] - x->lo[a], 1e-300); }
    /* about one triangle per cell, at most 64 cells per axis */
    x->h = fmax(cbrt(vol / (nt > 0 ? nt : 1)), ext / 64);
    if (!(x->h > 0)) x->h = 1;
    for (a = 0; a < 3; a++) x->n[a] = gclamp((int)((hi[a] - x->lo[a]) / x->h) + 1, 65);
    ncell = x->n[0] * x->n[1] * x->n[2];
    x->start = sb_alloc(sizeof(int) * (size_t)(ncell + 1));
    cnt = sb_alloc(sizeof(int) * (size_t)(ncell + 1));
    for (k = 0; k < 2; k++) {   /* count, then fill */
        for (t = 0; t < nt; t++) {
            int c0[3], c1[3], i, j, l;
            for (a = 0; a < 3; a++) {
                c0[a] = gclamp((int)floor((x->box[6 * t + a] - x->lo[a]) / x->h), x->n[a]);
                c1[a] = gclamp((int)floor((x->box[6 * t + 3 + a] - x->lo[a]) / x->h), x->n[a]);
            }
            for (l = c0[2]; l <= c1[2]; l++)
                for (j = c0[1]; j <= c1[1]; j++)
                    for (i = c0[0]; i <= c1[0]; i++) {
                        int c = i + x->n[0] * (j + x->n[1] * l);
                        if (k == 0) x->start[c + 1]++;
                        else x->items[x->start[c] + cnt[c]++] = t;
                    }
        }
        if (k == 0) {
            for (t = 0; t < ncell; t++) x->start[t + 1] += x->start[t];
            x->items = sb_alloc(sizeof(int) * (size_t)(x->start[ncell] + 1));
        }
    }
    free(cnt);
}

void sb_rt_tri_index_free(tri_index *x)
{
    free(x->box); free(x->start); free(x->items);
    memset(x, 0, sizeof *x);
}

static void tri_test(const tri_index *x, int t, const double p[3], double *best, int *bt, double bw[3])
{
    const double *bx = x->box + 6 * t;
    double d = 0, e, w[3], dd;
    int a;
    for (a = 0; a < 3; a++) {
        e = p[a] < bx[a] ? bx[a] - p[a] : p[a] > bx[3 + a] ? p[a] - bx[3 + a] : 0;
        d += e * e;
    }
    if (d > *best) return;
    dd = closest_tri(p, x->P + 3 * x->tri[3 * t], x->P + 3 * x->tri[3 * t + 1], x->P + 3 * x->tri[3 * t + 2], w);
    /* ties: the lower triangle index, so the answer does not depend on the visiting order */
    if (dd < *best || (dd == *best && t < *bt)) { *best = dd; *bt = t; memcpy(bw, w, 3 * sizeof(double)); }
}

int sb_rt_tri_closest(const tri_index *x, const double p[3], double bw[3])
{
    double best = 1e300;
    int bt = -1, c[3], a, r, rmax = 0;
    for (a = 0; a < 3; a++) {
        c[a] = gclamp((int)floor((p[a] - x->lo[a]) / x->h), x->n[a]);
        rmax = c[a] > rmax ? c[a] : rmax;
        rmax = x->n[a] - 1 - c[a] > rmax ? x->n[a] - 1 - c[a] : rmax;
    }
    for (r = 0; r <= rmax; r++) {
        int i, j, l;
        for (l = c[2] - r; l <= c[2] + r; l++) {
            if (l < 0 || l >= x->n[2]) continue;
            for (j = c[1] - r; j <= c[1] + r; j++) {
                if (j < 0 || j >= x->n[1]) continue;
                for (i = c[0] - r; i <= c[0] + r; i++) {
                    int cc, q;
                    if (i < 0 || i >= x->n[0]) continue;
                    if (abs(i - c[0]) != r && abs(j - c[1]) != r && abs(l - c[2]) != r) continue;   /* the shell only */
                    cc = i + x->n[0] * (j + x->n[1] * l);
                    for (q = x->start[cc]; q < x->start[cc + 1]; q++) tri_test(x, x->items[q], p, &best, &bt, bw);
                }
            }
        }
        /* every triangle not yet seen lies in cells at least r cells away: farther than r h */
        if (bt >= 0 && best < (r * x->h) * (r * x->h)) break;
    }
    return bt;
}

void sb_rt_embed_point(const sb_model *o, const double *P, int k, double out[3])
{
    double N[8];
    int c, a;
    sb_shape(o->emb_t + 3 * k, N, NULL);
    out[0] = out[1] = out[2] = 0;
    for (c = 0; c < 8; c++)
        for (a = 0; a < 3; a++) out[a] += N[c] * P[3 * o->cells[8 * o->emb_cell[k] + c] + a];
}

/* mapped position of A's surface vertex k */
void sb_rt_mapped_surface_point(const sb_retarget *rt, int k, double out[3]) { sb_rt_embed_point(rt->A, rt->h, k, out); }

int sb_rt_update_surface(sb_retarget *rt)
{
    const sb_model *A = rt->A;
    const sb_mesh *mA = rt->mA, *mB = rt->mB;
    sb_rt_term *S = rt->term + rt->nsk;
    double L2 = rt->L * rt->L;
    int k;
    memset(S, 0, sizeof(sb_rt_term) * (size_t)rt->nsf);
    if (rt->corr == SB_RT_CORR_VERTEX) {
        for (k = 0; k < mA->nv; k++) {
            sb_rt_add_point(&S[k], A, A->emb_cell[k], A->emb_t + 3 * k, 1.0);
            memcpy(S[k].t, mB->v + 3 * k, sizeof S[k].t);
            S[k].f = rt->opt.w_surf / (mA->nv * L2);
        }
        rt->nsa = mA->nv;
        return 0;
    }
    {
        double *hs = sb_alloc(sizeof(double) * 3 * (size_t)mA->nv);
        tri_index tb, ta;
        for (k = 0; k < mA->nv; k++) {
            sb_rt_mapped_surface_point(rt, k, hs + 3 * k);
            if (!finite3(hs + 3 * k)) { free(hs); return sb_fail("retarget: the map is not finite (surface vertex %d of A)", k); }
        }
        sb_rt_tri_index_make(&tb, mB->v, mB->tri, mB->nt);
        sb_rt_tri_index_make(&ta, hs, A->tri, A->nt);
        /* A -> B: mapped A vertex to its closest point on B */
        for (k = 0; k < mA->nv; k++) {
            double bw[3];
            int t = sb_rt_tri_closest(&tb, hs + 3 * k, bw), c, a;
            sb_rt_add_point(&S[k], A, A->emb_cell[k], A->emb_t + 3 * k, 1.0);
            for (a = 0; a < 3; a++) {
                S[k].t[a] = 0;
                for (c = 0; c < 3; c++) S[k].t[a] += bw[c] * mB->v[3 * mB->tri[3 * t + c] + a];
            }
            S[k].f = 0.5 * rt->opt.w_surf / (mA->nv * L2);
        }
        /* B -> A: B vertex to the closest point of the mapped A surface (fixed triangle and weights) */
        for (k = 0; k < mB->nv; k++) {
            double bw[3];
            int t = sb_rt_tri_closest(&ta, mB->v + 3 * k, bw), c;
            sb_rt_term *tm = &S[mA->nv + k];
            for (c = 0; c < 3; c++) {
                int sv = A->tri[3 * t + c];
                if (bw[c] != 0) sb_rt_add_point(tm, A, A->emb_cell[sv], A->emb_t + 3 * sv, bw[c]);
            }
            memcpy(tm->t, mB->v + 3 * k, sizeof tm->t);
            tm->f = 0.5 * rt->opt.w_surf / (mB->nv * L2);
        }
        rt->nsa = mA->nv;
        free(hs); sb_rt_tri_index_free(&tb); sb_rt_tri_index_free(&ta);
    }
    return 0;
}

