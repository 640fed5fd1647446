/* sn_kernels_fsimd.h -- the float flavour's 4-lane layer for its SIMD
 * kernels (sn_kernels_fsimd.c, and the inline rotations and IC(0) block
 * products of sn_kernels_rot.h / sn_kernels_ic.h): x86-64 AVX2 builds use
 * 128-bit SSE/AVX operations (256-bit permutes to gather a 3x3's rows and
 * columns), aarch64 AdvSIMD the same operations.
 *
 * Bits: a 3-vector result sits in lanes 0..2, lane k computing exactly the
 * scalar reference's expression for output k, ((p0 + p1) + p2) then added
 * to its accumulator, with separate multiplies and adds (no FMA: the
 * intrinsics are separate operations, and the runtime builds in -std=c99,
 * where gcc does not contract; clang contracts only within one source
 * expression). IEEE float in every lane, round to nearest: the same float
 * as the reference, so the float hash is the scalar one (KERNELS.md
 * "SIMD kernels", float flavour). Lane 3 holds junk from inside the block
 * (finite blob reals or their products) and is never stored or counted.
 * ARMv7 NEON is not used: its float arithmetic flushes subnormals to zero. */
#ifndef SN_KERNELS_FSIMD_H
#define SN_KERNELS_FSIMD_H

#include "sn_kernels.h"

#if defined(SN_KERNELS_FAVX2)
#include <immintrin.h>
typedef __m128 sn_fv;
#define FV_SET1(x) _mm_set1_ps(x)
#define FV_ADD(a, b) _mm_add_ps((a), (b))
#define FV_MUL(a, b) _mm_mul_ps((a), (b))
#define FV_SUB(a, b) _mm_sub_ps((a), (b))
#define FV_LD4(p) _mm_loadu_ps((const float *)(const void *)(p))
#define FV_ST4(p, v) _mm_storeu_ps((float *)(void *)(p), (v))
SN_INLINE sn_fv fv_ld3(const float *p) { /* MOVSD + MOVSS (no masked load: see fv_st3) */
    double d; /* lanes 0-1 by memcpy: _mm_load_sd's double load of float storage breaks strict aliasing (GCC moved it above
               * the floats' stores once inlined: x86-64 round 3) */
    memcpy(&d, p, sizeof d);
    return _mm_movelh_ps(_mm_castpd_ps(_mm_set_sd(d)), _mm_load_ss(p + 2));
}
/* lanes 0-1 by MOVLPS, lane 2 by EXTRACTPS (VMASKMOVPS stores are
 * microcoded and slow on AMD Zen) */
SN_INLINE void fv_st3(float *p, sn_fv v) {
    const int z = _mm_extract_ps(v, 2);
    _mm_storel_pi((__m64 *)(void *)p, v);
    memcpy(p + 2, &z, 4);
}
/* the lanes sn_out would change (|a| > SN_FLIM or NaN: fv_out3's test) as a
 * compare mask; OR-ed over several vectors, one test for all of them when
 * none clamps, the common case (x86-64 round 4) */
#define FV_BAD(a) _mm_cmp_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), (a)), _mm_set1_ps(SN_FLIM), _CMP_NLE_UQ)
/* rows and columns of a row-major 3x3 from v0 = B0..B7, v1 = B1..B8 */
#define FV_PERM(v, a, b, c) _mm256_castps256_ps128(_mm256_permutevar8x32_ps((v), _mm256_setr_epi32(a, b, c, c, 0, 0, 0, 0)))
SN_INLINE void fv_rows8(__m256 v0, __m256 v1, sn_fv r[3]) {
    r[0] = _mm256_castps256_ps128(v0);
    r[1] = FV_PERM(v0, 3, 4, 5);
    r[2] = FV_PERM(v1, 5, 6, 7);
}
SN_INLINE void fv_cols8(__m256 v0, __m256 v1, sn_fv c[3]) {
    c[0] = FV_PERM(v0, 0, 3, 6);
    c[1] = FV_PERM(v0, 1, 4, 7);
    c[2] = FV_PERM(v1, 1, 4, 7);
}
#define FV_LD8(p) _mm256_loadu_ps((const float *)(const void *)(p))
/* rows / columns of 9 floats at B (loads stay inside the 9) */
SN_INLINE void fv_rows(const void *B, sn_fv r[3]) {
    const float *f = (const float *)B;
    r[0] = FV_LD4(f);
    r[1] = FV_LD4(f + 3);
    r[2] = _mm_permute_ps(FV_LD4(f + 5), _MM_SHUFFLE(3, 3, 2, 1));
}
SN_INLINE void fv_cols(const void *B, sn_fv c[3]) {
    const float *f = (const float *)B;
    fv_cols8(FV_LD8(f), FV_LD8(f + 1), c);
}
SN_INLINE void fv_blk(const void *B, sn_fv r[3], sn_fv c[3]) {
    const float *f = (const float *)B;
    const __m256 v0 = FV_LD8(f), v1 = FV_LD8(f + 1);
    fv_rows8(v0, v1, r);
    fv_cols8(v0, v1, c);
}
/* sn_out's float clamp on every lane: > SN_FLIM -> SN_FLIM, < -SN_FLIM ->
 * -SN_FLIM, NaN -> +0; the bad lanes' mask in *m */
