/* nlref.c -- nonlinear St. Venant-Kirchhoff reference (nlref.h). */
#include "nlref.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define ND 33   /* dofs per cell: 8 corners x 3, then 3 bubbles x 3 */

static double inv_wmin(const nlref *n);

static const double gl3[3] = {0.11270166537925831148, 0.5, 0.88729833462074168852};
static const double gw3[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};

static void lag3(double t, double L[3]) {
    L[0] = (t - gl3[1]) * (t - gl3[2]) / ((gl3[0] - gl3[1]) * (gl3[0] - gl3[2]));
    L[1] = (t - gl3[0]) * (t - gl3[2]) / ((gl3[1] - gl3[0]) * (gl3[1] - gl3[2]));
    L[2] = (t - gl3[0]) * (t - gl3[1]) / ((gl3[2] - gl3[0]) * (gl3[2] - gl3[1]));
}

/* in-place Cholesky of the n x n row-major A (lower triangle used); 0 or -1 */
static int chol(double *A, unsigned n) {
    unsigned i, j, k;
    for (j = 0; j < n; j++) {
        double s = A[(size_t)j * n + j];
        for (k = 0; k < j; k++) s -= A[(size_t)j * n + k] * A[(size_t)j * n + k];
        if (!(s > 0)) return -1;
        s = sqrt(s);
        A[(size_t)j * n + j] = s;
        for (i = j + 1; i < n; i++) {
            double r = A[(size_t)i * n + j];
            for (k = 0; k < j; k++) r -= A[(size_t)i * n + k] * A[(size_t)j * n + k];
            A[(size_t)i * n + j] = r / s;
        }
    }
    return 0;
}
static void chol_solve(const double *A, unsigned n, double *x) {
    unsigned i, k;
    for (i = 0; i < n; i++) {
        double r = x[i];
        for (k = 0; k < i; k++) r -= A[(size_t)i * n + k] * x[k];
        x[i] = r / A[(size_t)i * n + i];
    }
    for (i = n; i-- > 0;) {
        double r = x[i];
        for (k = i + 1; k < n; k++) r -= A[(size_t)k * n + i] * x[k];
        x[i] = r / A[(size_t)i * n + i];
    }
}

/* ---------------- open: bake, blob, moments ---------------- */

int nlref_open(nlref *n, const char *desc_path, char *err, size_t errn) {
    int ns, npt, ci, q, k, r, ngc, *gslot, *slot, *mq;
    double *frac = NULL, (*tq)[3], (*Lq)[9], hs, w0, lsc;
    unsigned e, cap;
    memset(n, 0, sizeof *n);
    if (sb_desc_load(desc_path, &n->d)) { snprintf(err, errn, "%s", sb_error()); sb_desc_free(&n->d); return -1; }
    n->have_d = 1;
    if (sb_mesh_load_obj(n->d.mesh_path, &n->mesh)) { snprintf(err, errn, "%s", sb_error()); nlref_close(n); return -1; }
    n->have_mesh = 1;
    if (sb_build(&n->d, &n->mesh, &n->o, 1)) { snprintf(err, errn, "%s", sb_error()); nlref_close(n); return -1; }
    n->have_o = 1;
    if (sb_blob_make(&n->o, SB_DOUBLE, &n->b)) { snprintf(err, errn, "%s", sb_error()); nlref_close(n); return -1; }
    n->have_b = 1;
    if (snref_load(&n->m, n->b.bytes, n->b.size, err, errn)) { nlref_close(n); return -1; }
    n->have_m = 1;
    n->nC = n->m.nC; n->nF = n->m.nF; n->nV = n->m.nV;
    n->L = n->m.unit * n->o.unit;         /* metres per internal unit */
    n->hc = n->o.c / n->m.unit;           /* cell edge, internal units */
    lsc = n->o.h * n->o.h * n->L / n->b.m0;
    /* inside fractions of the partly filled cells, by the build's routine */
    npt = n->d.subdiv * n->d.subdiv * n->d.subdiv * 8;
    ngc = (n->o.gn[0] - 1) * (n->o.gn[1] - 1) * (n->o.gn[2] - 1);
    gslot = malloc(sizeof(int) * (size_t)ngc); slot = malloc(sizeof(int) * n->nC);
    for (k = 0; k < ngc; k++) gslot[k] = -1;
    for (ci = 0, ns = 0; ci < (int)n->nC; ci++) {
        slot[ci] = -1;
        if (n->o.cell_fill[ci] > 0 && n->o.cell_fill[ci] < 1) { slot[ci] = ns++; gslot[n->o.cell_grid[ci]] = slot[ci]; }
    }
    frac = calloc((size_t)npt * (size_t)(ns ? ns : 1), sizeof *frac);
    if (ns) {
        sb_inside in;
        sb_inside_init(&in, &n->mesh);
        sb_box_fractions(&n->o, &n->mesh, &in, n->d.subdiv, gslot, frac, -1);
        sb_inside_free(&in);
    }
    for (k = 0; k < ns * npt; k++) frac[k] = frac[k] > 1 ? 1 : frac[k];
    tq = malloc(sizeof(double) * 3 * (size_t)npt); Lq = malloc(sizeof(double) * 9 * (size_t)npt); mq = malloc(sizeof(int) * (size_t)npt);
    {
        static const double gp2[2] = {0.21132486540518711775, 0.78867513459481288225};
        int nn = n->d.subdiv;
        for (q = 0; q < npt; q++) {
            int sx = q / 8 % nn, sy = q / 8 / nn % nn, sz = q / 8 / (nn * nn), gp = q % 8;
            tq[q][0] = (sx + gp2[gp & 1]) / nn; tq[q][1] = (sy + gp2[(gp >> 1) & 1]) / nn; tq[q][2] = (sz + gp2[(gp >> 2) & 1]) / nn;
            for (k = 0; k < 3; k++) lag3(tq[q][k], Lq[q] + 3 * k);
        }
    }
    hs = n->hc * n->hc * n->hc;
    w0 = hs / (double)npt;
    cap = n->nC * (unsigned)(npt > 27 ? npt : 27);
    n->efirst = calloc(n->nC + 1, sizeof *n->efirst);
    n->elam = calloc(cap, sizeof *n->elam); n->emu = calloc(cap, sizeof *n->emu);
    n->emw = calloc((size_t)cap * 4, sizeof *n->emw);
    n->inc = calloc(n->nC, 1);
    n->alpha = calloc((size_t)n->nC * 9, sizeof *n->alpha);
    e = 0;
    for (ci = 0; ci < (int)n->nC; ci++) {
        const double *x0 = n->o.x + 3 * n->o.cells[8 * ci];
        int onemat = 1, mat0 = 0;
        const double *f = slot[ci] >= 0 ? frac + (size_t)slot[ci] * (size_t)npt : NULL;
        n->efirst[ci] = e;
        for (q = 0; q < npt; q++) {
            double p[3];
            int mat = 0;
            if (n->d.nmr) {
                for (k = 0; k < 3; k++) p[k] = x0[k] + tq[q][k] * n->o.c;
                for (r = 0; r < n->d.nmr; r++) if (sb_region_has(&n->o, &n->d.mrules[r].r, p)) mat = n->d.mrules[r].mat;
            }
            mq[q] = mat;
            if (q == 0) mat0 = mat; else if (mat != mat0) onemat = 0;
        }
        if (f == NULL && onemat) {   /* one material, wholly inside (or air): 3x3x3 Gauss, exact to degree 5 per axis */
            const sb_material *mt = &n->d.mats[mat0];
            double in = n->o.cell_fill[ci] >= 1 ? 1.0 : n->d.air;
            int x, y, z;
            for (z = 0; z < 3; z++) for (y = 0; y < 3; y++) for (x = 0; x < 3; x++) {
                double *pw = n->emw + 4 * (size_t)e;
                pw[0] = gl3[x]; pw[1] = gl3[y]; pw[2] = gl3[z];
                pw[3] = hs * gw3[x] * gw3[y] * gw3[z] * in;
                n->elam[e] = lsc * mt->E * mt->nu / ((1 + mt->nu) * (1 - 2 * mt->nu));
                n->emu[e] = lsc * mt->E / (2 * (1 + mt->nu));
                e++;
            }
        } else {   /* the tool's own points: sub-box Gauss points weighted by inside fraction (+ air) */
            for (q = 0; q < npt; q++) {
                const sb_material *mt = &n->d.mats[mq[q]];
                double fq = f ? f[q] : n->o.cell_fill[ci] >= 1 ? 1.0 : 0.0, w = w0 * (fq + n->d.air * (1 - fq)), *pw = n->emw + 4 * (size_t)e;
                if (w == 0) continue;
                pw[0] = tq[q][0]; pw[1] = tq[q][1]; pw[2] = tq[q][2]; pw[3] = w;
                n->elam[e] = lsc * mt->E * mt->nu / ((1 + mt->nu) * (1 - 2 * mt->nu));
                n->emu[e] = lsc * mt->E / (2 * (1 + mt->nu));
                e++;
            }
        }
        n->inc[ci] = n->d.element == SB_ELEM_INCOMPATIBLE;
    }
    n->efirst[n->nC] = e;
    /* bubbles only where the tool condensed them (the same Cholesky test) */
    for (ci = 0; ci < (int)n->nC; ci++) {
        double K[576];
        if (n->inc[ci] && nlref_rest_condensed(n, (unsigned)ci, K) != 0) { n->inc[ci] = 0; n->n_trilinear++; }
    }
    free(gslot); free(slot); free(frac); free(tq); free(Lq); free(mq);
    return 0;
}

