/* sn_kernels_xnorm.c -- fixed flavour: sn_get_normals' area-weighted
 * vertex normals. The same integers as the loop in sn_embed.c before
 * issue 15 (test_runtime_surface keeps that loop as its reference):
 * - each face's e1 x e2 exact in int64 (edges clamped to +-2^30 only when
 *   a position lies beyond +-2^29: within that no edge reaches the clamp);
 * - one shift for the mesh, bitlen(max |n_k|) - 24 (>= 0): the first pass
 *   ORs the magnitudes (the OR's bit length is the maximum's);
 * - the rounded, shifted components summed per vertex in int32,
 *   saturating. Each term is <= 2^24, so a vertex of at most 127 faces
 *   cannot saturate: the first pass counts every vertex's faces (in out,
 *   zeroed after) and, when all are below 128, the sums are plain adds;
 * - the unit step, sn_unit's (sn_math.c) integers on (x, y, z, 0).
 * x86-64 (not SIMD=scalar): the unit step's rounded root from the double
 * root, corrected exactly (sn_k_xrsqrt); AVX2: both triangle
 * passes' cross products eight faces at a time in lanes. */
#include "sn_kernels_xnorm.h"
#include "sn_kernels.h"

#if !defined(SN_FLOAT)
#if defined(__x86_64__) && defined(__SSE2__) && defined(__GNUC__) && !defined(SN_SIMD_SCALAR)
#define SN_XN_DSQRT 1
#include <emmintrin.h>
#endif
#if defined(SN_KERNELS_AVX2)
#include <immintrin.h>
#endif

/* the nearest integer to sqrt(x) for 16 <= x < 3 2^62 (sn_unit's rounded
 * root: floor, plus one when x - floor^2 > floor). x86-64: sqrt(2 (x >> 1))
 * in double (x >> 1 < 2^62 converts as int64; 2 d is exact; the conversion
 * and the root each round by <= 2^-53 relative and the dropped bit moves
 * the root by < 2^-3 for x >= 16): within 1/2 + 2^-3 of the root, so the
 * nearest integer to it is the answer or one off; one exact test either
 * way fixes it (R is the answer iff R^2 - R < x <= R^2 + R; R < 2^32: no
 * overflow). Elsewhere sn_isqrt64 and the rounding step. */
SN_INLINE uint64_t xrsqrt(uint64_t x) {
#if defined(SN_XN_DSQRT)
    const __m128d d = _mm_cvtsi64_sd(_mm_setzero_pd(), (long long)(x >> 1));
    uint64_t R = (uint64_t)(int64_t)(_mm_cvtsd_f64(_mm_sqrt_sd(d, _mm_add_sd(d, d))) + 0.5), R2;
    R2 = R * R;
    if (x > R2 + R) R++;
    else if (x <= R2 - R) R--;
    return R;
#else
    uint64_t N = sn_isqrt64(x);
    if (x - N * N > N) N++;
    return N;
#endif
}
uint32_t sn_k_xrsqrt(uint64_t x) { return (uint32_t)xrsqrt(x); }

/* one summed normal to unit length in place: sn_qnormalize on (x, y, z, 0)
 * (sn_unit with n = 4: the zero fourth component adds nothing to the
 * maximum or the squares); a zero sum gives (0, 0, 1). Off x86-64
 * sn_qnormalize itself. */
