/* sb_retarget_xfer.c -- rig retargeting (seed 003 §4.4): static equilibrium
 * at rest (eq. 10), a rig's force field resampled from character A onto B and
 * its transfer (eq. 15-16 applied), and the rig file written for B. */
#include "sb_retarget_int.h"
#include "sb_lbfgsb.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------- static equilibrium at rest (eq. 10) ---------------- */

/* y = S_FF x over free rows (x, y: nf x 3) */
static void sff_mul(const sb_model *o, const double *x, double *y)
{
    int i, p, a, b;
    for (i = 0; i < o->nf; i++) {
        double s[3] = { 0, 0, 0 };
        for (p = o->nbptr[i]; p < o->nbptr[i + 1]; p++) {
            int j = o->nb[p];
            const double *S = o->S + 9 * (size_t)p;
            if (j >= o->nf) continue;
            for (a = 0; a < 3; a++)
                for (b = 0; b < 3; b++) s[a] += S[3 * a + b] * x[3 * j + b];
        }
        for (a = 0; a < 3; a++) y[3 * i + a] = s[a];
    }
}

void sb_rt_force_of(const sb_model *o, const double *q, double *Q)
{
    double *x = sb_alloc(sizeof(double) * 3 * (size_t)o->nf);
    int i;
    for (i = 0; i < 3 * o->nf; i++) x[i] = q[i] * o->unit;   /* metres */
    sff_mul(o, x, Q);
    free(x);
}

double sb_rt_static(const sb_model *o, const double *Q, double *q)
{
    int n = 3 * o->nf, i, it, p;
    double *x = sb_alloc(sizeof(double) * (size_t)n), *r = sb_alloc(sizeof(double) * (size_t)n);
    double *z = sb_alloc(sizeof(double) * (size_t)n), *d = sb_alloc(sizeof(double) * (size_t)n), *Ad = sb_alloc(sizeof(double) * (size_t)n);
    double *Pinv = sb_alloc(sizeof(double) * 9 * (size_t)o->nf), rz = 0, bn, res;
    /* block-Jacobi preconditioner */
    for (i = 0; i < o->nf; i++) {
        p = sb_pattern_find(o, i, i);
        if (p < 0 || inv3(o->S + 9 * (size_t)p, Pinv + 9 * (size_t)i) == 0) { Pinv[9 * i] = Pinv[9 * i + 4] = Pinv[9 * i + 8] = 1; }
    }
    for (i = 0; i < n; i++) r[i] = Q[i];
    bn = norm(r, n);
    for (i = 0; i < o->nf; i++) {
        int a;
        for (a = 0; a < 3; a++) z[3 * i + a] = dot3(Pinv + 9 * i + 3 * a, r + 3 * i);
    }
    for (i = 0; i < n; i++) { d[i] = z[i]; rz += r[i] * z[i]; }
    for (it = 0; it < 20 * n + 100 && bn > 0 && norm(r, n) > 1e-13 * bn; it++) {
        double dAd = 0, al, rz1 = 0;
        int a;
        sff_mul(o, d, Ad);
        for (i = 0; i < n; i++) dAd += d[i] * Ad[i];
        if (!(dAd > 0)) break;
        al = rz / dAd;
        for (i = 0; i < n; i++) { x[i] += al * d[i]; r[i] -= al * Ad[i]; }
        for (i = 0; i < o->nf; i++)
            for (a = 0; a < 3; a++) z[3 * i + a] = dot3(Pinv + 9 * i + 3 * a, r + 3 * i);
        for (i = 0; i < n; i++) rz1 += r[i] * z[i];
        for (i = 0; i < n; i++) d[i] = z[i] + rz1 / rz * d[i];
        rz = rz1;
    }
    /* true residual */
    sff_mul(o, x, Ad);
    for (i = 0; i < n; i++) r[i] = Q[i] - Ad[i];
    res = bn > 0 ? norm(r, n) / bn : 0;
    memset(q, 0, sizeof(double) * 3 * (size_t)o->nv);
    for (i = 0; i < n; i++) q[i] = x[i] / o->unit;   /* mesh units */
    free(x); free(r); free(z); free(d); free(Ad); free(Pinv);
    return isfinite(res) ? res : -1;
}

/* rest position of o's surface vertex k from its embedding */
static void sb_rt_surface_point(const sb_model *o, int k, double y[3]) { sb_rt_embed_point(o, o->x, k, y); }

