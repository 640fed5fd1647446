/* sn_kernels_fsimd.c -- the float flavour's SIMD kernels of sn_kernels.h
 * (x86-64 AVX2, aarch64 AdvSIMD; the layer in sn_kernels_fsimd.h).
 *
 * cell_mul: a corner's 3 outputs are lanes 0..2. Block (a,b) adds B u_b to
 * L_a (B's columns times broadcast u_b[c]) and B^T u_a to L_b (B's rows),
 * each as ((p0 + p1) + p2) added to the accumulator, and the blocks come in
 * the reference's order (rows ascending; a corner's row takes the
 * transposed blocks of the rows above it, then its own row): every output
 * is the scalar reference's float, bit for bit. AVX2 uses 8 lanes for the
 * cell products (two 3-vector halves: below). */
#include "sn_kernels_fsimd.h"
#include "sn_kernels_rot.h" /* sn_k_rotm, sn_k_free8 */

#if defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)

#define BLKP(K, a, b) ((K) + (size_t)SN_K_BLK(a, b) * SN_REAL_BYTES)

/* the nf accumulators to l (3 floats each; 4-lane stores in ascending
 * order, each overwriting the previous one's lane 3, the last masked) */
SN_INLINE void store_rows(sn_acc *l, const sn_fv *L, uint32_t nf) {
    uint32_t i;
    for (i = 0; i + 1 < nf; i++) FV_ST4(l + 3 * i, L[i]);
    if (nf) fv_st3(l + 3 * (nf - 1), L[nf - 1]);
}

#if defined(SN_KERNELS_FAVX2)
/* AVX2: a block's two terms side by side in 8 lanes, [B u_b | B^T u_a]:
 * one VPERMPS puts column c in the low half and row c in the high half,
 * times [u_b[c] x4 | u_a[c] x4]; the low half is added to L_a, the high
 * half to L_b, in the order of the 4-lane code (each half's lane k is the
 * same ((p0 + p1) + p2) of output k): the same floats. */
#define F8_PERM(v, a, b, c, d, e, f) _mm256_permutevar8x32_ps((v), _mm256_setr_epi32(a, b, c, c, d, e, f, f))
/* block (a, b) of a cell: la += B u_b, lb += B^T u_a (w: u_a's components x8) */
SN_INLINE void f8_pair(const unsigned char *B, const sn_q *ub, __m256 w0, __m256 w1, __m256 w2, sn_fv *la, sn_fv *lb) {
    const __m256 v0 = FV_LD8(B), v1 = FV_LD8((const float *)(const void *)B + 1);
    const __m256 t = _mm256_add_ps(
        _mm256_add_ps(_mm256_mul_ps(F8_PERM(v0, 0, 3, 6, 0, 1, 2), _mm256_blend_ps(_mm256_set1_ps(ub[0]), w0, 0xF0)),
                      _mm256_mul_ps(F8_PERM(v0, 1, 4, 7, 3, 4, 5), _mm256_blend_ps(_mm256_set1_ps(ub[1]), w1, 0xF0))),
        _mm256_mul_ps(F8_PERM(v1, 1, 4, 7, 5, 6, 7), _mm256_blend_ps(_mm256_set1_ps(ub[2]), w2, 0xF0)));
    *la = FV_ADD(*la, _mm256_castps256_ps128(t));
    *lb = FV_ADD(*lb, _mm256_extractf128_ps(t, 1));
}
void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    sn_fv L[8], c[3];
    uint32_t i, j;
    for (i = 0; i < 8; i++) L[i] = FV_SET1(0.0f); /* all 8: stores, not a call of memset */
    for (i = 0; i < nf; i++) {
        const uint32_t a = fc[i];
        const __m256 wa0 = _mm256_set1_ps(u[3 * i]), wa1 = _mm256_set1_ps(u[3 * i + 1]), wa2 = _mm256_set1_ps(u[3 * i + 2]);
        sn_fv la;
        fv_cols(BLKP(K, a, a), c);
        la = FV_ADD(L[i], FV_MAC3(c, _mm256_castps256_ps128(wa0), _mm256_castps256_ps128(wa1),
                                  _mm256_castps256_ps128(wa2))); /* diagonal block (a,a) */
        for (j = i + 1; j < nf; j++) {
            f8_pair(BLKP(K, a, fc[j]), u + 3 * j, wa0, wa1, wa2, &la, &L[j]);
        }
        L[i] = la;
    }
    store_rows(l, L, nf);
}
#undef F8_PERM
#else
void sn_k_cell_mul(const unsigned char *K, const uint8_t *fc, uint32_t nf, const sn_q *u, sn_acc *l) {
    sn_fv L[8], r[3], c[3];
    uint32_t i, j;
    for (i = 0; i < nf; i++) L[i] = FV_SET1(0.0f);
    for (i = 0; i < nf; i++) {
        const uint32_t a = fc[i];
        const sn_fv ua0 = FV_SET1(u[3 * i]), ua1 = FV_SET1(u[3 * i + 1]), ua2 = FV_SET1(u[3 * i + 2]);
        sn_fv la;
        fv_cols(BLKP(K, a, a), c);
        la = FV_ADD(L[i], FV_MAC3(c, ua0, ua1, ua2)); /* diagonal block (a,a) */
        for (j = i + 1; j < nf; j++) {
            const sn_fv ub0 = FV_SET1(u[3 * j]), ub1 = FV_SET1(u[3 * j + 1]), ub2 = FV_SET1(u[3 * j + 2]);
            fv_blk(BLKP(K, a, fc[j]), r, c);
            la = FV_ADD(la, FV_MAC3(c, ub0, ub1, ub2));
            L[j] = FV_ADD(L[j], FV_MAC3(r, ua0, ua1, ua2));
        }
        L[i] = la;
    }
    store_rows(l, L, nf);
}

