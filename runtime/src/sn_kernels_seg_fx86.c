/* sn_kernels_seg_fx86.c -- the float flavour's segment projections on
 * x86-64 (sn_segment_sweep.c star(), pair() not measuring, an attachment's
 * pins) in SIMD lanes: SSE (the baseline; star_fv's vectors, an end per
 * lane) and, in the AVX2 builds, 8-lane vectors with an end per 128-bit
 * half. The scalar code's floats and saturation counts (test_runtime_kernels
 * test_seg_star; KERNELS.md "Cheaper sweeps, same bits" 6 and "Segment
 * sweeps, round 2"). Not built under SN_SIMD_SCALAR. */
#include "sn_segment.h"

#if defined(SEG_STAR_SSE)
#include <immintrin.h>
/* Float, x86-64 (SSE2, the baseline; AVX2 builds the same code VEX-encoded;
 * not under SN_SIMD_SCALAR): star() with its
 * k = 3 or 4 ends in the lanes of SSE vectors (lane 3 at k = 3 repeats end
 * 0 and is never counted or stored). Every lane computes star()'s float
 * expressions in its order (((a + b) + c), separate multiplies and adds, no
 * FMA: KERNELS.md "SIMD kernels", float flavour), the sums over the ends
 * (the mean's, the last end's share) run end by end as in star() on the
 * transposed vectors, the clamps are star()'s compares (blends, NaN kept),
 * and sn_out's rare clamped or NaN lanes go through sn_out itself: the
 * scalar star's floats and counts. */
#if !defined(__AVX2__) /* the SSE kernels' helpers (AVX2 builds: the 8-lane ones below) */
/* mask ? b : a per lane, mask all ones or zeros (a compare's): BLENDVPS
 * where built (SSE4.1), else bitwise (SSE2) */
SN_INLINE __m128 fv_sel(__m128 a, __m128 b, __m128 mask) {
#if defined(__SSE4_1__)
    return _mm_blendv_ps(a, b, mask);
#else
    return _mm_or_ps(_mm_and_ps(mask, b), _mm_andnot_ps(mask, a));
#endif
}
/* seg_lim: a > m ? m : (a < -m ? -m : a) (-m by the sign bit, as negation) */
SN_INLINE __m128 fv_lim(__m128 a, __m128 m) {
    const __m128 nm = _mm_xor_ps(m, _mm_set1_ps(-0.0f));
    return fv_sel(fv_sel(a, nm, _mm_cmplt_ps(a, nm)), m, _mm_cmpgt_ps(a, m));
}
/* sn_out(v, 0) in the lanes of km: unchanged unless beyond +-SN_FLIM or NaN */
SN_INLINE __m128 fv_out(__m128 v, int km, uint32_t *sat) {
    const __m128 lim = _mm_set1_ps(SN_FLIM), nlim = _mm_set1_ps(-SN_FLIM);
    const int f = _mm_movemask_ps(_mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(v, lim), _mm_cmplt_ps(v, nlim)),
                                            _mm_cmpunord_ps(v, v))) & km;
    if (f) {
        float x[4];
        unsigned j;
        _mm_storeu_ps(x, v);
        for (j = 0; j < 4; j++)
            if (f >> j & 1) x[j] = sn_out(x[j], 0, sat);
        v = _mm_loadu_ps(x);
    }
    return v;
}

/* words 0-5 of four segments (S3 may repeat S0) transposed: G the positions'
 * x, y, z and u the directions', an end per lane */
