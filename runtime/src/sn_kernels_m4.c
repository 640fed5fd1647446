/* sn_kernels_m4.c -- Cortex-M4/M7 (ARMv7E-M, DSP extension) kernels of
 * sn_kernels.h, fixed flavour. Plain C written so the compiler keeps the
 * accumulators in registers and emits one SMLAL per multiply-add
 * (RdLo:RdHi += Rn * Rm, exact 64-bit) with word loads of the block:
 *   pass 1, row a:    L_a   += B_ab u_b  for b >= a   (rows of the blocks)
 *   pass 2, column b: L_b   += B_ab^T u_a for a < b   (the transposed blocks)
 * Each pass holds three 64-bit sums (6 registers), the three operands and
 * one block entry: no accumulator is loaded or stored inside a row.
 * The same exact products as the scalar reference, summed in another order
 * (sn_kernels.h, NUMERICS.md "SIMD kernels"). Blob reals are read as
 * native int32: ARMv7E-M is little-endian here and allows unaligned LDR. */
#include "sn_kernels.h"

#if defined(SN_KERNELS_M4)

#if !SN_HOST_LE
#error "sn_kernels_m4.c reads blob reals as native int32: little-endian only (build with SIMD=scalar)"
#endif

#define BLK(a, b) SN_K_BLK(a, b)

/* Listed corners (the mat-vec's free corners): the same two passes in C,
 * the compiler's SMLAL with word loads; blocks (a, fc[j]) of a row are not
 * contiguous any more. */
static void cell_mul_list(const int32_t *S, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    uint32_t i, j;
    /* pass 1: L_i = sum_{j >= i} B(a_i, a_j) u_j */
    for (i = 0; i < nf; i++) {
        const uint32_t a = fc[i];
        int64_t s0 = 0, s1 = 0, s2 = 0;
        for (j = i; j < nf; j++) {
            const int32_t *B = S + BLK(a, fc[j]);
            const int32_t x = u[3 * j], y = u[3 * j + 1], z = u[3 * j + 2];
            s0 += (int64_t)B[0] * x;
            s0 += (int64_t)B[1] * y;
            s0 += (int64_t)B[2] * z;
            s1 += (int64_t)B[3] * x;
            s1 += (int64_t)B[4] * y;
            s1 += (int64_t)B[5] * z;
            s2 += (int64_t)B[6] * x;
            s2 += (int64_t)B[7] * y;
            s2 += (int64_t)B[8] * z;
        }
        l[3 * i] = s0;
        l[3 * i + 1] = s1;
        l[3 * i + 2] = s2;
    }
    /* pass 2: L_j += sum_{i < j} B(a_i, a_j)^T u_i */
    for (j = 1; j < nf; j++) {
        const uint32_t b = fc[j];
        int64_t s0 = l[3 * j], s1 = l[3 * j + 1], s2 = l[3 * j + 2];
        for (i = 0; i < j; i++) {
            const int32_t *B = S + BLK(fc[i], b);
            const int32_t x = u[3 * i], y = u[3 * i + 1], z = u[3 * i + 2];
            s0 += (int64_t)B[0] * x;
            s1 += (int64_t)B[1] * x;
            s2 += (int64_t)B[2] * x;
            s0 += (int64_t)B[3] * y;
            s1 += (int64_t)B[4] * y;
            s2 += (int64_t)B[5] * y;
            s0 += (int64_t)B[6] * z;
            s1 += (int64_t)B[7] * z;
            s2 += (int64_t)B[8] * z;
        }
        l[3 * j] = s0;
        l[3 * j + 1] = s1;
        l[3 * j + 2] = s2;
    }
}

#if defined(__OPTIMIZE__)
/* Optimized builds: the two passes as small Thumb-2 assembly loops, LDM for
 * block rows and corner vectors (ascending fixed registers r4-r6 / r8-r10),
 * one SMLAL per multiply-add, the six 32-bit halves of three int64 sums in
 * registers the compiler picks. The block counter lives in memory (all 14
 * allocatable registers are taken otherwise). -O0 keeps r7 as the frame
 * pointer and cannot give the asm its registers: the C loops below. */
SN_INLINE int64_t join64(int32_t hi, uint32_t lo) { return (int64_t)hi * 4294967296LL + (int64_t)lo; }

