/* sn_kernels.c -- portable scalar reference of the kernels in sn_kernels.h
 * (every target without a SIMD/DSP path, both flavours). The per-ISA files
 * must give the same integers (fixed flavour) or the same floats (float:
 * sn_kernels_fsimd.c). */
#include "sn_kernels.h"
#include "sn_instance.h"

/* Block (a,b), a <= b: float, a pointer to its 9 stored reals; fixed, the 9
 * decoded int32 entries (sn_k_blk). ENT(B, k) reads entry k. */
#if defined(SN_FLOAT)
typedef const unsigned char *blk_t;
#define BLK_GET(K, a, b, B) ((B) = (K) + (size_t)SN_K_BLK(a, b) * RB)
#define ENT(B, k) rd_real(B, k)
#else
typedef sn_q blk_t[9];
#define BLK_GET(K, a, b, B) sn_k_blk(K, a, b, B)
#define ENT(B, k) ((B)[k])
#endif
/* Overflow freedom without clamps (fixed): entries |e| <= 2^27 (validator),
 * operands |x| <= 2^28 (every sn_q is clamped), so one block row is < 3*2^55. */
#define BLK_ROW(l, B, e) do { \
    (l)[0] += sn_mul(ENT(B, 0), (e)[0]) + sn_mul(ENT(B, 1), (e)[1]) + sn_mul(ENT(B, 2), (e)[2]); \
    (l)[1] += sn_mul(ENT(B, 3), (e)[0]) + sn_mul(ENT(B, 4), (e)[1]) + sn_mul(ENT(B, 5), (e)[2]); \
    (l)[2] += sn_mul(ENT(B, 6), (e)[0]) + sn_mul(ENT(B, 7), (e)[1]) + sn_mul(ENT(B, 8), (e)[2]); \
} while (0)
/* acc += B^T e (scatter of the transposed block) */
#define BLK_MAC_T(acc, B, e) do { \
    (acc)[0] += sn_mul(ENT(B, 0), (e)[0]) + sn_mul(ENT(B, 3), (e)[1]) + sn_mul(ENT(B, 6), (e)[2]); \
    (acc)[1] += sn_mul(ENT(B, 1), (e)[0]) + sn_mul(ENT(B, 4), (e)[1]) + sn_mul(ENT(B, 7), (e)[2]); \
    (acc)[2] += sn_mul(ENT(B, 2), (e)[0]) + sn_mul(ENT(B, 5), (e)[1]) + sn_mul(ENT(B, 8), (e)[2]); \
} while (0)

#if defined(SN_KERNELS_SCALAR)
/* The order of the partial sums is the full product's (rows ascending;
 * corner b's row takes the transposed blocks of the rows above it, then its
 * own row), so the float flavour's bits do not depend on the list. */
void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    uint32_t i, j;
    blk_t B;
    for (i = 0; i < 3 * nf; i++) l[i] = 0;
    for (i = 0; i < nf; i++) {
        uint32_t a = fc[i];
        BLK_GET(K, a, a, B);
        BLK_ROW(l + 3 * i, B, u + 3 * i); /* diagonal block (a,a) */
        for (j = i + 1; j < nf; j++) {
            BLK_GET(K, a, fc[j], B);
            BLK_ROW(l + 3 * i, B, u + 3 * j);
            BLK_MAC_T(l + 3 * j, B, u + 3 * i);
        }
    }
    for (i = 0; i < 3 * nf; i++) SN_RANGE(SN_WITHIN(l[i], 60), "cell row beyond 24 * 2^55", l[i]);
}

const char *sn_kernels_name(void) { return "scalar"; }
#endif /* SN_KERNELS_SCALAR */

#if defined(SN_KERNELS_SCALAR)
/* First writes of BLK_ROW / BLK_MAC_T into an output: (sn_acc)0 + the
 * block term, the value the += had from a zeroed output (float: the same
 * sum, signed zeros included; fixed: the term), so the outputs need no
 * zeroing pass (the Cortex-M4's newlib-nano memset is a byte loop). */
