/* sn_kernels_rot.h -- rotations into and out of the vertex and cell frames
 * (sn_solve.c, sn_precond.c): R^T v and R v rounded to Q of v (Q30 rotation,
 * round half up, clamp to +-SN_LIM, counted), and acc += R t unrounded.
 * Inline: one 3-vector per call, called per corner and per vertex.
 *
 *   sn_k_rot_t(R, v, out, sat)  = sn_rot_t   (sn_internal.h, the reference)
 *   sn_k_rot(R, v, out, sat)    = sn_rot
 *   sn_k_rot_acc(acc, R, t)     = sn_rot_acc (sn_instance.h)
 *
 * AVX2: the 3 results as int64 lanes (the 4th unused): R loaded as R0..R7
 * and R1..R8 (both inside the 9), VPERMD puts a column or row in the even
 * slots, VPMULDQ multiplies exactly. The sum |x| < 3 2^58 is rounded without
 * a 64-bit arithmetic shift: x + 2^29 + 2^62 is >= 0 and < 2^63, its logical
 * shift by 30 minus 2^32 is floor((x + 2^29) / 2^30), sn_rshr64's value;
 * then the same clamp and count. NEON: below. Same integers as the
 * reference (exact products, one rounding per output). Other paths: the
 * reference (the M4: narrowed to int32 before its clamp, below). Float:
 * AVX2 and aarch64 by sn_kernels_fsimd.h's lanes, the reference's bits. */
#ifndef SN_KERNELS_ROT_H
#define SN_KERNELS_ROT_H

#include "sn_kernels.h"
#include "sn_instance.h"

#if defined(SN_KERNELS_AVX2)
#include <immintrin.h>

#define SN_K_R8(p) _mm256_loadu_si256((const __m256i *)(const void *)(p))
/* 3 int64 without VPMASKMOVQ (microcoded, slow on AMD Zen): 16 + 8 bytes */
SN_INLINE __m256i sn_k_ld3q(const int64_t *p) {
    return _mm256_inserti128_si256(_mm256_castsi128_si256(_mm_loadu_si128((const __m128i *)(const void *)p)),
                                   _mm_loadl_epi64((const __m128i *)(const void *)(p + 2)), 1);
}
SN_INLINE void sn_k_st3q(int64_t *p, __m256i v) {
    _mm_storeu_si128((__m128i *)(void *)p, _mm256_castsi256_si128(v));
    _mm_storel_epi64((__m128i *)(void *)(p + 2), _mm256_extracti128_si256(v, 1));
}
/* lane k = sum_c R[i_c(k)] v[c]; i0, i1 index R0..R7, i2 indexes R1..R8 */
SN_INLINE __m256i sn_k_rot3(const sn_q *R, const sn_q v[3], __m256i i0, __m256i i1, __m256i i2) {
    const __m256i r0 = SN_K_R8(R), r1 = SN_K_R8(R + 1);
    return _mm256_add_epi64(
        _mm256_add_epi64(_mm256_mul_epi32(_mm256_permutevar8x32_epi32(r0, i0), _mm256_set1_epi32(v[0])),
                         _mm256_mul_epi32(_mm256_permutevar8x32_epi32(r0, i1), _mm256_set1_epi32(v[1]))),
        _mm256_mul_epi32(_mm256_permutevar8x32_epi32(r1, i2), _mm256_set1_epi32(v[2])));
}
/* nonzero where a lane may lie outside +-SN_LIM: (y + 2^28) >> 29 (logical)
 * is 0 exactly for y in [-2^28, 2^28) (y = 2^28 only takes the full path);
 * the full compares and blends run only then (x86-64 round 2) */
#define SN_K_INLIM(y) _mm256_testz_si256(_mm256_srli_epi64(_mm256_add_epi64((y), _mm256_set1_epi64x(SN_LIM)), 29), \
                                         _mm256_set1_epi64x(-1))
/* sn_out(x, SN_Q_ROT) per lane, lanes 0..2 (lane 3: 0, so that callers'
 * clamps of sums with it count nothing there) */
SN_INLINE __m256i sn_k_rot_rnd(__m256i x, uint32_t *sat) {
    const __m256i lim = _mm256_set1_epi64x(SN_LIM), nlim = _mm256_set1_epi64x(-(int64_t)SN_LIM);
    __m256i y = _mm256_sub_epi64(
        _mm256_srli_epi64(_mm256_add_epi64(x, _mm256_set1_epi64x(((int64_t)1 << 62) + ((int64_t)1 << (SN_Q_ROT - 1)))), SN_Q_ROT),
        _mm256_set1_epi64x((int64_t)1 << (62 - SN_Q_ROT)));
    __m256i hi, lo;
    int m;
    y = _mm256_blend_epi32(y, _mm256_setzero_si256(), 0xC0);
    if (SN_K_INLIM(y)) return y;
    hi = _mm256_cmpgt_epi64(y, lim);
    lo = _mm256_cmpgt_epi64(nlim, y);
    m = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_or_si256(hi, lo))) & 7;
    y = _mm256_blendv_epi8(_mm256_blendv_epi8(y, lim, hi), nlim, lo);
    if (m) *sat += (uint32_t)((m & 1) + (m >> 1 & 1) + (m >> 2)); /* rare */
    return y;
}
/* lanes 0..2 -> out: sn_out(x, SN_Q_ROT) each */
SN_INLINE void sn_k_rot_out(__m256i x, sn_q out[3], uint32_t *sat) {
    const __m256i y = sn_k_rot_rnd(x, sat);
    const __m128i o = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(y, _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0)));
    const int32_t o2 = _mm_extract_epi32(o, 2);
    _mm_storel_epi64((__m128i *)(void *)out, o); /* no VPMASKMOVD (see sn_k_st3q) */
    memcpy(out + 2, &o2, 4);
}
/* out = R^T v: lane k = R[k] v0 + R[3+k] v1 + R[6+k] v2 */
SN_INLINE void sn_k_rot_t(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    sn_k_rot_out(sn_k_rot3(R, v, _mm256_setr_epi32(0, 0, 1, 0, 2, 0, 0, 0), _mm256_setr_epi32(3, 0, 4, 0, 5, 0, 0, 0),
                           _mm256_setr_epi32(5, 0, 6, 0, 7, 0, 0, 0)),
                 out, sat);
}
/* out = R v: lane k = R[3k] v0 + R[3k+1] v1 + R[3k+2] v2 */
SN_INLINE __m256i sn_k_rot_x(const sn_q R[9], const sn_q v[3]) {
    return sn_k_rot3(R, v, _mm256_setr_epi32(0, 0, 3, 0, 6, 0, 0, 0), _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0),
                     _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0));
}
SN_INLINE void sn_k_rot(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    sn_k_rot_out(sn_k_rot_x(R, v), out, sat);
}
/* R^T v and R v from v's int64 lanes (x86-64 round 2: the IC(0) sweeps
 * rotate a vertex's value where they form it, sn_precond.c) */
SN_INLINE __m256i sn_k_rot3v(const sn_q *R, __m256i v, __m256i i0, __m256i i1, __m256i i2) {
    const __m256i r0 = SN_K_R8(R), r1 = SN_K_R8(R + 1);
    return _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(_mm256_permutevar8x32_epi32(r0, i0), _mm256_permute4x64_epi64(v, 0x00)),
                                             _mm256_mul_epi32(_mm256_permutevar8x32_epi32(r0, i1), _mm256_permute4x64_epi64(v, 0x55))),
                            _mm256_mul_epi32(_mm256_permutevar8x32_epi32(r1, i2), _mm256_permute4x64_epi64(v, 0xAA)));
}
/* sn_out(R^T v, SN_Q_ROT) as lanes (v in memory) */
SN_INLINE __m256i sn_k_rot_t4(const sn_q R[9], const sn_q v[3], uint32_t *sat) {
    return sn_k_rot_rnd(sn_k_rot3(R, v, _mm256_setr_epi32(0, 0, 1, 0, 2, 0, 0, 0), _mm256_setr_epi32(3, 0, 4, 0, 5, 0, 0, 0),
                                  _mm256_setr_epi32(5, 0, 6, 0, 7, 0, 0, 0)),
                        sat);
}
/* out = sn_out(R v, SN_Q_ROT), v as lanes */
SN_INLINE void sn_k_rot4(const sn_q R[9], __m256i v, sn_q out[3], uint32_t *sat) {
    sn_k_rot_out(sn_k_rot3v(R, v, _mm256_setr_epi32(0, 0, 3, 0, 6, 0, 0, 0), _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0),
                            _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0)),
                 out, sat);
}
/* acc += R t (int64, masked to the 3 entries) */
SN_INLINE void sn_k_rot_acc(sn_acc acc[3], const sn_q *R, const sn_q t[3]) {
    sn_k_st3q(acc, _mm256_add_epi64(sn_k_ld3q(acc), sn_k_rot_x(R, t)));
}
#undef SN_K_R8

