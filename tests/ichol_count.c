/* ichol_count.c -- the iteration count of an ICHOL blob by the whole-clip
 * criterion of runtime/SOLVER_STUDY.md §1 (issue 15 item 3): the double
 * reference steps the clips with exact solves, with block Jacobi at the
 * count N it is compared with (the Jacobi blob), and with the ICHOL blob's
 * IC(0) (its int16 factor as stored) at 1..16 iterations, all in lockstep;
 * error = max over the clips of the max surface distance from the exact run,
 * relative to the max elastic displacement. The count is the smallest k whose
 * error is at most block Jacobi's at N, plus one iteration of margin.
 * Not a test: a measurement (make ichol-counts), its numbers go into the
 * examples' descriptions (tools/DESCRIPTION.md "Preconditioner").
 *
 * Usage: ichol_count JACOBI_BLOB ICHOL_BLOB N CLIP [CLIP...]
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sinew.h"
#include "sn_clip.h"
#include "snref.h"
#include "reference/phys_util.h"
#include "reference/ref_clips.h"

#define KMAX 16

/* the warm start extrapolated from the last two solutions,
 * x0 = dv_k + theta (dv_k - dv_{k-1}) (ICHOL_EXTRAP=theta; a study) */
typedef struct { double theta, *prev; unsigned n; } extrap;
static void extrap_hook(void *ctx, const snref_state *s, const double *b, const double *x0) {
    extrap *e = (extrap *)ctx;
    double *x = (double *)(size_t)x0; /* the state's own dv: writable */
    unsigned i;
    (void)s; (void)b;
    for (i = 0; i < e->n; i++) {
        double t = x[i];
        x[i] = t + e->theta * (t - e->prev[i]);
        e->prev[i] = t;
    }
}

int main(int argc, char **argv) {
    pu_rt rt;
    snref_model mj, mi;
    snref_state sj0, ex, bj, ic[KMAX], icx[KMAX], *st[2 * KMAX + 2];
    extrap xe[KMAX];
    double er[2 * KMAX + 3];
    const char *th = getenv("ICHOL_EXTRAP");
    unsigned n, j, ns = 0, nx = th ? KMAX : 0;
    if (argc < 5) { fprintf(stderr, "usage: ichol_count JACOBI_BLOB ICHOL_BLOB N CLIP...\n"); return 2; }
    n = (unsigned)atoi(argv[3]);
    if (pu_rt_open(&rt, argv[1]) || pu_ref_open(&mj, &sj0, argv[1]) || pu_ref_open(&mi, &ic[0], argv[2])) return 1;
    if (mj.nIC || !mi.nIC) { fprintf(stderr, "%s must be a block-Jacobi blob and %s an ICHOL blob\n", argv[1], argv[2]); return 1; }
    snref_init(&ex, &mj); ex.exact = 1; st[ns++] = &ex;
    snref_init(&bj, &mj); bj.iters = n; st[ns++] = &bj;
    for (j = 0; j < KMAX; j++) { if (j) snref_init(&ic[j], &mi); ic[j].iters = j + 1; st[ns++] = &ic[j]; }
    for (j = 0; j < nx; j++) {
        snref_init(&icx[j], &mi); icx[j].iters = j + 1;
        xe[j].theta = atof(th); xe[j].n = 3 * mi.nF; xe[j].prev = calloc(3 * mi.nF, sizeof(double));
        icx[j].solve_hook = extrap_hook; icx[j].hook_ctx = &xe[j];
        st[ns++] = &icx[j];
    }
    if (pu_drive_clips(&rt, &mj, (const char **)argv + 4, (unsigned)argc - 4, st, ns, er)) return 1;
    printf("%s: whole clips, max surface error against exact solves / max elastic displacement (%.4g mesh units)\n", argv[2], er[ns]);
    printf("  block Jacobi %u it.: %.3e\n  IC(0):", n, er[1] / er[ns]);
    for (j = 0; j < KMAX; j++) printf(" %u it. %.3e%s", j + 1, er[2 + j] / er[ns], j + 1 < KMAX ? "," : "\n");
    for (j = 0; j < KMAX && er[2 + j] > er[1]; j++) {}
    if (nx) {
        unsigned q;
        printf("  IC(0), warm start extrapolated (theta %s):", th);
        for (q = 0; q < KMAX; q++) printf(" %u it. %.3e%s", q + 1, er[2 + KMAX + q] / er[ns], q + 1 < KMAX ? "," : "\n");
    }
    if (j < KMAX) printf("  => IC(0) reaches block Jacobi's %u-iteration accuracy at %u iterations; with one of margin: iterations %u\n", n, j + 1, j + 2);
    else printf("  => IC(0) does not reach block Jacobi's accuracy within %u iterations\n", KMAX);
    pu_rt_close(&rt);
    return 0;
}
