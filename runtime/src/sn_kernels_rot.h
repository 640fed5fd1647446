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
/* lane k = sum_c R[i_c(k)] v[c]; i0, i1 index R0..R7, i2 indexes R1..R8 */
SN_INLINE __m256i sn_k_rot3(const sn_q *R, const sn_q v[3], __m256i i0, __m256i i1, __m256i i2) {
    const __m256i r0 = SN_K_R8(R), r1 = SN_K_R8(R + 1);
    return _mm256_add_epi64(
        _mm256_add_epi64(_mm256_mul_epi32(_mm256_permutevar8x32_epi32(r0, i0), _mm256_set1_epi64x(v[0])),
                         _mm256_mul_epi32(_mm256_permutevar8x32_epi32(r0, i1), _mm256_set1_epi64x(v[1]))),
        _mm256_mul_epi32(_mm256_permutevar8x32_epi32(r1, i2), _mm256_set1_epi64x(v[2])));
}
/* lanes 0..2 -> out: sn_out(x, SN_Q_ROT) each */
SN_INLINE void sn_k_rot_out(__m256i x, sn_q out[3], uint32_t *sat) {
    const __m256i lim = _mm256_set1_epi64x(SN_LIM), nlim = _mm256_set1_epi64x(-(int64_t)SN_LIM);
    __m256i y = _mm256_sub_epi64(
        _mm256_srli_epi64(_mm256_add_epi64(x, _mm256_set1_epi64x(((int64_t)1 << 62) + ((int64_t)1 << (SN_Q_ROT - 1)))), SN_Q_ROT),
        _mm256_set1_epi64x((int64_t)1 << (62 - SN_Q_ROT)));
    const __m256i hi = _mm256_cmpgt_epi64(y, lim), lo = _mm256_cmpgt_epi64(nlim, y);
    const int m = _mm256_movemask_pd(_mm256_castsi256_pd(_mm256_or_si256(hi, lo))) & 7;
    y = _mm256_blendv_epi8(_mm256_blendv_epi8(y, lim, hi), nlim, lo);
    *sat += (uint32_t)((m & 1) + (m >> 1 & 1) + (m >> 2));
    _mm_maskstore_epi32((int *)(void *)out, _mm_setr_epi32(-1, -1, -1, 0),
                        _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(y, _mm256_setr_epi32(0, 2, 4, 6, 0, 0, 0, 0))));
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
/* acc += R t (int64, masked to the 3 entries) */
SN_INLINE void sn_k_rot_acc(sn_acc acc[3], const sn_q *R, const sn_q t[3]) {
    const __m256i m3 = _mm256_setr_epi64x(-1, -1, -1, 0);
    _mm256_maskstore_epi64((long long *)(void *)acc, m3,
                           _mm256_add_epi64(_mm256_maskload_epi64((const long long *)(const void *)acc, m3), sn_k_rot_x(R, t)));
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
    if (v > SN_LIM) { (*sat)++; return SN_LIM; }
    if (v < -SN_LIM) { (*sat)++; return -SN_LIM; }
    return v;
}
SN_INLINE void sn_k_rot_t(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    int k;
    for (k = 0; k < 3; k++) out[k] = sn_k_rot_out1(sn_mul(R[k], v[0]) + sn_mul(R[3 + k], v[1]) + sn_mul(R[6 + k], v[2]), sat);
}
SN_INLINE void sn_k_rot(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    int k;
    for (k = 0; k < 3; k++)
        out[k] = sn_k_rot_out1(sn_mul(R[3 * k], v[0]) + sn_mul(R[3 * k + 1], v[1]) + sn_mul(R[3 * k + 2], v[2]), sat);
}
#define sn_k_rot_acc sn_rot_acc

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

#endif /* SN_KERNELS_ROT_H */
