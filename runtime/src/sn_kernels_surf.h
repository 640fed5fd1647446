/* sn_kernels_surf.h -- one embedded surface vertex (seed 000 §3.1):
 * acc_k = sum_a phi_a(t) p_{v_a,k} over its cell's 8 corners, for
 * sn_get_surface's plain-lattice loop (sn_embed.c surface_plain).
 *
 * Bits. Fixed: phi_a as sn_trilinear rounds it (Q30), the 24 products and
 * their sums exact in int64 (|p| <= 2^28, sum phi = 2^30: every partial sum
 * below 2^58), so any order gives the scalar sums. Float: phi_a with
 * sn_trilinear's two products and scale in that order, each product phi_a
 * p, and each component summed a = 0..7 from 0 as the scalar loop does:
 * the same floats. AVX2: the 8 corners in lanes, their positions by three
 * gathers (indices 3 v_a + k inside the positions array). */
#ifndef SN_KERNELS_SURF_H
#define SN_KERNELS_SURF_H

#include "sn_kernels.h"
#if defined(SN_KERNELS_AVX2) || defined(SN_KERNELS_FAVX2)
#include <immintrin.h>
#endif

/* Trilinear weights phi_a (Q30 / float, summing to one) of a cell's 8
 * corners at coordinates t (Q15), corner a at bits (x, y, z). */
SN_INLINE void sn_k_tri_w(const uint32_t t[3], sn_q phi[8]) {
    /* the four x-y products once (each two corners' first factor, in the
     * order of wx * wy * wz: the same values), written out (no index
     * arithmetic); t <= 32768 (validated), so wx * wy <= 2^30 fits 32 bits */
    const uint32_t x0 = 32768u - t[0], y0 = 32768u - t[1], z0 = 32768u - t[2];
#if defined(SN_FLOAT)
    const float xy0 = (float)x0 * (float)y0, xy1 = (float)t[0] * (float)y0, xy2 = (float)x0 * (float)t[1],
                xy3 = (float)t[0] * (float)t[1], fz0 = (float)z0, fz1 = (float)t[2];
#define SN_TRI(xy, z) ((xy) * (z) * (1.0f / 35184372088832.0f)) /* 2^45 */
    phi[0] = SN_TRI(xy0, fz0); phi[1] = SN_TRI(xy1, fz0); phi[2] = SN_TRI(xy2, fz0); phi[3] = SN_TRI(xy3, fz0);
    phi[4] = SN_TRI(xy0, fz1); phi[5] = SN_TRI(xy1, fz1); phi[6] = SN_TRI(xy2, fz1); phi[7] = SN_TRI(xy3, fz1);
#else
    const uint32_t xy0 = x0 * y0, xy1 = t[0] * y0, xy2 = x0 * t[1], xy3 = t[0] * t[1], z1 = t[2];
    /* Q30 weight: (wx*wy) Q30, times wz Q15, >> 15 */
#define SN_TRI(xy, z) ((int32_t)(((uint64_t)(xy) * (z) + (1u << 14)) >> 15))
    phi[0] = SN_TRI(xy0, z0); phi[1] = SN_TRI(xy1, z0); phi[2] = SN_TRI(xy2, z0); phi[3] = SN_TRI(xy3, z0);
    phi[4] = SN_TRI(xy0, z1); phi[5] = SN_TRI(xy1, z1); phi[6] = SN_TRI(xy2, z1); phi[7] = SN_TRI(xy3, z1);
#endif
#undef SN_TRI
}

/* the reference: acc = sum_a phi_a p_{v_a} in order a = 0..7 */
SN_INLINE void sn_k_surf1_ref(const uint32_t t[3], const unsigned char *cell, const sn_q *pos, sn_acc acc[3]) {
    sn_q phi[8];
    uint32_t a;
    sn_acc x = 0, y = 0, z = 0;
    sn_k_tri_w(t, phi);
    for (a = 0; a < 8; a++) {
        const sn_q *pv = pos + 3 * sn_rd_u16(cell + 2 * a);
        x += sn_mul(phi[a], pv[0]); y += sn_mul(phi[a], pv[1]); z += sn_mul(phi[a], pv[2]);
    }
    acc[0] = x; acc[1] = y; acc[2] = z;
}

