/* test_bake_lbfgsb.c -- the host tool's L-BFGS-B (tools/sb_lbfgsb.c) on the
 * textbook problems: Rosenbrock in 2 and 100 dimensions, a bound-constrained
 * quadratic with a known active set, an ill-conditioned quadratic
 * (condition 1e6), bad input, determinism and the caller's work array. */
#include "sb_lbfgsb.h"
#include "sn_test.h"
#include <string.h>

/* extended Rosenbrock: sum_{i<n/2} 100 (x_2i+1 - x_2i^2)^2 + (1 - x_2i)^2 for the 100-dim
 * chained version below; rosen2 is the classic 2-d one */
static double rosen(void *ctx, const double *x, double *g)
{
    int n = *(const int *)ctx, i;
    double f = 0;
    for (i = 0; i < n; i++) g[i] = 0;
    for (i = 0; i + 1 < n; i++) {   /* chained: sum 100 (x_i+1 - x_i^2)^2 + (1 - x_i)^2 */
        double a = x[i + 1] - x[i] * x[i], b = 1 - x[i];
        f += 100 * a * a + b * b;
        g[i] += -400 * a * x[i] - 2 * b;
        g[i + 1] += 200 * a;
    }
    return f;
}

/* f = 1/2 sum d_i (x_i - c_i)^2 */
typedef struct { int n; const double *dg, *c; int evals; } quad_t;
static double quad(void *ctx, const double *x, double *g)
{
    quad_t *q = ctx;
    double f = 0;
    int i;
    q->evals++;
    for (i = 0; i < q->n; i++) { double e = x[i] - q->c[i]; f += 0.5 * q->dg[i] * e * e; g[i] = q->dg[i] * e; }
    return f;
}

/* a coupled bound-constrained quadratic: f = 1/2 x^T A x - b^T x, A tridiagonal (2, -1) */
static double tri(void *ctx, const double *x, double *g)
{
    int n = *(const int *)ctx, i;
    double f = 0;
    for (i = 0; i < n; i++) {
        double ax = 2 * x[i] - (i > 0 ? x[i - 1] : 0) - (i + 1 < n ? x[i + 1] : 0);
        g[i] = ax - 1.0;
        f += 0.5 * x[i] * ax - x[i];
    }
    return f;
}

static double nanfn(void *ctx, const double *x, double *g) { (void)ctx; g[0] = 0; return x[0] * NAN; }

