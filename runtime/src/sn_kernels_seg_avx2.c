/* sn_kernels_seg_avx2.c -- the fixed star projection of a sheet node
 * (sn_segment_sweep.c star(), seed 004 §3.2) with its k = 3 or 4 ends in the
 * int64 lanes of AVX2 vectors (x86-64 AVX2 and AVX-512 builds, fixed, not
 * under SN_SIMD_SCALAR). Same integers as star(): every factor is an int32
 * (the bounds of star/move_seg, SEGMENTS.md "Fixed point, bounds"), so a
 * product is one VPMULDQ of the lanes' low words; a rounded shift whose
 * result is an int32 is the low word of a LOGICAL shift (AVX2 has no 64-bit
 * arithmetic one: the low 32 bits of x >> s agree for s <= 32); int32 sums
 * are 32-bit adds on the low words; the turn's limiter is taken before its
 * shift (clamp(y, +-2^(28+sh)) >> sh = clamp(y >> sh, +-2^28), floor
 * shifts); the mean's sums over the ends are exact int64 sums (any order);
 * the rare clamped lanes of seg_out go through the scalar clamp with their
 * counts. The lane of a missing 4th end (k = 3) repeats end 0 and is
 * neither summed, counted nor stored. KERNELS.md "Segment sweeps, round 2". */
#include "sn_segment.h"

#if defined(SEG_STAR_IV)
#include <immintrin.h>

typedef __m256i v4;
/* the lane helpers inlined (GCC kept move_iv a call, its arrays in memory) */
#if defined(__GNUC__)
#define IV_HOT static inline __attribute__((always_inline))
#else
#define IV_HOT static inline
#endif
/* the loops over the three components unrolled (else GCC keeps them, their vectors in memory) */
#if defined(__GNUC__)
#define IV_UNROLL3 _Pragma("GCC unroll 3")
#else
#define IV_UNROLL3
#endif
#define V64(x) _mm256_set1_epi64x((long long)(x))
#define LDV(p) _mm256_loadu_si256((const v4 *)(const void *)(p))

/* r30 of int64 lanes whose results are int32 (low words valid) */
SN_INLINE v4 r30v(v4 a) { return _mm256_srli_epi64(_mm256_add_epi64(a, V64((int64_t)1 << 29)), 30); }
/* r30s(x, b) of the lanes' low words */
SN_INLINE v4 r30sv(v4 x, v4 b) { return r30v(_mm256_mul_epi32(x, b)); }
/* the low words sign-extended to the lanes (VPMULDQ by 1: one instruction) */
SN_INLINE v4 sextv(v4 a) { return _mm256_mul_epi32(a, V64(1)); }
/* all four lanes: the int64 sum of the lanes */
SN_INLINE v4 hsum64(v4 a) {
    a = _mm256_add_epi64(a, _mm256_permute4x64_epi64(a, 0x4E));
    return _mm256_add_epi64(a, _mm256_shuffle_epi32(a, 0x4E));
}
/* seg_out of the low words in the lanes of km (bit 2j: lane j): unchanged
 * within +-SN_LIM, else clamped and counted by the scalar code */
SN_INLINE v4 outv(v4 v, int km, uint32_t *sat) {
    const v4 lim = _mm256_set1_epi32(SN_LIM), nlim = _mm256_set1_epi32(-SN_LIM);
    const int f = _mm256_movemask_ps(_mm256_castsi256_ps(
                      _mm256_or_si256(_mm256_cmpgt_epi32(v, lim), _mm256_cmpgt_epi32(nlim, v)))) & km;
    if (f) {
        int32_t x[8];
        unsigned j;
        _mm256_storeu_si256((v4 *)(void *)x, v);
        for (j = 0; j < 8; j += 2)
            if (f >> j & 1) x[j] = (int32_t)seg_out(x[j], sat);
        v = LDV(x);
    }
    return v;
}
/* outv of three vectors: one test of all three on the straight path */
IV_HOT void outv3(v4 v[3], int km, uint32_t *sat) {
    const v4 lim = _mm256_set1_epi32(SN_LIM), nlim = _mm256_set1_epi32(-SN_LIM);
    const v4 o = _mm256_or_si256(_mm256_or_si256(_mm256_or_si256(_mm256_cmpgt_epi32(v[0], lim), _mm256_cmpgt_epi32(nlim, v[0])),
                                                 _mm256_or_si256(_mm256_cmpgt_epi32(v[1], lim), _mm256_cmpgt_epi32(nlim, v[1]))),
                                 _mm256_or_si256(_mm256_cmpgt_epi32(v[2], lim), _mm256_cmpgt_epi32(nlim, v[2])));
    if (_mm256_movemask_ps(_mm256_castsi256_ps(o)) & km) {
        v[0] = outv(v[0], km, sat);
        v[1] = outv(v[1], km, sat);
        v[2] = outv(v[2], km, sat);
    }
}
/* y clamped to [lo, hi] (int64 lanes) */
SN_INLINE v4 clampv(v4 y, v4 lo, v4 hi) {
    y = _mm256_blendv_epi8(y, hi, _mm256_cmpgt_epi64(y, hi));
    return _mm256_blendv_epi8(y, lo, _mm256_cmpgt_epi64(lo, y));
}
/* (x ^ n) - n: x negated in the lanes where n is all ones */
SN_INLINE v4 negv(v4 x, v4 n) { return _mm256_sub_epi32(_mm256_xor_si256(x, n), n); }

