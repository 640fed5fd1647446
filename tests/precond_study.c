/* precond_study.c -- issue 15 item 3: stronger preconditioners than the
 * rotated block Jacobi, measured in double precision on the real step systems
 * of the examples (no runtime arithmetic: the runtime only poses the skeleton
 * from the clip, exactly as the players do; the states, right-hand sides and
 * warm starts come from the double reference tools/ref/snref.c stepping with
 * the blob's own iteration count and block Jacobi, as the runtime does).
 *
 * For every sampled step: A = (1+a1) M^_FF + (1+b1) sum_e R_e S^_e R_e^T at
 * the step's cell frames, its right-hand side b and warm start x0 (the
 * previous step's dv); x* = the exact solve (PCG to 1e-13). Target: the
 * errors ||x - x*||_A and max_i |x_i - x*_i| of today's solve (N_blob
 * block-Jacobi iterations from x0). For each candidate: the smallest k whose
 * k iterations from the same x0 reach both; reported as the worst step (the
 * fixed count must cover it), the 90th percentile and the median; the mean
 * contraction of the A-norm error per iteration over the first 10.
 *
 * Candidates (all z = R C R^T r with R the per-vertex frames, C baked in the
 * rest frame from A0 = (1+a1) M^ + (1+b1) sum_e S^_e, R = I):
 *   BJ      today: C = P (blob PRECOND)
 *   SGS     block symmetric Gauss-Seidel on A0: C = (D+L)^-1 D (D+L)^-T
 *   IC0     incomplete Cholesky of A0 (scalar, pattern of the 3x3 blocks, natural order)
 *   CHOL    complete Cholesky of A0 (skyline, reverse Cuthill-McKee): the limit of
 *           any rest-frame factorization with fill
 *   +CT     additive coarse correction, trilinear basis on the lattice of 2-cell spacing
 *   +CA     additive coarse correction, 2x2x2-vertex aggregates, 6 rigid modes each
 *           (both: Galerkin Phi^T A0 Phi baked, skyline Cholesky)
 * Chebyshev / polynomial preconditioners are not listed: k mat-vecs of a
 * polynomial in BA cannot beat k CG iterations with B in the A-norm (CG is
 * optimal over the same Krylov space), and the mat-vec is the dominant cost.
 *
 * Cost: multiply-adds counted from the runtime's loops (sn_solve.c): the
 * cell-by-cell mat-vec (576 per cell + 9 per free corner each way), the
 * mass pass, the vector operations, each preconditioner; memory as int32
 * entries (+ u16 column indices for sparse factors).
 *
 * Usage: precond_study FIXED_BLOB CLIP [CLIP...] [-every K]
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

#define MAXIT 60
#define MAXS 4096

static void inv3(const double *A, double *B);
static void m3v(const double *B, const double *x, double *y);
/* ---------------- block sparse symmetric matrix (free vertices) ---------------- */
typedef struct {
    unsigned n;          /* vertices */
    unsigned *rp, *ci;   /* full pattern (both triangles + diagonal), sorted */
    double *v;           /* 9 per block, row-major */
    int *map;            /* n*n: block index or -1 */
} bsr;

static unsigned nF_, n3_;
static const snref_model *M_;
static bsr A0, At;
static int *grid; /* nV*3 lattice coordinates */

static void bsr_pattern(bsr *A, const snref_model *m) {
    unsigned n = m->nF, e, a, b, i, j, cnt = 0;
    A->n = n;
    A->map = malloc(sizeof(int) * n * n);
    for (i = 0; i < n * n; i++) A->map[i] = -1;
    for (e = 0; e < m->nC; e++)
        for (a = 0; a < 8; a++)
            for (b = 0; b < 8; b++) {
                unsigned va = m->cells[8 * e + a], vb = m->cells[8 * e + b];
                if (va < n && vb < n) A->map[va * n + vb] = 0;
            }
    for (i = 0; i < n; i++) {
        A->map[i * n + i] = 0;
        for (unsigned k = m->rowptr[i]; k < m->rowptr[i + 1]; k++)
            if (m->cols[k] < n) { A->map[i * n + m->cols[k]] = 0; A->map[m->cols[k] * n + i] = 0; }
    }
    A->rp = malloc(sizeof(unsigned) * (n + 1));
    for (i = 0; i < n; i++) {
        A->rp[i] = cnt;
        for (j = 0; j < n; j++) if (A->map[i * n + j] >= 0) A->map[i * n + j] = (int)cnt++;
    }
    A->rp[n] = cnt;
    A->ci = malloc(sizeof(unsigned) * cnt);
    A->v = calloc(9 * (size_t)cnt, sizeof(double));
    for (i = 0; i < n; i++)
        for (j = 0; j < n; j++) if (A->map[i * n + j] >= 0) A->ci[A->map[i * n + j]] = j;
}

/* A = ca M^ + cb sum_e R_e S_e R_e^T (Rc NULL: rest frame) */
static void bsr_assemble(bsr *A, const snref_model *m, const double *Rc) {
    unsigned n = m->nF, e, a, b, i, j, k, l;
    double ca = 1.0 + m->a1, cb = 1.0 + m->b1;
    memset(A->v, 0, 9 * sizeof(double) * A->rp[n]);
    for (e = 0; e < m->nC; e++) {
        const double *K = m->cellk + 576 * (size_t)e, *R = Rc ? Rc + 9 * e : NULL;
        for (a = 0; a < 8; a++)
            for (b = 0; b < 8; b++) {
                unsigned va = m->cells[8 * e + a], vb = m->cells[8 * e + b];
                double B[9], T[9];
                double *dst;
                if (va >= n || vb >= n) continue;
                for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) B[3 * i + j] = K[24 * (3 * a + i) + 3 * b + j];
                if (R) { /* R B R^T */
                    for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) {
                        double s = 0; for (k = 0; k < 3; k++) s += B[3 * i + k] * R[3 * j + k]; T[3 * i + j] = s; }
                    for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) {
                        double s = 0; for (k = 0; k < 3; k++) s += R[3 * i + k] * T[3 * k + j]; B[3 * i + j] = s; }
                }
                dst = A->v + 9 * (size_t)A->map[va * n + vb];
                for (l = 0; l < 9; l++) dst[l] += cb * B[l];
            }
    }
    for (i = 0; i < n; i++) {
        double *d = A->v + 9 * (size_t)A->map[i * n + i];
        for (k = 0; k < 3; k++) d[4 * k] += ca * m->mdiag[i];
        for (l = m->rowptr[i]; l < m->rowptr[i + 1]; l++) {
            unsigned c = m->cols[l];
            if (c >= n) continue;
            for (k = 0; k < 3; k++) {
                A->v[9 * (size_t)A->map[i * n + c] + 4 * k] += ca * m->moff[l];
                A->v[9 * (size_t)A->map[c * n + i] + 4 * k] += ca * m->moff[l];
            }
        }
    }
}

static void bsr_mul(const bsr *A, const double *x, double *y) {
    unsigned i, p, k;
    for (i = 0; i < A->n; i++) {
        double s[3] = { 0, 0, 0 };
        for (p = A->rp[i]; p < A->rp[i + 1]; p++) {
            const double *B = A->v + 9 * (size_t)p, *xx = x + 3 * A->ci[p];
            for (k = 0; k < 3; k++) s[k] += B[3 * k] * xx[0] + B[3 * k + 1] * xx[1] + B[3 * k + 2] * xx[2];
        }
        y[3 * i] = s[0]; y[3 * i + 1] = s[1]; y[3 * i + 2] = s[2];
    }
}

static double dotv(const double *a, const double *b, unsigned n) {
    double s = 0; unsigned i;
    for (i = 0; i < n; i++) s += a[i] * b[i];
    return s;
}

/* ---------------- skyline Cholesky (scalar, with a vertex permutation) ---------------- */
typedef struct {
    unsigned n;            /* scalar size */
    unsigned *first;       /* first column of row i */
    size_t *off;           /* row i's entries L[i][first..i] start at off[i] */
    double *L;
    unsigned *perm;        /* scalar new -> old */
    size_t nnz;
} sky;

static double *sky_at(sky *S, unsigned i, unsigned j) { return S->L + S->off[i] + (j - S->first[i]); }

