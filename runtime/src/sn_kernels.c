/* sn_kernels.c -- portable scalar reference of the kernels in sn_kernels.h
 * (the float flavour and every target without a SIMD/DSP path). The
 * per-ISA files must give the same integers (fixed flavour). */
#include "sn_kernels.h"
#include "sn_instance.h"

#if defined(SN_KERNELS_SCALAR)

/* block (a,b), a <= b, as 9 entries (float: the stored reals; fixed: sn_k_blk) */
SN_INLINE void blk_get(const unsigned char *K, uint32_t a, uint32_t b, sn_q B[9]) {
#if defined(SN_FLOAT)
    const unsigned char *p = K + (size_t)SN_K_BLK(a, b) * RB;
    uint32_t k;
    for (k = 0; k < 9; k++) B[k] = rd_real(p, k);
#else
    sn_k_blk(K, a, b, B);
#endif
}
/* Overflow freedom without clamps (fixed): entries |e| <= 2^27 (validator),
 * operands |x| <= 2^28 (every sn_q is clamped), so one block row is < 3*2^55. */
SN_INLINE void blk_row(sn_acc l[3], const sn_q B[9], const sn_q e[3]) {
    l[0] += sn_mul(B[0], e[0]) + sn_mul(B[1], e[1]) + sn_mul(B[2], e[2]);
    l[1] += sn_mul(B[3], e[0]) + sn_mul(B[4], e[1]) + sn_mul(B[5], e[2]);
    l[2] += sn_mul(B[6], e[0]) + sn_mul(B[7], e[1]) + sn_mul(B[8], e[2]);
}
/* acc += B^T e (scatter of the transposed block) */
SN_INLINE void blk_mac_t(sn_acc acc[3], const sn_q B[9], const sn_q e[3]) {
    acc[0] += sn_mul(B[0], e[0]) + sn_mul(B[3], e[1]) + sn_mul(B[6], e[2]);
    acc[1] += sn_mul(B[1], e[0]) + sn_mul(B[4], e[1]) + sn_mul(B[7], e[2]);
    acc[2] += sn_mul(B[2], e[0]) + sn_mul(B[5], e[1]) + sn_mul(B[8], e[2]);
}

/* The order of the partial sums is the full product's (rows ascending;
 * corner b's row takes the transposed blocks of the rows above it, then its
 * own row), so the float flavour's bits do not depend on the list. */
void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    uint32_t i, j;
    sn_q B[9];
    for (i = 0; i < 3 * nf; i++) l[i] = 0;
    for (i = 0; i < nf; i++) {
        uint32_t a = fc[i];
        blk_get(K, a, a, B);
        blk_row(l + 3 * i, B, u + 3 * i); /* diagonal block (a,a) */
        for (j = i + 1; j < nf; j++) {
            blk_get(K, a, fc[j], B);
            blk_row(l + 3 * i, B, u + 3 * j);
            blk_mac_t(l + 3 * j, B, u + 3 * i);
        }
    }
    for (i = 0; i < 3 * nf; i++) SN_RANGE(SN_WITHIN(l[i], 60), "cell row beyond 24 * 2^55", l[i]);
}

const char *sn_kernels_name(void) { return "scalar"; }
#endif /* SN_KERNELS_SCALAR */

#if !defined(SN_FLOAT) && !defined(SN_KERNELS_AVX2) && !defined(SN_KERNELS_NEON)
/* The bound uses the OR of the magnitudes (same bit length as their
 * maximum, no compares). */
int64_t sn_k_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n, int *e) {
    uint32_t i, k, oa = 0, ob = 0, nv = n / 3;
    int s;
    int64_t sum = 0;
    for (i = 0; i < n; i++) {
        oa |= a[i] < 0 ? (uint32_t)-(int64_t)a[i] : (uint32_t)a[i];
        ob |= b[i] < 0 ? (uint32_t)-(int64_t)b[i] : (uint32_t)b[i];
    }
    /* n * max|a| * max|b| < 2^62 after shifting each product right by s */
    s = bitlen64(oa) + bitlen64(ob) + bitlen64(n) - 62;
    s = s < 0 ? 0 : s;
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
