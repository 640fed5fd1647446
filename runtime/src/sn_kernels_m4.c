/* sn_kernels_m4.c -- Cortex-M4/M7 (ARMv7E-M, DSP extension) kernels of
 * sn_kernels.h, fixed flavour. Plain C written so the compiler keeps the
 * row accumulators in registers and emits one SMLAL per multiply-add
 * (RdLo:RdHi += Rn * Rm, exact 64-bit). Each block is decoded once
 * (LDRSH of the int16 mantissa, LSL by its exponent; the diagonal's int32)
 * and used both ways: row a's three sums stay in registers for the whole
 * row, the transposed block's three go to corner b's sums in memory.
 * The same exact products as the scalar reference, summed in another order
 * (sn_kernels.h, NUMERICS.md "SIMD kernels"). */
#include "sn_kernels.h"
#include "sn_instance.h" /* bitlen64 */

#if defined(SN_KERNELS_M4)

void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    uint32_t i, j;
    for (i = 0; i < 3 * nf; i++) l[i] = 0;
    for (i = 0; i < nf; i++) {
        const uint32_t a = fc[i];
        const int32_t ax = u[3 * i], ay = u[3 * i + 1], az = u[3 * i + 2];
        const unsigned char *d = K + SN_CELLK_DIAG + 24u * a;
        const int32_t dxx = sn_rd_i32(d), dyy = sn_rd_i32(d + 4), dzz = sn_rd_i32(d + 8);
        const int32_t dxy = sn_rd_i32(d + 12), dxz = sn_rd_i32(d + 16), dyz = sn_rd_i32(d + 20);
        /* diagonal block (a,a), symmetric */
        int64_t s0 = l[3 * i] + (int64_t)dxx * ax + (int64_t)dxy * ay + (int64_t)dxz * az;
        int64_t s1 = l[3 * i + 1] + (int64_t)dxy * ax + (int64_t)dyy * ay + (int64_t)dyz * az;
        int64_t s2 = l[3 * i + 2] + (int64_t)dxz * ax + (int64_t)dyz * ay + (int64_t)dzz * az;
        for (j = i + 1; j < nf; j++) {
            const uint32_t o = SN_CELLK_OFFIDX(a, fc[j]);
            const unsigned char *m = K + SN_CELLK_OFF + 18u * o;
            const int32_t sc = (int32_t)1 << K[SN_CELLK_EXP + o];
            const int32_t bx = u[3 * j], by = u[3 * j + 1], bz = u[3 * j + 2];
            sn_acc *lb = l + 3 * j;
            int32_t B0 = sn_k_rd_i16(m) * sc, B1 = sn_k_rd_i16(m + 2) * sc, B2 = sn_k_rd_i16(m + 4) * sc;
            int64_t t0 = lb[0], t1 = lb[1], t2 = lb[2];
            s0 += (int64_t)B0 * bx;
            s0 += (int64_t)B1 * by;
            s0 += (int64_t)B2 * bz;
            t0 += (int64_t)B0 * ax;
            t1 += (int64_t)B1 * ax;
            t2 += (int64_t)B2 * ax;
            B0 = sn_k_rd_i16(m + 6) * sc;
            B1 = sn_k_rd_i16(m + 8) * sc;
            B2 = sn_k_rd_i16(m + 10) * sc;
            s1 += (int64_t)B0 * bx;
            s1 += (int64_t)B1 * by;
            s1 += (int64_t)B2 * bz;
            t0 += (int64_t)B0 * ay;
            t1 += (int64_t)B1 * ay;
            t2 += (int64_t)B2 * ay;
            B0 = sn_k_rd_i16(m + 12) * sc;
            B1 = sn_k_rd_i16(m + 14) * sc;
            B2 = sn_k_rd_i16(m + 16) * sc;
            s2 += (int64_t)B0 * bx;
            s2 += (int64_t)B1 * by;
            s2 += (int64_t)B2 * bz;
            lb[0] = t0 + (int64_t)B0 * az;
            lb[1] = t1 + (int64_t)B1 * az;
            lb[2] = t2 + (int64_t)B2 * az;
        }
        l[3 * i] = s0;
        l[3 * i + 1] = s1;
        l[3 * i + 2] = s2;
    }
    for (i = 0; i < 3 * nf; i++) SN_RANGE(SN_WITHIN(l[i], 60), "cell row beyond 24 * 2^55", l[i]);
}