SN_INLINE void fv_load4(const sn_q *S0, const sn_q *S1, const sn_q *S2, const sn_q *S3, __m128 *G0, __m128 *G1,
                        __m128 *G2, __m128 *u0, __m128 *u1, __m128 *u2) {
    __m128 a = _mm_loadu_ps(S0), b = _mm_loadu_ps(S1), c = _mm_loadu_ps(S2), d = _mm_loadu_ps(S3), R0, R1;
    _MM_TRANSPOSE4_PS(a, b, c, d);
    *G0 = a; *G1 = b; *G2 = c; *u0 = d;
    R0 = _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd((const double *)(const void *)(S0 + 4))), (const __m64 *)(const void *)(S1 + 4));
    R1 = _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd((const double *)(const void *)(S2 + 4))), (const __m64 *)(const void *)(S3 + 4));
    *u1 = _mm_shuffle_ps(R0, R1, _MM_SHUFFLE(2, 0, 2, 0));
    *u2 = _mm_shuffle_ps(R0, R1, _MM_SHUFFLE(3, 1, 3, 1));
}
/* back: words 0-5 of the first n (2..4) segments */
SN_INLINE void fv_store(sn_q *S0, sn_q *S1, sn_q *S2, sn_q *S3, __m128 G0, __m128 G1, __m128 G2, __m128 u0, __m128 u1,
                        __m128 u2, unsigned n) {
    __m128 R0 = _mm_unpacklo_ps(u1, u2), R1 = _mm_unpackhi_ps(u1, u2);
    _MM_TRANSPOSE4_PS(G0, G1, G2, u0);
    _mm_storeu_ps(S0, G0); _mm_storel_pi((__m64 *)(void *)(S0 + 4), R0);
    _mm_storeu_ps(S1, G1); _mm_storeh_pi((__m64 *)(void *)(S1 + 4), R0);
    if (n >= 3u) { _mm_storeu_ps(S2, G2); _mm_storel_pi((__m64 *)(void *)(S2 + 4), R1); }
    if (n == 4u) { _mm_storeu_ps(S3, u0); _mm_storeh_pi((__m64 *)(void *)(S3 + 4), R1); }
}
/* the ends' level constants (seg_kf): a coarse end's own half (word 12) and
 * turn factor rf s_13; level 0's half and kf in every lane */
SN_INLINE void fv_lvl(const seg_lvl *L, const sn_q *S0, const sn_q *S1, const sn_q *S2, const sn_q *S3, sn_q rf, seg_n kf,
                      __m128 *hv, __m128 *kv) {
    if (L->l != 0) {
        *hv = _mm_setr_ps(S0[12], S1[12], S2[12], S3[12]);
        *kv = _mm_mul_ps(_mm_set1_ps(rf), _mm_setr_ps(S0[13], S1[13], S2[13], S3[13]));
    } else {
        *hv = _mm_set1_ps(L->half);
        *kv = _mm_set1_ps(kf);
    }
}
/* move_seg's turn per lane: u turned towards the gap d by the factor kv
 * (limited), renormalized by one Newton step; move_seg's floats in order */
