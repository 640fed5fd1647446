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

const char *sn_kernels_name(void) { return "m4"; }

#else
typedef int sn_kernels_m4_unused_; /* ISO C: no empty translation unit */
#endif