SN_INLINE void xunit1(sn_vec3 *o) {
#if defined(SN_XN_DSQRT)
    const int32_t c0 = o->x, c1 = o->y, c2 = o->z;
    uint64_t a0 = c0 < 0 ? (uint64_t)0 - (uint64_t)(int64_t)c0 : (uint64_t)c0;
    uint64_t a1 = c1 < 0 ? (uint64_t)0 - (uint64_t)(int64_t)c1 : (uint64_t)c1;
    uint64_t a2 = c2 < 0 ? (uint64_t)0 - (uint64_t)(int64_t)c2 : (uint64_t)c2;
    const uint64_t m = a0 | a1 | a2; /* its bit length is the maximum's */
    uint64_t n2, N, r, v0, v1, v2;
    int b;
    if (!m) { o->z = SN_ONE_ROT; return; }
    b = 64 - __builtin_clzll(m);
    if (b > 31) { a0 >>= b - 31; a1 >>= b - 31; a2 >>= b - 31; }
    else { a0 <<= 31 - b; a1 <<= 31 - b; a2 <<= 31 - b; }
    n2 = a0 * a0 + a1 * a1 + a2 * a2; /* each < 2^62 */
    N = xrsqrt(n2); /* n2 in [2^60, 3 2^62) */
    if (N <= ((uint64_t)1 << 30)) r = (uint64_t)1 << 32;
    else if (N >= ((uint64_t)1 << 32)) r = (uint64_t)1 << 30;
    else {
        const int s = N < ((uint64_t)1 << 31) ? 1 : 0;
        r = sn_div64n((((uint64_t)1 << 62) + (N >> 1)) << s, (uint32_t)(N << s));
    }
    v0 = (a0 * r + ((uint64_t)1 << 31)) >> 32; v1 = (a1 * r + ((uint64_t)1 << 31)) >> 32; v2 = (a2 * r + ((uint64_t)1 << 31)) >> 32;
    o->x = c0 < 0 ? -(int32_t)v0 : (int32_t)v0;
    o->y = c1 < 0 ? -(int32_t)v1 : (int32_t)v1;
    o->z = c2 < 0 ? -(int32_t)v2 : (int32_t)v2;
#else
    sn_q q[4];
    q[0] = o->x; q[1] = o->y; q[2] = o->z; q[3] = 0;
    if (q[0] == 0 && q[1] == 0 && q[2] == 0) { o->z = SN_ONE_ROT; return; }
    sn_qnormalize(q);
    o->x = q[0]; o->y = q[1]; o->z = q[2];
#endif
}
#if defined(SN_KERNELS_AVX2)
/* uint64 lanes below 2^52 as doubles, exact (the 2^52 exponent trick) */
SN_INLINE __m256d xu2d(__m256i v) {
    const __m256i mg = _mm256_set1_epi64x(0x4330000000000000);
    return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(v, mg)), _mm256_castsi256_pd(mg));
}
/* doubles in [0, 2^51) to the nearest integer (d + 2^52 has ulp 1) */
SN_INLINE __m256i xd2u(__m256d d) {
    const __m256d mg = _mm256_set1_pd(4503599627370496.0);
    return _mm256_sub_epi64(_mm256_castpd_si256(_mm256_add_pd(d, mg)), _mm256_castpd_si256(mg));
}
/* xunit1 for four vertices in int64 lanes, the same integers: |c| in
 * int32 (INT32_MIN's as 2^31), b from the exponent of m as an exact double,
 * the scaling by per-lane shifts, the squares 32 x 32 -> 64 (a < 2^31);
 * N from the double root of n2 (its two 32-bit halves, one rounding) to
 * the nearest integer, corrected exactly as in xrsqrt (n2 and the bounds
 * compared as unsigned: sign bits flipped); r = floor((2^62 + N/2) / N)
 * from the double quotient minus 1/2 to the nearest integer (within 1 of
 * r: the numerator rounds by <= 2^9, the quotient by <= 2^-21), at most
 * 2^32 - 1, then q N > num: q - 1, (q + 1) N <= num: q + 1 (q N < 2^63);
 * N <= 2^30: r = 2^32, v = a. Zero lanes take N = 2^31 for the unused
 * quotient (no division by 0: no floating-point exception raised). */