#elif defined(SN_KERNELS_NEON)
#include <arm_neon.h>
/* NEON (aarch64 and ARMv7): lanes 0-1 in an int64x2 by VMULL/VMLAL by
 * scalar, lane 2 scalar. VRSHR #30 is the round half up of sn_rshr64; the
 * result fits int32 (|x| < 3 2^58), so VMOVN, then the clamp and its count
 * in int32 (ARMv7 NEON has no 64-bit compare). */
SN_INLINE void sn_k_rot_out2(int64x2_t x01, int64_t x2, sn_q out[3], uint32_t *sat) {
    const int32x2_t lim = vdup_n_s32(SN_LIM), nlim = vdup_n_s32(-SN_LIM);
    const int32x2_t q = vmovn_s64(vrshrq_n_s64(x01, SN_Q_ROT));
    const uint32x2_t over = vorr_u32(vcgt_s32(q, lim), vclt_s32(q, nlim));
    *sat += (vget_lane_u32(over, 0) & 1u) + (vget_lane_u32(over, 1) & 1u);
    vst1_s32(out, vmax_s32(vmin_s32(q, lim), nlim));
    out[2] = sn_out(x2, SN_Q_ROT, sat);
}
/* out = R^T v: lanes (R0,R1) v0 + (R3,R4) v1 + (R6,R7) v2 */
SN_INLINE void sn_k_rot_t(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    int64x2_t x = vmull_n_s32(vld1_s32(R), v[0]);
    x = vmlal_n_s32(x, vld1_s32(R + 3), v[1]);
    x = vmlal_n_s32(x, vld1_s32(R + 6), v[2]);
    sn_k_rot_out2(x, sn_mul(R[2], v[0]) + sn_mul(R[5], v[1]) + sn_mul(R[8], v[2]), out, sat);
}
/* R v: VLD3 de-interleaves (R0,R3) (R1,R4) (R2,R5); row 2 scalar */
SN_INLINE int64x2_t sn_k_rot_x01(const sn_q R[9], const sn_q v[3]) {
    const int32x2x3_t c = vld3_s32(R);
    int64x2_t x = vmull_n_s32(c.val[0], v[0]);
    x = vmlal_n_s32(x, c.val[1], v[1]);
    return vmlal_n_s32(x, c.val[2], v[2]);
}
SN_INLINE void sn_k_rot(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    const int64x2_t x = sn_k_rot_x01(R, v);
    sn_k_rot_out2(x, sn_mul(R[6], v[0]) + sn_mul(R[7], v[1]) + sn_mul(R[8], v[2]), out, sat);
}
SN_INLINE void sn_k_rot_acc(sn_acc acc[3], const sn_q *R, const sn_q t[3]) {
    vst1q_s64(acc, vaddq_s64(vld1q_s64(acc), sn_k_rot_x01(R, t)));
    acc[2] += sn_mul(R[6], t[0]) + sn_mul(R[7], t[1]) + sn_mul(R[8], t[2]);
}

#elif defined(SN_KERNELS_M4)
/* Cortex-M4: the rounded sum narrowed to int32 before the clamp, as the
 * SIMD paths do (|x| < 3 2^58, so |x / 2^30| < 3 2^28: exact): 32-bit
 * compares instead of 64-bit pairs (cow step -0.8%; on x86-64 the same C
 * costs +0.4%, so other scalar paths keep the reference). */
SN_INLINE sn_q sn_k_rot_out1(int64_t x, uint32_t *sat) {
    int32_t v;
    SN_RANGE(x < 3 * ((int64_t)1 << 58) && x > -3 * ((int64_t)1 << 58), "frame rotation sum beyond 3 2^58", x);
    v = (int32_t)sn_rshr64(x, SN_Q_ROT);
    if ((uint32_t)v + (uint32_t)SN_LIM <= 2u * (uint32_t)SN_LIM) return v; /* |v| <= SN_LIM: one unsigned compare */
    (*sat)++;
    return v > 0 ? SN_LIM : -SN_LIM;
}
/* Written out, v in int32 registers (an empty asm: GCC otherwise kept
 * the int64 a clamped v came from, or hoisted v's sign extensions out of a
 * loop of 3, and multiplied 64 x 64: UMULL, MUL, MLA a term, not one
 * SMLAL). */
#define SN_K_I32(v0, v1, v2) __asm__("" : "+r"(v0), "+r"(v1), "+r"(v2))
SN_INLINE void sn_k_rot_t(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    int32_t v0 = v[0], v1 = v[1], v2 = v[2];
    SN_K_I32(v0, v1, v2);
    out[0] = sn_k_rot_out1(sn_mul(R[0], v0) + sn_mul(R[3], v1) + sn_mul(R[6], v2), sat);
    out[1] = sn_k_rot_out1(sn_mul(R[1], v0) + sn_mul(R[4], v1) + sn_mul(R[7], v2), sat);
    out[2] = sn_k_rot_out1(sn_mul(R[2], v0) + sn_mul(R[5], v1) + sn_mul(R[8], v2), sat);
}
SN_INLINE void sn_k_rot(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    int32_t v0 = v[0], v1 = v[1], v2 = v[2];
    SN_K_I32(v0, v1, v2);
    out[0] = sn_k_rot_out1(sn_mul(R[0], v0) + sn_mul(R[1], v1) + sn_mul(R[2], v2), sat);
    out[1] = sn_k_rot_out1(sn_mul(R[3], v0) + sn_mul(R[4], v1) + sn_mul(R[5], v2), sat);
    out[2] = sn_k_rot_out1(sn_mul(R[6], v0) + sn_mul(R[7], v1) + sn_mul(R[8], v2), sat);
}
#define sn_k_rot_acc sn_rot_acc
/* sn_out(l, s) for 0 < s < 32, bit = 2^(s-1): the rounding add's carry and
 * the shift on the two words (sn_rshr64_var's form), the clamp as the low
 * word within +-SN_LIM and the high word its sign (sn_k_axpy's test); an
 * int32 result without 64-bit compares. The same value and count. */
SN_INLINE int32_t sn_k_out_w(sn_acc l, int s, uint32_t bit, uint32_t *sat) {
    const int64_t r = l + (int64_t)bit; /* ADDS, ADC (a carry by compare cost GCC 4) */
    const uint32_t lo0 = (uint32_t)r;
    const int32_t hi0 = (int32_t)(r >> 32);
    const uint32_t lo = (lo0 >> s) | ((uint32_t)hi0 << (32 - s));
    const int32_t hi = hi0 >> s;
    SN_RANGE(l <= (int64_t)6521908912666391106 && l >= -(int64_t)6521908912666391106, /* 2^62.5, as sn_out */
             "accumulator beyond 2^62.5 reaches sn_out", l);
    if (lo + (uint32_t)SN_LIM <= 2u * (uint32_t)SN_LIM && hi == (int32_t)lo >> 31) return (int32_t)lo;
    (*sat)++;
    return hi < 0 ? -SN_LIM : SN_LIM;
}
/* the same for 32 <= s <= 62, 2^(s-1) = bhi 2^32 + blo: the value is the
 * high word after the rounding add, shifted by s - 32 (the low word only
 * carries), an int32 (|l| < 2^62.5) */
SN_INLINE int32_t sn_k_out_hw(sn_acc l, int s, uint32_t blo, int32_t bhi, uint32_t *sat) {
    const int32_t v = (int32_t)((l + (int64_t)(((uint64_t)(uint32_t)bhi << 32) | blo)) >> 32) >> (s - 32);
    SN_RANGE(l <= (int64_t)6521908912666391106 && l >= -(int64_t)6521908912666391106, /* 2^62.5, as sn_out */
             "accumulator beyond 2^62.5 reaches sn_out", l);
    if ((uint32_t)v + (uint32_t)SN_LIM <= 2u * (uint32_t)SN_LIM) return v;
    (*sat)++;
    return v > 0 ? SN_LIM : -SN_LIM;
}

#elif defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)
#include "sn_kernels_fsimd.h"
/* Float (sn_kernels_fsimd.h): lane k is the reference's output k, the
 * same operations in the same order, through sn_out's clamp and count. */