void sb_rt_surface(const sb_model *o, const double *q, double *s)
{
    int k, c, a;
    for (k = 0; k < o->ns; k++) {
        double N[8];
        sb_shape(o->emb_t + 3 * k, N, NULL);
        for (a = 0; a < 3; a++) s[3 * k + a] = 0;
        for (c = 0; c < 8; c++) {
            int v = o->cells[8 * o->emb_cell[k] + c];
            for (a = 0; a < 3; a++) s[3 * k + a] += N[c] * (o->x[3 * v + a] + (q ? q[3 * v + a] : 0));
        }
    }
}

int sb_rt_rig_force(const sb_model *o, const char *names, double *Q, int *control)
{
    const char *p = names;
    int nsel = 0;
    memset(Q, 0, sizeof(double) * 3 * (size_t)o->nf);
    if (control) *control = -1;
    while (p && *p) {
        const char *e = strchr(p, ',');
        size_t l = e ? (size_t)(e - p) : strlen(p);
        int r, k, found = -1;
        for (r = 0; r < o->nrig; r++)
            if (strlen(o->rig[r].def.name) == l && !strncmp(o->rig[r].def.name, p, l)) { found = r; break; }
        if (found < 0) {
            char list[2048];
            size_t n = 0;
            list[0] = 0;
            for (r = 0; r < o->nrig && n + SB_NAME_MAX + 3 < sizeof list; r++) n += (size_t)snprintf(list + n, sizeof list - n, " %s", o->rig[r].def.name);
            return sb_fail("retarget: character A has no rig '%.*s' (rigs:%s)", (int)l, p, o->nrig ? list : " none");
        }
        for (k = 0; k < o->rig[found].n; k++) {
            int v = o->rig[found].vert[k], a;
            for (a = 0; a < 3; a++) Q[3 * v + a] += o->rig[found].Q[3 * k + a];
        }
        if (control && *control < 0) *control = o->rig[found].def.control;
        nsel++;
        p = e ? e + 1 : NULL;
    }
    if (!nsel) return sb_fail("retarget: no rig named");
    return 0;
}

/* ---------------- transfer ---------------- */

/* The resample's weights, measured on test_bake_retarget (the limb onto a
 * sheared copy, two bump rigs; A onto itself): interior samples on a 2x2x2
 * grid per cell of A at weight 0.01 against 1 for each surface vertex of B,
 * and the second-difference smoothing at 1e-6: surface error max 0.26% /
 * 0.15% (rms 0.02% / 0.02%) of the largest displacement for the two rigs, A
 * onto itself 0.12%. Cell centres and A's surface vertices at weight 1 with
 * smoothing 1e-4 (the first version): 1.0% / 16%, and 10.8% onto itself. */
#define RS_PER_CELL 2
#define RS_WINT 0.01
#define RS_MU 1e-6

/* a sample of the transferred field: B cell, reference coordinates, value */
typedef struct rs_sample { int cell; double t[3]; double v[3]; double w; } rs_sample;

static void add_sample(const sb_model *B, const int *cmap, rs_sample *S, int *ns, const double y[3], const double v[3], double w)
{
    double t[3];
    int ci = sb_rt_locate(B, cmap, y, t);
    if (ci < 0) return;
    S[*ns].cell = ci;
    S[*ns].w = w;
    memcpy(S[*ns].t, t, sizeof t);
    memcpy(S[*ns].v, v, 3 * sizeof(double));
    (*ns)++;
}

/* point of A's cell ci at reference coordinates t under the map h, and its derivative d/dt */
static void mapped_cell_point(const sb_retarget *rt, int ci, const double t[3], double p[3], double D[9])
{
    const sb_model *A = rt->A;
    double N[8], dN[8][3];
    int k, a, b;
    sb_shape(t, N, dN);
    for (a = 0; a < 3; a++) p[a] = 0;
    for (a = 0; a < 9; a++) D[a] = 0;
    for (k = 0; k < 8; k++) {
        const double *hv = rt->h + 3 * A->cells[8 * ci + k];
        for (a = 0; a < 3; a++) {
            p[a] += N[k] * hv[a];
            for (b = 0; b < 3; b++) D[3 * a + b] += dN[k][b] * hv[a];
        }
    }
}

