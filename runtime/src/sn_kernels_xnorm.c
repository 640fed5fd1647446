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
 * x86-64 (not SIMD=scalar): the unit step on int64 operands without
 * sn_unit's generic loop; AVX2: both triangle passes' cross products eight
 * faces at a time in lanes. Integers only: the fixed library has no float
 * instruction (tests/scripts/test_nofloat.sh; a root or quotient from
 * doubles, corrected exactly, was measured faster: KERNELS.md "Outputs and
 * contacts, round 2"). */
#include "sn_kernels_xnorm.h"
#include "sn_kernels.h"

#if !defined(SN_FLOAT)
#if defined(__x86_64__) && defined(__SSE2__) && defined(__GNUC__) && !defined(SN_SIMD_SCALAR)
#define SN_XN_X64 1
#include <emmintrin.h>
#endif
#if defined(SN_KERNELS_AVX2)
#include <immintrin.h>
#endif

/* the nearest integer to sqrt(x) (sn_unit's rounded root: floor, plus one
 * when x - floor^2 > floor) */
SN_INLINE uint64_t xrsqrt(uint64_t x) {
    uint64_t N = sn_isqrt64(x);
    if (x - N * N > N) N++;
    return N;
}
uint32_t sn_k_xrsqrt(uint64_t x) { return (uint32_t)xrsqrt(x); }

/* one summed normal to unit length in place: sn_qnormalize on (x, y, z, 0)
 * (sn_unit with n = 4: the zero fourth component adds nothing to the
 * maximum or the squares); a zero sum gives (0, 0, 1). Off x86-64
 * sn_qnormalize itself. */
SN_INLINE void xunit1(sn_vec3 *o) {
#if defined(SN_XN_X64)
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
void sn_k_xunit(sn_vec3 *out, uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; i++) xunit1(out + i);
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
#if defined(SN_XN_X64)
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
            const long long hv = shift ? (long long)1 << (shift - 1) : 0; /* long long: clang's -Wsign-conversion on ?: */
            const __m256i h = _mm256_set1_epi64x(hv);
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
