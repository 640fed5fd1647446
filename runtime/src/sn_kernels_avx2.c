/* sn_kernels_avx2.c -- x86-64 AVX2 (and AVX-512VL: the same code, EVEX
 * encoded) kernels of sn_kernels.h, fixed flavour.
 *
 * cell_mul: one 3x3 block as 4 int64 lanes (the 4th unused) per column or
 * row: two overlapping unaligned loads (B0..B7, B1..B8), VPERMD puts a
 * column or row in the even int32 slots, VPMULDQ multiplies the signed low
 * halves exactly into int64 lanes (the odd slots are ignored), VPADDQ
 * accumulates. Block (a,b): L_a += B col_c * u_b[c], L_b += B row_r * u_a[r]
 * (that is B^T u_a). Same integer sums as the scalar reference in another
 * order: exact, bounded (sn_kernels.h, NUMERICS.md "SIMD kernels"). */
#include "sn_kernels.h"

#if defined(SN_KERNELS_AVX2)
#include <immintrin.h>

#define LD(p) _mm256_loadu_si256((const __m256i *)(const void *)(p))
#define MUL(v, idx, s) _mm256_mul_epi32(_mm256_permutevar8x32_epi32((v), (idx)), (s))

void sn_k_cell_mul(const unsigned char *K, const sn_q u[24], sn_acc l[24]) {
    /* the 4th lane of each index vector reads B0 (a harmless product, never stored) */
    const __m256i ic0 = _mm256_setr_epi32(0, 0, 3, 0, 6, 0, 0, 0); /* col 0 from B0..B7 */
    const __m256i ic1 = _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0); /* col 1 from B0..B7, col 2 from B1..B8 */
    const __m256i ir0 = _mm256_setr_epi32(0, 0, 1, 0, 2, 0, 0, 0); /* row 0 from B0..B7 */
    const __m256i ir1 = _mm256_setr_epi32(3, 0, 4, 0, 5, 0, 0, 0); /* row 1 from B0..B7 */
    const __m256i ir2 = _mm256_setr_epi32(5, 0, 6, 0, 7, 0, 0, 0); /* row 2 from B1..B8 */
    __m256i L[8];
    int a, b;
    for (a = 0; a < 8; a++) L[a] = _mm256_setzero_si256();
    for (a = 0; a < 8; a++) {
        const __m256i ua0 = _mm256_set1_epi32(u[3 * a]), ua1 = _mm256_set1_epi32(u[3 * a + 1]);
        const __m256i ua2 = _mm256_set1_epi32(u[3 * a + 2]);
        __m256i v0 = LD(K), v1 = LD(K + 4), la;
        /* diagonal block (a,a), stored in full: L_a += B u_a */
        la = _mm256_add_epi64(L[a], _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ic0, ua0), MUL(v0, ic1, ua1)),
                                                      MUL(v1, ic1, ua2)));
        K += 9 * 4;
        for (b = a + 1; b < 8; b++, K += 9 * 4) {
            const __m256i ub0 = _mm256_set1_epi32(u[3 * b]), ub1 = _mm256_set1_epi32(u[3 * b + 1]);
            const __m256i ub2 = _mm256_set1_epi32(u[3 * b + 2]);
            v0 = LD(K);
            v1 = LD(K + 4);
            la = _mm256_add_epi64(la, _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ic0, ub0), MUL(v0, ic1, ub1)),
                                                        MUL(v1, ic1, ub2)));
            L[b] = _mm256_add_epi64(L[b], _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ir0, ua0), MUL(v0, ir1, ua1)),
                                                            MUL(v1, ir2, ua2)));
        }
        L[a] = la;
    }
    for (a = 0; a < 8; a++) {
        int64_t t[4];
        _mm256_storeu_si256((__m256i *)(void *)t, L[a]);
        l[3 * a] = t[0];
        l[3 * a + 1] = t[1];
        l[3 * a + 2] = t[2];
        SN_RANGE(SN_WITHIN(t[0], 60) && SN_WITHIN(t[1], 60) && SN_WITHIN(t[2], 60),
                 "cell row beyond 24 * 2^55", t[0]);
    }
}

#if defined(__AVX512F__) && defined(__AVX512VL__)
const char *sn_kernels_name(void) { return "avx512"; }
#else
const char *sn_kernels_name(void) { return "avx2"; }
#endif

#else
typedef int sn_kernels_avx2_unused_; /* ISO C: no empty translation unit */
#endif