static void xunit4(sn_vec3 *o) {
    const int *P = (const int *)(void *)o;
    const __m128i ix = _mm_setr_epi32(0, 3, 6, 9);
    const __m128i cx = _mm_i32gather_epi32(P, ix, 4), cy = _mm_i32gather_epi32(P + 1, ix, 4), cz = _mm_i32gather_epi32(P + 2, ix, 4);
    const __m128i z32 = _mm_cmpeq_epi32(_mm_or_si128(_mm_or_si128(cx, cy), cz), _mm_setzero_si128());
    const __m256i a0 = _mm256_cvtepu32_epi64(_mm_abs_epi32(cx)), a1 = _mm256_cvtepu32_epi64(_mm_abs_epi32(cy)),
                  a2 = _mm256_cvtepu32_epi64(_mm_abs_epi32(cz));
    const __m256i m = _mm256_or_si256(_mm256_or_si256(a0, a1), a2);
    const __m256i b = _mm256_sub_epi64(_mm256_srli_epi64(_mm256_castpd_si256(xu2d(m)), 52), _mm256_set1_epi64x(1022));
    const __m256i sl = _mm256_sub_epi64(_mm256_set1_epi64x(31), b), sr = _mm256_sub_epi64(b, _mm256_set1_epi64x(31));
    /* counts beyond 63 (a negative count) give 0: b <= 31 shifts left, b = 32 right by 1 */
    const __m256i s0 = _mm256_or_si256(_mm256_sllv_epi64(a0, sl), _mm256_srlv_epi64(a0, sr)),
                  s1 = _mm256_or_si256(_mm256_sllv_epi64(a1, sl), _mm256_srlv_epi64(a1, sr)),
                  s2 = _mm256_or_si256(_mm256_sllv_epi64(a2, sl), _mm256_srlv_epi64(a2, sr));
    const __m256i n2 = _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epu32(s0, s0), _mm256_mul_epu32(s1, s1)), _mm256_mul_epu32(s2, s2));
    const __m256i sg = _mm256_set1_epi64x(INT64_MIN), ones = _mm256_set1_epi64x(-1), lo32 = _mm256_set1_epi64x(0xFFFFFFFF);
    const __m256d dn2 = _mm256_add_pd(_mm256_mul_pd(xu2d(_mm256_srli_epi64(n2, 32)), _mm256_set1_pd(4294967296.0)),
                                      xu2d(_mm256_and_si256(n2, lo32)));
    const __m256i zero = _mm256_cvtepi32_epi64(z32), ux = _mm256_xor_si256(n2, sg);
    __m256i R = xd2u(_mm256_sqrt_pd(dn2)), R2, big, num, q, qn, v0, v1, v2;
    __m256d qd;
    __m128i ox, oy, oz;
    int32_t fx[4], fy[4], fz[4];
    int k;
    R2 = _mm256_mul_epu32(R, R);
    R = _mm256_sub_epi64(R, _mm256_cmpgt_epi64(ux, _mm256_xor_si256(_mm256_add_epi64(R2, R), sg)));          /* x > R^2 + R: + 1 */
    R = _mm256_add_epi64(R, _mm256_xor_si256(_mm256_cmpgt_epi64(ux, _mm256_xor_si256(_mm256_sub_epi64(R2, R), sg)), ones)); /* x <= R^2 - R: - 1 */
    R = _mm256_blendv_epi8(R, _mm256_set1_epi64x((int64_t)1 << 31), zero);
    big = _mm256_cmpgt_epi64(R, _mm256_set1_epi64x((int64_t)1 << 30));
    num = _mm256_add_epi64(_mm256_set1_epi64x((int64_t)1 << 62), _mm256_srli_epi64(R, 1));
    qd = _mm256_div_pd(_mm256_add_pd(xu2d(_mm256_srli_epi64(R, 1)), _mm256_set1_pd(4611686018427387904.0)), xu2d(R));
    q = xd2u(_mm256_sub_pd(qd, _mm256_set1_pd(0.5)));
    q = _mm256_blendv_epi8(q, lo32, _mm256_cmpgt_epi64(q, lo32));
    qn = _mm256_mul_epu32(q, R);
    q = _mm256_add_epi64(q, _mm256_cmpgt_epi64(qn, num));                                                    /* q N > num: - 1 */
    q = _mm256_sub_epi64(q, _mm256_xor_si256(_mm256_cmpgt_epi64(_mm256_add_epi64(qn, R), num), ones));       /* (q + 1) N <= num: + 1 */
    {
        const __m256i half = _mm256_set1_epi64x((int64_t)1 << 31), hi = _mm256_setr_epi32(1, 3, 5, 7, 1, 3, 5, 7),
                      lo = _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6), big32 = _mm256_permutevar8x32_epi32(big, lo);
        /* (a r + 2^31) >> 32: the high words; N <= 2^30: a itself (low words); the four lanes' words packed low */
        v0 = _mm256_blendv_epi8(_mm256_permutevar8x32_epi32(s0, lo), _mm256_permutevar8x32_epi32(_mm256_add_epi64(_mm256_mul_epu32(s0, q), half), hi), big32);
        v1 = _mm256_blendv_epi8(_mm256_permutevar8x32_epi32(s1, lo), _mm256_permutevar8x32_epi32(_mm256_add_epi64(_mm256_mul_epu32(s1, q), half), hi), big32);
        v2 = _mm256_blendv_epi8(_mm256_permutevar8x32_epi32(s2, lo), _mm256_permutevar8x32_epi32(_mm256_add_epi64(_mm256_mul_epu32(s2, q), half), hi), big32);
    }
    ox = _mm_sign_epi32(_mm256_castsi256_si128(v0), cx); /* c < 0: -v, c = 0: 0 (v = 0 there) */
    oy = _mm_sign_epi32(_mm256_castsi256_si128(v1), cy);
    oz = _mm_blendv_epi8(_mm_sign_epi32(_mm256_castsi256_si128(v2), cz), _mm_set1_epi32(SN_ONE_ROT), z32);
    _mm_storeu_si128((__m128i *)(void *)fx, ox); _mm_storeu_si128((__m128i *)(void *)fy, oy); _mm_storeu_si128((__m128i *)(void *)fz, oz);
    for (k = 0; k < 4; k++) { o[k].x = fx[k]; o[k].y = fy[k]; o[k].z = fz[k]; }
}
#endif
void sn_k_xunit(sn_vec3 *out, uint32_t n) {
    uint32_t i = 0;
#if defined(SN_KERNELS_AVX2)
    for (; i + 4 <= n; i += 4) xunit4(out + i);
#endif
    for (; i < n; i++) xunit1(out + i);
}