SN_INLINE void sn_k_rot_t(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    sn_fv r[3];
    fv_rows(R, r); /* lane k: R[k] v0 + R[3+k] v1 + R[6+k] v2 */
    fv_st3(out, fv_out3(FV_MAC3(r, FV_SET1(v[0]), FV_SET1(v[1]), FV_SET1(v[2])), sat));
}
SN_INLINE void sn_k_rot(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    sn_fv c[3];
    fv_cols(R, c); /* lane k: R[3k] v0 + R[3k+1] v1 + R[3k+2] v2 */
    fv_st3(out, fv_out3(FV_MAC3(c, FV_SET1(v[0]), FV_SET1(v[1]), FV_SET1(v[2])), sat));
}
SN_INLINE void sn_k_rot_acc(sn_acc acc[3], const sn_q *R, const sn_q t[3]) {
    sn_fv c[3];
    fv_cols(R, c);
    fv_st3(acc, FV_ADD(fv_ld3(acc), FV_MAC3(c, FV_SET1(t[0]), FV_SET1(t[1]), FV_SET1(t[2]))));
}
#else
#define sn_k_rot_t sn_rot_t
#define sn_k_rot sn_rot
#define sn_k_rot_acc sn_rot_acc
#endif

/* Helpers of the per-corner loops (sn_solve.c), written on the kernels above:
 *   sn_k_out_rot_acc(acc, R, l, sh, sat): t = sn_out(l, sh) per entry, acc += R t
 *   sn_k_sub3(x, y, out, sat): out = sn_add(x, -y) per entry
 *   sn_k_sub3a(x, y, sat): x = sn_out(x - y, 0) per entry (y accumulators)
 *   sn_k_add3(x, y, out, sat): out = sn_add(x, y); sn_k_coef3(x, c, out, sat): out = coef(x, c)
 *   sn_k_sub3r(sec, ia, ib, out, sat): out = sn_add(real ia + c, -real ib + c) of a blob section
 *   sn_k_sym_out(b, e, out, sh, sat): out = sn_out(0 + D e, sh), D the
 *     symmetric block of 6 reals at b (xx yy zz xy xz yz; sn_precond.c)
 * Float SIMD paths: lanes as in sn_kernels_fsimd.h (the same floats and
 * counts); fixed AVX2 / AVX-512: int64 lanes (sn_k_out4, the same integers
 * and counts); every other path: the reference loops. */
#if defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)
#if defined(SN_KERNELS_FAVX2)
#define SN_K_LANE(v, k) _mm_permute_ps((v), _MM_SHUFFLE(k, k, k, k))
#define SN_K_NEG(v) _mm_xor_ps((v), _mm_set1_ps(-0.0f))
#else
#define SN_K_LANE(v, k) vdupq_laneq_f32((v), (k))
#define SN_K_NEG(v) vnegq_f32(v)
#endif
SN_INLINE void sn_k_out_rot_acc(sn_acc acc[3], const sn_q *R, const sn_acc l[3], int sh, uint32_t *sat) {
    sn_fv c[3];
    const sn_fv t = fv_out3(fv_ld3(l), sat);
    (void)sh;
    fv_cols(R, c);
    fv_st3(acc, FV_ADD(fv_ld3(acc), FV_MAC3(c, SN_K_LANE(t, 0), SN_K_LANE(t, 1), SN_K_LANE(t, 2))));
}
SN_INLINE void sn_k_sub3(const sn_q x[3], const sn_q y[3], sn_q out[3], uint32_t *sat) {
    fv_st3(out, fv_out3(FV_ADD(fv_ld3(x), SN_K_NEG(fv_ld3(y))), sat));
}
SN_INLINE void sn_k_sub3a(sn_q x[3], const sn_acc y[3], uint32_t *sat) {
    fv_st3(x, fv_out3(FV_SUB(fv_ld3(x), fv_ld3(y)), sat));
}
SN_INLINE void sn_k_add3(const sn_q x[3], const sn_q y[3], sn_q out[3], uint32_t *sat) {
    fv_st3(out, fv_out3(FV_ADD(fv_ld3(x), fv_ld3(y)), sat));
}
SN_INLINE void sn_k_sub3r(const unsigned char *sec, uint32_t ia, uint32_t ib, sn_q out[3], uint32_t *sat) {
    const float *f = (const float *)(const void *)sec; /* float blob reals, little-endian host */
    fv_st3(out, fv_out3(FV_ADD(fv_ld3(f + ia), SN_K_NEG(fv_ld3(f + ib))), sat));
}
SN_INLINE void sn_k_coef3(const sn_q x[3], sn_q c, sn_q out[3], uint32_t *sat) {
    fv_st3(out, fv_out3(FV_MUL(fv_ld3(x), FV_SET1(c)), sat));
}
/* the symmetric block's columns (xx xy xz) (xy yy yz) (xz yz zz) */
SN_INLINE void sn_k_sym_cols(const unsigned char *b, sn_fv c[3]) {
#if defined(SN_KERNELS_FAVX2)
    const __m256 v = _mm256_insertf128_ps(_mm256_castps128_ps256(FV_LD4(b)), FV_LD4(b + 8), 1); /* xx yy zz xy zz xy xz yz */
    c[0] = FV_PERM(v, 0, 3, 6);
    c[1] = FV_PERM(v, 3, 1, 7);
    c[2] = FV_PERM(v, 6, 7, 2);
#else
    const float32x4_t lo = FV_LD4(b);              /* xx yy zz xy */
    const float32x4_t hi = FV_LD4(b + 8);          /* zz xy xz yz */
    const float32x4_t t = vextq_f32(hi, hi, 1);    /* xy xz yz zz */
    c[0] = vsetq_lane_f32(vgetq_lane_f32(lo, 0), vextq_f32(lo, t, 3), 0); /* xy xy xz yz -> xx xy xz yz */
    c[1] = vsetq_lane_f32(vgetq_lane_f32(lo, 1), t, 1);                    /* xy yy yz zz */
    c[2] = vextq_f32(t, t, 1);                                             /* xz yz zz xy */
#endif
}
SN_INLINE void sn_k_sym_out(const unsigned char *b, const sn_q e[3], sn_q out[3], int sh, uint32_t *sat) {
    sn_fv c[3];
    (void)sh;
    sn_k_sym_cols(b, c);
    fv_st3(out, fv_out3(FV_ADD(FV_SET1(0.0f), FV_MAC3(c, FV_SET1(e[0]), FV_SET1(e[1]), FV_SET1(e[2]))), sat));
}
#if defined(SN_KERNELS_FAVX2)
/* cell_forces' elastic energy term: ec = sum over k = 3..23 of
 * d[k] sn_out(l[k]) added in k order (x86-64 round 2): the clamps and
 * products 8 at a time (the same floats; lanes 0..2 neither counted nor
 * summed), the sum in the reference's order. */
#define SN_K_ENERGY24 1
SN_INLINE sn_acc sn_k_energy24(const sn_q d[24], const sn_acc l[24], int s, uint32_t *sat) {
    const __m256 lim = _mm256_set1_ps(SN_FLIM), nlim = _mm256_set1_ps(-SN_FLIM);
    float p[24];
    sn_acc ec = 0;
    uint32_t k;
    (void)s;
    for (k = 0; k < 24; k += 8) {
        const __m256 x = _mm256_loadu_ps(l + k);
        const __m256 hi = _mm256_cmp_ps(x, lim, _CMP_GT_OQ), lo = _mm256_cmp_ps(x, nlim, _CMP_LT_OQ);
        const __m256 nan = _mm256_cmp_ps(x, x, _CMP_UNORD_Q);
        const int m = _mm256_movemask_ps(_mm256_or_ps(_mm256_or_ps(hi, lo), nan)) & (k ? 0xFF : 0xF8);
        if (m) *sat += (uint32_t)((0x4332322132212110ull >> (4 * (m & 15)) & 15u) + (0x4332322132212110ull >> (4 * (m >> 4)) & 15u)); /* rare */
        _mm256_storeu_ps(p + k, _mm256_mul_ps(_mm256_loadu_ps(d + k),
                                              _mm256_andnot_ps(nan, _mm256_blendv_ps(_mm256_blendv_ps(x, lim, hi), nlim, lo))));
    }
#pragma GCC unroll 24
    for (k = 3; k < 24; k++) ec += p[k]; /* unrolled: 21 adds from memory (x86-64 round 3) */
    return ec;
}
/* cell_forces' corner (sn_solve.c; x86-64 round 2): t = sn_add(p_a, -p_0),
 * s = sn_add(w_a, -w_0), uu = sn_out(R^T s), d = sn_add(sn_out(R^T t),
 * -sn_add(x_a, -x_0)) (x: the blob's rest positions at reals ia, ib), kept
 * in registers between the steps; the reference's floats and counts. */