void nlref_close(nlref *n) {
    if (n->have_m) snref_free(&n->m);
    if (n->have_b) sb_blob_free(&n->b);
    if (n->have_o) sb_model_free(&n->o);
    if (n->have_mesh) sb_mesh_free(&n->mesh);
    if (n->have_d) sb_desc_free(&n->d);
    free(n->efirst); free(n->elam); free(n->emu); free(n->emw); free(n->inc); free(n->alpha); free(n->lin_dmp); free(n->tw_cell); free(n->tw_joint); free(n->tw_T);
    memset(n, 0, sizeof *n);
}

/* ---------------- the element ---------------- */

double nlref_cell(const nlref *n, unsigned e, const double P[24], const double A[9], double *g, double *H) {
    unsigned q, a, i, j, k, nd = n->inc[e] ? ND : 24;
    double psi = 0, h = n->hc;
    if (g) memset(g, 0, sizeof(double) * ND);
    if (H) memset(H, 0, sizeof(double) * ND * ND);
    for (q = n->efirst[e]; q < n->efirst[e + 1]; q++) {
        double t[3], N[8], dN[8][3], gv[ND][3], F[9], E[9], S[9], PK[9], trE, W;
        int cd[ND];
        const double *pw = n->emw + 4 * (size_t)q;
        t[0] = pw[0]; t[1] = pw[1]; t[2] = pw[2];
        sb_shape(t, N, dN);
        for (a = 0; a < 8; a++)
            for (i = 0; i < 3; i++) { cd[3 * a + i] = (int)i; for (k = 0; k < 3; k++) gv[3 * a + i][k] = dN[a][k] / h; }
        for (a = 0; a < 3; a++)   /* bubble a, component i: gradient 4 (1 - 2 t_a) / h e_a */
            for (i = 0; i < 3; i++) {
                cd[24 + 3 * a + i] = (int)i;
                for (k = 0; k < 3; k++) gv[24 + 3 * a + i][k] = k == a ? 4.0 * (1.0 - 2.0 * t[a]) / h : 0.0;
            }
        memset(F, 0, sizeof F);
        for (a = 0; a < 8; a++)
            for (i = 0; i < 3; i++) for (k = 0; k < 3; k++) F[3 * i + k] += P[3 * a + i] * gv[3 * a][k];
        if (nd == ND)
            for (a = 0; a < 3; a++)
                for (i = 0; i < 3; i++) for (k = 0; k < 3; k++) F[3 * i + k] += A[3 * a + i] * gv[24 + 3 * a][k];
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++) {
                double s = 0;
                for (k = 0; k < 3; k++) s += F[3 * k + i] * F[3 * k + j];
                E[3 * i + j] = 0.5 * (s - (i == j));
            }
        trE = E[0] + E[4] + E[8];
        {
            double w = pw[3], lam = n->elam[q], mu = n->emu[q];
            unsigned d, d2;
            W = 0;
            for (i = 0; i < 9; i++) W += mu * E[i] * E[i];
            W += 0.5 * lam * trE * trE;
            psi += w * W;
            if (!g && !H) continue;
            for (i = 0; i < 9; i++) S[i] = 2 * mu * E[i] + (i % 4 == 0 ? lam * trE : 0);
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++) { double s = 0; for (k = 0; k < 3; k++) s += F[3 * i + k] * S[3 * k + j]; PK[3 * i + j] = s; }
            if (g)
                for (d = 0; d < nd; d++) {
                    const double *v = gv[d];
                    int c = cd[d];
                    g[d] += w * (PK[3 * c] * v[0] + PK[3 * c + 1] * v[1] + PK[3 * c + 2] * v[2]);
                }
            if (H)
                for (d = 0; d < nd; d++) {
                    const double *v = gv[d], *u = F + 3 * cd[d];   /* u_d = F^T e_c: row c of F */
                    double Sv[3], ugv = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
                    for (i = 0; i < 3; i++) Sv[i] = S[3 * i] * v[0] + S[3 * i + 1] * v[1] + S[3 * i + 2] * v[2];
                    for (d2 = d; d2 < nd; d2++) {
                        const double *v2 = gv[d2], *u2 = F + 3 * cd[d2];
                        double val = mu * ((u[0] * u2[0] + u[1] * u2[1] + u[2] * u2[2]) * (v[0] * v2[0] + v[1] * v2[1] + v[2] * v2[2])
                                           + (u[0] * v2[0] + u[1] * v2[1] + u[2] * v2[2]) * (v[0] * u2[0] + v[1] * u2[1] + v[2] * u2[2]))
                                     + lam * ugv * (u2[0] * v2[0] + u2[1] * v2[1] + u2[2] * v2[2]);
                        if (cd[d] == cd[d2]) val += Sv[0] * v2[0] + Sv[1] * v2[1] + Sv[2] * v2[2];
                        H[d * ND + d2] += w * val;
                    }
                }
        }
    }
    if (H)
        for (i = 0; i < ND; i++) for (j = 0; j < i; j++) H[i * ND + j] = H[j * ND + i];
    return psi;
}