/* words 0-5 of four segments (S3 may repeat one) as lanes: G[c], u[c] sign-extended */
IV_HOT void load_iv(const sn_q *S0, const sn_q *S1, const sn_q *S2, const sn_q *S3, v4 G[3], v4 u[3]) {
    const v4 r0 = LDV(S0), r1 = LDV(S1), r2 = LDV(S2), r3 = LDV(S3); /* words 0-7 (a segment has 16) */
    const v4 a = _mm256_unpacklo_epi32(r0, r1), b = _mm256_unpacklo_epi32(r2, r3);
    const v4 c = _mm256_unpackhi_epi32(r0, r1), d = _mm256_unpackhi_epi32(r2, r3);
    const v4 w04 = _mm256_unpacklo_epi64(a, b), w15 = _mm256_unpackhi_epi64(a, b);
    const v4 w26 = _mm256_unpacklo_epi64(c, d), w37 = _mm256_unpackhi_epi64(c, d);
    G[0] = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(w04));
    u[1] = _mm256_cvtepi32_epi64(_mm256_extracti128_si256(w04, 1));
    G[1] = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(w15));
    u[2] = _mm256_cvtepi32_epi64(_mm256_extracti128_si256(w15, 1));
    G[2] = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(w26));
    u[0] = _mm256_cvtepi32_epi64(_mm256_castsi256_si128(w37));
}
/* the lanes' low words back to words 0-5 of the first n (2..4) segments: per
 * lane the word pairs (G0 G1), (G2 u0), (u1 u2) as one int64 each */
IV_HOT void store_iv(sn_q *S0, sn_q *S1, sn_q *S2, sn_q *S3, const v4 G[3], const v4 u[3], unsigned n) {
    const v4 q01 = _mm256_blend_epi32(G[0], _mm256_slli_epi64(G[1], 32), 0xAA);
    const v4 q23 = _mm256_blend_epi32(G[2], _mm256_slli_epi64(u[0], 32), 0xAA);
    const v4 q45 = _mm256_blend_epi32(u[1], _mm256_slli_epi64(u[2], 32), 0xAA);
    const v4 e02 = _mm256_unpacklo_epi64(q01, q23), e13 = _mm256_unpackhi_epi64(q01, q23);
    const __m128i w01 = _mm256_castsi256_si128(q45);
    _mm_storeu_si128((__m128i *)(void *)S0, _mm256_castsi256_si128(e02));
    _mm_storel_epi64((__m128i *)(void *)(S0 + 4), w01);
    _mm_storeu_si128((__m128i *)(void *)S1, _mm256_castsi256_si128(e13));
    _mm_storeh_pd((double *)(void *)(S1 + 4), _mm_castsi128_pd(w01));
    if (n >= 3u) {
        const __m128i w23 = _mm256_extracti128_si256(q45, 1);
        _mm_storeu_si128((__m128i *)(void *)S2, _mm256_extracti128_si256(e02, 1));
        _mm_storel_epi64((__m128i *)(void *)(S2 + 4), w23);
        if (n == 4u) {
            _mm_storeu_si128((__m128i *)(void *)S3, _mm256_extracti128_si256(e13, 1));
            _mm_storeh_pd((double *)(void *)(S3 + 4), _mm_castsi128_pd(w23));
        }
    }
}
/* move_seg's turn (sn_segment_sweep.c) in the lanes: gaps d, turn factors
 * kv, shifts shv and biases bv; the translation G + t (seg_out, counted) is
 * the callers' (independent of the turn: fewer vectors live at once) */
