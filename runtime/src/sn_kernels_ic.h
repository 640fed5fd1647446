/* sn_kernels_ic.h -- the IC(0) preconditioner's block products (sn_precond.c,
 * NUMERICS.md "Preconditioner"): one 3x3 ICHOL block U (int16 mantissas,
 * one frac per block; SN_ELEM_ICHOL bytes: m[9], frac, pad) times a
 * 3-vector, each of the three rows rounded alone. Inline: they run once per
 * stored block of each sweep, where a call would cost as much as the block.
 *
 *   sn_k_ic_col: a[c] += round(sum_r U[3r+c] y[r], s)   (U^T y, forward)
 *   sn_k_ic_row: l[r] += round(sum_c U[3r+c] z[c], frac) (U z, backward)
 *
 * round(p, s): s >= 0 the round-half-up shift (sn_rshr64), s < 0 scaled up
 * by 2^-s <= 2^15 and clamped (counted). Fixed: |U| < 2^15, |y| <= 2^28, so
 * |p| < 3 2^43 < 2^44.6. The _ref versions are the portable reference (and
 * the float flavour); the AVX2 and NEON versions return the same integers:
 * the products are exact, each row is rounded alone with the same rule, and
 * the sums into a and l are exact int64 sums (bounds: sn_precond.c). */
#ifndef SN_KERNELS_IC_H
#define SN_KERNELS_IC_H

#include "sn_kernels.h"

/* int16 from two little-endian bytes, without an implementation-defined
 * conversion (little-endian hosts: one load; int16_t is two's complement) */
SN_INLINE int32_t sn_k_ic_i16(const unsigned char *p) {
#if SN_HOST_LE
    int16_t v;
    memcpy(&v, p, 2);
    return v;
#else
    return (int32_t)(sn_rd_u16(p) ^ 0x8000u) - 32768;
#endif
}

/* Block U (entries as sn_q: fixed the mantissa, float the value) and its frac. */
/* The 9 entries written out: the compilers kept a loop of 9 through memory. */
SN_INLINE int sn_k_ic_block(const unsigned char *b, sn_q U[9]) {
#if defined(SN_FLOAT)
    uint32_t u = (uint32_t)(127 - b[18]) << 23; /* 2^-frac, frac <= 47: a normal float */
    float s;
    memcpy(&s, &u, 4);
#define SN_K_IC_E(k) U[k] = (float)sn_k_ic_i16(b + 2 * (k)) * s
#else
#define SN_K_IC_E(k) U[k] = sn_k_ic_i16(b + 2 * (k))
#endif
    SN_K_IC_E(0); SN_K_IC_E(1); SN_K_IC_E(2); SN_K_IC_E(3); SN_K_IC_E(4);
    SN_K_IC_E(5); SN_K_IC_E(6); SN_K_IC_E(7); SN_K_IC_E(8);
#undef SN_K_IC_E
    return b[18];
}

/* A block row product p (|p| < 2^44.6) at shift s: rounded (s >= 0: < 2^44.6,
 * no clamp needed) or, s < 0, scaled up by 2^-s <= 2^15 and clamped to the
 * state range (counted). Float: p. */
SN_INLINE sn_acc sn_k_ic_round(sn_acc p, int s, uint32_t *sat) {
#if defined(SN_FLOAT)
    (void)s; (void)sat;
    return p;
#else
    if (s >= 0) return sn_rshr64(p, s);
    return sn_out(p * ((int64_t)1 << -s), 0, sat);
#endif
}

SN_INLINE void sn_k_ic_col_ref(const unsigned char *b, const sn_q y[3], int s, sn_acc a[3], uint32_t *sat) {
    sn_q U[9];
    (void)sn_k_ic_block(b, U);
    a[0] += sn_k_ic_round(sn_mul(U[0], y[0]) + sn_mul(U[3], y[1]) + sn_mul(U[6], y[2]), s, sat);
    a[1] += sn_k_ic_round(sn_mul(U[1], y[0]) + sn_mul(U[4], y[1]) + sn_mul(U[7], y[2]), s, sat);
    a[2] += sn_k_ic_round(sn_mul(U[2], y[0]) + sn_mul(U[5], y[1]) + sn_mul(U[8], y[2]), s, sat);
}

