/* sb_lbfgsb.h -- L-BFGS-B: limited-memory quasi-Newton minimization with
 * bounds on the variables (Byrd, Lu, Nocedal, Zhu 1995, "A limited memory
 * algorithm for bound constrained optimization"), written for Sinew's host
 * tool (seed 003 §4.2-4.4: rig fitting, pose fitting, retargeting).
 *
 * Each iteration: (1) the generalized Cauchy point along the projected
 * gradient path x(t) = P(x - t g), minimizing the compact L-BFGS model
 * B = theta I - W M W^T piecewise over the breakpoints (BLNZ §4);
 * (2) subspace minimization of the model over the variables still free at the
 * Cauchy point (direct primal method, BLNZ §5.1, the reduced inverse by the
 * Sherman-Morrison-Woodbury formula), the step truncated to stay inside the
 * box; (3) a backtracking Armijo line search (sufficient decrease
 * f(x + t d) <= f(x) + 1e-4 t g.d, t from 1, safeguarded quadratic
 * interpolation into [0.1 t, 0.5 t]) along d = xbar - x, which stays feasible
 * for t in (0, 1] since the box is convex. A correction pair (s, y) is kept
 * only if s.y > eps |y|^2 (keeps B positive definite without a Wolfe
 * curvature condition). If the model direction is not a descent direction or
 * the line search fails, the memory is dropped and the iteration retried from
 * the projected steepest-descent path; a second failure ends the run with
 * status 3.
 *
 * C99 + libc + libm, no globals, deterministic (ties among breakpoints broken
 * by variable index). */
#ifndef SB_LBFGSB_H
#define SB_LBFGSB_H

#include <stddef.h>

typedef double (*sb_opt_fn)(void *ctx, const double *x, double *grad); /* returns f(x), writes the gradient */
typedef struct sb_opt_opts {
    int m;              /* correction pairs kept (default 8) */
    int max_iter;       /* iterations (default 2000) */
    double pgtol;       /* stop when |P(x - g) - x|_inf <= pgtol (default 1e-6) */
    double ftol;        /* stop when (f_k - f_k+1) / max(|f_k|, |f_k+1|, 1) <= ftol (default 1e-13) */
    int verbose;        /* progress lines to stderr: iteration, f, |proj grad|_inf; N > 0: at the start,
                         * every N-th iteration and a closing line (0: silent) */
    const char *label;  /* prefix of the progress lines (NULL: "lbfgsb") */
} sb_opt_opts;
typedef struct sb_opt_result {
    int iterations;
    int evaluations;
    double f;
    double pgnorm;
    int status;         /* 0 converged pgtol, 1 converged ftol, 2 max_iter, 3 line search failed, -1 bad input */
} sb_opt_result;
enum { SB_OPT_PGTOL = 0, SB_OPT_FTOL = 1, SB_OPT_MAXITER = 2, SB_OPT_LSFAIL = 3, SB_OPT_BADINPUT = -1 };

void sb_opt_defaults(sb_opt_opts *o);

/* Minimize fn over lo <= x <= hi from x (projected into the box first); x is
 * overwritten with the best point found. lo/hi may be NULL (unbounded);
 * entries may be -HUGE_VAL / +HUGE_VAL. Returns res->status (res may be NULL).
 * Bad input (-1, x untouched): n < 1, fn or x NULL, o->m < 1, lo > hi or a NaN
 * bound, a non-finite start, or f / gradient non-finite at the start.
 * work: NULL (allocated internally) or at least sb_lbfgsb_work_len(n, o->m)
 * doubles. */
int sb_lbfgsb(int n, double *x, const double *lo, const double *hi,
              sb_opt_fn fn, void *ctx, const sb_opt_opts *o, sb_opt_result *res, double *work);
size_t sb_lbfgsb_work_len(int n, int m);

#endif
