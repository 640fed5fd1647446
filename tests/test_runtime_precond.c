/* test_runtime_precond.c -- the runtime's IC(0) preconditioner (sn_precond.c,
 * NUMERICS.md "Preconditioner") against a double-precision solve with the
 * same factor: z = R (I + L^)^-T D^-1 (I + L^)^-1 R^T r with the blob's
 * ICHOL blocks and PRECOND pivots as decoded by the double reference, the
 * instance's own frames R (after 30 steps of the cow animation: rotated
 * frames) and k_i, on random force-like r.
 *
 * Tolerance (fixed), derived from the formats, per component: the exact
 * error of the fixed sweeps propagated alongside in double -- each rounding
 * into a vertex's force format Q(19 + k_i) contributes 2^-(20 + k_i), each
 * rounding into Q22 2^-23, and an incoming error e is carried as |U| e,
 * |D^-1| e and |R| e (rotations are the instance's exact Q30 values). No
 * clamp may happen (saturation counter 0), so the bound is rigorous.
 * Float: the same sweeps with |U|, |D^-1|, |R| on |r| (the magnitudes of
 * every partial sum) times gamma_n = n u / (1 - n u), u = 2^-24, n = 400
 * sequential operations along the longest chain (two sweeps over <= 26
 * blocks of 3-term rows plus three 3-term products): Higham's bound for
 * sequences of dot products. Both: the error must also reach a fraction of
 * the bound on some component (REACH: a test that cannot fail is no test).
 * Assets: cow and beast (their example blobs, ICHOL by default).
 * Also: the fused sweeps (sn_precond) give the bits and clamp count of the
 * five passes (sn_precond_mask over every vertex) on these residuals and on
 * four that clamp. */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"
#include "sn_instance.h"
#include "sn_kernels.h" /* sn_kernels_name */

/* fixed: the propagated bound is tight (measured 0.4-0.8 of it); float:
 * gamma_n is a worst case over n operations (measured ~0.01 of it) */
#if defined(SN_FLOAT)
#define REACH 1e-3
#else
#define REACH 0.25
#endif
static double rng_state = 0.5;
static double urand(void) { /* deterministic, from the harness seed */
    rng_state = fmod(rng_state * 9301.0 + 49297.0 + 0.123, 233280.0);
    return rng_state / 233280.0;
}

static void mt(const double *R, const double *v, double *o) { int c; for (c = 0; c < 3; c++) o[c] = R[c] * v[0] + R[3 + c] * v[1] + R[6 + c] * v[2]; }
static void mv(const double *R, const double *v, double *o) { int c; for (c = 0; c < 3; c++) o[c] = R[3 * c] * v[0] + R[3 * c + 1] * v[1] + R[3 * c + 2] * v[2]; }
static void abs9(const double *A, double *B) { int k; for (k = 0; k < 9; k++) B[k] = fabs(A[k]); }

/* The sweeps in double. mode 0: the exact solve of x; mode 1: the fixed
 * error bound (rf: force rounding of vertex i, r22: Q22 rounding);
 * mode 2: magnitudes (|.| everywhere). */
