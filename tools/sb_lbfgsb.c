/* sb_lbfgsb.c -- L-BFGS-B (Byrd, Lu, Nocedal, Zhu 1995) for the host tool;
 * the algorithm and its choices are described in sb_lbfgsb.h.
 *
 * Notation (BLNZ): pairs s_k = x_k+1 - x_k, y_k = g_k+1 - g_k, the newest
 * `col` of them kept oldest first as the columns of S and Y (n x col);
 * theta = y.y / s.y of the newest pair; W = [Y, theta S] (n x 2col);
 * K = M^-1 = [[-D, L^T], [L, theta S^T S]] with D = diag(s_i.y_i) and L the
 * strictly lower part of S^T Y; B = theta I - W M W^T. */
#include "sb_lbfgsb.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void sb_opt_defaults(sb_opt_opts *o)
{
    o->m = 8;
    o->max_iter = 2000;
    o->pgtol = 1e-6;
    o->ftol = 1e-13;
    o->verbose = 0;
    o->label = NULL;
}

size_t sb_lbfgsb_work_len(int n, int m)
{
    size_t N = n > 0 ? (size_t)n : 1, M = m > 0 ? (size_t)m : 1;
    return 2 * N * M + 14 * N + 16 * M * M + 40 * M + 64;
}

typedef struct {
    int n, m, col;
    double theta;
    double *S, *Y;              /* n x m each, column k at [k*n] */
    double *K, *Mi, *Nm, *lu;   /* 2m x 2m: K = M^-1, M, scratch, LU scratch */
    double *p, *c, *v, *wb, *tmp, *yy; /* 2m vectors */
    int *piv;                   /* 2m */
} lmem;

/* dense solve A x = b (k x k, row-major; A copied into lu), partial pivoting; -1 if singular */
static int dsolve(int k, const double *A, double *lu, int *piv, double *b)
{
    int i, j, r;
    memcpy(lu, A, sizeof(double) * (size_t)k * (size_t)k);
    for (i = 0; i < k; i++) {
        int best = i;
        double mx = fabs(lu[i * k + i]);
        for (r = i + 1; r < k; r++) if (fabs(lu[r * k + i]) > mx) { mx = fabs(lu[r * k + i]); best = r; }
        if (!(mx > 0)) return -1;
        piv[i] = best;
        if (best != i) {
            for (j = 0; j < k; j++) { double t = lu[i * k + j]; lu[i * k + j] = lu[best * k + j]; lu[best * k + j] = t; }
            { double t = b[i]; b[i] = b[best]; b[best] = t; }
        }
        for (r = i + 1; r < k; r++) {
            double f = lu[r * k + i] / lu[i * k + i];
            if (f == 0) continue;
            for (j = i; j < k; j++) lu[r * k + j] -= f * lu[i * k + j];
            b[r] -= f * b[i];
        }
    }
    for (i = k - 1; i >= 0; i--) {
        double s = b[i];
        for (j = i + 1; j < k; j++) s -= lu[i * k + j] * b[j];
        b[i] = s / lu[i * k + i];
    }
    return 0;
}

/* row i of W = [Y, theta S] */
static void wrow(const lmem *L, int i, double *w)
{
    int k;
    for (k = 0; k < L->col; k++) { w[k] = L->Y[(size_t)k * L->n + i]; w[L->col + k] = L->theta * L->S[(size_t)k * L->n + i]; }
}

/* y = M x (2col) */
static void mmul(const lmem *L, const double *x, double *y)
{
    int k = 2 * L->col, i, j;
    for (i = 0; i < k; i++) {
        double s = 0;
        for (j = 0; j < k; j++) s += L->Mi[i * k + j] * x[j];
        y[i] = s;
    }
}