#endif

#if defined(SN_KERNELS_FAVX2)
/* cell_stiff on x86-64 float (sn_solve.c; round 3): sn_k_rot_t_m for the
 * free corners in ascending order, sn_k_cell_mul's product (above, u at 4
 * floats a corner) and sn_k_out_rot_acc_m per corner, the same operations
 * in the same order (the same floats and counts), one case per corner
 * count nf: the loops unrolled in full, the accumulators in registers. */
#define F8_PERM(v, a, b, c, d, e, f) _mm256_permutevar8x32_ps((v), _mm256_setr_epi32(a, b, c, c, d, e, f, f))
__attribute__((always_inline)) /* a copy per count (GCC kept one call with nf a variable) */
SN_INLINE void cell_stiff_n(const unsigned char *K, const unsigned char *cl, uint32_t fm, const sn_k_rotm *m, const sn_q *d,
                            sn_acc *acc, uint32_t *sat, const uint32_t nf) {
    float u[32];
    uint32_t fc[8] = {0}, vi[8] = {0}, i, j; /* set for i < nf: zeroed for GCC's flow analysis */
    sn_fv L[8], c[3], bad = _mm_setzero_ps();
#pragma GCC unroll 8
    for (i = 0; i < nf; i++, fm &= fm - 1u) {
        const sn_q *v;
        fc[i] = (uint32_t)__builtin_ctz(fm);
        vi[i] = sn_rd_u16(cl + 2 * fc[i]);
        v = d + 3 * vi[i];
        L[i] = FV_MAC3(m->r, FV_SET1(v[0]), FV_SET1(v[1]), FV_SET1(v[2]));
        bad = _mm_or_ps(bad, FV_BAD(L[i]));
    }
    /* sn_out of each: one test for the corners (x86-64 round 4), per corner
     * only if a lane clamps (the same values and count) */
    if (_mm_movemask_ps(bad) & 7) {
#pragma GCC unroll 8
        for (i = 0; i < nf; i++) L[i] = fv_out3(L[i], sat);
    }
#pragma GCC unroll 8
    for (i = 0; i < nf; i++) {
        FV_ST4(u + 4 * i, L[i]); /* lane 3 unread */
        L[i] = FV_SET1(0.0f);
    }
#pragma GCC unroll 8
    for (i = 0; i < nf; i++) {
        const __m256 wa0 = _mm256_set1_ps(u[4 * i]), wa1 = _mm256_set1_ps(u[4 * i + 1]), wa2 = _mm256_set1_ps(u[4 * i + 2]);
        sn_fv la;
        fv_cols(BLKP(K, fc[i], fc[i]), c);
        la = FV_ADD(L[i], FV_MAC3(c, _mm256_castps256_ps128(wa0), _mm256_castps256_ps128(wa1), _mm256_castps256_ps128(wa2)));
#pragma GCC unroll 8
        for (j = i + 1; j < nf; j++) {
            f8_pair(BLKP(K, fc[i], fc[j]), u + 4 * j, wa0, wa1, wa2, &la, &L[j]);
        }
        L[i] = la;
    }
    bad = _mm_setzero_ps();
#pragma GCC unroll 8
    for (i = 0; i < nf; i++) bad = _mm_or_ps(bad, FV_BAD(L[i]));
    if (_mm_movemask_ps(bad) & 7) { /* as above */
#pragma GCC unroll 8
        for (i = 0; i < nf; i++) L[i] = fv_out3(L[i], sat);
    }
#pragma GCC unroll 8
    for (i = 0; i < nf; i++) { /* sn_k_out_rot_acc_m: acc += R sn_out(l) */
        const sn_fv t = L[i];
        sn_acc *a = acc + 3 * vi[i];
        fv_st3(a, FV_ADD(fv_ld3(a), FV_MAC3(m->c, SN_K_LANE(t, 0), SN_K_LANE(t, 1), SN_K_LANE(t, 2))));
    }
}
#undef F8_PERM
void sn_k_cell_stiff(const unsigned char *K, const unsigned char *cl, uint32_t nF, const sn_q *R, const sn_q *d, sn_acc *acc,
                     uint32_t *sat) {
    const uint32_t fm = sn_k_free8(cl, nF);
#if defined(__POPCNT__) /* every AVX2 target has it (x86-64 round 4: one instruction for ten) */
    const uint32_t n = (uint32_t)__builtin_popcount(fm); /* the free corners' count */
#else
    uint32_t n = fm - (fm >> 1 & 0x55u);
    n = (n & 0x33u) + (n >> 2 & 0x33u);
    n = (n + (n >> 4)) & 0x0Fu; /* the free corners' count */
#endif
    sn_k_rotm m;
    if (!fm) return; /* no free corner (a sixth of cow_fem's cells): before the frame's loads (x86-64 round 4) */
    sn_k_rotm_ld(&m, R);
    switch (n) {
    case 1: cell_stiff_n(K, cl, fm, &m, d, acc, sat, 1); break;
    case 2: cell_stiff_n(K, cl, fm, &m, d, acc, sat, 2); break;
    case 3: cell_stiff_n(K, cl, fm, &m, d, acc, sat, 3); break;
    case 4: cell_stiff_n(K, cl, fm, &m, d, acc, sat, 4); break;
    case 5: cell_stiff_n(K, cl, fm, &m, d, acc, sat, 5); break;
    case 6: cell_stiff_n(K, cl, fm, &m, d, acc, sat, 6); break;
    case 7: cell_stiff_n(K, cl, fm, &m, d, acc, sat, 7); break;
    case 8: cell_stiff_n(K, cl, fm, &m, d, acc, sat, 8); break;
    default: break; /* no free corner */
    }
}
#endif