/* K = Hpp - Hpa Haa^-1 Hap (and gc = gp - Hpa Haa^-1 ga if gc); Haa's factor
 * and Y = Haa^-1 [Hap | ga] left in fac/Y for the back substitution.
 * shift: added to Haa's diagonal as a multiple of its largest diagonal entry
 * when it is not positive definite. Returns the number of shifts. */
static int condense(const double *H, const double *g, double *K, double *gc, double fac[81], double Y[9 * 25]) {
    double amax = 0, sh = 0;
    int i, j, k, tries = 0;
    for (i = 0; i < 9; i++) amax = fmax(amax, H[(24 + i) * ND + 24 + i]);
    for (;;) {
        for (i = 0; i < 9; i++) for (j = 0; j < 9; j++) fac[9 * i + j] = H[(24 + i) * ND + 24 + j] + (i == j ? sh : 0);
        if (chol(fac, 9) == 0) break;
        sh = sh > 0 ? sh * 10 : 1e-10 * amax;
        tries++;
    }
    for (j = 0; j < 25; j++) {   /* columns: Hap (24) then ga */
        double x[9];
        for (i = 0; i < 9; i++) x[i] = j < 24 ? H[(24 + i) * ND + j] : g ? g[24 + i] : 0;
        chol_solve(fac, 9, x);
        for (i = 0; i < 9; i++) Y[25 * i + j] = x[i];
    }
    if (K)
        for (i = 0; i < 24; i++)
            for (j = 0; j < 24; j++) {
                double s = H[i * ND + j];
                for (k = 0; k < 9; k++) s -= H[i * ND + 24 + k] * Y[25 * k + j];
                K[24 * i + j] = s;
            }
    if (gc)
        for (i = 0; i < 24; i++) {
            double s = g[i];
            for (k = 0; k < 9; k++) s -= H[i * ND + 24 + k] * Y[25 * k + 24];
            gc[i] = s;
        }
    return tries;
}

static void rest_corners(const nlref *n, unsigned e, double P[24]) {
    unsigned a, k;
    for (a = 0; a < 8; a++) for (k = 0; k < 3; k++) P[3 * a + k] = n->m.rest[3 * n->m.cells[8 * e + a] + k];
}

int nlref_rest_condensed(const nlref *n, unsigned e, double K[576]) {
    double P[24], A[9] = {0}, H[ND * ND], fac[81], Y[225], amax = 0;
    int i, j;
    unsigned char keep = n->inc[e];
    ((nlref *)n)->inc[e] = 1;
    rest_corners(n, e, P);
    nlref_cell(n, e, P, A, NULL, H);
    ((nlref *)n)->inc[e] = keep;
    for (i = 0; i < 9; i++) amax = fmax(amax, H[(24 + i) * ND + 24 + i]);
    {   /* the tool's test: every pivot s > 1e-10 Kaa_jj */
        double Lf[81];
        int k;
        for (j = 0; j < 9; j++) {
            double s = H[(24 + j) * ND + 24 + j];
            for (k = 0; k < j; k++) s -= Lf[9 * j + k] * Lf[9 * j + k];
            if (!(s > 1e-10 * H[(24 + j) * ND + 24 + j]) || !keep) {
                for (i = 0; i < 24; i++) for (k = 0; k < 24; k++) K[24 * i + k] = H[i * ND + k];
                return -1;
            }
            Lf[9 * j + j] = sqrt(s);
            for (i = j + 1; i < 9; i++) {
                double r = H[(24 + i) * ND + 24 + j];
                for (k = 0; k < j; k++) r -= Lf[9 * i + k] * Lf[9 * j + k];
                Lf[9 * i + j] = r / Lf[9 * j + j];
            }
        }
    }
    (void)amax;
    condense(H, NULL, K, NULL, fac, Y);
    return 0;
}