/* e1 x e2 of triangle (a, b, c), exact in int64; clamp: each edge
 * component to +-2^30 (products below 2^62) */
SN_INLINE void xface(const sn_vec3 *p, uint32_t a, uint32_t b, uint32_t c, int clamp, int64_t n[3]) {
    int64_t e1[3], e2[3];
    int k;
    e1[0] = (int64_t)p[b].x - p[a].x; e1[1] = (int64_t)p[b].y - p[a].y; e1[2] = (int64_t)p[b].z - p[a].z;
    e2[0] = (int64_t)p[c].x - p[a].x; e2[1] = (int64_t)p[c].y - p[a].y; e2[2] = (int64_t)p[c].z - p[a].z;
    if (clamp)
        for (k = 0; k < 3; k++) {
            e1[k] = e1[k] > (1 << 30) ? (1 << 30) : (e1[k] < -(1 << 30) ? -(1 << 30) : e1[k]);
            e2[k] = e2[k] > (1 << 30) ? (1 << 30) : (e2[k] < -(1 << 30) ? -(1 << 30) : e2[k]);
        }
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
}
SN_INLINE uint64_t xabs(int64_t v) { return v < 0 ? (uint64_t)0 - (uint64_t)v : (uint64_t)v; } /* |v| <= 2^61 */