#if defined(SN_KERNELS_FAVX2)
/* AVX2: the two products side by side in 8 lanes, [l1 row | l2 row]: a
 * block's row or column in both halves (one VPERMPS), times [u1_b[c] x4 |
 * u2_b[c] x4] (built once per cell), the rows accumulated in the
 * reference's order as before. Lanes never mix (lane k of a half is output
 * k of that product), so the floats are the 4-lane code's. l2 is computed
 * at every row (rows outside rows2 are unspecified: finite, unread). */
#define F8_PERM(v, a, b, c) _mm256_permutevar8x32_ps((v), _mm256_setr_epi32(a, b, c, c, a, b, c, c))
#define F8_MAC3(c, x) _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps((c)[0], (x)[0]), _mm256_mul_ps((c)[1], (x)[1])), \
                                    _mm256_mul_ps((c)[2], (x)[2]))
SN_INLINE void f8_cols(const unsigned char *B, __m256 c[3]) {
    const __m256 v0 = FV_LD8(B), v1 = FV_LD8((const float *)(const void *)B + 1);
    c[0] = F8_PERM(v0, 0, 3, 6);
    c[1] = F8_PERM(v0, 1, 4, 7);
    c[2] = F8_PERM(v1, 1, 4, 7);
}
SN_INLINE void f8_blk(const unsigned char *B, __m256 r[3], __m256 c[3]) {
    const float *f = (const float *)(const void *)B;
    const __m256 v0 = FV_LD8(B), v1 = FV_LD8(f + 1);
    /* rows by 16-byte broadcasts inside the block (x86-64 round 3: no
     * permute index registers; lane 3 junk, never stored) */
    r[0] = _mm256_broadcast_ps((const __m128 *)(const void *)f);
    r[1] = _mm256_broadcast_ps((const __m128 *)(const void *)(f + 3));
    r[2] = _mm256_permute_ps(_mm256_broadcast_ps((const __m128 *)(const void *)(f + 5)), _MM_SHUFFLE(3, 3, 2, 1));
    c[0] = F8_PERM(v0, 0, 3, 6);
    c[1] = F8_PERM(v0, 1, 4, 7);
    c[2] = F8_PERM(v1, 1, 4, 7);
}
void sn_k_cell_mul2(const unsigned char *K, const sn_q u1[24], const sn_q u2[24], sn_acc l1[24], sn_acc l2[24],
                    uint32_t rows2) {
    __m256 L[8], W[24], r[3], c[3];
    uint32_t a, b;
    (void)rows2;
    for (a = 3; a < 24; a++) /* corner 0's operands are never read */
        W[a] = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_broadcast_ss(u1 + a)), _mm_broadcast_ss(u2 + a), 1);
    for (a = 0; a < 8; a++) L[a] = _mm256_setzero_ps();
    /* unrolled in full (x86-64 round 3): constant block offsets, L in
     * registers; the same operations in the same order */