/* dense symmetric matrix get: Afn(i,j) on old scalar indices */
typedef double (*getfn)(void *ctx, unsigned i, unsigned j);

static int sky_factor(sky *S, unsigned n, const unsigned *perm, getfn get, void *ctx, const unsigned *firstv) {
    unsigned i, j, k;
    S->n = n; S->perm = malloc(sizeof(unsigned) * n); memcpy(S->perm, perm, sizeof(unsigned) * n);
    S->first = malloc(sizeof(unsigned) * n); S->off = malloc(sizeof(size_t) * (n + 1));
    S->nnz = 0;
    for (i = 0; i < n; i++) { S->first[i] = firstv[i]; S->off[i] = S->nnz; S->nnz += i - firstv[i] + 1; }
    S->off[n] = S->nnz;
    S->L = calloc(S->nnz, sizeof(double));
    for (i = 0; i < n; i++)
        for (j = S->first[i]; j <= i; j++) *sky_at(S, i, j) = get(ctx, perm[i], perm[j]);
    for (i = 0; i < n; i++) {
        for (j = S->first[i]; j <= i; j++) {
            unsigned k0 = S->first[i] > S->first[j] ? S->first[i] : S->first[j];
            double s = *sky_at(S, i, j);
            const double *li = S->L + S->off[i] - S->first[i], *lj = S->L + S->off[j] - S->first[j];
            for (k = k0; k < j; k++) s -= li[k] * lj[k];
            if (j == i) { if (s <= 0) return -1; *sky_at(S, i, i) = sqrt(s); }
            else *sky_at(S, i, j) = s / lj[j];
        }
    }
    return 0;
}

static void sky_solve(const sky *S, const double *r, double *z, double *w) {
    unsigned i, k, n = S->n;
    for (i = 0; i < n; i++) {
        const double *li = S->L + S->off[i] - S->first[i];
        double s = r[S->perm[i]];
        for (k = S->first[i]; k < i; k++) s -= li[k] * w[k];
        w[i] = s / li[i];
    }
    for (i = n; i-- > 0;) {
        const double *li = S->L + S->off[i] - S->first[i];
        w[i] /= li[i];
        for (k = S->first[i]; k < i; k++) w[k] -= li[k] * w[i];
    }
    for (i = 0; i < n; i++) z[S->perm[i]] = w[i];
}

/* ---------------- rest-frame preconditioners ---------------- */
static double get_A0(void *ctx, unsigned i, unsigned j) {
    const bsr *A = ctx;
    int b = A->map[(i / 3) * A->n + j / 3];
    return b < 0 ? 0.0 : A->v[9 * (size_t)b + 3 * (i % 3) + j % 3];
}

/* reverse Cuthill-McKee of a graph given by a callback adjacency (CSR) */
static void rcm_order(unsigned n, const unsigned *rp, const unsigned *ci, unsigned *perm) {
    unsigned *deg = malloc(sizeof(unsigned) * n), *q = malloc(sizeof(unsigned) * n);
    char *seen = calloc(n, 1);
    unsigned head = 0, tail = 0, i, p, cnt = 0;
    for (i = 0; i < n; i++) deg[i] = rp[i + 1] - rp[i];
    while (cnt < n) {
        unsigned s = n;
        for (i = 0; i < n; i++) if (!seen[i] && (s == n || deg[i] < deg[s])) s = i;
        seen[s] = 1; q[tail++] = s;
        while (head < tail) {
            unsigned u = q[head++], nb[64], nn = 0, a, b;
            perm[cnt++] = u;
            for (p = rp[u]; p < rp[u + 1]; p++) if (!seen[ci[p]] && nn < 64) { nb[nn++] = ci[p]; seen[ci[p]] = 1; }
            for (a = 1; a < nn; a++) for (b = a; b > 0 && deg[nb[b]] < deg[nb[b - 1]]; b--) { unsigned t = nb[b]; nb[b] = nb[b - 1]; nb[b - 1] = t; }
            for (a = 0; a < nn; a++) q[tail++] = nb[a];
        }
    }
    for (i = 0; i < n / 2; i++) { unsigned t = perm[i]; perm[i] = perm[n - 1 - i]; perm[n - 1 - i] = t; }
    free(deg); free(q); free(seen);
}

/* vertex order -> scalar order and skyline first columns for matrix with vertex graph (rp, ci) */
static void sky_from_vertex_order(unsigned nv, const unsigned *vperm, const unsigned *rp, const unsigned *ci,
                                  unsigned *sperm, unsigned *first) {
    unsigned *inv = malloc(sizeof(unsigned) * nv), i, p, k;
    for (i = 0; i < nv; i++) inv[vperm[i]] = i;
    for (i = 0; i < nv; i++) {
        unsigned f = i;
        for (p = rp[vperm[i]]; p < rp[vperm[i] + 1]; p++) if (inv[ci[p]] < f) f = inv[ci[p]];
        for (k = 0; k < 3; k++) { sperm[3 * i + k] = 3 * vperm[i] + k; first[3 * i + k] = 3 * f; }
    }
    free(inv);
}

static sky CH;          /* complete Cholesky of A0 */
/* IC(0): scalar lower CSR with the block pattern */
static unsigned *icp, *icc; static double *icv, *icv_rest, *icv_cur; static size_t ic_nnz; static double ic_flops, ic_fl_rest;
static const bsr *icA = &A0;
static double *Dinv;    /* block SGS: inverse diagonal blocks of A0 */

static void ic0_build(void) {
    const bsr *AA = icA;
    unsigned n = n3_, i, p, q;
    double *w = calloc(n, sizeof(double));
    unsigned *pos = malloc(sizeof(unsigned) * n);
    if (!icp) icp = malloc(sizeof(unsigned) * (n + 1));
    ic_nnz = 0;
    for (i = 0; i < n; i++) { /* count: j <= i with block in pattern */
        unsigned vi = i / 3;
        icp[i] = (unsigned)ic_nnz;
        for (p = AA->rp[vi]; p < AA->rp[vi + 1]; p++) {
            unsigned vj = AA->ci[p], k;
            for (k = 0; k < 3; k++) if (3 * vj + k <= i) ic_nnz++;
        }
    }
    icp[n] = (unsigned)ic_nnz;
    if (!icc) icc = malloc(sizeof(unsigned) * ic_nnz);
    icv = malloc(sizeof(double) * ic_nnz);
    for (i = 0; i < n; i++) {
        unsigned vi = i / 3, c = icp[i];
        for (p = AA->rp[vi]; p < AA->rp[vi + 1]; p++) {
            unsigned vj = AA->ci[p], k;
            for (k = 0; k < 3; k++) if (3 * vj + k <= i) { icc[c] = 3 * vj + k; icv[c] = AA->v[9 * (size_t)p + 3 * (i % 3) + k]; c++; }
        }
    }
    /* up-looking IC(0): row i, entries j<i: L_ij = (A_ij - sum_{k<j} L_ik L_jk)/L_jj */
    for (i = 0; i < n; i++) pos[i] = (unsigned)-1;
    for (i = 0; i < n; i++) {
        for (p = icp[i]; p < icp[i + 1]; p++) { pos[icc[p]] = p; w[icc[p]] = 0; }
        for (p = icp[i]; p < icp[i + 1]; p++) {
            unsigned j = icc[p];
            double s = icv[p];
            for (q = icp[j]; q < icp[j + 1] - 1; q++) { /* row j, k < j */
                unsigned k = icc[q];
                if (pos[k] != (unsigned)-1 && k < j) { s -= icv[pos[k]] * icv[q]; ic_flops += 1; }
            }
            if (j == i) { if (s <= 0) { fprintf(stderr, "IC0 breakdown at %u\n", i); s = fabs(icv[p]) * 1e-3 + 1e-30; } icv[p] = sqrt(s); }
            else icv[p] = s / icv[icp[j + 1] - 1];
        }
        for (p = icp[i]; p < icp[i + 1]; p++) pos[icc[p]] = (unsigned)-1;
    }
    free(w); free(pos);
}
static void ic0_solve(const double *r, double *z) {
    unsigned n = n3_, i, p;
    for (i = 0; i < n; i++) {
        double s = r[i];
        for (p = icp[i]; p < icp[i + 1] - 1; p++) s -= icv[p] * z[icc[p]];
        z[i] = s / icv[icp[i + 1] - 1];
    }
    for (i = n; i-- > 0;) {
        z[i] /= icv[icp[i + 1] - 1];
        for (p = icp[i]; p < icp[i + 1] - 1; p++) z[icc[p]] -= icv[p] * z[i];
    }
}