/* reference coordinates of y in A's mapped cell ci (Newton from the centre); 0 if y is inside it */
static int invert_cell(const sb_retarget *rt, int ci, const double y[3], double t[3])
{
    int it, a;
    t[0] = t[1] = t[2] = 0.5;
    for (it = 0; it < 40; it++) {
        double p[3], D[9], Di[9], r[3], dt[3];
        mapped_cell_point(rt, ci, t, p, D);
        for (a = 0; a < 3; a++) r[a] = y[a] - p[a];
        if (inv3(D, Di) == 0) return -1;
        for (a = 0; a < 3; a++) dt[a] = dot3(Di + 3 * a, r);
        for (a = 0; a < 3; a++) t[a] = fmin(fmax(t[a] + dt[a], -1.0), 2.0);
        if (sqrt(dot3(dt, dt)) < 1e-12) break;
    }
    for (a = 0; a < 3; a++) if (!(t[a] >= -1e-9 && t[a] <= 1 + 1e-9)) return -1;
    for (a = 0; a < 3; a++) t[a] = fmin(fmax(t[a], 0.0), 1.0);
    return 0;
}

/* the transferred field at A's cell ci, reference coordinates t */
static void field_at(const sb_model *A, const double *qbar, int ci, const double t[3], double v[3])
{
    double N[8];
    int c, a;
    sb_shape(t, N, NULL);
    v[0] = v[1] = v[2] = 0;
    for (c = 0; c < 8; c++)
        for (a = 0; a < 3; a++) v[a] += N[c] * qbar[3 * A->cells[8 * ci + c] + a];
}

/* y (nf_B x 3) = (sum_s phi phi^T + mu D^T D) x over B's free vertices (skeleton values 0) */
static void rs_mul(const sb_model *B, const rs_sample *S, int ns, const int (*st)[4], const double *stw, int nst, double mu,
                   const double *x, double *y)
{
    int s, k, a, c;
    memset(y, 0, sizeof(double) * 3 * (size_t)B->nf);
    for (s = 0; s < ns; s++) {
        double N[8], r[3] = { 0, 0, 0 };
        sb_shape(S[s].t, N, NULL);
        for (k = 0; k < 8; k++) {
            int v = B->cells[8 * S[s].cell + k];
            if (v < B->nf) for (a = 0; a < 3; a++) r[a] += N[k] * x[3 * v + a];
        }
        for (k = 0; k < 8; k++) {
            int v = B->cells[8 * S[s].cell + k];
            if (v < B->nf) for (a = 0; a < 3; a++) y[3 * v + a] += S[s].w * N[k] * r[a];
        }
    }
    for (s = 0; s < nst; s++) {
        double r[3] = { 0, 0, 0 };
        for (c = 0; c < 4; c++) if (st[s][c] >= 0 && st[s][c] < B->nf) for (a = 0; a < 3; a++) r[a] += stw[4 * s + c] * x[3 * st[s][c] + a];
        for (c = 0; c < 4; c++) if (st[s][c] >= 0 && st[s][c] < B->nf) for (a = 0; a < 3; a++) y[3 * st[s][c] + a] += mu * stw[4 * s + c] * r[a];
    }
}