#pragma GCC unroll 8
    for (a = 0; a < 8; a++) {
        __m256 la = L[a];
        if (a) { /* the diagonal block; corner 0's is a product with 0 */
            f8_cols(BLKP(K, a, a), c);
            la = _mm256_add_ps(la, F8_MAC3(c, W + 3 * a));
        }
#pragma GCC unroll 8
        for (b = a + 1; b < 8; b++) {
            f8_blk(BLKP(K, a, b), r, c);
            la = _mm256_add_ps(la, F8_MAC3(c, W + 3 * b));
            if (a) L[b] = _mm256_add_ps(L[b], F8_MAC3(r, W + 3 * a)); /* B^T u_0 = 0 */
        }
        L[a] = la;
    }
    for (a = 0; a < 7; a++) {
        FV_ST4(l1 + 3 * a, _mm256_castps256_ps128(L[a]));
        FV_ST4(l2 + 3 * a, _mm256_extractf128_ps(L[a], 1));
    }
    fv_st3(l1 + 21, _mm256_castps256_ps128(L[7]));
    fv_st3(l2 + 21, _mm256_extractf128_ps(L[7], 1));
}
#undef F8_PERM
#undef F8_MAC3

#else /* aarch64: 4 lanes */
/* Both right-hand-side products, one block load for both: row 0 takes B
 * u_b only (corner 0's operands are 0, sn_kernels.h: the skipped terms are
 * +-0 added to a +0 partial sum, which stays +0), l1 every row, l2 the
 * rows in rows2 (the others unspecified): each output's sums in the
 * reference's order, the same floats. */