/* l has 4 entries (the 4th is the SIMD paths' scratch, never read). */
SN_INLINE void sn_k_ic_row_ref(const unsigned char *b, const sn_q z[3], sn_acc l[4], uint32_t *sat) {
    sn_q U[9];
    int s = sn_k_ic_block(b, U);
    l[0] += sn_k_ic_round(sn_mul(U[0], z[0]) + sn_mul(U[1], z[1]) + sn_mul(U[2], z[2]), s, sat);
    l[1] += sn_k_ic_round(sn_mul(U[3], z[0]) + sn_mul(U[4], z[1]) + sn_mul(U[5], z[2]), s, sat);
    l[2] += sn_k_ic_round(sn_mul(U[6], z[0]) + sn_mul(U[7], z[1]) + sn_mul(U[8], z[2]), s, sat);
}

#if defined(SN_KERNELS_AVX2)
#include <immintrin.h>
#include "sn_kernels_rot.h" /* sn_k_ld3q, sn_k_st3q */
/* 4 int64 lanes (the 4th unused). Round half up for 0 <= s <= 62 without an
 * arithmetic 64-bit shift (AVX2 has none): with B = 2^62, p + 2^(s-1) + B
 * is >= 0 and < 2^63 (|p| < 2^44.6), so its logical shift is the floor, and
 * B >> s is exact (s <= 62): floor((x + B) / 2^s) - B / 2^s = floor(x / 2^s).
 * The two constants per s come from a table (sn_kernels_avx2.c: row s =
 * [2^62 + 2^(s-1) x4 | 2^(62-s) x4]), one folded load each: the sweeps
 * round every block at its own s, and building them cost ~10 instructions. */
#define SN_K_IC_RT_N 63 /* s = 0..62: the forward shift's range (SN_ICHOL_FRAC_MAX + 15) */
extern const int64_t sn_k_ic_rtab[SN_K_IC_RT_N][8];
SN_INLINE __m256i sn_k_ic_rshr(__m256i p, int s) {
    const int64_t *t = sn_k_ic_rtab[s];
    return _mm256_sub_epi64(_mm256_srl_epi64(_mm256_add_epi64(p, _mm256_loadu_si256((const __m256i *)(const void *)t)),
                                             _mm_cvtsi32_si128(s)),
                            _mm256_loadu_si256((const __m256i *)(const void *)(t + 4)));
}
#define SN_K_IC_W(p) _mm256_cvtepi16_epi64(_mm_loadl_epi64((const __m128i *)(const void *)(p)))
/* U^T y in lanes 0..2 (lane 3 junk): columns of U as lanes, U0..U3, U3..U6,
 * U6..U9 (8-byte loads, inside the 20-byte block); y as VPMULDQ operands
 * (the even int32 slots: y[c] in every slot) */
SN_INLINE __m256i sn_k_ic_colp(const unsigned char *b, __m256i y0, __m256i y1, __m256i y2) {
    return _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(SN_K_IC_W(b), y0), _mm256_mul_epi32(SN_K_IC_W(b + 6), y1)),
                            _mm256_mul_epi32(SN_K_IC_W(b + 12), y2));
}
/* U z in lanes 0..2 (lane 3: 0): rows of U as lanes, (U0,U3,U6) (U1,U4,U7) from bytes
 * 0..15, (U2,U5,U8) from bytes 4..19 by the same byte shuffle */
