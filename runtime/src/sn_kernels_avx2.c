/* sn_kernels_avx2.c -- x86-64 AVX2 (and AVX-512VL: the same code, EVEX
 * encoded, but for the cell products' zmm forms below) kernels of
 * sn_kernels.h, fixed flavour.
 *
 * cell_mul: one 3x3 block as 4 int64 lanes (the 4th unused) per column or
 * row: the block decoded into two int32 vectors (B0..B7, B1..B8; blk_ld), VPERMD puts a
 * column or row in the even int32 slots, VPMULDQ multiplies the signed low
 * halves exactly into int64 lanes (the odd slots are ignored), VPADDQ
 * accumulates. Block (a,b): L_a += B col_c * u_b[c], L_b += B row_r * u_a[r]
 * (that is B^T u_a). Same integer sums as the scalar reference in another
 * order: exact, bounded (sn_kernels.h, KERNELS.md "SIMD kernels"). */
#include "sn_kernels.h"
#include "sn_instance.h" /* bitlen64 */
#include "sn_kernels_ic.h" /* sn_k_ic_rtab */

#if defined(SN_KERNELS_AVX2)
#include <immintrin.h>

#define LD(p) _mm256_loadu_si256((const __m256i *)(const void *)(p))
#define MUL(v, idx, s) _mm256_mul_epi32(_mm256_permutevar8x32_epi32((v), (idx)), (s))

/* Block (a,b), a <= b, of a fixed CELLK record (sn_format.h) as int32 lanes
 * v0 = B0..B7 and v1 = B1..B8, the entries of sn_k_blk: a diagonal block
 * from its 6 symmetric int32 (one load of 8: the 2 past them are the next
 * block's or the first mantissas, inside the record), an off-diagonal one as
 * VPMOVSXWD of 8 mantissas and the 9th, shifted left by e (m 2^e < 2^27:
 * exact in int32). */
SN_INLINE void blk_ld(const unsigned char *K, uint32_t a, uint32_t b, __m256i *v0, __m256i *v1) {
    if (a == b) {
        const __m256i d = LD(K + SN_CELLK_DIAG + 24u * a); /* xx yy zz xy xz yz . . */
        *v0 = _mm256_permutevar8x32_epi32(d, _mm256_setr_epi32(0, 3, 4, 3, 1, 5, 4, 5));
        *v1 = _mm256_permutevar8x32_epi32(d, _mm256_setr_epi32(3, 4, 3, 1, 5, 4, 5, 2));
    } else {
        const uint32_t o = SN_CELLK_OFFIDX(a, b);
        const unsigned char *p = K + SN_CELLK_OFF + 18u * o;
        const int e = K[SN_CELLK_EXP + o];
        const __m256i m = _mm256_sll_epi32(_mm256_cvtepi16_epi32(_mm_loadu_si128((const __m128i *)(const void *)p)),
                                           _mm_cvtsi32_si128(e));
        const int32_t b8 = sn_k_rd_i16(p + 16) * ((int32_t)1 << e);
        *v0 = m;
        *v1 = _mm256_blend_epi32(_mm256_permutevar8x32_epi32(m, _mm256_setr_epi32(1, 2, 3, 4, 5, 6, 7, 7)),
                                 _mm256_set1_epi32(b8), 0x80);
    }
}

#if defined(__AVX512F__) && defined(__AVX512VL__)
/* AVX-512: 8 int64 lanes hold two 3-vectors (the 4th lane of each half
 * unused). cell_mul: a block's two terms side by side, [B u_b | B^T u_a]
 * (one VPERMD puts column c in the low half and row c in the high half;
 * the operand [u_b[c] | u_a[c]] by one merge-masked broadcast); cell_mul2:
 * the two products side by side, [l1 row | l2 row], operands [u1_b[c] |
 * u2_b[c]] built once per cell. Exact int64 sums, any order (above). */