SN_INLINE sn_fv fv_clamp(sn_fv a, int *m) {
    const sn_fv lim = _mm_set1_ps(SN_FLIM), nlim = _mm_set1_ps(-SN_FLIM);
    sn_fv hi, lo, nan;
    /* the common case first (x86-64 round 2): |a| <= SN_FLIM in every lane,
     * NaN excluded (one unordered-or-greater compare): a, mask 0 */
    *m = _mm_movemask_ps(_mm_cmp_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), a), lim, _CMP_NLE_UQ));
    if (!*m) return a;
    hi = _mm_cmpgt_ps(a, lim);
    lo = _mm_cmplt_ps(a, nlim);
    nan = _mm_cmpunord_ps(a, a);
    return _mm_andnot_ps(nan, _mm_blendv_ps(_mm_blendv_ps(a, lim, hi), nlim, lo));
}
#elif defined(SN_KERNELS_FNEON)
#include <arm_neon.h>
typedef float32x4_t sn_fv;
#define FV_SET1(x) vdupq_n_f32(x)
#define FV_ADD(a, b) vaddq_f32((a), (b))
#define FV_MUL(a, b) vmulq_f32((a), (b))
#define FV_SUB(a, b) vsubq_f32((a), (b))
#define FV_LD4(p) vld1q_f32((const float *)(const void *)(p))
#define FV_ST4(p, v) vst1q_f32((float *)(void *)(p), (v))
SN_INLINE sn_fv fv_ld3(const float *p) { return vcombine_f32(vld1_f32(p), vld1_dup_f32(p + 2)); }
SN_INLINE void fv_st3(float *p, sn_fv v) {
    vst1_f32(p, vget_low_f32(v));
    vst1q_lane_f32(p + 2, v, 2);
}
SN_INLINE void fv_rows(const void *B, sn_fv r[3]) {
    const float *f = (const float *)B;
    const sn_fv t = vld1q_f32(f + 5); /* B5..B8 */
    r[0] = vld1q_f32(f);
    r[1] = vld1q_f32(f + 3);
    r[2] = vextq_f32(t, t, 1);
}
/* VLD3 of 6 floats de-interleaves (B0,B3) (B1,B4) (B2,B5); the third row's B6..B8 added */
SN_INLINE void fv_cols(const void *B, sn_fv c[3]) {
    const float *f = (const float *)B;
    const float32x2x3_t t = vld3_f32(f);
    const float32x2_t h = vld1_f32(f + 6);
    c[0] = vcombine_f32(t.val[0], h);
    c[1] = vcombine_f32(t.val[1], vrev64_f32(h));
    c[2] = vcombine_f32(t.val[2], vld1_dup_f32(f + 8));
}
SN_INLINE void fv_blk(const void *B, sn_fv r[3], sn_fv c[3]) {
    fv_rows(B, r);
    fv_cols(B, c);
}
SN_INLINE sn_fv fv_clamp(sn_fv a, int *m) {
    const sn_fv lim = vdupq_n_f32(SN_FLIM), nlim = vdupq_n_f32(-SN_FLIM);
    const uint32x4_t hi = vcgtq_f32(a, lim), lo = vcltq_f32(a, nlim), ok = vceqq_f32(a, a);
    const uint32x4_t bad = vorrq_u32(vorrq_u32(hi, lo), vmvnq_u32(ok));
    const uint32x4_t bit = {1u, 2u, 4u, 8u};
    *m = (int)vaddvq_u32(vandq_u32(bad, bit));
    return vreinterpretq_f32_u32(vandq_u32(vreinterpretq_u32_f32(vbslq_f32(lo, nlim, vbslq_f32(hi, lim, a))), ok));
}
#endif

#if defined(SN_KERNELS_FAVX2) || defined(SN_KERNELS_FNEON)
/* lanes 0..2 through sn_out (clamp, count) */
SN_INLINE sn_fv fv_out3(sn_fv a, uint32_t *sat) {
    int m;
#if defined(SN_KERNELS_FAVX2)
    /* x86-64 round 2: the common case first, lanes 0..2 finite and within
     * +-SN_FLIM (|a| by the sign mask, one unordered-or-greater compare):
     * a unchanged, as fv_clamp leaves it (lane 3: junk either way, never
     * stored, counted or read) */
    m = _mm_movemask_ps(_mm_cmp_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), a), _mm_set1_ps(SN_FLIM), _CMP_NLE_UQ));
    if (!(m & 7)) return a;
#endif
    a = fv_clamp(a, &m);
    if (m) *sat += (uint32_t)(0x32212110u >> (4 * (m & 7)) & 15u); /* clamps are rare: a branch, then lanes 0..2's count */
    return a;
}
/* ((c0 x0 + c1 x1) + c2 x2), the reference's order */
#define FV_MAC3(c, x0, x1, x2) FV_ADD(FV_ADD(FV_MUL((c)[0], (x0)), FV_MUL((c)[1], (x1))), FV_MUL((c)[2], (x2)))
#endif

#endif /* SN_KERNELS_FSIMD_H */