/* block view of the IC0 factor: row vertex i, blocks (i, j<=i); rotated per step */
static unsigned *lbp, *lbc, *lbcell; static double *lb, *lbr, *ldl_L, ldl_lmax, ldl_grow;
static void lb_build(const snref_model *m) {
    unsigned i, p, a, b, cnt = 0, e;
    lbp = malloc(sizeof(unsigned) * (nF_ + 1));
    for (i = 0; i < nF_; i++) { lbp[i] = cnt; for (p = A0.rp[i]; p < A0.rp[i + 1]; p++) if (A0.ci[p] <= i) cnt++; }
    lbp[nF_] = cnt;
    lbc = malloc(sizeof(unsigned) * cnt); lbcell = malloc(sizeof(unsigned) * cnt);
    lb = calloc(9 * (size_t)cnt, sizeof(double)); lbr = calloc(9 * (size_t)cnt, sizeof(double));
    for (i = 0, cnt = 0; i < nF_; i++) for (p = A0.rp[i]; p < A0.rp[i + 1]; p++) if (A0.ci[p] <= i) {
        unsigned j = A0.ci[p], q;
        lbc[cnt] = j; lbcell[cnt] = (unsigned)-1;
        for (e = 0; e < m->nC && lbcell[cnt] == (unsigned)-1; e++) {
            int hi = 0, hj = 0;
            for (a = 0; a < 8; a++) { hi |= m->cells[8 * e + a] == i; hj |= m->cells[8 * e + a] == j; }
            if (hi && hj) lbcell[cnt] = e;
        }
        for (a = 0; a < 3; a++) for (q = icp[3 * i + a]; q < icp[3 * i + a + 1]; q++)
            if (icc[q] / 3 == j) { b = icc[q] % 3; lb[9 * (size_t)cnt + 3 * a + b] = icv_rest[q]; }
        cnt++;
    }
}
static void mm3(const double *A, const double *B, double *C, int tb);
static void inv3(const double *A, double *B);
/* unit-lower block L^_ij = L_ij L_jj^-1 (A0 ~ (I+L^) D (I+L^)^T, D_i = L_ii L_ii^T): its largest entry */
static void ldl_build(void) {
    unsigned i, p, k;
    ldl_L = calloc(9 * (size_t)lbp[nF_], sizeof(double));
    for (i = 0; i < nF_; i++)
        for (p = lbp[i]; p < lbp[i + 1]; p++) {
            unsigned j = lbc[p];
            double Ljj[9], Li[9];
            memcpy(Ljj, lb + 9 * (size_t)(lbp[j + 1] - 1), sizeof Ljj);
            inv3(Ljj, Li);
            if (j == i) continue;
            mm3(lb + 9 * (size_t)p, Li, ldl_L + 9 * (size_t)p, 0);
            for (k = 0; k < 9; k++) if (fabs(ldl_L[9 * (size_t)p + k]) > ldl_lmax) ldl_lmax = fabs(ldl_L[9 * (size_t)p + k]);
        }
}
static void mm3(const double *A, const double *B, double *C, int tb) {
    unsigned i, j, k;
    for (i = 0; i < 3; i++) for (j = 0; j < 3; j++) { double s = 0; for (k = 0; k < 3; k++) s += A[3 * i + k] * (tb ? B[3 * j + k] : B[3 * k + j]); C[3 * i + j] = s; }
}
/* off-diagonal blocks R_c L_ij R_c^T with c a cell holding both; diagonal blocks kept (applied R_i L_ii R_i^T) */
static void lb_rotate(const snref_state *s) {
    unsigned i, p;
    for (i = 0; i < nF_; i++) for (p = lbp[i]; p < lbp[i + 1]; p++) {
        double T[9];
        const double *R = lbc[p] == i ? s->R + 9 * i : s->Rc + 9 * lbcell[p];
        mm3(R, lb + 9 * (size_t)p, T, 0); mm3(T, R, lbr + 9 * (size_t)p, 1);
    }
}
static void lb_solve(const double *r, double *z) {
    unsigned i, p, k;
    double s[3], t[3];
    for (i = 0; i < nF_; i++) {
        const double *D = lbr + 9 * (size_t)(lbp[i + 1] - 1); /* rotated lower-triangular diagonal block */
        for (k = 0; k < 3; k++) s[k] = r[3 * i + k];
        for (p = lbp[i]; p + 1 < lbp[i + 1]; p++) { m3v(lbr + 9 * (size_t)p, z + 3 * lbc[p], t); for (k = 0; k < 3; k++) s[k] -= t[k]; }
        { double Di[9]; inv3(D, Di); m3v(Di, s, z + 3 * i); }
    }
    for (i = nF_; i-- > 0;) {
        const double *D = lbr + 9 * (size_t)(lbp[i + 1] - 1);
        double Di[9], DiT[9];
        unsigned a, b;
        inv3(D, Di);
        for (a = 0; a < 3; a++) for (b = 0; b < 3; b++) DiT[3 * a + b] = Di[3 * b + a];
        m3v(DiT, z + 3 * i, t);
        for (k = 0; k < 3; k++) z[3 * i + k] = t[k];
        for (p = lbp[i]; p + 1 < lbp[i + 1]; p++) { /* z_j -= L_ij^T z_i */
            const double *B = lbr + 9 * (size_t)p;
            unsigned j = lbc[p];
            for (a = 0; a < 3; a++) z[3 * j + a] -= B[a] * z[3 * i] + B[3 + a] * z[3 * i + 1] + B[6 + a] * z[3 * i + 2];
        }
    }
}

static void inv3(const double *A, double *B) {
    double d = A[0] * (A[4] * A[8] - A[5] * A[7]) - A[1] * (A[3] * A[8] - A[5] * A[6]) + A[2] * (A[3] * A[7] - A[4] * A[6]);
    B[0] = (A[4] * A[8] - A[5] * A[7]) / d; B[1] = (A[2] * A[7] - A[1] * A[8]) / d; B[2] = (A[1] * A[5] - A[2] * A[4]) / d;
    B[3] = (A[5] * A[6] - A[3] * A[8]) / d; B[4] = (A[0] * A[8] - A[2] * A[6]) / d; B[5] = (A[2] * A[3] - A[0] * A[5]) / d;
    B[6] = (A[3] * A[7] - A[4] * A[6]) / d; B[7] = (A[1] * A[6] - A[0] * A[7]) / d; B[8] = (A[0] * A[4] - A[1] * A[3]) / d;
}
static void m3v(const double *B, const double *x, double *y) {
    y[0] = B[0] * x[0] + B[1] * x[1] + B[2] * x[2];
    y[1] = B[3] * x[0] + B[4] * x[1] + B[5] * x[2];
    y[2] = B[6] * x[0] + B[7] * x[1] + B[8] * x[2];
}
static void sgs_solve(const double *r, double *z) {
    unsigned n = nF_, i, p, k;
    for (i = 0; i < n; i++) { /* forward: y_i = D^-1 (r_i - sum_{j<i} A_ij y_j) */
        double s[3] = { r[3 * i], r[3 * i + 1], r[3 * i + 2] }, t[3];
        for (p = A0.rp[i]; p < A0.rp[i + 1] && A0.ci[p] < i; p++) {
            m3v(A0.v + 9 * (size_t)p, z + 3 * A0.ci[p], t);
            for (k = 0; k < 3; k++) s[k] -= t[k];
        }
        m3v(Dinv + 9 * i, s, z + 3 * i);
    }
    for (i = n; i-- > 0;) { /* backward: z_i = y_i - D^-1 sum_{j>i} A_ij z_j */
        double s[3] = { 0, 0, 0 }, t[3];
        for (p = A0.rp[i]; p < A0.rp[i + 1]; p++) {
            if (A0.ci[p] <= i) continue;
            m3v(A0.v + 9 * (size_t)p, z + 3 * A0.ci[p], t);
            for (k = 0; k < 3; k++) s[k] += t[k];
        }
        m3v(Dinv + 9 * i, s, t);
        for (k = 0; k < 3; k++) z[3 * i + k] -= t[k];
    }
}