#define Z_IDX(a, b, c, d, e, f) _mm512_setr_epi32(a, 0, b, 0, c, 0, a, 0, d, 0, e, 0, f, 0, d, 0)
#define Z_PERM(v, idx) _mm512_permutexvar_epi32((idx), _mm512_castsi256_si512(v))
#define Z_MAC3(p0, p1, p2, x0, x1, x2) \
    _mm512_add_epi64(_mm512_add_epi64(_mm512_mul_epi32((p0), (x0)), _mm512_mul_epi32((p1), (x1))), _mm512_mul_epi32((p2), (x2)))
SN_INLINE void st3x2(sn_acc *lo, sn_acc *hi, __m512i v) { /* lanes 0..2 -> lo, 4..6 -> hi */
    int64_t t[8];
    _mm512_storeu_si512((void *)t, v);
    lo[0] = t[0]; lo[1] = t[1]; lo[2] = t[2];
    hi[0] = t[4]; hi[1] = t[5]; hi[2] = t[6];
    SN_RANGE(SN_WITHIN(t[0], 60) && SN_WITHIN(t[1], 60) && SN_WITHIN(t[2], 60), "cell row beyond 24 * 2^55", t[0]);
}

void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    const __m256i ic0 = _mm256_setr_epi32(0, 0, 3, 0, 6, 0, 0, 0), ic1 = _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0);
    const __m512i z0 = Z_IDX(0, 3, 6, 0, 1, 2); /* v0: column 0 | row 0 */
    const __m512i z1 = Z_IDX(1, 4, 7, 3, 4, 5); /* v0: column 1 | row 1 */
    const __m512i z2 = Z_IDX(1, 4, 7, 5, 6, 7); /* v1: column 2 | row 2 */
    __m256i L[8];
    uint32_t i, j;
    for (i = 0; i < nf; i++) L[i] = _mm256_setzero_si256();
    for (i = 0; i < nf; i++) {
        const uint32_t a = fc[i];
        const __m512i wa0 = _mm512_set1_epi32(u[3 * i]), wa1 = _mm512_set1_epi32(u[3 * i + 1]);
        const __m512i wa2 = _mm512_set1_epi32(u[3 * i + 2]);
        __m256i v0, v1, la;
        blk_ld(K, a, a, &v0, &v1);
        la = _mm256_add_epi64(L[i], _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ic0, _mm512_castsi512_si256(wa0)),
                                                                      MUL(v0, ic1, _mm512_castsi512_si256(wa1))),
                                                     MUL(v1, ic1, _mm512_castsi512_si256(wa2))));
        for (j = i + 1; j < nf; j++) {
            __m512i t;
            blk_ld(K, a, fc[j], &v0, &v1);
            t = Z_MAC3(Z_PERM(v0, z0), Z_PERM(v0, z1), Z_PERM(v1, z2), _mm512_mask_set1_epi32(wa0, 0x00FF, u[3 * j]),
                       _mm512_mask_set1_epi32(wa1, 0x00FF, u[3 * j + 1]), _mm512_mask_set1_epi32(wa2, 0x00FF, u[3 * j + 2]));
            la = _mm256_add_epi64(la, _mm512_castsi512_si256(t));
            L[j] = _mm256_add_epi64(L[j], _mm512_extracti64x4_epi64(t, 1));
        }
        L[i] = la;
    }
    for (i = 0; i < nf; i++) {
        int64_t t[4];
        _mm256_storeu_si256((__m256i *)(void *)t, L[i]);
        l[3 * i] = t[0];
        l[3 * i + 1] = t[1];
        l[3 * i + 2] = t[2];
        SN_RANGE(SN_WITHIN(t[0], 60) && SN_WITHIN(t[1], 60) && SN_WITHIN(t[2], 60), "cell row beyond 24 * 2^55", t[0]);
    }
}

