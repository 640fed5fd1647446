/* sn_kernels_fnorm.c -- float flavour: the vertex normals' last step
 * (sn_get_normals), each summed normal scaled to unit length, four
 * vertices at a time on x86-64 (SSE2: every x86-64 build but SIMD=scalar).
 *
 * Bits: each lane computes sn_qnormalize's float arithmetic on (x, y, z, 0)
 * exactly as the scalar code does (sn_funit, sn_frsqrt in sn_math.c): m the
 * largest |c| by the same "greater than" test, c/m by division, the squares
 * summed in order, the bit estimate and three Newton steps with the same
 * products in the same order, frsqrt(n2)/m, c * r. IEEE single in every
 * lane, round to nearest, separate multiplies and adds (no FMA), so every
 * output is the scalar loop's (test_runtime_surface compares them bit for
 * bit, zero, tiny, huge and NaN normals included). The scalar loop was
 * latency-bound: five divisions and a dependent Newton chain per vertex,
 * 85% of sn_get_normals' time on cow_fem. */
#include "sn_instance.h"

#if defined(SN_FLOAT)
/* the reference: one vertex (sn_get_normals' loop before the lanes) */
static void fnorm1(sn_vec3 *o) {
    sn_q q[4];
    q[0] = o->x; q[1] = o->y; q[2] = o->z; q[3] = 0.0f;
    if (q[0] == 0.0f && q[1] == 0.0f && q[2] == 0.0f) { o->z = 1.0f; return; }
    sn_qnormalize(q);
    o->x = q[0]; o->y = q[1]; o->z = q[2];
}

#if defined(__SSE2__) && !defined(SN_SIMD_SCALAR)
#include <emmintrin.h>
static __m128 sel(__m128 m, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(m, a), _mm_andnot_ps(m, b)); }
static __m128 gtmax(__m128 a, __m128 m) { return sel(_mm_cmpgt_ps(a, m), a, m); } /* a > m ? a : m */
#endif

void sn_k_fnormals(sn_vec3 *out, uint32_t n) {
    uint32_t i = 0;
#if defined(__SSE2__) && !defined(SN_SIMD_SCALAR)
    const __m128 sign = _mm_set1_ps(-0.0f), zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    const __m128 tiny_m = _mm_set1_ps(1e-30f), tiny_n = _mm_set1_ps(1e-37f), half = _mm_set1_ps(0.5f), th = _mm_set1_ps(1.5f);
    const __m128i magic = _mm_set1_epi32(0x5f3759df);
    for (; i + 4 <= n; i += 4) {
        sn_vec3 *o = out + i;
        const __m128 x = _mm_setr_ps(o[0].x, o[1].x, o[2].x, o[3].x), y = _mm_setr_ps(o[0].y, o[1].y, o[2].y, o[3].y),
                     z = _mm_setr_ps(o[0].z, o[1].z, o[2].z, o[3].z);
        const __m128 allz = _mm_and_ps(_mm_and_ps(_mm_cmpeq_ps(x, zero), _mm_cmpeq_ps(y, zero)), _mm_cmpeq_ps(z, zero));
        __m128 m = gtmax(_mm_andnot_ps(sign, z), gtmax(_mm_andnot_ps(sign, y), gtmax(_mm_andnot_ps(sign, x), zero)));
        const __m128 ok = _mm_cmpgt_ps(m, tiny_m); /* sn_funit's !(m > 1e-30): (0, 0, 0) */
        __m128 qx, qy, qz, n2, yy, r, rx, ry, rz;
        float fx[4], fy[4], fz[4];
        int k;
        m = sel(ok, m, one); /* lanes that fail take no division by 0 (their result is replaced) */
        qx = _mm_div_ps(x, m); qy = _mm_div_ps(y, m); qz = _mm_div_ps(z, m);
        n2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(qx, qx), _mm_mul_ps(qy, qy)), _mm_mul_ps(qz, qz));
        yy = _mm_castsi128_ps(_mm_sub_epi32(magic, _mm_srli_epi32(_mm_castps_si128(n2), 1)));
        for (k = 0; k < 3; k++) yy = _mm_mul_ps(yy, _mm_sub_ps(th, _mm_mul_ps(_mm_mul_ps(_mm_mul_ps(half, n2), yy), yy)));
        yy = _mm_and_ps(_mm_cmpgt_ps(n2, tiny_n), yy); /* sn_frsqrt's !(x > 1e-37): 0 */
        r = _mm_div_ps(yy, m);
        rx = _mm_and_ps(ok, _mm_mul_ps(x, r)); ry = _mm_and_ps(ok, _mm_mul_ps(y, r)); rz = _mm_and_ps(ok, _mm_mul_ps(z, r));
        rx = sel(allz, x, rx); ry = sel(allz, y, ry); rz = sel(allz, one, rz);
        _mm_storeu_ps(fx, rx); _mm_storeu_ps(fy, ry); _mm_storeu_ps(fz, rz);
        for (k = 0; k < 4; k++) { o[k].x = fx[k]; o[k].y = fy[k]; o[k].z = fz[k]; }
    }
#endif
    for (; i < n; i++) fnorm1(out + i);
}

/* the scalar reference, for the tests: every vertex alone */
void sn_k_fnormals_ref(sn_vec3 *out, uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; i++) fnorm1(out + i);
}
#else
typedef int sn_kernels_fnorm_fixed_; /* the fixed flavour normalizes in sn_embed.c */
#endif