/* K from S, Y, theta; M = K^-1 column by column. -1 if K is singular. */
static int build_middle(lmem *L)
{
    int c = L->col, k = 2 * c, i, j;
    size_t n = (size_t)L->n, t;
    for (i = 0; i < c; i++)
        for (j = 0; j < c; j++) {
            double sy = 0, ss = 0;
            const double *si = L->S + (size_t)i * n, *yj = L->Y + (size_t)j * n, *sj = L->S + (size_t)j * n;
            for (t = 0; t < n; t++) { sy += si[t] * yj[t]; ss += si[t] * sj[t]; }
            /* K = [[-D, L^T], [L, theta S^T S]], L_ij = s_i.y_j for i > j */
            L->K[i * k + j] = (i == j) ? -sy : 0;
            L->K[(c + i) * k + j] = (i > j) ? sy : 0;        /* L block (rows c+i, cols j) */
            L->K[j * k + (c + i)] = (i > j) ? sy : 0;        /* L^T block (rows j, cols c+i) */
            L->K[(c + i) * k + (c + j)] = L->theta * ss;
        }
    for (j = 0; j < k; j++) {
        for (i = 0; i < k; i++) L->tmp[i] = (i == j);
        if (dsolve(k, L->K, L->lu, L->piv, L->tmp)) return -1;
        for (i = 0; i < k; i++) L->Mi[i * k + j] = L->tmp[i];
    }
    return 0;
}

static int cmp_brk(const void *a, const void *b)
{
    const double *x = a, *y = b;
    if (x[0] < y[0]) return -1;
    if (x[0] > y[0]) return 1;
    return (x[1] > y[1]) - (x[1] < y[1]);
}

static double lo_of(const double *lo, int i) { return lo ? lo[i] : -HUGE_VAL; }
static double hi_of(const double *hi, int i) { return hi ? hi[i] : HUGE_VAL; }

/* |P(x - g) - x|_inf */
static double pgnorm(int n, const double *x, const double *g, const double *lo, const double *hi)
{
    double mx = 0;
    int i;
    for (i = 0; i < n; i++) {
        double z = x[i] - g[i], l = lo_of(lo, i), h = hi_of(hi, i);
        if (z < l) z = l;
        if (z > h) z = h;
        z = fabs(z - x[i]);
        if (z > mx) mx = z;
    }
    return mx;
}

/* generalized Cauchy point xcp from x along P(x - t g); c = W^T (xcp - x) */
static void cauchy(lmem *L, const double *x, const double *g, const double *lo, const double *hi,
                   double *xcp, double *d, double *brk)
{
    int n = L->n, k2 = 2 * L->col, i, j, nb = 0, b;
    double fp = 0, fpp, dtmin, told = 0;
    for (j = 0; j < k2; j++) { L->p[j] = 0; L->c[j] = 0; }
    for (i = 0; i < n; i++) {
        double t, l = lo_of(lo, i), h = hi_of(hi, i);
        xcp[i] = x[i];
        if (g[i] < 0) t = h < HUGE_VAL ? (x[i] - h) / g[i] : HUGE_VAL;
        else if (g[i] > 0) t = l > -HUGE_VAL ? (x[i] - l) / g[i] : HUGE_VAL;
        else t = HUGE_VAL;
        d[i] = t > 0 ? -g[i] : 0;
        if (d[i] != 0) {
            fp -= d[i] * d[i];
            if (k2) { wrow(L, i, L->wb); for (j = 0; j < k2; j++) L->p[j] += L->wb[j] * d[i]; }
            if (t < HUGE_VAL) { brk[2 * nb] = t; brk[2 * nb + 1] = i; nb++; }
        }
    }
    if (fp == 0) return;   /* projected gradient zero */
    mmul(L, L->p, L->v);
    fpp = -L->theta * fp;
    for (j = 0; j < k2; j++) fpp -= L->p[j] * L->v[j];
    if (!(fpp > 0)) fpp = 1e-300;
    dtmin = -fp / fpp;
    qsort(brk, (size_t)nb, 2 * sizeof(double), cmp_brk);
    for (b = 0; b < nb; b++) {
        double tb = brk[2 * b], dt = tb - told, gb, zb, wMc = 0, wMp = 0, wMw = 0;
        int ib = (int)brk[2 * b + 1];
        if (dtmin < dt) break;
        /* variable ib reaches its bound */
        gb = g[ib];
        xcp[ib] = gb > 0 ? lo_of(lo, ib) : hi_of(hi, ib);
        zb = xcp[ib] - x[ib];
        for (j = 0; j < k2; j++) L->c[j] += dt * L->p[j];
        if (k2) {
            wrow(L, ib, L->wb);
            mmul(L, L->c, L->v);
            for (j = 0; j < k2; j++) wMc += L->wb[j] * L->v[j];
            mmul(L, L->p, L->v);
            for (j = 0; j < k2; j++) wMp += L->wb[j] * L->v[j];
            mmul(L, L->wb, L->v);
            for (j = 0; j < k2; j++) wMw += L->wb[j] * L->v[j];
        }
        fp += dt * fpp + gb * gb + L->theta * gb * zb - gb * wMc;
        fpp -= L->theta * gb * gb + 2 * gb * wMp + gb * gb * wMw;
        for (j = 0; j < k2; j++) L->p[j] += gb * L->wb[j];
        d[ib] = 0;
        told = tb;
        if (!(fpp > 0)) fpp = 1e-300;
        dtmin = -fp / fpp;
        if (fp >= 0) { dtmin = 0; b++; break; }
    }
    if (dtmin < 0) dtmin = 0;
    told += dtmin;
    for (i = 0; i < n; i++) if (d[i] != 0) xcp[i] = x[i] + told * d[i];
    /* keep xcp in the box despite rounding */
    for (i = 0; i < n; i++) {
        double l = lo_of(lo, i), h = hi_of(hi, i);
        if (xcp[i] < l) xcp[i] = l;
        if (xcp[i] > h) xcp[i] = h;
    }
    for (j = 0; j < k2; j++) L->c[j] += dtmin * L->p[j];
}