/* ---------------- global assembly ---------------- */

static void cell_pos(const nlref *n, unsigned e, const double *p, double P[24]) {
    unsigned a, k;
    for (a = 0; a < 8; a++) for (k = 0; k < 3; k++) P[3 * a + k] = p[3 * n->m.cells[8 * e + a] + k];
}

/* skeleton positions of the pose in s (as snref's skeleton_pos) */
static void skeleton_set(const snref_state *s, double *p) {
    const snref_model *m = s->m;
    unsigned k, i;
    for (k = m->nF; k < m->nV; k++) {
        double R[9];
        int b = m->fb1[k];
        const double *x = m->rest + 3 * k;
        snref_quat_to_mat(s->jq + 4 * b, R);
        for (i = 0; i < 3; i++) p[3 * k + i] = R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2] + s->jt[3 * b + i];
    }
}

/* Relax the bubbles of every cell at fixed p (Newton per cell). */
static void relax_bubbles(const nlref *n, const double *p, double *alpha) {
    unsigned e, it, i;
    for (e = 0; e < n->nC; e++) {
        double P[24], g[ND], H[ND * ND], fac[81], Y[225];
        if (!n->inc[e]) continue;
        cell_pos(n, e, p, P);
        for (it = 0; it < 30; it++) {
            double gn = 0, psi0, t = 1, A1[9];
            psi0 = nlref_cell(n, e, P, alpha + 9 * e, g, H);
            for (i = 0; i < 9; i++) gn += g[24 + i] * g[24 + i];
            if (gn == 0) break;
            condense(H, g, NULL, NULL, fac, Y);
            for (; t > 1e-6; t *= 0.5) {
                for (i = 0; i < 9; i++) A1[i] = alpha[9 * e + i] - t * Y[25 * i + 24];
                if (nlref_cell(n, e, P, A1, NULL, NULL) <= psi0) break;
            }
            memcpy(alpha + 9 * e, A1, sizeof A1);
            {   /* stop once the step is below round-off of the cell size */
                double st = 0;
                for (i = 0; i < 9; i++) st = fmax(st, fabs(t * Y[25 * i + 24]));
                if (st < 1e-15 * n->hc) break;
            }
        }
    }
}

double nlref_force(nlref *n, const double *p, const double *alpha, double *f) {
    unsigned e, a, k;
    double E = 0, *al = calloc((size_t)n->nC * 9, sizeof *al);
    if (alpha) memcpy(al, alpha, sizeof(double) * 9 * n->nC);
    memset(f, 0, sizeof(double) * 3 * n->nF);
    for (e = 0; e < n->nC; e++) {
        double P[24], g[ND];
        cell_pos(n, e, p, P);
        E += nlref_cell(n, e, P, al + 9 * e, g, NULL);
        for (a = 0; a < 8; a++) {
            unsigned v = n->m.cells[8 * e + a];
            if (v >= n->nF) continue;
            for (k = 0; k < 3; k++) f[3 * v + k] -= g[3 * a + k];
        }
    }
    free(al);
    return E;
}

/* y (free rows) = M (x over free, and skeleton columns if with_skel) */
static void mass_mul(const snref_model *m, const double *x, double *y, int with_skel) {
    unsigned i, e, k, nn = with_skel ? m->nV : m->nF;
    for (i = 0; i < m->nF; i++) for (k = 0; k < 3; k++) y[3 * i + k] = m->mdiag[i] * x[3 * i + k];
    for (i = 0; i < m->nF; i++)
        for (e = m->rowptr[i]; e < m->rowptr[i + 1]; e++) {
            unsigned j = m->cols[e];
            if (j >= nn) continue;
            for (k = 0; k < 3; k++) y[3 * i + k] += m->moff[e] * x[3 * j + k];
            if (j < m->nF) for (k = 0; k < 3; k++) y[3 * j + k] += m->moff[e] * x[3 * i + k];
        }
}

/* the problem: Pi = sum psi_e - load.p_F [+ dynamic terms] */
typedef struct {
    nlref *n;
    const double *load;     /* 3nF */
    int dyn;
    const double *p0, *v0;  /* dynamic: start positions (3nV) and velocities (3nV; skeleton: new) */
    double a1, b1;
    const double *Kn;       /* dynamic: per-cell condensed tangent at the start (nC*576) */
} prob_t;

