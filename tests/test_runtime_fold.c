/* test_runtime_fold.c -- the float initial-residual fold (sn_solve.c rhs_x0,
 * SN_FOLD; NUMERICS.md "The initial residual folded in") in torn states,
 * float flavour only:
 *   operands: a state whose v + x0 leaves the guard SN_FLIM (|v|, |x0| <=
 *     SN_FLIM each; a one-step jump's v with the solve's dv of its size),
 *     otherwise quiet: the folded residual against b - A x0 formed the
 *     unfolded way (sn_rhs, the mat-vec, their difference in double) within
 *     the float rounding bound below; the clamping fold of the attempt
 *     before (v + x0 clamped at SN_FLIM) misses it by ~M |v + x0 - SN_FLIM|;
 *   cold start: a 180 degree snap of the whole cow plus a jump in one step
 *     (the soak's torn state); when its folded rhs clamps, the next step's
 *     warm start is 0, so its folded residual is b (the unfolded b - A 0)
 *     within the same bound, and the cow settles with no saturation.
 * Tolerance: each entry of b - A x0 is a float sum over at most 8 cells x
 * (24 products + rotation) and a mass row of <= 53 blocks, both ways; the
 * two orders differ by at most ~2 x 128 roundings of the largest partial sum,
 * bounded by |b|_inf + |A x0|_inf + |b - A x0|_inf (the norm-wise scale; the
 * products' own cancellation is the same both ways). 2^-15 of that scale
 * (256 x 2^-23 rounded up) is the bound; the measured ratio is printed. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "sn_test.h"
#include "sinew.h"
#include "sn_instance.h"
#include "sn_kernels.h" /* sn_kernels_name */
#include "sn_blended.h" /* sn_rhs */

typedef struct { void *bytes, *mem; const sn_blob *blob; sn_instance *inst; sn_ihdr *h; uint32_t nJ; } rt;

static int rt_open(rt *r, const char *name) {
    char p[512];
    const char *b = getenv("BUILD");
    FILE *f;
    long n;
    sn_blob_info info;
    memset(r, 0, sizeof *r);
    snprintf(p, sizeof p, "%s/examples/%s.blob", b && *b ? b : "build", name);
    if (!(f = fopen(p, "rb"))) { printf("  cannot read %s\n", p); return -1; }
    fseek(f, 0, SEEK_END); n = ftell(f); fseek(f, 0, SEEK_SET);
    r->bytes = malloc((size_t)n + 8);
    if (!r->bytes || fread(r->bytes, 1, (size_t)n, f) != (size_t)n) { fclose(f); return -1; }
    fclose(f);
    if (sn_blob_validate(r->bytes, (size_t)n, &r->blob) != SN_OK) return -1;
    sn_blob_get_info(r->blob, &info);
    r->nJ = info.joints;
    r->mem = malloc(sn_instance_size(r->blob));
    if (sn_instance_init(r->mem, sn_instance_size(r->blob), r->blob, &r->inst) != SN_OK) return -1;
    r->h = (sn_ihdr *)(void *)r->inst;
    return 0;
}

/* root pose: turned by deg about z, moved by t (mesh units) */
static void pose(rt *r, double deg, const double t[3]) {
    sn_xform x[64];
    uint32_t j;
    for (j = 0; j < r->nJ && j < 64; j++) {
        x[j].rot.x = x[j].rot.y = x[j].rot.z = 0; x[j].rot.w = 1;
        x[j].pos.x = x[j].pos.y = x[j].pos.z = 0;
    }
    x[0].rot.z = (float)sin(deg * 3.14159265358979 / 360); x[0].rot.w = (float)cos(deg * 3.14159265358979 / 360);
    x[0].pos.x = (float)t[0]; x[0].pos.y = (float)t[1]; x[0].pos.z = (float)t[2];
    sn_set_pose(r->inst, x, r->nJ);
}

/* the step's stages before the solve (sn_step.c) */
static void stages(rt *r) {
    uint32_t s = 0;
    sn_frames(r->h, &s);
    sn_skeleton(r->h, &s);
    sn_crease_step(r->h, &s);
}

/* folded residual rf (x0) against b - A x0 the unfolded way; returns the
 * error over the scale, the clamps of each way in *sf, *su */
static double compare(rt *r, const sn_q *x0, uint32_t *sf, uint32_t *su, double *scale) {
    const uint32_t n = 3 * r->h->v.nF;
    sn_q *rf = malloc(n * sizeof *rf), *b = malloc(n * sizeof *b), *q = malloc(n * sizeof *q), *xs = malloc(n * sizeof *xs);
    double err = 0, sb = 0, sq = 0, sr = 0;
    uint32_t i;
    memcpy(xs, x0, n * sizeof *xs); /* x0 may be the instance's x: the passes leave it */
    *sf = *su = 0;
    sn_fold_rhs(r->h, rf, xs, sf);
    sn_rhs(r->h, b, 1, su);
    sn_fold_matvec(r->h, xs, q, su);
    for (i = 0; i < n; i++) {
        const double ru = sn_add(b[i], -q[i], su); /* the unfolded r = sn_add(b, -A x0), as sn_solve */
        if (fabs(rf[i] - ru) > err) err = fabs(rf[i] - ru);
        if (fabs(b[i]) > sb) sb = fabs(b[i]);
        if (fabs(q[i]) > sq) sq = fabs(q[i]);
        if (fabs(ru) > sr) sr = fabs(ru);
    }
    *scale = sb + sq + sr;
    free(rf); free(b); free(q); free(xs);
    return err / *scale;
}