SN_INLINE void fv_turn(__m128 *u0, __m128 *u1, __m128 *u2, __m128 d0, __m128 d1, __m128 d2, __m128 kv) {
    const __m128 a = *u0, b = *u1, c = *u2;
    __m128 du, e0, e1, e2, eu, x0, x1, x2, fn;
    du = _mm_add_ps(_mm_add_ps(_mm_mul_ps(d0, a), _mm_mul_ps(d1, b)), _mm_mul_ps(d2, c));
    e0 = fv_lim(_mm_mul_ps(_mm_sub_ps(d0, _mm_mul_ps(du, a)), kv), _mm_set1_ps(ROT_MAX));
    e1 = fv_lim(_mm_mul_ps(_mm_sub_ps(d1, _mm_mul_ps(du, b)), kv), _mm_set1_ps(ROT_MAX));
    e2 = fv_lim(_mm_mul_ps(_mm_sub_ps(d2, _mm_mul_ps(du, c)), kv), _mm_set1_ps(ROT_MAX));
    eu = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e0, a), _mm_mul_ps(e1, b)), _mm_mul_ps(e2, c));
    x0 = _mm_sub_ps(_mm_add_ps(a, e0), _mm_mul_ps(eu, a));
    x1 = _mm_sub_ps(_mm_add_ps(b, e1), _mm_mul_ps(eu, b));
    x2 = _mm_sub_ps(_mm_add_ps(c, e2), _mm_mul_ps(eu, c));
    fn = _mm_sub_ps(_mm_set1_ps(1.5f),
                    _mm_mul_ps(_mm_set1_ps(0.5f),
                               _mm_add_ps(_mm_add_ps(_mm_mul_ps(x0, x0), _mm_mul_ps(x1, x1)), _mm_mul_ps(x2, x2))));
    *u0 = _mm_mul_ps(x0, fn); *u1 = _mm_mul_ps(x1, fn); *u2 = _mm_mul_ps(x2, fn);
}
#endif
#if !defined(__AVX2__) /* AVX builds: star_f8, pair_f8 below */
/* (star_fv) */
void seg_star_fx(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, uint32_t *sat) {
    sn_q *S0 = L->S + SEG_W * seg[0], *S1 = L->S + SEG_W * seg[1], *S2 = L->S + SEG_W * seg[2];
    sn_q *S3 = k == 4u ? L->S + SEG_W * seg[3] : S0;
    const int km = k == 4u ? 0xF : 0x7;
    const __m128 z = _mm_setzero_ps();
    /* the ends' signs as sign bits (negation = the scalar's -h, -kf) */
    const __m128 neg = _mm_and_ps(_mm_castsi128_ps(_mm_cmplt_epi32(
                                      _mm_setr_epi32(sgn[0], sgn[1], sgn[2], k == 4u ? sgn[3] : sgn[0]), _mm_setzero_si128())),
                                  _mm_set1_ps(-0.0f));
    __m128 G0, G1, G2, u0, u1, u2, P0, P1, P2, R0, R1, R2, R3, m, d0, d1, d2, t0, t1, t2, last, kv, hv;
    uint32_t ls = 0;
    fv_load4(S0, S1, S2, S3, &G0, &G1, &G2, &u0, &u1, &u2);
    fv_lvl(L, S0, S1, S2, S3, C->rf1, C->kf1, &hv, &kv);
    hv = _mm_xor_ps(hv, neg);
    kv = _mm_xor_ps(kv, neg);
    P0 = _mm_add_ps(G0, _mm_mul_ps(hv, u0));
    P1 = _mm_add_ps(G1, _mm_mul_ps(hv, u1));
    P2 = _mm_add_ps(G2, _mm_mul_ps(hv, u2));
    /* the mean: per end (P_j0, P_j1, P_j2, 0), summed end by end from 0 */
    R0 = P0; R1 = P1; R2 = P2; R3 = z;
    _MM_TRANSPOSE4_PS(R0, R1, R2, R3);
    m = _mm_add_ps(_mm_add_ps(_mm_add_ps(z, R0), R1), R2);
    if (k == 4u) m = _mm_add_ps(m, R3);
    m = fv_out(_mm_div_ps(m, _mm_set1_ps((float)k)), 0x7, &ls);
    d0 = fv_out(_mm_sub_ps(_mm_shuffle_ps(m, m, 0x00), P0), km, &ls);
    d1 = fv_out(_mm_sub_ps(_mm_shuffle_ps(m, m, 0x55), P1), km, &ls);
    d2 = fv_out(_mm_sub_ps(_mm_shuffle_ps(m, m, 0xAA), P2), km, &ls);
    /* t = D omega gamma; the last end's: minus the others', end by end from 0 */
    hv = _mm_set1_ps(C->g1n);
    t0 = _mm_mul_ps(d0, hv); t1 = _mm_mul_ps(d1, hv); t2 = _mm_mul_ps(d2, hv);
    R0 = t0; R1 = t1; R2 = t2; R3 = z;
    _MM_TRANSPOSE4_PS(R0, R1, R2, R3);
    last = _mm_sub_ps(_mm_sub_ps(z, R0), R1);
    if (k == 4u) last = _mm_sub_ps(last, R2);
    last = fv_lim(last, _mm_set1_ps((sn_acc)2 * SN_LIM));
    {
        const __m128 lm = _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32((int)k - 1)));
        t0 = fv_sel(t0, _mm_shuffle_ps(last, last, 0x00), lm);
        t1 = fv_sel(t1, _mm_shuffle_ps(last, last, 0x55), lm);
        t2 = fv_sel(t2, _mm_shuffle_ps(last, last, 0xAA), lm);
    }
    /* move_seg per lane (kv: the ends' turn factors) */
    fv_turn(&u0, &u1, &u2, d0, d1, d2, kv);
    G0 = fv_out(_mm_add_ps(G0, t0), km, &ls);
    G1 = fv_out(_mm_add_ps(G1, t1), km, &ls);
    G2 = fv_out(_mm_add_ps(G2, t2), km, &ls);
    /* back: words 0-5 of the k ends (not lane 3 at k = 3) */
    fv_store(S0, S1, S2, S3, G0, G1, G2, u0, u1, u2, k);
    *sat += ls;
}
/* pair() (not measuring) with its two moves in lanes 0 (segment a) and 1
 * (b) of star_fv's vectors (lanes 2-3 repeat them, unstored, uncounted):
 * d = P_b - P_a once (lane 0, sn_out counted there), t = d omega gamma/2;
 * b takes -d, -t (float negation: exact), each lane move_seg's floats */