static double dyn_terms(const prob_t *pr, const double *p, double *grad /* 3nF or NULL */) {
    const nlref *n = pr->n;
    const snref_model *m = &n->m;
    unsigned N3 = 3 * n->nV, F3 = 3 * n->nF, i, e, a, b;
    double *vn = malloc(sizeof(double) * N3), *d = malloc(sizeof(double) * N3), *t = malloc(sizeof(double) * F3), *t2 = malloc(sizeof(double) * F3);
    double Phi = 0;
    for (i = 0; i < N3; i++) { vn[i] = p[i] - pr->p0[i]; d[i] = vn[i] - (i < F3 ? pr->v0[i] : 0); }
    /* skeleton rows of d: v'_S - v_S, v0 holds v_S of the start for i >= F3 */
    for (i = F3; i < N3; i++) d[i] = vn[i] - pr->v0[i];
    /* kinetic: 1/2 d_F M_FF d_F + d_F M_FS d_S; mass damping 1/2 a1 v'_F M v'_F + v'_F M_FS v'_S */
    {
        double *dz = calloc(N3, sizeof *dz);
        memcpy(dz, d, sizeof(double) * F3);
        mass_mul(m, dz, t, 0);                /* M_FF d_F */
        mass_mul(m, d, t2, 1);                /* M_F. d */
        for (i = 0; i < F3; i++) { Phi += d[i] * (0.5 * t[i] + (t2[i] - t[i])); if (grad) grad[i] += t2[i]; }
        memcpy(dz, vn, sizeof(double) * F3);
        mass_mul(m, dz, t, 0);
        mass_mul(m, vn, t2, 1);
        for (i = 0; i < F3; i++) { Phi += pr->a1 * vn[i] * (0.5 * t[i] + (t2[i] - t[i])); if (grad) grad[i] += pr->a1 * t2[i]; }
        free(dz);
    }
    /* stiffness damping: 1/2 b1 sum_e v'_e Kn_e v'_e */
    if (pr->b1 != 0)
        for (e = 0; e < n->nC; e++) {
            const double *K = pr->Kn + 576 * (size_t)e;
            double ve[24], kv[24];
            for (a = 0; a < 8; a++) for (i = 0; i < 3; i++) ve[3 * a + i] = vn[3 * m->cells[8 * e + a] + i];
            for (a = 0; a < 24; a++) { double s = 0; for (b = 0; b < 24; b++) s += K[24 * a + b] * ve[b]; kv[a] = s; Phi += 0.5 * pr->b1 * ve[a] * s; }
            if (grad)
                for (a = 0; a < 8; a++) {
                    unsigned v = m->cells[8 * e + a];
                    if (v < n->nF) for (i = 0; i < 3; i++) grad[3 * v + i] += pr->b1 * kv[3 * a + i];
                }
        }
    free(vn); free(d); free(t); free(t2);
    return Phi;
}

/* twist penalty (nlref_set_twist): 1/2 sum_entries sum_ab T_ab d_a.d_b,
 * d_a = p_a - (R_j x_a + t_j) of the entry's bone j at the pose of n->tw_s.
 * Adds to the energy (returned), to gp (free rows) and K (F3 x F3) if non-NULL. */
static double twist_terms(const nlref *n, const double *p, double *gp, double *K) {
    unsigned t, a, b, i, F3 = 3 * n->nF;
    double E = 0;
    if (!n->ntw || !n->tw_s) return 0;
    for (t = 0; t < n->ntw; t++) {
        const unsigned *cv = n->m.cells + 8 * n->tw_cell[t];
        const double *T = n->tw_T + 64 * (size_t)t;
        double R[9], d[24];
        int j = n->tw_joint[t];
        snref_quat_to_mat(n->tw_s->jq + 4 * j, R);
        for (a = 0; a < 8; a++) {
            const double *x = n->m.rest + 3 * cv[a];
            for (i = 0; i < 3; i++) d[3 * a + i] = p[3 * cv[a] + i] - (R[3 * i] * x[0] + R[3 * i + 1] * x[1] + R[3 * i + 2] * x[2] + n->tw_s->jt[3 * j + i]);
        }
        for (a = 0; a < 8; a++)
            for (b = 0; b < 8; b++) {
                double dd = d[3 * a] * d[3 * b] + d[3 * a + 1] * d[3 * b + 1] + d[3 * a + 2] * d[3 * b + 2];
                E += 0.5 * T[8 * a + b] * dd;
                if (cv[a] >= n->nF) continue;
                if (gp) for (i = 0; i < 3; i++) gp[3 * cv[a] + i] += T[8 * a + b] * d[3 * b + i];
                if (K && cv[b] < n->nF) for (i = 0; i < 3; i++) K[(size_t)(3 * cv[a] + i) * F3 + 3 * cv[b] + i] += T[8 * a + b];
            }
    }
    return E;
}

int nlref_set_twist(nlref *n, double kappa, double r, int nsub) {
    unsigned e, sg, cap = n->nC * (unsigned)(n->o.nseg > 0 ? n->o.nseg : 1);
    free(n->tw_cell); free(n->tw_joint); free(n->tw_T);
    n->tw_cell = NULL; n->tw_joint = NULL; n->tw_T = NULL; n->ntw = 0;
    if (!(kappa > 0)) return 0;
    n->tw_cell = malloc(sizeof(unsigned) * cap); n->tw_joint = malloc(sizeof(int) * cap); n->tw_T = malloc(sizeof(double) * 64 * cap);
    double *A0 = malloc(sizeof(double) * 3 * (size_t)(n->o.nseg + 1)), *A1 = malloc(sizeof(double) * 3 * (size_t)(n->o.nseg + 1));
    for (sg = 0; sg < (unsigned)n->o.nseg; sg++) {
        int ch = n->o.seg_child[sg], par = n->o.joints[ch].parent;
        if (par < 0 || n->m.jparent[ch] != par) { free(A0); free(A1); return -1; }   /* blob joints = the tool's sorted joints */
        memcpy(A0 + 3 * sg, n->o.joints[par].pos, sizeof(double) * 3);
        memcpy(A1 + 3 * sg, n->o.joints[ch].pos, sizeof(double) * 3);
    }
    for (sg = 0; sg < (unsigned)n->o.nseg; sg++) {
        int ch = n->o.seg_child[sg], par = n->o.joints[ch].parent;
        for (e = 0; e < n->nC; e++) {
            double *T = n->tw_T + 64 * (size_t)n->ntw, mx = 0;
            int k;
            nlref_twist_cell(n, e, n->o.nseg, A0, A1, (int)sg, r, kappa, nsub, T);
            for (k = 0; k < 64; k++) mx = fmax(mx, T[k]);
            if (mx == 0) continue;
            n->tw_cell[n->ntw] = e; n->tw_joint[n->ntw] = par; n->ntw++;
        }
    }
    free(A0); free(A1);
    return 0;
}