/* subspace minimization over the variables free at xcp: xbar (in place of xcp's copy) */
static void subspace(lmem *L, const double *x, const double *g, const double *lo, const double *hi,
                     const double *xcp, double *xbar, double *r, int *fr)
{
    int n = L->n, k2 = 2 * L->col, i, j, a, nf = 0;
    double th = L->theta, alpha = 1;
    memcpy(xbar, xcp, sizeof(double) * (size_t)n);
    for (i = 0; i < n; i++) if (xcp[i] > lo_of(lo, i) && xcp[i] < hi_of(hi, i)) fr[nf++] = i;
    if (!nf) return;
    /* reduced gradient r = Z^T (g + theta (xcp - x) - W M c) */
    if (k2) mmul(L, L->c, L->v);
    for (a = 0; a < nf; a++) {
        double s;
        i = fr[a];
        s = g[i] + th * (xcp[i] - x[i]);
        if (k2) { wrow(L, i, L->wb); for (j = 0; j < k2; j++) s -= L->wb[j] * L->v[j]; }
        r[i] = s;
    }
    /* du = -(r / theta + A (K - A^T A / theta)^-1 A^T r / theta^2), A = Z^T W */
    if (k2) {
        for (j = 0; j < k2 * k2; j++) L->Nm[j] = L->K[j];
        for (j = 0; j < k2; j++) L->yy[j] = 0;
        for (a = 0; a < nf; a++) {
            int u, w;
            i = fr[a];
            wrow(L, i, L->wb);
            for (u = 0; u < k2; u++) {
                L->yy[u] += L->wb[u] * r[i];
                for (w = 0; w < k2; w++) L->Nm[u * k2 + w] -= L->wb[u] * L->wb[w] / th;
            }
        }
        if (dsolve(k2, L->Nm, L->lu, L->piv, L->yy)) for (j = 0; j < k2; j++) L->yy[j] = 0;
    }
    for (a = 0; a < nf; a++) {
        double du;
        i = fr[a];
        du = r[i] / th;
        if (k2) {
            double s = 0;
            wrow(L, i, L->wb);
            for (j = 0; j < k2; j++) s += L->wb[j] * L->yy[j];
            du += s / (th * th);
        }
        r[i] = -du;   /* the step on free variable i */
    }
    /* truncate: largest alpha <= 1 keeping xcp + alpha du in the box */
    for (a = 0; a < nf; a++) {
        double du = r[fr[a]], l = lo_of(lo, fr[a]), h = hi_of(hi, fr[a]), xc = xcp[fr[a]];
        if (du > 0 && h < HUGE_VAL && xc + alpha * du > h) alpha = (h - xc) / du;
        if (du < 0 && l > -HUGE_VAL && xc + alpha * du < l) alpha = (l - xc) / du;
    }
    if (alpha < 0) alpha = 0;
    for (a = 0; a < nf; a++) {
        double l, h;
        i = fr[a];
        l = lo_of(lo, i); h = hi_of(hi, i);
        xbar[i] = xcp[i] + alpha * r[i];
        if (xbar[i] < l) xbar[i] = l;
        if (xbar[i] > h) xbar[i] = h;
    }
}