int main(void)
{
    sb_opt_opts o;
    sb_opt_result r;
    int i;
    (void)t_seed;   /* deterministic problems: no random seed */
    sb_opt_defaults(&o);
    {   /* Rosenbrock 2-d from (-1.2, 1) */
        int n = 2;
        double x[2] = {-1.2, 1};
        o.pgtol = 1e-9;
        sb_lbfgsb(n, x, NULL, NULL, rosen, &n, &o, &r, NULL);
        printf("  rosenbrock 2-d: status %d, %d iterations, %d evaluations, f %.3g, x (%.12f, %.12f)\n", r.status, r.iterations, r.evaluations, r.f, x[0], x[1]);
        T_CHECK(r.status == 0 || r.status == 1, "status %d", r.status);
        T_NEAR(x[0], 1, 1e-6, "x* = (1, 1); tolerance 1e-6 from |pg| <= 1e-9 and the Hessian's smallest eigenvalue ~0.4");
        T_NEAR(x[1], 1, 1e-6, "x* = (1, 1)");
        T_CHECK(r.iterations < 100, "2-d Rosenbrock in %d iterations (want < 100)", r.iterations);
    }
    {   /* Rosenbrock 100-d (chained), from x_i = -1.2 at even i, 1 at odd i */
        int n = 100;
        double x[100], err = 0;
        for (i = 0; i < n; i++) x[i] = (i % 2) ? 1 : -1.2;
        o.pgtol = 1e-8;
        o.max_iter = 5000;
        sb_lbfgsb(n, x, NULL, NULL, rosen, &n, &o, &r, NULL);
        for (i = 0; i < n; i++) err = fmax(err, fabs(x[i] - 1));
        printf("  rosenbrock 100-d: status %d, %d iterations, %d evaluations, f %.3g, max |x_i - 1| %.3g\n", r.status, r.iterations, r.evaluations, r.f, err);
        T_CHECK(r.status == 0 || r.status == 1, "status %d", r.status);
        T_NEAR(err, 0, 1e-5, "x* = 1: max |x_i - 1| within 1e-5 (pgtol 1e-8; the chained valley's smallest Hessian eigenvalue is ~1e-3)");
        /* with bounds that leave x* inside: same answer */
        {
            double lo[100], hi[100], y[100], e2 = 0;
            for (i = 0; i < n; i++) { lo[i] = -2; hi[i] = 2; y[i] = (i % 2) ? 1 : -1.2; }
            sb_lbfgsb(n, y, lo, hi, rosen, &n, &o, &r, NULL);
            for (i = 0; i < n; i++) e2 = fmax(e2, fabs(y[i] - 1));
            printf("  rosenbrock 100-d in [-2, 2]^100: status %d, %d iterations, max |x_i - 1| %.3g\n", r.status, r.iterations, e2);
            T_NEAR(e2, 0, 1e-5, "inactive bounds: same x* = 1");
        }
        /* active upper bound x_0 <= 0.5: known answer for the 2-d problem: x = (0.5, 0.25) */
        {
            int n2 = 2;
            double y[2] = {-1.2, 1}, lo[2] = {-HUGE_VAL, -HUGE_VAL}, hi[2] = {0.5, HUGE_VAL};
            sb_lbfgsb(n2, y, lo, hi, rosen, &n2, &o, &r, NULL);
            printf("  rosenbrock 2-d with x0 <= 0.5: status %d, %d iterations, x (%.10f, %.10f)\n", r.status, r.iterations, y[0], y[1]);
            T_NEAR(y[0], 0.5, 0, "x0 at its bound exactly");
            T_NEAR(y[1], 0.25, 1e-7, "x1 = x0^2 given x0 = 0.5");
        }
    }
    {   /* bound-constrained separable quadratic: minimizer clip(c, lo, hi), active set known */
        enum { N = 50 };
        double dg[N], c[N], lo[N], hi[N], x[N], err = 0;
        int nact = 0, wrong = 0;
        quad_t q;
        for (i = 0; i < N; i++) {
            dg[i] = 1 + i % 7;
            c[i] = 3.0 * sin(1.3 * i + 0.2);
            lo[i] = -1; hi[i] = (i % 3 == 0) ? HUGE_VAL : 1.5;
            x[i] = 0;
        }
        q.n = N; q.dg = dg; q.c = c; q.evals = 0;
        o.pgtol = 1e-8;
        o.ftol = 0;   /* stop on the projected gradient (or when f stops falling at rounding) */
        sb_lbfgsb(N, x, lo, hi, quad, &q, &o, &r, NULL);
        for (i = 0; i < N; i++) {
            double want = c[i] < lo[i] ? lo[i] : c[i] > hi[i] ? hi[i] : c[i];
            int act = want != c[i];
            nact += act;
            if (act && x[i] != want) wrong++;   /* active variables exactly on the bound */
            err = fmax(err, fabs(x[i] - want));
        }
        printf("  separable box QP (50 vars, %d active bounds): status %d, %d iterations, max error %.3g\n", nact, r.status, r.iterations, err);
        T_CHECK(r.status == 0 || r.status == 1, "converged (status %d)", r.status);
        T_CHECK(nact > 10, "the problem has active bounds (%d)", nact);
        T_CHECK(wrong == 0, "%d active variables not exactly on their bound", wrong);
        T_NEAR(err, 0, 1e-8, "x* = clip(c, lo, hi): |g_i| = d_i |x_i - c_i| <= pgtol 1e-8 with d_i >= 1");
    }
    {   /* coupled QP: tridiagonal (2,-1), b = 1, x <= 4: unconstrained x_i = i(n+1-i)/2 (1-based) peaks at n^2/8 */
        int n = 20;
        double x[20], hi[20], lo[20], err = 0;
        for (i = 0; i < n; i++) { x[i] = 0; lo[i] = 0; hi[i] = 4; }
        o.pgtol = 1e-10;
        sb_lbfgsb(n, x, lo, hi, tri, &n, &o, &r, NULL);
        /* known answer: the bound is active on a middle run; outside it x solves the
         * discrete -x'' = 1 with x_0 = 0 and x_k+1 = 4: x_i = i(k+1-i)/2 + 4i/(k+1).
         * k = 3 gives x_3 = 4.5 > 4 (infeasible); k = 2 gives (7/3, 11/3) and the
         * bound's multiplier at x_3: -(8 - 11/3 - 4 - 1) = 2/3 >= 0. So x = (7/3, 11/3,
         * 4 x 16, 11/3, 7/3). Checked too: KKT (gradient <= 0 on the upper bound,
         * 0 on the free variables) */
        {
            double gr[20], gmax = 0;
            int act = 0, bad = 0;
            tri(&n, x, gr);
            for (i = 0; i < n; i++) {
                if (x[i] >= 4 - 1e-12) { act++; if (gr[i] > 1e-9) bad++; }
                else if (x[i] > 1e-12) gmax = fmax(gmax, fabs(gr[i]));
            }
            err = gmax;
            printf("  tridiagonal QP with x <= 4 (20 vars): status %d, %d iterations, %d at the upper bound, KKT: max |g_free| %.3g\n",
                   r.status, r.iterations, act, err);
            T_CHECK(act == 16, "the upper bound is active on the middle 16 variables, got %d", act);
            T_CHECK(bad == 0, "%d bound variables with a wrong-sign multiplier", bad);
            T_NEAR(err, 0, 1e-9, "free variables stationary");
            T_NEAR(x[0], 7.0 / 3, 1e-9, "free end: 7/3");
            T_NEAR(x[1], 11.0 / 3, 1e-9, "free end: 11/3");
            T_NEAR(x[18], 11.0 / 3, 1e-9, "free end: 11/3");
            T_NEAR(x[19], 7.0 / 3, 1e-9, "free end: 7/3");
        }
    }
    {   /* ill-conditioned quadratic: eigenvalues 1 .. 1e6 (log-spaced), 200 vars */
        enum { N = 200 };
        double dg[N], c[N], x[N], err = 0;
        quad_t q;
        for (i = 0; i < N; i++) { dg[i] = pow(10.0, 6.0 * i / (N - 1)); c[i] = cos(0.7 * i); x[i] = 0; }
        q.n = N; q.dg = dg; q.c = c; q.evals = 0;
        o.pgtol = 1e-6;   /* 1e-12 of the starting gradient (~1e6) */
        o.max_iter = 20000;
        sb_lbfgsb(N, x, NULL, NULL, quad, &q, &o, &r, NULL);
        for (i = 0; i < N; i++) err = fmax(err, fabs(x[i] - c[i]));
        printf("  ill-conditioned QP (condition 1e6, 200 vars): status %d, %d iterations, %d evaluations, max |x - x*| %.3g\n",
               r.status, r.iterations, r.evaluations, err);
        T_CHECK(r.status == 0, "converged on pgtol (status %d)", r.status);
        T_NEAR(err, 0, 1e-6, "|g_i| = d_i |x_i - c_i| <= 1e-6 with d_i >= 1");
        /* conjugate gradients' bound for a 1e12 reduction at condition 1e6:
         * sqrt(1e6)/2 ln(2e12) ~ 14,000 iterations; L-BFGS with 8 pairs should not be worse */
        T_CHECK(r.iterations <= 14500, "%d iterations (CG bound ~14,000)", r.iterations);
        /* determinism: same inputs -> same bits; caller's work array gives the same */
        {
            double y[N], *wk = malloc(sizeof(double) * sb_lbfgsb_work_len(N, o.m));
            sb_opt_result r2;
            for (i = 0; i < N; i++) y[i] = 0;
            sb_lbfgsb(N, y, NULL, NULL, quad, &q, &o, &r2, wk);
            T_CHECK(!memcmp(x, y, sizeof x) && r2.iterations == r.iterations, "same result with the caller's work array");
            free(wk);
        }
    }
    {   /* bad input */
        int n = 2;
        double x[2] = {0, 0}, lo[2] = {1, 0}, hi[2] = {0, 1}, xn[2] = {NAN, 0};
        T_CHECK(sb_lbfgsb(0, x, NULL, NULL, rosen, &n, &o, &r, NULL) == -1 && r.status == -1, "n = 0");
        T_CHECK(sb_lbfgsb(2, x, lo, hi, rosen, &n, &o, &r, NULL) == -1, "lo > hi");
        T_CHECK(sb_lbfgsb(2, xn, NULL, NULL, rosen, &n, &o, &r, NULL) == -1, "NaN start");
        T_CHECK(sb_lbfgsb(2, x, NULL, NULL, NULL, &n, &o, &r, NULL) == -1, "no function");
        T_CHECK(sb_lbfgsb(1, x, NULL, NULL, nanfn, NULL, &o, &r, NULL) == -1, "f NaN at the start");
        o.m = 0;
        T_CHECK(sb_lbfgsb(2, x, NULL, NULL, rosen, &n, &o, &r, NULL) == -1, "m = 0");
        T_CHECK(x[0] == 0 && x[1] == 0, "x untouched on bad input");
    }
    return T_END();
}