static int resample(const sb_retarget *rt, const double *qbar, double *qB, sb_rt_transfer_stats *stt)
{
    const sb_model *A = rt->A, *B = rt->B;
    int cap = A->nv + A->nc * RS_PER_CELL * RS_PER_CELL * RS_PER_CELL + B->ns, ns = 0, i, k, a, nst = 0, it, n = 3 * B->nf;
    rs_sample *S = sb_alloc(sizeof(rs_sample) * (size_t)cap);
    int (*st)[4] = sb_alloc(sizeof(int) * 4 * 6 * (size_t)B->nv);
    double *stw = sb_alloc(sizeof(double) * 4 * 6 * (size_t)B->nv), mu;
    double *b = sb_alloc(sizeof(double) * (size_t)n), *x = sb_alloc(sizeof(double) * (size_t)n), *r = sb_alloc(sizeof(double) * (size_t)n);
    double *d = sb_alloc(sizeof(double) * (size_t)n), *Ad = sb_alloc(sizeof(double) * (size_t)n), *dg = sb_alloc(sizeof(double) * (size_t)B->nf);
    double *z = sb_alloc(sizeof(double) * (size_t)n), rz = 0, bn;
    unsigned char *has = sb_alloc((size_t)B->nv);
    size_t ngc = (size_t)(B->gn[0] - 1) * (size_t)(B->gn[1] - 1) * (size_t)(B->gn[2] - 1);
    int *cmap = sb_alloc(sizeof(int) * ngc);
    sb_inside in;
    for (i = 0; i < (int)ngc; i++) cmap[i] = -1;
    for (i = 0; i < B->nc; i++) cmap[B->cell_grid[i]] = i;
    /* samples: B's surface vertices (weight 1) with the transferred field at
     * their preimage under h (the mapped cell of A holding the vertex; a
     * vertex outside A's mapped lattice takes the field at the closest point
     * of A's mapped surface), and, inside A's mesh only (lattice vertices and
     * cell points outside it carry the 'air' displacement, not flesh), A's
     * mapped lattice vertices and RS_PER_CELL^3 points per cell (weight
     * RS_WINT) */
    stt->surf_inside = stt->surf_outside = 0;
    sb_inside_init(&in, rt->mA);
    for (i = 0; i < A->nv; i++) if (sb_inside_test(&in, A->x + 3 * i)) add_sample(B, cmap, S, &ns, rt->h + 3 * i, qbar + 3 * i, RS_WINT);
    for (k = 0; k < A->nc * RS_PER_CELL * RS_PER_CELL * RS_PER_CELL; k++) {
        int q = k % (RS_PER_CELL * RS_PER_CELL * RS_PER_CELL), ci = k / (RS_PER_CELL * RS_PER_CELL * RS_PER_CELL);
        double t[3], xc[3], y[3], v[3], D[9];
        t[0] = (2 * (q % RS_PER_CELL) + 1) / (2.0 * RS_PER_CELL);
        t[1] = (2 * ((q / RS_PER_CELL) % RS_PER_CELL) + 1) / (2.0 * RS_PER_CELL);
        t[2] = (2 * (q / (RS_PER_CELL * RS_PER_CELL)) + 1) / (2.0 * RS_PER_CELL);
        sb_cell_point(A, ci, t, xc);
        if (!sb_inside_test(&in, xc)) continue;
        mapped_cell_point(rt, ci, t, y, D);
        field_at(A, qbar, ci, t, v);
        add_sample(B, cmap, S, &ns, y, v, RS_WINT);
    }
    {
        double *cbox = sb_alloc(sizeof(double) * 6 * (size_t)A->nc), *hs = sb_alloc(sizeof(double) * 3 * (size_t)A->ns);
        tri_index ta;
        int c;
        for (c = 0; c < A->nc; c++)
            for (a = 0; a < 3; a++) {
                double lo = 1e300, hi = -1e300;
                int j;
                for (j = 0; j < 8; j++) { double w = rt->h[3 * A->cells[8 * c + j] + a]; lo = fmin(lo, w); hi = fmax(hi, w); }
                cbox[6 * c + a] = lo; cbox[6 * c + 3 + a] = hi;
            }
        for (k = 0; k < A->ns; k++) sb_rt_mapped_surface_point(rt, k, hs + 3 * k);
        sb_rt_tri_index_make(&ta, hs, A->tri, A->nt);
        for (k = 0; k < B->ns; k++) {
            double y[3], t[3], v[3], tol = 1e-9 * rt->L;
            int found = 0;
            sb_rt_surface_point(B, k, y);
            for (c = 0; c < A->nc && !found; c++) {
                if (y[0] < cbox[6 * c] - tol || y[0] > cbox[6 * c + 3] + tol || y[1] < cbox[6 * c + 1] - tol || y[1] > cbox[6 * c + 4] + tol ||
                    y[2] < cbox[6 * c + 2] - tol || y[2] > cbox[6 * c + 5] + tol)
                    continue;
                if (invert_cell(rt, c, y, t)) continue;
                field_at(A, qbar, c, t, v);
                found = 1;
            }
            if (found) stt->surf_inside++;
            else {          /* the closest point of A's mapped surface */
                stt->surf_outside++;
                double bw[3], vv[3];
                int tr = sb_rt_tri_closest(&ta, y, bw), j;
                v[0] = v[1] = v[2] = 0;
                for (j = 0; j < 3; j++) {
                    int sv = A->tri[3 * tr + j];
                    field_at(A, qbar, A->emb_cell[sv], A->emb_t + 3 * sv, vv);
                    for (a = 0; a < 3; a++) v[a] += bw[j] * vv[a];
                }
            }
            add_sample(B, cmap, S, &ns, y, v, 1.0);
        }
        sb_rt_tri_index_free(&ta);
        free(cbox); free(hs);
    }
    if (!stt->surf_inside) {
        sb_inside_free(&in); free(cmap);
        free(S); free(st); free(stw); free(b); free(x); free(r); free(d); free(Ad); free(dg); free(z); free(has);
        return sb_fail("retarget: empty overlap: none of B's %d surface vertices lies in A's mapped lattice (the map does not cover B)", B->ns);
    }
    sb_inside_free(&in);
    free(cmap);
    if (!ns) {
        free(S); free(st); free(stw); free(b); free(x); free(r); free(d); free(Ad); free(dg); free(z); free(has);
        return sb_fail("retarget: empty overlap: no point of A's mapped lattice or surface lies in B's lattice (the map does not cover B)");
    }
    for (i = 0; i < ns; i++) for (k = 0; k < 8; k++) has[B->cells[8 * S[i].cell + k]] = 1;
    stt->inside = stt->outside = 0;
    for (i = 0; i < B->nf; i++) { if (has[i]) stt->inside++; else stt->outside++; }
    /* second-difference stencils on B's grid */
    {
        int stp[3] = { 1, B->gn[0], B->gn[0] * B->gn[1] }, ax, bx;
        for (i = 0; i < B->nv; i++) {
            int gv = B->v_grid[i], gc[3];
            gc[0] = gv % B->gn[0]; gc[1] = (gv / B->gn[0]) % B->gn[1]; gc[2] = gv / (B->gn[0] * B->gn[1]);
            for (ax = 0; ax < 3; ax++) {
                int lo, hi;
                if (gc[ax] < 1 || gc[ax] > B->gn[ax] - 2) continue;
                lo = B->gvert[gv - stp[ax]]; hi = B->gvert[gv + stp[ax]];
                if (lo < 0 || hi < 0) continue;
                st[nst][0] = lo; st[nst][1] = i; st[nst][2] = hi; st[nst][3] = -1;
                stw[4 * nst] = 1; stw[4 * nst + 1] = -2; stw[4 * nst + 2] = 1; stw[4 * nst + 3] = 0;
                nst++;
            }
            for (ax = 0; ax < 3; ax++)
                for (bx = ax + 1; bx < 3; bx++) {
                    int u, v, w;
                    if (gc[ax] > B->gn[ax] - 2 || gc[bx] > B->gn[bx] - 2) continue;
                    u = B->gvert[gv + stp[ax]]; v = B->gvert[gv + stp[bx]]; w = B->gvert[gv + stp[ax] + stp[bx]];
                    if (u < 0 || v < 0 || w < 0) continue;
                    st[nst][0] = i; st[nst][1] = u; st[nst][2] = v; st[nst][3] = w;
                    stw[4 * nst] = 1; stw[4 * nst + 1] = -1; stw[4 * nst + 2] = -1; stw[4 * nst + 3] = 1;
                    nst++;
                }
        }
    }
    mu = RS_MU;
    /* right-hand side sum_s phi v_s, Jacobi diagonal */
    for (i = 0; i < ns; i++) {
        double N[8];
        sb_shape(S[i].t, N, NULL);
        for (k = 0; k < 8; k++) {
            int v = B->cells[8 * S[i].cell + k];
            if (v >= B->nf) continue;
            for (a = 0; a < 3; a++) b[3 * v + a] += S[i].w * N[k] * S[i].v[a];
            dg[v] += S[i].w * N[k] * N[k];
        }
    }
    for (i = 0; i < nst; i++) for (k = 0; k < 4; k++) if (st[i][k] >= 0 && st[i][k] < B->nf) dg[st[i][k]] += mu * stw[4 * i + k] * stw[4 * i + k];
    bn = norm(b, n);
    memcpy(r, b, sizeof(double) * (size_t)n);
    for (i = 0; i < n; i++) { z[i] = dg[i / 3] > 0 ? r[i] / dg[i / 3] : r[i]; d[i] = z[i]; rz += r[i] * z[i]; }
    for (it = 0; it < 20 * n + 100 && bn > 0 && norm(r, n) > 1e-12 * bn; it++) {
        double dAd = 0, al, rz1 = 0;
        rs_mul(B, S, ns, (const int (*)[4])st, stw, nst, mu, d, Ad);
        for (i = 0; i < n; i++) dAd += d[i] * Ad[i];
        if (!(dAd > 0)) break;
        al = rz / dAd;
        for (i = 0; i < n; i++) { x[i] += al * d[i]; r[i] -= al * Ad[i]; }
        for (i = 0; i < n; i++) { z[i] = dg[i / 3] > 0 ? r[i] / dg[i / 3] : r[i]; rz1 += r[i] * z[i]; }
        for (i = 0; i < n; i++) d[i] = z[i] + rz1 / rz * d[i];
        rz = rz1;
    }
    memset(qB, 0, sizeof(double) * 3 * (size_t)B->nv);
    memcpy(qB, x, sizeof(double) * (size_t)n);
    free(S); free(st); free(stw); free(b); free(x); free(r); free(d); free(Ad); free(dg); free(z); free(has);
    return 0;
}