SN_INLINE __m256i sn_k_ic_rowp(const unsigned char *b, __m256i z0, __m256i z1, __m256i z2) {
    const __m128i sh0 = _mm_setr_epi8(0, 1, 6, 7, 12, 13, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1); /* lane 3: 0 */
    const __m128i sh1 = _mm_setr_epi8(2, 3, 8, 9, 14, 15, -1, -1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i v = _mm_loadu_si128((const __m128i *)(const void *)b);
    const __m128i w = _mm_loadu_si128((const __m128i *)(const void *)(b + 4));
    return _mm256_add_epi64(
        _mm256_add_epi64(_mm256_mul_epi32(_mm256_cvtepi16_epi64(_mm_shuffle_epi8(v, sh0)), z0),
                         _mm256_mul_epi32(_mm256_cvtepi16_epi64(_mm_shuffle_epi8(v, sh1)), z1)),
        _mm256_mul_epi32(_mm256_cvtepi16_epi64(_mm_shuffle_epi8(w, sh0)), z2));
}

/* s < 0 (scale-up and clamp, a rare blob): the reference. */
SN_INLINE void sn_k_ic_col(const unsigned char *b, const sn_q y[3], int s, sn_acc a[3], uint32_t *sat) {
    if (s < 0) { sn_k_ic_col_ref(b, y, s, a, sat); return; }
    sn_k_st3q(a, _mm256_add_epi64(sn_k_ld3q(a), sn_k_ic_rshr(sn_k_ic_colp(b, _mm256_set1_epi32(y[0]), _mm256_set1_epi32(y[1]),
                                                                           _mm256_set1_epi32(y[2])), s))); /* no masked moves */
}
/* frac = b[18] >= 0 */
SN_INLINE void sn_k_ic_row(const unsigned char *b, const sn_q z[3], sn_acc l[4], uint32_t *sat) {
    (void)sat;
    _mm256_storeu_si256((__m256i *)(void *)l,
                        _mm256_add_epi64(_mm256_loadu_si256((const __m256i *)(const void *)l),
                                         sn_k_ic_rshr(sn_k_ic_rowp(b, _mm256_set1_epi32(z[0]), _mm256_set1_epi32(z[1]),
                                                                   _mm256_set1_epi32(z[2])), b[18])));
}

/* The sweeps' loops (sn_precond.c ic_forward / ic_backward), x86-64 round
 * 2: y_j's operands built once per column, the row's sum kept in a
 * register; the same integers as the per-block calls above. */
/* ic_forward's column j: acc_i += round(U_ji^T y_j, frac + k_j - k_i) over
 * the blocks at blk, their row indices at cols < cend, up to the first
 * i >= nF; returns the blocks read. */
#define SN_K_IC_FWD_RUN 1
/* y0..y2: y's entries as VPMULDQ operands. Always inlined: GCC kept it a
 * call from sn_precond.c's fused sweep (~40 instructions a vertex). */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
SN_INLINE uint32_t sn_k_ic_fwd_ops(const unsigned char *blk, const unsigned char *cols, const unsigned char *cend, __m256i y0,
                                   __m256i y1, __m256i y2, const sn_q y[3], int kj, const uint8_t *kk, uint32_t nF, sn_acc *acc,
                                   uint32_t *sat) {
    const unsigned char *c = cols;
    for (; c < cend; c += 2, blk += SN_ELEM_ICHOL) {
        const uint32_t i = sn_rd_u16(c);
        int s;
        if (i >= nF) break; /* skeleton columns: not in ICHOL */
        s = (int)blk[18] + kj - (int)kk[i];
        if (s < 0) sn_k_ic_col_ref(blk, y, s, acc + 3 * i, sat);
        else sn_k_st3q(acc + 3 * i, _mm256_add_epi64(sn_k_ld3q(acc + 3 * i), sn_k_ic_rshr(sn_k_ic_colp(blk, y0, y1, y2), s)));
    }
    return (uint32_t)(c - cols) / 2u;
}
SN_INLINE uint32_t sn_k_ic_fwd_run(const unsigned char *blk, const unsigned char *cols, const unsigned char *cend,
                                   const sn_q y[3], int kj, const uint8_t *kk, uint32_t nF, sn_acc *acc, uint32_t *sat) {
    return sn_k_ic_fwd_ops(blk, cols, cend, _mm256_set1_epi32(y[0]), _mm256_set1_epi32(y[1]), _mm256_set1_epi32(y[2]), y, kj,
                           kk, nF, acc, sat);
}
/* ic_backward's row: l = sum of round(U_e z_cols[e], frac_e) over nb blocks
 * (l[3] scratch) */
#define SN_K_IC_BWD_ROW 1
SN_INLINE void sn_k_ic_bwd_row(const unsigned char *b, const unsigned char *cols, uint32_t nb, const sn_q *z, sn_acc l[4],
                               uint32_t *sat) {
    __m256i a = _mm256_setzero_si256();
    uint32_t e;
    (void)sat;
    for (e = 0; e < nb; e++, b += SN_ELEM_ICHOL) {
        const sn_q *zi = z + 3 * sn_rd_u16(cols + 2 * e);
        a = _mm256_add_epi64(a, sn_k_ic_rshr(sn_k_ic_rowp(b, _mm256_set1_epi32(zi[0]), _mm256_set1_epi32(zi[1]),
                                                          _mm256_set1_epi32(zi[2])), b[18]));
    }
    _mm256_storeu_si256((__m256i *)(void *)l, a);
}
/* the same sum as lanes (lane 3: 0), z_i read as the int64 zq[3 i..3 i+2]
 * (|z_i| <= SN_LIM: VPMULDQ's low halves are the values) */
SN_INLINE __m256i sn_k_ic_bwd_rowq(const unsigned char *b, const unsigned char *cols, uint32_t nb, const sn_acc *zq) {
    __m256i a = _mm256_setzero_si256();
    uint32_t e;
    for (e = 0; e < nb; e++, b += SN_ELEM_ICHOL) {
        const sn_acc *zi = zq + 3 * sn_rd_u16(cols + 2 * e);
        a = _mm256_add_epi64(a, sn_k_ic_rshr(sn_k_ic_rowp(b, _mm256_set1_epi64x(zi[0]), _mm256_set1_epi64x(zi[1]),
                                                          _mm256_set1_epi64x(zi[2])), b[18]));
    }
    return a;
}
#undef SN_K_IC_W

#elif defined(SN_KERNELS_NEON)
#include <arm_neon.h>
/* The block widened to int32 (VMOVL), then as in sn_kernels_neon.c: VLD3
 * de-interleaves (U0,U3) (U1,U4) (U2,U5); lanes 0,1 by VMULL/VMLAL by
 * scalar, the third row/column as a pair product plus one scalar. VRSHL by
 * -s is the round-half-up shift of sn_rshr64 (no intermediate overflow). */
SN_INLINE void sn_k_ic_u32(const unsigned char *b, int32_t U[9]) {
    const int16x8_t v = vld1q_s16((const int16_t *)(const void *)b);
    vst1q_s32(U, vmovl_s16(vget_low_s16(v)));
    vst1q_s32(U + 4, vmovl_s16(vget_high_s16(v)));
    U[8] = sn_k_ic_i16(b + 16);
}

SN_INLINE void sn_k_ic_col(const unsigned char *b, const sn_q y[3], int s, sn_acc a[3], uint32_t *sat) {
    int32_t U[9];
    int64x2_t p;
    int64_t p2;
    if (s < 0) { sn_k_ic_col_ref(b, y, s, a, sat); return; }
    sn_k_ic_u32(b, U);
    p = vmull_n_s32(vld1_s32(U), y[0]);
    p = vmlal_n_s32(p, vld1_s32(U + 3), y[1]);
    p = vmlal_n_s32(p, vld1_s32(U + 6), y[2]);
    p2 = (int64_t)U[2] * y[0] + (int64_t)U[5] * y[1] + (int64_t)U[8] * y[2];
    vst1q_s64(a, vaddq_s64(vld1q_s64(a), vrshlq_s64(p, vdupq_n_s64(-s))));
    a[2] += sn_rshr64(p2, s);
}

SN_INLINE void sn_k_ic_row(const unsigned char *b, const sn_q z[3], sn_acc l[4], uint32_t *sat) {
    int32_t U[9];
    int32x2x3_t c;
    int64x2_t p, q;
    int s = b[18];
    (void)sat;
    sn_k_ic_u32(b, U);
    c = vld3_s32(U);
    p = vmull_n_s32(c.val[0], z[0]);
    p = vmlal_n_s32(p, c.val[1], z[1]);
    p = vmlal_n_s32(p, c.val[2], z[2]);
    q = vmull_s32(vld1_s32(U + 6), vld1_s32(z));
    vst1q_s64(l, vaddq_s64(vld1q_s64(l), vrshlq_s64(p, vdupq_n_s64(-s))));
    l[2] += sn_rshr64(vgetq_lane_s64(q, 0) + vgetq_lane_s64(q, 1) + (int64_t)U[8] * z[2], s);
}

#elif defined(SN_KERNELS_M4)
/* Cortex-M4: each row's sum starts from the rounding term 2^(s-1) (the
 * three SMLAL add onto it) and, for 0 < s < 32, the block's three rows
 * share the shift split over the two words: lo >> s | hi << (32 - s) and
 * hi >> s, the value of sn_rshr64 (the sum is exact, < 2^44.6 + 2^30, no
 * overflow). Other s (s < 0 scales up and clamps): the reference. */
/* out[k] += (2^(s-1) + sum_j U[ko k + ji j] v[j]) >> s over the block's 9
 * int16 entries (byte strides: column products ko 2, ji 6; row products ko
 * 6, ji 2) */
SN_INLINE void sn_k_ic_m4(const unsigned char *b, const sn_q v[3], int s, uint32_t ko, uint32_t ji, sn_acc out[3]) {
    const int64_t bias = (int64_t)((uint32_t)1 << (s - 1));
    const int32_t v0 = v[0], v1 = v[1], v2 = v[2];
    /* written out: GCC keeps a loop of 3 (+0.1 M a cow step) */
#define SN_K_IC_T(k) sn_shr64_w(bias + (int64_t)sn_k_ic_i16(b + (k) * ko) * v0 + \
                                (int64_t)sn_k_ic_i16(b + (k) * ko + ji) * v1 + (int64_t)sn_k_ic_i16(b + (k) * ko + 2 * ji) * v2, s)
    out[0] += SN_K_IC_T(0);
    out[1] += SN_K_IC_T(1);
    out[2] += SN_K_IC_T(2);
#undef SN_K_IC_T
}
SN_INLINE void sn_k_ic_col(const unsigned char *b, const sn_q y[3], int s, sn_acc a[3], uint32_t *sat) {
    if (s <= 0 || s >= 32) sn_k_ic_col_ref(b, y, s, a, sat);
    else sn_k_ic_m4(b, y, s, 2, 6, a);
}
SN_INLINE void sn_k_ic_row(const unsigned char *b, const sn_q z[3], sn_acc l[4], uint32_t *sat) {
    const int s = b[18];
    if (s <= 0 || s >= 32) sn_k_ic_row_ref(b, z, l, sat);
    else sn_k_ic_m4(b, z, s, 6, 2, l);
}
/* the backward sweep's row: sn_kernels_m4.c's Thumb-2 loop (sn_m4_ic_rows)
 * over the blocks with 0 < s < 32, from the first other block on
 * sn_m4_ic_rows_rest (the reference for such blocks) */