/* l2 at every row (rows outside rows2 unspecified: exact sums, unread) */
void sn_k_cell_mul2(const unsigned char *K, const sn_q u1[24], const sn_q u2[24], sn_acc l1[24], sn_acc l2[24],
                    uint32_t rows2) {
    const __m512i c0 = Z_IDX(0, 3, 6, 0, 3, 6), c1 = Z_IDX(1, 4, 7, 1, 4, 7); /* c1 also column 2 of v1 */
    const __m512i r0 = Z_IDX(0, 1, 2, 0, 1, 2), r1 = Z_IDX(3, 4, 5, 3, 4, 5), r2 = Z_IDX(5, 6, 7, 5, 6, 7);
    __m512i L[8], W[24];
    uint32_t a, b;
    (void)rows2;
    for (a = 3; a < 24; a++) W[a] = _mm512_mask_set1_epi32(_mm512_set1_epi32(u1[a]), 0xFF00, u2[a]); /* corner 0's unread */
    for (a = 0; a < 8; a++) L[a] = _mm512_setzero_si512();
    for (a = 0; a < 8; a++) {
        __m512i la = L[a];
        __m256i v0, v1;
        if (a) { /* the diagonal block (a,a); corner 0's is a product with 0 */
            blk_ld(K, a, a, &v0, &v1);
            la = _mm512_add_epi64(la, Z_MAC3(Z_PERM(v0, c0), Z_PERM(v0, c1), Z_PERM(v1, c1), W[3 * a], W[3 * a + 1], W[3 * a + 2]));
        }
        for (b = a + 1; b < 8; b++) {
            blk_ld(K, a, b, &v0, &v1);
            la = _mm512_add_epi64(la, Z_MAC3(Z_PERM(v0, c0), Z_PERM(v0, c1), Z_PERM(v1, c1), W[3 * b], W[3 * b + 1], W[3 * b + 2]));
            if (a) /* B^T u_0 = 0 */
                L[b] = _mm512_add_epi64(L[b], Z_MAC3(Z_PERM(v0, r0), Z_PERM(v0, r1), Z_PERM(v1, r2), W[3 * a], W[3 * a + 1],
                                                     W[3 * a + 2]));
        }
        L[a] = la;
    }
    for (a = 0; a < 8; a++) st3x2(l1 + 3 * a, l2 + 3 * a, L[a]);
}
#undef Z_IDX
#undef Z_PERM
#undef Z_MAC3

#else
void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    /* the 4th lane of each index vector reads B0 (a harmless product, never stored) */
    const __m256i ic0 = _mm256_setr_epi32(0, 0, 3, 0, 6, 0, 0, 0); /* col 0 from B0..B7 */
    const __m256i ic1 = _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0); /* col 1 from B0..B7, col 2 from B1..B8 */
    const __m256i ir0 = _mm256_setr_epi32(0, 0, 1, 0, 2, 0, 0, 0); /* row 0 from B0..B7 */
    const __m256i ir1 = _mm256_setr_epi32(3, 0, 4, 0, 5, 0, 0, 0); /* row 1 from B0..B7 */
    const __m256i ir2 = _mm256_setr_epi32(5, 0, 6, 0, 7, 0, 0, 0); /* row 2 from B1..B8 */
    __m256i L[8];
    uint32_t i, j;
    for (i = 0; i < nf; i++) L[i] = _mm256_setzero_si256();
    for (i = 0; i < nf; i++) {
        const uint32_t a = fc[i];
        const __m256i ua0 = _mm256_set1_epi32(u[3 * i]), ua1 = _mm256_set1_epi32(u[3 * i + 1]);
        const __m256i ua2 = _mm256_set1_epi32(u[3 * i + 2]);
        __m256i v0, v1, la;
        blk_ld(K, a, a, &v0, &v1);
        /* diagonal block (a,a): L_a += B u_a */
        la = _mm256_add_epi64(L[i], _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ic0, ua0), MUL(v0, ic1, ua1)),
                                                      MUL(v1, ic1, ua2)));
        for (j = i + 1; j < nf; j++) {
            const __m256i ub0 = _mm256_set1_epi32(u[3 * j]), ub1 = _mm256_set1_epi32(u[3 * j + 1]);
            const __m256i ub2 = _mm256_set1_epi32(u[3 * j + 2]);
            blk_ld(K, a, fc[j], &v0, &v1);
            la = _mm256_add_epi64(la, _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ic0, ub0), MUL(v0, ic1, ub1)),
                                                        MUL(v1, ic1, ub2)));
            L[j] = _mm256_add_epi64(L[j], _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ir0, ua0), MUL(v0, ir1, ua1)),
                                                            MUL(v1, ir2, ua2)));
        }
        L[i] = la;
    }
    for (i = 0; i < nf; i++) {
        int64_t t[4];
        _mm256_storeu_si256((__m256i *)(void *)t, L[i]);
        l[3 * i] = t[0];
        l[3 * i + 1] = t[1];
        l[3 * i + 2] = t[2];
        SN_RANGE(SN_WITHIN(t[0], 60) && SN_WITHIN(t[1], 60) && SN_WITHIN(t[2], 60),
                 "cell row beyond 24 * 2^55", t[0]);
    }
}