/* ---------------- coarse spaces ---------------- */
typedef struct {
    unsigned nc;               /* coarse unknowns */
    unsigned *rp, *ci;         /* per free scalar row i: coarse columns and weights (Phi, sparse rows) */
    double *w;
    sky S;                     /* Cholesky of Phi^T A0 Phi */
    size_t phi_nnz;
    double ma;                 /* multiply-adds to apply (restrict + solve + prolong) */
} coarse;
static coarse CT, CA;

typedef struct { const double *Ac; unsigned nc; } densectx;
static double get_dense(void *ctx, unsigned i, unsigned j) { const densectx *d = ctx; return d->Ac[(size_t)i * d->nc + j]; }

static void coarse_finish(coarse *C) {
    unsigned nc = C->nc, i, c, p, q;
    double *Ac = calloc((size_t)nc * nc, sizeof(double)), *col = calloc(n3_, sizeof(double)), *y = calloc(n3_, sizeof(double));
    unsigned *cc = NULL, *cnt = calloc(nc, sizeof(unsigned)), *perm = malloc(sizeof(unsigned) * nc), *first = malloc(sizeof(unsigned) * nc);
    unsigned *crp;
    densectx dc;
    /* Phi^T A0 Phi column by column */
    for (c = 0; c < nc; c++) {
        memset(col, 0, n3_ * sizeof(double));
        for (i = 0; i < n3_; i++) for (p = C->rp[i]; p < C->rp[i + 1]; p++) if (C->ci[p] == c) col[i] = C->w[p];
        bsr_mul(&A0, col, y);
        for (i = 0; i < n3_; i++) for (p = C->rp[i]; p < C->rp[i + 1]; p++) Ac[(size_t)C->ci[p] * nc + c] += C->w[p] * y[i];
    }
    /* graph of Ac, RCM, skyline */
    crp = malloc(sizeof(unsigned) * (nc + 1));
    for (i = 0, q = 0; i < nc; i++) { crp[i] = q; for (c = 0; c < nc; c++) if (c != i && fabs(Ac[(size_t)i * nc + c]) > 1e-14 * fabs(Ac[(size_t)i * nc + i])) q++; }
    crp[nc] = q; cc = calloc(q + 1, sizeof(unsigned));
    for (i = 0, q = 0; i < nc; i++) for (c = 0; c < nc; c++) if (c != i && fabs(Ac[(size_t)i * nc + c]) > 1e-14 * fabs(Ac[(size_t)i * nc + i])) cc[q++] = c;
    rcm_order(nc, crp, cc, perm);
    {
        unsigned *inv = malloc(sizeof(unsigned) * nc);
        for (i = 0; i < nc; i++) inv[perm[i]] = i;
        for (i = 0; i < nc; i++) { unsigned f = i; for (p = crp[perm[i]]; p < crp[perm[i] + 1]; p++) if (inv[cc[p]] < f) f = inv[cc[p]]; first[i] = f; }
        free(inv);
    }
    for (i = 0; i < nc; i++) Ac[(size_t)i * nc + i] *= 1.0 + 1e-12;
    dc.Ac = Ac; dc.nc = nc;
    if (sky_factor(&C->S, nc, perm, get_dense, &dc, first) != 0) fprintf(stderr, "coarse Cholesky failed\n");
    C->ma = 2.0 * (double)C->phi_nnz + 2.0 * (double)C->S.nnz;
    free(Ac); free(col); free(y); free(cnt); free(perm); free(first); free(crp); free(cc);
}

static void coarse_trilinear(coarse *C, const snref_model *m) {
    unsigned i, k, dx, dy, dz, nF = m->nF, p;
    int gmax[3] = { 0, 0, 0 };
    int *id;
    unsigned ncn = 0, nx, ny, nz;
    for (i = 0; i < m->nV; i++) for (k = 0; k < 3; k++) if (grid[3 * i + k] > gmax[k]) gmax[k] = grid[3 * i + k];
    nx = gmax[0] / 2 + 2; ny = gmax[1] / 2 + 2; nz = gmax[2] / 2 + 2;
    id = malloc(sizeof(int) * nx * ny * nz);
    for (i = 0; i < nx * ny * nz; i++) id[i] = -1;
    /* coarse nodes touched by free vertices */
    for (i = 0; i < nF; i++) {
        const int *g = grid + 3 * i;
        for (dx = 0; dx < 2; dx++) for (dy = 0; dy < 2; dy++) for (dz = 0; dz < 2; dz++) {
            unsigned cx = g[0] / 2 + dx, cy = g[1] / 2 + dy, cz = g[2] / 2 + dz;
            if ((dx && !(g[0] & 1)) || (dy && !(g[1] & 1)) || (dz && !(g[2] & 1))) continue;
            if (id[(cz * ny + cy) * nx + cx] < 0) id[(cz * ny + cy) * nx + cx] = (int)ncn++;
        }
    }
    C->nc = 3 * ncn;
    C->rp = malloc(sizeof(unsigned) * (3 * nF + 1)); C->ci = malloc(sizeof(unsigned) * 24 * nF); C->w = malloc(sizeof(double) * 24 * nF);
    p = 0;
    for (i = 0; i < nF; i++) {
        const int *g = grid + 3 * i;
        for (k = 0; k < 3; k++) {
            C->rp[3 * i + k] = p;
            for (dx = 0; dx < 2; dx++) for (dy = 0; dy < 2; dy++) for (dz = 0; dz < 2; dz++) {
                unsigned cx = g[0] / 2 + dx, cy = g[1] / 2 + dy, cz = g[2] / 2 + dz;
                if ((dx && !(g[0] & 1)) || (dy && !(g[1] & 1)) || (dz && !(g[2] & 1))) continue;
                C->ci[p] = 3 * (unsigned)id[(cz * ny + cy) * nx + cx] + k;
                C->w[p] = ((g[0] & 1) ? 0.5 : 1.0) * ((g[1] & 1) ? 0.5 : 1.0) * ((g[2] & 1) ? 0.5 : 1.0);
                p++;
            }
        }
    }
    C->rp[3 * nF] = p;
    C->phi_nnz = p;
    free(id);
    coarse_finish(C);
}

static void coarse_aggregate(coarse *C, const snref_model *m) {
    unsigned i, k, nF = m->nF, p, a;
    int gmax[3] = { 0, 0, 0 };
    unsigned nx, ny, nz, na = 0, *agg = malloc(sizeof(unsigned) * nF);
    int *id;
    double *cen, *cnt;
    for (i = 0; i < m->nV; i++) for (k = 0; k < 3; k++) if (grid[3 * i + k] > gmax[k]) gmax[k] = grid[3 * i + k];
    nx = gmax[0] / 2 + 1; ny = gmax[1] / 2 + 1; nz = gmax[2] / 2 + 1;
    id = malloc(sizeof(int) * nx * ny * nz);
    for (i = 0; i < nx * ny * nz; i++) id[i] = -1;
    for (i = 0; i < nF; i++) {
        unsigned c = ((grid[3 * i + 2] / 2) * ny + grid[3 * i + 1] / 2) * nx + grid[3 * i] / 2;
        if (id[c] < 0) id[c] = (int)na++;
        agg[i] = (unsigned)id[c];
    }
    cen = calloc(3 * na, sizeof(double)); cnt = calloc(na, sizeof(double));
    for (i = 0; i < nF; i++) { for (k = 0; k < 3; k++) cen[3 * agg[i] + k] += m->rest[3 * i + k]; cnt[agg[i]] += 1; }
    for (a = 0; a < na; a++) for (k = 0; k < 3; k++) cen[3 * a + k] /= cnt[a];
    C->nc = 6 * na;
    C->rp = malloc(sizeof(unsigned) * (3 * nF + 1)); C->ci = malloc(sizeof(unsigned) * 9 * nF); C->w = malloc(sizeof(double) * 9 * nF);
    p = 0;
    for (i = 0; i < nF; i++) {
        double y[3];
        for (k = 0; k < 3; k++) y[k] = (m->rest[3 * i + k] - cen[3 * agg[i] + k]) / m->cell;
        for (k = 0; k < 3; k++) {
            unsigned r;
            C->rp[3 * i + k] = p;
            C->ci[p] = 6 * agg[i] + k; C->w[p] = 1.0; p++;
            /* rotation about axis r: (e_r x y)_k */
            for (r = 0; r < 3; r++) {
                double e[3] = { 0, 0, 0 }, cr[3];
                e[r] = 1;
                cr[0] = e[1] * y[2] - e[2] * y[1]; cr[1] = e[2] * y[0] - e[0] * y[2]; cr[2] = e[0] * y[1] - e[1] * y[0];
                if (cr[k] != 0 && cnt[agg[i]] >= 3) { C->ci[p] = 6 * agg[i] + 3 + r; C->w[p] = cr[k]; p++; }
            }
        }
    }
    C->rp[3 * nF] = p;
    C->phi_nnz = p;
    /* aggregates too small for rotations: give their rotation unknowns a unit diagonal (no coupling) */
    free(id); free(cen);
    {   /* drop unused coarse columns: renumber */
        unsigned *used = calloc(C->nc, sizeof(unsigned)), nn = 0, c;
        for (i = 0; i < p; i++) used[C->ci[i]] = 1;
        for (c = 0; c < C->nc; c++) used[c] = used[c] ? ++nn : 0;
        for (i = 0; i < p; i++) C->ci[i] = used[C->ci[i]] - 1;
        C->nc = nn;
        free(used);
    }
    free(cnt); free(agg);
    coarse_finish(C);
}