#define SN_K_IC_BWD_ROW 1
const unsigned char *sn_m4_ic_rows(const unsigned char *b, const unsigned char *cols, const unsigned char *end,
                                   const sn_q *z, sn_acc l[4]);
void sn_m4_ic_rows_rest(const unsigned char *b, const unsigned char *cols, const unsigned char *end, const sn_q *z,
                        sn_acc l[4], uint32_t *sat);
SN_INLINE void sn_k_ic_bwd_row(const unsigned char *b, const unsigned char *cols, uint32_t nb, const sn_q *z, sn_acc l[4],
                               uint32_t *sat) {
    const unsigned char *end = b + (size_t)nb * SN_ELEM_ICHOL, *p = sn_m4_ic_rows(b, cols, end, z, l);
    if (p != end) sn_m4_ic_rows_rest(p, cols + 2u * ((uint32_t)(p - b) / SN_ELEM_ICHOL), end, z, l, sat);
}

/* the forward sweep's column j (ic_forward): sn_kernels_m4.c's Thumb-2 loop
 * (sn_m4_ic_cols) over blk, cols < cend while the row i < nF, from the
 * first block with s = frac + kj - kk[i] outside 1..31 on
 * sn_m4_ic_cols_rest (the reference for such blocks). The struct is set
 * once per sweep (sn_k_ic_fwd_init), blk, cols, cend, kj and y per column;
 * sn_k_ic_fwd_col returns the blocks read (ic_forward's loop's count). */