/* (pair_fv) */
void seg_pair_fx(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, uint32_t *sat) {
    sn_q *A = L->S + SEG_W * a, *B = L->S + SEG_W * b;
    const __m128 sz = _mm_set1_ps(-0.0f), n1 = _mm_setr_ps(0.0f, -0.0f, 0.0f, -0.0f);
    const __m128 neg = _mm_and_ps(_mm_castsi128_ps(_mm_cmplt_epi32(_mm_setr_epi32(sa, sb, sa, sb), _mm_setzero_si128())), sz);
    __m128 G0, G1, G2, u0, u1, u2, R0, R1, d0, d1, d2, kv, hv, g;
    uint32_t ls = 0;
    /* words 0-3 of A, B, A, B transposed to G0, G1, G2, u0; words 4-5 by pairs */
    G0 = _mm_loadu_ps(A); G1 = _mm_loadu_ps(B); G2 = G0; u0 = G1;
    _MM_TRANSPOSE4_PS(G0, G1, G2, u0);
    R0 = _mm_loadh_pi(_mm_castpd_ps(_mm_load_sd((const double *)(const void *)(A + 4))), (const __m64 *)(const void *)(B + 4));
    u1 = _mm_shuffle_ps(R0, R0, _MM_SHUFFLE(2, 0, 2, 0));
    u2 = _mm_shuffle_ps(R0, R0, _MM_SHUFFLE(3, 1, 3, 1));
    fv_lvl(L, A, B, A, B, C->rf2, C->kf0, &hv, &kv);
    hv = _mm_xor_ps(hv, neg);
    kv = _mm_xor_ps(kv, neg);
    /* lane 0: P_b - P_a (lanes swapped in pairs) */
    R0 = _mm_add_ps(G0, _mm_mul_ps(hv, u0));
    d0 = _mm_sub_ps(_mm_shuffle_ps(R0, R0, _MM_SHUFFLE(2, 3, 0, 1)), R0);
    R0 = _mm_add_ps(G1, _mm_mul_ps(hv, u1));
    d1 = _mm_sub_ps(_mm_shuffle_ps(R0, R0, _MM_SHUFFLE(2, 3, 0, 1)), R0);
    R0 = _mm_add_ps(G2, _mm_mul_ps(hv, u2));
    d2 = _mm_sub_ps(_mm_shuffle_ps(R0, R0, _MM_SHUFFLE(2, 3, 0, 1)), R0);
    d0 = fv_out(d0, 0x1, &ls); d1 = fv_out(d1, 0x1, &ls); d2 = fv_out(d2, 0x1, &ls);
    /* t = d omega gamma / 2 (lane 0), then both broadcast, negated in lane 1 */
    g = _mm_set1_ps(C->gh);
    R0 = _mm_mul_ps(d0, g); R1 = _mm_mul_ps(d1, g); g = _mm_mul_ps(d2, g);
    G0 = fv_out(_mm_add_ps(G0, _mm_xor_ps(_mm_shuffle_ps(R0, R0, 0), n1)), 0x3, &ls);
    G1 = fv_out(_mm_add_ps(G1, _mm_xor_ps(_mm_shuffle_ps(R1, R1, 0), n1)), 0x3, &ls);
    G2 = fv_out(_mm_add_ps(G2, _mm_xor_ps(_mm_shuffle_ps(g, g, 0), n1)), 0x3, &ls);
    d0 = _mm_xor_ps(_mm_shuffle_ps(d0, d0, 0), n1);
    d1 = _mm_xor_ps(_mm_shuffle_ps(d1, d1, 0), n1);
    d2 = _mm_xor_ps(_mm_shuffle_ps(d2, d2, 0), n1);
    /* move_seg's turn per lane (as star_fv) */
    fv_turn(&u0, &u1, &u2, d0, d1, d2, kv);
    fv_store(A, B, A, B, G0, G1, G2, u0, u1, u2, 2u);
    *sat += ls;
}
#endif
#if defined(__AVX2__)
/* Float AVX (the AVX2 builds): pair() with an end per 128-bit half of
 * 8-lane vectors, its x, y, z in lanes 0-2 (lane 3 a neighbouring word,
 * never stored or counted): one operation per step of the move for both
 * ends and all three components; the dot products summed in star()'s order
 * ((x + y) + z) by in-lane shuffles. The same floats and counts as
 * pair_core (test_seg_star). */