#if defined(SN_KERNELS_AVX2) || defined(SN_KERNELS_FAVX2)
/* the corners' weight factors in lanes a = (x, y, z bits): wx, wy, wz */
#define SN_K_W8(t, wx, wy, wz) do { \
        const int32_t x0_ = 32768 - (int32_t)(t)[0], y0_ = 32768 - (int32_t)(t)[1], z0_ = 32768 - (int32_t)(t)[2]; \
        const int32_t x1_ = (int32_t)(t)[0], y1_ = (int32_t)(t)[1], z1_ = (int32_t)(t)[2]; \
        wx = _mm256_setr_epi32(x0_, x1_, x0_, x1_, x0_, x1_, x0_, x1_); \
        wy = _mm256_setr_epi32(y0_, y0_, y1_, y1_, y0_, y0_, y1_, y1_); \
        wz = _mm256_setr_epi32(z0_, z0_, z0_, z0_, z1_, z1_, z1_, z1_); \
    } while (0)
#endif

#if defined(SN_KERNELS_AVX2)
/* sum of a vector's four int64 */
SN_INLINE int64_t sn_k_hsum64(__m256i v) {
    const __m128i s = _mm_add_epi64(_mm256_castsi256_si128(v), _mm256_extracti128_si256(v, 1));
    return _mm_cvtsi128_si64(_mm_add_epi64(s, _mm_unpackhi_epi64(s, s)));
}
/* sum_a phi_a p_a of 8 int32 lanes, exact in int64 (products by even and odd lanes) */
SN_INLINE int64_t sn_k_dot8_64(__m256i phi, __m256i p) {
    const __m256i e = _mm256_mul_epi32(phi, p), o = _mm256_mul_epi32(_mm256_srli_epi64(phi, 32), _mm256_srli_epi64(p, 32));
    return sn_k_hsum64(_mm256_add_epi64(e, o));
}
SN_INLINE void sn_k_surf1(const uint32_t t[3], const unsigned char *cell, const sn_q *pos, sn_acc acc[3]) {
    __m256i wx, wy, wz, xy, pe, po, phi, idx;
    const __m256i half = _mm256_set1_epi64x((int64_t)1 << 14);
    SN_K_W8(t, wx, wy, wz);
    xy = _mm256_mullo_epi32(wx, wy); /* <= 2^30 */
    pe = _mm256_srli_epi64(_mm256_add_epi64(_mm256_mul_epu32(xy, wz), half), 15);
    po = _mm256_srli_epi64(_mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(xy, 32), _mm256_srli_epi64(wz, 32)), half), 15);
    phi = _mm256_blend_epi32(pe, _mm256_slli_epi64(po, 32), 0xAA); /* sn_k_tri_w's Q30 weights */
    idx = _mm256_cvtepu16_epi32(_mm_loadu_si128((const __m128i *)(const void *)cell));
    idx = _mm256_add_epi32(idx, _mm256_add_epi32(idx, idx));
    acc[0] = sn_k_dot8_64(phi, _mm256_i32gather_epi32((const int *)pos, idx, 4));
    acc[1] = sn_k_dot8_64(phi, _mm256_i32gather_epi32((const int *)(pos + 1), idx, 4));
    acc[2] = sn_k_dot8_64(phi, _mm256_i32gather_epi32((const int *)(pos + 2), idx, 4));
}
#elif defined(SN_KERNELS_FAVX2)
/* 0 + p_0 + p_1 + ... + p_7, left to right (the scalar loop's sum), in
 * registers (a store and eight narrower reloads stall store forwarding) */