#define SN_K_IC_FWD_COL 1
struct sn_m4_icc {
    const unsigned char *blk;  /* 0: the next block */
    const unsigned char *cols; /* 4: its row index (u16) */
    const unsigned char *cend; /* 8: the column's end in cols */
    const uint8_t *kk;         /* 12 */
    sn_acc *acc;               /* 16 */
    uint32_t nF;               /* 20 */
    int32_t kj;                /* 24: k_j */
    const sn_q *y;             /* 28: y_j */
};
int sn_m4_ic_cols(struct sn_m4_icc *c); /* 1: stopped at a block for the reference */
void sn_m4_ic_cols_rest(struct sn_m4_icc *c, uint32_t *sat);
SN_INLINE void sn_k_ic_fwd_init(struct sn_m4_icc *c, const uint8_t *kk, sn_acc *acc, uint32_t nF) {
    c->kk = kk;
    c->acc = acc;
    c->nF = nF;
}
SN_INLINE uint32_t sn_k_ic_fwd_col(struct sn_m4_icc *c, const unsigned char *blk, const unsigned char *cols,
                                   const unsigned char *cend, const sn_q y[3], int kj, uint32_t *sat) {
    c->blk = blk; c->cols = cols; c->cend = cend; c->kj = kj; c->y = y;
    if (sn_m4_ic_cols(c)) sn_m4_ic_cols_rest(c, sat);
    return (uint32_t)(c->cols - cols) / 2u;
}

/* the fused sweeps' vertex steps (sn_precond.c ic_fused) in Thumb-2
 * (sn_kernels_m4_ic.c): y_j = sn_out(R_j^T r_j - acc_j); and, for 0 < sh
 * < 32, z'_j = sn_out(sn_out(D_j^-1 y_j, sh) - l) to zq_j, z_j = R_j z'_j
 * (z_j holds y_j on entry); the C kernels' values and clamp counts */
#define SN_K_IC_VTX 1
void sn_m4_icf_y(const sn_q *R, const sn_q *r, const sn_acc *acc, sn_q *y, uint32_t *sat);
void sn_m4_icb_z(const unsigned char *P, sn_q *z, const sn_acc *l, sn_q *zq, const sn_q *R, int sh, uint32_t *sat);