/* A cell's frame as rows (R^T v, sn_k_rot_t) and columns (R v,
 * sn_k_out_rot_acc) once for its corners (x86-64 round 2): the same floats. */
#define SN_K_ROTM 1
typedef struct { sn_fv r[3], c[3]; } sn_k_rotm;
SN_INLINE void sn_k_rotm_ld(sn_k_rotm *m, const sn_q *R) {
    fv_rows(R, m->r); /* lane k: R[k] v0 + R[3+k] v1 + R[6+k] v2 */
    fv_cols(R, m->c); /* lane k: R[3k] v0 + R[3k+1] v1 + R[3k+2] v2 */
}
SN_INLINE void sn_k_rot_t_m(const sn_k_rotm *m, const sn_q v[3], sn_q out[3], uint32_t *sat) {
    fv_st3(out, fv_out3(FV_MAC3(m->r, FV_SET1(v[0]), FV_SET1(v[1]), FV_SET1(v[2])), sat));
}
SN_INLINE void sn_k_out_rot_acc_m(sn_acc acc[3], const sn_k_rotm *m, const sn_acc l[3], int sh, uint32_t *sat) {
    const sn_fv t = fv_out3(fv_ld3(l), sat);
    (void)sh;
    fv_st3(acc, FV_ADD(fv_ld3(acc), FV_MAC3(m->c, SN_K_LANE(t, 0), SN_K_LANE(t, 1), SN_K_LANE(t, 2))));
}
/* A cell's free corners (index < nF) as bits 0..7 (x86-64 round 3): the
 * 8 little-endian u16 indices of its CELLS record (16 bytes) compared at
 * once, unsigned (a <= nF - 1 as min(a, nF - 1) == a). */
#define SN_K_FREE8 1
SN_INLINE uint32_t sn_k_free8(const unsigned char *cl, uint32_t nF) {
    const __m128i v = _mm_loadu_si128((const __m128i *)(const void *)cl);
    const __m128i m = _mm_cmpeq_epi16(_mm_min_epu16(v, _mm_set1_epi16((short)(uint16_t)(nF - 1u))), v);
    return nF ? (uint32_t)_mm_movemask_epi8(_mm_packs_epi16(m, _mm_setzero_si128())) : 0u;
}
/* cell_forces' corner row out (sn_solve.c): acc += R sn_out(ld + lu), the
 * cut level's and details' shares 0 (added as +0, as the reference's loop
 * does: the sum's signed zero) */
SN_INLINE void sn_k_out_rot_acc2_m(sn_acc acc[3], const sn_k_rotm *m, const sn_acc ld[3], const sn_acc lu[3], uint32_t *sat) {
    const sn_fv z = FV_SET1(0.0f);
    const sn_fv t = fv_out3(FV_ADD(FV_ADD(FV_ADD(fv_ld3(ld), fv_ld3(lu)), z), z), sat);
    fv_st3(acc, FV_ADD(fv_ld3(acc), FV_MAC3(m->c, SN_K_LANE(t, 0), SN_K_LANE(t, 1), SN_K_LANE(t, 2))));
}
/* sn_k_corner (below) with corner 0's operands (p_0, w_0, x_0) loaded once
 * per cell (x86-64 round 3: the stores of d and uu kept GCC from hoisting
 * them); the same floats and counts */
#define SN_K_CORNER0 1
typedef struct { sn_fv p0, w0, x0; } sn_k_c0;
SN_INLINE void sn_k_c0_ld(sn_k_c0 *c, const sn_q *p0, const sn_q *w0, const unsigned char *rest, uint32_t ib) {
    c->p0 = SN_K_NEG(fv_ld3(p0));
    c->w0 = SN_K_NEG(fv_ld3(w0));
    c->x0 = SN_K_NEG(fv_ld3((const float *)(const void *)rest + ib));
}
SN_INLINE void sn_k_corner_c0(const sn_k_rotm *m, const sn_k_c0 *c0, const sn_q *pa, const sn_q *wa, const unsigned char *rest,
                              uint32_t ia, sn_q d[3], sn_q uu[3], uint32_t *sat) {
    const float *f = (const float *)(const void *)rest; /* float blob reals, little-endian host */
    const sn_fv *r = m->r;
    sn_fv t, x;
#if defined(SN_KERNELS_FAVX2)
    { /* the six values without their sn_out and one test (x86-64 round 4):
       * when no lane clamps, sn_out leaves every one, so these are the
       * values below; otherwise the steps below */
        const sn_fv t1 = FV_ADD(fv_ld3(wa), c0->w0), t2 = FV_ADD(fv_ld3(pa), c0->p0);
        const sn_fv u = FV_MAC3(r, SN_K_LANE(t1, 0), SN_K_LANE(t1, 1), SN_K_LANE(t1, 2));
        const sn_fv l = FV_MAC3(r, SN_K_LANE(t2, 0), SN_K_LANE(t2, 1), SN_K_LANE(t2, 2));
        const sn_fv x1 = FV_ADD(fv_ld3(f + ia), c0->x0), d1 = FV_ADD(l, SN_K_NEG(x1));
        const sn_fv bad = _mm_or_ps(_mm_or_ps(_mm_or_ps(FV_BAD(t1), FV_BAD(t2)), _mm_or_ps(FV_BAD(u), FV_BAD(l))),
                                    _mm_or_ps(FV_BAD(x1), FV_BAD(d1)));
        if (!(_mm_movemask_ps(bad) & 7)) {
            fv_st3(uu, u);
            fv_st3(d, d1);
            return;
        }
    }
#endif
    t = fv_out3(FV_ADD(fv_ld3(wa), c0->w0), sat);
    fv_st3(uu, fv_out3(FV_MAC3(r, SN_K_LANE(t, 0), SN_K_LANE(t, 1), SN_K_LANE(t, 2)), sat));
    t = fv_out3(FV_ADD(fv_ld3(pa), c0->p0), sat);
    t = fv_out3(FV_MAC3(r, SN_K_LANE(t, 0), SN_K_LANE(t, 1), SN_K_LANE(t, 2)), sat);
    x = fv_out3(FV_ADD(fv_ld3(f + ia), c0->x0), sat);
    fv_st3(d, fv_out3(FV_ADD(t, SN_K_NEG(x)), sat));
}
#define SN_K_CORNER 1
SN_INLINE void sn_k_corner(const sn_k_rotm *m, const sn_q *pa, const sn_q *p0, const sn_q *wa, const sn_q *w0, const unsigned char *rest,
                           uint32_t ia, uint32_t ib, sn_q d[3], sn_q uu[3], uint32_t *sat) {
    const float *f = (const float *)(const void *)rest; /* float blob reals, little-endian host */
    const sn_fv *r = m->r;
    sn_fv t, x;
    t = fv_out3(FV_ADD(fv_ld3(wa), SN_K_NEG(fv_ld3(w0))), sat);
    fv_st3(uu, fv_out3(FV_MAC3(r, SN_K_LANE(t, 0), SN_K_LANE(t, 1), SN_K_LANE(t, 2)), sat));
    t = fv_out3(FV_ADD(fv_ld3(pa), SN_K_NEG(fv_ld3(p0))), sat);
    t = fv_out3(FV_MAC3(r, SN_K_LANE(t, 0), SN_K_LANE(t, 1), SN_K_LANE(t, 2)), sat);
    x = fv_out3(FV_ADD(fv_ld3(f + ia), SN_K_NEG(fv_ld3(f + ib))), sat);
    fv_st3(d, fv_out3(FV_ADD(t, SN_K_NEG(x)), sat));
}
#endif
#elif defined(SN_KERNELS_AVX2)
/* Fixed AVX2 (and AVX-512): the helpers on int64 lanes (the 4th lane 0 or
 * unused, never stored). sn_k_out4 is sn_out per lane with shift s (0..62
 * per int64 lane; a negative shift is passed as 0, sn_rshr64's "s <= 0:
 * x"): y = x + 2^(s-1) (VPSLLVQ of 1 by s - 1: s = 0 wraps to a count >= 64,
 * 0), floor(y / 2^s) as (y ^ m) >> s ^ m with m y's sign (AVX2 has no
 * 64-bit arithmetic shift), the clamp to +-SN_LIM and its count (a nibble
 * table of the 4-bit mask). |x| < 2^62.5 (sn_out's contract): no overflow.
 * The same integers and counts as the reference loops below. */