SN_INLINE float sn_k_fsum8_seq(__m256 v) {
    const __m128 lo = _mm256_castps256_ps128(v), hi = _mm256_extractf128_ps(v, 1);
    __m128 s = _mm_add_ss(_mm_setzero_ps(), lo);
    s = _mm_add_ss(s, _mm_shuffle_ps(lo, lo, 1));
    s = _mm_add_ss(s, _mm_movehl_ps(lo, lo));
    s = _mm_add_ss(s, _mm_shuffle_ps(lo, lo, 3));
    s = _mm_add_ss(s, hi);
    s = _mm_add_ss(s, _mm_shuffle_ps(hi, hi, 1));
    s = _mm_add_ss(s, _mm_movehl_ps(hi, hi));
    s = _mm_add_ss(s, _mm_shuffle_ps(hi, hi, 3));
    return _mm_cvtss_f32(s);
}
SN_INLINE void sn_k_surf1(const uint32_t t[3], const unsigned char *cell, const sn_q *pos, sn_acc acc[3]) {
    __m256i wx, wy, wz, idx;
    __m256 phi;
    SN_K_W8(t, wx, wy, wz);
    phi = _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_cvtepi32_ps(wx), _mm256_cvtepi32_ps(wy)), _mm256_cvtepi32_ps(wz)),
                        _mm256_set1_ps(1.0f / 35184372088832.0f)); /* ((wx wy) wz) 2^-45: sn_k_tri_w's floats */
    idx = _mm256_cvtepu16_epi32(_mm_loadu_si128((const __m128i *)(const void *)cell));
    idx = _mm256_add_epi32(idx, _mm256_add_epi32(idx, idx));
    acc[0] = sn_k_fsum8_seq(_mm256_mul_ps(phi, _mm256_i32gather_ps(pos, idx, 4)));
    acc[1] = sn_k_fsum8_seq(_mm256_mul_ps(phi, _mm256_i32gather_ps(pos + 1, idx, 4)));
    acc[2] = sn_k_fsum8_seq(_mm256_mul_ps(phi, _mm256_i32gather_ps(pos + 2, idx, 4)));
}
#else
#define sn_k_surf1 sn_k_surf1_ref
#endif


/* ---- the contact rows' point (sn_contact.c, plain lattice, exact sums):
 * the corners' weights phi, the free corners' squared weights fw = sum over
 * v_a < nF of phi_a^2, and the point and its predicted velocity
 * sp = sum_a phi_a p_a (p: pos for free corners, pst for skeleton ones at
 * 3 (v_a - nF)), sv = sum_a phi_a v_a (vpre for free, vel for skeleton).
 * Bits: fixed, exact int64 sums (phi_a^2 <= 2^60 summing to <= 2^60; |p|,
 * |v| <= 2^31: partial sums below 2^62), any order; float, each sum a =
 * 0..7 from 0 in order, the skeleton corners' fw terms +0 (adding +0 to a
 * sum >= +0 changes no bit). AVX2: the corners in lanes, the positions by
 * masked gathers (a lane's other array is not read). ---- */
SN_INLINE void sn_k_ct8_ref(const uint32_t t[3], const uint16_t vx[8], uint32_t nF, const sn_q *pos, const sn_q *pst,
                            const sn_q *vel, const sn_q *vpre, sn_q phi[8], sn_acc *fw, sn_acc sp[3], sn_acc sv[3]) {
    sn_acc w = 0, p0 = 0, p1 = 0, p2 = 0, v0 = 0, v1 = 0, v2 = 0;
    uint32_t k;
    sn_k_tri_w(t, phi);
    for (k = 0; k < 8; k++)
        if (vx[k] < nF) w += sn_mul(phi[k], phi[k]);
    for (k = 0; k < 8; k++) {
        const uint32_t a = vx[k];
        const sn_q *pp = a < nF ? pos + 3 * a : pst + 3 * (a - nF), *vv = a < nF ? vpre + 3 * a : vel + 3 * a;
        p0 += sn_mul(phi[k], pp[0]); p1 += sn_mul(phi[k], pp[1]); p2 += sn_mul(phi[k], pp[2]);
        v0 += sn_mul(phi[k], vv[0]); v1 += sn_mul(phi[k], vv[1]); v2 += sn_mul(phi[k], vv[2]);
    }
    *fw = w;
    sp[0] = p0; sp[1] = p1; sp[2] = p2; sv[0] = v0; sv[1] = v1; sv[2] = v2;
}
#if defined(SN_KERNELS_AVX2) || defined(SN_KERNELS_FAVX2)
/* lane a: free ? A[3 v_a + k] : B[3 (v_a - nF) + k] (ia, ib the two indices; off lanes not read) */
#if defined(SN_FLOAT)
#define SN_K_G2(A, B, ia, ib, fr, k) \
    _mm256_mask_i32gather_ps(_mm256_mask_i32gather_ps(_mm256_setzero_ps(), (A) + (k), ia, _mm256_castsi256_ps(fr), 4), (B) + (k), ib, \
                             _mm256_castsi256_ps(_mm256_xor_si256(fr, _mm256_set1_epi32(-1))), 4)
