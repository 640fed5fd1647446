/* test_runtime_math.c -- sn_math.c against libm in double.
 *
 * Built twice (fixed, float). Errors are measured in units of the output's
 * LSB in the fixed flavour (Q30 for quaternions / rotation entries, Q16.16
 * for rotated vectors) and absolutely in the float flavour. Tolerances, and
 * why (the error analyses are in the comments of runtime/src/sn_math.c):
 *   isqrt      exact floor, every input
 *   normalize  2 LSB   (sqrt rounded to nearest: 0.5, reciprocal: 0.5, final rounding: 0.5)
 *   qtomat     1 LSB   (one rounding from exact Q60 sums)
 *   axis-angle 4 LSB   (axis normalize 1.5 + sin/cos polynomial ~1.5 + final normalize 1.5; no
 *                       error from the angle: reduced exactly in integers, 2^-45 constant)
 *   mul        1 LSB   (exact Q60 sums, one rounding)
 *   rotate     1 LSB + |v| * 2^-28  (matrix entries carry 0.5 LSB Q30 each)
 *   slerp      8 LSB   (CORDIC atan2 ~1, sin/cos ~1.5, ratio division ~1, final normalize 1.5,
 *                       inputs normalized first ~1.5)
 *   float      a few float ulps of 1: 1e-6 for the trigonometric ones, 4e-7 for the others.
 *   trilinear  fixed: exact (wx wy wz / 2^15 rounded half up, computed here in double: < 2^53);
 *              float: 2 roundings of 2^-24 relative (the scale by 2^-45 is exact)
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "sn_test.h"
#include "sinew.h"
#include "sn_internal.h"

void sn_trilinear(const uint32_t t[3], sn_q phi[8]); /* sn_embed.c (declared in sn_instance.h) */

#if defined(SN_FLOAT)
#define FLAV "float"
#define Q30(d) ((float)(d))
#define FROM30(x) ((double)(x))
#define L16(d) ((float)(d))
#define FROM16(x) ((double)(x))
#define ANG(d) ((float)(d))
#define FROMANG(x) ((double)(x))
#define TOL30(lsb, fl) (fl)
#define LSB30 (1.0) /* float: figures are absolute errors */
#else
#define FLAV "fixed"
#define Q30(d) ((int32_t)floor((d) * 1073741824.0 + 0.5))
#define FROM30(x) ((double)(x) / 1073741824.0)
#define L16(d) ((int32_t)floor((d) * 65536.0 + 0.5))
#define FROM16(x) ((double)(x) / 65536.0)
#define ANG(d) ((int32_t)floor((d) * 65536.0 + 0.5))
#define FROMANG(x) ((double)(x) / 65536.0)
#define TOL30(lsb, fl) ((lsb) / 1073741824.0)
#define LSB30 (1.0 / 1073741824.0)
#endif

static uint64_t g_rng;
static uint64_t rnd64(void) {
    g_rng ^= g_rng << 13;
    g_rng ^= g_rng >> 7;
    g_rng ^= g_rng << 17;
    return g_rng;
}
static double rndu(void) { return (double)(rnd64() >> 11) / 9007199254740992.0; } /* [0,1) */
static double rnds(void) { return 2.0 * rndu() - 1.0; }