SN_INLINE uint32_t sn_k_cnt4(int m) { return (uint32_t)(0x4332322132212110ull >> (4 * m) & 15u); }
#if defined(__AVX512F__) && defined(__AVX512VL__) /* compares into mask registers, VPMINSQ/VPMAXSQ, VPSRAVQ */
SN_INLINE __m256i sn_k_clamp4(__m256i y, uint32_t *sat) {
    const __m256i lim = _mm256_set1_epi64x(SN_LIM), nlim = _mm256_set1_epi64x(-(int64_t)SN_LIM);
    const int m = (int)(_mm256_cmpgt_epi64_mask(y, lim) | _mm256_cmpgt_epi64_mask(nlim, y));
    if (m) *sat += sn_k_cnt4(m); /* rare */
    return _mm256_max_epi64(_mm256_min_epi64(y, lim), nlim);
}
SN_INLINE __m256i sn_k_out4(__m256i x, __m256i s, uint32_t *sat) {
    const __m256i one = _mm256_set1_epi64x(1);
    return sn_k_clamp4(_mm256_srav_epi64(_mm256_add_epi64(x, _mm256_sllv_epi64(one, _mm256_sub_epi64(s, one))), s), sat);
}
#else
SN_INLINE __m256i sn_k_clamp4(__m256i y, uint32_t *sat) {
    const __m256i lim = _mm256_set1_epi64x(SN_LIM), nlim = _mm256_set1_epi64x(-(int64_t)SN_LIM);
    __m256i hi, lo;
    if (SN_K_INLIM(y)) return y;
    hi = _mm256_cmpgt_epi64(y, lim);
    lo = _mm256_cmpgt_epi64(nlim, y);
    const int m = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_or_si256(hi, lo)));
    if (m) *sat += sn_k_cnt4(m); /* rare */
    return _mm256_blendv_epi8(_mm256_blendv_epi8(y, lim, hi), nlim, lo);
}
SN_INLINE __m256i sn_k_out4(__m256i x, __m256i s, uint32_t *sat) {
    const __m256i one = _mm256_set1_epi64x(1);
    const __m256i y = _mm256_add_epi64(x, _mm256_sllv_epi64(one, _mm256_sub_epi64(s, one)));
    const __m256i m = _mm256_cmpgt_epi64(_mm256_setzero_si256(), y);
    return sn_k_clamp4(_mm256_xor_si256(_mm256_srlv_epi64(_mm256_xor_si256(y, m), s), m), sat);
}
#endif
SN_INLINE __m256i sn_k_sh4(int sh) { return _mm256_set1_epi64x(sh < 0 ? 0 : sh); }
/* 3 int32 as int64 lanes (lane 3: 0), and back (lanes 0..2; no masked moves, as sn_k_st3q) */
SN_INLINE __m256i sn_k_ld3d(const void *p) {
    int32_t z;
    memcpy(&z, (const unsigned char *)p + 8, 4);
    return _mm256_cvtepi32_epi64(_mm_insert_epi32(_mm_loadl_epi64((const __m128i *)p), z, 2));
}
SN_INLINE __m128i sn_k_pack4(__m256i v) {
    return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0)));
}
SN_INLINE void sn_k_st3d(sn_q *p, __m256i v) {
    const __m128i o = sn_k_pack4(v);
    const int32_t o2 = _mm_extract_epi32(o, 2);
    _mm_storel_epi64((__m128i *)(void *)p, o);
    memcpy(p + 2, &o2, 4);
}
SN_INLINE void sn_k_out_rot_acc(sn_acc acc[3], const sn_q *R, const sn_acc l[3], int sh, uint32_t *sat) {
    const __m256i t = sn_k_out4(sn_k_ld3q(l), sn_k_sh4(sh), sat); /* lane 3: 0 */
    const __m256i r0 = _mm256_loadu_si256((const __m256i *)(const void *)R);
    const __m256i r1 = _mm256_loadu_si256((const __m256i *)(const void *)(R + 1));
    const __m256i ic0 = _mm256_setr_epi32(0, 0, 3, 0, 6, 0, 0, 0), ic1 = _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0);
    const __m256i x = _mm256_add_epi64(
        _mm256_add_epi64(_mm256_mul_epi32(_mm256_permutevar8x32_epi32(r0, ic0), _mm256_permute4x64_epi64(t, 0x00)),
                         _mm256_mul_epi32(_mm256_permutevar8x32_epi32(r0, ic1), _mm256_permute4x64_epi64(t, 0x55))),
        _mm256_mul_epi32(_mm256_permutevar8x32_epi32(r1, ic1), _mm256_permute4x64_epi64(t, 0xAA)));
    sn_k_st3q(acc, _mm256_add_epi64(sn_k_ld3q(acc), x)); /* acc += R t */
}
SN_INLINE void sn_k_sub3(const sn_q x[3], const sn_q y[3], sn_q out[3], uint32_t *sat) {
    sn_k_st3d(out, sn_k_clamp4(_mm256_sub_epi64(sn_k_ld3d(x), sn_k_ld3d(y)), sat));
}
SN_INLINE void sn_k_sub3r(const unsigned char *sec, uint32_t ia, uint32_t ib, sn_q out[3], uint32_t *sat) {
    /* fixed blob reals: little-endian int32 (x86) */
    sn_k_st3d(out, sn_k_clamp4(_mm256_sub_epi64(sn_k_ld3d(sec + 4u * ia), sn_k_ld3d(sec + 4u * ib)), sat));
}
SN_INLINE void sn_k_add3(const sn_q x[3], const sn_q y[3], sn_q out[3], uint32_t *sat) {
    sn_k_st3d(out, sn_k_clamp4(_mm256_add_epi64(sn_k_ld3d(x), sn_k_ld3d(y)), sat));
}
SN_INLINE void sn_k_coef3(const sn_q x[3], sn_q c, sn_q out[3], uint32_t *sat) {
    sn_k_st3d(out, sn_k_out4(_mm256_mul_epi32(sn_k_ld3d(x), _mm256_set1_epi32(c)), _mm256_set1_epi64x(SN_Q_COEF), sat));
}
SN_INLINE void sn_k_sub3a(sn_q x[3], const sn_acc y[3], uint32_t *sat) {
    sn_k_st3d(x, sn_k_clamp4(_mm256_sub_epi64(sn_k_ld3d(x), sn_k_ld3q(y)), sat));
}
/* l = D e (D: xx yy zz xy xz yz, 6 int32 at b) rounded: sn_out(l, sh) as lanes (lane 3: 0) */
SN_INLINE __m256i sn_k_sym_out4(const unsigned char *b, const sn_q e[3], int sh, uint32_t *sat) {
    const __m256i v = _mm256_inserti128_si256(_mm256_castsi128_si256(_mm_loadu_si128((const __m128i *)(const void *)b)),
                                              _mm_loadl_epi64((const __m128i *)(const void *)(b + 16)), 1); /* xx yy zz xy xz yz 0 0 */
    const __m256i x = _mm256_add_epi64(
        _mm256_add_epi64(_mm256_mul_epi32(_mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 0, 3, 0, 4, 0, 6, 0)), _mm256_set1_epi32(e[0])),
                         _mm256_mul_epi32(_mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(3, 0, 1, 0, 5, 0, 6, 0)), _mm256_set1_epi32(e[1]))),
        _mm256_mul_epi32(_mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(4, 0, 5, 0, 2, 0, 6, 0)), _mm256_set1_epi32(e[2])));
    return sn_k_out4(x, sn_k_sh4(sh), sat); /* lane 3: 0 * e */
}
SN_INLINE void sn_k_sym_out(const unsigned char *b, const sn_q e[3], sn_q out[3], int sh, uint32_t *sat) {
    sn_k_st3d(out, sn_k_sym_out4(b, e, sh, sat));
}
/* A cell's frame permuted once for its corners (x86-64 round 2: cell_stiff,
 * cell_forces): t0..t2 for R^T v (sn_k_rot_t's lanes), c0..c2 for R v
 * (sn_k_out_rot_acc's); sn_k_rot_t_m / sn_k_out_rot_acc_m are those two
 * with the permutes done, the same integers. */