IV_HOT void turn_iv(v4 u[3], const v4 d[3], v4 kv, v4 shv, v4 bv) {
    const v4 hi = _mm256_sllv_epi64(V64(ROT_MAX), shv), lo = _mm256_sub_epi64(_mm256_setzero_si256(), hi);
    v4 du, e0, e1, e2, eu, x0, x1, x2, f;
    du = r30v(_mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(d[0], u[0]), _mm256_mul_epi32(d[1], u[1])),
                               _mm256_mul_epi32(d[2], u[2])));
    e0 = _mm256_srlv_epi64(clampv(_mm256_add_epi64(_mm256_mul_epi32(_mm256_sub_epi32(d[0], r30sv(du, u[0])), kv), bv), lo, hi), shv);
    e1 = _mm256_srlv_epi64(clampv(_mm256_add_epi64(_mm256_mul_epi32(_mm256_sub_epi32(d[1], r30sv(du, u[1])), kv), bv), lo, hi), shv);
    e2 = _mm256_srlv_epi64(clampv(_mm256_add_epi64(_mm256_mul_epi32(_mm256_sub_epi32(d[2], r30sv(du, u[2])), kv), bv), lo, hi), shv);
    eu = r30v(_mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(e0, u[0]), _mm256_mul_epi32(e1, u[1])),
                               _mm256_mul_epi32(e2, u[2])));
    x0 = _mm256_sub_epi32(_mm256_add_epi32(u[0], e0), r30sv(eu, u[0]));
    x1 = _mm256_sub_epi32(_mm256_add_epi32(u[1], e1), r30sv(eu, u[1]));
    x2 = _mm256_sub_epi32(_mm256_add_epi32(u[2], e2), r30sv(eu, u[2]));
    /* f = sn_rshr64(3 2^60 - |x|^2, 31): positive, so the logical shift */
    f = _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epi32(x0, x0), _mm256_mul_epi32(x1, x1)), _mm256_mul_epi32(x2, x2));
    f = _mm256_srli_epi64(_mm256_sub_epi64(V64(((int64_t)3 << 60) + ((int64_t)1 << 30)), f), 31);
    u[0] = r30sv(x0, f); u[1] = r30sv(x1, f); u[2] = r30sv(x2, f);
}

/* An end's level constants in the lanes (seg_kf, seg_bias): on a coarse
 * level each segment's own half (word 12), turn factor r30s(rf, word 13),
 * shift (word 14) and bias 2^(shift-1); on level 0 the level's half, kf,
 * shift and bias0 in every lane. rf, kf: rf1, kf1 (star, pins) or rf2, kf0
 * (pair). */
IV_HOT void lvl_iv(const seg_ctx *C, const seg_lvl *L, const sn_q *S0, const sn_q *S1, const sn_q *S2, const sn_q *S3,
                   sn_q rf, seg_n kf, v4 *hv, v4 *kv, v4 *shv, v4 *bv) {
    if (L->l != 0) {
        *hv = _mm256_setr_epi64x(S0[12], S1[12], S2[12], S3[12]);
        *kv = r30sv(V64(rf), _mm256_setr_epi64x(S0[13], S1[13], S2[13], S3[13]));
        *shv = _mm256_setr_epi64x(S0[14], S1[14], S2[14], S3[14]);
        *bv = _mm256_srli_epi64(_mm256_sllv_epi64(V64(1), *shv), 1);
    } else {
        *hv = V64(L->half);
        *kv = V64(kf);
        *shv = V64(L->sh);
        *bv = V64(C->bias0);
    }
}