/* the right-hand side's two products, each block loaded once: row 0 takes
 * B u_b only (corner 0's operands are 0, sn_kernels.h), l1 every row, l2
 * the rows in rows2 (the others are left unspecified: their sums are
 * skipped). Exact int64 sums, the same integers as two sn_k_cell_mul calls. */
void sn_k_cell_mul2(const unsigned char *K, const sn_q u1[24], const sn_q u2[24], sn_acc l1[24], sn_acc l2[24],
                    uint32_t rows2) {
    const __m256i ic0 = _mm256_setr_epi32(0, 0, 3, 0, 6, 0, 0, 0), ic1 = _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0);
    const __m256i ir0 = _mm256_setr_epi32(0, 0, 1, 0, 2, 0, 0, 0), ir1 = _mm256_setr_epi32(3, 0, 4, 0, 5, 0, 0, 0);
    const __m256i ir2 = _mm256_setr_epi32(5, 0, 6, 0, 7, 0, 0, 0);
    __m256i L1[8], L2[8];
    uint32_t a, b;
    for (a = 0; a < 8; a++) L1[a] = L2[a] = _mm256_setzero_si256();
    for (a = 0; a < 8; a++) {
        const uint32_t ra = rows2 >> a & 1u;
        const __m256i xa0 = _mm256_set1_epi32(u1[3 * a]), xa1 = _mm256_set1_epi32(u1[3 * a + 1]);
        const __m256i xa2 = _mm256_set1_epi32(u1[3 * a + 2]);
        const __m256i ya0 = _mm256_set1_epi32(u2[3 * a]), ya1 = _mm256_set1_epi32(u2[3 * a + 1]);
        const __m256i ya2 = _mm256_set1_epi32(u2[3 * a + 2]);
        __m256i v0, v1, c0, c1, c2, la1 = L1[a], la2 = L2[a];
        if (a) { /* the diagonal block (a,a); corner 0's is a product with 0 */
            blk_ld(K, a, a, &v0, &v1);
            c0 = _mm256_permutevar8x32_epi32(v0, ic0);
            c1 = _mm256_permutevar8x32_epi32(v0, ic1);
            c2 = _mm256_permutevar8x32_epi32(v1, ic1);
            la1 = _mm256_add_epi64(la1, _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(c0, xa0), _mm256_mul_epi32(c1, xa1)),
                                                         _mm256_mul_epi32(c2, xa2)));
            if (ra)
                la2 = _mm256_add_epi64(la2, _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(c0, ya0), _mm256_mul_epi32(c1, ya1)),
                                                             _mm256_mul_epi32(c2, ya2)));
        }
        for (b = a + 1; b < 8; b++) {
            const uint32_t rb = rows2 >> b & 1u;
            blk_ld(K, a, b, &v0, &v1);
            c0 = _mm256_permutevar8x32_epi32(v0, ic0);
            c1 = _mm256_permutevar8x32_epi32(v0, ic1);
            c2 = _mm256_permutevar8x32_epi32(v1, ic1);
            la1 = _mm256_add_epi64(la1, _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(c0, _mm256_set1_epi32(u1[3 * b])),
                                                                          _mm256_mul_epi32(c1, _mm256_set1_epi32(u1[3 * b + 1]))),
                                                         _mm256_mul_epi32(c2, _mm256_set1_epi32(u1[3 * b + 2]))));
            if (ra)
                la2 = _mm256_add_epi64(la2, _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(c0, _mm256_set1_epi32(u2[3 * b])),
                                                                              _mm256_mul_epi32(c1, _mm256_set1_epi32(u2[3 * b + 1]))),
                                                             _mm256_mul_epi32(c2, _mm256_set1_epi32(u2[3 * b + 2]))));
            if (!a) continue; /* B^T u_0 = 0 */
            L1[b] = _mm256_add_epi64(L1[b], _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ir0, xa0), MUL(v0, ir1, xa1)),
                                                             MUL(v1, ir2, xa2)));
            if (rb)
                L2[b] = _mm256_add_epi64(L2[b], _mm256_add_epi64(_mm256_add_epi64(MUL(v0, ir0, ya0), MUL(v0, ir1, ya1)),
                                                                 MUL(v1, ir2, ya2)));
        }
        L1[a] = la1;
        L2[a] = la2;
    }
    for (a = 0; a < 8; a++) {
        int64_t t[4], w[4];
        _mm256_storeu_si256((__m256i *)(void *)t, L1[a]);
        _mm256_storeu_si256((__m256i *)(void *)w, L2[a]);
        l1[3 * a] = t[0];
        l1[3 * a + 1] = t[1];
        l1[3 * a + 2] = t[2];
        l2[3 * a] = w[0];
        l2[3 * a + 1] = w[1];
        l2[3 * a + 2] = w[2];
        SN_RANGE(SN_WITHIN(t[0], 60) && SN_WITHIN(t[1], 60) && SN_WITHIN(t[2], 60), "cell row beyond 24 * 2^55", t[0]);
    }
}