void sn_k_cell_mul2(const unsigned char *K, const sn_q u1[24], const sn_q u2[24], sn_acc l1[24], sn_acc l2[24],
                    uint32_t rows2) {
    sn_fv L1[8], L2[8], r[3], c[3];
    uint32_t a, b;
    for (a = 0; a < 8; a++) L1[a] = L2[a] = FV_SET1(0.0f);
    for (a = 0; a < 8; a++) {
        const uint32_t ra = rows2 >> a & 1u;
        const sn_fv xa0 = FV_SET1(u1[3 * a]), xa1 = FV_SET1(u1[3 * a + 1]), xa2 = FV_SET1(u1[3 * a + 2]);
        const sn_fv ya0 = FV_SET1(u2[3 * a]), ya1 = FV_SET1(u2[3 * a + 1]), ya2 = FV_SET1(u2[3 * a + 2]);
        sn_fv la1 = L1[a], la2 = L2[a];
        if (a) {
            fv_cols(BLKP(K, a, a), c);
            la1 = FV_ADD(la1, FV_MAC3(c, xa0, xa1, xa2));
            if (ra) la2 = FV_ADD(la2, FV_MAC3(c, ya0, ya1, ya2));
        }
        for (b = a + 1; b < 8; b++) {
            const uint32_t rb = rows2 >> b & 1u;
            fv_blk(BLKP(K, a, b), r, c);
            la1 = FV_ADD(la1, FV_MAC3(c, FV_SET1(u1[3 * b]), FV_SET1(u1[3 * b + 1]), FV_SET1(u1[3 * b + 2])));
            if (ra) la2 = FV_ADD(la2, FV_MAC3(c, FV_SET1(u2[3 * b]), FV_SET1(u2[3 * b + 1]), FV_SET1(u2[3 * b + 2])));
            if (!a) continue;
            L1[b] = FV_ADD(L1[b], FV_MAC3(r, xa0, xa1, xa2));
            if (rb) L2[b] = FV_ADD(L2[b], FV_MAC3(r, ya0, ya1, ya2));
        }
        L1[a] = la1;
        L2[a] = la2;
    }
    store_rows(l1, L1, 8);
    store_rows(l2, L2, 8);
}

#endif

/* out[i] = sn_add(a[i], sn_mulq(s, x[i])): s x clamped and counted, added to
 * a[i], clamped and counted again; 4 entries per iteration, the tail in
 * scalar (each entry alone: the same floats and counts) */
void sn_k_axpy(sn_q *out, const sn_q *a, sn_q s, const sn_q *x, uint32_t n, int sh, uint32_t *sat) {
    const sn_fv vs = FV_SET1(s);
    uint32_t i = 0, c = 0;
#if defined(SN_KERNELS_FAVX2)
    { /* x86-64 round 3: 8 entries at a time while no lane clamps (|s x| and
       * |a + s x| within SN_FLIM, no NaN: sn_out leaves them), from the
       * first block with a clamp on the 4-lane loop below */
        const __m256 s8 = _mm256_set1_ps(s), lim = _mm256_set1_ps(SN_FLIM), sg = _mm256_set1_ps(-0.0f);
        for (; i + 8 <= n; i += 8) {
            const __m256 q = _mm256_mul_ps(s8, _mm256_loadu_ps(x + i)), o = _mm256_add_ps(_mm256_loadu_ps(a + i), q);
            if (_mm256_movemask_ps(_mm256_or_ps(_mm256_cmp_ps(_mm256_andnot_ps(sg, q), lim, _CMP_NLE_UQ),
                                                _mm256_cmp_ps(_mm256_andnot_ps(sg, o), lim, _CMP_NLE_UQ))))
                break;
            _mm256_storeu_ps(out + i, o);
        }
    }
#endif
    for (; i + 4 <= n; i += 4) {
        int m1, m2;
        sn_fv q = fv_clamp(FV_MUL(vs, FV_LD4(x + i)), &m1);
        q = fv_clamp(FV_ADD(FV_LD4(a + i), q), &m2);
        FV_ST4(out + i, q);
        if (m1 | m2) /* rare: the counts of the 4-bit masks from a nibble table */
            c += (uint32_t)((0x4332322132212110ull >> (4 * m1) & 15u) + (0x4332322132212110ull >> (4 * m2) & 15u));
    }
    *sat += c;
    for (; i < n; i++) out[i] = sn_add(a[i], sn_mulq(s, x[i], sh, sat), sat);
}

#if defined(SN_KERNELS_FAVX2)
/* 2^-frac for the IC(0) blocks' decode (sn_kernels_ic.h SN_K_IC_S), exact;
 * frac <= SN_ICHOL_FRAC_MAX = 47 in a valid blob, the table to 62 (the
 * kernel test's fracs) */