void seg_star_iv(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, uint32_t *sat) {
    sn_q *S0 = L->S + SEG_W * seg[0], *S1 = L->S + SEG_W * seg[1], *S2 = L->S + SEG_W * seg[2];
    sn_q *S3 = k == 4u ? L->S + SEG_W * seg[3] : S0;
    const int km = k == 4u ? 0x55 : 0x15;
    const v4 z = _mm256_setzero_si256();
    /* lanes of the mean (all k ends) and of the ends before the last */
    const v4 lm = k == 4u ? _mm256_set1_epi64x(-1) : _mm256_setr_epi64x(-1, -1, -1, 0);
    const v4 tm = k == 4u ? _mm256_setr_epi64x(-1, -1, -1, 0) : _mm256_setr_epi64x(-1, -1, 0, 0);
    const v4 neg = _mm256_setr_epi64x(sgn[0] < 0 ? -1 : 0, sgn[1] < 0 ? -1 : 0, sgn[2] < 0 ? -1 : 0,
                                      (k == 4u ? sgn[3] : sgn[0]) < 0 ? -1 : 0);
    v4 G[3], u[3], P[3], d[3], t[3], hv, kv, shv, bv, s;
    uint32_t ls = 0;
    unsigned c;
    load_iv(S0, S1, S2, S3, G, u);
    lvl_iv(C, L, S0, S1, S2, S3, C->rf1, C->kf1, &hv, &kv, &shv, &bv);
    hv = negv(hv, neg);
    kv = negv(kv, neg);
    IV_UNROLL3
    for (c = 0; c < 3; c++) {
        /* the ends G +- half u (|.| < 2^30), their mean (mean_k, counted),
         * D = m - P (|m| <= 2^28: within int32, seg_out) */
        P[c] = _mm256_add_epi32(G[c], r30sv(hv, u[c]));
        s = hsum64(_mm256_and_si256(sextv(P[c]), lm));
        d[c] = _mm256_sub_epi32(V64(mean_k(_mm_cvtsi128_si64(_mm256_castsi256_si128(s)), k, &ls)), P[c]);
    }
    outv3(d, km, &ls);
    {   /* t = D omega gamma (|.| <= 2^29); the last end's: minus the others'
         * sum (< 2^30.6, an int32) limited to +-2^29 (seg_lim) */
        const v4 g = V64(C->g1n), last = k == 4u ? _mm256_setr_epi64x(0, 0, 0, -1) : _mm256_setr_epi64x(0, 0, -1, 0);
        const v4 m2 = _mm256_set1_epi32(2 * SN_LIM), nm2 = _mm256_set1_epi32(-2 * SN_LIM);
        IV_UNROLL3
    for (c = 0; c < 3; c++) {
            t[c] = r30sv(d[c], g);
            s = _mm256_and_si256(t[c], tm);
            s = _mm256_add_epi32(s, _mm256_permute4x64_epi64(s, 0x4E));
            s = _mm256_add_epi32(s, _mm256_shuffle_epi32(s, 0x4E));
            s = _mm256_max_epi32(_mm256_min_epi32(_mm256_sub_epi32(z, s), m2), nm2);
            G[c] = _mm256_add_epi32(G[c], _mm256_blendv_epi8(t[c], s, last));
        }
    }
    outv3(G, km, &ls);
    turn_iv(u, d, kv, shv, bv);
    store_iv(S0, S1, S2, S3, G, u, k);
    *sat += ls;
}

/* pair() (not measuring) with its two moves in lanes 0 (segment a) and 1
 * (b), lanes 2-3 repeating them unstored: d = P_b - P_a clamped and counted
 * once (lane 0), t = r30s(d, omega gamma / 2); a takes +d, +t, b -d, -t */
void seg_pair_iv(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, uint32_t *sat) {
    sn_q *A = L->S + SEG_W * a, *B = L->S + SEG_W * b;
    const long long na = sa < 0 ? -1 : 0, nb = sb < 0 ? -1 : 0;
    const v4 neg = _mm256_setr_epi64x(na, nb, na, nb), nl1 = _mm256_setr_epi64x(0, -1, 0, -1);
    v4 G[3], u[3], d[3], hv, kv, shv, bv, g = V64(C->gh);
    uint32_t ls = 0;
    unsigned c;
    load_iv(A, B, A, B, G, u);
    lvl_iv(C, L, A, B, A, B, C->rf2, C->kf0, &hv, &kv, &shv, &bv);
    hv = negv(hv, neg);
    kv = negv(kv, neg);
    IV_UNROLL3
    for (c = 0; c < 3; c++) { /* lane 0: P_b - P_a (lanes swapped in pairs) */
        const v4 P = _mm256_add_epi32(G[c], r30sv(hv, u[c]));
        d[c] = _mm256_sub_epi32(_mm256_shuffle_epi32(P, 0x4E), P);
    }
    outv3(d, 0x01, &ls); /* seg_out counted in lane 0 only */
    IV_UNROLL3
    for (c = 0; c < 3; c++) {
        G[c] = _mm256_add_epi32(G[c], negv(_mm256_permute4x64_epi64(r30sv(d[c], g), 0x00), nl1));
        d[c] = negv(_mm256_permute4x64_epi64(d[c], 0x00), nl1);
    }
    outv3(G, 0x05, &ls);
    turn_iv(u, d, kv, shv, bv);
    store_iv(A, B, A, B, G, u, 2u);
    *sat += ls;
}