static void coarse_apply_add(const coarse *C, const double *t, double *u, double *wc, double *ws) {
    unsigned i, p;
    memset(wc, 0, C->nc * sizeof(double));
    for (i = 0; i < n3_; i++) for (p = C->rp[i]; p < C->rp[i + 1]; p++) wc[C->ci[p]] += C->w[p] * t[i];
    sky_solve(&C->S, wc, wc, ws);
    for (i = 0; i < n3_; i++) for (p = C->rp[i]; p < C->rp[i + 1]; p++) u[i] += C->w[p] * wc[C->ci[p]];
}

/* ---------------- candidates ---------------- */
enum { P_BJ, P_SGS, P_IC0, P_IC0_AVG, P_BJ_AVG, P_IC0_EDGE, P_IC0_CUR, P_CHOL, P_BJ_CT, P_BJ_CA, P_SGS_CT, P_IC0_CT, P_BJ_CTB, P_IC0_CTB, P_COUNT };
static const char *pname[P_COUNT] = { "BJ (today)", "SGS", "IC0", "IC0, frames = mean of the cells' (per step)", "BJ, frames = mean of the cells' (per step)", "IC0 cell-frame blocks (per step)", "IC0 of the step matrix (per step)", "CHOL (rest, full)", "BJ+CT", "BJ+CA", "SGS+CT", "IC0+CT", "BJ+CT balancing", "IC0+CT balancing" };
static const snref_state *S_;
static double *wt, *wu, *wc, *ws, *wb1, *wb2, *wb3;

static double *Ravg;
/* per free vertex: the mean of its cells' frames, made orthogonal (Newton polar iteration) */
static void frames_avg(const snref_state *s) {
    const snref_model *m = s->m;
    unsigned e, a, i, k, it;
    memset(Ravg, 0, 9 * sizeof(double) * nF_);
    for (e = 0; e < m->nC; e++) for (a = 0; a < 8; a++) { unsigned v = m->cells[8 * e + a]; if (v < nF_) for (k = 0; k < 9; k++) Ravg[9 * v + k] += s->Rc[9 * e + k]; }
    for (i = 0; i < nF_; i++) {
        double *R = Ravg + 9 * i, Ri[9];
        for (it = 0; it < 8; it++) { inv3(R, Ri); for (k = 0; k < 9; k++) R[k] = 0.5 * (R[k] + Ri[3 * (k % 3) + k / 3]); }
    }
}
static void prec_apply(int kind, const double *r, double *z) {
    unsigned i, nF = nF_;
    const double *R = (kind == P_IC0_AVG || kind == P_BJ_AVG) ? Ravg : S_->R;
    if (kind == P_IC0_AVG) kind = P_IC0;
    if (kind == P_BJ_AVG) kind = P_BJ;
    if (kind == P_IC0_EDGE) { lb_solve(r, z); return; }
    if (kind == P_IC0_CUR) { icv = icv_cur; ic0_solve(r, z); icv = icv_rest; return; }
    for (i = 0; i < nF; i++) { /* t = R^T r */
        const double *Ri = R + 9 * i, *ri = r + 3 * i;
        unsigned k;
        for (k = 0; k < 3; k++) wt[3 * i + k] = Ri[k] * ri[0] + Ri[3 + k] * ri[1] + Ri[6 + k] * ri[2];
    }
    switch (kind) {
    case P_BJ: case P_BJ_CT: case P_BJ_CA:
        for (i = 0; i < nF; i++) m3v(M_->precond + 9 * i, wt + 3 * i, wu + 3 * i);
        if (kind == P_BJ_CT) coarse_apply_add(&CT, wt, wu, wc, ws);
        if (kind == P_BJ_CA) coarse_apply_add(&CA, wt, wu, wc, ws);
        break;
    case P_SGS: case P_SGS_CT:
        sgs_solve(wt, wu);
        if (kind == P_SGS_CT) coarse_apply_add(&CT, wt, wu, wc, ws);
        break;
    case P_IC0: case P_IC0_CT:
        ic0_solve(wt, wu);
        if (kind == P_IC0_CT) coarse_apply_add(&CT, wt, wu, wc, ws);
        break;
    case P_CHOL:
        sky_solve(&CH, wt, wu, ws);
        break;
    case P_BJ_CTB: case P_IC0_CTB: { /* u = C t + (I - C A0) B (I - A0 C) t, all in the rest frame */
        unsigned j;
        memset(wb1, 0, n3_ * sizeof(double));
        coarse_apply_add(&CT, wt, wb1, wc, ws);           /* c1 = C t */
        bsr_mul(&A0, wb1, wb2);
        for (j = 0; j < n3_; j++) wb2[j] = wt[j] - wb2[j]; /* t - A0 c1 */
        if (kind == P_BJ_CTB) for (i = 0; i < nF; i++) m3v(M_->precond + 9 * i, wb2 + 3 * i, wu + 3 * i);
        else ic0_solve(wb2, wu);                            /* y = B (t - A0 c1) */
        bsr_mul(&A0, wu, wb2);
        memset(wb3, 0, n3_ * sizeof(double));
        coarse_apply_add(&CT, wb2, wb3, wc, ws);          /* C A0 y */
        for (j = 0; j < n3_; j++) wu[j] += wb1[j] - wb3[j];
        break;
    }
    }
    for (i = 0; i < nF; i++) m3v(R + 9 * i, wu + 3 * i, z + 3 * i);
}

/* PCG from x0; errA[k], errM[k] after k iterations (k = 0..iters). Returns residual of last. */
static double *cr, *cz, *cd, *cq, *cx, *ce, *ctmp;
static void errs(const double *x, const double *xs, double *eA, double *eM) {
    unsigned i;
    double m = 0;
    for (i = 0; i < n3_; i++) ce[i] = x[i] - xs[i];
    bsr_mul(&At, ce, ctmp);
    *eA = sqrt(fmax(0, dotv(ce, ctmp, n3_)));
    for (i = 0; i < nF_; i++) { double d = sqrt(ce[3 * i] * ce[3 * i] + ce[3 * i + 1] * ce[3 * i + 1] + ce[3 * i + 2] * ce[3 * i + 2]); if (d > m) m = d; }
    *eM = m;
}
static void pcg(int kind, const double *b, const double *x0, unsigned iters, double tol, double *xout,
                const double *xs, double *eA, double *eM) {
    unsigned i, it, n = n3_;
    double rz, bn = sqrt(dotv(b, b, n));
    memcpy(cx, x0, n * sizeof(double));
    bsr_mul(&At, cx, cq);
    for (i = 0; i < n; i++) cr[i] = b[i] - cq[i];
    prec_apply(kind, cr, cz);
    memcpy(cd, cz, n * sizeof(double));
    rz = dotv(cr, cz, n);
    if (xs) errs(cx, xs, eA, eM);
    for (it = 0; it < iters; it++) {
        double dq, al, rz1, be;
        if (tol > 0 && sqrt(dotv(cr, cr, n)) <= tol * bn) break;
        bsr_mul(&At, cd, cq);
        dq = dotv(cd, cq, n);
        al = dq > 0 ? rz / dq : 0;
        for (i = 0; i < n; i++) { cx[i] += al * cd[i]; cr[i] -= al * cq[i]; }
        prec_apply(kind, cr, cz);
        rz1 = dotv(cr, cz, n);
        be = rz > 0 ? rz1 / rz : 0;
        for (i = 0; i < n; i++) cd[i] = cz[i] + be * cd[i];
        rz = rz1;
        if (xs) errs(cx, xs, eA + it + 1, eM + it + 1);
    }
    if (xout) memcpy(xout, cx, n * sizeof(double));
}