static double pi_value(const prob_t *pr, const double *p, const double *alpha) {
    const nlref *n = pr->n;
    unsigned e, i;
    double v = 0;
    for (e = 0; e < n->nC; e++) { double P[24]; cell_pos(n, e, p, P); v += nlref_cell(n, e, P, alpha + 9 * e, NULL, NULL); }
    for (i = 0; i < 3 * n->nF; i++) v -= pr->load[i] * p[i];
    if (pr->dyn) v += dyn_terms(pr, p, NULL);
    v += twist_terms(n, p, NULL, NULL);
    return v;
}

/* |grad Pi| over free p rows and alpha */
static double grad_norm(const prob_t *pr, const double *p, const double *alpha) {
    const nlref *n = pr->n;
    unsigned F3 = 3 * n->nF, e, a, i;
    double *gp = malloc(sizeof(double) * F3), s = 0;
    for (i = 0; i < F3; i++) gp[i] = -pr->load[i];
    if (pr->dyn) dyn_terms(pr, p, gp);
    twist_terms(n, p, gp, NULL);
    for (e = 0; e < n->nC; e++) {
        double P[24], g[ND];
        cell_pos(n, e, p, P);
        nlref_cell(n, e, P, alpha + 9 * e, g, NULL);
        for (a = 0; a < 8; a++) {
            unsigned va = n->m.cells[8 * e + a];
            if (va < n->nF) for (i = 0; i < 3; i++) gp[3 * va + i] += g[3 * a + i];
        }
        if (n->inc[e]) for (i = 0; i < 9; i++) s += g[24 + i] * g[24 + i];
    }
    for (i = 0; i < F3; i++) s += gp[i] * gp[i];
    free(gp);
    return sqrt(s);
}

/* Newton on pr from (p, alpha); p skeleton rows already set. */
/* The gradient of Pi over the free p rows (uncondensed: the cells' element
 * gradients G, not their bubble-condensed form), as a new calloc'd array. */
static double *true_gradient(const prob_t *pr, const double *p, const double *G) {
    const nlref *n = pr->n;
    const snref_model *m = &n->m;
    unsigned F3 = 3 * n->nF, e, a, i;
    double *gp = calloc(F3, sizeof *gp);
    for (i = 0; i < F3; i++) gp[i] = -pr->load[i];
    if (pr->dyn) dyn_terms(pr, p, gp);
    twist_terms(n, p, gp, NULL);
    for (e = 0; e < n->nC; e++)
        for (a = 0; a < 8; a++) {
            unsigned va = m->cells[8 * e + a];
            if (va < n->nF) for (i = 0; i < 3; i++) gp[3 * va + i] += G[(size_t)ND * e + 3 * a + i];
        }
    return gp;
}