/* An attachment's pins (pin(), not measuring) on its k = 2..4 ends at once:
 * the ends are distinct segments and the target T fixed, so the k moves are
 * independent (any order: the same state). Per lane: the end P = G +- r30s(half, u)
 * (end_of: the offset rounded from the positive half, then added or
 * subtracted) clamped and counted, d = T - P (sn_add: int64, clamped and
 * counted), t = r30s(d, omega gamma) clamped and counted, move_seg. */
void seg_pins_iv(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3],
                 uint32_t *sat) {
    sn_q *S0 = L->S + SEG_W * seg[0], *S1 = L->S + SEG_W * seg[1];
    sn_q *S2 = k >= 3u ? L->S + SEG_W * seg[2] : S0, *S3 = k == 4u ? L->S + SEG_W * seg[3] : S0;
    const int km = k == 4u ? 0x55 : (k == 3u ? 0x15 : 0x05), kq = k == 4u ? 0xF : (k == 3u ? 0x7 : 0x3);
    const v4 neg = _mm256_setr_epi64x(sgn[0] < 0 ? -1 : 0, sgn[1] < 0 ? -1 : 0, (k >= 3u ? sgn[2] : sgn[0]) < 0 ? -1 : 0,
                                      (k == 4u ? sgn[3] : sgn[0]) < 0 ? -1 : 0);
    const v4 lim = V64(SN_LIM), nlim = V64(-SN_LIM), g = V64(C->g1n);
    v4 G[3], u[3], P[3], d[3], hv, kv, shv, bv;
    uint32_t ls = 0;
    unsigned c;
    load_iv(S0, S1, S2, S3, G, u);
    lvl_iv(C, L, S0, S1, S2, S3, C->rf1, C->kf1, &hv, &kv, &shv, &bv);
    kv = negv(kv, neg);
    IV_UNROLL3
    for (c = 0; c < 3; c++) P[c] = _mm256_add_epi32(G[c], negv(r30sv(hv, u[c]), neg));
    outv3(P, km, &ls);
    IV_UNROLL3
    for (c = 0; c < 3; c++) d[c] = _mm256_sub_epi64(V64(T[c]), sextv(P[c]));
    {   /* sn_add's clamp of the int64 differences */
        const v4 o = _mm256_or_si256(_mm256_or_si256(_mm256_or_si256(_mm256_cmpgt_epi64(d[0], lim), _mm256_cmpgt_epi64(nlim, d[0])),
                                                     _mm256_or_si256(_mm256_cmpgt_epi64(d[1], lim), _mm256_cmpgt_epi64(nlim, d[1]))),
                                     _mm256_or_si256(_mm256_cmpgt_epi64(d[2], lim), _mm256_cmpgt_epi64(nlim, d[2])));
        if (_mm256_movemask_pd(_mm256_castsi256_pd(o)) & kq) {
            int64_t x[4];
            unsigned j;
            for (c = 0; c < 3; c++) {
                _mm256_storeu_si256((v4 *)(void *)x, d[c]);
                for (j = 0; j < k; j++)
                    if (x[j] > SN_LIM || x[j] < -SN_LIM) { ls++; x[j] = x[j] > 0 ? SN_LIM : -SN_LIM; }
                d[c] = LDV(x);
            }
        }
    }
    IV_UNROLL3
    for (c = 0; c < 3; c++) P[c] = r30sv(d[c], g); /* t */
    outv3(P, km, &ls);
    IV_UNROLL3
    for (c = 0; c < 3; c++) G[c] = _mm256_add_epi32(G[c], P[c]);
    outv3(G, km, &ls);
    turn_iv(u, d, kv, shv, bv);
    store_iv(S0, S1, S2, S3, G, u, k);
    *sat += ls;
}
#else
typedef int sn_kernels_seg_avx2_empty_; /* ISO C: a translation unit declares something */
#endif
