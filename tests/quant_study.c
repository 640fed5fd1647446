/* quant_study.c -- issue 15 item 4: accuracy of narrower stiffness storage,
 * measured in double precision before any runtime change. The float64 blob's
 * cell matrices S^_e are re-quantized host-side as a writer would store them
 * and the reference steps each variant through test_physics_runtime's
 * deterministic 600-step animation; the error is that test's "quantization"
 * column: max surface-vertex distance from the float64 run (same CG
 * iterations), relative to the max elastic displacement.
 *
 * Variants (Q = the fixed blob's frac_S grid, largest entry in [2^26, 2^27]):
 *   int32          today: every entry round(x 2^Q); diagonal blocks = minus the
 *                  sum of the row's rounded off-diagonal blocks, symmetrized
 *   int16/block    off-diagonal blocks int16 mantissa + one exponent per block
 *                  (largest |mantissa| in [2^14, 2^15)), diagonal blocks as int32
 *   int16/block all  the diagonal blocks int16 + exponent too
 *   int16/cell     one exponent per cell (largest entry of the cell in [2^14, 2^15))
 *   int16/row      one exponent per cell block row (8 blocks, 24 x 3 entries)
 *
 * Usage: quant_study FIXED_BLOB DOUBLE_BLOB cow|limb
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sinew.h"
#include "snref.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"

#define STEPS 600
enum { V_INT32, V_BLOCK, V_BLOCK_ALL, V_CELL, V_ROW, V_COUNT };
static const char *vname[V_COUNT] = { "int32 (today)", "int16/block, diagonal int32", "int16/block, all", "int16/cell", "int16/row" };

static int bitlen(double a) { int b = 0; while (a >= 1.0) { a /= 2; b++; } return b; }

/* quantize x (value) on grid 2^-Q with e extra bits dropped: round(x 2^(Q-e)) 2^(e-Q) */
static double qz(double x, int Q, int e) { return ldexp(floor(ldexp(x, Q - e) + 0.5), e - Q); }

static void quantize(const snref_model *m, int Q, int v, double *out) {
    unsigned e, a, b, i, j;
    for (e = 0; e < m->nC; e++) {
        const double *K = m->cellk + 576 * (size_t)e;
        double *O = out + 576 * (size_t)e;
        int ecell = 0, erow[8] = { 0 };
        double mc = 0, mr[8] = { 0 };
        for (a = 0; a < 8; a++) for (i = 0; i < 3; i++) for (j = 0; j < 24; j++) {
            double t = fabs(ldexp(K[24 * (3 * a + i) + j], Q));
            if (t > mc) mc = t;
            if (t > mr[a]) mr[a] = t;
        }
        ecell = bitlen(mc) > 15 ? bitlen(mc) - 15 : 0;
        for (a = 0; a < 8; a++) erow[a] = bitlen(mr[a]) > 15 ? bitlen(mr[a]) - 15 : 0;
        /* off-diagonal blocks (a < b), mirrored */
        for (a = 0; a < 8; a++) for (b = a + 1; b < 8; b++) {
            double mb = 0;
            int eb;
            for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) { double t = fabs(ldexp(K[24 * (3 * a + i) + 3 * b + j], Q)); if (t > mb) mb = t; }
            eb = v == V_INT32 ? 0 : v == V_CELL ? ecell : v == V_ROW ? erow[a] : (bitlen(mb) > 15 ? bitlen(mb) - 15 : 0);
            for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) {
                double x = qz(K[24 * (3 * a + i) + 3 * b + j], Q, eb);
                O[24 * (3 * a + i) + 3 * b + j] = x;
                O[24 * (3 * b + j) + 3 * a + i] = x;
            }
        }
        /* diagonal blocks: minus the row's off-diagonal sum, symmetrized, on the grid */
        for (a = 0; a < 8; a++) {
            double D[9], mb = 0;
            int eb;
            for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) {
                double s = 0;
                for (b = 0; b < 8; b++) if (b != a) s -= O[24 * (3 * a + i) + 3 * b + j];
                D[3 * i + j] = s;
            }
            for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) { double t = fabs(ldexp(D[3 * i + j], Q)); if (t > mb) mb = t; }
            eb = (v == V_BLOCK_ALL) ? (bitlen(mb) > 15 ? bitlen(mb) - 15 : 0) : v == V_CELL ? ecell : v == V_ROW ? erow[a] : 0;
            for (i = 0; i < 3; i++) for (j = i; j < 3; j++) {
                double x = qz(0.5 * (D[3 * i + j] + D[3 * j + i]), Q, eb);
                O[24 * (3 * a + i) + 3 * a + j] = x;
                O[24 * (3 * a + j) + 3 * a + i] = x;
            }
        }
    }
}

typedef void (*pose_fn)(const sn_blob *, unsigned, unsigned, double, sn_xform *);