#endif

/* Block-floating dot product: magnitudes ORed 8 lanes at a time (VPABSD of
 * a clamped int32 has the bits of the scalar's uint32 magnitude); then 4
 * vertices = 12 products per iteration in three 4-lane groups, each lane
 * shifted by s + k of its vertex: round half up (VPSLLVQ by sh-1 = -1 gives
 * 0 for sh = 0), arithmetic shift as x ^ m >> sh ^ m. */
SN_INLINE __m256i rshr4(__m256i x, __m256i sh) {
    const __m256i one = _mm256_set1_epi64x(1);
    __m256i y = _mm256_add_epi64(x, _mm256_sllv_epi64(one, _mm256_sub_epi64(sh, one)));
    __m256i m = _mm256_cmpgt_epi64(_mm256_setzero_si256(), y);
    return _mm256_xor_si256(_mm256_srlv_epi64(_mm256_xor_si256(y, m), sh), m);
}
#define LD4(p) _mm256_cvtepi32_epi64(_mm_loadu_si128((const __m128i *)(const void *)(p)))

int64_t sn_k_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n, int *e) {
    uint32_t i, k, oa = 0, ob = 0, nv = n / 3, t[8];
    int s;
    int64_t sum = 0, lanes[4];
    __m256i va = _mm256_setzero_si256(), vb = _mm256_setzero_si256(), acc = _mm256_setzero_si256();
    for (i = 0; i + 8 <= n; i += 8) {
        va = _mm256_or_si256(va, _mm256_abs_epi32(_mm256_loadu_si256((const __m256i *)(const void *)(a + i))));
        vb = _mm256_or_si256(vb, _mm256_abs_epi32(_mm256_loadu_si256((const __m256i *)(const void *)(b + i))));
    }
    _mm256_storeu_si256((__m256i *)(void *)t, va);
    for (k = 0; k < 8; k++) oa |= t[k];
    _mm256_storeu_si256((__m256i *)(void *)t, vb);
    for (k = 0; k < 8; k++) ob |= t[k];
    s = sn_k_dot_scale(a, b, i, n, oa, ob);
    {
        const __m256i vs = _mm256_set1_epi64x(s);
        for (i = 0; i + 4 <= nv; i += 4) {
            const sn_q *pa = a + 3 * i, *pb = b + 3 * i;
            uint32_t k4;
            __m256i kv, s0, s1, s2;
            memcpy(&k4, kk + i, 4);
            kv = _mm256_add_epi64(_mm256_cvtepu8_epi64(_mm_cvtsi32_si128((int)k4)), vs);
            s0 = _mm256_permute4x64_epi64(kv, 0x40); /* k0 k0 k0 k1 */
            s1 = _mm256_permute4x64_epi64(kv, 0xA5); /* k1 k1 k2 k2 */
            s2 = _mm256_permute4x64_epi64(kv, 0xFE); /* k2 k3 k3 k3 */
            acc = _mm256_add_epi64(acc, rshr4(_mm256_mul_epi32(LD4(pa), LD4(pb)), s0));
            acc = _mm256_add_epi64(acc, rshr4(_mm256_mul_epi32(LD4(pa + 4), LD4(pb + 4)), s1));
            acc = _mm256_add_epi64(acc, rshr4(_mm256_mul_epi32(LD4(pa + 8), LD4(pb + 8)), s2));
        }
    }
    _mm256_storeu_si256((__m256i *)(void *)lanes, acc);
    sum = lanes[0] + lanes[1] + lanes[2] + lanes[3];
    for (; i < nv; i++) {
        int sh = s + kk[i];
        int64_t half = sh > 0 ? (int64_t)1 << (sh - 1) : 0;
        for (k = 3 * i; k < 3 * i + 3; k++) sum += ((int64_t)a[k] * b[k] + half) >> sh;
    }
    *e = s;
    return sum;
}