typedef __m256 f8;
/* per half: ((q0 + q1) + q2) in every lane */
SN_INLINE f8 f8_dot3(f8 q) {
    const f8 s = _mm256_add_ps(q, _mm256_permute_ps(q, _MM_SHUFFLE(3, 3, 3, 1)));
    return _mm256_permute_ps(_mm256_add_ps(s, _mm256_permute_ps(q, _MM_SHUFFLE(3, 3, 3, 2))), 0);
}
/* seg_lim, a > m ? m : (a < -m ? -m : a), as MINPS/MAXPS with the limit
 * first: min(m, a) = m < a ? m : a and max(-m, r) = -m > r ? -m : r, so a
 * NaN (every compare false) and -0.0 come through as a (fv_lim's values) */
SN_INLINE f8 f8_lim(f8 a, f8 m) {
    return _mm256_max_ps(_mm256_xor_ps(m, _mm256_set1_ps(-0.0f)), _mm256_min_ps(m, a));
}
/* sn_out(v, 0) in the lanes of km: the lanes with |v| > SN_FLIM or NaN
 * (one unordered-or-greater compare of |v|) through sn_out */
SN_INLINE f8 f8_out(f8 v, int km, uint32_t *sat) {
    const int f = _mm256_movemask_ps(_mm256_cmp_ps(_mm256_andnot_ps(_mm256_set1_ps(-0.0f), v), _mm256_set1_ps(SN_FLIM),
                                                   _CMP_NLE_UQ)) & km;
    if (f) {
        float x[8];
        unsigned j;
        _mm256_storeu_ps(x, v);
        for (j = 0; j < 8; j++)
            if (f >> j & 1) x[j] = sn_out(x[j], 0, sat);
        v = _mm256_loadu_ps(x);
    }
    return v;
}
#define F8_PAIR(lo, hi) _mm256_insertf128_ps(_mm256_castps128_ps256(lo), (hi), 1)
/* move_seg's turn per half: u + e, e = lim((d - (d.u) u) kf), then one Newton step */
/* the ends' level constants (seg_kf), ends 0-1 in ha / ka and 2-3 in hb /
 * kb, an end per half: a coarse end's own half (word 12) and turn factor
 * rf1 s_13; level 0's half and kf1 everywhere (star_f8, pins_f8) */