#if defined(SN_KERNELS_AVX2)
/* triangles t..t+7: their corner indices (3 i, for the position gathers) */
SN_INLINE void xidx8(const unsigned char *tri, __m256i *a, __m256i *b, __m256i *c) {
    const __m256i off = _mm256_setr_epi32(0, 3, 6, 9, 12, 15, 18, 21); /* u16 units: 6 bytes a triangle */
    const __m256i ab = _mm256_i32gather_epi32((const int *)(const void *)tri, off, 2);       /* a | b << 16 */
    const __m256i bc = _mm256_i32gather_epi32((const int *)(const void *)(tri + 2), off, 2); /* b | c << 16: no byte past the triangle */
    const __m256i ia = _mm256_and_si256(ab, _mm256_set1_epi32(0xFFFF)), ib = _mm256_srli_epi32(ab, 16),
                  ic = _mm256_srli_epi32(bc, 16);
    *a = _mm256_add_epi32(ia, _mm256_add_epi32(ia, ia));
    *b = _mm256_add_epi32(ib, _mm256_add_epi32(ib, ib));
    *c = _mm256_add_epi32(ic, _mm256_add_epi32(ic, ic));
}
/* the 8 faces' normals (non-wide: edges within +-2^30 fit int32), int64
 * in two halves: ne[k] faces 0, 2, 4, 6, no[k] faces 1, 3, 5, 7 */
SN_INLINE void xcross8(const sn_vec3 *p, const unsigned char *tri, __m256i ne[3], __m256i no[3]) {
    const int *P = (const int *)(const void *)p;
    __m256i a, b, c, e1[3], e2[3], o1[3], o2[3];
    int k;
    xidx8(tri, &a, &b, &c);
    for (k = 0; k < 3; k++) {
        const __m256i pa = _mm256_i32gather_epi32(P + k, a, 4);
        e1[k] = _mm256_sub_epi32(_mm256_i32gather_epi32(P + k, b, 4), pa);
        e2[k] = _mm256_sub_epi32(_mm256_i32gather_epi32(P + k, c, 4), pa);
        o1[k] = _mm256_srli_epi64(e1[k], 32);
        o2[k] = _mm256_srli_epi64(e2[k], 32);
    }
    /* mul_epi32: the low int32 of each 64-bit lane, signed, exact int64 */
    ne[0] = _mm256_sub_epi64(_mm256_mul_epi32(e1[1], e2[2]), _mm256_mul_epi32(e1[2], e2[1]));
    ne[1] = _mm256_sub_epi64(_mm256_mul_epi32(e1[2], e2[0]), _mm256_mul_epi32(e1[0], e2[2]));
    ne[2] = _mm256_sub_epi64(_mm256_mul_epi32(e1[0], e2[1]), _mm256_mul_epi32(e1[1], e2[0]));
    no[0] = _mm256_sub_epi64(_mm256_mul_epi32(o1[1], o2[2]), _mm256_mul_epi32(o1[2], o2[1]));
    no[1] = _mm256_sub_epi64(_mm256_mul_epi32(o1[2], o2[0]), _mm256_mul_epi32(o1[0], o2[2]));
    no[2] = _mm256_sub_epi64(_mm256_mul_epi32(o1[0], o2[1]), _mm256_mul_epi32(o1[1], o2[0]));
}
SN_INLINE __m256i xabs8(__m256i v) {
#if defined(__AVX512VL__)
    return _mm256_abs_epi64(v);
#else
    const __m256i s = _mm256_cmpgt_epi64(_mm256_setzero_si256(), v);
    return _mm256_sub_epi64(_mm256_xor_si256(v, s), s);
#endif
}
/* sn_rshr64(v, shift) in int64 lanes: (v + h) >> shift arithmetic; AVX2 has
 * no arithmetic 64-bit shift: the sign bit flipped (v + 2^63, unsigned),
 * shifted logically, minus 2^(63 - shift) */