/* ---------------- sampling ---------------- */
static unsigned every = 2, nsamp, ktab[P_COUNT][MAXS], nskip;
static double contr[P_COUNT], contr_n, relA_bj, relM_bj;
static double *xstar;

static void hook(void *ctx, const snref_state *s, const double *b, const double *x0) {
    unsigned k, p;
    double eA[P_COUNT][MAXIT + 1], eM[P_COUNT][MAXIT + 1], tA, tM, e0;
    unsigned N = s->iters;
    (void)ctx;
    if (s->steps % every || s->steps < 2 || nsamp >= MAXS) return;
    S_ = s;
    bsr_assemble(&At, M_, s->Rc);
    icA = &At; free(icv_cur); ic0_build(); icv_cur = icv; icv = icv_rest; icA = &A0;
    lb_rotate(s);
    frames_avg(s);
    pcg(P_BJ, b, x0, 5000, 1e-13, xstar, NULL, NULL, NULL);
    for (p = 0; p < P_COUNT; p++) pcg((int)p, b, x0, MAXIT, 0, NULL, xstar, eA[p], eM[p]);
    tA = eA[P_BJ][N]; tM = eM[P_BJ][N]; e0 = eA[P_BJ][0];
    {   /* block LDL^T form of the IC0 factor: forward-sweep growth on this step's residual */
        unsigned i, q, kk;
        double *t = malloc(sizeof(double) * n3_), *y = malloc(sizeof(double) * n3_), mt = 0, my = 0;
        bsr_mul(&At, x0, t);
        for (i = 0; i < n3_; i++) t[i] = b[i] - t[i];
        for (i = 0; i < nF_; i++) { double u[3]; const double *Ri = s->R + 9 * i; for (kk = 0; kk < 3; kk++) u[kk] = Ri[kk] * t[3 * i] + Ri[3 + kk] * t[3 * i + 1] + Ri[6 + kk] * t[3 * i + 2]; memcpy(y + 3 * i, u, sizeof u); }
        for (i = 0; i < n3_; i++) if (fabs(y[i]) > mt) mt = fabs(y[i]);
        for (i = 0; i < nF_; i++)
            for (q = lbp[i]; q + 1 < lbp[i + 1]; q++) {
                double tt[3];
                m3v(ldl_L + 9 * (size_t)q, y + 3 * lbc[q], tt);
                for (kk = 0; kk < 3; kk++) y[3 * i + kk] -= tt[kk];
            }
        for (i = 0; i < n3_; i++) if (fabs(y[i]) > my) my = fabs(y[i]);
        if (mt > 0 && my / mt > ldl_grow) ldl_grow = my / mt;
        free(t); free(y);
    }
    if (!(e0 > 0) || tA <= 1e-12 * e0) { nskip++; return; } /* nothing to solve (rest) */
    relA_bj += tA / e0; relM_bj += eM[P_BJ][0] > 0 ? tM / eM[P_BJ][0] : 0;
    for (p = 0; p < P_COUNT; p++) {
        for (k = 0; k <= MAXIT; k++) if (eA[p][k] <= tA * (1 + 1e-9) && eM[p][k] <= tM * (1 + 1e-9)) break;
        ktab[p][nsamp] = k;
        contr[p] += pow(fmax(eA[p][10], 1e-300) / e0, 0.1);
    }
    contr_n += 1;
    nsamp++;
}

static int cmpu(const void *a, const void *b) { unsigned x = *(const unsigned *)a, y = *(const unsigned *)b; return x < y ? -1 : x > y; }

static int hook_kind;
/* The design's fixed-point IC0 emulated in double: forces on the Q19 grid
 * (k_i = 0, the coarsest force format), z on Q22; block LDL^T sweeps rounding
 * each block-row contribution, D^-1 rounded to Q22, rotations exact. */
static double *ldl_Di, *qy, *qw;
static int q_bj;
static double rq(double x, int q) { return ldexp(floor(ldexp(x, q) + 0.5), -q); }
static void ldl_apply_q(const snref_state *s, const double *r, double *z) {
    unsigned i, p, k, a;
    if (!ldl_Di) {
        ldl_Di = malloc(sizeof(double) * 9 * nF_); qy = malloc(sizeof(double) * n3_); qw = malloc(sizeof(double) * n3_);
        for (i = 0; i < nF_; i++) {
            double Li[9];
            inv3(lb + 9 * (size_t)(lbp[i + 1] - 1), Li);
            for (a = 0; a < 3; a++) for (k = 0; k < 3; k++) { double sm = 0; unsigned q; for (q = 0; q < 3; q++) sm += Li[3 * q + a] * Li[3 * q + k]; ldl_Di[9 * i + 3 * a + k] = sm; }
        }
    }
    for (i = 0; i < nF_; i++) { const double *Ri = s->R + 9 * i; for (k = 0; k < 3; k++) qy[3 * i + k] = rq(Ri[k] * r[3 * i] + Ri[3 + k] * r[3 * i + 1] + Ri[6 + k] * r[3 * i + 2], 19); }
    if (q_bj) { /* today's block Jacobi with the same roundings */
        for (i = 0; i < nF_; i++) { double t[3]; m3v(M_->precond + 9 * i, qy + 3 * i, qw + 3 * i); m3v(s->R + 9 * i, qw + 3 * i, t); for (k = 0; k < 3; k++) z[3 * i + k] = rq(rq(t[k], 22), 22); }
        return;
    }
    for (i = 0; i < nF_; i++) {
        for (p = lbp[i]; p + 1 < lbp[i + 1]; p++) { double t[3]; m3v(ldl_L + 9 * (size_t)p, qy + 3 * lbc[p], t); for (k = 0; k < 3; k++) qy[3 * i + k] -= rq(t[k], 19); }
        m3v(ldl_Di + 9 * i, qy + 3 * i, qw + 3 * i);
        for (k = 0; k < 3; k++) qw[3 * i + k] = rq(qw[3 * i + k], 22);
    }
    for (i = nF_; i-- > 0;)
        for (p = lbp[i]; p + 1 < lbp[i + 1]; p++) {
            const double *B = ldl_L + 9 * (size_t)p;
            unsigned j = lbc[p];
            for (a = 0; a < 3; a++) qw[3 * j + a] -= rq(B[a] * qw[3 * i] + B[3 + a] * qw[3 * i + 1] + B[6 + a] * qw[3 * i + 2], 22);
        }
    for (i = 0; i < nF_; i++) { double t[3]; m3v(s->R + 9 * i, qw + 3 * i, t); for (k = 0; k < 3; k++) z[3 * i + k] = rq(t[k], 22); }
}
static void phook(void *ctx, const snref_state *s, const double *r, double *z) {
    (void)ctx; S_ = s;
    if (hook_kind < 0) ldl_apply_q(s, r, z); else prec_apply(hook_kind, r, z);
}
static void phook_q(void *ctx, const snref_state *s, const double *r, double *z) { (void)ctx; q_bj = 0; ldl_apply_q(s, r, z); }
static void phook_qbj(void *ctx, const snref_state *s, const double *r, double *z) { (void)ctx; q_bj = 1; ldl_apply_q(s, r, z); }