#elif defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)
#include "sn_kernels_fsimd.h"
/* Float: U's rows (col) or columns (row) in lanes, decoded exactly as the
 * reference (int16 -> float, times 2^-frac: exact), the reference's
 * operations in its order per lane (sn_kernels_fsimd.h). AVX2: rows from
 * three 8-byte VPMOVSXWD loads (U0..3, U3..6, U6..9: inside the 20-byte
 * element; lane 3 junk), columns by the fixed path's byte shuffle; aarch64:
 * the 9 entries decoded to floats in memory, then the layer's loads. */
SN_INLINE float sn_k_ic_scale(const unsigned char *b) {
    uint32_t u = (uint32_t)(127 - b[18]) << 23; /* 2^-frac, as sn_k_ic_block */
    float s;
    memcpy(&s, &u, 4);
    return s;
}
#if defined(SN_KERNELS_FAVX2)
/* 2^-frac, frac = 0..SN_ICHOL_FRAC_MAX (sn_kernels_fsimd.c): one broadcast
 * load instead of forming the float's bits per block (x86-64 round 2) */
extern const float sn_k_ic_p2[63]; /* frac 0..62 */
#define SN_K_IC_S(b) _mm_broadcast_ss(&sn_k_ic_p2[(b)[18]])
#define SN_K_IC_F(v) _mm_cvtepi32_ps(_mm_cvtepi16_epi32(v))
SN_INLINE void sn_k_ic_rows(const unsigned char *b, sn_fv r[3]) {
    const sn_fv s = SN_K_IC_S(b);
    r[0] = FV_MUL(SN_K_IC_F(_mm_loadl_epi64((const __m128i *)(const void *)b)), s);
    r[1] = FV_MUL(SN_K_IC_F(_mm_loadl_epi64((const __m128i *)(const void *)(b + 6))), s);
    r[2] = FV_MUL(SN_K_IC_F(_mm_loadl_epi64((const __m128i *)(const void *)(b + 12))), s);
}
SN_INLINE void sn_k_ic_cols(const unsigned char *b, sn_fv c[3]) {
    const __m128i sh0 = _mm_setr_epi8(0, 1, 6, 7, 12, 13, 0, 1, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i sh1 = _mm_setr_epi8(2, 3, 8, 9, 14, 15, 2, 3, -1, -1, -1, -1, -1, -1, -1, -1);
    const __m128i v = _mm_loadu_si128((const __m128i *)(const void *)b);
    const __m128i w = _mm_loadu_si128((const __m128i *)(const void *)(b + 4));
    const sn_fv s = SN_K_IC_S(b);
    c[0] = FV_MUL(SN_K_IC_F(_mm_shuffle_epi8(v, sh0)), s);
    c[1] = FV_MUL(SN_K_IC_F(_mm_shuffle_epi8(v, sh1)), s);
    c[2] = FV_MUL(SN_K_IC_F(_mm_shuffle_epi8(w, sh0)), s);
}
#undef SN_K_IC_F
#else
SN_INLINE void sn_k_ic_f9(const unsigned char *b, float U[12]) {
    const int16x8_t v = vld1q_s16((const int16_t *)(const void *)b);
    const float32x4_t s = vdupq_n_f32(sn_k_ic_scale(b));
    vst1q_f32(U, vmulq_f32(vcvtq_f32_s32(vmovl_s16(vget_low_s16(v))), s));
    vst1q_f32(U + 4, vmulq_f32(vcvtq_f32_s32(vmovl_s16(vget_high_s16(v))), s));
    U[8] = (float)sn_k_ic_i16(b + 16) * vgetq_lane_f32(s, 0);
    U[9] = U[10] = U[11] = 0.0f;
}
SN_INLINE void sn_k_ic_rows(const unsigned char *b, sn_fv r[3]) {
    float U[12];
    sn_k_ic_f9(b, U);
    fv_rows(U, r);
}
SN_INLINE void sn_k_ic_cols(const unsigned char *b, sn_fv c[3]) {
    float U[12];
    sn_k_ic_f9(b, U);
    fv_cols(U, c);
}
#endif
/* a[c] += U[c] y0 + U[3+c] y1 + U[6+c] y2 (float: no rounding step) */
SN_INLINE void sn_k_ic_col(const unsigned char *b, const sn_q y[3], int s, sn_acc a[3], uint32_t *sat) {
    sn_fv r[3];
    (void)s; (void)sat;
    sn_k_ic_rows(b, r);
    fv_st3(a, FV_ADD(fv_ld3(a), FV_MAC3(r, FV_SET1(y[0]), FV_SET1(y[1]), FV_SET1(y[2]))));
}
/* l[r] += U[3r] z0 + U[3r+1] z1 + U[3r+2] z2; l has 4 entries */
SN_INLINE void sn_k_ic_row(const unsigned char *b, const sn_q z[3], sn_acc l[4], uint32_t *sat) {
    sn_fv c[3];
    (void)sat;
    sn_k_ic_cols(b, c);
    FV_ST4(l, FV_ADD(FV_LD4(l), FV_MAC3(c, FV_SET1(z[0]), FV_SET1(z[1]), FV_SET1(z[2]))));
}
#if defined(SN_KERNELS_FAVX2)
/* x86-64 round 2 (sn_precond.c ic_fused): ic_forward's column j with y_j's
 * lanes broadcast once (y0..y2), and ic_backward's row sum as lanes, z_i
 * read from zq (3 floats per vertex); each lane the reference's
 * ((p0 + p1) + p2) added to its accumulator in the reference's order. */
SN_INLINE uint32_t sn_k_ic_fwd_ops(const unsigned char *blk, const unsigned char *cols, const unsigned char *cend, sn_fv y0,
                                   sn_fv y1, sn_fv y2, uint32_t nF, sn_acc *acc) {
    const unsigned char *c = cols;
    for (; c < cend; c += 2, blk += SN_ELEM_ICHOL) {
        const uint32_t i = sn_rd_u16(c);
        sn_fv r[3];
        if (i >= nF) break; /* skeleton columns: not in ICHOL */
        sn_k_ic_rows(blk, r);
        fv_st3(acc + 3 * i, FV_ADD(fv_ld3(acc + 3 * i), FV_MAC3(r, y0, y1, y2)));
    }
    return (uint32_t)(c - cols) / 2u;
}
/* Two blocks at once in 8 lanes, [block e | block e+1]: each column by one
 * VPSHUFB putting the int16 in the high half of a 32-bit slot (VPSRAD 16
 * sign-extends: the VPMOVSXWD value) and the two scales 2^-frac from the
 * frac bytes (127 - frac) << 23, the same floats as sn_k_ic_cols; the two
 * row sums then added to l one after the other (l + A) + B, the
 * reference's order. */
SN_INLINE __m256 sn_k_ic_cols2(const unsigned char *b, __m256 c[3]) {
    const __m256i m0 = _mm256_setr_epi8(-1, -1, 0, 1, -1, -1, 6, 7, -1, -1, 12, 13, -1, -1, -1, -1,
                                        -1, -1, 0, 1, -1, -1, 6, 7, -1, -1, 12, 13, -1, -1, -1, -1);
    const __m256i m1 = _mm256_setr_epi8(-1, -1, 2, 3, -1, -1, 8, 9, -1, -1, 14, 15, -1, -1, -1, -1,
                                        -1, -1, 2, 3, -1, -1, 8, 9, -1, -1, 14, 15, -1, -1, -1, -1);
    const __m256i mf = _mm256_setr_epi8(14, -1, -1, -1, 14, -1, -1, -1, 14, -1, -1, -1, 14, -1, -1, -1,
                                        14, -1, -1, -1, 14, -1, -1, -1, 14, -1, -1, -1, 14, -1, -1, -1);
    const __m256i v = _mm256_inserti128_si256(_mm256_castsi128_si256(_mm_loadu_si128((const __m128i *)(const void *)b)),
                                              _mm_loadu_si128((const __m128i *)(const void *)(b + SN_ELEM_ICHOL)), 1);
    const __m256i w = _mm256_inserti128_si256(_mm256_castsi128_si256(_mm_loadu_si128((const __m128i *)(const void *)(b + 4))),
                                              _mm_loadu_si128((const __m128i *)(const void *)(b + SN_ELEM_ICHOL + 4)), 1);
    const __m256 sc = _mm256_castsi256_ps(
        _mm256_slli_epi32(_mm256_sub_epi32(_mm256_set1_epi32(127), _mm256_shuffle_epi8(w, mf)), 23)); /* b[18]: w's byte 14 */
    c[0] = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_shuffle_epi8(v, m0), 16)), sc);
    c[1] = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_shuffle_epi8(v, m1), 16)), sc);
    c[2] = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_shuffle_epi8(w, m0), 16)), sc);
    return sc;
}
#define SN_K_ZZ(p, q) _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_broadcast_ss(p)), _mm_broadcast_ss(q), 1)
/* a += each block's row sums, in order (from a = 0: the reference's l) */
#if defined(__GNUC__)
__attribute__((always_inline)) /* GCC made it a call once two callers had it */
#endif
SN_INLINE sn_fv sn_k_ic_bwd_acc(sn_fv a, const unsigned char *b, const unsigned char *cols, uint32_t nb, const sn_acc *zq) {
    uint32_t e = 0;
    for (; e + 2 <= nb; e += 2, b += 2 * SN_ELEM_ICHOL) {
        const sn_acc *z1 = zq + 3 * sn_rd_u16(cols + 2 * e), *z2 = zq + 3 * sn_rd_u16(cols + 2 * e + 2);
        __m256 c[3], p;
        (void)sn_k_ic_cols2(b, c);
        p = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(c[0], SN_K_ZZ(z1, z2)), _mm256_mul_ps(c[1], SN_K_ZZ(z1 + 1, z2 + 1))),
                          _mm256_mul_ps(c[2], SN_K_ZZ(z1 + 2, z2 + 2)));
        a = FV_ADD(FV_ADD(a, _mm256_castps256_ps128(p)), _mm256_extractf128_ps(p, 1));
    }
    for (; e < nb; e++, b += SN_ELEM_ICHOL) {
        const sn_acc *zi = zq + 3 * sn_rd_u16(cols + 2 * e);
        sn_fv c[3];
        sn_k_ic_cols(b, c);
        a = FV_ADD(a, FV_MAC3(c, FV_SET1(zi[0]), FV_SET1(zi[1]), FV_SET1(zi[2])));
    }
    return a;
}
SN_INLINE sn_fv sn_k_ic_bwd_rowv(const unsigned char *b, const unsigned char *cols, uint32_t nb, const sn_acc *zq) {
    return sn_k_ic_bwd_acc(FV_SET1(0.0f), b, cols, nb, zq); /* the reference's l = 0, then l += each block's row sums */
}
/* the same row with its first block's z taken from register zf when hf
 * (x86-64 round 4: z'_j+1, just computed by the backward sweep, enters row j
 * without a store and reload on the sweep's chain); the same pairs and
 * order, the same floats (zf holds zq's value) */