const float sn_k_ic_p2[63] = {
    0x1p-0f,  0x1p-1f,  0x1p-2f,  0x1p-3f,  0x1p-4f,  0x1p-5f,  0x1p-6f,  0x1p-7f,  0x1p-8f,  0x1p-9f,  0x1p-10f, 0x1p-11f,
    0x1p-12f, 0x1p-13f, 0x1p-14f, 0x1p-15f, 0x1p-16f, 0x1p-17f, 0x1p-18f, 0x1p-19f, 0x1p-20f, 0x1p-21f, 0x1p-22f, 0x1p-23f,
    0x1p-24f, 0x1p-25f, 0x1p-26f, 0x1p-27f, 0x1p-28f, 0x1p-29f, 0x1p-30f, 0x1p-31f, 0x1p-32f, 0x1p-33f, 0x1p-34f, 0x1p-35f,
    0x1p-36f, 0x1p-37f, 0x1p-38f, 0x1p-39f, 0x1p-40f, 0x1p-41f, 0x1p-42f, 0x1p-43f, 0x1p-44f, 0x1p-45f, 0x1p-46f, 0x1p-47f,
    0x1p-48f, 0x1p-49f, 0x1p-50f, 0x1p-51f, 0x1p-52f, 0x1p-53f, 0x1p-54f, 0x1p-55f, 0x1p-56f, 0x1p-57f, 0x1p-58f, 0x1p-59f,
    0x1p-60f, 0x1p-61f, 0x1p-62f};

/* The mat-vec's mass pass without a mask (sn_solve.c pass_M_ff; x86-64
 * round 2): acc += M^ y over the free rows, lanes the 3 components, each
 * lane's sums in pass_M_ff's order: l = 0 + M_ii y_i, l += M_ij y_j, then
 * acc_i += l; acc_j += M_ij y_i as the row reaches j. The same floats. */
void sn_k_mass_ff(const unsigned char *rp, const unsigned char *cols, const unsigned char *md, const unsigned char *mo,
                  const sn_q *y, sn_acc *acc, uint32_t nF) {
    uint32_t i;
    for (i = 0; i < nF; i++) {
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        const sn_fv yi = fv_ld3(y + 3 * i);
        sn_fv l = FV_ADD(FV_SET1(0.0f), FV_MUL(FV_SET1(rd_real(md, i)), yi));
        for (; e < end; e++) {
            const uint32_t j = sn_rd_u16(cols + 2 * e);
            sn_fv m;
            if (j >= nF) break; /* skeleton columns come last */
            m = FV_SET1(rd_real(mo, e));
            l = FV_ADD(l, FV_MUL(m, fv_ld3(y + 3 * j)));
            fv_st3(acc + 3 * j, FV_ADD(fv_ld3(acc + 3 * j), FV_MUL(m, yi)));
        }
        fv_st3(acc + 3 * i, FV_ADD(fv_ld3(acc + 3 * i), l));
    }
}
#endif

#if defined(SN_KERNELS_FAVX2)
/* The float right-hand side's loops (sn_kernels.h SN_K_FRHS; x86-64 round
 * 3): lanes are entries, each the reference's expression (a tail entry by
 * the reference itself); clamps counted per lane from the 4-bit masks. */
#define BITS4(m) ((uint32_t)(0x4332322132212110ull >> (4 * (m)) & 15u))
/* the fold's operands (sn_kernels.h sn_fold_w1 / sn_fold_y1): the same
 * float operations per lane, no clamp */