#define TOL (1.0 / 32768.0) /* 2^-15 of the scale (header) */

static void operands(void) {
    rt r;
    const double z[3] = {0, 0, 0};
    uint32_t i, k, sf, sfa, su, n3;
    double e, sc, vmax = 0;
    sn_q *vel, *x, *xc;
    if (rt_open(&r, "cow_float")) { T_CHECK(0, "cow_float.blob"); return; }
    pose(&r, 0, z);
    for (k = 0; k < 20; k++) sn_step(r.inst);
    stages(&r);
    n3 = 3 * r.h->v.nF;
    vel = ARR(r.h, o_vel, sn_q);
    x = ARR(r.h, o_x, sn_q);
    /* a one-step jump along x: every free vertex's v and x0 (the solve's dv of
     * v's size, the same sign) by 0.55 SN_FLIM (v + x0: 1.1 SN_FLIM), the
     * skeleton's v' as well: a uniform field, no corner difference, so the
     * cell rows and the unfolded passes stay below the guard (checked) */
    for (i = 0; i < 3 * r.h->v.nV; i++) vel[i] = i % 3 == 0 ? 0.55f * SN_FLIM : 0.0f;
    for (i = 0; i < n3; i++) x[i] = i % 3 == 0 ? 0.55f * SN_FLIM : 0.0f;
    for (i = 0; i < n3; i++) if (fabs((double)vel[i] + x[i]) > vmax) vmax = fabs((double)vel[i] + x[i]);
    e = compare(&r, x, &sfa, &su, &sc);
    T_FIGURE("uniform jump, |v + x0| up to %.0f (guard %.0f): folded vs unfolded b - A x0: %.3g of the scale %.4g; "
             "clamps folded %u, unfolded %u", vmax, (double)SN_FLIM, e, sc, sfa, su);
    T_CHECK(vmax > 1.05 * SN_FLIM, "the state's v + x0 leaves the guard (%g)", vmax);
    T_CHECK(su == 0, "the unfolded passes clamp nothing in this state (%u)", su);
    /* the same with x0 of the opposite sign (v + x0 = 0: the usual cancelling warm start) */
    xc = malloc(n3 * sizeof *xc);
    for (i = 0; i < n3; i++) xc[i] = -vel[i];
    e = compare(&r, xc, &sf, &su, &sc);
    T_FIGURE("uniform jump, x0 = -v: %.3g of the scale %.4g; clamps folded %u, unfolded %u", e, sc, sf, su);
    T_CHECK(e <= TOL && su == 0 && sf == 0, "x0 = -v: %.3g (clamps %u, %u)", e, sf, su);
    free(xc);
    /* the folded rhs clamps here (the corner differences (1+b1)(v + x0) -
     * b1 v' beyond the guard at the skeleton's cells): this step's residual
     * is not b - A x0, so the solve drops the warm start for the next one */
    T_CHECK(sfa > 0, "the folded rhs clamps in this state (the cold start's case): %u", sfa);
    {
        uint32_t s = 0, nz = 0;
        sn_solve(r.h, &s);
        for (i = 0; i < n3; i++) nz += x[i] != 0;
        T_CHECK(nz == 0, "after the clamped folded rhs the next warm start is 0 (%u of %u entries not)", nz, n3);
        stages(&r);
        e = compare(&r, x, &sf, &su, &sc);
        T_FIGURE("the step after (cold, x0 = 0): folded vs unfolded b - A x0: %.3g of the scale %.4g (bound %.3g); clamps folded %u, unfolded %u",
                 e, sc, TOL, sf, su);
        T_CHECK(e <= TOL, "cold start: folded residual = b - A x0 within %.3g of the scale: %.3g", TOL, e);
    }
    free(r.mem); free(r.bytes);
}

/* the soak's torn state once: the whole cow snapped by 180 degrees and moved
 * in one step, then held: it settles with no saturation in the last 300 of
 * 600 steps (test_physics_soak's recovery check, one event) */
static void snap(void) {
    rt r;
    const double z[3] = {0, 0, 0}, jump[3] = {3000, -2000, 1500};
    uint32_t k, s0, s1, s2;
    sn_stats st;
    if (rt_open(&r, "cow_float")) { T_CHECK(0, "cow_float.blob"); return; }
    pose(&r, 0, z);
    for (k = 0; k < 20; k++) sn_step(r.inst);
    sn_get_stats(r.inst, &st);
    s0 = st.saturations;
    pose(&r, 180, jump);
    for (k = 0; k < 300; k++) sn_step(r.inst);
    sn_get_stats(r.inst, &st);
    s1 = st.saturations;
    for (k = 0; k < 300; k++) sn_step(r.inst);
    sn_get_stats(r.inst, &st);
    s2 = st.saturations;
    T_FIGURE("180 degree snap + jump, held: %u saturations in the first 300 steps, %u in the next 300", s1 - s0, s2 - s1);
    T_CHECK(s1 > s0, "the snap tears the state (%u saturations)", s1 - s0);
    T_CHECK(s2 == s1, "the cow settles: %u saturations in steps 300..600 after the snap", s2 - s1);
    free(r.mem); free(r.bytes);
}

int main(void) {
    printf("float initial-residual fold in torn states (%s; seed %lu unused: fixed states)\n", sn_kernels_name(), (unsigned long)T_SEED());
    operands();
    snap();
    return T_END();
}