SN_INLINE __m256i xrshr8(__m256i v, __m256i h, __m128i cnt, __m256i bias) {
#if defined(__AVX512VL__)
    (void)bias;
    return _mm256_sra_epi64(_mm256_add_epi64(v, h), cnt);
#else
    const __m256i sign = _mm256_set1_epi64x(INT64_MIN);
    return _mm256_sub_epi64(_mm256_srl_epi64(_mm256_xor_si256(_mm256_add_epi64(v, h), sign), cnt), bias);
#endif
}
#endif

/* pass 1, no vertex of 128 faces or more (non-wide): plain int32 sums */
SN_INLINE void xadd(sn_vec3 *out, const unsigned char *tri, int32_t s0, int32_t s1, int32_t s2) {
    const uint32_t a = sn_rd_u16(tri), b = sn_rd_u16(tri + 2), c = sn_rd_u16(tri + 4);
    out[a].x += s0; out[a].y += s1; out[a].z += s2;
    out[b].x += s0; out[b].y += s1; out[b].z += s2;
    out[c].x += s0; out[c].y += s1; out[c].z += s2;
}

void sn_k_xnormals(const unsigned char *tris, uint32_t nT, const sn_vec3 *p, uint32_t nS, sn_vec3 *out) {
    uint64_t bits = 0;
    uint32_t i, t = 0, deg = 0, wide = 0;
    int shift;
    {   /* positions within +-2^29: no edge reaches the clamp (one loop over the 3 nS int32: vectorized) */
        const int32_t *q = (const int32_t *)(const void *)p;
        i = 0;
#if defined(SN_XN_DSQRT)
        {
            const __m128i hi = _mm_set1_epi32(1 << 29), lo = _mm_set1_epi32(-(1 << 29));
            __m128i w = _mm_setzero_si128();
            for (; i + 4 <= 3 * nS; i += 4) {
                const __m128i v = _mm_loadu_si128((const __m128i *)(const void *)(q + i));
                w = _mm_or_si128(w, _mm_or_si128(_mm_cmpgt_epi32(v, hi), _mm_cmpgt_epi32(lo, v)));
            }
            wide = (uint32_t)_mm_movemask_epi8(w);
        }
#endif
        for (; i < 3 * nS; i++) wide |= (uint32_t)q[i] + (1u << 29) > (1u << 30);
    }
    memset(out, 0, (size_t)nS * sizeof *out);
    if (wide) {
        for (t = 0; t < nT; t++) {
            int64_t n[3];
            xface(p, sn_rd_u16(tris + 6 * t), sn_rd_u16(tris + 6 * t + 2), sn_rd_u16(tris + 6 * t + 4), 1, n);
            bits |= xabs(n[0]) | xabs(n[1]) | xabs(n[2]);
        }
        deg = 128; /* the saturating sums */
    } else {
        /* pass 0: the magnitudes' OR, each vertex's faces counted in out[].x
         * (at most 3 nT < 2^31: the triangles' 6 bytes each fit a u32-sized blob) */
#if defined(SN_KERNELS_AVX2)
        __m256i acc = _mm256_setzero_si256();
        for (; t + 8 <= nT; t += 8) {
            const unsigned char *tri = tris + 6 * t;
            __m256i ne[3], no[3];
            uint32_t j;
            xcross8(p, tri, ne, no);
            acc = _mm256_or_si256(acc, _mm256_or_si256(_mm256_or_si256(xabs8(ne[0]), xabs8(no[0])),
                                                       _mm256_or_si256(_mm256_or_si256(xabs8(ne[1]), xabs8(no[1])),
                                                                       _mm256_or_si256(xabs8(ne[2]), xabs8(no[2])))));
            for (j = 0; j < 24; j += 3) { out[sn_rd_u16(tri + 2 * j)].x++; out[sn_rd_u16(tri + 2 * j + 2)].x++; out[sn_rd_u16(tri + 2 * j + 4)].x++; }
        }
        {
            uint64_t l[4];
            _mm256_storeu_si256((__m256i *)(void *)l, acc);
            bits = l[0] | l[1] | l[2] | l[3];
        }
#endif
        for (; t < nT; t++) {
            const uint32_t a = sn_rd_u16(tris + 6 * t), b = sn_rd_u16(tris + 6 * t + 2), c = sn_rd_u16(tris + 6 * t + 4);
            int64_t n[3];
            xface(p, a, b, c, 0, n);
            bits |= xabs(n[0]) | xabs(n[1]) | xabs(n[2]);
            out[a].x++; out[b].x++; out[c].x++;
        }
        for (i = 0; i < nS; i++) { deg |= (uint32_t)out[i].x; out[i].x = 0; } /* y, z still 0 */
    }
    shift = bitlen64(bits) - 24; /* the largest |n_k| >> shift below 2^24 */
    shift = shift < 0 ? 0 : shift;
    if (deg < 128) { /* every term <= 2^24, at most 127 at a vertex: no sum reaches 2^31 */
        t = 0;
#if defined(SN_KERNELS_AVX2)
        {
            const __m256i h = _mm256_set1_epi64x(shift ? (int64_t)1 << (shift - 1) : 0);
            const __m128i cnt = _mm_cvtsi32_si128(shift);
            const __m256i bias = _mm256_srl_epi64(_mm256_set1_epi64x(INT64_MIN), cnt);
            for (; t + 8 <= nT; t += 8) {
                const unsigned char *tri = tris + 6 * t;
                __m256i ne[3], no[3];
                int32_t s[3][8];
                uint32_t j;
                int k;
                xcross8(p, tri, ne, no);
                for (k = 0; k < 3; k++) /* |result| <= 2^24: the low int32 of each lane; odd faces to the high halves */
                    _mm256_storeu_si256((__m256i *)(void *)s[k],
                                        _mm256_blend_epi32(xrshr8(ne[k], h, cnt, bias), _mm256_slli_epi64(xrshr8(no[k], h, cnt, bias), 32), 0xAA));
                for (j = 0; j < 8; j++) xadd(out, tri + 6 * j, s[0][j], s[1][j], s[2][j]);
            }
        }
#endif
        for (; t < nT; t++) {
            int64_t n[3];
            xface(p, sn_rd_u16(tris + 6 * t), sn_rd_u16(tris + 6 * t + 2), sn_rd_u16(tris + 6 * t + 4), 0, n);
            xadd(out, tris + 6 * t, (int32_t)sn_rshr64(n[0], shift), (int32_t)sn_rshr64(n[1], shift), (int32_t)sn_rshr64(n[2], shift));
        }
    } else {
        for (t = 0; t < nT; t++) {
            const uint32_t a = sn_rd_u16(tris + 6 * t), b = sn_rd_u16(tris + 6 * t + 2), c = sn_rd_u16(tris + 6 * t + 4);
            int64_t n[3];
            int32_t s0, s1, s2;
            if (wide) xface(p, a, b, c, 1, n);
            else xface(p, a, b, c, 0, n);
            s0 = (int32_t)sn_rshr64(n[0], shift); s1 = (int32_t)sn_rshr64(n[1], shift); s2 = (int32_t)sn_rshr64(n[2], shift);
            out[a].x = pub_add(out[a].x, s0); out[a].y = pub_add(out[a].y, s1); out[a].z = pub_add(out[a].z, s2);
            out[b].x = pub_add(out[b].x, s0); out[b].y = pub_add(out[b].y, s1); out[b].z = pub_add(out[b].z, s2);
            out[c].x = pub_add(out[c].x, s0); out[c].y = pub_add(out[c].y, s1); out[c].z = pub_add(out[c].z, s2);
        }
    }
    sn_k_xunit(out, nS);
}
#else
typedef int sn_kernels_xnorm_float_; /* the float flavour's normals: sn_embed.c, sn_kernels_fnorm.c */
#endif