#define BLK_ROW0(l, B, e) do { \
    (l)[0] = (sn_acc)0 + (sn_mul(ENT(B, 0), (e)[0]) + sn_mul(ENT(B, 1), (e)[1]) + sn_mul(ENT(B, 2), (e)[2])); \
    (l)[1] = (sn_acc)0 + (sn_mul(ENT(B, 3), (e)[0]) + sn_mul(ENT(B, 4), (e)[1]) + sn_mul(ENT(B, 5), (e)[2])); \
    (l)[2] = (sn_acc)0 + (sn_mul(ENT(B, 6), (e)[0]) + sn_mul(ENT(B, 7), (e)[1]) + sn_mul(ENT(B, 8), (e)[2])); \
} while (0)
#define BLK_MAC_T0(acc, B, e) do { \
    (acc)[0] = (sn_acc)0 + (sn_mul(ENT(B, 0), (e)[0]) + sn_mul(ENT(B, 3), (e)[1]) + sn_mul(ENT(B, 6), (e)[2])); \
    (acc)[1] = (sn_acc)0 + (sn_mul(ENT(B, 1), (e)[0]) + sn_mul(ENT(B, 4), (e)[1]) + sn_mul(ENT(B, 7), (e)[2])); \
    (acc)[2] = (sn_acc)0 + (sn_mul(ENT(B, 2), (e)[0]) + sn_mul(ENT(B, 5), (e)[1]) + sn_mul(ENT(B, 8), (e)[2])); \
} while (0)
/* Both right-hand-side products, one decode per block; each output's
 * partial sums in sn_k_cell_mul's order (the M4's is sn_kernels_m4.c's).
 * Row 0: corner 0's operands are 0 (sn_kernels.h), so its diagonal block
 * and the transposed uses of its blocks add exact zeros (float: +-0 to a
 * +0 partial sum, which stays +0): only B u_b into row 0. So row 0's first
 * term is block (0,1)'s, row 1's its diagonal block's, row b > 1's the
 * transposed block (1,b)'s: those are first writes (BLK_ROW0, BLK_MAC_T0).
 * l2's rows outside rows2 (skeleton corners) are skipped, not written. */
void sn_k_cell_mul2(const unsigned char *K, const sn_q u1[24], const sn_q u2[24], sn_acc l1[24], sn_acc l2[24],
                    uint32_t rows2) {
    uint32_t a, b;
    blk_t B;
    BLK_GET(K, 0, 1, B);
    BLK_ROW0(l1, B, u1 + 3);
    if (rows2 & 1u) BLK_ROW0(l2, B, u2 + 3);
    for (b = 2; b < 8; b++) {
        BLK_GET(K, 0, b, B);
        BLK_ROW(l1, B, u1 + 3 * b);
        if (rows2 & 1u) BLK_ROW(l2, B, u2 + 3 * b);
    }
    {   /* row 1: the first write of every row b > 1 */
        const uint32_t ra = rows2 >> 1 & 1u;
        BLK_GET(K, 1, 1, B);
        BLK_ROW0(l1 + 3, B, u1 + 3);
        if (ra) BLK_ROW0(l2 + 3, B, u2 + 3);
        for (b = 2; b < 8; b++) {
            BLK_GET(K, 1, b, B);
            BLK_ROW(l1 + 3, B, u1 + 3 * b);
            BLK_MAC_T0(l1 + 3 * b, B, u1 + 3);
            if (ra) BLK_ROW(l2 + 3, B, u2 + 3 * b);
            if (rows2 >> b & 1u) BLK_MAC_T0(l2 + 3 * b, B, u2 + 3);
        }
    }
    for (a = 2; a < 8; a++) {
        const uint32_t ra = rows2 >> a & 1u;
        BLK_GET(K, a, a, B);
        BLK_ROW(l1 + 3 * a, B, u1 + 3 * a);
        if (ra) BLK_ROW(l2 + 3 * a, B, u2 + 3 * a);
        for (b = a + 1; b < 8; b++) {
            BLK_GET(K, a, b, B);
            BLK_ROW(l1 + 3 * a, B, u1 + 3 * b);
            BLK_MAC_T(l1 + 3 * b, B, u1 + 3 * a);
            if (ra) BLK_ROW(l2 + 3 * a, B, u2 + 3 * b);
            if (rows2 >> b & 1u) BLK_MAC_T(l2 + 3 * b, B, u2 + 3 * a);
        }
    }
    for (a = 0; a < 24; a++)
        SN_RANGE(SN_WITHIN(l1[a], 60) && (!(rows2 >> (a / 3) & 1u) || SN_WITHIN(l2[a], 60)), "cell row beyond 24 * 2^55",
                 l1[a]);
}
#endif

#if !defined(SN_FLOAT) && !defined(SN_KERNELS_AVX2) && !defined(SN_KERNELS_NEON) && !defined(SN_KERNELS_M4)
/* The scale: sn_k_dot_scale (sn_kernels.h). */
int64_t sn_k_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n, int *e) {
    uint32_t i, k, nv = n / 3;
    const int s = sn_k_dot_scale(a, b, 0, n, 0, 0);
    int64_t sum = 0;
    for (i = 0; i < nv; i++) {
        int sh = s + kk[i];
        int64_t half = sh > 0 ? (int64_t)1 << (sh - 1) : 0;
        for (k = 3 * i; k < 3 * i + 3; k++) sum += ((int64_t)a[k] * b[k] + half) >> sh;
    }
    *e = s;
    return sum;
}
#endif

typedef int sn_kernels_c_unused_; /* ISO C: never an empty translation unit */