/* CG updates, 4 values per iteration: the product s x_i exact (VPMULDQ),
 * rounded by sh with the bias trick of sn_kernels_ic.h (|s x| <= 2^59:
 * s x + 2^(sh-1) + 2^62 is in [0, 2^63), its logical shift minus 2^62 >> sh
 * is sn_rshr64's value), clamped and counted as sn_out, added to a_i in
 * int64, clamped and counted again (sn_add); the tail in scalar. */
SN_INLINE __m256i clamp4(__m256i q, uint32_t *c) {
    const __m256i lim = _mm256_set1_epi64x(SN_LIM), nlim = _mm256_set1_epi64x(-(int64_t)SN_LIM);
    const __m256i hi = _mm256_cmpgt_epi64(q, lim), lo = _mm256_cmpgt_epi64(nlim, q);
    const int m = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_or_si256(hi, lo)));
    if (m) *c += (uint32_t)((m & 1) + (m >> 1 & 1) + (m >> 2 & 1) + (m >> 3)); /* rare */
    return _mm256_blendv_epi8(_mm256_blendv_epi8(q, lim, hi), nlim, lo);
}

void sn_k_axpy(sn_q *out, const sn_q *a, sn_q s, const sn_q *x, uint32_t n, int sh, uint32_t *sat) {
    const int64_t b = ((int64_t)1 << 62) + (sh > 0 ? (int64_t)1 << (sh - 1) : 0), f = ((int64_t)1 << 62) >> sh;
    const __m256i vs = _mm256_set1_epi64x(s), bias = _mm256_set1_epi64x(b), off = _mm256_set1_epi64x(f);
    const __m256i even = _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0);
    const __m128i cnt = _mm_cvtsi32_si128(sh);
    uint32_t i, c = 0;
    for (i = 0; i + 4 <= n; i += 4) {
        __m256i q = _mm256_sub_epi64(_mm256_srl_epi64(_mm256_add_epi64(_mm256_mul_epi32(LD4(x + i), vs), bias), cnt), off);
        q = clamp4(_mm256_add_epi64(clamp4(q, &c), LD4(a + i)), &c);
        _mm_storeu_si128((__m128i *)(void *)(out + i), _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(q, even)));
    }
    *sat += c;
    for (; i < n; i++) out[i] = sn_add(a[i], sn_mulq(s, x[i], sh, sat), sat);
}