int sb_rt_transfer(const sb_retarget *rt, const double *QA, double *QB, double *qA_out, double *qB_out, sb_rt_transfer_stats *st)
{
    const sb_model *A = rt->A, *B = rt->B;
    double *qA = sb_alloc(sizeof(double) * 3 * (size_t)A->nv), *qbar = sb_alloc(sizeof(double) * 3 * (size_t)A->nv);
    double *qB = sb_alloc(sizeof(double) * 3 * (size_t)B->nv), res;
    int i, a;
    sb_rt_transfer_stats s;
    memset(&s, 0, sizeof s);
    if (!rt->J) { free(qA); free(qbar); free(qB); return sb_fail("retarget: transfer before the Jacobians"); }
    for (i = 0; i < 3 * A->nf; i++)
        if (!isfinite(QA[i])) { free(qA); free(qbar); free(qB); return sb_fail("retarget: the source rig force is not finite"); }
    /* Q_A -> q_A (eq. 10 on A) */
    res = sb_rt_static(A, QA, qA);
    s.static_res = res;
    if (!(res >= 0 && res < 1e-8)) {
        free(qA); free(qbar); free(qB);
        return sb_fail("retarget: the static solve on A did not converge (relative residual %.3g)", res);
    }
    /* q_bar_i = J_i q_A,i */
    for (i = 0; i < A->nv; i++) {
        for (a = 0; a < 3; a++) qbar[3 * i + a] = dot3(rt->J + 9 * i + 3 * a, qA + 3 * i);
        s.qA_max = fmax(s.qA_max, sqrt(dot3(qA + 3 * i, qA + 3 * i)));
    }
    /* resample: fit B's trilinear field (free vertices; skeleton vertices
     * held at 0) to the transferred field by least squares over samples of
     * the overlap: every mapped lattice vertex h(x_i) of A (value J_i q_A,i,
     * the transferred coefficient of eq. 16), every mapped cell centre and
     * surface vertex of A (value: the trilinear interpolation of the J_i q_A,i),
     * each located in B's lattice; plus mu times the squared second
     * differences of q_B on B's grid (vertices without samples nearby follow
     * their neighbours smoothly). */
    if (resample(rt, qbar, qB, &s)) { free(qA); free(qbar); free(qB); return -1; }
    for (i = 0; i < B->nf; i++) s.qB_max = fmax(s.qB_max, sqrt(dot3(qB + 3 * i, qB + 3 * i)));
    /* Q_B = S_FF q_B (eq. 10 on B, skeleton held: q_S = 0) */
    sb_rt_force_of(B, qB, QB);
    for (i = 0; i < 3 * B->nf; i++)
        if (!isfinite(QB[i])) { free(qA); free(qbar); free(qB); return sb_fail("retarget: the transferred force is not finite"); }
    if (qA_out) memcpy(qA_out, qA, sizeof(double) * 3 * (size_t)A->nv);
    if (qB_out) memcpy(qB_out, qB, sizeof(double) * 3 * (size_t)B->nv);
    if (st) *st = s;
    free(qA); free(qbar); free(qB);
    return 0;
}

/* ---------------- output ---------------- */

int sb_rt_write_rig_levels(const char *path, int nlev, const sb_model *const *B, const sb_mesh *mB, const double *const *Q, const char *comment)
{
    int i, l;
    for (l = 0; l < nlev; l++) {
        double qmax = 0;
        for (i = 0; i < 3 * B[l]->nf; i++) {
            if (!isfinite(Q[l][i])) return sb_fail("retarget: the rig force%s is not finite: nothing written", l ? " on B's level 1" : "");
            qmax = fmax(qmax, fabs(Q[l][i]));
        }
        if (!(qmax > 0)) return sb_fail("retarget: the rig force%s is zero: nothing written", l ? " on B's level 1" : "");
    }
    return sb_rigfile_write_fits(path, nlev, B, mB, Q, comment);
}

int sb_rt_write_rig(const char *path, const sb_model *B, const sb_mesh *mB, const double *Q, const char *comment)
{
    return sb_rt_write_rig_levels(path, 1, &B, mB, &Q, comment);
}