SN_INLINE void f8_lvl(const seg_ctx *C, const seg_lvl *L, const sn_q *S0, const sn_q *S1, const sn_q *S2, const sn_q *S3,
                      f8 *ha, f8 *hb, f8 *ka, f8 *kb) {
    if (L->l != 0) {
        const f8 rf = _mm256_set1_ps(C->rf1);
        *ha = F8_PAIR(_mm_set1_ps(S0[12]), _mm_set1_ps(S1[12]));
        *hb = F8_PAIR(_mm_set1_ps(S2[12]), _mm_set1_ps(S3[12]));
        *ka = _mm256_mul_ps(rf, F8_PAIR(_mm_set1_ps(S0[13]), _mm_set1_ps(S1[13])));
        *kb = _mm256_mul_ps(rf, F8_PAIR(_mm_set1_ps(S2[13]), _mm_set1_ps(S3[13])));
    } else {
        *ha = *hb = _mm256_set1_ps(L->half);
        *ka = *kb = _mm256_set1_ps(C->kf1);
    }
}
SN_INLINE f8 f8_turn(f8 u, f8 d, f8 kv) {
    const f8 du = f8_dot3(_mm256_mul_ps(d, u));
    const f8 e = f8_lim(_mm256_mul_ps(_mm256_sub_ps(d, _mm256_mul_ps(du, u)), kv), _mm256_set1_ps(ROT_MAX));
    const f8 eu = f8_dot3(_mm256_mul_ps(e, u));
    const f8 x = _mm256_sub_ps(_mm256_add_ps(u, e), _mm256_mul_ps(eu, u));
    return _mm256_mul_ps(x, _mm256_sub_ps(_mm256_set1_ps(1.5f), _mm256_mul_ps(_mm256_set1_ps(0.5f), f8_dot3(_mm256_mul_ps(x, x)))));
}
/* words 0-5 of A (low half) and B (high half, if hb): G0 G1 G2 u0 u1 u2 */
SN_INLINE void f8_store(sn_q *A, sn_q *B, f8 G, f8 u, int hb) {
    const f8 w = _mm256_blend_ps(G, _mm256_permute_ps(u, 0), 0x88), r = _mm256_permute_ps(u, _MM_SHUFFLE(3, 3, 2, 1));
    _mm_storeu_ps(A, _mm256_castps256_ps128(w));
    _mm_storel_pi((__m64 *)(void *)(A + 4), _mm256_castps256_ps128(r));
    if (hb) {
        _mm_storeu_ps(B, _mm256_extractf128_ps(w, 1));
        _mm_storel_pi((__m64 *)(void *)(B + 4), _mm256_extractf128_ps(r, 1));
    }
}
/* (pair_f8) */
void seg_pair_fx(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, uint32_t *sat) {
    sn_q *A = L->S + SEG_W * a, *B = L->S + SEG_W * b;
    const f8 nb = _mm256_setr_ps(0.0f, 0.0f, 0.0f, 0.0f, -0.0f, -0.0f, -0.0f, -0.0f);
    f8 G = F8_PAIR(_mm_loadu_ps(A), _mm_loadu_ps(B)), u = F8_PAIR(_mm_loadu_ps(A + 3), _mm_loadu_ps(B + 3));
    f8 P, d, t;
    float ha, hb, ka, kb;
    uint32_t ls = 0;
    if (L->l != 0) { ha = A[12]; hb = B[12]; ka = C->rf2 * A[13]; kb = C->rf2 * B[13]; }
    else { ha = hb = L->half; ka = kb = C->kf0; }
    if (sa < 0) { ha = -ha; ka = -ka; }
    if (sb < 0) { hb = -hb; kb = -kb; }
    /* lanes 0-2: d = P_b - P_a, counted there; b takes -d, -t */
    P = _mm256_add_ps(G, _mm256_mul_ps(F8_PAIR(_mm_set1_ps(ha), _mm_set1_ps(hb)), u));
    d = f8_out(_mm256_sub_ps(_mm256_permute2f128_ps(P, P, 0x01), P), 0x07, &ls);
    d = _mm256_permute2f128_ps(d, d, 0x00);
    t = _mm256_xor_ps(_mm256_mul_ps(d, _mm256_set1_ps(C->gh)), nb);
    d = _mm256_xor_ps(d, nb);
    G = f8_out(_mm256_add_ps(G, t), 0x77, &ls);
    u = f8_turn(u, d, F8_PAIR(_mm_set1_ps(ka), _mm_set1_ps(kb)));
    f8_store(A, B, G, u, 1);
    *sat += ls;
}

/* star() with ends 0, 1 in the halves of one vector and 2, 3 in another
 * (k = 3: the 4th half repeats end 0, never summed, counted or stored);
 * the mean's and the last share's sums end by end from 0 as star() */
