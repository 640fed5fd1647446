/* test_bake_cut.c -- the cut level's elements (tools/sb_cut.c; runtime/LEVELS.md
 * §2 "The cut level") on the cow, in double precision, against level 1's
 * assembled matrices: for random vectors x over the cut level's functions
 * (level 0's vertices, then the extras),
 *
 *     sum_E K_E x_E   ==   P^T S_1 P x     (and M alike),
 *
 * K_E the bake's per-cell sums over E's children of W_c^T S_c W_c, S_1 level 1's
 * assembled stiffness (sb_build's pattern S, not its per-cell matrices) minus the
 * kept level-1 cells outside every kept level-0 cell, P level 1's vertices as the
 * cut basis gives them: a level-0 vertex's own value, a level-1 skeleton vertex
 * its extra, a free one the dyadic weights of the level-0 grid points around it
 * (from positions here, not from the bake's cell walk). Built with air 0, so
 * the children level 1 did not keep add nothing. Also: every cut element's rows
 * sum to 0 over its corners and extras (translations: W_c's rows sum to 1).
 * Then the same with every detail (format 6.5: level 1's free vertices at
 * non-corner points, P's row there the coarse weights plus 1 on the detail),
 * and 'details' refused without 'levels 2 cut'. */
#include "sb_level.h"
#include "sb_cut.h"
#include "sn_format.h"
#include "sn_test.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned long rng = 4242;
static double rnd(void) { rng = rng * 6364136223846793005UL + 1442695040888963407UL; return (double)(rng >> 11) / 9007199254740992.0 - 0.5; }

static int coarse_vertex(const sb_model *o, const int g[3])
{
    if (g[0] < 0 || g[1] < 0 || g[2] < 0 || g[0] >= o->gn[0] || g[1] >= o->gn[1] || g[2] >= o->gn[2]) return -1;
    return o->gvert[g[0] + o->gn[0] * (g[1] + o->gn[1] * g[2])];
}

/* Dense Cholesky solve of the SPD system A x = b (n unknowns, A overwritten, x in b); a zero row (an unknown no
 * element reaches) is pinned at 0. Returns -1 if a pivot is not positive. */
static int chol_solve(double *A, int n, double *b)
{
    int i, j, k, *fst = malloc(sizeof(int) * (size_t)n);   /* each row's first nonzero: the factor keeps the profile */
    for (i = 0; i < n; i++) {
        if (A[(size_t)n * i + i] == 0) { A[(size_t)n * i + i] = 1; b[i] = 0; }
        for (fst[i] = 0; fst[i] < i && A[(size_t)n * i + fst[i]] == 0; fst[i]++) {}
    }
    for (j = 0; j < n; j++) {
        double *rj = A + (size_t)n * j, d = rj[j];
        for (k = fst[j]; k < j; k++) d -= rj[k] * rj[k];
        if (!(d > 0)) { free(fst); return -1; }
        rj[j] = d = sqrt(d);
        for (i = j + 1; i < n; i++) {
            double *ri = A + (size_t)n * i, t = ri[j];
            if (fst[i] > j) continue;
            for (k = fst[i] > fst[j] ? fst[i] : fst[j]; k < j; k++) t -= ri[k] * rj[k];
            ri[j] = t / d;
        }
    }
    free(fst);
    for (i = 0; i < n; i++) { for (k = 0; k < i; k++) b[i] -= A[(size_t)n * i + k] * b[k]; b[i] /= A[(size_t)n * i + i]; }
    for (i = n - 1; i >= 0; i--) { for (k = i + 1; k < n; k++) b[i] -= A[(size_t)n * k + i] * b[k]; b[i] /= A[(size_t)n * i + i]; }
    return 0;
}

/* The preconditioner study (`test_bake_cut --precond`, not in make test): PCG on the step matrix
 * A = (1+a1) M + (1+b1) h^2 K (NUMERICS step 5-6, rest frame) from 0 to |r| <= 1e-4 |b|, b the gravity load, with
 * (1) IC(0) of A on its pattern (every function: the design's masked IC(0) with all active; diagonal shift s A_ii
 * doubled from 1e-3 until the pivots are positive), (2) IC(0) of the coarse block + 3x3 block Jacobi on the
 * details (coupling dropped). Returns the iterations (500: not converged); *shift the shift used. */
static int ic0(const double *A, int n, const int *blk, double *L, double *shift, int nfix)
{
    int i, j, k;
    for (*shift = 0;; *shift = *shift ? 2 * *shift : 1e-3) {
        int ok = 1;
        for (i = 0; i < n && ok; i++)
            for (j = 0; j <= i; j++) {
                double t = A[(size_t)n * i + j];
                if (t == 0 || (blk && blk[i] != blk[j])) { L[(size_t)n * i + j] = 0; continue; }   /* IC(0): A's pattern, within a block */
                if (i == j && i >= nfix) t *= 1 + *shift;   /* rows before nfix unshifted */
                for (k = 0; k < j; k++) t -= L[(size_t)n * i + k] * L[(size_t)n * j + k];
                if (i == j) { if (!(t > 0)) { ok = 0; break; } L[(size_t)n * i + i] = sqrt(t); }
                else L[(size_t)n * i + j] = t / L[(size_t)n * j + j];
            }
        if (ok) return 0;
        if (*shift > 1) return -1;
    }
}
static void ic0_apply(const double *L, int n, const double *r, double *z)
{
    int i, k;
    for (i = 0; i < n; i++) { double t = r[i]; for (k = 0; k < i; k++) t -= L[(size_t)n * i + k] * z[k]; z[i] = t / L[(size_t)n * i + i]; }
    for (i = n - 1; i >= 0; i--) { double t = z[i]; for (k = i + 1; k < n; k++) t -= L[(size_t)n * k + i] * z[k]; z[i] = t / L[(size_t)n * i + i]; }
}
static int pcg_iters(const double *A, int n, const double *b, const double *L, double *xout)
{
    double *x = calloc((size_t)n, sizeof(double)), *r = calloc((size_t)n, sizeof(double)), *z = calloc((size_t)n, sizeof(double));
    double *d = malloc(sizeof(double) * (size_t)n), *q = malloc(sizeof(double) * (size_t)n), rz, bn = 0, rn;
    int i, k, it;
    for (i = 0; i < n; i++) { r[i] = b[i]; bn += b[i] * b[i]; }
    ic0_apply(L, n, r, z);
    for (i = 0, rz = 0; i < n; i++) { d[i] = z[i]; rz += r[i] * z[i]; }
    for (it = 0; it < 500; it++) {
        double dq = 0, al, rz2 = 0;
        for (i = 0, rn = 0; i < n; i++) rn += r[i] * r[i];
        if (rn <= 1e-8 * bn) break;
        for (i = 0; i < n; i++) { double t = 0; const double *ai = A + (size_t)n * i; for (k = 0; k < n; k++) t += ai[k] * d[k]; q[i] = t; dq += d[i] * t; }
        al = rz / dq;
        for (i = 0; i < n; i++) { x[i] += al * d[i]; r[i] -= al * q[i]; }
        ic0_apply(L, n, r, z);
        for (i = 0; i < n; i++) rz2 += r[i] * z[i];
        for (i = 0; i < n; i++) d[i] = z[i] + rz2 / rz * d[i];
        rz = rz2;
    }
    if (xout) memcpy(xout, x, sizeof(double) * (size_t)n);
    free(x); free(r); free(z); free(d); free(q);
    return it;
}
static int g_precond;