#else
#define SN_K_G2(A, B, ia, ib, fr, k) \
    _mm256_mask_i32gather_epi32(_mm256_mask_i32gather_epi32(_mm256_setzero_si256(), (const int *)((A) + (k)), ia, fr, 4), \
                                (const int *)((B) + (k)), ib, _mm256_xor_si256(fr, _mm256_set1_epi32(-1)), 4)
#endif
SN_INLINE void sn_k_ct8(const uint32_t t[3], const uint16_t vx[8], uint32_t nF, const sn_q *pos, const sn_q *pst,
                        const sn_q *vel, const sn_q *vpre, sn_q phi[8], sn_acc *fw, sn_acc sp[3], sn_acc sv[3]) {
    __m256i wx, wy, wz;
    const __m256i v8 = _mm256_cvtepu16_epi32(_mm_loadu_si128((const __m128i *)(const void *)vx));
    const __m256i fr = _mm256_cmpgt_epi32(_mm256_set1_epi32((int32_t)nF), v8); /* v_a < nF (both below 2^16) */
    const __m256i ia = _mm256_add_epi32(v8, _mm256_add_epi32(v8, v8));
    const __m256i ib = _mm256_sub_epi32(ia, _mm256_set1_epi32((int32_t)(3 * nF)));
    SN_K_W8(t, wx, wy, wz);
#if defined(SN_FLOAT)
    {
        const __m256 ph = _mm256_mul_ps(_mm256_mul_ps(_mm256_mul_ps(_mm256_cvtepi32_ps(wx), _mm256_cvtepi32_ps(wy)), _mm256_cvtepi32_ps(wz)),
                                        _mm256_set1_ps(1.0f / 35184372088832.0f)), /* sn_k_tri_w's floats */
                     pf = _mm256_and_ps(ph, _mm256_castsi256_ps(fr));
        _mm256_storeu_ps(phi, ph);
        *fw = sn_k_fsum8_seq(_mm256_mul_ps(pf, pf));
        sp[0] = sn_k_fsum8_seq(_mm256_mul_ps(ph, SN_K_G2(pos, pst, ia, ib, fr, 0)));
        sp[1] = sn_k_fsum8_seq(_mm256_mul_ps(ph, SN_K_G2(pos, pst, ia, ib, fr, 1)));
        sp[2] = sn_k_fsum8_seq(_mm256_mul_ps(ph, SN_K_G2(pos, pst, ia, ib, fr, 2)));
        sv[0] = sn_k_fsum8_seq(_mm256_mul_ps(ph, SN_K_G2(vpre, vel, ia, ia, fr, 0)));
        sv[1] = sn_k_fsum8_seq(_mm256_mul_ps(ph, SN_K_G2(vpre, vel, ia, ia, fr, 1)));
        sv[2] = sn_k_fsum8_seq(_mm256_mul_ps(ph, SN_K_G2(vpre, vel, ia, ia, fr, 2)));
    }
#else
    {
        const __m256i half = _mm256_set1_epi64x((int64_t)1 << 14), xy = _mm256_mullo_epi32(wx, wy);
        const __m256i pe = _mm256_srli_epi64(_mm256_add_epi64(_mm256_mul_epu32(xy, wz), half), 15);
        const __m256i po = _mm256_srli_epi64(_mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(xy, 32), _mm256_srli_epi64(wz, 32)), half), 15);
        const __m256i ph = _mm256_blend_epi32(pe, _mm256_slli_epi64(po, 32), 0xAA), pf = _mm256_and_si256(ph, fr);
        _mm256_storeu_si256((__m256i *)(void *)phi, ph);
        *fw = sn_k_dot8_64(pf, pf);
        sp[0] = sn_k_dot8_64(ph, SN_K_G2(pos, pst, ia, ib, fr, 0));
        sp[1] = sn_k_dot8_64(ph, SN_K_G2(pos, pst, ia, ib, fr, 1));
        sp[2] = sn_k_dot8_64(ph, SN_K_G2(pos, pst, ia, ib, fr, 2));
        sv[0] = sn_k_dot8_64(ph, SN_K_G2(vpre, vel, ia, ia, fr, 0));
        sv[1] = sn_k_dot8_64(ph, SN_K_G2(vpre, vel, ia, ia, fr, 1));
        sv[2] = sn_k_dot8_64(ph, SN_K_G2(vpre, vel, ia, ia, fr, 2));
    }
#endif
}
#undef SN_K_G2
#else
#define sn_k_ct8 sn_k_ct8_ref
#endif

#endif