/* (star_f8) */
void seg_star_fx(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, uint32_t *sat) {
    sn_q *S0 = L->S + SEG_W * seg[0], *S1 = L->S + SEG_W * seg[1], *S2 = L->S + SEG_W * seg[2];
    sn_q *S3 = k == 4u ? L->S + SEG_W * seg[3] : S0;
    const int k23 = k == 4u ? 0x77 : 0x07;
    const f8 z = _mm256_setzero_ps();
    f8 Ga = F8_PAIR(_mm_loadu_ps(S0), _mm_loadu_ps(S1)), ua = F8_PAIR(_mm_loadu_ps(S0 + 3), _mm_loadu_ps(S1 + 3));
    f8 Gb = F8_PAIR(_mm_loadu_ps(S2), _mm_loadu_ps(S3)), ub = F8_PAIR(_mm_loadu_ps(S2 + 3), _mm_loadu_ps(S3 + 3));
    /* the ends' signs as sign bits, per half (negation = star()'s -h, -kf) */
    const __m256i sv = _mm256_castsi128_si256(_mm_cmplt_epi32(
        _mm_setr_epi32(sgn[0], sgn[1], sgn[2], k == 4u ? sgn[3] : sgn[0]), _mm_setzero_si128()));
    const f8 sz = _mm256_set1_ps(-0.0f);
    const f8 na = _mm256_and_ps(_mm256_castsi256_ps(_mm256_permutevar8x32_epi32(sv, _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1))), sz);
    const f8 nb = _mm256_and_ps(_mm256_castsi256_ps(_mm256_permutevar8x32_epi32(sv, _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3))), sz);
    f8 Pa, Pb, m, da, db, ta, tb, l, ha, hb, ka, kb;
    uint32_t ls = 0;
    f8_lvl(C, L, S0, S1, S2, S3, &ha, &hb, &ka, &kb);
    ha = _mm256_xor_ps(ha, na); hb = _mm256_xor_ps(hb, nb);
    ka = _mm256_xor_ps(ka, na); kb = _mm256_xor_ps(kb, nb);
    Pa = _mm256_add_ps(Ga, _mm256_mul_ps(ha, ua));
    Pb = _mm256_add_ps(Gb, _mm256_mul_ps(hb, ub));
    /* low half: (((0 + P0) + P1) + P2) (+ P3) / k */
    m = _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(z, Pa), _mm256_permute2f128_ps(Pa, Pa, 0x01)), Pb);
    if (k == 4u) m = _mm256_add_ps(m, _mm256_permute2f128_ps(Pb, Pb, 0x01));
    m = f8_out(_mm256_div_ps(m, _mm256_set1_ps((float)k)), 0x07, &ls);
    m = _mm256_permute2f128_ps(m, m, 0x00);
    da = f8_out(_mm256_sub_ps(m, Pa), 0x77, &ls);
    db = f8_out(_mm256_sub_ps(m, Pb), k23, &ls);
    m = _mm256_set1_ps(C->g1n);
    ta = _mm256_mul_ps(da, m);
    tb = _mm256_mul_ps(db, m);
    /* the last end's: ((0 - t0) - t1) (- t2), limited */
    l = _mm256_sub_ps(_mm256_sub_ps(z, ta), _mm256_permute2f128_ps(ta, ta, 0x01));
    if (k == 4u) l = _mm256_sub_ps(l, tb);
    l = f8_lim(l, _mm256_set1_ps((sn_acc)2 * SN_LIM));
    tb = k == 4u ? _mm256_insertf128_ps(tb, _mm256_castps256_ps128(l), 1) : _mm256_insertf128_ps(tb, _mm256_castps256_ps128(l), 0);
    Ga = f8_out(_mm256_add_ps(Ga, ta), 0x77, &ls);
    Gb = f8_out(_mm256_add_ps(Gb, tb), k23, &ls);
    ua = f8_turn(ua, da, ka);
    ub = f8_turn(ub, db, kb);
    f8_store(S0, S1, Ga, ua, 1);
    f8_store(S2, S3, Gb, ub, k == 4u);
    *sat += ls;
}
#endif
#if defined(__AVX2__)
/* pins_fv with ends 0-1 and 2-3 in the halves of two 8-lane vectors (k = 2:
 * one vector; k = 3: the 4th half repeats end 0, never counted or stored) */
SN_INLINE void pin_f8(const seg_ctx *C, sn_q *A, sn_q *B, f8 neg, f8 h, f8 kv, const f8 T, int km, int hb, uint32_t *sat) {
    f8 G = F8_PAIR(_mm_loadu_ps(A), _mm_loadu_ps(B)), u = F8_PAIR(_mm_loadu_ps(A + 3), _mm_loadu_ps(B + 3)), d;
    /* end_of: the offset from the positive half, added or subtracted */
    d = f8_out(_mm256_add_ps(G, _mm256_xor_ps(_mm256_mul_ps(u, h), neg)), km, sat);
    d = f8_out(_mm256_sub_ps(T, d), km, sat);
    G = f8_out(_mm256_add_ps(G, f8_out(_mm256_mul_ps(d, _mm256_set1_ps(C->g1n)), km, sat)), km, sat);
    u = f8_turn(u, d, _mm256_xor_ps(kv, neg));
    f8_store(A, B, G, u, hb);
}
/* (pins_f8) */
void seg_pins_fx(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3],
                    uint32_t *sat) {
    sn_q *S0 = L->S + SEG_W * seg[0], *S1 = L->S + SEG_W * seg[1];
    sn_q *S2 = k >= 3u ? L->S + SEG_W * seg[2] : S0, *S3 = k == 4u ? L->S + SEG_W * seg[3] : S0;
    const __m256i sv = _mm256_castsi128_si256(_mm_cmplt_epi32(
        _mm_setr_epi32(sgn[0], sgn[1], k >= 3u ? sgn[2] : sgn[0], k == 4u ? sgn[3] : sgn[0]), _mm_setzero_si128()));
    const f8 sz = _mm256_set1_ps(-0.0f);
    const f8 Tv = _mm256_setr_ps(T[0], T[1], T[2], 0.0f, T[0], T[1], T[2], 0.0f);
    f8 ha, hb, ka, kb;
    uint32_t ls = 0;
    f8_lvl(C, L, S0, S1, S2, S3, &ha, &hb, &ka, &kb);
    pin_f8(C, S0, S1, _mm256_and_ps(_mm256_castsi256_ps(_mm256_permutevar8x32_epi32(sv, _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1))), sz),
           ha, ka, Tv, 0x77, 1, &ls);
    if (k >= 3u)
        pin_f8(C, S2, S3, _mm256_and_ps(_mm256_castsi256_ps(_mm256_permutevar8x32_epi32(sv, _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3))), sz),
               hb, kb, Tv, k == 4u ? 0x77 : 0x07, k == 4u, &ls);
    *sat += ls;
}
#endif
#if !defined(__AVX2__)
/* An attachment's pins (pin(), not measuring) on its k = 2..4 ends in the
 * lanes of star_fv's vectors (distinct segments, a fixed target: the moves
 * are independent). Per lane pin()'s floats: P = sn_out(G +- half u),
 * d = sn_out(T - P), t = sn_out(d omega gamma), move_seg. */