void sn_k_fold_w(sn_q *u, const sn_q *vel, const sn_q *x0, sn_q ck, uint32_t n) {
    const sn_fv c = FV_SET1(ck);
    uint32_t i;
    for (i = 0; i + 4 <= n; i += 4) FV_ST4(u + i, FV_MUL(FV_ADD(FV_LD4(vel + i), FV_LD4(x0 + i)), c));
    for (; i < n; i++) u[i] = sn_fold_w1(vel[i], x0[i], ck);
}
void sn_k_fold_y(sn_q *u, const sn_q *vel, const sn_q *x0, sn_q a1, uint32_t n) {
    const sn_fv c = FV_SET1(a1);
    uint32_t i;
    for (i = 0; i + 4 <= n; i += 4) {
        const sn_fv x = FV_LD4(x0 + i);
        FV_ST4(u + i, FV_ADD(FV_MUL(FV_ADD(FV_LD4(vel + i), x), c), x));
    }
    for (; i < n; i++) u[i] = sn_fold_y1(vel[i], x0[i], a1);
}
void sn_k_negout(sn_q *b, const sn_acc *acc, uint32_t n, uint32_t *sat) {
    const sn_fv sg = FV_SET1(-0.0f);
    uint32_t i, t = 0;
    for (i = 0; i + 4 <= n; i += 4) {
        int m;
        FV_ST4(b + i, _mm_xor_ps(fv_clamp(FV_LD4(acc + i), &m), sg)); /* the reference's negation: the sign flipped */
        if (m) t += BITS4(m); /* rare */
    }
    *sat += t;
    for (; i < n; i++) b[i] = -sn_out(acc[i], 0, sat);
}
void sn_k_mass_rhs(const unsigned char *rp, const unsigned char *cols, const unsigned char *md, const unsigned char *mo,
                   const sn_q *y, const sn_q *vel, const sn_q *ds, sn_q a1, sn_acc *acc, uint32_t nF, uint32_t *sat) {
    const sn_fv c = FV_SET1(a1);
    uint32_t i;
    for (i = 0; i < nF; i++) {
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        const sn_fv yi = fv_ld3(y + 3 * i);
        sn_fv l = FV_ADD(FV_SET1(0.0f), FV_MUL(FV_SET1(rd_real(md, i)), yi));
        for (; e < end; e++) {
            const uint32_t j = sn_rd_u16(cols + 2 * e);
            const sn_fv m = FV_SET1(rd_real(mo, e));
            if (j >= nF) { /* y_j = sn_add(coef(v_j, a1), ds_j) per block, as sn_k_coef3 and sn_k_add3 */
                const sn_fv yj = fv_out3(FV_ADD(fv_out3(FV_MUL(fv_ld3(vel + 3 * j), c), sat), fv_ld3(ds + 3 * (j - nF))), sat);
                l = FV_ADD(l, FV_MUL(m, yj));
                continue;
            }
            l = FV_ADD(l, FV_MUL(m, fv_ld3(y + 3 * j)));
            fv_st3(acc + 3 * j, FV_ADD(fv_ld3(acc + 3 * j), FV_MUL(m, yi)));
        }
        fv_st3(acc + 3 * i, FV_ADD(fv_ld3(acc + 3 * i), l));
    }
}
void sn_k_grav_rhs(sn_q *b, const sn_acc *acc, const sn_q *R, const unsigned char *ml, const sn_q g[3], int modelled,
                   uint32_t nF, uint32_t *sat) {
    const sn_fv g0 = FV_SET1(g[0]), g1 = FV_SET1(g[1]), g2 = FV_SET1(g[2]), gv = fv_ld3(g), sg = FV_SET1(-0.0f);
    sn_fv c[3];
    uint32_t i;
    for (i = 0; i < nF; i++) {
        sn_fv gi = gv, gr, t;
        fv_cols(R + 9 * i, c);
        gr = fv_out3(FV_MAC3(c, g0, g1, g2), sat); /* sn_k_rot: formed (and counted) as the reference does, modelled or not */
        if (modelled) gi = fv_out3(FV_ADD(gv, _mm_xor_ps(gr, sg)), sat); /* sn_add(g, -gr) */
        t = fv_out3(FV_ADD(fv_ld3(b + 3 * i), fv_out3(FV_MUL(FV_SET1(rd_real(ml, i)), gi), sat)), sat);
        fv_st3(b + 3 * i, fv_out3(FV_ADD(t, _mm_xor_ps(fv_out3(fv_ld3(acc + 3 * i), sat), sg)), sat));
    }
}
/* the CG's float dot (sn_solve.c dot): entry i into lane i mod 8, the tail
 * by a masked load (its zero lanes add +0: a partial sum is never -0, so
 * exactly nothing), then ((p0 + p1) + (p2 + p3)) + ((p4 + p5) + (p6 + p7))
 * by two HADDs and the halves' sum: the reference's floats */