static int newton(const prob_t *pr, double *p, double *alpha, double tol, unsigned max_iter, nlref_stats *st) {
    nlref *n = pr->n;
    const snref_model *m = &n->m;
    unsigned F3 = 3 * n->nF, nC = n->nC, e, a, b, i, j, it;
    double *K = malloc(sizeof(double) * F3 * F3), *r = malloc(sizeof(double) * F3), *dp = malloc(sizeof(double) * 3 * n->nV);
    double *H = malloc(sizeof(double) * ND * ND * nC), *G = malloc(sizeof(double) * ND * nC);
    double *fac = malloc(sizeof(double) * 81 * nC), *Y = malloc(sizeof(double) * 225 * nC), *dal = malloc(sizeof(double) * 9 * nC);
    double *pt = malloc(sizeof(double) * 3 * n->nV), *at = malloc(sizeof(double) * 9 * nC), *Md = NULL;
    int rc = -1, small = 0;
    nlref_stats s0;
    if (!st) st = &s0;
    memset(st, 0, sizeof *st);
    if (pr->dyn) {   /* dense (1+a1) M_FF */
        double *x = calloc(3 * n->nV, sizeof *x), *y = malloc(sizeof(double) * F3);
        Md = malloc(sizeof(double) * F3 * F3);
        for (j = 0; j < F3; j++) {
            x[j] = 1; mass_mul(m, x, y, 0); x[j] = 0;
            for (i = 0; i < F3; i++) Md[(size_t)i * F3 + j] = (1 + pr->a1) * y[i];
        }
        free(x); free(y);
    }
    for (it = 0;; it++) {
        double gn2 = 0, fsc2 = 0, lsc2 = 0, res, D, Pi0, t, kmax = 0, sh = 0;
        int tries = 0;
        unsigned ninv0 = 0;
        memset(K, 0, sizeof(double) * F3 * F3);
        for (i = 0; i < F3; i++) { r[i] = -pr->load[i]; lsc2 += pr->load[i] * pr->load[i]; }
        if (pr->dyn) dyn_terms(pr, p, r);
        twist_terms(n, p, r, K);
        for (e = 0; e < nC; e++) {
            double P[24], Kc[576], gc[24], *He = H + (size_t)ND * ND * e, *ge = G + (size_t)ND * e;
            cell_pos(n, e, p, P);
            nlref_cell(n, e, P, alpha + 9 * e, ge, He);
            if (n->inc[e]) {
                st->shifts += (unsigned)condense(He, ge, Kc, gc, fac + 81 * e, Y + 225 * e);
                for (i = 0; i < 9; i++) gn2 += ge[24 + i] * ge[24 + i];
            } else {
                for (a = 0; a < 24; a++) { gc[a] = ge[a]; for (b = 0; b < 24; b++) Kc[24 * a + b] = He[a * ND + b]; }
            }
            for (a = 0; a < 8; a++) {
                unsigned va = m->cells[8 * e + a];
                if (va >= n->nF) continue;
                for (i = 0; i < 3; i++) { r[3 * va + i] += gc[3 * a + i]; fsc2 += ge[3 * a + i] * ge[3 * a + i]; }
                for (b = 0; b < 8; b++) {
                    unsigned vb = m->cells[8 * e + b];
                    if (vb >= n->nF) continue;
                    for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) K[(size_t)(3 * va + i) * F3 + 3 * vb + j] += Kc[24 * (3 * a + i) + 3 * b + j];
                }
            }
        }
        /* true gradient norm: free p rows (uncondensed g_p) and alpha */
        {
            double *gp = true_gradient(pr, p, G);
            for (i = 0; i < F3; i++) gn2 += gp[i] * gp[i];
            free(gp);
        }
        res = sqrt(gn2);
        if (it == 0) st->res0 = res;
        st->res = res;
        st->relres = res / (sqrt(lsc2) + sqrt(fsc2) + 1e-300);
        st->iters = it;
        if (st->relres <= tol) { rc = 0; break; }
        if (it >= max_iter) break;
        if (Md) for (i = 0; i < F3 * F3; i++) K[i] += Md[i];
        if (pr->dyn && pr->b1 != 0)
            for (e = 0; e < nC; e++)
                for (a = 0; a < 8; a++) {
                    unsigned va = m->cells[8 * e + a];
                    if (va >= n->nF) continue;
                    for (b = 0; b < 8; b++) {
                        unsigned vb = m->cells[8 * e + b];
                        if (vb >= n->nF) continue;
                        for (i = 0; i < 3; i++) for (j = 0; j < 3; j++)
                            K[(size_t)(3 * va + i) * F3 + 3 * vb + j] += pr->b1 * pr->Kn[576 * (size_t)e + 24 * (3 * a + i) + 3 * b + j];
                    }
                }
        for (i = 0; i < F3; i++) kmax = fmax(kmax, K[(size_t)i * F3 + i]);
        for (;;) {   /* Cholesky, shifted until positive definite */
            double *Kf = malloc(sizeof(double) * F3 * F3);
            memcpy(Kf, K, sizeof(double) * F3 * F3);
            for (i = 0; i < F3; i++) Kf[(size_t)i * F3 + i] += sh;
            if (chol(Kf, F3) == 0) {
                for (i = 0; i < F3; i++) dp[i] = -r[i];
                chol_solve(Kf, F3, dp);
                free(Kf);
                break;
            }
            free(Kf);
            sh = sh > 0 ? sh * 10 : 1e-8 * kmax;
            tries++;
        }
        if (tries) st->shifts++;
        for (i = F3; i < 3 * n->nV; i++) dp[i] = 0;
        /* bubbles: dalpha = -Haa^-1 (ga + Hap dp_e) */
        D = 0;
        for (e = 0; e < nC; e++) {
            double dpe[24], *He = H + (size_t)ND * ND * e, *ge = G + (size_t)ND * e, x[9];
            if (!n->inc[e]) { memset(dal + 9 * e, 0, sizeof(double) * 9); continue; }
            for (a = 0; a < 8; a++) for (i = 0; i < 3; i++) dpe[3 * a + i] = dp[3 * m->cells[8 * e + a] + i];
            for (i = 0; i < 9; i++) { double s = ge[24 + i]; for (a = 0; a < 24; a++) s += He[(24 + i) * ND + a] * dpe[a]; x[i] = s; }
            chol_solve(fac + 81 * e, 9, x);
            for (i = 0; i < 9; i++) { dal[9 * e + i] = -x[i]; D += ge[24 + i] * dal[9 * e + i]; }
        }
        {   /* directional derivative of Pi: true gradient . (dp, dalpha) */
            double *gp = true_gradient(pr, p, G);
            for (i = 0; i < F3; i++) D += gp[i] * dp[i];
            free(gp);
        }
        Pi0 = pi_value(pr, p, alpha);
        if (n->keep_orientation) nlref_min_jacobian(n, p, alpha, inv_wmin(n), &ninv0);
        for (t = 1; t > 1e-12; t *= 0.5) {
            double Pt;
            for (i = 0; i < 3 * n->nV; i++) pt[i] = p[i] + t * dp[i];
            for (i = 0; i < 9 * nC; i++) at[i] = alpha[i] + t * dal[i];
            if (n->keep_orientation) {   /* no step may invert more quadrature points */
                unsigned ninv;
                nlref_min_jacobian(n, pt, at, inv_wmin(n), &ninv);
                if (ninv > ninv0) continue;
            }
            Pt = pi_value(pr, pt, at);
            /* Armijo; near convergence Pi's round-off hides the decrease: a full
             * step that halves the gradient is taken too (quadratic convergence) */
            if (Pt <= Pi0 + 1e-4 * t * D || (t == 1 && grad_norm(pr, pt, at) <= 0.5 * res)) break;
        }
        if (!(t > 1e-12)) break;   /* line search failed */
        if (t < 1e-3 && ++small >= 5) break;   /* stalled (an orientation-keeping solve against a fold) */
        memcpy(p, pt, sizeof(double) * 3 * n->nV);
        memcpy(alpha, at, sizeof(double) * 9 * nC);
    }
    free(K); free(r); free(dp); free(H); free(G); free(fac); free(Y); free(dal); free(pt); free(at); free(Md);
    return rc;
}

/* load = gravity (+ rig) as snref applies it: residual - elastic force */
static void load_of(const snref_state *s, double *load) {
    unsigned i, F3 = 3 * s->m->nF;
    double *f = malloc(sizeof(double) * F3);
    snref_residual(s, load);
    snref_force(s, s->p, f);
    for (i = 0; i < F3; i++) load[i] -= f[i];
    free(f);
}

int nlref_static(nlref *n, snref_state *s, double tol, unsigned max_iter, nlref_stats *st) {
    prob_t pr;
    double *load = malloc(sizeof(double) * 3 * n->nF);
    int rc;
    memset(&pr, 0, sizeof pr);
    skeleton_set(s, s->p);
    load_of(s, load);
    pr.n = n; pr.load = load;
    n->tw_s = s;
    relax_bubbles(n, s->p, n->alpha);
    rc = newton(&pr, s->p, n->alpha, tol, max_iter, st);
    n->tw_s = NULL;
    memset(s->v, 0, sizeof(double) * 3 * n->nV);
    free(load);
    return rc;
}