#define SN_K_ROTM 1
typedef struct { __m256i t0, t1, t2, c0, c1, c2; } sn_k_rotm;
SN_INLINE void sn_k_rotm_ld(sn_k_rotm *m, const sn_q *R) {
    const __m256i r0 = _mm256_loadu_si256((const __m256i *)(const void *)R);
    const __m256i r1 = _mm256_loadu_si256((const __m256i *)(const void *)(R + 1));
    const __m256i ic1 = _mm256_setr_epi32(1, 0, 4, 0, 7, 0, 0, 0);
    m->t0 = _mm256_permutevar8x32_epi32(r0, _mm256_setr_epi32(0, 0, 1, 0, 2, 0, 0, 0));
    m->t1 = _mm256_permutevar8x32_epi32(r0, _mm256_setr_epi32(3, 0, 4, 0, 5, 0, 0, 0));
    m->t2 = _mm256_permutevar8x32_epi32(r1, _mm256_setr_epi32(5, 0, 6, 0, 7, 0, 0, 0));
    m->c0 = _mm256_permutevar8x32_epi32(r0, _mm256_setr_epi32(0, 0, 3, 0, 6, 0, 0, 0));
    m->c1 = _mm256_permutevar8x32_epi32(r0, ic1);
    m->c2 = _mm256_permutevar8x32_epi32(r1, ic1);
}
SN_INLINE __m256i sn_k_rot_t_mv(const sn_k_rotm *m, __m256i v, uint32_t *sat) { /* v as lanes */
    return sn_k_rot_rnd(_mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(m->t0, _mm256_permute4x64_epi64(v, 0x00)),
                                                          _mm256_mul_epi32(m->t1, _mm256_permute4x64_epi64(v, 0x55))),
                                         _mm256_mul_epi32(m->t2, _mm256_permute4x64_epi64(v, 0xAA))),
                        sat);
}
SN_INLINE void sn_k_rot_t_m(const sn_k_rotm *m, const sn_q v[3], sn_q out[3], uint32_t *sat) {
    sn_k_rot_out(_mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(m->t0, _mm256_set1_epi32(v[0])),
                                                   _mm256_mul_epi32(m->t1, _mm256_set1_epi32(v[1]))),
                                  _mm256_mul_epi32(m->t2, _mm256_set1_epi32(v[2]))),
                 out, sat);
}
SN_INLINE void sn_k_out_rot_acc_m(sn_acc acc[3], const sn_k_rotm *m, const sn_acc l[3], int sh, uint32_t *sat) {
    const __m256i t = sn_k_out4(sn_k_ld3q(l), sn_k_sh4(sh), sat); /* lane 3: 0 */
    const __m256i x = _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(m->c0, _mm256_permute4x64_epi64(t, 0x00)),
                                                        _mm256_mul_epi32(m->c1, _mm256_permute4x64_epi64(t, 0x55))),
                                       _mm256_mul_epi32(m->c2, _mm256_permute4x64_epi64(t, 0xAA)));
    sn_k_st3q(acc, _mm256_add_epi64(sn_k_ld3q(acc), x)); /* acc += R t */
}
/* cell_forces' elastic energy term: sum over k = 3..23 of d[k] sn_out(l[k], s)
 * (x86-64 round 2), 4 terms a vector (lanes 0..2 of the first masked to 0:
 * no term, no clamp). |d|, |sn_out| <= 2^28: each product < 2^56, the sum
 * of 21 < 2^61, exact in any order: the reference loop's int64. */
#define SN_K_ENERGY24 1
SN_INLINE sn_acc sn_k_energy24(const sn_q d[24], const sn_acc l[24], int s, uint32_t *sat) {
    const __m256i sv = sn_k_sh4(s);
    __m256i a = _mm256_setzero_si256();
    int64_t t[4];
    uint32_t k;
    for (k = 0; k < 24; k += 4) {
        __m256i x = _mm256_loadu_si256((const __m256i *)(const void *)(l + k));
        if (k == 0) x = _mm256_blend_epi32(x, _mm256_setzero_si256(), 0x3F); /* k = 0..2: d_0 = 0 */
        a = _mm256_add_epi64(a, _mm256_mul_epi32(sn_k_out4(x, sv, sat),
                                                 _mm256_cvtepi32_epi64(_mm_loadu_si128((const __m128i *)(const void *)(d + k)))));
    }
    _mm256_storeu_si256((__m256i *)(void *)t, a);
    return t[0] + t[1] + t[2] + t[3];
}
/* cell_forces' corner (sn_solve.c; x86-64 round 2): t = sn_add(p_a, -p_0),
 * s = sn_add(w_a, -w_0), uu = sn_out(R^T s), d = sn_add(sn_out(R^T t),
 * -sn_add(x_a, -x_0)) (x: the blob's rest positions at reals ia, ib), kept
 * in int64 lanes between the steps; the same integers and counts. */
#define SN_K_CORNER 1
SN_INLINE void sn_k_corner(const sn_k_rotm *m, const sn_q *pa, const sn_q *p0, const sn_q *wa, const sn_q *w0, const unsigned char *rest,
                           uint32_t ia, uint32_t ib, sn_q d[3], sn_q uu[3], uint32_t *sat) {
    const __m256i t = sn_k_clamp4(_mm256_sub_epi64(sn_k_ld3d(pa), sn_k_ld3d(p0)), sat);
    const __m256i s = sn_k_clamp4(_mm256_sub_epi64(sn_k_ld3d(wa), sn_k_ld3d(w0)), sat);
    const __m256i x = sn_k_clamp4(_mm256_sub_epi64(sn_k_ld3d(rest + 4u * ia), sn_k_ld3d(rest + 4u * ib)), sat);
    sn_k_st3d(uu, sn_k_rot_t_mv(m, s, sat));
    sn_k_st3d(d, sn_k_clamp4(_mm256_sub_epi64(sn_k_rot_t_mv(m, t, sat), x), sat)); /* lane 3: 0 */
}
#else /* the reference loops (written as loops: the Cortex-M4's code is smaller and faster than written out) */
#if defined(SN_KERNELS_M4)
/* t = sn_out(l, sh) per entry, acc += R t: for 0 < sh < 32 Thumb-2
 * (sn_m4_out_rot_acc, sn_kernels_m4.c: sn_k_out_w's rounding and clamp,
 * R's rows by LDM into SMLAL chains from acc), other shifts in C
 * (sn_k_out_rot_acc_c); exact int64 sums, the same integers and counts */
void sn_m4_out_rot_acc(sn_acc acc[3], const sn_q *R, const sn_acc l[3], int sh, uint32_t *sat);
void sn_k_out_rot_acc_c(sn_acc acc[3], const sn_q *R, const sn_acc l[3], int sh, uint32_t *sat);
SN_INLINE void sn_k_out_rot_acc(sn_acc acc[3], const sn_q *R, const sn_acc l[3], int sh, uint32_t *sat) {
    if ((uint32_t)(sh - 1) < 31u) sn_m4_out_rot_acc(acc, R, l, sh, sat);
    else sn_k_out_rot_acc_c(acc, R, l, sh, sat);
}
/* l = D e in int32 registers (e read first: out may be e), then sn_k_out_w
 * (0 < sh < 32: Thumb-2, sn_m4_sym_out in sn_kernels_m4.c; b 4-aligned) or
 * sn_out; exact sums, the same integers */
void sn_m4_sym_out(const unsigned char *b, const sn_q *e, sn_q *out, int sh, uint32_t *sat);
SN_INLINE void sn_k_sym_out(const unsigned char *b, const sn_q e[3], sn_q out[3], int sh, uint32_t *sat) {
    if ((uint32_t)(sh - 1) < 31u) { sn_m4_sym_out(b, e, out, sh, sat); return; }
    {
    const sn_q xx = rd_real(b, 0), yy = rd_real(b, 1), zz = rd_real(b, 2);
    const sn_q xy = rd_real(b, 3), xz = rd_real(b, 4), yz = rd_real(b, 5);
    int32_t e0 = e[0], e1 = e[1], e2 = e[2];
    sn_acc l0, l1, l2;
    SN_K_I32(e0, e1, e2);
    l0 = sn_mul(xx, e0) + sn_mul(xy, e1) + sn_mul(xz, e2);
    l1 = sn_mul(xy, e0) + sn_mul(yy, e1) + sn_mul(yz, e2);
    l2 = sn_mul(xz, e0) + sn_mul(yz, e1) + sn_mul(zz, e2);
    out[0] = sn_out(l0, sh, sat);
    out[1] = sn_out(l1, sh, sat);
    out[2] = sn_out(l2, sh, sat);
    }
}
#define SN_K_SYM_OUT_M4 1
#else
SN_INLINE void sn_k_out_rot_acc(sn_acc acc[3], const sn_q *R, const sn_acc l[3], int sh, uint32_t *sat) {
    sn_q t[3];
    int c;
    for (c = 0; c < 3; c++) t[c] = sn_out(l[c], sh, sat);
    sn_k_rot_acc(acc, R, t);
}
#endif
#if defined(SN_KERNELS_M4)
/* sn_add(x, -y) as QSUB (sn_add's QADD with the negation folded in: the
 * same saturated difference for every y the reference can negate) and its
 * one-compare clamp; written out (the loop's counter and NEG cost 4 of 11
 * instructions an entry) */