/* all 8 corners: every row's blocks contiguous */
static void cell_mul_full(const unsigned char *K, const sn_q u[24], sn_acc l[24]) {
    const int32_t *S = (const int32_t *)(const void *)K;
    int a, b;
    /* pass 1: L_a = sum_{b >= a} B_ab u_b; the blocks of row a are contiguous.
     * Per block: LDM u_b, 3 x (LDM one block row, 3 SMLAL), counter: 17 instructions / 9 MACs */
    for (a = 0; a < 8; a++) {
        const int32_t *B = S + BLK(a, a), *v = u + 3 * a;
        uint32_t l0 = 0, l1 = 0, l2 = 0;
        int32_t h0 = 0, h1 = 0, h2 = 0;
        int32_t n = 8 - a;
        __asm__ volatile(
            "1:\n\t"
            "ldmia %[v]!, {r8, r9, r10}\n\t"
            "ldmia %[B]!, {r4, r5, r6}\n\t"
            "smlal %[l0], %[h0], r4, r8\n\t"
            "smlal %[l0], %[h0], r5, r9\n\t"
            "smlal %[l0], %[h0], r6, r10\n\t"
            "ldmia %[B]!, {r4, r5, r6}\n\t"
            "smlal %[l1], %[h1], r4, r8\n\t"
            "smlal %[l1], %[h1], r5, r9\n\t"
            "smlal %[l1], %[h1], r6, r10\n\t"
            "ldmia %[B]!, {r4, r5, r6}\n\t"
            "smlal %[l2], %[h2], r4, r8\n\t"
            "smlal %[l2], %[h2], r5, r9\n\t"
            "smlal %[l2], %[h2], r6, r10\n\t"
            "ldr r4, %[n]\n\t"
            "subs r4, r4, #1\n\t"
            "str r4, %[n]\n\t"
            "bne 1b\n\t"
            : [l0] "+r"(l0), [h0] "+r"(h0), [l1] "+r"(l1), [h1] "+r"(h1), [l2] "+r"(l2), [h2] "+r"(h2),
              [B] "+r"(B), [v] "+r"(v), [n] "+m"(n)
            :
            : "r4", "r5", "r6", "r8", "r9", "r10", "cc", "memory");
        l[3 * a] = join64(h0, l0);
        l[3 * a + 1] = join64(h1, l1);
        l[3 * a + 2] = join64(h2, l2);
    }
    /* pass 2: L_b += sum_{a < b} B_ab^T u_a: per block 3 x (LDR u_a[r], LDM block row r,
     * 3 SMLAL), then on to block (a+1,b), 9 (6-a) words further: 21 instructions / 9 MACs */
    for (b = 1; b < 8; b++) {
        const int32_t *B = S + BLK(0, b), *v = u;
        uint32_t l0 = 0, l1 = 0, l2 = 0;
        int32_t h0 = 0, h1 = 0, h2 = 0;
        int32_t n = b, st = 36 * 6;
        __asm__ volatile(
            "1:\n\t"
            "ldr r8, [%[v]], #4\n\t"
            "ldmia %[B]!, {r4, r5, r6}\n\t"
            "smlal %[l0], %[h0], r4, r8\n\t"
            "smlal %[l1], %[h1], r5, r8\n\t"
            "smlal %[l2], %[h2], r6, r8\n\t"
            "ldr r8, [%[v]], #4\n\t"
            "ldmia %[B]!, {r4, r5, r6}\n\t"
            "smlal %[l0], %[h0], r4, r8\n\t"
            "smlal %[l1], %[h1], r5, r8\n\t"
            "smlal %[l2], %[h2], r6, r8\n\t"
            "ldr r8, [%[v]], #4\n\t"
            "ldmia %[B]!, {r4, r5, r6}\n\t"
            "smlal %[l0], %[h0], r4, r8\n\t"
            "smlal %[l1], %[h1], r5, r8\n\t"
            "smlal %[l2], %[h2], r6, r8\n\t"
            "add %[B], %[B], %[st]\n\t"
            "sub %[st], %[st], #36\n\t"
            "ldr r4, %[n]\n\t"
            "subs r4, r4, #1\n\t"
            "str r4, %[n]\n\t"
            "bne 1b\n\t"
            : [l0] "+r"(l0), [h0] "+r"(h0), [l1] "+r"(l1), [h1] "+r"(h1), [l2] "+r"(l2), [h2] "+r"(h2),
              [B] "+r"(B), [v] "+r"(v), [st] "+r"(st), [n] "+m"(n)
            :
            : "r4", "r5", "r6", "r8", "cc", "memory");
        l[3 * b] += join64(h0, l0);
        l[3 * b + 1] += join64(h1, l1);
        l[3 * b + 2] += join64(h2, l2);
    }
}

#endif /* __OPTIMIZE__ */

void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    uint32_t i;
#if defined(__OPTIMIZE__)
    if (nf == 8) cell_mul_full(K, u, l);
    else
#endif
        cell_mul_list((const int32_t *)(const void *)K, fc, nf, u, l);
    for (i = 0; i < 3 * nf; i++) SN_RANGE(SN_WITHIN(l[i], 60), "cell row beyond 24 * 2^55", l[i]);
}


const char *sn_kernels_name(void) { return "m4"; }

#else
typedef int sn_kernels_m4_unused_; /* ISO C: no empty translation unit */
#endif