static void sweeps(const snref_model *m, const double *Rv, const double *kq, const double *x, double *z, int mode) {
    unsigned i, j, e, n = 0, c, nF = m->nF;
    const double r22 = mode == 1 ? ldexp(1.0, -23) : 0;
    double A[9], t[3], u[3];
    for (i = 0; i < nF; i++) {
        if (mode == 0) mt(Rv + 9 * i, x + 3 * i, z + 3 * i);
        else { abs9(Rv + 9 * i, A); mt(A, x + 3 * i, z + 3 * i); }
        if (mode == 1) for (c = 0; c < 3; c++) z[3 * i + c] = ldexp(1.0, -20 - (int)kq[i]); /* R^T r rounded; r exact */
    }
    for (j = 0; j < nF; j++)
        for (e = m->rowptr[j]; e < m->rowptr[j + 1] && m->cols[e] < nF; e++, n++) {
            const double *U = m->ichol + 9 * (size_t)n;
            i = m->cols[e];
            if (mode == 0) { mt(U, z + 3 * j, t); for (c = 0; c < 3; c++) z[3 * i + c] -= t[c]; }
            else {
                abs9(U, A); mt(A, z + 3 * j, t);
                for (c = 0; c < 3; c++) z[3 * i + c] += t[c] + (mode == 1 ? ldexp(1.0, -20 - (int)kq[i]) : 0);
            }
        }
    for (i = 0; i < nF; i++) {
        if (mode == 0) mv(m->precond + 9 * i, z + 3 * i, t); else { abs9(m->precond + 9 * i, A); mv(A, z + 3 * i, t); }
        for (c = 0; c < 3; c++) z[3 * i + c] = t[c] + r22;
    }
    for (j = nF; j-- > 0;) {
        unsigned f = m->rowptr[j];
        while (f < m->rowptr[j + 1] && m->cols[f] < nF) f++;
        n -= f - m->rowptr[j];
        for (e = m->rowptr[j]; e < f; e++) {
            const double *U = m->ichol + 9 * (size_t)(n + e - m->rowptr[j]);
            i = m->cols[e];
            if (mode == 0) { mv(U, z + 3 * i, t); for (c = 0; c < 3; c++) z[3 * j + c] -= t[c]; }
            else { abs9(U, A); mv(A, z + 3 * i, t); for (c = 0; c < 3; c++) z[3 * j + c] += t[c] + r22; }
        }
    }
    for (i = 0; i < nF; i++) {
        for (c = 0; c < 3; c++) u[c] = z[3 * i + c];
        if (mode == 0) mv(Rv + 9 * i, u, z + 3 * i); else { abs9(Rv + 9 * i, A); mv(A, u, z + 3 * i); }
        if (mode == 1) for (c = 0; c < 3; c++) z[3 * i + c] += r22;
    }
}

/* 1 if the five passes (sn_precond_mask over every vertex: precond_core's
 * unfused route) give z and the clamp count sat that sn_precond (the fused
 * sweeps, ic_fused: every path but the masked ones) gave for r */
static int fused_vs_passes(sn_ihdr *hd, const sn_q *r, const sn_q *z, uint32_t sat, unsigned nF) {
    uint8_t *all = malloc(nF);
    sn_q *z5 = malloc(3 * nF * sizeof *z5);
    uint32_t sat5 = 0;
    int same;
    memset(all, 1, nF);
    sn_precond_mask(hd, all, 0, NULL, r, z5, &sat5);
    same = memcmp(z, z5, 3 * nF * sizeof *z5) == 0 && sat == sat5;
    free(all); free(z5);
    return same;
}

