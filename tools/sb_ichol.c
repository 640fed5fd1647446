/* sb_ichol.c -- the IC(0) preconditioner of the blob (section ICHOL,
 * runtime/SOLVER_STUDY.md §1, runtime/NUMERICS.md "Preconditioner"): the
 * incomplete block LDL^T of the rest-frame step matrix over free vertices,
 *   A0 = (1+a1) M^ + (1+b1) S^  ~  (I + L^) D (I + L^)^T,
 * on the free-free pattern of the mass matrix (no fill), in double. */
#include "sb.h"
#include "../runtime/src/sn_format.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void mm(const double *A, const double *B, double *C) { /* C = A B */
    int i, j, k;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            double s = 0;
            for (k = 0; k < 3; k++) s += A[3 * i + k] * B[3 * k + j];
            C[3 * i + j] = s;
        }
}
static void mmt(const double *A, const double *B, double *C) { /* C = A B^T */
    int i, j, k;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            double s = 0;
            for (k = 0; k < 3; k++) s += A[3 * i + k] * B[3 * j + k];
            C[3 * i + j] = s;
        }
}
/* inverse of a symmetric 3x3; 0 when it is not positive definite */
static int spd_inv(const double *A, double *B) {
    double d1 = A[0], d2 = A[0] * A[4] - A[1] * A[3];
    double c0 = A[4] * A[8] - A[5] * A[7], c1 = A[5] * A[6] - A[3] * A[8], c2 = A[3] * A[7] - A[4] * A[6];
    double d = A[0] * c0 + A[1] * c1 + A[2] * c2;
    if (!(d1 > 0 && d2 > 0 && d > 0)) return 0;
    B[0] = c0 / d; B[1] = (A[2] * A[7] - A[1] * A[8]) / d; B[2] = (A[1] * A[5] - A[2] * A[4]) / d;
    B[3] = c1 / d; B[4] = (A[0] * A[8] - A[2] * A[6]) / d; B[5] = (A[2] * A[3] - A[0] * A[5]) / d;
    B[6] = c2 / d; B[7] = (A[1] * A[6] - A[0] * A[7]) / d; B[8] = (A[0] * A[4] - A[1] * A[3]) / d;
    return 1;
}

/* block (i, nb[p]) of A0 */
static void a0_block(const sb_model *o, int i, int p, double m0, double a1, double b1, double *A) {
    double sm = (1 + a1) * o->M[p] / m0, ss = (1 + b1) * o->h * o->h / m0;
    int k;
    for (k = 0; k < 9; k++) A[k] = ss * o->S[9 * (size_t)p + (size_t)k];
    if (o->nb[p] == i) /* the diagonal block symmetrized, as block Jacobi's */
        for (k = 0; k < 9; k++) A[k] = 0.5 * (A[k] + ss * o->S[9 * (size_t)p + (size_t)(3 * (k % 3) + k / 3)]);
    for (k = 0; k < 3; k++) A[4 * k] += sm;
}