SN_INLINE sn_fv sn_k_ic_bwd_rowr(const unsigned char *b, const unsigned char *cols, uint32_t nb, const sn_acc *zq, sn_fv zf,
                                 int hf) {
    sn_fv a = FV_SET1(0.0f);
    const sn_fv f0 = _mm_permute_ps(zf, 0x00), f1 = _mm_permute_ps(zf, 0x55), f2 = _mm_permute_ps(zf, 0xAA);
    if (hf && nb >= 2) {
        const sn_acc *z2 = zq + 3 * sn_rd_u16(cols + 2);
        __m256 c[3], p;
        (void)sn_k_ic_cols2(b, c);
        p = _mm256_add_ps(
            _mm256_add_ps(_mm256_mul_ps(c[0], _mm256_insertf128_ps(_mm256_castps128_ps256(f0), _mm_broadcast_ss(z2), 1)),
                          _mm256_mul_ps(c[1], _mm256_insertf128_ps(_mm256_castps128_ps256(f1), _mm_broadcast_ss(z2 + 1), 1))),
            _mm256_mul_ps(c[2], _mm256_insertf128_ps(_mm256_castps128_ps256(f2), _mm_broadcast_ss(z2 + 2), 1)));
        a = FV_ADD(FV_ADD(a, _mm256_castps256_ps128(p)), _mm256_extractf128_ps(p, 1));
        return sn_k_ic_bwd_acc(a, b + 2 * SN_ELEM_ICHOL, cols + 4, nb - 2, zq);
    }
    if (hf) { /* nb == 1 */
        sn_fv c[3];
        sn_k_ic_cols(b, c);
        return FV_ADD(a, FV_MAC3(c, f0, f1, f2));
    }
    return sn_k_ic_bwd_rowv(b, cols, nb, zq);
}
#undef SN_K_ZZ
#endif

#else
#define sn_k_ic_col sn_k_ic_col_ref
#define sn_k_ic_row sn_k_ic_row_ref
#endif

/* l = sum of round(U_e z_cols[e]) over nb consecutive blocks (the backward
 * sweep's row j, its free columns: cols the row's LE u16 column indices;
 * l[3] scratch); the paths without their own (scalar, NEON, the float
 * flavour's): the loop of sn_k_ic_row from 0 */
#if !defined(SN_K_IC_BWD_ROW)
SN_INLINE void sn_k_ic_bwd_row(const unsigned char *b, const unsigned char *cols, uint32_t nb, const sn_q *z, sn_acc l[4],
                               uint32_t *sat) {
    uint32_t e;
    l[0] = l[1] = l[2] = l[3] = 0;
    for (e = 0; e < nb; e++, b += SN_ELEM_ICHOL) sn_k_ic_row(b, z + 3 * sn_rd_u16(cols + 2 * e), l, sat);
}
#endif

#endif /* SN_KERNELS_IC_H */