typedef void (*pose_fn_t)(const sn_blob *, unsigned, unsigned, double, sn_xform *);
static void asset(const char *name, pose_fn_t pf) {
    char path[512], nm[64];
    pu_rt rt;
    snref_model m;
    snref_state s;
    unsigned k, i, c, nJ, trial;
    sn_xform *pose;
    double h;
    snprintf(nm, sizeof nm, "%s%s", name, PU_BLOB_SUFFIX);
    pu_example(path, sizeof path, nm);
    if (pu_rt_open(&rt, path) != 0 || pu_ref_open(&m, &s, path) != 0) { T_CHECK(0, "%s: cannot open", path); return; }
    T_CHECK(m.nIC > 0, "%s: the example is baked with ICHOL (%u blocks)", name, m.nIC);
    if (!m.nIC) return;
    nJ = rt.info.joints;
    h = pu_len(rt.info.timestep);
    pose = malloc(nJ * sizeof *pose);
    for (k = 0; k < 30; k++) { pf(rt.blob, nJ, k, h, pose); sn_set_pose(rt.inst, pose, nJ); sn_step(rt.inst); }
    {
        sn_ihdr *hd = (sn_ihdr *)(void *)rt.inst;
        const sn_q *Rq = CARR(hd, o_R, sn_q);
        const uint8_t *kk = CARR(hd, o_k, uint8_t);
        unsigned n3 = 3 * m.nF;
        sn_q *r = malloc(n3 * sizeof *r), *z = malloc(n3 * sizeof *z);
        double *Rv = malloc(9 * m.nF * sizeof *Rv), *kq = malloc(m.nF * sizeof *kq), *x = malloc(n3 * sizeof *x);
        double *ze = malloc(n3 * sizeof *ze), *eb = malloc(n3 * sizeof *eb), *xa = malloc(n3 * sizeof *xa);
        double worst = 0, reach = 0, zmax = 0;
        int same5 = 0, clamped = 0;
        for (i = 0; i < m.nF; i++) {
#if defined(SN_FLOAT)
            for (c = 0; c < 9; c++) Rv[9 * i + c] = Rq[9 * i + c];
            kq[i] = 0;
            (void)kk;
#else
            for (c = 0; c < 9; c++) Rv[9 * i + c] = ldexp((double)Rq[9 * i + c], -30);
            kq[i] = kk[i];
#endif
        }
        for (trial = 0; trial < 20; trial++) {
            uint32_t sat = 0;
            double sc = 1;
            for (i = 0; i < n3; i++) x[i] = 2 * urand() - 1;
            sweeps(&m, Rv, kq, x, ze, 0);   /* scale r so that max |z| = 8 internal units (violent) or 0.01 (gentle) */
            for (i = 0; i < n3; i++) if (fabs(ze[i]) > zmax) zmax = fabs(ze[i]);
            sc = (trial & 1 ? 8.0 : 0.01) / zmax;
            zmax = 0;
            for (i = 0; i < n3; i++) {
                double v = x[i] * sc;
#if defined(SN_FLOAT)
                r[i] = (float)v; x[i] = r[i];
#else
                r[i] = (sn_q)floor(ldexp(v, 19 + kk[i / 3]) + 0.5);
                x[i] = ldexp((double)r[i], -19 - kk[i / 3]);
#endif
                xa[i] = fabs(x[i]);
            }
            sn_precond(hd, r, z, &sat);
            T_CHECK(sat == 0, "%s trial %u: %u saturations", name, trial, sat);
            same5 += fused_vs_passes(hd, r, z, sat, m.nF);
            sweeps(&m, Rv, kq, x, ze, 0);
#if defined(SN_FLOAT)
            sweeps(&m, Rv, kq, xa, eb, 2);
            for (i = 0; i < n3; i++) eb[i] *= 400 * ldexp(1.0, -24) / (1 - 400 * ldexp(1.0, -24));
#else
            sweeps(&m, Rv, kq, x, eb, 1);
#endif
            for (i = 0; i < n3; i++) {
#if defined(SN_FLOAT)
                double zi = z[i];
#else
                double zi = ldexp((double)z[i], -22);
#endif
                double err = fabs(zi - ze[i]);
                if (err / eb[i] > worst) worst = err / eb[i];
                if (err > REACH * eb[i]) reach = 1;
                if (fabs(ze[i]) > zmax) zmax = fabs(ze[i]);
            }
        }
        {   /* clamps on both routes: r at and inside +-SN_LIM (fixed), up to 1e4 > SN_FLIM (float) */
            uint32_t sat = 0;
            for (trial = 0; trial < 4; trial++) {
                for (i = 0; i < n3; i++) {
#if defined(SN_FLOAT)
                    r[i] = (float)((2 * urand() - 1) * 1e4);
#else
                    r[i] = urand() < 0.5 ? (urand() < 0.5 ? SN_LIM : -SN_LIM) : (sn_q)((2 * urand() - 1) * SN_LIM);
#endif
                }
                sat = 0;
                sn_precond(hd, r, z, &sat);
                same5 += fused_vs_passes(hd, r, z, sat, m.nF);
                clamped += sat > 0;
            }
        }
        T_CHECK(same5 == 24, "%s: the fused sweeps (sn_precond, path %s) give the five passes' bits and clamp count (sn_precond_mask, all "
                "vertices) in %d of 24 residuals", name, sn_kernels_name(), same5);
        T_CHECK(clamped == 4, "%s: the residuals at the state range clamp (%d of 4 with clamps)", name, clamped);
        T_FIGURE("%s %s: IC(0) apply vs the double solve of the same factor, 20 random residuals scaled to max |z| 8 and 0.01 internal units, %u free vertices, %u blocks: "
                 "largest error / derived bound %.3f (max |z| %.3g)", name, PU_FLAVOUR_NAME, m.nF, m.nIC, worst, zmax);
        T_CHECK(worst <= 1.0, "%s: the runtime's IC(0) apply is within the bound derived from its formats (worst %.3f of it)", name, worst);
        T_CHECK(reach, "%s: some component's error exceeds %g of its bound (the bound is not vacuous)", name, REACH);
        free(r); free(z); free(Rv); free(kq); free(x); free(ze); free(eb); free(xa);
    }
    free(pose);
    snref_release(&s); snref_free(&m);
    pu_rt_close(&rt);
}

int main(void) {
    rng_state = (double)(T_SEED() % 1000u) + 0.5;
    asset("cow", pu_cow_pose);
    asset("beast", pu_beast_pose);
    return T_END();
}