/* random unit quaternion in double */
static void rnd_unit(double q[4]) {
    double n;
    do {
        int k;
        n = 0;
        for (k = 0; k < 4; k++) { q[k] = rnds(); n += q[k] * q[k]; }
    } while (n < 1e-3 || n > 1.0);
    n = sqrt(n);
    q[0] /= n; q[1] /= n; q[2] /= n; q[3] /= n;
}
static sn_quat to_quat(const double q[4]) {
    sn_quat r;
    r.x = Q30(q[0]); r.y = Q30(q[1]); r.z = Q30(q[2]); r.w = Q30(q[3]);
    return r;
}
static void from_quat(sn_quat q, double d[4]) {
    d[0] = FROM30(q.x); d[1] = FROM30(q.y); d[2] = FROM30(q.z); d[3] = FROM30(q.w);
}
static double qerr(sn_quat got, const double want[4]) {
    double g[4], e = 0;
    int k;
    from_quat(got, g);
    for (k = 0; k < 4; k++) e = fabs(g[k] - want[k]) > e ? fabs(g[k] - want[k]) : e;
    return e;
}
static void dmul(const double a[4], const double b[4], double o[4]) {
    o[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    o[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    o[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    o[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
}
static void dmat(const double q[4], double R[9]) {
    double x = q[0], y = q[1], z = q[2], w = q[3];
    R[0] = 1 - 2 * (y * y + z * z); R[1] = 2 * (x * y - z * w); R[2] = 2 * (x * z + y * w);
    R[3] = 2 * (x * y + z * w); R[4] = 1 - 2 * (x * x + z * z); R[5] = 2 * (y * z - x * w);
    R[6] = 2 * (x * z - y * w); R[7] = 2 * (y * z + x * w); R[8] = 1 - 2 * (x * x + y * y);
}
static void dnorm(double q[4]) {
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    q[0] /= n; q[1] /= n; q[2] /= n; q[3] /= n;
}
/* reference slerp along the shorter arc of normalized inputs */
static void dslerp(const double a0[4], const double b0[4], double t, double o[4]) {
    double a[4], b[4], d = 0, th, s0, s1;
    int k;
    memcpy(a, a0, sizeof a); memcpy(b, b0, sizeof b);
    dnorm(a); dnorm(b);
    for (k = 0; k < 4; k++) d += a[k] * b[k];
    if (d < 0) { for (k = 0; k < 4; k++) b[k] = -b[k]; d = -d; }
    th = acos(d > 1 ? 1 : d);
    if (th < 1e-12) { memcpy(o, a, sizeof a); return; }
    s0 = sin((1 - t) * th) / sin(th);
    s1 = sin(t * th) / sin(th);
    for (k = 0; k < 4; k++) o[k] = s0 * a[k] + s1 * b[k];
    dnorm(o);
}

static void test_isqrt(void) {
    static const uint64_t edge[] = {0, 1, 2, 3, 4, 5, 8, 9, 15, 16, 17, 0xFFFFFFFFull,
        0x100000000ull, 0xFFFFFFFE00000001ull, 0xFFFFFFFE00000000ull, 0xFFFFFFFFFFFFFFFFull,
        0x8000000000000000ull, 0x7FFFFFFFFFFFFFFFull, 0x3FFFFFFFFFFFFFFFull, 0x4000000000000000ull};
    size_t i;
    int bad = 0;
    for (i = 0; i < sizeof edge / sizeof edge[0] + 200000; i++) {
        uint64_t x, r;
        if (i < sizeof edge / sizeof edge[0]) x = edge[i];
        else if (i % 3 == 0) { uint64_t k = rnd64() >> 32; x = k * k - (i % 2); }   /* around squares */
        else x = rnd64() >> (rnd64() % 64);
        r = sn_isqrt64(x);
        if (!(r * r <= x && (r == 0xFFFFFFFFull || (r + 1) * (r + 1) > x))) {
            if (bad++ < 5) T_CHECK(0, "isqrt(%llu) = %llu", (unsigned long long)x, (unsigned long long)r);
        }
        if (sn_isqrt64_digits(x) != r && bad++ < 5) /* the 32-bit targets' method, here too */
            T_CHECK(0, "isqrt_digits(%llu) = %u", (unsigned long long)x, sn_isqrt64_digits(x));
        if (sn_isqrt64_kara(x) != r && bad++ < 5) /* Karatsuba (M4, 64-bit hosts: this build's) */
            T_CHECK(0, "isqrt_kara(%llu) = %u", (unsigned long long)x, sn_isqrt64_kara(x));
    }
    T_CHECK(bad == 0, "isqrt: %d of %d inputs not the exact floor", bad, (int)i);
}

#if !defined(SN_FLOAT)
/* sn_div64n against the compiler's 64-bit division (exact integers): edges of
 * the divisor range [2^31, 2^32), remainders near d, quotients near 2^32, and
 * every reciprocal the segment meshes take (2^61 / (x 2^(32 - bits x))). */
static void test_div64n(void) {
    int bad = 0, i;
    for (i = 0; i < 2000000; i++) {
        uint32_t d = (uint32_t)rnd64() | 0x80000000u, q;
        uint64_t n, lim;
        if (i % 5 == 1) d = 0x80000000u + (uint32_t)(rnd64() % 4);
        if (i % 5 == 2) d = 0xFFFFFFFFu - (uint32_t)(rnd64() % 4);
        lim = (uint64_t)d << 32; /* n < lim: the quotient fits 32 bits */
        switch (i % 4) {
        case 0: n = rnd64() % lim; break;
        case 1: n = lim - 1u - rnd64() % 1024u; break;            /* quotient 2^32 - 1 */
        case 2: n = (rnd64() % d) * d + (d - 1u - (uint32_t)(rnd64() % 4)); break; /* remainder near d */
        default: n = ((rnd64() % d) << 32) | (rnd64() & 0xFFFF0000u); break;
        }
        q = sn_div64n_digits(n, d); /* the 32-bit targets' method, here too */
        if (((uint64_t)q != n / d || sn_div64n(n, d) != q) && bad++ < 5)
            T_CHECK(0, "div64n(%llu, %u) = %u", (unsigned long long)n, d, q);
    }
    for (i = 1; i <= (1 << 22); i++) { /* reciprocals: x over 2^22 and scaled to 2^30 */
        uint64_t x = (uint64_t)i << (i & 8 ? 8 : 0);
        int b = 0;
        while ((x >> b) != 0) b++;
        if ((uint64_t)sn_div64n_digits((uint64_t)1 << 61, (uint32_t)(x << (32 - b))) != ((uint64_t)1 << (29 + b)) / x &&
            bad++ < 5) T_CHECK(0, "div64n reciprocal of %llu", (unsigned long long)x);
    }
    T_CHECK(bad == 0, "div64n: %d quotients not exact", bad);
}
#endif

static void test_normalize(void) {
    double maxe = 0;
    int i, k;
    for (i = 0; i < 100000; i++) {
        sn_q q[4];
        double d[4], n = 0, want[4];
        int sh = (int)(rnd64() % 31);
        for (k = 0; k < 4; k++) {
#if defined(SN_FLOAT)
            q[k] = (float)(rnds() * ldexp(1.0, sh - 10));
#else
            q[k] = (int32_t)((int64_t)(int32_t)(uint32_t)rnd64() >> sh);
#endif
            d[k] = (double)q[k];
            n += d[k] * d[k];
        }
        if (n == 0) continue;
        for (k = 0; k < 4; k++) want[k] = d[k] / sqrt(n);
        sn_qnormalize(q);
        for (k = 0; k < 4; k++) maxe = fabs(FROM30(q[k]) - want[k]) > maxe ? fabs(FROM30(q[k]) - want[k]) : maxe;
    }
    T_FIGURE("%s normalize: max error %.3g LSB(Q30)", FLAV, maxe / LSB30);
    T_CHECK(maxe <= TOL30(2, 4e-7), "normalize max error %.3g", maxe);
    {
        sn_q z[4] = {0, 0, 0, 0};
        sn_qnormalize(z);
        T_CHECK(z[0] == 0 && z[1] == 0 && z[2] == 0 && z[3] == Q30(1.0), "zero -> identity");
    }
#if !defined(SN_FLOAT)
    {
        sn_q m[4] = {INT32_MIN, INT32_MIN, INT32_MIN, INT32_MIN};
        sn_qnormalize(m);
        T_CHECK(m[0] == -(1 << 29) && m[3] == -(1 << 29), "INT32_MIN components -> -1/2");
    }
#endif
}

static void test_qtomat(void) {
    double maxe = 0;
    int i, k;
    for (i = 0; i < 50000; i++) {
        double d[4], R[9];
        sn_q q[4], M[9];
        rnd_unit(d);
        for (k = 0; k < 4; k++) { q[k] = Q30(d[k]); d[k] = FROM30(q[k]); }
        dmat(d, R);
        sn_qtomat(q, M);
        for (k = 0; k < 9; k++) maxe = fabs(FROM30(M[k]) - R[k]) > maxe ? fabs(FROM30(M[k]) - R[k]) : maxe;
    }
    T_FIGURE("%s qtomat: max error %.3g LSB(Q30)", FLAV, maxe / LSB30);
    T_CHECK(maxe <= TOL30(1, 4e-7), "qtomat max error %.3g", maxe);
}

static void test_axis_angle(void) {
    double maxe = 0;
    int i;
    for (i = 0; i < 100000; i++) {
        sn_vec3 ax;
        sn_real ang;
        double a[3], n, half, want[4], e;
        int sh = (int)(rnd64() % 15);
        do {
            a[0] = rnds() * ldexp(1.0, sh); a[1] = rnds() * ldexp(1.0, sh); a[2] = rnds() * ldexp(1.0, sh);
            ax.x = L16(a[0]); ax.y = L16(a[1]); ax.z = L16(a[2]);
            a[0] = FROM16(ax.x); a[1] = FROM16(ax.y); a[2] = FROM16(ax.z);
            n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        } while (n == 0);
        if (i % 4 == 0) ang = ANG(rnds() * 32767.0);   /* full range */
        else ang = ANG(rnds() * 720.0);
        half = FROMANG(ang) * 3.14159265358979323846 / 360.0;
        want[0] = a[0] / n * sin(half); want[1] = a[1] / n * sin(half);
        want[2] = a[2] / n * sin(half); want[3] = cos(half);
        e = qerr(sn_quat_axis_angle(ax, ang), want);
        maxe = e > maxe ? e : maxe;
    }
    T_FIGURE("%s axis_angle: max error %.3g LSB(Q30)", FLAV, maxe / LSB30);
    T_CHECK(maxe <= TOL30(4, 1e-6), "axis_angle max error %.3g", maxe);
    {
        sn_vec3 z = {0, 0, 0}, x = {0, 0, 0};
        sn_quat q = sn_quat_axis_angle(z, ANG(90));
        T_CHECK(q.x == 0 && q.y == 0 && q.z == 0 && q.w == Q30(1), "zero axis -> identity");
        x.x = L16(3);
        q = sn_quat_axis_angle(x, 0);
        T_CHECK(q.x == 0 && q.y == 0 && q.z == 0 && fabs(FROM30(q.w) - 1.0) <= TOL30(0, 1.2e-7),
                "angle 0 -> identity (exact in fixed)");
        q = sn_quat_axis_angle(x, ANG(180));
        T_NEAR(FROM30(q.x), 1.0, TOL30(1, 1e-7), "180 deg about x");
        T_NEAR(FROM30(q.w), 0.0, TOL30(1, 1e-7), "180 deg about x");
    }
}

static void test_mul(void) {
    double maxe = 0;
    int i, k;
    for (i = 0; i < 100000; i++) {
        double a[4], b[4], o[4];
        sn_quat qa, qb;
        rnd_unit(a); rnd_unit(b);
        qa = to_quat(a); qb = to_quat(b);
        from_quat(qa, a); from_quat(qb, b);
        dmul(a, b, o);
        {
            double e = qerr(sn_quat_mul(qa, qb), o);
            maxe = e > maxe ? e : maxe;
        }
        (void)k;
    }
    T_FIGURE("%s mul: max error %.3g LSB(Q30)", FLAV, maxe / LSB30);
    T_CHECK(maxe <= TOL30(1, 4e-7), "mul max error %.3g", maxe);
}

static void test_rotate(void) {
    double maxe = 0;
    int i, k;
    for (i = 0; i < 100000; i++) {
        double q[4], R[9], v[3], w[3], vmax = 0, e = 0, tol;
        sn_quat qq;
        sn_vec3 vv, r;
        int sh = (int)(rnd64() % 15);
        rnd_unit(q);
        qq = to_quat(q);
        from_quat(qq, q);
        for (k = 0; k < 3; k++) v[k] = rnds() * ldexp(1.0, sh);
        vv.x = L16(v[0]); vv.y = L16(v[1]); vv.z = L16(v[2]);
        v[0] = FROM16(vv.x); v[1] = FROM16(vv.y); v[2] = FROM16(vv.z);
        dmat(q, R);
        for (k = 0; k < 3; k++) {
            w[k] = R[3 * k] * v[0] + R[3 * k + 1] * v[1] + R[3 * k + 2] * v[2];
            vmax = fabs(v[k]) > vmax ? fabs(v[k]) : vmax;
        }
        r = sn_quat_rotate(qq, vv);
        e = fabs(FROM16(r.x) - w[0]);
        e = fabs(FROM16(r.y) - w[1]) > e ? fabs(FROM16(r.y) - w[1]) : e;
        e = fabs(FROM16(r.z) - w[2]) > e ? fabs(FROM16(r.z) - w[2]) : e;
#if defined(SN_FLOAT)
        tol = 4e-7 * (vmax + 1);
#else
        tol = (1.0 + vmax * 65536.0 * ldexp(1.0, -28)) / 65536.0;
#endif
        maxe = e / tol > maxe ? e / tol : maxe;
    }
    T_FIGURE("%s rotate: max error %.3g of tolerance (1 LSB + |v| 2^-28)", FLAV, maxe);
    T_CHECK(maxe <= 1.0, "rotate max error %.3g of tolerance", maxe);
}

static void test_slerp(void) {
    double maxe = 0;
    int i, k;
    for (i = 0; i < 100000; i++) {
        double a[4], b[4], o[4], t, e;
        sn_quat qa, qb, r;
        sn_real tt;
        rnd_unit(a);
        switch (i % 5) {
        case 0: case 1: rnd_unit(b); break;
        case 2: {   /* nearby: rotate a by a tiny angle 10^-(1..9) rad */
            double ax[4], ang = pow(10.0, -(double)(1 + (int)(rnd64() % 9)));
            rnd_unit(ax);
            ax[3] = 0; dnorm(ax);
            ax[0] *= sin(ang / 2); ax[1] *= sin(ang / 2); ax[2] *= sin(ang / 2); ax[3] = cos(ang / 2);
            dmul(ax, a, b);
            break;
        }
        case 3: {   /* nearly opposite: -a rotated a little (shorter arc through the flip) */
            double ax[4], ang = pow(10.0, -(double)(1 + (int)(rnd64() % 6)));
            rnd_unit(ax);
            ax[3] = 0; dnorm(ax);
            ax[0] *= sin(ang / 2); ax[1] *= sin(ang / 2); ax[2] *= sin(ang / 2); ax[3] = cos(ang / 2);
            dmul(ax, a, b);
            for (k = 0; k < 4; k++) b[k] = -b[k];
            break;
        }
        default: {  /* about 90 degrees apart (dot ~ 0) */
            double ax[4];
            rnd_unit(ax);
            ax[3] = 0; dnorm(ax);
            dmul(ax, a, b);
            break;
        }
        }
        qa = to_quat(a); qb = to_quat(b);
        from_quat(qa, a); from_quat(qb, b);
        t = rndu();
        tt = Q30(t);
        t = FROM30(tt);
        dslerp(a, b, t, o);
        r = sn_quat_slerp(qa, qb, tt);
        e = qerr(r, o);
        {   /* a.b ~ 0 (rotations 180 degrees apart): both arcs are equally short and
             * the 1-LSB input normalization may pick either; accept the other one */
            double d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], nb[4], o2[4];
            if (fabs(d) < 1e-6) {
                for (k = 0; k < 4; k++) nb[k] = -b[k];
                dslerp(a, nb, t, o2);
                /* dslerp flips back when the sign of d decides: force the other arc */
                if (d != 0) {
                    double s0 = cos(t * acos(0.0)), s1 = sin(t * acos(0.0));
                    for (k = 0; k < 4; k++) o2[k] = s0 * a[k] + s1 * (d > 0 ? -b[k] : b[k]);
                    dnorm(o2);
                }
                e = qerr(r, o2) < e ? qerr(r, o2) : e;
            }
        }
        if (e > TOL30(8, 1e-6) && maxe <= TOL30(8, 1e-6))
            T_CHECK(0, "slerp case %d t=%.6f err %.3g LSB", i % 5, t, e / LSB30);
        maxe = e > maxe ? e : maxe;
    }
    T_FIGURE("%s slerp: max error %.3g LSB(Q30)", FLAV, maxe / LSB30);
    T_CHECK(maxe <= TOL30(8, 1e-6), "slerp max error %.3g", maxe);
    {   /* endpoints are exact; shorter arc picks -b */
        double a[4], b[4];
        sn_quat qa, qb, r, nb;
        rnd_unit(a); rnd_unit(b);
        qa = to_quat(a); qb = to_quat(b);
        qa = sn_quat_slerp(qa, qa, 0); /* normalized as the public call does */
        qb = sn_quat_slerp(qb, qb, 0);
        r = sn_quat_slerp(qa, qb, 0);
        T_CHECK(r.x == qa.x && r.y == qa.y && r.z == qa.z && r.w == qa.w, "t = 0 gives a exactly");
        r = sn_quat_slerp(qa, qb, Q30(1.0));
        nb = qb;
        if (FROM30(qa.x) * FROM30(qb.x) + FROM30(qa.y) * FROM30(qb.y) + FROM30(qa.z) * FROM30(qb.z) +
                FROM30(qa.w) * FROM30(qb.w) < 0) {
            nb.x = -qb.x; nb.y = -qb.y; nb.z = -qb.z; nb.w = -qb.w;
        }
        T_CHECK(r.x == nb.x && r.y == nb.y && r.z == nb.z && r.w == nb.w, "t = 1 gives +-b exactly");
        r = sn_quat_slerp(qa, qa, Q30(0.3));
        T_CHECK(r.x == qa.x && r.w == qa.w, "a == b gives a");
    }
}

/* sn_qslerp_pair + sn_qslerp_at (sn_pose.c's per-pair cache) against one
 * sn_qslerp / sn_qslerp_path call: the same bits for every t of one pair. */
static void test_slerp_pair(void) {
    int i, j, k, path, bad = 0;
    for (i = 0; i < 20000; i++) {
        double a[4], b[4];
        sn_quat qa, qb;
        sn_q A[4], B[4], o1[4], o2[4];
        sn_slerp_pair p;
        rnd_unit(a); rnd_unit(b);
        if (i % 4 == 1) for (k = 0; k < 4; k++) b[k] = -b[k] * 0.999 + a[k] * 0.001 * (double)(i % 3);
        if (i % 4 == 2) for (k = 0; k < 4; k++) b[k] = a[k];
        qa = to_quat(a); qb = to_quat(b);
        A[0] = qa.x; A[1] = qa.y; A[2] = qa.z; A[3] = qa.w;
        B[0] = qb.x; B[1] = qb.y; B[2] = qb.z; B[3] = qb.w;
        for (path = 0; path < 2; path++) {
            sn_qslerp_pair(A, B, path, &p);
            for (j = 0; j < 6; j++) {
                sn_q t = j == 0 ? Q30(0.0) : j == 1 ? Q30(1.0) : Q30(rndu());
                if (path) sn_qslerp_path(A, B, t, o1);
                else sn_qslerp(A, B, t, o1);
                sn_qslerp_at(A, B, &p, t, o2);
                if (memcmp(o1, o2, sizeof o1) != 0 && bad++ < 5) T_CHECK(0, "slerp pair case %d path %d t %d differs", i, path, j);
            }
        }
    }
    T_CHECK(bad == 0, "slerp pair: %d of 240000 results differ from one call", bad);
}

static void test_status(void) {
    int i, j;
    for (i = 0; i < (int)SN_STATUS_COUNT; i++) {
        const char *s = sn_status_str((sn_status)i);
        T_CHECK(s != NULL && s[0] != 0, "status %d has a message", i);
        for (j = 0; j < i; j++) T_CHECK(strcmp(s, sn_status_str((sn_status)j)) != 0, "status %d unique", i);
    }
    T_CHECK(strcmp(sn_status_str(SN_OK), "ok") == 0, "SN_OK");
    T_CHECK(sn_status_str(SN_STATUS_COUNT) != NULL && sn_status_str((sn_status)-1) != NULL, "out of range");
}

/* sn_out keeps every state value in range: clamps counted; in float a NaN
 * becomes 0 (counted) and an infinity the clamp, so neither enters the state. */
/* sn_trilinear (sn_embed.c): corner a at bits (x, y, z) weighs
 * prod_i (bit_i ? t_i : 32768 - t_i) / 2^45, against that product in double
 * (exact: < 2^53), on a grid with the ends and the middle of [0, 32768] */
static void test_trilinear(void) {
    static const uint32_t ends[] = {0u, 1u, 2u, 16383u, 16384u, 16385u, 32766u, 32767u, 32768u};
    uint32_t t[3], i, j, k, a, n = 0, bad = 0;
    double worst = 0;
    for (i = 0; i < 9 + 40; i++)
        for (j = 0; j < 9 + 40; j++)
            for (k = 0; k < 9 + 40; k++) {
                sn_q phi[8];
                t[0] = i < 9 ? ends[i] : (i - 9) * 819u + 7u;
                t[1] = j < 9 ? ends[j] : (j - 9) * 811u + 13u;
                t[2] = k < 9 ? ends[k] : 32768u - (k - 9) * 797u;
                sn_trilinear(t, phi);
                for (a = 0; a < 8; a++) {
                    double p = (double)((a & 1u) ? t[0] : 32768u - t[0]) * (double)((a & 2u) ? t[1] : 32768u - t[1]) *
                               (double)((a & 4u) ? t[2] : 32768u - t[2]);
#if defined(SN_FLOAT)
                    double want = p / 35184372088832.0, err = fabs((double)phi[a] - want);
                    if (err > 2.5 * 5.96e-8 * want) bad++;
                    if (want > 0 && err / want > worst) worst = err / want;
#else
                    double want = floor(p / 32768.0 + 0.5), err = fabs((double)phi[a] - want);
                    if (err != 0) bad++;
                    if (err > worst) worst = err;
#endif
                    n++;
                }
            }
    T_CHECK(bad == 0, "trilinear: %u of %u weights off the reference (worst %.3g)", bad, n, worst);
    T_FIGURE("trilinear: %u weights, worst error %.3g (%s)", n, worst, FLAV);
}

static void test_out_guard(void) {
    uint32_t sat = 0;
#if defined(SN_FLOAT)
    T_CHECK(sn_out(NAN, 0, &sat) == 0.0f && sat == 1, "float: NaN -> 0, counted");
    T_CHECK(sn_out(INFINITY, 0, &sat) == SN_FLIM && sn_out(-INFINITY, 0, &sat) == -SN_FLIM && sat == 3, "float: +-inf -> +-clamp, counted");
    T_CHECK(sn_out(1.5f, 0, &sat) == 1.5f && sat == 3, "float: a finite value passes unchanged");
#else
    T_CHECK(sn_out((int64_t)SN_LIM << 4, 4, &sat) == SN_LIM && sat == 0, "fixed: exactly the limit passes");
    T_CHECK(sn_out(((int64_t)SN_LIM + 1) << 4, 4, &sat) == SN_LIM && sat == 1, "fixed: beyond the limit clamps, counted");
#endif
}

int main(void) {
    g_rng = 0x9E3779B97F4A7C15ull ^ (uint64_t)T_SEED();
    printf("  flavour: %s\n", FLAV);
    test_isqrt();
#if !defined(SN_FLOAT)
    test_div64n();
#endif
    test_normalize();
    test_qtomat();
    test_axis_angle();
    test_mul();
    test_rotate();
    test_slerp();
    test_slerp_pair();
    test_status();
    test_out_guard();
    test_trilinear();
    return T_END();
}