static void check(const char *path)
{
    sb_desc d, d2;
    sb_mesh m;
    sb_srcmap src;
    sb_model o, o2;
    sb_cut cut, cutA;
    int i, k, E, a, b, n, N, wd, bad = 0, norphan = 0, *pn, *pi, *xof, *dof, *orphan;
    double *u1 = NULL, smax[3], srms[3], fmaxs[3], frms[3];
    int sunk[3], *held, nheld = 0, nair = 0, nfree0 = 0, air0ok = -1;
    double *pw, *x, *ya, *yb, *ma, *mb, *px, *spx, *mpx, ea = 0, sa = 0, em = 0, sm = 0, rowsum = 0, rowscale = 0;
    const int NL = SB_CUT_NL, N3 = 3 * SB_CUT_NL;
    memset(&m, 0, sizeof m); memset(&o, 0, sizeof o); memset(&o2, 0, sizeof o2);
    if (sb_desc_load(path, &d) || sb_desc_mesh(&d, &m, &src) || sb_build(&d, &m, &o, 1)) { T_CHECK(0, "%s: %s", path, sb_error()); return; }
    d.levels = 2; d.levels_cut = 1;
    sb_level_desc(&d, &o, &d2);
    if (sb_level_model(&d, &d2, &m, &o2) || sb_cut_build(&o, &o2, 0.0, &cut)) { T_CHECK(0, "%s: %s", path, sb_error()); return; }
    /* the statics below take the bake's air element (d.air: without it a coarse vertex outside level 1's lattice,
     * with every detail around it active, has no stiffness left: the details cancel its hat in the kept children) */
    if (sb_cut_build(&o, &o2, d.air, &cutA)) { T_CHECK(0, "%s: %s", path, sb_error()); return; }
    /* The air-held coarse vertices (LEVELS.md §3): a coarse unknown at a grid point where level 1 has no vertex
     * has, in the kept children, a hat that is a sum of the level-1 hats at its neighbouring points; with all of
     * those details active they cancel it and only the air holds its mode. Rule (ii): per such vertex (index
     * order) hold out its own detail, the one of largest weight on it (4/8 an edge point, 2/8 a face, 1/8 the
     * centre) not held out already, ties by the detail's index (one shared by two vertices leaves a combination
     * of their hats cancelled). */
    held = calloc((size_t)cut.nd + 1, sizeof(int));
    for (i = 0; i < o.nv; i++) {
        int best = -1, bw = 0;
        if (!(i < o.nf || (cut.v1[i] >= 0 && cut.v1[i] < o2.nf)) || cut.v1[i] >= 0) continue;
        nair++;
        for (E = 0; E < o.nc; E++)
            for (a = 0; a < 8; a++) {
                int pt;
                if (o.cells[8 * E + a] != i) continue;
                for (pt = 0; pt < 27; pt++) {
                    int p3[3] = {pt % 3, pt / 3 % 3, pt / 9}, w = 1, dd = cut.dsub[27 * E + pt];
                    for (k = 0; k < 3; k++) w *= (a >> k & 1) ? p3[k] : 2 - p3[k];
                    if (dd < 0 || w == 0) continue;
                    if (held[dd]) continue;
                    if (w > bw || (w == bw && dd < best)) { bw = w; best = dd; }
                }
            }
        if (best >= 0) { held[best] = 1; nheld++; } else nfree0++;
    }
    for (wd = 0; wd < 3; wd++) {
    /* wd 1: the details too (level-1 free vertices at non-corner points of kept cells, after the extras);
     * wd 2: every detail but the held-out ones (their columns 0, their rows left out of the comparison) */
    N = o.nv + cut.nx + (wd ? cut.nd : 0);
    norphan = 0; bad = 0; ea = sa = em = sm = rowsum = rowscale = 0;
    /* P's rows over level 1's vertices, from positions on the two grids */
    xof = malloc(sizeof(int) * (size_t)o2.nv); dof = malloc(sizeof(int) * (size_t)o2.nv);
    for (n = 0; n < o2.nv; n++) xof[n] = dof[n] = -1;
    for (i = 0; i < cut.nx; i++) xof[cut.xv[i]] = o.nv + i;
    for (i = 0; wd && i < cut.nd; i++) if (wd == 1 || !held[i]) dof[cut.dv[i]] = o.nv + cut.nx + i;
    pn = calloc((size_t)o2.nv + 1, sizeof(int)); pi = malloc(sizeof(int) * 9 * (size_t)o2.nv); pw = malloc(sizeof(double) * 9 * (size_t)o2.nv);
    for (n = 0; n < o2.nv; n++) {
        double t[3];
        int g[3], odd = 0;
        for (k = 0; k < 3; k++) { t[k] = (o2.x[3 * n + k] - o.gorg[k]) / o.c; g[k] = (int)floor(t[k] + 1e-9); t[k] -= g[k]; odd |= fabs(t[k] - 0.5) < 1e-9; }
        pn[n + 1] = pn[n];
        if (odd && n >= o2.nf && xof[n] >= 0) { pi[pn[n + 1]] = xof[n]; pw[pn[n + 1]++] = 1; continue; }
        for (a = 0; a < 8; a++) {
            int ga[3], v;
            double w = 1;
            for (k = 0; k < 3; k++) { ga[k] = g[k] + (a >> k & 1); w *= (a >> k & 1) ? t[k] : 1 - t[k]; }
            if (w < 1e-12) continue;
            if ((v = coarse_vertex(&o, ga)) < 0) { pn[n + 1] = pn[n]; pi[pn[n]] = -1; break; }   /* outside level 0: no row */
            pi[pn[n + 1]] = v; pw[pn[n + 1]++] = w;
        }
        if (pn[n + 1] > pn[n] && dof[n] >= 0) { pi[pn[n + 1]] = dof[n]; pw[pn[n + 1]++] = 1; }   /* + its detail */
        if (pn[n + 1] == pn[n] && dof[n] >= 0) bad++;   /* a detail where level 0 has no row */
    }
    /* the kept level-1 cells in no kept level-0 cell: taken out of level 1's sums */
    orphan = calloc((size_t)o2.nc, sizeof(int));
    {
        int *cellat = malloc(sizeof(int) * (size_t)o.gn[0] * (size_t)o.gn[1] * (size_t)o.gn[2]);
        for (i = 0; i < o.gn[0] * o.gn[1] * o.gn[2]; i++) cellat[i] = -1;
        for (E = 0; E < o.nc; E++) cellat[o.cell_grid[E]] = E;
        for (i = 0; i < o2.nc; i++) {
            int g[3];
            const double *x0 = o2.x + 3 * o2.cells[8 * i];
            for (k = 0; k < 3; k++) g[k] = (int)floor((x0[k] - o.gorg[k]) / o.c + 1e-9);
            orphan[i] = g[0] < 0 || g[1] < 0 || g[2] < 0 || g[0] >= o.gn[0] - 1 || g[1] >= o.gn[1] - 1 || g[2] >= o.gn[2] - 1 ||
                        cellat[g[0] + (o.gn[0] - 1) * (g[1] + (o.gn[1] - 1) * g[2])] < 0;
            norphan += orphan[i];
        }
        free(cellat);
    }
    x = malloc(sizeof(double) * 3 * (size_t)N); ya = calloc(3 * (size_t)N, sizeof(double)); yb = calloc(3 * (size_t)N, sizeof(double));
    ma = calloc(3 * (size_t)N, sizeof(double)); mb = calloc(3 * (size_t)N, sizeof(double));
    px = calloc(3 * (size_t)o2.nv, sizeof(double)); spx = calloc(3 * (size_t)o2.nv, sizeof(double)); mpx = calloc(3 * (size_t)o2.nv, sizeof(double));
    for (i = 0; i < 3 * N; i++) x[i] = wd == 2 && i >= 3 * (o.nv + cut.nx) && held[i / 3 - o.nv - cut.nx] ? 0 : rnd();
    /* the bake's elements, scattered */
    for (E = 0; E < o.nc; E++) {
        int vl[SB_CUT_NL], nl = 8 + cut.cnx[E] + (wd ? cut.cnd[E] : 0), r, s;
        const double *KE = cut.K + (size_t)(N3 * N3) * (size_t)E, *ME = cut.M + (size_t)(NL * NL) * (size_t)E;
        for (a = 0; a < 8; a++) vl[a] = o.cells[8 * E + a];
        for (a = 0; a < cut.cnx[E]; a++) vl[8 + a] = o.nv + cut.cx[SB_CUT_MAXX * E + a];
        for (a = 0; wd && a < cut.cnd[E]; a++) vl[8 + cut.cnx[E] + a] = o.nv + cut.nx + cut.cd[SB_CUT_MAXX * E + a];
        for (a = 0; a < nl; a++)
            for (r = 0; r < 3; r++) {
                double rs = 0, sc = 0;
                for (b = 0; b < nl; b++) {
                    ma[3 * vl[a] + r] += ME[NL * a + b] * x[3 * vl[b] + r];
                    for (s = 0; s < 3; s++) {
                        double kk = KE[(size_t)N3 * (size_t)(3 * a + r) + (size_t)(3 * b + s)];
                        ya[3 * vl[a] + r] += kk * x[3 * vl[b] + s];
                        if (b < 8 + cut.cnx[E]) rs += kk;   /* a translation: corners and extras move, details stay 0 */
                        sc += fabs(kk);
                    }
                }
                rowsum = fmax(rowsum, fabs(rs)); rowscale = fmax(rowscale, sc);
            }
    }
    /* level 1's assembled matrices through P */
    for (n = 0; n < o2.nv; n++) {
        if (pn[n + 1] == pn[n] && pi[pn[n]] == -1) continue;
        for (k = pn[n]; k < pn[n + 1]; k++) for (a = 0; a < 3; a++) px[3 * n + a] += pw[k] * x[3 * pi[k] + a];
    }
    for (n = 0; n < o2.nv; n++)
        for (k = o2.nbptr[n]; k < o2.nbptr[n + 1]; k++) {
            int j = o2.nb[k], r, s;
            for (r = 0; r < 3; r++) {
                mpx[3 * n + r] += o2.M[k] * px[3 * j + r];
                for (s = 0; s < 3; s++) spx[3 * n + r] += o2.S[9 * (size_t)k + (size_t)(3 * r + s)] * px[3 * j + s];
            }
        }
    for (i = 0; i < o2.nc; i++) {
        int r, s;
        if (!orphan[i]) continue;
        for (a = 0; a < 8; a++)
            for (b = 0; b < 8; b++)
                for (r = 0; r < 3; r++) {
                    int na = o2.cells[8 * i + a], nb = o2.cells[8 * i + b];
                    mpx[3 * na + r] -= o2.Me[64 * (size_t)i + (size_t)(8 * a + b)] * px[3 * nb + r];
                    for (s = 0; s < 3; s++) spx[3 * na + r] -= o2.Se[576 * (size_t)i + (size_t)(24 * (3 * a + r) + 3 * b + s)] * px[3 * nb + s];
                }
    }
    for (n = 0; n < o2.nv; n++) {
        if (pn[n + 1] == pn[n]) {   /* no row (outside level 0's grid): nothing of its may remain */
            for (a = 0; a < 3; a++) bad += fabs(spx[3 * n + a]) > 1e-9 || fabs(mpx[3 * n + a]) > 1e-12;
            continue;
        }
        for (k = pn[n]; k < pn[n + 1]; k++)
            for (a = 0; a < 3; a++) { yb[3 * pi[k] + a] += pw[k] * spx[3 * n + a]; mb[3 * pi[k] + a] += pw[k] * mpx[3 * n + a]; }
    }
    for (i = 0; i < 3 * N; i++) {
        if (wd == 2 && i >= 3 * (o.nv + cut.nx) && held[i / 3 - o.nv - cut.nx]) continue;
        ea = fmax(ea, fabs(ya[i] - yb[i])); sa = fmax(sa, fabs(ya[i]));
        em = fmax(em, fabs(ma[i] - mb[i])); sm = fmax(sm, fabs(ma[i]));
    }
    T_FIGURE("%s: cut level%s: %d extras, %d details, %d level-1 cells outside the kept level-0 cells; sum_E K_E x vs P^T S_1 P x %.2e, "
             "mass %.2e (of the largest entry of the product); element rows sum to %.2e of the row's |K| sum", path,
             wd == 1 ? " with every detail" : wd ? " with every detail but the held-out" : "", cut.nx, wd == 1 ? cut.nd : wd ? cut.nd - nheld : 0, norphan, ea / sa, em / sm, rowsum / rowscale);
    /* 1e-12: each product entry sums <= 8 children x 64 corner pairs x 81 weighted terms, in another order than
     * the assembled route (rounding ~1e-15 relative per term); the rows' null space likewise */
    T_CHECK(ea <= 1e-12 * sa && em <= 1e-12 * sm, "%s: cut elements vs level 1's assembled Galerkin product: stiffness %g, mass %g (want <= 1e-12)",
            path, ea / sa, em / sm);
    T_CHECK(rowsum <= 1e-12 * rowscale, "%s: cut element rows sum to %g of their scale (want <= 1e-12: translations)", path, rowsum / rowscale);
    T_CHECK(bad == 0, "%s: %d level-1 rows outside level 0's grid kept a stiffness or mass", path, bad);
    {   /* linear statics under gravity (rest frame, skeleton held): the cut level (wd 0) and with every detail (wd 1)
         * against level 1 (its kept cells in kept level-0 cells), on level 1's vertices: what stage 2's runtime
         * test asks in motion (LEVELS.md §3 "Details on the cut level") */
        int nu = 0, *uid = malloc(sizeof(int) * (size_t)N), r, s2;
        double *A, *f, um = 0, em = 0, e2 = 0;
        double *key = malloc(sizeof(double) * (size_t)N);
        int *ord = malloc(sizeof(int) * (size_t)N), m2;
        for (i = 0; i < N; i++) {   /* unknowns numbered along z, then y, x (a short profile for the factor) */
            const double *xp = i < o.nv ? o.x + 3 * i : i >= o.nv + cut.nx ? cut.dx + 3 * (i - o.nv - cut.nx) : NULL;
            int fr = i < o.nv ? i < o.nf || (cut.v1[i] >= 0 && cut.v1[i] < o2.nf) : i >= o.nv + cut.nx && !(wd == 2 && held[i - o.nv - cut.nx]);
            uid[i] = fr ? 0 : -1;
            key[i] = xp ? (xp[2] * 1e6 + xp[1]) * 1e6 + xp[0] : 0;
            ord[i] = i;
        }
        for (i = 1; i < N; i++) {   /* insertion sort by key (ties by index) */
            int t = ord[i];
            for (m2 = i; m2 > 0 && key[ord[m2 - 1]] > key[t]; m2--) ord[m2] = ord[m2 - 1];
            ord[m2] = t;
        }
        for (i = 0; i < N; i++) if (uid[ord[i]] >= 0) uid[ord[i]] = nu++;
        free(key); free(ord);
        A = calloc((size_t)9 * (size_t)nu * (size_t)nu, sizeof(double)); f = calloc(3 * (size_t)nu, sizeof(double));
        for (E = 0; E < o.nc; E++) {
            int vl[SB_CUT_NL], nl = 8 + cut.cnx[E] + (wd ? cut.cnd[E] : 0);
            const double *KE = cutA.K + (size_t)(N3 * N3) * (size_t)E, *ME = cutA.M + (size_t)(NL * NL) * (size_t)E;
            for (a = 0; a < 8; a++) vl[a] = o.cells[8 * E + a];
            for (a = 0; a < cut.cnx[E]; a++) vl[8 + a] = o.nv + cut.cx[SB_CUT_MAXX * E + a];
            for (a = 0; wd && a < cut.cnd[E]; a++) vl[8 + cut.cnx[E] + a] = o.nv + cut.nx + cut.cd[SB_CUT_MAXX * E + a];
            for (a = 0; a < nl; a++) {
                int ia = uid[vl[a]];
                if (ia < 0) continue;
                for (b = 0; b < 8 + cut.cnx[E]; b++) f[3 * ia + 1] -= ME[NL * a + b];   /* g = -y: the cut basis sums to 1 without the details */
                for (b = 0; b < nl; b++) {
                    int ib = uid[vl[b]];
                    if (ib < 0) continue;
                    for (r = 0; r < 3; r++)
                        for (s2 = 0; s2 < 3; s2++)
                            A[(size_t)3 * nu * (size_t)(3 * ia + r) + (size_t)(3 * ib + s2)] += KE[(size_t)N3 * (size_t)(3 * a + r) + (size_t)(3 * b + s2)];
                }
            }
        }
        if (wd == 2) {   /* with air 0 (the bake's elements without the air element) the held-out rule leaves no
                          * coarse hat cancelled: the system stays positive definite (every detail: singular) */
            double *A0 = calloc((size_t)9 * (size_t)nu * (size_t)nu, sizeof(double)), *f0 = calloc(3 * (size_t)nu, sizeof(double));
            for (E = 0; E < o.nc; E++) {
                int vl[SB_CUT_NL], nl = 8 + cut.cnx[E] + cut.cnd[E];
                const double *KE = cut.K + (size_t)(N3 * N3) * (size_t)E;
                for (a = 0; a < 8; a++) vl[a] = o.cells[8 * E + a];
                for (a = 0; a < cut.cnx[E]; a++) vl[8 + a] = o.nv + cut.cx[SB_CUT_MAXX * E + a];
                for (a = 0; a < cut.cnd[E]; a++) vl[8 + cut.cnx[E] + a] = o.nv + cut.nx + cut.cd[SB_CUT_MAXX * E + a];
                for (a = 0; a < nl; a++)
                    for (b = 0; b < nl; b++)
                        if (uid[vl[a]] >= 0 && uid[vl[b]] >= 0)
                            for (r = 0; r < 3; r++)
                                for (s2 = 0; s2 < 3; s2++)
                                    A0[(size_t)3 * nu * (size_t)(3 * uid[vl[a]] + r) + (size_t)(3 * uid[vl[b]] + s2)] +=
                                        KE[(size_t)N3 * (size_t)(3 * a + r) + (size_t)(3 * b + s2)];
            }
            for (i = 0; i < 3 * nu; i++) f0[i] = 1;
            air0ok = chol_solve(A0, 3 * nu, f0) == 0;
            free(A0); free(f0);
        }
        if (!u1) {   /* level 1, once: its assembled matrices less the cells in no kept level-0 cell */
            int n1 = o2.nf;
            double *A1 = calloc((size_t)9 * (size_t)n1 * (size_t)n1, sizeof(double));
            u1 = calloc(3 * (size_t)o2.nv, sizeof(double));
            for (n = 0; n < n1; n++)
                for (k = o2.nbptr[n]; k < o2.nbptr[n + 1]; k++) {
                    int j = o2.nb[k];
                    u1[3 * n + 1] -= o2.M[k];
                    if (j >= n1) continue;
                    for (r = 0; r < 3; r++) for (s2 = 0; s2 < 3; s2++) A1[(size_t)3 * n1 * (size_t)(3 * n + r) + (size_t)(3 * j + s2)] += o2.S[9 * (size_t)k + (size_t)(3 * r + s2)];
                }
            for (i = 0; i < o2.nc; i++) {
                if (!orphan[i]) continue;
                for (a = 0; a < 8; a++)
                    for (b = 0; b < 8; b++) {
                        int na = o2.cells[8 * i + a], nb = o2.cells[8 * i + b];
                        if (na >= n1) continue;
                        u1[3 * na + 1] += o2.Me[64 * (size_t)i + (size_t)(8 * a + b)];
                        if (nb >= n1) continue;
                        for (r = 0; r < 3; r++) for (s2 = 0; s2 < 3; s2++)
                            A1[(size_t)3 * n1 * (size_t)(3 * na + r) + (size_t)(3 * nb + s2)] -= o2.Se[576 * (size_t)i + (size_t)(24 * (3 * a + r) + 3 * b + s2)];
                    }
            }
            for (i = 0; i < 9 * n1 * n1; i++) if (fabs(A1[i]) < 1e-9 * fabs(A1[(size_t)(3 * n1 + 1) * (size_t)(i / (3 * n1))])) A1[i] = 0;   /* the orphans' cancellation */
            T_CHECK(chol_solve(A1, 3 * n1, u1) == 0, "%s: level 1's static system is positive definite", path);
            free(A1);
        }
        if (g_precond) {   /* the step matrix: the mass as its own pass (it needs the element's mass blocks again) */
            int n3 = 3 * nu, *blk = malloc(sizeof(int) * (size_t)n3), it1, it2;
            double *S = malloc(sizeof(double) * (size_t)n3 * (size_t)n3), *L = malloc(sizeof(double) * (size_t)n3 * (size_t)n3), sh1, sh2;
            double hh = o.h, a1 = hh * o.alpha, b1 = o.beta / hh;
            for (i = 0; i < n3 * n3; i++) S[i] = (1 + b1) * hh * hh * A[i];
            for (E = 0; E < o.nc; E++) {
                int vl[SB_CUT_NL], nl = 8 + cut.cnx[E] + (wd ? cut.cnd[E] : 0);
                const double *ME = cutA.M + (size_t)(NL * NL) * (size_t)E;
                for (a = 0; a < 8; a++) vl[a] = o.cells[8 * E + a];
                for (a = 0; a < cut.cnx[E]; a++) vl[8 + a] = o.nv + cut.cx[SB_CUT_MAXX * E + a];
                for (a = 0; wd && a < cut.cnd[E]; a++) vl[8 + cut.cnx[E] + a] = o.nv + cut.nx + cut.cd[SB_CUT_MAXX * E + a];
                for (a = 0; a < nl; a++)
                    for (b = 0; b < nl; b++)
                        if (uid[vl[a]] >= 0 && uid[vl[b]] >= 0)
                            for (r = 0; r < 3; r++) S[(size_t)n3 * (size_t)(3 * uid[vl[a]] + r) + (size_t)(3 * uid[vl[b]] + r)] += (1 + a1) * ME[NL * a + b];
            }
            for (i = 0; i < N; i++) if (uid[i] >= 0) for (r = 0; r < 3; r++) blk[3 * uid[i] + r] = i < o.nv ? 0 : 1 + uid[i];
            it1 = ic0(S, n3, NULL, L, &sh1, 0) ? -1 : pcg_iters(S, n3, f, L, NULL);
            it2 = ic0(S, n3, blk, L, &sh2, 0) ? -1 : pcg_iters(S, n3, f, L, NULL);
            {   /* (3) coarse rows first, unshifted (the cut level's own IC(0): no detail active = the cut level's factor),
                 * then the details, the shift on their pivots only: masking off inactive details restricts it exactly */
                int *pm = malloc(sizeof(int) * (size_t)n3), nc3 = 0, it3, jj;
                double *P2 = malloc(sizeof(double) * (size_t)n3 * (size_t)n3), *f2 = malloc(sizeof(double) * (size_t)n3), sh3;
                for (i = 0; i < n3; i++) if (blk[i] == 0) pm[nc3++] = i;
                for (i = 0, jj = nc3; i < n3; i++) if (blk[i] != 0) pm[jj++] = i;
                for (i = 0; i < n3; i++) {
                    f2[i] = f[pm[i]];
                    for (jj = 0; jj < n3; jj++) P2[(size_t)n3 * i + jj] = S[(size_t)n3 * pm[i] + pm[jj]];
                }
                double *xs = calloc((size_t)n3, sizeof(double));
                it3 = ic0(P2, n3, NULL, L, &sh3, nc3) ? -1 : pcg_iters(P2, n3, f2, L, xs);
                printf("  precond %s%s: coarse rows first (unshifted), the details after (shift %g on their pivots): %d iterations\n", path,
                       wd == 1 ? " every detail" : wd ? " every detail but the held-out" : " cut level", sh3, it3);
                if (wd && it3 >= 0) {   /* the same factor masked to the coarse rows + the K details of largest |x| (the static answer) */
                    static const int Ks[3] = {0, 25, 50};
                    int kq, nd3 = (n3 - nc3) / 3;
                    for (kq = 0; kq < 3; kq++) {
                        int *on = calloc((size_t)nd3, sizeof(int)), *ix = malloc(sizeof(int) * (size_t)n3), na = 0, t2, q2;
                        double *Aa, *La, *fa;
                        for (t2 = 0; t2 < Ks[kq]; t2++) {   /* the K largest, ties by index */
                            int best = -1;
                            double bm = -1;
                            for (q2 = 0; q2 < nd3; q2++) {
                                double mm = 0;
                                for (jj = 0; jj < 3; jj++) mm = fmax(mm, fabs(xs[nc3 + 3 * q2 + jj]));
                                if (!on[q2] && mm > bm) { bm = mm; best = q2; }
                            }
                            if (best >= 0) on[best] = 1;
                        }
                        for (i = 0; i < n3; i++) if (i < nc3 || on[(i - nc3) / 3]) ix[na++] = i;
                        Aa = malloc(sizeof(double) * (size_t)na * (size_t)na); La = malloc(sizeof(double) * (size_t)na * (size_t)na);
                        fa = malloc(sizeof(double) * (size_t)na);
                        for (i = 0; i < na; i++) {
                            fa[i] = f2[ix[i]];
                            for (jj = 0; jj < na; jj++) {
                                Aa[(size_t)na * i + jj] = P2[(size_t)n3 * ix[i] + ix[jj]];
                                La[(size_t)na * i + jj] = L[(size_t)n3 * ix[i] + ix[jj]];
                            }
                        }
                        printf("  precond %s: that factor masked to the coarse rows + the %d details of largest static answer: %d iterations\n", path,
                               Ks[kq], pcg_iters(Aa, na, fa, La, NULL));
                        free(on); free(ix); free(Aa); free(La); free(fa);
                    }
                }
                free(xs);
                free(pm); free(P2); free(f2);
            }
            printf("  precond %s%s: %d unknowns: IC(0) of every function %d iterations (shift %g); coarse IC(0) + block Jacobi on the details %d "
                   "(shift %g)\n", path, wd == 1 ? " every detail" : wd ? " every detail but the held-out" : " cut level", n3, it1, sh1, it2, sh2);
            free(S); free(L); free(blk);
        }
        T_CHECK(chol_solve(A, 3 * nu, f) == 0, "%s: the cut level's static system%s is positive definite", path, wd ? " with every detail" : "");
        for (n = 0; n < o2.nv; n++) if (n < o2.nf) for (a = 0; a < 3; a++) um = fmax(um, fabs(u1[3 * n + a]));
        for (n = 0, k = 0; n < o2.nv; n++) {
            double pu[3] = {0, 0, 0}, q;
            int kk;
            if (pn[n + 1] == pn[n]) continue;
            for (kk = pn[n]; kk < pn[n + 1]; kk++) if (uid[pi[kk]] >= 0) for (a = 0; a < 3; a++) pu[a] += pw[kk] * f[3 * uid[pi[kk]] + a];
            for (a = 0; a < 3; a++) { q = fabs(pu[a] - (n < o2.nf ? u1[3 * n + a] : 0)); em = fmax(em, q); e2 += q * q; }
            k++;
        }
        smax[wd] = em / um; srms[wd] = sqrt(e2 / (3.0 * k)) / um; sunk[wd] = 3 * nu;
        {   /* the surface (what the runtime draws): level 1's trilinear in its cell; the cut field in the child holding
             * the point, its corners the coarse field's dyadic values, 0 at an extra, + the detail there (wd 1) */
            double sm = 0, se = 0, s2e = 0;
            int sv;
            for (sv = 0; sv < o.ns; sv++) {
                const double *t = o.emb_t + 3 * sv, *t1 = o2.emb_t + 3 * sv;
                int c0[3], ch, q;
                double w1[3] = {0, 0, 0}, wc[3] = {0, 0, 0};
                E = o.emb_cell[sv];
                for (a = 0; a < 8; a++) {   /* level 1 */
                    int v = o2.cells[8 * o2.emb_cell[sv] + a];
                    double w = 1;
                    for (q = 0; q < 3; q++) w *= (a >> q & 1) ? t1[q] : 1 - t1[q];
                    if (v < o2.nf) for (q = 0; q < 3; q++) w1[q] += w * u1[3 * v + q];
                }
                for (q = 0; q < 3; q++) { c0[q] = t[q] >= 0.5; }
                for (ch = 0; ch < 8; ch++) {   /* the child's corner ch at half-cell point pt */
                    int uu[3], pt, b2;
                    double w = 1, val[3] = {0, 0, 0};
                    for (q = 0; q < 3; q++) {
                        double tc = 2 * t[q] - c0[q];
                        uu[q] = c0[q] + (ch >> q & 1);
                        w *= (ch >> q & 1) ? tc : 1 - tc;
                    }
                    pt = uu[0] + 3 * uu[1] + 9 * uu[2];
                    if (cut.csub[27 * E + pt] >= 0) continue;   /* an extra: held */
                    for (b2 = 0; b2 < 8; b2++) {   /* the coarse field there */
                        double wb = 1;
                        int id = uid[o.cells[8 * E + b2]];
                        for (q = 0; q < 3; q++) wb *= (b2 >> q & 1) ? 0.5 * uu[q] : 1 - 0.5 * uu[q];
                        if (wb != 0 && id >= 0) for (q = 0; q < 3; q++) val[q] += wb * f[3 * id + q];
                    }
                    if (wd && cut.dsub[27 * E + pt] >= 0) {
                        int id = uid[o.nv + cut.nx + cut.dsub[27 * E + pt]];
                        if (id >= 0) for (q = 0; q < 3; q++) val[q] += f[3 * id + q];
                    }
                    for (q = 0; q < 3; q++) wc[q] += w * val[q];
                }
                for (q = 0; q < 3; q++) {
                    double dq = fabs(wc[q] - w1[q]);
                    sm = fmax(sm, fabs(w1[q])); se = fmax(se, dq); s2e += dq * dq;
                }
            }
            fmaxs[wd] = se / sm; frms[wd] = sqrt(s2e / (3.0 * o.ns)) / sm;
        }
        free(A); free(f); free(uid);
    }
    free(x); free(ya); free(yb); free(ma); free(mb); free(px); free(spx); free(mpx); free(pn); free(pi); free(pw); free(xof); free(dof);
    free(orphan);
    }
    T_FIGURE("%s: linear statics under gravity against level 1 (%d unknowns), of its largest displacement: lattice: cut level (%d unknowns) "
             "max %.3g rms %.3g, with every detail (%d) max %.3g rms %.3g; surface: cut level max %.3g rms %.3g, with every detail max %.3g rms %.3g",
             path, 3 * o2.nf, sunk[0], smax[0], srms[0], sunk[1], smax[1], srms[1], fmaxs[0], frms[0], fmaxs[1], frms[1]);
    T_FIGURE("%s: air-held coarse vertices (free, at no level-1 vertex) %d; details held out (one in each one's support) %d of %d; "
             "statics with the rest (%d unknowns): lattice max %.3g rms %.3g, surface max %.3g rms %.3g; with air 0 %s",
             path, nair, nheld, cut.nd, sunk[2], smax[2], srms[2], fmaxs[2], frms[2], air0ok ? "positive definite" : "singular");
    T_CHECK(air0ok == 1, "%s: with the held-out details inactive and air 0 the static system is positive definite", path);
    T_CHECK(smax[2] < smax[0] && srms[2] < srms[0] && fmaxs[2] < fmaxs[0] && frms[2] < frms[0],
            "%s: statics with every detail but the held-out nearer level 1 than the cut level", path);
    /* the details add level 1's free hats inside the kept cells: nearer level 1 at every measure */
    T_CHECK(smax[1] < smax[0] && srms[1] < srms[0] && fmaxs[1] < fmaxs[0] && frms[1] < frms[0],
            "%s: statics with every detail nearer level 1 than the cut level (lattice max %.3g vs %.3g, rms %.3g vs %.3g; surface max %.3g vs %.3g, "
            "rms %.3g vs %.3g)", path, smax[1], smax[0], srms[1], srms[0], fmaxs[1], fmaxs[0], frms[1], frms[0]);
    free(u1); free(held);
    sb_cut_free(&cut); sb_cut_free(&cutA); sb_model_free(&o2); sb_model_free(&o); sb_mesh_free(&m); sb_srcmap_free(&src); sb_desc_free(&d);
}