SN_INLINE sn_q sn_k_qsub(sn_q x, sn_q y, uint32_t *sat) {
    const int32_t v = __qsub(x, y);
    if ((uint32_t)v + (uint32_t)SN_LIM <= 2u * (uint32_t)SN_LIM) return v;
    (*sat)++;
    return v > 0 ? SN_LIM : -SN_LIM;
}
SN_INLINE void sn_k_sub3(const sn_q x[3], const sn_q y[3], sn_q out[3], uint32_t *sat) {
    const sn_q a0 = sn_k_qsub(x[0], y[0], sat), a1 = sn_k_qsub(x[1], y[1], sat), a2 = sn_k_qsub(x[2], y[2], sat);
    out[0] = a0; out[1] = a1; out[2] = a2; /* out may be x or y */
}
SN_INLINE void sn_k_sub3r(const unsigned char *sec, uint32_t ia, uint32_t ib, sn_q out[3], uint32_t *sat) {
    out[0] = sn_k_qsub(rd_real(sec, ia), rd_real(sec, ib), sat);
    out[1] = sn_k_qsub(rd_real(sec, ia + 1), rd_real(sec, ib + 1), sat);
    out[2] = sn_k_qsub(rd_real(sec, ia + 2), rd_real(sec, ib + 2), sat);
}
#else
SN_INLINE void sn_k_sub3(const sn_q x[3], const sn_q y[3], sn_q out[3], uint32_t *sat) {
    int c;
    for (c = 0; c < 3; c++) out[c] = sn_add(x[c], -y[c], sat);
}
SN_INLINE void sn_k_sub3r(const unsigned char *sec, uint32_t ia, uint32_t ib, sn_q out[3], uint32_t *sat) {
    uint32_t c;
    for (c = 0; c < 3; c++) out[c] = sn_add(rd_real(sec, ia + c), -rd_real(sec, ib + c), sat);
}
#endif
#if defined(SN_KERNELS_M4)
/* written out, sn_add by QADD; coef's rounding by sn_k_out_w; x - y's
 * clamp (sn_out at shift 0) on the two words (sn_k_out_w's test) */
SN_INLINE void sn_k_add3(const sn_q x[3], const sn_q y[3], sn_q out[3], uint32_t *sat) {
    const sn_q a0 = sn_add(x[0], y[0], sat), a1 = sn_add(x[1], y[1], sat), a2 = sn_add(x[2], y[2], sat);
    out[0] = a0; out[1] = a1; out[2] = a2; /* out may be x or y */
}
SN_INLINE void sn_k_coef3(const sn_q x[3], sn_q c, sn_q out[3], uint32_t *sat) {
    const uint32_t bit = (uint32_t)1 << (SN_Q_COEF - 1);
    const sn_q a0 = sn_k_out_w(sn_mul(x[0], c), SN_Q_COEF, bit, sat), a1 = sn_k_out_w(sn_mul(x[1], c), SN_Q_COEF, bit, sat);
    const sn_q a2 = sn_k_out_w(sn_mul(x[2], c), SN_Q_COEF, bit, sat);
    out[0] = a0; out[1] = a1; out[2] = a2;
}
/* coef(v, c) when it cannot clamp, |v| <= SN_LIM and |c| <= ONE_COEF
 * (|v c| + 2^23 < (SN_LIM + 1) 2^24): the rounded high bits, no test
 * (bit = 2^(SN_Q_COEF - 1)) */
SN_INLINE int32_t sn_k_coef_nc(sn_q v, sn_q c, uint32_t bit) {
    const int64_t x = sn_mul(v, c) + (int64_t)bit; /* SMLAL from the rounding term */
    SN_RANGE(v <= SN_LIM && v >= -SN_LIM && c <= ((int32_t)1 << SN_Q_COEF) && c >= -((int32_t)1 << SN_Q_COEF),
             "coef beyond its no-clamp bound", v);
    return (int32_t)(((uint32_t)(x >> 32) << (32 - SN_Q_COEF)) | ((uint32_t)x >> SN_Q_COEF));
}
SN_INLINE sn_q sn_k_sub_w(sn_q x, sn_acc y, uint32_t *sat) {
    const int64_t d = (int64_t)x - y;
    const uint32_t lo = (uint32_t)d;
    const int32_t hi = (int32_t)(d >> 32);
    SN_RANGE(d <= (int64_t)6521908912666391106 && d >= -(int64_t)6521908912666391106, /* 2^62.5, as sn_out */
             "accumulator beyond 2^62.5 reaches sn_out", d);
    if (lo + (uint32_t)SN_LIM <= 2u * (uint32_t)SN_LIM && hi == (int32_t)lo >> 31) return (int32_t)lo;
    (*sat)++;
    return hi < 0 ? -SN_LIM : SN_LIM;
}
SN_INLINE void sn_k_sub3a(sn_q x[3], const sn_acc y[3], uint32_t *sat) {
    x[0] = sn_k_sub_w(x[0], y[0], sat);
    x[1] = sn_k_sub_w(x[1], y[1], sat);
    x[2] = sn_k_sub_w(x[2], y[2], sat);
}
#else
SN_INLINE void sn_k_add3(const sn_q x[3], const sn_q y[3], sn_q out[3], uint32_t *sat) {
    int c;
    for (c = 0; c < 3; c++) out[c] = sn_add(x[c], y[c], sat);
}
SN_INLINE void sn_k_coef3(const sn_q x[3], sn_q c, sn_q out[3], uint32_t *sat) {
    int k;
    for (k = 0; k < 3; k++) out[k] = coef(x[k], c, sat);
}
SN_INLINE void sn_k_sub3a(sn_q x[3], const sn_acc y[3], uint32_t *sat) {
    x[0] = sn_out((sn_acc)x[0] - y[0], 0, sat);
    x[1] = sn_out((sn_acc)x[1] - y[1], 0, sat);
    x[2] = sn_out((sn_acc)x[2] - y[2], 0, sat);
}
#endif
/* l = 0 + D e, D symmetric stored xx yy zz xy xz yz (the sum from 0 as the
 * block Jacobi of format 5 did: float keeps its signed zeros); out = sn_out(l, sh) */
#if !defined(SN_K_SYM_OUT_M4)
SN_INLINE void sn_k_sym_out(const unsigned char *b, const sn_q e[3], sn_q out[3], int sh, uint32_t *sat) {
    sn_q xx = rd_real(b, 0), yy = rd_real(b, 1), zz = rd_real(b, 2);
    sn_q xy = rd_real(b, 3), xz = rd_real(b, 4), yz = rd_real(b, 5);
    sn_acc l[3];
    l[0] = l[1] = l[2] = 0;
    l[0] += sn_mul(xx, e[0]) + sn_mul(xy, e[1]) + sn_mul(xz, e[2]);
    l[1] += sn_mul(xy, e[0]) + sn_mul(yy, e[1]) + sn_mul(yz, e[2]);
    l[2] += sn_mul(xz, e[0]) + sn_mul(yz, e[1]) + sn_mul(zz, e[2]);
    out[0] = sn_out(l[0], sh, sat);
    out[1] = sn_out(l[1], sh, sat);
    out[2] = sn_out(l[2], sh, sat);
}
#endif
#endif

/* The mat-vec's last passes (sn_solve.c matvec), over n = 3 nF values:
 *   sn_k_outv(out, in, n, s, sat): out[i] = sn_out(in[i], s)
 *   sn_k_mix(q, acc, kk, n, fm, ck, cm, sat): q[i] = sn_out(q[i] ck +
 *     sn_out(acc[i], fm - SN_KREL(k of i's vertex)) cm, SN_Q_COEF)
 * Float SIMD paths: 4 entries per iteration (each entry alone: the same
 * floats and counts), the tail as the reference; fixed AVX2 / AVX-512: 4
 * int64 lanes by sn_k_out4 (sn_k_mix 4 vertices at a time). */