static void drive(const snref_model *m, const pu_rt *poser, pose_fn pf, unsigned iters, double *surf, double *disp) {
    snref_state s;
    unsigned k, nJ = poser->info.joints, nS = m->nS, i, c;
    sn_xform *pose = malloc(nJ * sizeof *pose);
    snref_xform *rp = malloc(nJ * sizeof *rp);
    double h = pu_len(poser->info.timestep);
    snref_init(&s, m);
    s.iters = iters; s.exact = iters == 0;
    if (disp) *disp = 0;
    for (k = 0; k < STEPS; k++) {
        pf(poser->blob, nJ, k, h, pose);
        pu_pose_to_ref(pose, nJ, rp);
        snref_set_pose(&s, rp);
        snref_step(&s);
        snref_get_surface(&s, surf + (size_t)k * nS * 3);
        if (disp) {
            double *skin = malloc(3 * m->nV * sizeof *skin), *ss = malloc(3 * nS * sizeof *ss), d;
            for (i = 0; i < m->nV; i++) {
                const double *R = s.R + 9 * i, *x = m->rest + 3 * i;
                for (c = 0; c < 3; c++) skin[3 * i + c] = (R[3 * c] * x[0] + R[3 * c + 1] * x[1] + R[3 * c + 2] * x[2] + s.c[3 * i + c]) * m->unit;
            }
            snref_surface_from_lattice(m, skin, ss);
            d = pu_maxdist(ss, surf + (size_t)k * nS * 3, nS);
            if (d > *disp) *disp = d;
            free(skin); free(ss);
        }
    }
    snref_release(&s);
    free(pose); free(rp);
}

static double maxerr(const double *a, const double *b, unsigned nS) {
    double mx = 0;
    unsigned k;
    for (k = 0; k < STEPS; k++) { double d = pu_maxdist(a + (size_t)k * nS * 3, b + (size_t)k * nS * 3, nS); if (d > mx) mx = d; }
    return mx;
}

int main(int argc, char **argv) {
    pu_rt poser;
    snref_model m32, m64;
    char err[200];
    unsigned v, nS, N;
    double disp, *s64, *sv, *ex;
    pose_fn pf;
    if (argc < 4) { fprintf(stderr, "usage: quant_study FIXED_BLOB DOUBLE_BLOB cow|limb\n"); return 2; }
    pf = !strcmp(argv[3], "limb") ? pu_limb_pose : pu_cow_pose;
    if (pu_rt_open(&poser, argv[1])) return 1;
    if (snref_load_file(&m32, argv[1], err, sizeof err) || snref_load_file(&m64, argv[2], err, sizeof err)) { fprintf(stderr, "%s\n", err); return 1; }
    nS = m64.nS; N = m64.cg_default;
    s64 = malloc((size_t)STEPS * nS * 3 * sizeof(double)); sv = malloc((size_t)STEPS * nS * 3 * sizeof(double));
    ex = malloc((size_t)STEPS * nS * 3 * sizeof(double));
    drive(&m64, &poser, pf, 0, ex, &disp);
    drive(&m64, &poser, pf, N, s64, NULL);
    printf("%s: %u cells, frac_S %u, %u CG iterations, %d steps; errors relative to the max elastic displacement %.4g mesh units\n",
           argv[3], m64.nC, m32.frac_S, N, STEPS, disp);
    printf("| CELLK storage | bytes per cell | CELLK bytes | quantization error vs float64 (N it.) | same, exact solves |\n|---|---|---|---|---|\n");
    {   /* the fixed blob itself, as test_physics_runtime's quantization column */
        drive(&m32, &poser, pf, N, sv, NULL);
        printf("| fixed blob (int32, as baked) | 1296 | %u | %.3e | |\n", 1296 * m64.nC, maxerr(sv, s64, nS) / disp);
    }
    for (v = 0; v < V_COUNT; v++) {
        snref_model mq = m64;
        double *K = malloc(576 * sizeof(double) * m64.nC), eN, eX;
        unsigned bpc = v == V_INT32 ? 1296 : v == V_BLOCK ? 28 * 19 + 8 * 24 : v == V_BLOCK_ALL ? 36 * 19 : v == V_CELL ? 36 * 18 + 1 : 36 * 18 + 8;
        quantize(&m64, (int)m32.frac_S, (int)v, K);
        mq.cellk = K;
        drive(&mq, &poser, pf, N, sv, NULL);
        eN = maxerr(sv, s64, nS) / disp;
        drive(&mq, &poser, pf, 0, sv, NULL);
        eX = maxerr(sv, ex, nS) / disp;
        printf("| %s | %u | %u | %.3e | %.3e |\n", vname[v], bpc, bpc * m64.nC, eN, eX);
        free(K);
    }
    pu_rt_close(&poser);
    return 0;
}