/* What the cut level carries and what it refuses at bake time (the limb plus one extra line each;
 * $BUILD/tests/cut_refuse/): constraints, colliders and crease bake (their rows follow the cut field,
 * sn_point_weights); 'adapt' is refused, the error naming the 'levels' line. */
static void refusals(void)
{
    static const char *extra[4][3] = {{"tools/examples/limb/limb.sinew", "constraints 4\n", NULL},
                                      {"tools/examples/limb/limb.sinew", "adapt 0.03 0.01 10\n", "adaptation"},
                                      {"tools/examples/limb/limb.sinew", "colliders 2 8\n", NULL},
                                      {"tools/examples/limb/limb_crease.sinew", "", NULL}};
    const char *b = getenv("BUILD") ? getenv("BUILD") : "build";
    char d[600], path[700], cmd[1500], want[64];
    int i, c;
    snprintf(d, sizeof d, "%s/tests/cut_refuse", b);
    snprintf(cmd, sizeof cmd, "mkdir -p '%s' && cp tools/examples/limb/limb.obj '%s/limb.obj'", d, d);
    if (system(cmd) != 0) { T_CHECK(0, "cannot make %s", d); return; }
    for (i = 0; i < 4; i++) {
        FILE *in = fopen(extra[i][0], "r"), *f;
        sb_model o;
        sb_blob bl;
        int line = 1, rc;
        snprintf(path, sizeof path, "%s/limb%d.sinew", d, i);
        f = fopen(path, "w");
        if (!in || !f) { T_CHECK(0, "cannot write %s", path); if (in) fclose(in); if (f) fclose(f); return; }
        while ((c = fgetc(in)) != EOF) { fputc(c, f); line += c == '\n'; }
        fclose(in);
        fputs(extra[i][1], f);
        fputs("levels 2 cut\n", f);
        fclose(f);
        rc = sb_bake_file(path, SB_FIXED, 1, &o, &bl);
        if (extra[i][2]) {
            snprintf(want, sizeof want, ":%d: levels 2 cut: %s", line + 1, extra[i][2]);
            T_CHECK(rc != 0 && strstr(sb_error(), want) != NULL, "cut level with '%.*s': refused naming the levels line ('%s' in '%s')",
                    (int)strlen(extra[i][1]) - 1, extra[i][1], want, rc ? sb_error() : "baked");
        } else
            T_CHECK(rc == 0 && (i != 3 || o.crease), "cut level with %s: bakes (%s)", i == 3 ? "limb_crease's crease lines" : extra[i][1],
                    rc ? sb_error() : "ok");
        if (rc == 0) { sb_model_free(&o); sb_blob_free(&bl); }
    }
}