int main(int argc, char **argv) {
    pu_rt rt;
    snref_model m;
    snref_state s;
    unsigned i, k, c, nclip = 0, p;
    const char *clips[16];
    double ffMA, setupMA[P_COUNT] = { 0 }, cellMA = 0, massMA, vecMA, matvecMA, pMA[P_COUNT], memB[P_COUNT], rhsMA;
    if (argc < 3) { fprintf(stderr, "usage: precond_study FIXED_BLOB CLIP... [-every K]\n"); return 2; }
    for (i = 2; i < (unsigned)argc; i++) {
        if (!strcmp(argv[i], "-every") && i + 1 < (unsigned)argc) every = (unsigned)atoi(argv[++i]);
        else if (nclip < 16) clips[nclip++] = argv[i];
    }
    if (pu_rt_open(&rt, argv[1]) || pu_ref_open(&m, &s, argv[1])) return 1;
    M_ = &m; nF_ = m.nF; n3_ = 3 * m.nF;
    /* lattice coordinates */
    grid = malloc(sizeof(int) * 3 * m.nV);
    {
        double mn[3] = { 1e300, 1e300, 1e300 };
        for (i = 0; i < m.nV; i++) for (k = 0; k < 3; k++) if (m.rest[3 * i + k] < mn[k]) mn[k] = m.rest[3 * i + k];
        for (i = 0; i < m.nV; i++) for (k = 0; k < 3; k++) {
            double g = (m.rest[3 * i + k] - mn[k]) / m.cell;
            grid[3 * i + k] = (int)floor(g + 0.5);
            if (fabs(g - grid[3 * i + k]) > 1e-3) { fprintf(stderr, "vertex %u not on the lattice (%g)\n", i, g); return 1; }
        }
    }
    bsr_pattern(&A0, &m); bsr_pattern(&At, &m);
    bsr_assemble(&A0, &m, NULL);
    /* check At (identity frames) against the reference's own products */
    {
        double *x = malloc(sizeof(double) * 3 * m.nV), *y1 = malloc(sizeof(double) * n3_), *y2 = malloc(sizeof(double) * n3_), *y3 = malloc(sizeof(double) * n3_), d = 0, nn = 0;
        for (i = 0; i < 3 * m.nV; i++) x[i] = i < n3_ ? sin(1.0 + i) : 0;
        bsr_mul(&A0, x, y1);
        snref_hess_mul(&s, x, y2); snref_mass_mul(&s, x, y3);
        for (i = 0; i < n3_; i++) { double t = (1 + m.b1) * y2[i] + (1 + m.a1) * y3[i]; d = fmax(d, fabs(t - y1[i])); nn = fmax(nn, fabs(t)); }
        if (d > 1e-10 * nn) { fprintf(stderr, "assembled A0 differs from the reference: %g of %g\n", d, nn); return 1; }
        free(x); free(y1); free(y2); free(y3);
    }
    /* factorizations */
    Dinv = malloc(sizeof(double) * 9 * nF_);
    for (i = 0; i < nF_; i++) inv3(A0.v + 9 * (size_t)A0.map[i * nF_ + i], Dinv + 9 * i);
    ic_flops = 0; ic0_build(); icv_rest = icv; ic_fl_rest = ic_flops;
    lb_build(&m);
    ldl_build();
    {
        unsigned *vperm = malloc(sizeof(unsigned) * nF_), *sperm = malloc(sizeof(unsigned) * n3_), *first = malloc(sizeof(unsigned) * n3_);
        rcm_order(nF_, A0.rp, A0.ci, vperm);
        sky_from_vertex_order(nF_, vperm, A0.rp, A0.ci, sperm, first);
        if (sky_factor(&CH, n3_, sperm, get_A0, &A0, first)) { fprintf(stderr, "A0 Cholesky failed\n"); return 1; }
        free(vperm); free(sperm); free(first);
    }
    coarse_trilinear(&CT, &m);
    coarse_aggregate(&CA, &m);
    Ravg = malloc(sizeof(double) * 9 * nF_);
    wb1 = malloc(sizeof(double) * n3_); wb2 = malloc(sizeof(double) * n3_); wb3 = malloc(sizeof(double) * n3_);
    wt = malloc(sizeof(double) * n3_); wu = malloc(sizeof(double) * n3_);
    wc = malloc(sizeof(double) * (n3_ + 6 * nF_)); ws = malloc(sizeof(double) * (n3_ + 6 * nF_));
    cr = malloc(sizeof(double) * n3_); cz = malloc(sizeof(double) * n3_); cd = malloc(sizeof(double) * n3_);
    cq = malloc(sizeof(double) * n3_); cx = malloc(sizeof(double) * n3_); ce = malloc(sizeof(double) * n3_);
    ctmp = malloc(sizeof(double) * n3_); xstar = malloc(sizeof(double) * n3_);

    /* the runtime's costs (multiply-adds), sn_solve.c */
    for (i = 0; i < m.nC; i++) { unsigned fc = 0; for (k = 0; k < 8; k++) fc += m.cells[8 * i + k] < nF_; cellMA += 576 + 18.0 * fc; }
    {
        unsigned nff = 0, nfs = 0;
        for (i = 0; i < nF_; i++) for (k = m.rowptr[i]; k < m.rowptr[i + 1]; k++) { if (m.cols[k] < nF_) nff++; else nfs++; }
        massMA = 3.0 * nF_ + 6.0 * nff;
        rhsMA = 2 * cellMA + m.nC * (8 * 18.0 + 24) + massMA + 3.0 * nfs + 30.0 * nF_;
    }
    matvecMA = cellMA + massMA + 6.0 * nF_;
    vecMA = 15.0 * nF_;
    {
        size_t offb = A0.rp[nF_] - nF_; /* off-diagonal blocks, both triangles */
        pMA[P_BJ] = 27.0 * nF_; memB[P_BJ] = 24.0 * nF_;
        pMA[P_SGS] = 18.0 * nF_ + 9.0 * offb + 18.0 * nF_; memB[P_SGS] = 4.0 * (9 * offb / 2 + 9.0 * nF_) + 2.0 * offb / 2;
        pMA[P_IC0] = 18.0 * nF_ + 2.0 * ic_nnz; memB[P_IC0] = 4.0 * ic_nnz + 2.0 * offb / 2;
        pMA[P_IC0_AVG] = pMA[P_IC0]; memB[P_IC0_AVG] = memB[P_IC0]; setupMA[P_IC0_AVG] = 0;
        pMA[P_BJ_AVG] = pMA[P_BJ]; memB[P_BJ_AVG] = memB[P_BJ];
        for (i = 0; i < m.nC; i++) for (k = 0; k < 8; k++) if (m.cells[8 * i + k] < nF_) { setupMA[P_IC0_AVG] += 4; } /* quaternion sums */
        setupMA[P_IC0_AVG] += 40.0 * nF_; setupMA[P_BJ_AVG] = setupMA[P_IC0_AVG]; /* normalise, to a matrix */
        pMA[P_IC0_EDGE] = pMA[P_IC0] - 18.0 * nF_; memB[P_IC0_EDGE] = memB[P_IC0];
        setupMA[P_IC0_EDGE] = 54.0 * lbp[nF_];   /* the factor's blocks rotated once per step (and held in the instance) */
        setupMA[P_IC0_CUR] = 54.0 * 36 * m.nC + ic_fl_rest + 2.0 * ic_nnz; /* assemble R S R^T, factor */
        pMA[P_IC0_CUR] = 2.0 * ic_nnz; memB[P_IC0_CUR] = 4.0 * ic_nnz;
        pMA[P_CHOL] = 18.0 * nF_ + 2.0 * CH.nnz; memB[P_CHOL] = 4.0 * CH.nnz + 4.0 * n3_;
        pMA[P_BJ_CT] = pMA[P_BJ] + CT.ma; memB[P_BJ_CT] = memB[P_BJ] + 4.0 * CT.S.nnz + 4.0 * CT.nc;
        pMA[P_BJ_CA] = pMA[P_BJ] + CA.ma; memB[P_BJ_CA] = memB[P_BJ] + 4.0 * CA.S.nnz + 4.0 * CA.nc + 4.0 * CA.phi_nnz;
        pMA[P_SGS_CT] = pMA[P_SGS] + CT.ma; memB[P_SGS_CT] = memB[P_SGS] + 4.0 * CT.S.nnz + 4.0 * CT.nc;
        pMA[P_BJ_CTB] = pMA[P_BJ] + 2 * CT.ma + 18.0 * (offb + nF_); memB[P_BJ_CTB] = memB[P_BJ_CT] + 4.0 * (9 * offb / 2 + 6.0 * nF_) + 2.0 * offb / 2;
        pMA[P_IC0_CTB] = pMA[P_IC0] + 2 * CT.ma + 18.0 * (offb + nF_); memB[P_IC0_CTB] = memB[P_IC0] + 4.0 * CT.S.nnz + 4.0 * CT.nc + 4.0 * (9 * offb / 2 + 6.0 * nF_);
        pMA[P_IC0_CT] = pMA[P_IC0] + CT.ma; memB[P_IC0_CT] = memB[P_IC0] + 4.0 * CT.S.nnz + 4.0 * CT.nc;
    }

    s.solve_hook = hook;
    {
        snref_state *one[1];
        one[0] = &s;
        if (pu_drive_clips(&rt, &m, clips, nclip, one, 1, NULL)) return 1;
    }
    printf("%s: nF %u, nC %u, blob N = %u block-Jacobi iterations; %u steps sampled (every %u; %u at rest skipped), clips:",
           argv[1], nF_, m.nC, m.cg_default, nsamp, every, nskip);
    for (c = 0; c < nclip; c++) printf(" %s", clips[c]);
    printf("\n  today's N iterations leave ||e||_A %.3g and max|e| %.3g of the warm start's (mean); coarse: trilinear %u unknowns, aggregates %u\n",
           relA_bj / nsamp, relM_bj / nsamp, CT.nc, CA.nc);
    {
        double ff = 0;
        ffMA = 0;
        for (i = 0; i < m.nC; i++) { unsigned fc = 0; for (k = 0; k < 8; k++) fc += m.cells[8 * i + k] < nF_; ff += 9.0 * fc * fc + 18.0 * fc; }
        printf("  the cell products over free corners only (the mat-vec's operand is 0 at skeleton corners and their rows are dropped): %.0f MA instead of %.0f\n", ff, cellMA);
        ffMA = ff + massMA + 6.0 * nF_;
    }
    printf("  MA = multiply-adds; mat-vec %.0f MA, vector ops %.0f MA per iteration, right-hand side ~%.0f MA\n", matvecMA, vecMA, rhsMA);
    printf("| preconditioner | iters worst | p90 | median | A-err contraction/iter | precond MA | iteration MA | per-step setup MA | solve MA/step (worst iters) | step MA | solve MA/step, free-corner mat-vec | precond bytes (int32) |\n");
    printf("|---|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (p = 0; p < P_COUNT; p++) {
        unsigned srt[MAXS], kw;
        double iterMA = matvecMA + vecMA + pMA[p], solve;
        memcpy(srt, ktab[p], nsamp * sizeof(unsigned));
        qsort(srt, nsamp, sizeof(unsigned), cmpu);
        kw = srt[nsamp - 1];
        solve = setupMA[p] + matvecMA + pMA[p] + 3.0 * nF_ + kw * iterMA;
        printf("| %s | %s%u | %u | %u | %.3f | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f |\n", pname[p], kw > MAXIT ? ">" : "", kw > MAXIT ? MAXIT : kw,
               srt[(nsamp * 9) / 10], srt[nsamp / 2], contr[p] / contr_n, pMA[p], iterMA, setupMA[p], solve, solve + rhsMA, solve - (kw + 1) * (matvecMA - ffMA), memB[p]);
    }
    printf("  IC0 as block LDL^T (unit lower L^ = L_ij L_jj^-1, D^-1 blocks): max |L^ entry| %.3g; forward sweep (I+L^)^-1 on the steps' residuals grows max|.| by at most %.3g\n",
           ldl_lmax, ldl_grow);
    if (nsamp) {   /* whole runs: exact solves, today's N BJ iterations, IC0 at 1..worst-case count */
        snref_state ex, bj, bjq, ic[16], icq[16], *st[35];
        double er[36];
        unsigned srt[MAXS], kw, j, ns;
        memcpy(srt, ktab[P_IC0], nsamp * sizeof(unsigned));
        qsort(srt, nsamp, sizeof(unsigned), cmpu);
        kw = srt[nsamp - 1] > 16 ? 16 : srt[nsamp - 1];
        snref_init(&ex, &m); snref_init(&bj, &m);
        ex.exact = 1;
        st[0] = &ex; st[1] = &bj; ns = 2;
        for (j = 0; j < kw; j++) { snref_init(&ic[j], &m); ic[j].precond_hook = phook; ic[j].iters = j + 1; st[ns++] = &ic[j]; }
        for (j = 0; j < kw; j++) { snref_init(&icq[j], &m); icq[j].precond_hook = phook_q; icq[j].iters = j + 1; st[ns++] = &icq[j]; }
        snref_init(&bjq, &m); bjq.precond_hook = phook_qbj; st[ns++] = &bjq;
        hook_kind = P_IC0;
        if (pu_drive_clips(&rt, &m, clips, nclip, st, ns, er) == 0) {
            printf("  whole clips, max surface error against exact solves / max elastic displacement (%.4g mesh units): BJ %u it. %.3e; IC0",
                   er[ns], m.cg_default, er[1] / er[ns]);
            for (j = 0; j < kw; j++) printf(" %u it. %.3e%s", j + 1, er[2 + j] / er[ns], j + 1 < kw ? "," : "\n");
            printf("  the same with fixed-point rounding in the preconditioner only (forces Q19 = k_i 0, the coarsest; z Q22): BJ %u it. %.3e; IC0 (LDL^T sweeps):",
                   m.cg_default, er[2 + 2 * kw] / er[ns]);
            for (j = 0; j < kw; j++) printf(" %u it. %.3e%s", j + 1, er[2 + kw + j] / er[ns], j + 1 < kw ? "," : "\n");
            for (j = 0; j < kw && er[2 + j] > er[1]; j++) {}
            if (j < kw) {
                double kk = j + 1, sIC = matvecMA + pMA[P_IC0] + 3.0 * nF_ + kk * (matvecMA + vecMA + pMA[P_IC0]);
                double sBJ = matvecMA + pMA[P_BJ] + 3.0 * nF_ + m.cg_default * (matvecMA + vecMA + pMA[P_BJ]);
                printf("  => IC0 matches today's whole-clip accuracy with %u iterations: solve %.0f MA/step (BJ %u: %.0f); with the free-corner mat-vec %.0f (BJ: %.0f)\n",
                       j + 1, sIC, m.cg_default, sBJ, sIC - (kk + 1) * (matvecMA - ffMA), sBJ - (m.cg_default + 1.0) * (matvecMA - ffMA));
            }
        }
        snref_release(&ex); snref_release(&bj);
        for (j = 0; j < kw; j++) { snref_release(&ic[j]); snref_release(&icq[j]); }
        snref_release(&bjq);
    }
    if (nsamp) {
        double nb = A0.rp[nF_], asm_mv = 9.0 * nb + 6.0 * nF_, its;
        double tot;
        unsigned srt[MAXS];
        memcpy(srt, ktab[P_IC0_CUR], nsamp * sizeof(unsigned));
        qsort(srt, nsamp, sizeof(unsigned), cmpu);
        its = srt[nsamp - 1];
        tot = setupMA[P_IC0_CUR] + (its + 1) * (asm_mv + pMA[P_IC0_CUR]) + its * vecMA + 3.0 * nF_;
        printf("  assembled step matrix: %.0f blocks (both triangles), a mat-vec over it %.0f MA (the cell-by-cell one: %.0f MA); "
               "assembled per step + IC0 of it + %g iterations on it: solve %.0f MA/step, instance +%.0f bytes (upper blocks + factor, int32)\n",
               nb, asm_mv, matvecMA, its, tot, 4.0 * (9.0 * (nb + nF_) / 2) + 4.0 * ic_nnz);
        printf("  assembled per step (%.0f MA) + today's %u block-Jacobi iterations on it: solve %.0f MA/step, instance +%.0f bytes\n",
               54.0 * 36 * m.nC, m.cg_default, 54.0 * 36 * m.nC + (m.cg_default + 1) * (asm_mv + pMA[P_BJ]) + m.cg_default * vecMA + 3.0 * nF_,
               4.0 * (9.0 * (nb + nF_) / 2));
    }
    pu_rt_close(&rt);
    return 0;
}