/* acc += M^ y over the free rows (acc zeroed by the caller): row i's sum
 * M_ii y_i + sum_j M_ij y_j in lanes, acc_j += M_ij y_i (|M| <= 2^23, |y| <=
 * 2^28: products < 2^51, exact int64 sums in any order) */
void sn_k_mass_ff(const unsigned char *rp, const unsigned char *cols, const unsigned char *md, const unsigned char *mo,
                  const sn_q *y, sn_acc *acc, uint32_t nF) {
    uint32_t i;
    for (i = 0; i < nF; i++) {
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        const __m256i yi = sn_k_ld3d(y + 3 * i);
        __m256i l = _mm256_mul_epi32(_mm256_set1_epi32(rd_real(md, i)), yi);
        for (; e < end; e++) {
            const uint32_t j = sn_rd_u16(cols + 2 * e);
            __m256i m;
            if (j >= nF) break; /* skeleton columns come last */
            m = _mm256_set1_epi32(rd_real(mo, e));
            l = _mm256_add_epi64(l, _mm256_mul_epi32(m, sn_k_ld3d(y + 3 * j)));
            sn_k_st3q(acc + 3 * j, _mm256_add_epi64(sn_k_ld3q(acc + 3 * j), _mm256_mul_epi32(m, yi)));
        }
        sn_k_st3q(acc + 3 * i, _mm256_add_epi64(sn_k_ld3q(acc + 3 * i), l));
    }
}

/* The IC(0) sweeps' rounding (sn_kernels_ic.h sn_k_ic_rnd): row s =
 * [2^62 + 2^(s-1) (0 for s = 0) x4 | 2^(62-s) x4], s = 0..62, so that
 * round(p, s) = ((p + row[0]) >>> s) - row[4] with one folded load each. */
#define RT_B(s) (((int64_t)1 << 62) + ((s) > 0 ? (int64_t)1 << ((s) > 0 ? (s) - 1 : 0) : 0))
#define RT_ROW(s) {RT_B(s), RT_B(s), RT_B(s), RT_B(s), ((int64_t)1 << 62) >> (s), ((int64_t)1 << 62) >> (s), \
                   ((int64_t)1 << 62) >> (s), ((int64_t)1 << 62) >> (s)}
#define RT_8(s) RT_ROW(s), RT_ROW(s + 1), RT_ROW(s + 2), RT_ROW(s + 3), RT_ROW(s + 4), RT_ROW(s + 5), RT_ROW(s + 6), RT_ROW(s + 7)
const int64_t sn_k_ic_rtab[SN_K_IC_RT_N][8] = {RT_8(0), RT_8(8), RT_8(16), RT_8(24), RT_8(32), RT_8(40), RT_8(48),
                                                RT_ROW(56), RT_ROW(57), RT_ROW(58), RT_ROW(59), RT_ROW(60), RT_ROW(61), RT_ROW(62)};
#undef RT_8
#undef RT_ROW
#undef RT_B

#if defined(__AVX512F__) && defined(__AVX512VL__)
const char *sn_kernels_name(void) { return "avx512"; }
#else
const char *sn_kernels_name(void) { return "avx2"; }
#endif

#else
typedef int sn_kernels_avx2_unused_; /* ISO C: no empty translation unit */
#endif