int sb_ichol(const sb_model *o, double m0, double a1, double b1, sb_ichol_t *f) {
    const int nF = o->nf;
    const size_t np = (size_t)o->nbptr[o->nv];
    double *Lh = calloc(9 * np, sizeof(double)); /* L^_ij at the pattern entry (i, j < i) */
    double *D = calloc(9 * (size_t)nF, sizeof(double));
    int *pos = malloc(sizeof(int) * (size_t)(nF > 0 ? nF : 1));
    int i, p, q, k, n;
    memset(f, 0, sizeof *f);
    if (!Lh || !D || !pos) { free(Lh); free(D); free(pos); return sb_fail("out of memory (IC(0) factor)"); }
    f->Dinv = calloc(9 * (size_t)nF, sizeof(double));
    for (i = 0; i < nF; i++) pos[i] = -1;
    for (i = 0; i < nF; i++) {
        double Di[9], T[9], W[9];
        for (p = o->nbptr[i]; p < o->nbptr[i + 1]; p++) if (o->nb[p] < nF) pos[o->nb[p]] = p;
        /* L^_ij = (A_ij - sum_{k<j} L^_ik D_k L^_jk^T) D_j^-1 for j < i in the pattern, ascending */
        for (p = o->nbptr[i]; p < o->nbptr[i + 1]; p++) {
            int j = o->nb[p];
            if (j >= i) break;
            a0_block(o, i, p, m0, a1, b1, W);
            for (q = o->nbptr[j]; q < o->nbptr[j + 1] && o->nb[q] < j; q++) {
                int kk = o->nb[q];
                if (pos[kk] < 0) continue;
                mm(Lh + 9 * (size_t)pos[kk], D + 9 * (size_t)kk, T);
                mmt(T, Lh + 9 * (size_t)q, Di);
                for (k = 0; k < 9; k++) W[k] -= Di[k];
            }
            mm(W, f->Dinv + 9 * (size_t)j, Lh + 9 * (size_t)p);
        }
        /* D_i = A_ii - sum_{k<i} L^_ik D_k L^_ik^T */
        p = pos[i];
        a0_block(o, i, p, m0, a1, b1, W);
        for (q = o->nbptr[i]; q < o->nbptr[i + 1] && o->nb[q] < i; q++) {
            int kk = o->nb[q];
            mm(Lh + 9 * (size_t)q, D + 9 * (size_t)kk, T);
            mmt(T, Lh + 9 * (size_t)q, Di);
            for (k = 0; k < 9; k++) W[k] -= Di[k];
        }
        for (k = 0; k < 9; k++) D[9 * (size_t)i + (size_t)k] = 0.5 * (W[k] + W[3 * (k % 3) + k / 3]);
        if (!spd_inv(D + 9 * (size_t)i, f->Dinv + 9 * (size_t)i)) {
            /* IC(0) breakdown: the pivot is not positive definite. Shift it
             * towards the full diagonal block until it is (never needed on the
             * examples: A0 is mass-dominated). */
            double A[9], s = 1.0 / 64;
            a0_block(o, i, p, m0, a1, b1, A);
            while (!spd_inv(D + 9 * (size_t)i, f->Dinv + 9 * (size_t)i)) {
                for (k = 0; k < 9; k++) D[9 * (size_t)i + (size_t)k] = (1 - s) * D[9 * (size_t)i + (size_t)k] + s * A[k];
                s = s < 0.5 ? 2 * s : 1;
                if (s == 1 && !spd_inv(A, f->Dinv + 9 * (size_t)i)) {
                    free(Lh); free(D); free(pos); sb_ichol_free(f);
                    return sb_fail("IC(0) preconditioner: the diagonal block of free lattice vertex %d is not positive definite "
                                   "(a degenerate lattice?): bake with 'precond jacobi'", i);
                }
            }
            f->shifted++;
        }
        for (p = o->nbptr[i]; p < o->nbptr[i + 1]; p++) if (o->nb[p] < nF) pos[o->nb[p]] = -1;
    }
    if (f->shifted && !o->quiet)
        fprintf(stderr, "sinew-bake: warning: IC(0) broke down at %d of %d free lattice vertices; their pivots were shifted towards "
                        "the diagonal blocks (a weaker preconditioner there: check the iteration count, or use 'precond jacobi')\n",
                f->shifted, nF);
    /* U_ji = L^_ij^T, row j: the free-free upper entries in pattern order */
    for (n = 0, i = 0; i < nF; i++)
        for (p = o->nbptr[i]; p < o->nbptr[i + 1]; p++) n += o->nb[p] > i && o->nb[p] < nF;
    f->n = n;
    f->U = calloc(9 * (size_t)(n > 0 ? n : 1), sizeof(double));
    for (n = 0, i = 0; i < nF; i++) /* row i of U holds column i of L^: find (j, i) in row j > i */
        for (p = o->nbptr[i]; p < o->nbptr[i + 1]; p++) {
            int j = o->nb[p], r;
            if (j <= i || j >= nF) continue;
            for (q = o->nbptr[j]; q < o->nbptr[j + 1] && o->nb[q] != i; q++) {}
            if (q == o->nbptr[j + 1]) { free(Lh); free(D); free(pos); sb_ichol_free(f); return sb_fail("mass pattern is not symmetric"); }
            for (r = 0; r < 9; r++) f->U[9 * (size_t)n + (size_t)r] = Lh[9 * (size_t)q + (size_t)(3 * (r % 3) + r / 3)];
            for (r = 0; r < 9; r++) f->maxU = fmax(f->maxU, fabs(f->U[9 * (size_t)n + (size_t)r]));
            n++;
        }
    free(Lh); free(D); free(pos);
    return 0;
}

/* One block as stored: int16 mantissas m with |m| <= 2^15 - 1 and one frac
 * (entry = m 2^-frac), frac as large as the block's largest entry allows,
 * at most SN_ICHOL_FRAC_MAX. Returns -1 if the block does not fit (|entry|
 * >= 2^15). bits < 15 (measurement only) rounds the mantissas to fewer bits. */
int sb_ichol_quant(const double *U, int bits, int m[9], int *frac) {
    double mx = 0;
    int k, e, fr;
    for (k = 0; k < 9; k++) mx = fmax(mx, fabs(U[k]));
    if (!(mx < 32767.0)) return -1;
    if (mx == 0) fr = SN_ICHOL_FRAC_MAX;
    else {
        frexp(mx, &e);           /* mx in [2^(e-1), 2^e) */
        fr = bits - e;           /* mx 2^fr < 2^bits */
        if (fr > SN_ICHOL_FRAC_MAX) fr = SN_ICHOL_FRAC_MAX;
        if (fr < 0) return -1;
        if (floor(ldexp(mx, fr) + 0.5) > ldexp(1.0, bits) - 1) fr--;
        if (fr < 0) return -1;
    }
    for (k = 0; k < 9; k++) {
        double x = ldexp(U[k], fr);
        m[k] = (int)(x < 0 ? -floor(-x + 0.5) : floor(x + 0.5));
        m[k] *= 1 << (15 - bits);
    }
    *frac = fr + 15 - bits;
    if (*frac > SN_ICHOL_FRAC_MAX) { /* tiny blocks at fewer bits: keep the top bits */
        for (k = 0; k < 9; k++) m[k] /= 1 << (*frac - SN_ICHOL_FRAC_MAX);
        *frac = SN_ICHOL_FRAC_MAX;
    }
    return 0;
}

void sb_ichol_free(sb_ichol_t *f) {
    free(f->U);
    free(f->Dinv);
    f->U = f->Dinv = NULL;
}