int nlref_step(nlref *n, snref_state *s, double tol, nlref_stats *st) {
    const snref_model *m = &n->m;
    unsigned N3 = 3 * n->nV, F3 = 3 * n->nF, e, i;
    double *load = malloc(sizeof(double) * F3), *p0 = malloc(sizeof(double) * N3), *v0 = malloc(sizeof(double) * N3);
    double *Kn = malloc(sizeof(double) * 576 * n->nC);
    prob_t pr;
    int rc;
    memcpy(p0, s->p, sizeof(double) * N3);
    memcpy(v0, s->v, sizeof(double) * N3);
    for (e = 0; e < n->nC; e++) {   /* tangent at the start, bubbles condensed */
        double P[24], g[ND], H[ND * ND], fac[81], Y[225];
        unsigned a, b;
        cell_pos(n, e, p0, P);
        nlref_cell(n, e, P, n->alpha + 9 * e, g, H);
        if (n->inc[e]) condense(H, g, Kn + 576 * (size_t)e, NULL, fac, Y);
        else for (a = 0; a < 24; a++) for (b = 0; b < 24; b++) Kn[576 * (size_t)e + 24 * a + b] = H[a * ND + b];
    }
    load_of(s, load);
    /* predictor: p = p0 + v (free), skeleton at the new pose */
    for (i = 0; i < F3; i++) s->p[i] = p0[i] + v0[i];
    skeleton_set(s, s->p);
    memset(&pr, 0, sizeof pr);
    pr.n = n; pr.load = load; pr.dyn = 1; pr.p0 = p0; pr.v0 = v0;
    pr.a1 = m->a1 * s->hscale * s->dscale; pr.b1 = m->b1 / s->hscale * s->dscale; pr.Kn = Kn;
    n->tw_s = s;
    rc = newton(&pr, s->p, n->alpha, tol, 50, st);
    n->tw_s = NULL;
    for (i = 0; i < N3; i++) s->v[i] = s->p[i] - p0[i];
    s->steps++;
    free(load); free(p0); free(v0); free(Kn);
    return rc;
}

static double seg_d2(const double p[3], const double a0[3], const double a1[3]) {
    double ab[3], l2 = 0, t = 0, d2 = 0;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = a1[k] - a0[k]; l2 += ab[k] * ab[k]; t += (p[k] - a0[k]) * ab[k]; }
    t = l2 > 0 ? t / l2 : 0;
    t = t < 0 ? 0 : t > 1 ? 1 : t;
    for (k = 0; k < 3; k++) { double d = p[k] - a0[k] - t * ab[k]; d2 += d * d; }
    return d2;
}

void nlref_twist_cell(const nlref *n, unsigned e, int nseg, const double *A0, const double *A1, int sel, double r, double kappa,
                      int nsub, double T[64]) {
    static const double gp2[2] = {0.21132486540518711775, 0.78867513459481288225};
    const double *x0 = n->o.x + 3 * n->o.cells[8 * e];
    double c = n->o.c, hs = n->hc * n->hc * n->hc, w = hs / (8.0 * nsub * nsub * nsub);
    int sx, sy, sz, g, a, b, k, o;
    memset(T, 0, sizeof(double) * 64);
    for (sz = 0; sz < nsub; sz++) for (sy = 0; sy < nsub; sy++) for (sx = 0; sx < nsub; sx++)
        for (g = 0; g < 8; g++) {
            double t[3], p[3], N[8], d2;
            int mine = 1;
            t[0] = (sx + gp2[g & 1]) / nsub; t[1] = (sy + gp2[(g >> 1) & 1]) / nsub; t[2] = (sz + gp2[(g >> 2) & 1]) / nsub;
            for (k = 0; k < 3; k++) p[k] = x0[k] + t[k] * c;
            d2 = seg_d2(p, A0 + 3 * sel, A1 + 3 * sel);
            if (d2 > r * r) continue;
            for (o = 0; o < nseg && mine; o++) {   /* nearest bone only (ties: the lower index) */
                double d2o;
                if (o == sel) continue;
                d2o = seg_d2(p, A0 + 3 * o, A1 + 3 * o);
                if (d2o < d2 || (d2o == d2 && o < sel)) mine = 0;
            }
            if (!mine) continue;
            sb_shape(t, N, NULL);
            for (a = 0; a < 8; a++) for (b = 0; b < 8; b++) T[8 * a + b] += kappa * w * N[a] * N[b];
        }
}

double nlref_min_jacobian(const nlref *n, const double *p, const double *alpha, double wmin, unsigned *ninv) {
    unsigned e, q, a, i, k;
    double jmin = HUGE_VAL, h = n->hc;
    if (ninv) *ninv = 0;
    for (e = 0; e < n->nC; e++) {
        double P[24];
        int free_ = 0;
        for (a = 0; a < 8; a++) free_ |= n->m.cells[8 * e + a] < n->nF;
        if (!free_) continue;   /* every corner on a bone: the pose alone decides it */
        cell_pos(n, e, p, P);
        for (q = n->efirst[e]; q < n->efirst[e + 1]; q++) {
            const double *pw = n->emw + 4 * (size_t)q;
            double N[8], dN[8][3], F[9] = {0}, J;
            if (pw[3] < wmin) continue;
            sb_shape(pw, N, dN);
            for (a = 0; a < 8; a++) for (i = 0; i < 3; i++) for (k = 0; k < 3; k++) F[3 * i + k] += P[3 * a + i] * dN[a][k] / h;
            if (n->inc[e] && alpha)
                for (a = 0; a < 3; a++) for (i = 0; i < 3; i++) F[3 * i + a] += alpha[9 * e + 3 * a + i] * 4.0 * (1.0 - 2.0 * pw[a]) / h;
            J = F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
            if (J < jmin) jmin = J;
            if (J <= 0 && ninv) (*ninv)++;
        }
    }
    return jmin;
}

static double inv_wmin(const nlref *n) {
    return 0.5 * n->hc * n->hc * n->hc / ((double)n->d.subdiv * n->d.subdiv * n->d.subdiv * 8);
}