static uint32_t rd32_(const unsigned char *p) { return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24; }
static double rd64_(const unsigned char *p) { uint64_t u = (uint64_t)rd32_(p) | (uint64_t)rd32_(p + 4) << 32; double x; memcpy(&x, &u, 8); return x; }

/* The fixed blob's details against the double blob's (the bake's double elements, h^2/m0 and 1/m0 units): every
 * CELLDK entry within half its grid step 2^(e - (frac_S - dshift)), every mass within half of 2^-frac_M, CELLD and
 * DETAIL's indices equal, the rest points within half a Q22 step. Returns the largest error in grid steps. */
static double details_rounding(const sb_blob *fx, const sb_blob *db, int *bad)
{
    const unsigned char *f = fx->bytes, *d = db->bytes;
    uint32_t n = fx->sec_size[SN_SEC_CELLDK] / 24u, i, k;
    int dsh = f[fx->sec_off[SN_SEC_DETAILS] + 2], fs = fx->frac_S - dsh, fm = fx->frac_M;
    double worst = 0;
    *bad = n == 0 || db->sec_size[SN_SEC_CELLDK] != n * 80u || db->sec_size[SN_SEC_CELLD] != fx->sec_size[SN_SEC_CELLD] ||
           memcmp(f + fx->sec_off[SN_SEC_CELLD], d + db->sec_off[SN_SEC_CELLD], fx->sec_size[SN_SEC_CELLD]) != 0;
    if (*bad) return 0;
    for (i = 0; i < n; i++) {
        const unsigned char *a = f + fx->sec_off[SN_SEC_CELLDK] + 24u * i, *b = d + db->sec_off[SN_SEC_CELLDK] + 80u * i;
        double step = ldexp(1.0, a[18] - fs), m = (double)(int32_t)rd32_(a + 20);
        for (k = 0; k < 9; k++) {
            double q = (double)(int16_t)(a[2 * k] | a[2 * k + 1] << 8) * step;
            worst = fmax(worst, fabs(q - rd64_(b + 8 * k)) / step);
        }
        worst = fmax(worst, fabs(ldexp(m, -fm) - rd64_(b + 72)) / ldexp(1.0, -fm));
    }
    n = fx->sec_size[SN_SEC_DETAIL] / 16u;
    for (i = 0; i < n; i++) {
        const unsigned char *a = f + fx->sec_off[SN_SEC_DETAIL] + 16u * i, *b = d + db->sec_off[SN_SEC_DETAIL] + 28u * i;
        *bad += memcmp(a, b, 4) != 0;
        for (k = 0; k < 3; k++) worst = fmax(worst, fabs(ldexp((double)(int32_t)rd32_(a + 4 + 4 * k), -22) - rd64_(b + 4 + 8 * k)) / ldexp(1.0, -22));
    }
    return worst;
}