/* The CG dot product (sn_kernels.c's reference): each product rounded alone,
 * (a b + 2^(sh-1)) >> sh. Here the rounding term is the SMLAL's starting
 * value and, for 0 < sh < 32 (sh = s + k_i, shared by a vertex's 3 terms),
 * the shift is done on the two words: the same rounded terms (sn_rshr64_var's
 * identity), summed in the same order. */
int64_t sn_k_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n, int *e) {
    uint32_t i, k, oa = 0, ob = 0, nv = n / 3;
    int s;
    int64_t sum = 0;
    for (i = 0; i < n; i++) {
        oa |= a[i] < 0 ? (uint32_t)-(int64_t)a[i] : (uint32_t)a[i];
        ob |= b[i] < 0 ? (uint32_t)-(int64_t)b[i] : (uint32_t)b[i];
    }
    s = bitlen64(oa) + bitlen64(ob) + bitlen64(n) - 62;
    s = s < 0 ? 0 : s;
    for (i = 0; i < nv; i++) {
        const int sh = s + kk[i];
        if (sh > 0 && sh < 32) {
            const int64_t bias = (int64_t)((uint32_t)1 << (sh - 1));
            const int r = 32 - sh;
            const sn_q *ai = a + 3 * i, *bi = b + 3 * i;
            /* written out: GCC kept a loop of 3 (15 instructions a term) */
#define SN_DOT_T(k)                                                                                       \
    do {                                                                                                  \
        const int64_t p = bias + (int64_t)ai[k] * bi[k];                                                  \
        const uint32_t lo = (uint32_t)p;                                                                  \
        const int32_t hi = (int32_t)(p >> 32);                                                            \
        sum += (int64_t)(hi >> sh) * ((int64_t)1 << 32) + (int64_t)((lo >> sh) | ((uint32_t)hi << r));   \
    } while (0)
            SN_DOT_T(0);
            SN_DOT_T(1);
            SN_DOT_T(2);
#undef SN_DOT_T
        } else {
            const int64_t half = sh > 0 ? (int64_t)1 << (sh - 1) : 0;
            for (k = 3 * i; k < 3 * i + 3; k++) sum += ((int64_t)a[k] * b[k] + half) >> sh;
        }
    }
    *e = s;
    return sum;
}

/* The CG vector updates (sn_kernels.h's reference, sn_mulq then sn_add per
 * value): for 0 < sh < 32 the product starts from the rounding term and is
 * shifted on the two words, the test hoisted out of the loop (inside
 * sn_out it cost the solve +6%); the same clamps and counts. */
void sn_k_axpy(sn_q *out, const sn_q *a, sn_q s, const sn_q *x, uint32_t n, int sh, uint32_t *sat) {
    uint32_t i;
    if (sh > 0 && sh < 32) {
        const int64_t bias = (int64_t)((uint32_t)1 << (sh - 1));
        const int r = 32 - sh;
        for (i = 0; i < n; i++) {
            const int64_t p = bias + (int64_t)s * x[i];
            const uint32_t lo = (uint32_t)p;
            const int32_t hi = (int32_t)(p >> 32);
            const int64_t v = (int64_t)(hi >> sh) * ((int64_t)1 << 32) + (int64_t)((lo >> sh) | ((uint32_t)hi << r));
            sn_q q;
            if (v > SN_LIM) { (*sat)++; q = SN_LIM; }
            else if (v < -SN_LIM) { (*sat)++; q = -SN_LIM; }
            else q = (int32_t)v;
            out[i] = sn_add(a[i], q, sat);
        }
    } else {
        for (i = 0; i < n; i++) out[i] = sn_add(a[i], sn_mulq(s, x[i], sh, sat), sat);
    }
}

const char *sn_kernels_name(void) { return "m4"; }

#else
typedef int sn_kernels_m4_unused_; /* ISO C: no empty translation unit */
#endif