#if defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)
SN_INLINE uint32_t sn_k_bits4(int m) { return (uint32_t)(0x4332322132212110ull >> (4 * m) & 15u); } /* 4-bit mask's count */
#endif
SN_INLINE void sn_k_outv(sn_q *out, const sn_acc *in, uint32_t n, int s, uint32_t *sat) {
    uint32_t i = 0;
#if defined(SN_KERNELS_AVX2)
    const __m256i sv = sn_k_sh4(s);
    uint32_t c = 0;
    for (; i + 4 <= n; i += 4)
        _mm_storeu_si128((__m128i *)(void *)(out + i), sn_k_pack4(sn_k_out4(_mm256_loadu_si256((const __m256i *)(const void *)(in + i)), sv, &c)));
    *sat += c;
#elif defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)
    uint32_t c = 0;
    for (; i + 4 <= n; i += 4) {
        int m;
        FV_ST4(out + i, fv_clamp(FV_LD4(in + i), &m));
        if (m) c += sn_k_bits4(m); /* rare */
    }
    *sat += c;
#elif defined(SN_KERNELS_M4)
    if (s > 0 && s < 32) {
        const uint32_t bit = (uint32_t)1 << (s - 1);
        for (; i < n; i++) out[i] = sn_k_out_w(in[i], s, bit, sat);
    }
#endif
    for (; i < n; i++) out[i] = sn_out(in[i], s, sat);
}
#if defined(SN_KERNELS_M4)
/* sn_k_mix's operands for sn_m4_mix (sn_kernels_m4.c), which advances q,
 * acc and kk over the vertices up to kend or the first one whose shift
 * base - kk is outside 1..31, adding its clamps to sat */
struct sn_m4_mixc {
    sn_q *q;
    const sn_acc *acc;
    const uint8_t *kk, *kend;
    int32_t base, ck, cm; /* base: fm - SN_KREL(0) */
    uint32_t sat;
};
void sn_m4_mix(struct sn_m4_mixc *c);
#endif
SN_INLINE void sn_k_mix(sn_q *q, const sn_acc *acc, const uint8_t *kk, uint32_t n, int fm, sn_q ck, sn_q cm, uint32_t *sat) {
    uint32_t i = 0;
#if defined(SN_KERNELS_AVX2)
    /* 4 vertices (12 values) per iteration: the per-vertex shifts as lanes
     * (as sn_k_dot: VPERMQ of the 4), the tail per vertex as the reference */
    const __m256i vk = _mm256_set1_epi64x(ck), vm = _mm256_set1_epi64x(cm), sq = _mm256_set1_epi64x(SN_Q_COEF);
    const __m128i base = _mm_set1_epi32(fm - SN_KREL(0));
    uint32_t c = 0, g;
    for (; i + 12 <= n; i += 12) {
        uint32_t k4;
        __m256i sv, sg[3];
        memcpy(&k4, kk + i / 3, 4);
        sv = _mm256_cvtepi32_epi64(_mm_max_epi32(_mm_sub_epi32(base, _mm_cvtepu8_epi32(_mm_cvtsi32_si128((int)k4))),
                                                 _mm_setzero_si128())); /* sh per vertex, s <= 0 as 0 */
        sg[0] = _mm256_permute4x64_epi64(sv, 0x40); /* v0 v0 v0 v1 */
        sg[1] = _mm256_permute4x64_epi64(sv, 0xA5); /* v1 v1 v2 v2 */
        sg[2] = _mm256_permute4x64_epi64(sv, 0xFE); /* v2 v3 v3 v3 */
        for (g = 0; g < 3; g++) {
            const __m256i mk = sn_k_out4(_mm256_loadu_si256((const __m256i *)(const void *)(acc + i + 4 * g)), sg[g], &c);
            const __m256i qv = _mm256_cvtepi32_epi64(_mm_loadu_si128((const __m128i *)(const void *)(q + i + 4 * g)));
            const __m256i sum = _mm256_add_epi64(_mm256_mul_epi32(qv, vk), _mm256_mul_epi32(mk, vm));
            _mm_storeu_si128((__m128i *)(void *)(q + i + 4 * g), sn_k_pack4(sn_k_out4(sum, sq, &c)));
        }
    }
    *sat += c;
    for (i /= 3; i < n / 3; i++) {
        int sh = fm - SN_KREL(kk[i]);
        uint32_t k;
        for (k = 0; k < 3; k++) {
            sn_q mk = sn_out(acc[3 * i + k], sh, sat);
            sn_acc s = sn_mul(q[3 * i + k], ck) + sn_mul(mk, cm);
            q[3 * i + k] = sn_out(s, SN_Q_COEF, sat);
        }
    }
#elif defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)
    const sn_fv vk = FV_SET1(ck), vm = FV_SET1(cm);
    uint32_t c = 0;
    for (; i + 4 <= n; i += 4) {
        int m1, m2;
        const sn_fv mk = fv_clamp(FV_LD4(acc + i), &m1);
        FV_ST4(q + i, fv_clamp(FV_ADD(FV_MUL(FV_LD4(q + i), vk), FV_MUL(mk, vm)), &m2));
        if (m1 | m2) c += sn_k_bits4(m1) + sn_k_bits4(m2); /* rare */
    }
    *sat += c;
    for (; i < n; i++) {
        sn_q mk = sn_out(acc[i], fm - SN_KREL(kk[i / 3]), sat);
        sn_acc s = sn_mul(q[i], ck) + sn_mul(mk, cm);
        q[i] = sn_out(s, SN_Q_COEF, sat);
    }
#elif defined(SN_KERNELS_M4)
    /* Thumb-2 (sn_m4_mix, sn_kernels_m4.c) while a vertex's shift is in
     * 1..31 (sn_k_out_w's rounding for both roundings); a vertex outside:
     * the reference's, then the assembly again */
    struct sn_m4_mixc c;
    c.q = q;
    c.acc = acc;
    c.kk = kk;
    c.kend = kk + n / 3;
    c.base = fm - SN_KREL(0);
    c.ck = ck;
    c.cm = cm;
    c.sat = 0;
    (void)i;
    for (;;) {
        uint32_t k;
        int sh;
        sn_m4_mix(&c);
        if (c.kk == c.kend) break;
        sh = fm - SN_KREL(*c.kk);
        for (k = 0; k < 3; k++) {
            sn_q mk = sn_out(c.acc[k], sh, &c.sat);
            c.q[k] = sn_out(sn_mul(c.q[k], ck) + sn_mul(mk, cm), SN_Q_COEF, &c.sat);
        }
        c.q += 3;
        c.acc += 3;
        c.kk++;
    }
    *sat += c.sat;
#else /* per vertex, its shift once (the loop the mat-vec had) */
    for (; i < n / 3; i++) {
        int sh = fm - SN_KREL(kk[i]);
        uint32_t k;
        for (k = 0; k < 3; k++) {
            sn_q mk = sn_out(acc[3 * i + k], sh, sat);
            sn_acc s;
            s = sn_mul(q[3 * i + k], ck) + sn_mul(mk, cm);
            q[3 * i + k] = sn_out(s, SN_Q_COEF, sat);
        }
    }
#endif
}

/* d sn_out(l, s), a term of a cell's elastic energy (cell_forces): on the
 * Cortex-M4 the rounded value held as an int32 (an empty asm, as SN_K_I32:
 * GCC otherwise multiplied the clamped int64 as 64 x 64 bits, UMULL, MUL,
 * MLA, not one SMLAL); elsewhere the reference expression itself (the same
 * code as before). The same value. */
#if defined(SN_KERNELS_M4)
SN_INLINE sn_acc sn_k_mul_out(sn_q d, sn_acc l, int s, uint32_t *sat) {
    int32_t t = (uint32_t)(s - 1) < 31u ? sn_k_out_w(l, s, (uint32_t)1 << (s - 1), sat) : sn_out(l, s, sat);
    __asm__("" : "+r"(t));
    return sn_mul(d, t);
}
/* sum over k = 3..23 of d[k] sn_out(l[k], s) (cell_forces' energy term,
 * corners 1..7): the test of s once, a corner's 3 values written out (the
 * loop tested s per value); exact int64 sums (|term| <= 2^56), the same
 * value and count */
#define SN_K_ENERGY 1
SN_INLINE sn_acc sn_k_energy(const sn_q *d, const sn_acc *l, int s, uint32_t *sat) {
    sn_acc e = 0;
    uint32_t k;
    if ((uint32_t)(s - 1) < 31u) {
        const uint32_t bit = (uint32_t)1 << (s - 1);
        for (k = 3; k < 24; k += 3) {
            int32_t t0 = sn_k_out_w(l[k], s, bit, sat), t1 = sn_k_out_w(l[k + 1], s, bit, sat);
            int32_t t2 = sn_k_out_w(l[k + 2], s, bit, sat);
            SN_K_I32(t0, t1, t2);
            e += sn_mul(d[k], t0) + sn_mul(d[k + 1], t1) + sn_mul(d[k + 2], t2);
        }
    } else
        for (k = 3; k < 24; k++) e += sn_mul(d[k], sn_out(l[k], s, sat));
    return e;
}
#else
#define sn_k_mul_out(d, l, s, sat) sn_mul((d), sn_out((l), (s), (sat)))
#endif

#endif /* SN_KERNELS_ROT_H */