/* 'details' needs the cut level: refused after plain 'levels 2', naming the details line; with 'levels 2 cut' it
 * bakes (the limb), and its fixed blocks are the double blob's rounded */
static void details_line(void)
{
    const char *b = getenv("BUILD") ? getenv("BUILD") : "build";
    char path[700], want[96];
    int k;
    for (k = 0; k < 2; k++) {
        FILE *in = fopen("tools/examples/limb/limb.sinew", "r"), *f;
        sb_model o;
        sb_blob bl;
        int line = 1, c, rc;
        snprintf(path, sizeof path, "%s/tests/cut_refuse/limb_details%d.sinew", b, k);
        f = fopen(path, "w");
        if (!in || !f) { T_CHECK(0, "cannot write %s", path); if (in) fclose(in); if (f) fclose(f); return; }
        while ((c = fgetc(in)) != EOF) { fputc(c, f); line += c == '\n'; }
        fclose(in);
        fputs(k ? "levels 2 cut\n" : "levels 2\n", f);
        fputs("details 8 0.03 0.01\n", f);
        fclose(f);
        rc = sb_bake_file(path, SB_FIXED, 1, &o, &bl);
        if (k == 0) {
            snprintf(want, sizeof want, ":%d: details need 'levels 2 cut'", line + 1);
            T_CHECK(rc != 0 && strstr(sb_error(), want) != NULL, "details without the cut level: refused naming its line ('%s' in '%s')", want,
                    rc ? sb_error() : "baked");
        } else {
            sb_model o2;
            sb_blob b2;
            T_CHECK(rc == 0 && bl.sec_size[SN_SEC_DETAILS] > 0 && bl.sec_size[SN_SEC_CELLDK] > 0, "details on the limb's cut level: bakes (%s)",
                    rc ? sb_error() : "ok");
            if (rc == 0 && sb_bake_file(path, SB_DOUBLE, 1, &o2, &b2) == 0) {
                int bad = 0;
                double w = details_rounding(&bl, &b2, &bad);
                T_FIGURE("limb details: fixed blocks, masses and rest points vs the double blob's: %.3f of their grid step at worst "
                         "(dshift %u)", w, bl.bytes[bl.sec_off[SN_SEC_DETAILS] + 2]);
                /* round to nearest: half a step, + 1e-6 for the double blob's own last bits */
                T_CHECK(bad == 0 && w <= 0.5 + 1e-6, "limb details: fixed = the double blob's rounded (%.4f steps, %d index mismatches)", w, bad);
                sb_model_free(&o2); sb_blob_free(&b2);
            } else T_CHECK(0, "details: double bake (%s)", sb_error());
        }
        if (rc == 0) { sb_model_free(&o); sb_blob_free(&bl); }
    }
}

int main(int argc, char **argv)
{
    (void)t_seed;
    g_precond = argc > 1 && !strcmp(argv[1], "--precond");
    check("tools/examples/cow/cow.sinew");
    refusals();
    details_line();
    return T_END();
}