float sn_k_fdot(const sn_q *a, const sn_q *b, uint32_t n) {
    __m256 p = _mm256_setzero_ps();
    __m128 q;
    uint32_t i;
    for (i = 0; i + 8 <= n; i += 8) p = _mm256_add_ps(p, _mm256_mul_ps(_mm256_loadu_ps(a + i), _mm256_loadu_ps(b + i)));
    if (i < n) {
        const __m256i m = _mm256_cmpgt_epi32(_mm256_set1_epi32((int)(n - i)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        p = _mm256_add_ps(p, _mm256_mul_ps(_mm256_maskload_ps(a + i, m), _mm256_maskload_ps(b + i, m)));
    }
    p = _mm256_hadd_ps(p, p); /* p0+p1, p2+p3, ., . | p4+p5, p6+p7, ., . */
    p = _mm256_hadd_ps(p, p); /* (p0+p1)+(p2+p3) x4 | (p4+p5)+(p6+p7) x4 */
    q = _mm_add_ss(_mm256_castps256_ps128(p), _mm256_extractf128_ps(p, 1));
    return _mm_cvtss_f32(q);
}
/* sn_skeleton: lane k holds entry k of the reference's sn_rot / sn_add
 * (((R_k0 x0 + R_k1 x1) + R_k2 x2), then each sum clamped by fv_out3 as
 * sn_out would, its count per lane) */
void sn_k_skeleton(const sn_q *jR, const sn_q *jT, const unsigned char *fr, const unsigned char *rest, uint32_t nF,
                   uint32_t nV, sn_q *pos, sn_q *vel, sn_q *ds, uint32_t *sat) {
    const sn_fv sg = FV_SET1(-0.0f);
    uint32_t i;
    for (i = nF; i < nV; i++) {
        const uint32_t b = fr[4 * (size_t)i];
        sn_fv c[3], pn, vn;
        fv_cols(jR + 9 * b, c);
        pn = fv_out3(FV_MAC3(c, FV_SET1(rd_real(rest, 3 * i)), FV_SET1(rd_real(rest, 3 * i + 1)),
                             FV_SET1(rd_real(rest, 3 * i + 2))), sat);
        pn = fv_out3(FV_ADD(pn, fv_ld3(jT + 3 * b)), sat);
        vn = fv_out3(FV_ADD(pn, _mm_xor_ps(fv_ld3(pos + 3 * i), sg)), sat);
        fv_st3(ds + 3 * (i - nF), fv_out3(FV_ADD(vn, _mm_xor_ps(fv_ld3(vel + 3 * i), sg)), sat));
        fv_st3(vel + 3 * i, vn);
        fv_st3(pos + 3 * i, pn);
    }
}
/* sn_rigs' entries: t by fv_out3 (lane k: sn_out(eta F_k)), then the
 * rotation's ((R_k0 t0 + R_k1 t1) + R_k2 t2) and the sum, each clamped as
 * sn_out would, counted per lane */
void sn_k_rig(sn_q eta, const unsigned char *F, const unsigned char *vx, uint32_t first, uint32_t cnt, const sn_q *R,
              sn_q *b, uint32_t *sat) {
    const sn_fv ev = FV_SET1(eta);
    uint32_t e;
    for (e = first; e < first + cnt; e++) {
        const uint32_t i = sn_rd_u16(vx + 2 * (size_t)e);
        const sn_fv t = fv_out3(FV_MUL(ev, fv_ld3((const float *)(const void *)(F + (size_t)12 * e))), sat);
        sn_fv c[3], f;
        fv_cols(R + 9 * i, c);
        f = fv_out3(FV_MAC3(c, _mm_shuffle_ps(t, t, 0x00), _mm_shuffle_ps(t, t, 0x55), _mm_shuffle_ps(t, t, 0xAA)), sat);
        fv_st3(b + 3 * i, fv_out3(FV_ADD(fv_ld3(b + 3 * i), f), sat));
    }
}
#undef BITS4
#endif

#if defined(SN_KERNELS_FAVX2) && defined(__AVX512F__) && defined(__AVX512VL__)
const char *sn_kernels_name(void) { return "avx512"; }
#elif defined(SN_KERNELS_FAVX2)
const char *sn_kernels_name(void) { return "avx2"; }
#else
const char *sn_kernels_name(void) { return "neon"; }
#endif

#else
typedef int sn_kernels_fsimd_unused_; /* ISO C: no empty translation unit */
#endif