/* (pins_fv) */
void seg_pins_fx(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3],
                    uint32_t *sat) {
    sn_q *S0 = L->S + SEG_W * seg[0], *S1 = L->S + SEG_W * seg[1];
    sn_q *S2 = k >= 3u ? L->S + SEG_W * seg[2] : S0, *S3 = k == 4u ? L->S + SEG_W * seg[3] : S0;
    const int km = k == 4u ? 0xF : (k == 3u ? 0x7 : 0x3);
    const __m128 neg = _mm_and_ps(_mm_castsi128_ps(_mm_cmplt_epi32(
                                      _mm_setr_epi32(sgn[0], sgn[1], k >= 3u ? sgn[2] : sgn[0], k == 4u ? sgn[3] : sgn[0]),
                                      _mm_setzero_si128())),
                                  _mm_set1_ps(-0.0f));
    __m128 G0, G1, G2, u0, u1, u2, d0, d1, d2, kv, hv;
    uint32_t ls = 0;
    fv_load4(S0, S1, S2, S3, &G0, &G1, &G2, &u0, &u1, &u2);
    fv_lvl(L, S0, S1, S2, S3, C->rf1, C->kf1, &hv, &kv);
    kv = _mm_xor_ps(kv, neg);
    /* end_of: the offset from the positive half, added or subtracted (x - o = x + (-o)) */
    d0 = fv_out(_mm_add_ps(G0, _mm_xor_ps(_mm_mul_ps(u0, hv), neg)), km, &ls);
    d1 = fv_out(_mm_add_ps(G1, _mm_xor_ps(_mm_mul_ps(u1, hv), neg)), km, &ls);
    d2 = fv_out(_mm_add_ps(G2, _mm_xor_ps(_mm_mul_ps(u2, hv), neg)), km, &ls);
    d0 = fv_out(_mm_sub_ps(_mm_set1_ps(T[0]), d0), km, &ls);
    d1 = fv_out(_mm_sub_ps(_mm_set1_ps(T[1]), d1), km, &ls);
    d2 = fv_out(_mm_sub_ps(_mm_set1_ps(T[2]), d2), km, &ls);
    hv = _mm_set1_ps(C->g1n);
    G0 = fv_out(_mm_add_ps(G0, fv_out(_mm_mul_ps(d0, hv), km, &ls)), km, &ls);
    G1 = fv_out(_mm_add_ps(G1, fv_out(_mm_mul_ps(d1, hv), km, &ls)), km, &ls);
    G2 = fv_out(_mm_add_ps(G2, fv_out(_mm_mul_ps(d2, hv), km, &ls)), km, &ls);
    fv_turn(&u0, &u1, &u2, d0, d1, d2, kv);
    fv_store(S0, S1, S2, S3, G0, G1, G2, u0, u1, u2, k);
    *sat += ls;
}
#endif
#else
typedef int sn_kernels_seg_fx86_empty_; /* ISO C: a translation unit declares something */
#endif