int sb_lbfgsb(int n, double *x, const double *lo, const double *hi,
              sb_opt_fn fn, void *ctx, const sb_opt_opts *o, sb_opt_result *res, double *work)
{
    sb_opt_opts def;
    sb_opt_result rr;
    lmem L;
    double *own = NULL, *w, *g, *xcp, *xbar, *d, *xn, *gn, *r, *brk, *x0, f, pg;
    int *fr, i, m, iter = 0, nev = 0, status = SB_OPT_MAXITER, fresh_retry = 0;
    const char *lab;
    size_t N;
    if (!res) res = &rr;
    memset(res, 0, sizeof *res);
    res->status = SB_OPT_BADINPUT;
    if (!o) { sb_opt_defaults(&def); o = &def; }
    lab = o->label ? o->label : "lbfgsb";
    if (n < 1 || !x || !fn || o->m < 1 || o->max_iter < 0 || !(o->pgtol >= 0) || !(o->ftol >= 0)) return SB_OPT_BADINPUT;
    for (i = 0; i < n; i++) {
        double l = lo_of(lo, i), h = hi_of(hi, i);
        if (l != l || h != h || l > h || l == HUGE_VAL || h == -HUGE_VAL || !isfinite(x[i])) return SB_OPT_BADINPUT;
    }
    m = o->m;
    N = (size_t)n;
    if (!work) {
        own = malloc(sizeof(double) * sb_lbfgsb_work_len(n, m));
        if (!own) return SB_OPT_BADINPUT;
        work = own;
    }
    w = work;
    L.n = n; L.m = m; L.col = 0; L.theta = 1;
    L.S = w; w += N * (size_t)m;
    L.Y = w; w += N * (size_t)m;
    g = w; w += N; xcp = w; w += N; xbar = w; w += N; d = w; w += N; xn = w; w += N; gn = w; w += N; r = w; w += N; x0 = w; w += N;
    brk = w; w += 2 * N;
    fr = (int *)w; w += N;   /* n ints in n doubles */
    L.K = w; w += 4 * (size_t)m * m; L.Mi = w; w += 4 * (size_t)m * m; L.Nm = w; w += 4 * (size_t)m * m; L.lu = w; w += 4 * (size_t)m * m;
    L.p = w; w += 2 * m; L.c = w; w += 2 * m; L.v = w; w += 2 * m; L.wb = w; w += 2 * m; L.tmp = w; w += 2 * m; L.yy = w; w += 2 * m;
    L.piv = (int *)w;
    memcpy(x0, x, sizeof(double) * N);
    for (i = 0; i < n; i++) {
        if (x[i] < lo_of(lo, i)) x[i] = lo_of(lo, i);
        if (x[i] > hi_of(hi, i)) x[i] = hi_of(hi, i);
    }
    f = fn(ctx, x, g);
    nev++;
    for (i = 0; i < n && isfinite(g[i]); i++) {}
    if (!isfinite(f) || i < n) { memcpy(x, x0, sizeof(double) * N); free(own); res->evaluations = nev; return SB_OPT_BADINPUT; }
    pg = pgnorm(n, x, g, lo, hi);
    if (o->verbose) fprintf(stderr, "%s: iter %5d  f %.12g  |pg|inf %.3e\n", lab, 0, f, pg);
    if (pg <= o->pgtol) status = SB_OPT_PGTOL;
    while (status == SB_OPT_MAXITER && iter < o->max_iter) {
        double gd = 0, t = 1, fn_ = 0, dnorm = 0, sy = 0, yy = 0;
        int ls, ok = 0;
        if (L.col > 0 && build_middle(&L)) { L.col = 0; L.theta = 1; }
        cauchy(&L, x, g, lo, hi, xcp, d, brk);
        subspace(&L, x, g, lo, hi, xcp, xbar, r, fr);
        for (i = 0; i < n; i++) { d[i] = xbar[i] - x[i]; gd += g[i] * d[i]; if (fabs(d[i]) > dnorm) dnorm = fabs(d[i]); }
        if (!(gd < 0) || dnorm == 0) {
            if (L.col > 0 && !fresh_retry) { L.col = 0; L.theta = 1; fresh_retry = 1; continue; }
            status = dnorm == 0 ? SB_OPT_PGTOL : SB_OPT_LSFAIL;
            break;
        }
        /* first step without curvature information: at most unit length */
        if (L.col == 0 && iter == 0 && dnorm > 1) t = 1 / dnorm;
        for (ls = 0; ls < 40; ls++) {
            for (i = 0; i < n; i++) {
                xn[i] = x[i] + t * d[i];
                if (xn[i] < lo_of(lo, i)) xn[i] = lo_of(lo, i);
                if (xn[i] > hi_of(hi, i)) xn[i] = hi_of(hi, i);
            }
            fn_ = fn(ctx, xn, gn);
            nev++;
            if (isfinite(fn_) && fn_ <= f + 1e-4 * t * gd) {
                for (i = 0; i < n && isfinite(gn[i]); i++) {}
                if (i == n) { ok = 1; break; }
            }
            {   /* quadratic interpolation, safeguarded */
                double tn = 0.5 * t;
                if (isfinite(fn_)) {
                    double den = 2 * (fn_ - f - gd * t);
                    if (den > 0) tn = -gd * t * t / den;
                }
                if (tn < 0.1 * t) tn = 0.1 * t;
                if (tn > 0.5 * t) tn = 0.5 * t;
                t = tn;
            }
            if (t * dnorm < 1e-300) break;
        }
        if (!ok) {
            if (L.col > 0 && !fresh_retry) { L.col = 0; L.theta = 1; fresh_retry = 1; continue; }
            status = SB_OPT_LSFAIL;
            break;
        }
        fresh_retry = 0;
        iter++;
        /* correction pair */
        for (i = 0; i < n; i++) {
            double s = xn[i] - x[i], y = gn[i] - g[i];
            sy += s * y; yy += y * y;
        }
        if (sy > 2.220446049250313e-16 * yy && yy > 0) {
            if (L.col == m) {
                memmove(L.S, L.S + N, sizeof(double) * N * (size_t)(m - 1));
                memmove(L.Y, L.Y + N, sizeof(double) * N * (size_t)(m - 1));
                L.col--;
            }
            for (i = 0; i < n; i++) { L.S[(size_t)L.col * N + i] = xn[i] - x[i]; L.Y[(size_t)L.col * N + i] = gn[i] - g[i]; }
            L.col++;
            L.theta = yy / sy;
        }
        {
            double fold = f;
            memcpy(x, xn, sizeof(double) * N);
            memcpy(g, gn, sizeof(double) * N);
            f = fn_;
            pg = pgnorm(n, x, g, lo, hi);
            if (pg <= o->pgtol) status = SB_OPT_PGTOL;
            else if ((fold - f) <= o->ftol * fmax(fmax(fabs(fold), fabs(f)), 1.0)) status = SB_OPT_FTOL;
            if (o->verbose > 0 && iter % o->verbose == 0) fprintf(stderr, "%s: iter %5d  f %.12g  |pg|inf %.3e\n", lab, iter, f, pg);
        }
    }
    res->iterations = iter;
    res->evaluations = nev;
    res->f = f;
    res->pgnorm = pg;
    res->status = status;
    if (o->verbose)
        fprintf(stderr, "%s: %s after %d iterations (%d evaluations): f %.12g, |pg|inf %.3e\n", lab,
                status == 0 ? "converged (pgtol)" : status == 1 ? "converged (ftol)" : status == 2 ? "stopped at max_iter" : "line search failed",
                iter, nev, f, pg);
    free(own);
    return status;
}
