/* test_runtime_kernels.c -- the cell product kernels of this build's path
 * (runtime/src/sn_kernels.h: scalar, AVX2, NEON or M4) against an
 * independent reference written from BLOB.md's CELLK layout, not from
 * sn_format.h's offsets or the runtime's decoder:
 *   fixed: random format-6.0 records (int32 symmetric diagonal blocks up to
 *   +-2^27, int16 mantissas up to +-(2^15 - 1) with exponents 0..12, some
 *   records entirely at the bounds), operands up to +-2^28; the reference
 *   expands the record into the full 24x24 matrix of integers (in double:
 *   every entry < 2^27, exact) and sums the products exactly in 128-bit
 *   halves. Tolerance 0: the kernel's sums are exact integer sums.
 *   float: random float32 records; reference in double; tolerance 24 terms
 *   x |entry| |operand| x 2^-23 (float accumulation of 24 products).
 * Free-corner lists: the mat-vec's product over a random subset of corners
 * equals the full product's rows with zero operands elsewhere (fixed:
 * exactly; float: bit for bit), and sn_k_cell_mul2 equals two calls
 * (corner 0's operands 0, its contract). */
#include <stdint.h>
#include <string.h>
#include "sn_test.h"
#include "sn_kernels.h"
#include "sn_kernels_ic.h"
#include "sn_kernels_rot.h"
#include "sn_kernels_surf.h"
#include "sn_kernels_xnorm.h" /* sn_k_xrsqrt, sn_k_xunit */
#include "sn_segment.h" /* seg_out, seg_lim */

static uint32_t rng = 12345u;
static uint32_t rnd32(void) { rng = rng * 1664525u + 1013904223u; return rng ^ (rng >> 15); }
static int32_t rnd_in(int32_t lim) { return (int32_t)((int64_t)(rnd32() % (2u * (uint32_t)lim + 1u)) - lim); }

static void put32(unsigned char *p, uint32_t v) { p[0] = (unsigned char)v; p[1] = (unsigned char)(v >> 8); p[2] = (unsigned char)(v >> 16); p[3] = (unsigned char)(v >> 24); }
#if defined(SN_FLOAT) && defined(SN_K_MASS_FF)
static uint32_t fbits(float f) { uint32_t u; memcpy(&u, &f, 4); return u; }
#endif

#if defined(SN_FLOAT)
#define REC 1296
/* random record, full matrix in S */
static void make_rec(unsigned char *K, double S[24][24], int extreme) {
    int a, b, i, j, n = 0;
    for (a = 0; a < 8; a++)
        for (b = a; b < 8; b++, n++)
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++) {
                    float f = extreme ? (rnd32() & 1 ? 1.0e3f : -1.0e3f) : (float)rnd_in(1 << 20) / 1024.0f;
                    uint32_t u;
                    memcpy(&u, &f, 4);
                    put32(K + 4 * (9 * n + 3 * i + j), u);
                    S[3 * a + i][3 * b + j] = f; /* a diagonal block is used as stored (in full) */
                    if (b != a) S[3 * b + j][3 * a + i] = f;
                }
}
#else
#define REC 724
/* BLOB.md format 6.0: i32 diag[8][6] (xx yy zz xy xz yz) at 0, i16 m[28][9]
 * at 192, u8 e[28] at 696; off-diagonal block (a,b) number 7a - a(a-1)/2 + b - a - 1 */
static void make_rec(unsigned char *K, double S[24][24], int extreme) {
    static const int s6[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
    int a, b, i, k, o = 0;
    for (a = 0; a < 8; a++)
        for (k = 0; k < 6; k++) {
            int32_t v = extreme ? (rnd32() & 1 ? (1 << 27) : -(1 << 27)) : rnd_in(1 << 27);
            put32(K + 24 * a + 4 * k, (uint32_t)v);
            S[3 * a + s6[k][0]][3 * a + s6[k][1]] = S[3 * a + s6[k][1]][3 * a + s6[k][0]] = v;
        }
    for (a = 0; a < 8; a++)
        for (b = a + 1; b < 8; b++, o++) {
            int e = extreme ? 12 : (int)(rnd32() % 13u);
            K[696 + o] = (unsigned char)e;
            for (i = 0; i < 9; i++) {
                int32_t m = extreme ? (rnd32() & 1 ? 32767 : -32767) : rnd_in(32767);
                uint16_t u = (uint16_t)(m < 0 ? m + 65536 : m);
                K[192 + 18 * o + 2 * i] = (unsigned char)u;
                K[192 + 18 * o + 2 * i + 1] = (unsigned char)(u >> 8);
                S[3 * a + i / 3][3 * b + i % 3] = S[3 * b + i % 3][3 * a + i / 3] = ldexp((double)m, e);
            }
        }
}
#endif

#if defined(SN_FLOAT)
/* The float summation order of sn_kernels.h, written here from BLOB.md's
 * float CELLK (36 upper blocks, row r holding (r,r)..(r,7), 9 row-major
 * floats each): outputs of row a take B u_b for b = a..7, outputs of row b
 * the transposed blocks (a,b), a < b, as the rows go; each block term is
 * (p0 + p1) + p2 added to the output. Separate statements: no contraction
 * by any compiler. Every path's float must be this one, bit for bit. */
static float kf(const unsigned char *K, int n, int k) {
    float f;
    uint32_t u = (uint32_t)K[36 * n + 4 * k] | (uint32_t)K[36 * n + 4 * k + 1] << 8 |
                 (uint32_t)K[36 * n + 4 * k + 2] << 16 | (uint32_t)K[36 * n + 4 * k + 3] << 24;
    memcpy(&f, &u, 4);
    return f;
}
static void order_ref(const unsigned char *K, const float *u, float *l) {
    int a, b, r, n = 0;
    for (a = 0; a < 24; a++) l[a] = 0.0f;
    for (a = 0; a < 8; a++)
        for (b = a; b < 8; b++, n++)
            for (r = 0; r < 3; r++) {
                float p0 = kf(K, n, 3 * r) * u[3 * b], p1 = kf(K, n, 3 * r + 1) * u[3 * b + 1];
                float p2 = kf(K, n, 3 * r + 2) * u[3 * b + 2], t = p0 + p1;
                t = t + p2;
                l[3 * a + r] = l[3 * a + r] + t;
                if (b == a) continue;
                p0 = kf(K, n, r) * u[3 * a];
                p1 = kf(K, n, 3 + r) * u[3 * a + 1];
                p2 = kf(K, n, 6 + r) * u[3 * a + 2];
                t = p0 + p1;
                t = t + p2;
                l[3 * b + r] = l[3 * b + r] + t;
            }
}
#endif

/* reference row r of S u; fixed: exact, the operand split into a high
 * part (>> 13) and a low one so that every product and partial sum is an
 * integer below 2^53 (exact in double) */
static int row_ok(double S[24][24], const sn_q *u, int r, sn_acc got) {
#if defined(SN_FLOAT)
    double ref = 0, mag = 0;
    int c;
    for (c = 0; c < 24; c++) { ref += S[r][c] * (double)u[c]; mag += fabs(S[r][c] * (double)u[c]); }
    return fabs((double)got - ref) <= 24.0 * mag * ldexp(1.0, -23) + 1e-30;
#else
    /* products |S u| < 2^55: sum the high and low 26-bit halves of u separately (each partial sum < 2^53 exact) */
    double hi = 0, lo = 0;
    int c;
    int64_t ref;
    for (c = 0; c < 24; c++) {
        int64_t uu = u[c], uh = uu >= 0 ? uu >> 13 : -((-uu) >> 13), ul = uu - uh * 8192;
        hi += S[r][c] * (double)uh; /* < 2^27 * 2^15 * 24 < 2^47 */
        lo += S[r][c] * (double)ul; /* < 2^27 * 2^13 * 24 < 2^45 */
    }
    ref = (int64_t)hi * 8192 + (int64_t)lo;
    return ref == got;
#endif
}

/* ---- IC(0) block products (sn_kernels_ic.h), against a reference written
 * from BLOB.md's ICHOL element (int16 m[9] row-major, u8 frac, pad) in
 * double: every product sum |p| < 3 2^43 is an exact double, and so are
 * p 2^-s and p 2^-s + 1/2 (< 2^52), so floor(p 2^-s + 1/2) is the exact
 * round-half-up. Fixed: tolerance 0 (the path's integers equal the
 * reference and the portable _ref; clamps counted alike). Float: the path
 * is the _ref; against double, 4 roundings (3 products, 3 adds into a) each
 * <= 2^-24 of a partial sum bounded by |a0| + sum |U y|: 2^-21 of that. */
static double ic_rnd(double p, int s, uint32_t *sat) {
#if defined(SN_FLOAT)
    (void)s; (void)sat;
    return p;
#else
    double v = floor(ldexp(p, -s) + (s > 0 ? 0.5 : 0.0));
    if (s >= 0) return v;
    if (v > 268435456.0) { (*sat)++; return 268435456.0; }
    if (v < -268435456.0) { (*sat)++; return -268435456.0; }
    return v;
#endif
}
static int ic_close(sn_acc got, double ref, double mag) {
#if defined(SN_FLOAT)
    return fabs((double)got - ref) <= ldexp(mag, -21) + 1e-30;
#else
    (void)mag;
    return (double)got == ref; /* |ref| < 2^52 here: exact in double */
#endif
}
static void test_ic(void) {
    int t, bad_path = 0, bad_ref = 0, clamps = 0;
    for (t = 0; t < 20000; t++) {
        unsigned char b[20];
        double U[9], scale, refc[3], refr[3], magc[3], magr[3];
        sn_q y[3];
        sn_acc a0[3], ac[3], ar[3], lc[4], lr[4];
        uint32_t sat_p = 0, sat_r = 0, sat_d = 0, satc_p = 0, satc_r = 0, satc_d = 0;
        int k, r, c, extreme = t % 16 == 0;
#if defined(SN_FLOAT)
        int frac = (int)(rnd32() % 41u), s = frac;
#else
        int frac = (int)(rnd32() % 63u); /* the row's shift: frac, 0..62 (sn_rshr64's range) */
        int s = t % 4 == 0 ? -(int)(rnd32() % 16u) : (int)(rnd32() % 63u); /* the column's: frac + k_j - k_i, -15..62 */
#endif
        scale = SN_FLAVOUR ? ldexp(1.0, -frac) : 1.0;
        for (k = 0; k < 9; k++) {
            int32_t m = extreme ? (rnd32() & 1 ? 32767 : -32767) : rnd_in(32767);
            uint16_t u = (uint16_t)(m < 0 ? m + 65536 : m);
            b[2 * k] = (unsigned char)u;
            b[2 * k + 1] = (unsigned char)(u >> 8);
            U[k] = ldexp((double)m, 0) * scale;
        }
        b[18] = (unsigned char)frac;
        b[19] = (unsigned char)rnd32(); /* pad: never used */
        for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
            y[k] = (float)rnd_in(1 << 20) / 256.0f;
            a0[k] = (float)rnd_in(1 << 20);
#else
            y[k] = extreme ? (rnd32() & 1 ? (1 << 28) : -(1 << 28)) : rnd_in(1 << 28);
            if (s < 0 && !extreme) y[k] /= (int32_t)1 << (rnd32() % 24u); /* some scaled-up rows below the clamp */
            a0[k] = (int64_t)rnd_in(1 << 30) * (1 << 19); /* |.| <= 2^49: the sweeps' accumulator bound */
#endif
            ac[k] = ar[k] = a0[k];
            lc[k] = lr[k] = a0[k];
        }
        lc[3] = lr[3] = 0;
        sn_k_ic_col(b, y, s, ac, &satc_p);
        sn_k_ic_col_ref(b, y, s, ar, &satc_r);
        sn_k_ic_row(b, y, lc, &sat_p);
        sn_k_ic_row_ref(b, y, lr, &sat_r);
        for (k = 0; k < 3; k++) {
            double pc = 0, pr = 0;
            magc[k] = magr[k] = fabs((double)a0[k]);
            for (r = 0; r < 3; r++) {
                pc += U[3 * r + k] * (double)y[r];
                magc[k] += fabs(U[3 * r + k] * (double)y[r]);
            }
            for (c = 0; c < 3; c++) {
                pr += U[3 * k + c] * (double)y[c];
                magr[k] += fabs(U[3 * k + c] * (double)y[c]);
            }
            refc[k] = (double)a0[k] + ic_rnd(pc, s, &satc_d);
            refr[k] = (double)a0[k] + ic_rnd(pr, frac, &sat_d);
        }
        for (k = 0; k < 3; k++) {
            bad_path += memcmp(&ac[k], &ar[k], sizeof ac[k]) != 0 || memcmp(&lc[k], &lr[k], sizeof lc[k]) != 0;
            bad_ref += !ic_close(ar[k], refc[k], magc[k]) || !ic_close(lr[k], refr[k], magr[k]);
        }
        bad_path += satc_p != satc_r || sat_p != sat_r;
        bad_ref += satc_r != satc_d || sat_r != sat_d;
        clamps += (int)satc_d;
    }
    T_CHECK(bad_path == 0, "IC(0) block products: %d differences between path %s and the portable reference", bad_path,
            sn_kernels_name());
    T_CHECK(bad_ref == 0, "IC(0) block products: %d rows or clamp counts off the double reference", bad_ref);
    T_FIGURE("IC(0) block products: 20000 random blocks (every 16th at the bounds, column shifts -15..62), %d clamped rows",
             clamps);
}

/* ---- frame rotations (sn_kernels_rot.h) against the reference in double:
 * fixed, R entries up to +-2^30 (Q30; any matrix, not only rotations, so
 * the clamp is reached), v up to +-2^28: the sum x < 3 2^58 is split as
 * in row_ok (v = 2^13 vh + vl, every partial sum < 2^53 exact) and rounded
 * half up by floor division on the exact int64, then clamped to +-2^28 and
 * counted. Tolerance 0 against both the double reference and sn_rot*
 * (sn_internal.h). Float: the path is sn_rot*; against double, 3 products
 * and 2 adds rounded: 2^-21 of sum |R v|. */
static double rot_ref(const double *r, int stride, const sn_q *v, double *mag) {
#if defined(SN_FLOAT)
    int c;
    double x = 0;
    *mag = 0;
    for (c = 0; c < 3; c++) { x += r[c * stride] * (double)v[c]; *mag += fabs(r[c * stride] * (double)v[c]); }
    return x;
#else
    double hi = 0, lo = 0;
    int64_t x, q;
    int c;
    *mag = 0;
    for (c = 0; c < 3; c++) {
        int64_t vv = v[c], vh = vv >= 0 ? vv >> 13 : -((-vv) >> 13), vl = vv - vh * 8192;
        hi += r[c * stride] * (double)vh;
        lo += r[c * stride] * (double)vl;
    }
    x = (int64_t)hi * 8192 + (int64_t)lo;
    q = x >= 0 ? x / 1073741824 : -((-x + 1073741823) / 1073741824); /* floor(x / 2^30) */
    if (x - q * 1073741824 >= 536870912) q++;                          /* round half up */
    return (double)q;
#endif
}
static void test_rot(void) {
    int t, k, bad_path = 0, bad_ref = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 20000; t++) {
        sn_q R[9], v[3], o1[3], o2[3], p1[3], p2[3];
        sn_acc a1[3], a2[3];
        double Rd[9], mag;
        uint32_t s1 = 0, s2 = 0, sd = 0;
        int extreme = t % 16 == 0;
        for (k = 0; k < 9; k++) {
#if defined(SN_FLOAT)
            R[k] = (float)rnd_in(1 << 20) / 1048576.0f;
#else
            R[k] = extreme ? (rnd32() & 1 ? (1 << 30) : -(1 << 30)) : rnd_in(1 << 30);
#endif
            Rd[k] = (double)R[k];
        }
        for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
            v[k] = (float)rnd_in(1 << 20) / 1024.0f; /* below SN_FLIM / 3: no clamp */
            if (extreme) v[k] = k == 2 && t % 48 == 0 ? nanf("") : (float)rnd_in(1 << 20) * 0.03125f; /* clamps, NaN */
            a1[k] = a2[k] = (float)rnd_in(1 << 20);
#else
            v[k] = extreme ? (rnd32() & 1 ? (1 << 28) : -(1 << 28)) : rnd_in(1 << 28);
            a1[k] = a2[k] = (int64_t)rnd_in(1 << 30) * (1 << 20);
#endif
        }
        sn_k_rot_t(R, v, o1, &s1);
        sn_rot_t(R, v, o2, &s2);
        sn_k_rot(R, v, p1, &s1);
        sn_rot(R, v, p2, &s2);
        sn_k_rot_acc(a1, R, v);
        sn_rot_acc(a2, R, v);
        bad_path += memcmp(o1, o2, sizeof o1) != 0 || memcmp(p1, p2, sizeof p1) != 0 || s1 != s2;
        bad_path += memcmp(a1, a2, sizeof a1) != 0 && v[2] == v[2]; /* a NaN's payload may differ: not state */
#if defined(SN_FLOAT)
        if (extreme) { clamps += s2; continue; } /* the float clamp (and NaN -> 0): against sn_rot* only */
#endif
        for (k = 0; k < 3; k++) {
            double xt = rot_ref(Rd + k, 3, v, &mag), mt = mag, xr = rot_ref(Rd + 3 * k, 1, v, &mag), mr = mag;
#if defined(SN_FLOAT)
            bad_ref += fabs((double)o2[k] - xt) > ldexp(mt, -21) + 1e-30 || fabs((double)p2[k] - xr) > ldexp(mr, -21) + 1e-30;
#else
            double lim = 268435456.0;
            (void)mt; (void)mr;
            sd += (uint32_t)((xt > lim || xt < -lim) + (xr > lim || xr < -lim));
            xt = xt > lim ? lim : xt < -lim ? -lim : xt;
            xr = xr > lim ? lim : xr < -lim ? -lim : xr;
            bad_ref += (double)o2[k] != xt || (double)p2[k] != xr;
#endif
        }
#if !defined(SN_FLOAT)
        bad_ref += s2 != sd;
#endif
        clamps += sd;
    }
#if !defined(SN_FLOAT)
    {   /* the clamp's edges: R = 2^30 I (Q30 identity), v = +-(2^28 - 1),
         * +-2^28, +-(2^28 + 1), INT32_MIN/MAX: the outputs are v clamped
         * to +-2^28, counted; against sn_rot* and the formula */
        static const int32_t ev[] = {(1 << 28) - 1, 1 << 28, (1 << 28) + 1, -(1 << 28) + 1, -(1 << 28), -(1 << 28) - 1,
                                     INT32_MAX, INT32_MIN};
        sn_q R[9] = {1 << 30, 0, 0, 0, 1 << 30, 0, 0, 0, 1 << 30}, v[3], o1[3], o2[3], p1[3], p2[3];
        unsigned i;
        for (i = 0; i < sizeof ev / sizeof ev[0]; i++) {
            uint32_t s1 = 0, s2 = 0, sd = 0, c;
            v[0] = ev[i]; v[1] = ev[(i + 3) % 8]; v[2] = ev[(i + 5) % 8];
            sn_k_rot_t(R, v, o1, &s1);
            sn_rot_t(R, v, o2, &s2);
            sn_k_rot(R, v, p1, &s1);
            sn_rot(R, v, p2, &s2);
            bad_path += memcmp(o1, o2, sizeof o1) != 0 || memcmp(p1, p2, sizeof p1) != 0 || s1 != s2;
            for (c = 0; c < 3; c++) {
                const int32_t w = v[c] > (1 << 28) ? (1 << 28) : v[c] < -(1 << 28) ? -(1 << 28) : v[c];
                sd += 2u * (w != v[c]);
                bad_ref += o2[c] != w || p2[c] != w;
            }
            bad_ref += s2 != sd;
        }
    }
#endif
    T_CHECK(bad_path == 0, "frame rotations: %d differences between path %s and sn_rot*", bad_path, sn_kernels_name());
    T_CHECK(bad_ref == 0, "frame rotations: %d results or clamp counts off the double reference", bad_ref);
    T_FIGURE("frame rotations: 20000 random matrices and vectors (every 16th at the bounds), %u clamped outputs", (unsigned)clamps);
}

/* ---- CG vector update (sn_kernels.h sn_k_axpy) against the formula
 * written here: fixed, the exact int64 product s x rounded half up by
 * floor division (|s x| <= 2^59), clamped to +-2^28 (counted), added to a
 * and clamped again (counted); tolerance 0, lengths 0..40 (the SIMD tails)
 * and both aliasings of the solver (out = a: axpy; out = x: d = z + beta d).
 * Float: out = a + s x, 2 roundings: 2^-22 of |a| + |s x|. */
static void test_axpy(void) {
    int t, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 3000; t++) {
        sn_q a[40], x[40], o[40], s;
        double ref[40], mag[40];
        uint32_t n = rnd32() % 41u, i, sat = 0, sd = 0;
        int sh = t % 3 == 0 ? (int)(rnd32() % 63u) : 28, alias = t % 3;
#if defined(SN_FLOAT)
        s = (float)rnd_in(1 << 20) / 1048576.0f; /* |a + s x| < SN_FLIM: no clamp */
        (void)sh;
#else
        s = t % 16 == 0 ? (rnd32() & 1 ? INT32_MAX : INT32_MIN) : (sn_q)(((int64_t)rnd32() - 2147483648) / ((int64_t)1 << (rnd32() % 31u)));
#endif
        for (i = 0; i < n; i++) {
#if defined(SN_FLOAT)
            a[i] = (float)rnd_in(1 << 20) / 1024.0f;
            x[i] = (float)rnd_in(1 << 20) / 1024.0f;
            ref[i] = (double)a[i] + (double)s * (double)x[i];
            mag[i] = fabs((double)a[i]) + fabs((double)s * (double)x[i]);
#else
            int64_t p, q, half = sh > 0 ? (int64_t)1 << (sh - 1) : 0, d = (int64_t)1 << sh;
            a[i] = rnd_in(1 << 28);
            x[i] = t % 16 == 1 ? (rnd32() & 1 ? (1 << 28) : -(1 << 28)) : rnd_in(1 << 28);
            p = (int64_t)s * x[i] + half;
            q = p >= 0 ? p / d : -((-p + d - 1) / d); /* floor */
            if (q > (1 << 28) || q < -(1 << 28)) { sd++; q = q > 0 ? (1 << 28) : -(1 << 28); }
            q += a[i];
            if (q > (1 << 28) || q < -(1 << 28)) { sd++; q = q > 0 ? (1 << 28) : -(1 << 28); }
            ref[i] = (double)q;
            mag[i] = 0;
#endif
        }
#if defined(SN_FLOAT)
        if (t % 16 == 0) { /* the float clamp and NaN -> 0, each counted: against sn_add/sn_mulq bit for bit */
            s = 1.0e3f;
            for (i = 0; i < n; i++) {
                if (rnd32() % 8u == 0) x[i] = nanf("");
                ref[i] = (double)sn_add(a[i], sn_mulq(s, x[i], sh, &sd), &sd);
                mag[i] = 0;
            }
        }
#endif
        if (alias == 1) { memcpy(o, a, sizeof a); sn_k_axpy(o, o, s, x, n, sh, &sat); }
        else if (alias == 2) { memcpy(o, x, sizeof x); sn_k_axpy(o, a, s, o, n, sh, &sat); }
        else sn_k_axpy(o, a, s, x, n, sh, &sat);
        for (i = 0; i < n; i++) {
#if defined(SN_FLOAT)
            bad += fabs((double)o[i] - ref[i]) > ldexp(mag[i], -22) + 1e-30;
#else
            bad += (double)o[i] != ref[i] + 0.0 * mag[i];
#endif
        }
        bad += sat != sd;
        clamps += sd;
    }
#if !defined(SN_FLOAT)
    {   /* the clamps' edges: s x 2^-3 = +-(2^28 - 1), +-2^28, +-(2^28 + 1)
         * exactly (x = 8, sh = 3) and INT32_MIN/MAX s, with a at 0 and
         * +-SN_LIM, against the same floor-and-clamp reference */
        static const int32_t es[] = {(1 << 28) - 1, 1 << 28, (1 << 28) + 1, -(1 << 28) + 1, -(1 << 28), -(1 << 28) - 1,
                                     INT32_MAX, INT32_MIN, 0};
        static const int32_t ea[] = {0, 1 << 28, -(1 << 28), 1, -1};
        unsigned i, j;
        for (i = 0; i < sizeof es / sizeof es[0]; i++) {
            sn_q a[5], x[5], o[5];
            uint32_t sat = 0, sd = 0;
            for (j = 0; j < 5; j++) { a[j] = ea[j]; x[j] = 8; }
            sn_k_axpy(o, a, es[i], x, 5, 3, &sat);
            for (j = 0; j < 5; j++) {
                int64_t q = ((int64_t)es[i] * 8 + 4) >> 3; /* exact: a multiple of 8 plus 4, >= 0 or floor by >> */
                if (q > (1 << 28) || q < -(1 << 28)) { sd++; q = q > 0 ? (1 << 28) : -(1 << 28); }
                q += a[j];
                if (q > (1 << 28) || q < -(1 << 28)) { sd++; q = q > 0 ? (1 << 28) : -(1 << 28); }
                bad += o[j] != (sn_q)q;
            }
            bad += sat != sd;
        }
    }
    {   /* the product's bound |s x| <= 2^31 2^28 at the CG's shifts 28..31
         * (the M4's word form there): s at INT32_MIN/MAX, +-1, 0, +-2^30, x at
         * +-2^28, +-(2^28 - 1), +-2^27, +-1, 0 (INT32_MIN x -2^28 rounds to
         * 2^31: clamped to +SN_LIM), against the same reference formula */
        static const int32_t es[] = {INT32_MIN, INT32_MAX, -INT32_MAX, 1, -1, 0, 1 << 30, -(1 << 30)};
        static const int32_t ex[] = {1 << 28, -(1 << 28), (1 << 28) - 1, -(1 << 28) + 1, 1 << 27, -(1 << 27), 1, -1, 0};
        static const int32_t ea[] = {0, 1 << 28, -(1 << 28), 1, -1};
        unsigned i, j, k;
        int sh;
        for (sh = 28; sh < 32; sh++)
            for (i = 0; i < sizeof es / sizeof es[0]; i++)
                for (k = 0; k < 5; k++) {
                    sn_q a[9], x[9], o[9];
                    uint32_t sat = 0, sd = 0;
                    for (j = 0; j < 9; j++) { a[j] = ea[(j + k) % 5]; x[j] = ex[j]; }
                    sn_k_axpy(o, a, es[i], x, 9, sh, &sat);
                    for (j = 0; j < 9; j++) {
                        int64_t q = ((int64_t)es[i] * x[j] + ((int64_t)1 << (sh - 1))) >> sh; /* floor: arithmetic shift */
                        if (q > (1 << 28) || q < -(1 << 28)) { sd++; q = q > 0 ? (1 << 28) : -(1 << 28); }
                        q += a[j];
                        if (q > (1 << 28) || q < -(1 << 28)) { sd++; q = q > 0 ? (1 << 28) : -(1 << 28); }
                        bad += o[j] != (sn_q)q;
                    }
                    bad += sat != sd;
                }
    }
#endif
    T_CHECK(bad == 0, "CG vector update (path %s): %d values or clamp counts off the reference", sn_kernels_name(), bad);
    T_FIGURE("CG vector update: 3000 random vectors of 0..40 values (shifts 28 and 0..62, both aliasings), %u clamps", (unsigned)clamps);
}

/* sn_k_ic_bwd_row (the backward sweep's row: on the M4 a Thumb-2 loop that
 * hands blocks with frac 0 or >= 32 to the reference and resumes) against
 * the loop of sn_k_ic_row_ref from 0 (bit for bit, both flavours) and, fixed,
 * the double reference (each row floor(p 2^-frac + 1/2), |p| < 3 2^15 2^31
 * < 2^48: exact; the int64 sum of up to 12 exact): 3000 runs of 0..12
 * blocks of a 30-vertex z, fracs mostly 1..31, every 4th run with 0 or
 * 32..62 anywhere (first, last, consecutive), z at +-2^28 or
 * INT32_MIN/MAX in every 8th run. Tolerance 0. */
static void test_ic_rows(void) {
    static unsigned char L[12 * 20], cols[24];
    int t, bad = 0, bad_ref = 0, odd = 0;
    for (t = 0; t < 3000; t++) {
        sn_q z[90];
        sn_acc lp[4], lr[4];
        double ref[3] = {0, 0, 0};
        uint32_t nb = rnd32() % 13u, e, k, sat_p = 0, sat_r = 0;
        int wild = t % 8 == 0;
        for (k = 0; k < 90; k++) {
#if defined(SN_FLOAT)
            z[k] = (float)rnd_in(1 << 20) / 256.0f;
#else
            z[k] = wild ? (t % 16 == 0 ? (rnd32() & 1 ? INT32_MAX : INT32_MIN) : (rnd32() & 1 ? (1 << 28) : -(1 << 28)))
                        : rnd_in(1 << 28);
#endif
        }
        for (e = 0; e < nb; e++) {
            unsigned char *b = L + 20 * e;
            uint32_t col = rnd32() % 30u;
            int frac = (int)(1u + rnd32() % 31u), r, c;
            if (t % 4 == 1 && rnd32() % 3u == 0) { frac = rnd32() & 1 ? 0 : (int)(32u + rnd32() % 31u); odd++; }
            for (k = 0; k < 9; k++) {
                int32_t m = wild ? (rnd32() & 1 ? 32767 : -32767) : rnd_in(32767);
                uint16_t u = (uint16_t)(m < 0 ? m + 65536 : m);
                b[2 * k] = (unsigned char)u;
                b[2 * k + 1] = (unsigned char)(u >> 8);
            }
            b[18] = (unsigned char)frac;
            b[19] = 0;
            cols[2 * e] = (unsigned char)col;
            cols[2 * e + 1] = 0;
            for (r = 0; r < 3; r++) {
                double p = 0;
                for (c = 0; c < 3; c++) {
                    int32_t m = (int16_t)(uint16_t)(b[2 * (3 * r + c)] | b[2 * (3 * r + c) + 1] << 8);
                    p += (double)m * (double)z[3 * col + (uint32_t)c];
                }
                ref[r] += SN_FLAVOUR ? 0.0 : floor(ldexp(p, -frac) + (frac > 0 ? 0.5 : 0.0));
            }
        }
        sn_k_ic_bwd_row(L, cols, nb, z, lp, &sat_p);
        lr[0] = lr[1] = lr[2] = lr[3] = 0;
        for (e = 0; e < nb; e++) sn_k_ic_row_ref(L + 20 * e, z + 3 * (cols[2 * e] | cols[2 * e + 1] << 8), lr, &sat_r);
        bad += memcmp(lp, lr, 3 * sizeof lp[0]) != 0 || sat_p != sat_r;
#if !defined(SN_FLOAT)
        for (k = 0; k < 3; k++) bad_ref += (double)lr[k] != ref[k];
#else
        (void)ref;
#endif
    }
    T_CHECK(bad == 0, "IC(0) backward rows (path %s): %d of 3000 runs differ from the reference loop", sn_kernels_name(), bad);
    T_CHECK(bad_ref == 0, "IC(0) backward rows: %d sums off the double reference", bad_ref);
    T_FIGURE("IC(0) backward rows: 3000 runs of 0..12 blocks, %d with frac 0 or >= 32", odd);
}

#if !defined(SN_FLOAT)
/* sn_k_mul_out (d sn_out(l, s): the energy's term; on the M4 with the
 * rounded value held as an int32) against sn_mul(d, sn_out(l, s)) and the
 * clamp written here: l at +-2^62 (sn_out's precondition: < 2^62.5), at
 * the clamp's edges (+-2^28 +- 1 after the shift, s 0..33) and random
 * widths, s 0..40, d up to INT32_MIN/MAX. Tolerance 0, counts included. */
static void test_mul_out(void) {
    int t, bad = 0;
    for (t = 0; t < 40000; t++) {
        const int s = (int)(rnd32() % (t % 4 == 0 ? 34u : 41u)); /* (2^28 + 1) 2^33 < 2^62 */
        const sn_q d = t % 16 == 0 ? (rnd32() & 1 ? INT32_MAX : INT32_MIN) : (sn_q)rnd32();
        int64_t l, q;
        uint32_t s1 = 0, s2 = 0, sd = 0;
        switch (t % 4) {
        case 0: l = (((int64_t)1 << 28) + (int64_t)(rnd32() % 3u) - 1) * ((int64_t)1 << s) * (rnd32() & 1 ? 1 : -1); break;
        case 1: l = rnd32() & 1 ? ((int64_t)1 << 62) : -((int64_t)1 << 62); break;
        default: l = (int64_t)(((uint64_t)rnd32() << 32 | rnd32()) >> (2 + rnd32() % 62u)) * (rnd32() & 1 ? 1 : -1);
        }
        q = s > 0 ? (l + ((int64_t)1 << (s - 1))) >> s : l;
        if (q > (1 << 28) || q < -(1 << 28)) { sd++; q = q > 0 ? (1 << 28) : -(1 << 28); }
        bad += sn_k_mul_out(d, l, s, &s1) != sn_mul(d, sn_out(l, s, &s2)) || s1 != s2;
        bad += sn_k_mul_out(d, l, s, &s1) != (int64_t)d * q || s1 != 2 * sd;
    }
    T_CHECK(bad == 0, "energy term d sn_out(l, s) (path %s): %d of 40000 off", sn_kernels_name(), bad);
}

/* The segment sweep's clamps (sn_segment.h; on a Cortex-M one unsigned
 * compare of the low word plus the high word's sign) against the compares
 * written here: seg_out on int32 values (the edges +-2^28 +- 1, INT32_MIN/MAX,
 * random), seg_lim on int64 values for m = 2^28 (ROT_MAX), 2^29, 1 and
 * INT32_MAX (edges +-m +- 1, a high word with a small low word such as
 * 2^32 + 5, +-2^62, random widths). Tolerance 0, counts included. */
static void test_seg_clamps(void) {
    static const int64_t m4[] = {(int64_t)1 << 28, (int64_t)1 << 29, 1, INT32_MAX};
    int t, bad = 0, n = 0;
    for (t = 0; t < 40000; t++) {
        const int32_t e32[] = {(1 << 28) + 1, 1 << 28, (1 << 28) - 1, -(1 << 28) + 1, -(1 << 28), -(1 << 28) - 1,
                               INT32_MAX, INT32_MIN, INT32_MIN + 1, 0};
        const int32_t v = t < 10 ? e32[t] : (int32_t)(rnd32() >> (rnd32() % 32u)) * (rnd32() & 1 ? 1 : -1);
        const int32_t want = v > (1 << 28) ? (1 << 28) : v < -(1 << 28) ? -(1 << 28) : v;
        const int64_t m = m4[t % 4];
        int64_t a, wl;
        uint32_t sat = 0;
        const int32_t got = (int32_t)seg_out((seg_n)v, &sat);
        bad += got != want || sat != (uint32_t)(want != v);
        switch (t % 8) {
        case 0: a = m + (int64_t)(t / 8 % 3) - 1; break;            /* m - 1, m, m + 1 */
        case 1: a = -m + (int64_t)(t / 8 % 3) - 1; break;
        case 2: a = ((int64_t)(rnd32() % 5u) - 2) * ((int64_t)1 << 32) + (int64_t)(rnd32() % 9u) - 4; break;
        case 3: a = rnd32() & 1 ? ((int64_t)1 << 62) : -((int64_t)1 << 62); break;
        default: a = (int64_t)(((uint64_t)rnd32() << 32 | rnd32()) >> (1 + rnd32() % 63u)) * (rnd32() & 1 ? 1 : -1);
        }
        wl = a > m ? m : a < -m ? -m : a;
        bad += seg_lim(a, m) != wl;
        n += 2;
    }
    T_CHECK(bad == 0, "segment clamps: %d of %d results off the compares", bad, n);
}

#endif

#if !defined(SN_FLOAT)
/* ---- the rounding shift for run-time shifts (sn_rshr64_var: the Cortex-M
 * split over two words, sn_rshr64 elsewhere) against floor((x + 2^(s-1)) /
 * 2^s) by division, written here: random x with |x| up to 2^62 (the
 * precondition x + 2^(s-1) < 2^63), s 0..62, and the edges around every
 * multiple of 2^s near 0, +-2^31, +-2^32 and +-2^62. Tolerance 0. */
static int64_t rshr_ref(int64_t x, int s) {
    int64_t d, q, r;
    if (s <= 0) return x;
    /* floor(x / 2^s) plus the carry of the remainder r in [0, 2^s) */
    d = (int64_t)1 << (s - 1);
    q = x / (d * 2);
    r = x % (d * 2);
    if (r < 0) { r += d * 2; q -= 1; }
    return q + (r + d >= d * 2 ? 1 : 0);
}
/* ---- the CG's block-floating dot product (sn_k_dot) against a reference
 * written from its contract (sn_kernels.h): s = max(0, bitlen(OR|a|) +
 * bitlen(OR|b|) + bitlen(n) - 62), each product a_k b_k rounded alone by
 * rshr_ref at s + k_i, summed exactly. Random lengths 0..600 (whole
 * vertices), values at scales 2^0..2^28 (every 8th vector at +-2^28),
 * k_i 0..15 (0..45 in every 4th: shifts beyond 31). Tolerance 0: the result
 * is an exact integer. */
static int bitlen_ref(uint64_t x) { int n = 0; while (x) { n++; x /= 2; } return n; }
static void test_dot(void) {
    static sn_q a[600], b[600];
    static uint8_t kk[200];
    int t, bad = 0;
    for (t = 0; t < 400; t++) {
        uint32_t nv = rnd32() % 201u, n = 3 * nv, i, oa = 0, ob = 0;
        int sa = (int)(rnd32() % 29u), sb = (int)(rnd32() % 29u), s, e = -1;
        int64_t ref = 0, got;
        for (i = 0; i < n; i++) {
            a[i] = t % 8 == 0 || t % 16 == 2 ? (rnd32() & 1 ? (1 << 28) : -(1 << 28)) : rnd_in((int32_t)1 << sa);
            /* every 16th: b all -2^28 (|b|'s bit length from a negative power of two alone) */
            b[i] = t % 16 == 2 ? -(1 << 28) : t % 8 == 1 ? (rnd32() & 1 ? (1 << 28) : -(1 << 28)) : rnd_in((int32_t)1 << sb);
            oa |= (uint32_t)(a[i] < 0 ? -a[i] : a[i]);
            ob |= (uint32_t)(b[i] < 0 ? -b[i] : b[i]);
        }
        /* k up to 45 in every 4th run: shifts s + k beyond 31 too (the M4's C fallback) */
        for (i = 0; i < nv; i++) kk[i] = (uint8_t)(rnd32() % (t % 4 == 3 ? 46u : 16u));
        s = bitlen_ref(oa) + bitlen_ref(ob) + bitlen_ref(n) - 62;
        s = s < 0 ? 0 : s;
        for (i = 0; i < n; i++) ref += rshr_ref((int64_t)a[i] * b[i], s + kk[i / 3]);
        got = sn_k_dot(a, b, kk, n, &e);
        bad += got != ref || e != s;
    }
    T_CHECK(bad == 0, "CG dot product (path %s): %d of 400 sums or exponents off the reference", sn_kernels_name(), bad);
}

static void test_rshr(void) {
    static const int64_t base[] = {0, (int64_t)1 << 31, (int64_t)1 << 32, (int64_t)1 << 61};
    int t, s, k, bad = 0, n = 0;
    for (t = 0; t < 200000; t++) {
        int64_t x = (int64_t)((((uint64_t)rnd32() << 32) | rnd32()) >> (2 + rnd32() % 61u)); /* 0 <= x < 2^62 */
        if (rnd32() & 1) x = -x;
        s = (int)(rnd32() % 63u);
        bad += sn_rshr64_var(x, s) != rshr_ref(x, s);
        n++;
    }
    for (s = 0; s <= 62; s++)
        for (k = 0; k < 4; k++) {
            int64_t m = s > 0 ? (int64_t)1 << (s - 1) : 1, j;
            for (j = -2; j <= 2; j++) {
                int64_t c[4] = {base[k] + j, base[k] + m + j, -base[k] + j, -base[k] - m + j};
                int i;
                for (i = 0; i < 4; i++) { bad += sn_rshr64_var(c[i], s) != rshr_ref(c[i], s); n++; }
            }
        }
    T_CHECK(bad == 0, "rounding shift: %d of %d results off floor((x + 2^(s-1)) / 2^s)", bad, n);
    /* sn_add over the whole int32 range (the Cortex-M's 32-bit sum with its
     * overflow test) against the int64 sum clamped to +-2^28, with the count */
    bad = 0;
    for (t = 0; t < 200000; t++) {
        const int32_t x = t % 4 == 0 ? (int32_t)((int64_t)rnd32() - 2147483648) /* any int32 */
                                     : (int32_t)(rnd32() >> (1 + rnd32() % 31u)) * (rnd32() & 1 ? 1 : -1);
        const int32_t y = t % 7 == 0 ? (x < 0 ? INT32_MIN : INT32_MAX)
                                     : (int32_t)(rnd32() >> (1 + rnd32() % 31u)) * (rnd32() & 1 ? 1 : -1);
        const int64_t w = (int64_t)x + y, c = w > (1 << 28) ? (1 << 28) : (w < -(1 << 28) ? -(1 << 28) : w);
        uint32_t sat = 0;
        const sn_q got = sn_add(x, y, &sat);
        bad += got != c || sat != (uint32_t)(c != w);
    }
    T_CHECK(bad == 0, "saturating add: %d of 200000 sums or counts off the clamped int64 sum", bad);
    {   /* every pair of edge values (the M4's QADD saturation and its
         * unsigned range compare at +-2^28 exactly) */
        static const int32_t ed[] = {INT32_MIN, INT32_MIN + 1, -(1 << 28) - 1, -(1 << 28), -(1 << 28) + 1, -1, 0, 1,
                                     (1 << 28) - 1, 1 << 28, (1 << 28) + 1, (1 << 29), INT32_MAX - 1, INT32_MAX};
        unsigned i, j;
        bad = 0;
        for (i = 0; i < sizeof ed / sizeof ed[0]; i++)
            for (j = 0; j < sizeof ed / sizeof ed[0]; j++) {
                const int64_t w = (int64_t)ed[i] + ed[j], c = w > (1 << 28) ? (1 << 28) : (w < -(1 << 28) ? -(1 << 28) : w);
                uint32_t sat = 0;
                const sn_q got = sn_add(ed[i], ed[j], &sat);
                bad += got != c || sat != (uint32_t)(c != w);
            }
        T_CHECK(bad == 0, "saturating add: %d of 196 edge pairs off the clamped int64 sum", bad);
    }
}

/* ---- the segment move's products and turn shift (sn_segment.h) against
 * rshr_ref, the division written above: r30s(x, b) (a Cortex-M4's SMMULR of
 * 4x and b) = round(x b / 2^30) for x in [-2^29, 2^29) (its precondition)
 * and any int32 b: the edges -2^29, -2^29 + 1, 2^29 - 1, 0, +-1, +-3 times
 * INT32_MIN, INT32_MAX, +-2^30, 2^30 - 1, 0, +-1, then random widths;
 * seg_rsh(a, sh, seg_bias(sh)) (the Cortex-M4's two words of an SMLAL sum) =
 * round(a / 2^sh) for sh 0..29 and |a| <= 2^61: a at the rounding edges
 * k 2^sh - 2^(sh-1) + {-1, 0, 1} and k 2^sh + {-1, 0, 1} with k near 0,
 * near the low word's edge (k 2^sh ~ +-2^32) and random, and random
 * products p kf (|p| < 2^29.6, |kf| <= 2^30, the move's). Tolerance 0. */
static void test_seg_move_ops(void) {
    static const int32_t ex[8] = {-(1 << 29), -(1 << 29) + 1, (1 << 29) - 1, 0, 1, -1, 3, -3};
    static const int32_t eb[8] = {INT32_MIN, INT32_MAX, 1 << 30, -(1 << 30), (1 << 30) - 1, 0, 1, -1};
    int t, bad_m = 0, bad_s = 0;
    for (t = 0; t < 60000; t++) {
        const int32_t sx = rnd32() & 1 ? 1 : -1, sb = rnd32() & 1 ? 1 : -1;
        const int32_t x = t < 64 ? ex[t % 8] : sx * (int32_t)(rnd32() >> (3 + rnd32() % 29u));
        const int32_t b = t < 64 ? eb[t / 8] : sb * (int32_t)(rnd32() >> (1 + rnd32() % 31u));
        const int sh = t % 30;
        const int64_t h = sh > 0 ? (int64_t)1 << (sh - 1) : 0, one = (int64_t)1 << sh;
        int64_t a, k;
        bad_m += (int64_t)r30s((seg_n)x, (seg_n)b) != rshr_ref((int64_t)x * b, 30);
        switch (t % 4) {
        case 0: k = (int64_t)(rnd32() % 9u) - 4; break;
        case 1: k = (((int64_t)1 << 32) >> sh) * (rnd32() & 1 ? 1 : -1) + (int64_t)(rnd32() % 5u) - 2; break;
        case 2: k = (int64_t)(((uint64_t)rnd32() << 32 | rnd32()) >> (3 + sh + rnd32() % 8u)) * (rnd32() & 1 ? 1 : -1); break;
        default: k = 0;
        }
        if (t % 4 == 3) { /* a move's product p kf */
            a = (int64_t)(sx * (int32_t)(rnd32() >> (2 + rnd32() % 30u))) * (sb * (int32_t)(rnd32() >> (2 + rnd32() % 30u)));
        } else {
            static const int64_t off[3] = {-1, 0, 1};
            a = k * one + off[rnd32() % 3u] - (rnd32() & 1 ? h : 0);
        }
        bad_s += seg_rsh(a, sh, seg_bias(sh)) != rshr_ref(a, sh);
    }
    T_CHECK(bad_m == 0, "segment r30s (path %s): %d of 60000 products off the rounded division", sn_kernels_name(), bad_m);
    T_CHECK(bad_s == 0, "segment turn shift seg_rsh: %d of 60000 values off the rounded division", bad_s);
}
#endif

#if defined(SN_FLOAT)
/* ---- the float star projection of a sheet node and the pair
 * (sn_segment_sweep.c): the step's forms (x86-64: star_fv, pair_fv, the ends
 * in SSE lanes) against star() and pair_core() bit for bit with the
 * saturation counts (the pair: the node's first two ends): 20000 random nodes of 3
 * or 4 ends (distinct segments of 6, random signs) on level 0 and on a
 * coarse level (the segments' own half lengths and turn factors), random
 * centres and unit directions; every 8th segment pushed to the clamps
 * (centre at +-(SN_FLIM - 0.5): the mean, the gaps and G + t clamp; half
 * lengths to 3 and turn factors to 40: the turn limiter), -0.0 components,
 * every 64th node with a NaN centre (sn_out's replacement), every 64th a
 * NaN direction (the limiter keeps a NaN). Tolerance 0. */
static float rnd_f(float a) { return a * ((float)(rnd32() % 2000001u) / 1000000.0f - 1.0f); }
static void test_seg_star(void) {
    static sn_q SA[6 * SEG_W], SB[6 * SEG_W], SP[6 * SEG_W], SQ[6 * SEG_W], SQ0[6 * SEG_W];
    seg_ctx C;
    seg_lvl L;
    int t, bad = 0, bad_pair = 0, bad_pins = 0;
    unsigned long sats = 0;
    memset(&C, 0, sizeof C);
    memset(&L, 0, sizeof L);
    for (t = 0; t < 20000; t++) {
        const unsigned k = 3u + (unsigned)(t & 1);
        uint32_t seg[5], perm[6] = {0, 1, 2, 3, 4, 5}, sa = 0, sb = 0, pa = 0, pb = 0, j, w;
        int sgn[5];
        float rf = (float)(rnd32() % 1001u) / 1000.0f;
        for (j = 5; j > 0; j--) { /* distinct segments in a random order */
            const uint32_t r = rnd32() % (j + 1u), x = perm[j];
            perm[j] = perm[r]; perm[r] = x;
        }
        for (j = 0; j < 5; j++) seg[j] = perm[j];
        for (j = 0; j < 5; j++) sgn[j] = rnd32() & 1 ? 1 : -1;
        L.l = (unsigned)(t >> 1 & 1);
        L.half = 0.05f + (float)(rnd32() % 1000u) / 1000.0f;
        C.rf1 = rf;
        C.kf1 = rf * (1.0f / L.half) * (t % 16 == 3 ? 40.0f : 1.0f);
        C.g1n = (float)(rnd32() % 1001u) / 500.0f;
        for (j = 0; j < 6; j++) {
            sn_q *S = SA + SEG_W * j;
            const int edge = rnd32() % 8u == 0;
            float n2;
            for (w = 0; w < 3; w++) S[w] = edge ? (rnd32() & 1 ? 1.0f : -1.0f) * (SN_FLIM - 0.5f) : rnd_f(8.0f);
            do {
                for (w = 3; w < 6; w++) S[w] = rnd_f(1.0f);
                n2 = S[3] * S[3] + S[4] * S[4] + S[5] * S[5];
            } while (n2 < 0.01f);
            for (w = 3; w < 6; w++) S[w] /= sqrtf(n2);
            if (rnd32() % 16u == 0) S[rnd32() % 6u] = -0.0f;
            for (w = 6; w < SEG_W; w++) S[w] = 0.0f;
            S[12] = edge ? 3.0f : 0.05f + (float)(rnd32() % 1000u) / 1000.0f;
            S[13] = 1.0f / S[12];
        }
        if (t % 64 == 5) SA[SEG_W * seg[0]] = NAN;
        if (t % 64 == 21) SA[SEG_W * seg[1] + 4] = NAN; /* a NaN direction: NaN reaches the turn limiter */
        C.rf2 = 0.5f * rf;
        C.kf0 = 0.5f * C.kf1;
        C.gh = (float)(rnd32() % 1001u) / 1000.0f;
        memcpy(SB, SA, sizeof SA);
        memcpy(SP, SA, sizeof SA);
        memcpy(SQ, SA, sizeof SA);
        memcpy(SQ0, SA, sizeof SA);
        L.S = SA;
        seg_star_test(&C, &L, seg, sgn, k, 0, &sa);
        L.S = SB;
        seg_star_test(&C, &L, seg, sgn, k, 1, &sb);
        bad += memcmp(SA, SB, sizeof SA) != 0 || sa != sb;
        sats += sa;
        L.S = SP; /* a pair of the first two ends */
        seg_pair_test(&C, &L, seg[0], sgn[0], seg[1], sgn[1], 0, &pa);
        L.S = SQ;
        seg_pair_test(&C, &L, seg[0], sgn[0], seg[1], sgn[1], 1, &pb);
        bad_pair += memcmp(SP, SQ, sizeof SP) != 0 || pa != pb;
        sats += pa;
        {   /* an attachment's pins on 2..4 of the ends (the target: every 8th
             * beyond SN_FLIM, every 64th NaN) */
            const unsigned kp = 2u + (unsigned)(t >> 2) % 3u;
            sn_q T[3];
            for (j = 0; j < 3; j++) T[j] = t % 8 == 6 ? rnd_f(2.0f * SN_FLIM) : rnd_f(8.0f);
            if (t % 64 == 9) T[1] = NAN;
            memcpy(SP, SQ0, sizeof SP);
            memcpy(SQ, SQ0, sizeof SQ);
            pa = pb = 0;
            L.S = SP;
            seg_pins_test(&C, &L, seg, sgn, kp, T, 0, &pa);
            L.S = SQ;
            seg_pins_test(&C, &L, seg, sgn, kp, T, 1, &pb);
            bad_pins += memcmp(SP, SQ, sizeof SP) != 0 || pa != pb;
            sats += pa;
        }
    }
    T_CHECK(bad_pins == 0, "float pins (path %s): %d of 20000 attachments differ from pin() (state or counts)",
            sn_kernels_name(), bad_pins);
    T_CHECK(bad == 0, "float star (path %s): %d of 20000 nodes differ from star() (state or counts)", sn_kernels_name(), bad);
    T_CHECK(bad_pair == 0, "float pair (path %s): %d of 20000 pairs differ from pair() (state or counts)", sn_kernels_name(),
            bad_pair);
    T_FIGURE("float star: 20000 random nodes, %lu clamps and NaN replacements counted", sats);
}
#endif

#if !defined(SN_FLOAT)
/* ---- the fixed star projection of a sheet node and the pair (sn_segment_sweep.c): the
 * step's forms (x86-64 AVX2: seg_star_iv, seg_pair_iv, the ends in int64 lanes) against
 * star() and pair_core() bit for bit with the saturation counts (on paths
 * without them the scalar against itself: the test still runs). 40000 random nodes of 3 or 4
 * ends (distinct segments of 6, random signs), on level 0 (one half length
 * 2^8..2^26, its reciprocal, shift and turn factors as seg_level and
 * seg_sweep_prep form them) and on a coarse level (each segment's own half
 * 1..2^27.8 with its reciprocal and shift 0..27, words 12-14), omega
 * (1-gamma) and omega gamma over their whole ranges; centres within the
 * state bound, every 8th segment at +-SN_LIM (the mean, the gaps and G + t
 * clamp), unit directions in Q30 with |u| in [0.987, 1] (the bound every
 * write of u keeps; every 8th (1/2, 1/2, 1/sqrt 2): the end offsets'
 * rounding ties); short halves and long gaps drive the turn limiter.
 * Tolerance 0. */
static void seg_recip_t(sn_q x, sn_q *r, sn_q *sh) { /* sn_segment_mesh.c recip(): 2^(29+b)/x, b - 1 */
    int b = 0;
    while (b < 32 && ((uint64_t)x >> b) != 0) b++;
    *r = (sn_q)(((uint64_t)1 << (29 + b)) / (uint64_t)x);
    *sh = b - 1;
}
static sn_q seg_half_t(int lo, int hi) { /* 2^lo..2^hi, log-uniform */
    const int b = lo + (int)(rnd32() % (unsigned)(hi - lo + 1));
    const sn_q x = (sn_q)(((int64_t)1 << b) + (int64_t)(rnd32() % (1u << b)));
    return x < 1 ? 1 : x;
}
/* the move itself (sn_segment_sweep.c move_seg: Cortex-M4 its turn in
 * Thumb-2, turn_m4) against the portable C (move_seg_c), bit for bit with
 * the counts: 60000 random moves, gaps within the state bound (every 8th at
 * +-SN_LIM), translations up to 2^29, unit directions (|u| in [0.987, 1]),
 * turn factors up to +-2^30 at random magnitudes and shifts 0..29 (the
 * limiter's both sides and its edge), centres up to the bound. Tolerance 0. */
static void test_seg_move(void) {
    int t, bad = 0;
    unsigned long sats = 0;
    for (t = 0; t < 60000; t++) {
        sn_q A[SEG_W], B[SEG_W], d[3], tt[3];
        const int sh = (int)(rnd32() % 30u), mb = (int)(rnd32() % 31u);
        const sn_q kf = (sn_q)((int64_t)rnd_in(1 << 30) >> (30 - mb));
        uint32_t sa = 0, sb = 0, w;
        double v[3], n2;
        const double len = 1.0 - (rnd32() % 1000u) * 1.2e-5;
        do {
            for (w = 0; w < 3; w++) v[w] = (double)rnd_in(1 << 20);
            n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        } while (n2 < 1e10);
        for (w = 0; w < SEG_W; w++) A[w] = (sn_q)rnd32();
        for (w = 0; w < 3; w++) {
            A[w] = rnd32() % 8u == 0 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
            A[3 + w] = (sn_q)floor(v[w] / sqrt(n2) * len * 1073741824.0 + 0.5);
            d[w] = rnd32() % 8u == 0 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM) >> (rnd32() % 20u);
            tt[w] = rnd_in(2 * SN_LIM);
        }
        memcpy(B, A, sizeof A);
        seg_move_test(A, d, tt, kf, sh, 0, &sa);
        seg_move_test(B, d, tt, kf, sh, 1, &sb);
        bad += memcmp(A, B, sizeof A) != 0 || sa != sb;
        sats += sa;
    }
    T_CHECK(bad == 0, "segment move (path %s): %d of 60000 moves differ from move_seg_c (state or counts)", sn_kernels_name(), bad);
    T_FIGURE("segment move: 60000 random moves, %lu clamps counted", sats);
}
static void test_seg_star_fixed(void) {
    static sn_q SA[6 * SEG_W], SB[6 * SEG_W], SP[6 * SEG_W], SQ[6 * SEG_W], SQ0[6 * SEG_W];
    seg_ctx C;
    seg_lvl L;
    int t, bad = 0, bad_pair = 0, bad_pins = 0;
    unsigned long sats = 0;
    memset(&C, 0, sizeof C);
    memset(&L, 0, sizeof L);
    for (t = 0; t < 40000; t++) {
        const unsigned k = 3u + (unsigned)(t & 1);
        uint32_t seg[5], perm[6] = {0, 1, 2, 3, 4, 5}, sa = 0, sb = 0, pa = 0, pb = 0, j, w;
        int sgn[5];
        sn_q rh, sh;
        for (j = 5; j > 0; j--) { /* distinct segments in a random order */
            const uint32_t r = rnd32() % (j + 1u), x = perm[j];
            perm[j] = perm[r]; perm[r] = x;
        }
        for (j = 0; j < 5; j++) seg[j] = perm[j];
        for (j = 0; j < 5; j++) sgn[j] = rnd32() & 1 ? 1 : -1;
        L.l = (unsigned)(t >> 1 & 1);
        L.half = seg_half_t(8, 26);
        seg_recip_t(L.half, &rh, &sh);
        L.rh = rh;
        L.sh = (int)sh;
        /* omega (1-gamma) <= 2^30, omega gamma < 2^31 (sn_segment.c) */
        C.rf1 = (sn_q)(rnd32() % ((1u << 30) + 1u));
        C.g1n = (seg_n)(rnd32() & 0x7FFFFFFFu);
        C.kf1 = (seg_n)(((int64_t)C.rf1 * rh + ((int64_t)1 << 29)) >> 30);
        C.bias0 = ((sn_acc)1 << sh) >> 1;
        for (j = 0; j < 6; j++) {
            sn_q *S = SA + SEG_W * j;
            const int edge = rnd32() % 8u == 0;
            double v[3], n2;
            const double len = 1.0 - (rnd32() % 1000u) * 1.2e-5;
            for (w = 0; w < 3; w++) S[w] = edge ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
            do {
                for (w = 0; w < 3; w++) v[w] = (double)rnd_in(1 << 20);
                n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            } while (n2 < 1e10);
            for (w = 0; w < 3; w++) S[3 + w] = (sn_q)floor(v[w] / sqrt(n2) * len * 1073741824.0 + 0.5);
            if (rnd32() % 8u == 1) { /* (+-1/2, +-1/2, +-1/sqrt 2) permuted: an odd half's h u_k/2^30 is a tie */
                const uint32_t r = rnd32() % 3u;
                for (w = 0; w < 3; w++)
                    S[3 + w] = (rnd32() & 1 ? 1 : -1) * (w == r ? 759250125 : (1 << 29));
            }
            for (w = 6; w < SEG_W; w++) S[w] = (sn_q)rnd32(); /* not read but 12-14 on a coarse level */
            S[12] = seg_half_t(0, 27);
            seg_recip_t(S[12], &S[13], &S[14]);
        }
        C.rf2 = C.rf1 >> 1;
        C.gh = (sn_q)(rnd32() % (1u << 30));
        C.kf0 = (seg_n)(((int64_t)C.rf2 * rh + ((int64_t)1 << 29)) >> 30);
        memcpy(SB, SA, sizeof SA);
        memcpy(SP, SA, sizeof SA);
        memcpy(SQ, SA, sizeof SA);
        memcpy(SQ0, SA, sizeof SA);
        L.S = SA;
        seg_star_test(&C, &L, seg, sgn, k, 0, &sa);
        L.S = SB;
        seg_star_test(&C, &L, seg, sgn, k, 1, &sb);
        L.S = SP; /* a pair of the first two ends */
        seg_pair_test(&C, &L, seg[0], sgn[0], seg[1], sgn[1], 0, &pa);
        L.S = SQ;
        seg_pair_test(&C, &L, seg[0], sgn[0], seg[1], sgn[1], 1, &pb);
        bad_pair += memcmp(SP, SQ, sizeof SP) != 0 || pa != pb;
        sats += pa;
        {   /* an attachment's pins on 2..4 of the ends, the target within the
             * state bound, at it, or (every 8th) beyond (the gap's clamp) */
            const unsigned kp = 2u + (unsigned)(t >> 2) % 3u;
            sn_q T[3];
            for (j = 0; j < 3; j++)
                T[j] = t % 8 == 6 ? rnd_in(1 << 30) : (rnd32() % 16u == 0 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM));
            memcpy(SP, SQ0, sizeof SP);
            memcpy(SQ, SQ0, sizeof SQ);
            pa = pb = 0;
            L.S = SP;
            seg_pins_test(&C, &L, seg, sgn, kp, T, 0, &pa);
            L.S = SQ;
            seg_pins_test(&C, &L, seg, sgn, kp, T, 1, &pb);
            bad_pins += memcmp(SP, SQ, sizeof SP) != 0 || pa != pb;
            sats += pa;
        }
        if (memcmp(SA, SB, sizeof SA) != 0 || sa != sb) {
            if (bad < 3) {
                for (j = 0; j < 6 * SEG_W; j++)
                    if (SA[j] != SB[j]) printf("  star node %d (k %u, l %u): word %u of segment %u: %ld vs %ld\n", t, k, L.l,
                                               (unsigned)(j % SEG_W), (unsigned)(j / SEG_W), (long)SA[j], (long)SB[j]);
                printf("  counts %u vs %u\n", (unsigned)sa, (unsigned)sb);
            }
            bad++;
        }
        sats += sa;
    }
    T_CHECK(bad == 0, "fixed star (path %s): %d of 40000 nodes differ from star() (state or counts)", sn_kernels_name(), bad);
    T_CHECK(bad_pair == 0, "fixed pair (path %s): %d of 40000 pairs differ from pair() (state or counts)", sn_kernels_name(),
            bad_pair);
    T_CHECK(bad_pins == 0, "fixed pins (path %s): %d of 40000 attachments differ from pin() (state or counts)",
            sn_kernels_name(), bad_pins);
    T_FIGURE("fixed star, pair, pins: 40000 random nodes, pairs and attachments, %lu clamps counted", sats);
}
/* A level-0 sheet's sweep over its nodes (sn_segment_sweep.c): the step's
 * (Cortex-M4: sheet_m4, each row's interior run without sheet_ends,
 * sn_m4_star / sn_m4_pair called directly) against the node loop
 * (node_proj per node), bit for bit with the clamp counts: 300 random sheets
 * of side 3..8 in both directions, segments as test_seg_star_fixed's (centres
 * within the state bound, every 8th at +-SN_LIM; unit directions), one half
 * length 2^8..2^26 with its reciprocal, shift and turn factors. Tolerance 0. */
static void test_seg_sheet(void) {
    static sn_q SA[2 * 8 * 7 * SEG_W], SB[2 * 8 * 7 * SEG_W];
    seg_ctx C;
    seg_lvl L;
    int t, bad = 0;
    unsigned long sats = 0;
    memset(&C, 0, sizeof C);
    memset(&L, 0, sizeof L);
    for (t = 0; t < 300; t++) {
        const uint32_t sd = 3u + rnd32() % 6u, ns = 2u * sd * (sd - 1u);
        uint32_t sa = 0, sb = 0, i, w;
        sn_q rh, sh;
        L.kind = SN_SEG_SHEET;
        L.side = sd;
        L.ns = ns;
        L.nn = sd * sd;
        L.l = 0;
        L.half = seg_half_t(8, 26);
        seg_recip_t(L.half, &rh, &sh);
        L.rh = rh;
        L.sh = (int)sh;
        C.rf1 = (sn_q)(rnd32() % ((1u << 30) + 1u));
        C.rf2 = C.rf1 >> 1;
        C.g1n = (seg_n)(rnd32() & 0x7FFFFFFFu);
        C.gh = (sn_q)(rnd32() % (1u << 30));
        C.kf1 = (seg_n)(((int64_t)C.rf1 * rh + ((int64_t)1 << 29)) >> 30);
        C.kf0 = (seg_n)(((int64_t)C.rf2 * rh + ((int64_t)1 << 29)) >> 30);
        C.bias0 = ((sn_acc)1 << sh) >> 1;
        for (i = 0; i < ns; i++) {
            sn_q *S = SA + SEG_W * i;
            const int edge = rnd32() % 8u == 0;
            double v[3], n2;
            const double len = 1.0 - (rnd32() % 1000u) * 1.2e-5;
            for (w = 0; w < 3; w++) S[w] = edge ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
            do {
                for (w = 0; w < 3; w++) v[w] = (double)rnd_in(1 << 20);
                n2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
            } while (n2 < 1e10);
            for (w = 0; w < 3; w++) S[3 + w] = (sn_q)floor(v[w] / sqrt(n2) * len * 1073741824.0 + 0.5);
            for (w = 6; w < SEG_W; w++) S[w] = (sn_q)rnd32();
        }
        memcpy(SB, SA, ns * SEG_W * sizeof SA[0]);
        L.S = SA;
        seg_sheet_test(&C, &L, (unsigned)t & 1u, 0, &sa);
        L.S = SB;
        seg_sheet_test(&C, &L, (unsigned)t & 1u, 1, &sb);
        bad += memcmp(SA, SB, ns * SEG_W * sizeof SA[0]) != 0 || sa != sb;
        sats += sa;
    }
    T_CHECK(bad == 0, "fixed sheet sweep (path %s): %d of 300 sheets differ from the node loop (state or counts)",
            sn_kernels_name(), bad);
    T_FIGURE("fixed sheet sweep: 300 random sheets of side 3..8, %lu clamps counted", sats);
}
#endif

/* ---- the loop helpers of sn_kernels_rot.h (sn_k_sub3, sn_k_sub3a,
 * sn_k_add3, sn_k_coef3, sn_k_sub3r, sn_k_sym_out, sn_k_out_rot_acc, sn_k_outv, sn_k_mix) against the
 * formulas written here with sn_out/sn_add/sn_mul (sn_internal.h, the
 * reference arithmetic): bit for bit with the same clamp counts. Float:
 * values past SN_FLIM and NaNs included (every path must clamp and count
 * them alike); fixed: values up to the state bound, accumulators up to
 * +-(2^62 + 2^30), shifts -14..61. */
static sn_q rnd_val(int wild) {
#if defined(SN_FLOAT)
    if (wild && rnd32() % 16u == 0) return nanf("");
    return (float)rnd_in(1 << 20) * (wild ? 0.01f : 0.001f);
#else
    return wild ? rnd_in(1 << 28) : rnd_in(1 << 24);
#endif
}
static sn_acc rnd_acc(int wild) {
#if defined(SN_FLOAT)
    return rnd_val(wild);
#else
    /* every 8th wild accumulator near +-2^62 (sn_out's contract: < 2^62.5) */
    if (wild && rnd32() % 8u == 0) return (rnd32() & 1 ? 1 : -1) * (((int64_t)1 << 62) + rnd_in(1 << 30));
    return (int64_t)rnd_in(1 << 30) * (wild ? (1 << 26) : (1 << 12));
#endif
}
/* sn_k_sub3, sn_k_add3 and sn_k_sub3a against sn_add / sn_out, bit for bit
 * with the same clamp counts: the number of results or counts off (0..3) */
static int vec3_off(const sn_q x[3], const sn_q y[3], const sn_acc ya[3]) {
    sn_q o1[3], o2[3];
    uint32_t s1 = 0, s2 = 0, k;
    int bad = 0;
    sn_k_sub3(x, y, o1, &s1);
    for (k = 0; k < 3; k++) o2[k] = sn_add(x[k], -y[k], &s2);
    bad += memcmp(o1, o2, sizeof o1) != 0 || s1 != s2;
    sn_k_add3(x, y, o1, &s1);
    for (k = 0; k < 3; k++) o2[k] = sn_add(x[k], y[k], &s2);
    bad += memcmp(o1, o2, sizeof o1) != 0 || s1 != s2;
    memcpy(o1, x, sizeof o1);
    sn_k_sub3a(o1, ya, &s1);
    for (k = 0; k < 3; k++) o2[k] = sn_out((sn_acc)x[k] - ya[k], 0, &s2);
    bad += memcmp(o1, o2, sizeof o1) != 0 || s1 != s2;
    return bad;
}
static void test_loops(void) {
    int t, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 4000; t++) {
#if defined(SN_FLOAT)
        int wild = t % 4 == 0, sh = (int)(rnd32() % 31u), k;
#else /* shifts -14..50: below 0 sn_out does not shift (the mix adds 8..11, up to 61) */
        int wild = t % 4 == 0, sh = (int)(rnd32() % 65u) - 14, k;
#endif
        sn_q x[3], y[3], o1[3], o2[3], R[9], q1[40], q2[40], ck = rnd_val(0), cm = rnd_val(0);
        sn_acc ya[3], a1[3], a2[3], l[3], in[40];
        sn_q Dw[6]; /* sn_k_sym_out's block 4-aligned, as the PRECOND section's (the M4's LDM) */
        unsigned char *D = (unsigned char *)Dw;
        uint8_t kk[14];
        uint32_t s1 = 0, s2 = 0, n = rnd32() % 41u, i;
#if defined(SN_FLOAT)
        ck *= 0.001f; /* |q ck| mostly inside SN_FLIM */
        cm *= 0.001f;
#endif
        for (k = 0; k < 3; k++) { x[k] = rnd_val(wild); y[k] = rnd_val(wild); ya[k] = rnd_acc(wild); l[k] = rnd_acc(wild); a1[k] = a2[k] = rnd_acc(0); }
        for (k = 0; k < 9; k++) R[k] = rnd_val(0);
        for (k = 0; k < 6; k++) {
            sn_q d = rnd_val(0);
            memcpy(D + 4 * k, &d, 4); /* little-endian hosts (the SIMD paths') */
        }
        for (k = 0; k < 14; k++) kk[k] = (uint8_t)(rnd32() % 4u);
        for (i = 0; i < n; i++) { in[i] = rnd_acc(wild); q1[i] = q2[i] = rnd_val(wild); }
        bad += vec3_off(x, y, ya);
        sn_k_coef3(x, ck, o1, &s1);
        for (k = 0; k < 3; k++) o2[k] = sn_mulq(x[k], ck, SN_Q_COEF, &s2);
        bad += memcmp(o1, o2, sizeof o1) != 0 || s1 != s2;
        {
            unsigned char sec[24];
            memcpy(sec, x, 12); /* little-endian hosts (the SIMD paths') */
            memcpy(sec + 12, y, 12);
            sn_k_sub3r(sec, 0, 3, o1, &s1);
            for (k = 0; k < 3; k++) o2[k] = sn_add(rd_real(sec, (uint32_t)k), -rd_real(sec, 3u + (uint32_t)k), &s2);
            bad += memcmp(o1, o2, sizeof o1) != 0 || s1 != s2;
        }
        sn_k_sym_out(D, x, o1, sh, &s1);
        {
            sn_q xx = rd_real(D, 0), yy = rd_real(D, 1), zz = rd_real(D, 2), xy = rd_real(D, 3), xz = rd_real(D, 4), yz = rd_real(D, 5);
            sn_acc m[3] = {0, 0, 0};
            m[0] += sn_mul(xx, x[0]) + sn_mul(xy, x[1]) + sn_mul(xz, x[2]);
            m[1] += sn_mul(xy, x[0]) + sn_mul(yy, x[1]) + sn_mul(yz, x[2]);
            m[2] += sn_mul(xz, x[0]) + sn_mul(yz, x[1]) + sn_mul(zz, x[2]);
            for (k = 0; k < 3; k++) o2[k] = sn_out(m[k], sh, &s2);
        }
        bad += (memcmp(o1, o2, sizeof o1) != 0 && x[0] == x[0] && x[1] == x[1] && x[2] == x[2]) || s1 != s2;
        sn_k_out_rot_acc(a1, R, l, sh, &s1);
        for (k = 0; k < 3; k++) o2[k] = sn_out(l[k], sh, &s2);
        sn_rot_acc(a2, R, o2);
        bad += memcmp(a1, a2, sizeof a1) != 0 || s1 != s2;
        sn_k_outv(q1, in, n, sh, &s1);
        for (i = 0; i < n; i++) q2[i] = sn_out(in[i], sh, &s2);
        bad += memcmp(q1, q2, n * sizeof q1[0]) != 0 || s1 != s2;
        for (i = 0; i < n; i++) q1[i] = q2[i] = rnd_val(wild);
        n -= n % 3; /* the mat-vec's 3 nF values */
        sn_k_mix(q1, in, kk, n, sh + 8, ck, cm, &s1);
        for (i = 0; i < n; i++) {
            sn_q mk = sn_out(in[i], sh + 8 - SN_KREL(kk[i / 3]), &s2);
            sn_acc m = sn_mul(q2[i], ck) + sn_mul(mk, cm);
            q2[i] = sn_out(m, SN_Q_COEF, &s2);
        }
        bad += memcmp(q1, q2, n * sizeof q1[0]) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "loop helpers (path %s): %d of 36000 results or clamp counts off the reference formulas", sn_kernels_name(), bad);
    T_FIGURE("loop helpers: 4000 random cases of each (every 4th with clamps%s), %u clamps", SN_FLAVOUR ? " and NaNs" : "", (unsigned)clamps);
}

#if !defined(SN_FLOAT)
/* The rounding-and-clamp helpers at their edges (every path; on the M4 they
 * run sn_k_out_w / sn_k_out_hw, "M4 round 3"): accumulators l = v 2^s + d
 * with v at 0, +-1, +-(SN_LIM - 1), +-SN_LIM, +-(SN_LIM + 1), +-2^30 and d at
 * 0, +-1, +-2^(s-1) and its neighbours (the rounding's ties), plus +-(2^62 -
 * 1) and random values, for every shift 0..62: sn_k_out_rot_acc, sn_k_outv,
 * sn_k_mix, sn_k_mul_out against sn_out (sn_internal.h, the reference),
 * bit for bit with the same clamp counts; on the M4 sn_k_out_w (s < 32) and
 * sn_k_out_hw (32..62) themselves too; sn_k_sym_out's first row at the
 * same edges for s = 1..31. */
static int edge_ls(int s, sn_acc *l) {
    static const int32_t vs[] = {0, 1, -1, SN_LIM - 1, -(SN_LIM - 1), SN_LIM, -SN_LIM, SN_LIM + 1, -(SN_LIM + 1),
                                 1 << 30, -(1 << 30)};
    const int64_t h = s > 0 ? (int64_t)1 << (s - 1) : 0;
    const int64_t ds[] = {0, 1, -1, h, -h, h - 1, -h - 1, h + 1, -h + 1};
    int n = 0;
    uint32_t a, b;
    for (a = 0; a < sizeof vs / sizeof vs[0]; a++) {
        const int64_t v = vs[a];
        if ((v < 0 ? -v : v) >= ((int64_t)1 << (62 - s))) continue; /* |v 2^s| < 2^62 */
        for (b = 0; b < sizeof ds / sizeof ds[0]; b++) l[n++] = v * ((int64_t)1 << s) + ds[b];
    }
    l[n++] = ((int64_t)1 << 62) - 1;
    l[n++] = -(((int64_t)1 << 62) - 1);
    for (a = 0; a < 6; a++) l[n++] = (int64_t)rnd_in(1 << 30) * ((int64_t)1 << (rnd32() % 32u));
    return n;
}
static void test_out_edges(void) {
    int s, bad = 0, cases = 0;
    uint32_t clamps = 0;
    for (s = 0; s <= 62; s++) {
        sn_acc l[128];
        const int n = edge_ls(s, l);
        int i, k;
        for (i = 0; i < n; i++) {
            sn_q R[9], q1[3], q2[3], ck = rnd_in(1 << 24), cm = rnd_in(1 << 24);
            sn_acc a1[3], a2[3], lv[3] = {l[i], l[(i + 1) % n], l[(i + 7) % n]};
            uint8_t kk[1] = {(uint8_t)(rnd32() % 4u)};
            uint32_t s1 = 0, s2 = 0;
            for (k = 0; k < 9; k++) R[k] = rnd_in(1 << 30);
            for (k = 0; k < 3; k++) a1[k] = a2[k] = (int64_t)rnd_in(1 << 30) << 20;
            sn_k_out_rot_acc(a1, R, lv, s, &s1);
            for (k = 0; k < 3; k++) q2[k] = sn_out(lv[k], s, &s2);
            sn_rot_acc(a2, R, q2);
            bad += memcmp(a1, a2, sizeof a1) != 0 || s1 != s2;
            sn_k_outv(q1, lv, 3, s, &s1);
            for (k = 0; k < 3; k++) q2[k] = sn_out(lv[k], s, &s2);
            bad += memcmp(q1, q2, sizeof q1) != 0 || s1 != s2;
            bad += sn_k_mul_out(ck, lv[0], s, &s1) != sn_mul(ck, sn_out(lv[0], s, &s2)) || s1 != s2;
            if (s >= SN_KREL(kk[0])) {
                const int fm = s + SN_KREL(kk[0]);
                for (k = 0; k < 3; k++) q1[k] = q2[k] = rnd_in(SN_LIM);
                sn_k_mix(q1, lv, kk, 3, fm, ck, cm, &s1);
                for (k = 0; k < 3; k++) q2[k] = sn_out(sn_mul(q2[k], ck) + sn_mul(sn_out(lv[k], s, &s2), cm), SN_Q_COEF, &s2);
                bad += memcmp(q1, q2, sizeof q1) != 0 || s1 != s2;
                {   /* the second rounding at its edges (q ck >> 24 = q at ck = 2^24,
                     * mk cm a small offset or a tie): sn_k_mix's v = +-SN_LIM exactly
                     * and its neighbours (the M4's test on the high word) */
                    static const int32_t vq[] = {0, 1, -1, SN_LIM - 1, -(SN_LIM - 1), SN_LIM, -SN_LIM, SN_LIM + 1,
                                                 -(SN_LIM + 1), 1 << 30, -(1 << 30), INT32_MAX, -INT32_MAX};
                    static const int32_t vm[] = {0, 1, -1, 1 << 23, -(1 << 23)};
                    const uint32_t a = (uint32_t)i % 13u, b = rnd32() % 5u;
                    for (k = 0; k < 3; k++) q1[k] = q2[k] = vq[(a + (uint32_t)k * 5u) % 13u];
                    sn_k_mix(q1, lv, kk, 3, fm, 1 << 24, vm[b], &s1);
                    for (k = 0; k < 3; k++)
                        q2[k] = sn_out(sn_mul(q2[k], 1 << 24) + sn_mul(sn_out(lv[k], s, &s2), vm[b]), SN_Q_COEF, &s2);
                    bad += memcmp(q1, q2, sizeof q1) != 0 || s1 != s2;
                }
            }
#if defined(SN_KERNELS_M4)
            if (s > 0 && s < 32) bad += sn_k_out_w(l[i], s, (uint32_t)1 << (s - 1), &s1) != sn_out(l[i], s, &s2) || s1 != s2;
            if (s >= 32) bad += sn_k_out_hw(l[i], s, s == 32 ? (uint32_t)1 << 31 : 0, s == 32 ? 0 : (int32_t)1 << (s - 33), &s1) !=
                                    sn_out(l[i], s, &s2) || s1 != s2;
#endif
            clamps += s2;
            cases++;
        }
    }
    /* sn_k_sym_out (the M4's sn_m4_sym_out for 0 < s < 32) with its first
     * row's sum at the same edges: xx = 2^(s-1), e0 = 2v, xy = 1, e1 = d,
     * xz = 0 give l0 = v 2^s + d exactly; the other rows random */
    for (s = 1; s <= 31; s++) {
        static const int32_t vs[] = {0, 1, -1, SN_LIM - 1, -(SN_LIM - 1), SN_LIM, -SN_LIM, SN_LIM + 1, -(SN_LIM + 1)};
        const int32_t h = (int32_t)((uint32_t)1 << (s - 1));
        const int32_t ds[] = {0, 1, -1, h, -h, h - 1, -h - 1, h + 1, -h + 1};
        uint32_t a, b;
        for (a = 0; a < sizeof vs / sizeof vs[0]; a++)
            for (b = 0; b < sizeof ds / sizeof ds[0]; b++) {
                sn_q D[6] = {h, rnd_in(1 << 30), rnd_in(1 << 30), 1, 0, rnd_in(1 << 30)}, e[3] = {2 * vs[a], ds[b], rnd_in(1 << 30)};
                sn_q o1[3], o2[3];
                sn_acc m[3];
                uint32_t s1 = 0, s2 = 0, k;
                sn_k_sym_out((const unsigned char *)D, e, o1, s, &s1);
                m[0] = sn_mul(D[0], e[0]) + sn_mul(D[3], e[1]) + sn_mul(D[4], e[2]);
                m[1] = sn_mul(D[3], e[0]) + sn_mul(D[1], e[1]) + sn_mul(D[5], e[2]);
                m[2] = sn_mul(D[4], e[0]) + sn_mul(D[5], e[1]) + sn_mul(D[2], e[2]);
                for (k = 0; k < 3; k++) o2[k] = sn_out(m[k], s, &s2);
                bad += memcmp(o1, o2, sizeof o1) != 0 || s1 != s2 || m[0] != (int64_t)vs[a] * ((int64_t)1 << s) + ds[b];
                clamps += s2;
                cases++;
            }
    }
    T_CHECK(bad == 0, "rounding helpers at their edges (path %s): %d results or clamp counts off sn_out", sn_kernels_name(), bad);
    T_FIGURE("rounding helpers: %d edge accumulators over shifts 0..62, %u clamps", cases, (unsigned)clamps);
}
#endif

#if !defined(SN_FLOAT)
/* The 3-vector helpers at the clamp edges (sn_k_sub3, sn_k_sub3r, sn_k_add3,
 * sn_k_coef3, sn_k_sub3a; the M4 writes them out on QSUB/QADD, sn_k_out_w
 * and the two-word clamp, "M4 round 3"): every pair of values from an edge
 * set (0, +-1, +-SN_LIM and one past, +-2^30, INT32_MAX, INT32_MIN + 1)
 * against sn_add / sn_out, bit for bit with the same counts. */
static void test_vec_edges(void) {
    static const int32_t ev[] = {0, 1, -1, SN_LIM, -SN_LIM, SN_LIM + 1, -SN_LIM - 1, 1 << 30, -(1 << 30), INT32_MAX,
                                 INT32_MIN + 1};
    static const int64_t ea[] = {0, 1, -1, SN_LIM, -(int64_t)SN_LIM, SN_LIM + 1, -(int64_t)SN_LIM - 1,
                                 (int64_t)1 << 40, -((int64_t)1 << 40), ((int64_t)1 << 62) - ((int64_t)1 << 31),
                                 -((int64_t)1 << 62) + ((int64_t)1 << 31)};
    const uint32_t ne = sizeof ev / sizeof ev[0];
    uint32_t i, j, k, c;
    int bad = 0;
    for (i = 0; i < ne; i++)
        for (j = 0; j < ne; j++) {
            sn_q x[3], y[3], o1[3], o2[3];
            sn_acc ya[3];
            unsigned char sec[24];
            uint32_t s1 = 0, s2 = 0;
            for (k = 0; k < 3; k++) { x[k] = ev[(i + k) % ne]; y[k] = ev[(j + 2 * k) % ne]; ya[k] = ea[(j + k) % ne]; }
            bad += vec3_off(x, y, ya);
            for (k = 0; k < 3; k++) { put32(sec + 4 * k, (uint32_t)x[k]); put32(sec + 12 + 4 * k, (uint32_t)y[k]); }
            sn_k_sub3r(sec, 0, 3, o1, &s1);
            for (k = 0; k < 3; k++) o2[k] = sn_add(x[k], -y[k], &s2);
            bad += memcmp(o1, o2, sizeof o1) != 0 || s1 != s2;
            for (c = 0; c < ne; c++) {
                sn_k_coef3(x, ev[c], o1, &s1);
                for (k = 0; k < 3; k++) o2[k] = sn_out(sn_mul(x[k], ev[c]), SN_Q_COEF, &s2);
                bad += memcmp(o1, o2, sizeof o1) != 0 || s1 != s2;
            }
        }
    T_CHECK(bad == 0, "3-vector helpers at the clamp edges (path %s): %d results or counts off sn_add/sn_out", sn_kernels_name(), bad);
}

/* sn_qtomat and sn_qnormalize (sn_math.c; the M4 clamps in int32,
 * multiplies 32 x 32 and normalizes in 32-bit words, "M4 round 3")
 * against the portable formulas written here in int64 (qtomat: the clamp
 * to +-2^30, Q60 products, round by 2^29, clamp) and, for the unit vector,
 * the scaled magnitudes, the rounded root (a double estimate corrected to
 * floor(sqrt)) and r = (2^62 + N/2) / N by uint64 division: bit for bit,
 * on quaternions with components at +-2^30 and one past, INT32_MIN/MAX,
 * 0 and random widths. */
static int64_t ref_c30(int64_t v) { return v > (1 << 30) ? (1 << 30) : (v < -(1 << 30) ? -(1 << 30) : v); }
static void ref_qtomat(const sn_q q[4], sn_q R[9]) {
    const int64_t x = ref_c30(q[0]), y = ref_c30(q[1]), z = ref_c30(q[2]), w = ref_c30(q[3]), one = (int64_t)1 << 30;
    int64_t e[9];
    int k;
    e[0] = one - sn_rshr64(y * y + z * z, 29);
    e[1] = sn_rshr64(x * y - z * w, 29);
    e[2] = sn_rshr64(x * z + y * w, 29);
    e[3] = sn_rshr64(x * y + z * w, 29);
    e[4] = one - sn_rshr64(x * x + z * z, 29);
    e[5] = sn_rshr64(y * z - x * w, 29);
    e[6] = sn_rshr64(x * z - y * w, 29);
    e[7] = sn_rshr64(y * z + x * w, 29);
    e[8] = one - sn_rshr64(x * x + y * y, 29);
    for (k = 0; k < 9; k++) R[k] = (int32_t)ref_c30(e[k]);
}
static void ref_qnormalize(sn_q q[4]) {
    uint64_t a[4], m = 0, n2 = 0, N, r;
    int i, b = 0;
    for (i = 0; i < 4; i++) {
        a[i] = q[i] < 0 ? (uint64_t)0 - (uint64_t)(int64_t)q[i] : (uint64_t)q[i];
        if (a[i] > m) m = a[i];
    }
    if (m == 0) { q[0] = q[1] = q[2] = 0; q[3] = 1 << 30; return; }
    while (b < 64 && m >> b) b++;
    for (i = 0; i < 4; i++) {
        a[i] = b > 31 ? a[i] >> (b - 31) : a[i] << (31 - b);
        n2 += a[i] * a[i];
    }
    N = (uint64_t)sqrt((double)n2);
    while (N * N > n2) N--;
    while ((N + 1) * (N + 1) <= n2) N++;
    if (n2 - N * N > N) N++;
    if (N <= ((uint64_t)1 << 30)) r = (uint64_t)1 << 32;
    else if (N >= ((uint64_t)1 << 32)) r = (uint64_t)1 << 30;
    else r = (((uint64_t)1 << 62) + (N >> 1)) / N;
    for (i = 0; i < 4; i++) {
        const uint64_t v = (a[i] * r + ((uint64_t)1 << 31)) >> 32;
        q[i] = q[i] < 0 ? -(int32_t)v : (int32_t)v;
    }
}
static void test_quat_words(void) {
    static const int32_t eq[] = {0, 1, -1, 1 << 30, -(1 << 30), (1 << 30) + 1, -(1 << 30) - 1, INT32_MAX, INT32_MIN, 1 << 29,
                                 759250125, -759250125, 1 << 14, -(1 << 14), 3 << 14}; /* 2^14, 3 2^14: products at the rounding's ties */
    int t, bad_m = 0, bad_n = 0;
    for (t = 0; t < 6000; t++) {
        sn_q q[4], q1[4], q2[4], R1[9], R2[9];
        int k;
        for (k = 0; k < 4; k++)
            q[k] = t % 3 == 0 ? eq[rnd32() % (sizeof eq / sizeof eq[0])] : (int32_t)(rnd32() >> (rnd32() % 32u)) * (rnd32() & 1 ? 1 : -1);
        sn_qtomat(q, R1);
        ref_qtomat(q, R2);
        bad_m += memcmp(R1, R2, sizeof R1) != 0;
        memcpy(q1, q, sizeof q);
        memcpy(q2, q, sizeof q);
        sn_qnormalize(q1);
        ref_qnormalize(q2);
        bad_n += memcmp(q1, q2, sizeof q1) != 0;
    }
    T_CHECK(bad_m == 0, "sn_qtomat: %d of 6000 quaternions off the int64 formula", bad_m);
    T_CHECK(bad_n == 0, "sn_qnormalize: %d of 6000 quaternions off the portable unit-vector arithmetic", bad_n);
}
#endif

#if defined(SN_K_IC_VTX)
/* The M4's fused-sweep vertex steps (sn_kernels_m4_ic.c, Thumb-2) against
 * the portable reference written from sn_internal.h's sn_rot_t / sn_rot /
 * sn_out: y = sn_out(R^T r - acc, 0); w = sn_out(0 + D y, sh) (D symmetric,
 * stored xx yy zz xy xz yz), z' = sn_out(w - l, 0), z = R z'. Random R
 * entries within +-2^30, r / y within or at +-SN_LIM, D entries up to int32,
 * accumulators up to +-2^50 (every 4th case at the bounds: clamps on each
 * test), sh 1..31; y, z', z and the clamp count must match exactly. */
static void test_ic_vtx(void) {
    int t, bad_y = 0, bad_z = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 6000; t++) {
        const int wild = t % 4 == 0, sh = (int)(1u + rnd32() % 31u);
        sn_q R[9], r[3], y1[3], y2[3], z1[3], z2[3], zq1[3], zq2[3], w[3], D[6];
        sn_acc acc[3], l[3], d3[3];
        unsigned char P[24];
        uint32_t s1 = 0, s2 = 0;
        int k;
        for (k = 0; k < 9; k++) R[k] = wild && rnd32() % 2u ? (rnd32() % 2u ? (1 << 30) : -(1 << 30)) : rnd_in(1 << 30);
        for (k = 0; k < 6; k++) {
            D[k] = wild ? (sn_q)rnd32() : rnd_in(1 << 26);
            put32(P + 4 * k, (uint32_t)D[k]);
        }
        for (k = 0; k < 3; k++) {
            r[k] = wild && rnd32() % 2u ? (rnd32() % 2u ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
            acc[k] = (sn_acc)rnd_in(1 << 30) * ((sn_acc)1 << (wild ? 20 : rnd32() % 8u));
            l[k] = (sn_acc)rnd_in(1 << 30) * ((sn_acc)1 << (wild ? 20 : rnd32() % 8u));
        }
        sn_m4_icf_y(R, r, acc, y1, &s1);
        sn_rot_t(R, r, y2, &s2);
        for (k = 0; k < 3; k++) y2[k] = sn_out((sn_acc)y2[k] - acc[k], 0, &s2);
        bad_y += memcmp(y1, y2, sizeof y1) != 0 || s1 != s2;
        clamps += s2;
        s1 = s2 = 0;
        memcpy(z1, y2, sizeof z1);
        memcpy(z2, y2, sizeof z2);
        sn_m4_icb_z(P, z1, l, zq1, R, sh, &s1);
        d3[0] = sn_mul(D[0], z2[0]) + sn_mul(D[3], z2[1]) + sn_mul(D[4], z2[2]);
        d3[1] = sn_mul(D[3], z2[0]) + sn_mul(D[1], z2[1]) + sn_mul(D[5], z2[2]);
        d3[2] = sn_mul(D[4], z2[0]) + sn_mul(D[5], z2[1]) + sn_mul(D[2], z2[2]);
        for (k = 0; k < 3; k++) w[k] = sn_out(sn_out(d3[k], sh, &s2) - l[k], 0, &s2);
        memcpy(zq2, w, sizeof w);
        sn_rot(R, w, z2, &s2);
        bad_z += memcmp(z1, z2, sizeof z1) != 0 || memcmp(zq1, zq2, sizeof zq1) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad_y == 0, "M4 fused forward vertex step (sn_m4_icf_y): %d of 6000 off the reference", bad_y);
    T_CHECK(bad_z == 0, "M4 fused backward vertex step (sn_m4_icb_z): %d of 6000 off the reference", bad_z);
    T_CHECK(clamps > 1000, "the vertex steps' cases clamp (%lu clamps)", (unsigned long)clamps);
    T_FIGURE("M4 fused vertex steps: 6000 cases each, %lu clamps", (unsigned long)clamps);
}
#endif

#if defined(SN_K_IC_FWD_COL)
/* The M4's forward-sweep column (sn_k_ic_fwd_col: sn_m4_ic_cols and its
 * reference fallback) against ic_forward's loop on the portable reference
 * (sn_k_ic_col_ref per block, stopping at the first row >= nF): random
 * columns of 0..12 blocks, row indices sometimes past nF, vertex exponents
 * 0..3 and fracs 0..40 (shifts below 1 and past 31 included), y at the
 * state bound and INT32_MIN/MAX; the accumulators, the clamp count and the
 * blocks read must match exactly. */
static void test_ic_fwd(void) {
    static unsigned char L[12 * 20], cols[24];
    static sn_acc a1[90], a2[90];
    int t, bad = 0, odd = 0, stops = 0;
    for (t = 0; t < 3000; t++) {
        sn_q y[3];
        uint8_t kk[30];
        const uint32_t nF = 20u + rnd32() % 10u, nb = rnd32() % 13u;
        const int kj = (int)(rnd32() % 4u), wild = t % 8 == 0;
        uint32_t e, k, n1, n2 = 0, s1 = 0, s2 = 0;
        struct sn_m4_icc c;
        for (k = 0; k < 3; k++)
            y[k] = wild ? (t % 16 == 0 ? (rnd32() & 1 ? INT32_MAX : INT32_MIN) : (rnd32() & 1 ? SN_LIM : -SN_LIM)) : rnd_in(SN_LIM);
        for (k = 0; k < 30; k++) kk[k] = (uint8_t)(rnd32() % 4u);
        for (k = 0; k < 90; k++) a1[k] = a2[k] = (int64_t)rnd_in(1 << 30) << 12;
        for (e = 0; e < nb; e++) {
            unsigned char *b = L + 20 * e;
            const uint32_t row = rnd32() % 16u == 0 ? nF + rnd32() % 3u : rnd32() % nF;
            for (k = 0; k < 9; k++) {
                const int32_t m = wild ? (rnd32() & 1 ? 32767 : -32767) : rnd_in(32767);
                const uint16_t u = (uint16_t)(m < 0 ? m + 65536 : m);
                b[2 * k] = (unsigned char)u;
                b[2 * k + 1] = (unsigned char)(u >> 8);
            }
            b[18] = (unsigned char)(rnd32() % 8u == 0 ? rnd32() % 41u : 1u + rnd32() % 28u);
            b[19] = 0;
            cols[2 * e] = (unsigned char)row;
            cols[2 * e + 1] = 0;
        }
        sn_k_ic_fwd_init(&c, kk, a1, nF);
        n1 = nb ? sn_k_ic_fwd_col(&c, L, cols, cols + 2 * nb, y, kj, &s1) : 0;
        for (e = 0; e < nb; e++) {
            const uint32_t i = cols[2 * e];
            int s;
            if (i >= nF) { stops++; break; }
            s = (int)L[20 * e + 18] + kj - (int)kk[i];
            odd += s <= 0 || s >= 32;
            sn_k_ic_col_ref(L + 20 * e, y, s, a2 + 3 * i, &s2);
            n2++;
        }
        bad += memcmp(a1, a2, sizeof a1) != 0 || s1 != s2 || n1 != n2;
    }
    T_CHECK(bad == 0, "IC(0) forward columns (path %s): %d of 3000 columns differ from the reference loop", sn_kernels_name(), bad);
    T_FIGURE("IC(0) forward columns: 3000 columns of 0..12 blocks, %d blocks with shift outside 1..31, %d stopped at a row >= nF", odd, stops);
}
#endif

#if defined(SN_K_IC_FWD_RUN)
/* x86-64's forward-sweep column (sn_k_ic_fwd_run) against ic_forward's
 * loop on the portable reference (sn_k_ic_col_ref per block, stopping at
 * the first row >= nF) and, per block, a double reference of the rounded
 * row (exact below 2^53): random columns of 0..12 blocks, rows sometimes
 * past nF, vertex exponents 0..15 and fracs 0..47 (shifts -15..62: the
 * scale-up below 0, the table's ends 0 and 62), y at the state bound and
 * INT32_MIN/MAX; accumulators, clamp count and blocks read must match. */
static void test_ic_fwd_run(void) {
    static unsigned char L[12 * 20], cols[24];
    static sn_acc a1[90], a2[90];
    static double a3[90];
    int t, bad = 0, bad_d = 0, lo = 0, hi = 0, neg = 0, stops = 0;
    for (t = 0; t < 6000; t++) {
        sn_q y[3];
        uint8_t kk[30];
        const uint32_t nF = 20u + rnd32() % 10u, nb = rnd32() % 13u;
        const int kj = (int)(rnd32() % 16u), wild = t % 8 == 0;
        uint32_t e, k, n1, n2 = 0, s1 = 0, s2 = 0;
        for (k = 0; k < 3; k++)
            y[k] = wild ? (t % 16 == 0 ? (rnd32() & 1 ? INT32_MAX : INT32_MIN) : (rnd32() & 1 ? SN_LIM : -SN_LIM)) : rnd_in(SN_LIM);
        for (k = 0; k < 30; k++) kk[k] = (uint8_t)(rnd32() % 16u);
        for (k = 0; k < 90; k++) a3[k] = (double)(a1[k] = a2[k] = (int64_t)rnd_in(1 << 30) << 12);
        for (e = 0; e < nb; e++) {
            unsigned char *b = L + 20 * e;
            const uint32_t row = rnd32() % 16u == 0 ? nF + rnd32() % 3u : rnd32() % nF;
            for (k = 0; k < 9; k++) {
                const int32_t m = wild ? (rnd32() & 1 ? 32767 : -32767) : rnd_in(32767);
                const uint16_t u = (uint16_t)(m < 0 ? m + 65536 : m);
                b[2 * k] = (unsigned char)u;
                b[2 * k + 1] = (unsigned char)(u >> 8);
            }
            b[18] = (unsigned char)(rnd32() % 4u == 0 ? (rnd32() & 1 ? 47u : 0u) : rnd32() % 48u);
            b[19] = 0;
            cols[2 * e] = (unsigned char)row;
            cols[2 * e + 1] = 0;
        }
        n1 = sn_k_ic_fwd_run(L, cols, cols + 2 * nb, y, kj, kk, nF, a1, &s1);
        for (e = 0; e < nb; e++) {
            const uint32_t i = cols[2 * e];
            const unsigned char *b = L + 20 * e;
            int s, c, r;
            if (i >= nF) { stops++; break; }
            s = (int)b[18] + kj - (int)kk[i];
            lo += s == 0;
            hi += s == 62;
            neg += s < 0;
            sn_k_ic_col_ref(b, y, s, a2 + 3 * i, &s2);
            for (c = 0; c < 3; c++) { /* round half up (s >= 0), or scaled up and clamped */
                double p = 0;
                for (r = 0; r < 3; r++) p += (double)(int16_t)(uint16_t)(b[6 * r + 2 * c] | b[6 * r + 2 * c + 1] << 8) * (double)y[r];
                p = s >= 0 ? floor(ldexp(p, -s) + (s > 0 ? 0.5 : 0.0)) : ldexp(p, -s);
                a3[3 * i + (uint32_t)c] += p > SN_LIM && s < 0 ? SN_LIM : p < -SN_LIM && s < 0 ? -SN_LIM : p;
            }
            n2++;
        }
        bad += memcmp(a1, a2, sizeof a1) != 0 || s1 != s2 || n1 != n2;
        for (k = 0; k < 90; k++) bad_d += (double)a1[k] != a3[k];
    }
    T_CHECK(bad == 0, "IC(0) forward columns (path %s): %d of 6000 columns differ from the reference loop", sn_kernels_name(), bad);
    T_CHECK(bad_d == 0, "IC(0) forward columns (path %s): %d accumulators off the double reference", sn_kernels_name(), bad_d);
    T_FIGURE("IC(0) forward columns (x86): 6000 columns of 0..12 blocks, %d blocks at shift 0, %d at 62, %d below 0, %d stopped at a row >= nF",
             lo, hi, neg, stops);
}
#endif

#if defined(SN_KERNELS_AVX2) || defined(SN_KERNELS_FAVX2)
/* x86-64's fused IC(0) sweep loops (sn_precond.c ic_fused) against the
 * reference per block (sn_k_ic_col_ref / sn_k_ic_row_ref, the portable
 * loops' order): the backward row with z read from the accumulators
 * (fixed: sn_k_ic_bwd_rowq, int64 z_i; float: sn_k_ic_bwd_rowv, two
 * blocks a step and the odd one) over 0..13 blocks with fracs 0..47 (the
 * float scale's range), and the float forward column (sn_k_ic_fwd_ops;
 * fixed: test_ic_fwd_run). Exact: the same integers / floats. */
static void test_ic_fused(void) {
    static unsigned char L[13 * 20], cols[26];
    static sn_acc zq[90], a1[90], a2[90];
    int t, bad_r = 0, bad_c = 0, bad_f = 0;
    for (t = 0; t < 4000; t++) {
        const uint32_t nb = rnd32() % 14u, nF = 24u;
        uint32_t e, k;
        sn_q y[3], z[90];
        sn_acc lr[4] = {0, 0, 0, 0}, lv[4];
        uint32_t s1 = 0;
        const int wild = t % 8 == 0;
        for (k = 0; k < 90; k++) {
#if defined(SN_FLOAT)
            z[k] = (float)rnd_in(1 << 20) / (float)(1u << (rnd32() % 24u));
#else
            z[k] = wild ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
#endif
            zq[k] = (sn_acc)z[k];
#if defined(SN_FLOAT)
            a1[k] = a2[k] = (float)rnd_in(1 << 20) / 64.0f;
#else
            a1[k] = a2[k] = (int64_t)rnd_in(1 << 30) << 12;
#endif
        }
        for (e = 0; e < nb; e++) {
            unsigned char *b = L + 20 * e;
            for (k = 0; k < 9; k++) {
                const int32_t m = wild ? (rnd32() & 1 ? 32767 : -32767) : rnd_in(32767);
                const uint16_t u = (uint16_t)(m < 0 ? m + 65536 : m);
                b[2 * k] = (unsigned char)u;
                b[2 * k + 1] = (unsigned char)(u >> 8);
            }
            b[18] = (unsigned char)(rnd32() % 4u == 0 ? (rnd32() & 1 ? 47u : 0u) : rnd32() % 48u);
            b[19] = 0;
            cols[2 * e] = (unsigned char)(rnd32() % (nF + 3u)); /* rows past nF: the forward column stops there */
            cols[2 * e + 1] = 0;
        }
        for (e = 0; e < nb; e++) sn_k_ic_row_ref(L + 20 * e, z + 3 * (cols[2 * e] % 30u), lr, &s1);
        for (e = 0; e < nb; e++) cols[2 * e] = (unsigned char)(cols[2 * e] % 30u);
#if defined(SN_FLOAT)
        {
            const sn_fv r = sn_k_ic_bwd_rowv(L, cols, nb, zq);
            FV_ST4(lv, r);
        }
        if (nb) { /* the row with its first block's z'_i from a register (x86-64 round 4): the same floats */
            sn_acc lw[4];
            FV_ST4(lw, sn_k_ic_bwd_rowr(L, cols, nb, zq, fv_ld3(zq + 3 * cols[0]), 1));
            bad_f += memcmp(lw, lr, 3 * sizeof lw[0]) != 0;
            FV_ST4(lw, sn_k_ic_bwd_rowr(L, cols, nb, zq, FV_SET1(NAN), 0)); /* hf 0: the register unread */
            bad_f += memcmp(lw, lr, 3 * sizeof lw[0]) != 0;
        }
#else
        _mm256_storeu_si256((__m256i *)(void *)lv, sn_k_ic_bwd_rowq(L, cols, nb, zq));
#endif
        bad_r += memcmp(lv, lr, 3 * sizeof lv[0]) != 0;
#if defined(SN_FLOAT)
        {
            uint32_t n1, n2 = 0;
            for (k = 0; k < 3; k++) y[k] = z[k];
            n1 = sn_k_ic_fwd_ops(L, cols, cols + 2 * nb, FV_SET1(y[0]), FV_SET1(y[1]), FV_SET1(y[2]), nF, a1);
            for (e = 0; e < nb && cols[2 * e] < nF; e++, n2++) sn_k_ic_col_ref(L + 20 * e, y, 0, a2 + 3 * cols[2 * e], &s1);
            bad_c += memcmp(a1, a2, sizeof a1) != 0 || n1 != n2;
        }
#else
        (void)y; (void)a1; (void)a2;
#endif
    }
    T_CHECK(bad_r == 0, "fused IC(0) backward rows (path %s): %d of 4000 differ from the reference", sn_kernels_name(), bad_r);
    T_CHECK(bad_c == 0, "fused IC(0) forward columns (path %s): %d of 4000 differ from the reference", sn_kernels_name(), bad_c);
#if defined(SN_FLOAT)
    T_CHECK(bad_f == 0, "fused IC(0) backward rows, first z from a register (path %s): %d of 2 x 4000 differ from the reference",
            sn_kernels_name(), bad_f);
#else
    (void)bad_f;
#endif
}
#endif

#if defined(SN_K_ENERGY24)
/* x86-64's cell energy sum (sn_k_energy24) against the reference loop,
 * sum over k = 3..23 of sn_mul(d[k], sn_out(l[k], s)) (sn_internal.h):
 * d at and inside +-2^28, l up to +-2^62 (clamps on both sides; float:
 * also +-inf and NaN), shifts -3..61; the value (fixed: the int64; float:
 * the reference order's float) and the clamp count must match. */
static void test_energy24(void) {
    int t, bad = 0, clamps = 0;
    for (t = 0; t < 4000; t++) {
        sn_q d[24];
        sn_acc l[24], ref = 0, got;
        uint32_t k, s1 = 0, s2 = 0;
        const int s = (int)(rnd32() % 65u) - 3;
        for (k = 0; k < 24; k++) {
            d[k] = t % 8 == 0 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
#if defined(SN_FLOAT)
            d[k] = (float)rnd_in(1 << 20) / 1024.0f;
            l[k] = (float)rnd_in(1 << 24) / 2048.0f; /* +-8192: about a quarter beyond SN_FLIM */
            if (t % 16 == 1 && rnd32() % 4u == 0) { /* sn_out's other float cases: +-inf, NaN */
                const uint32_t u = rnd32() % 3u;
                l[k] = u == 0 ? (sn_acc)HUGE_VAL : u == 1 ? (sn_acc)-HUGE_VAL : (sn_acc)NAN;
            }
#else
            l[k] = (int64_t)rnd_in(1 << 30) * ((int64_t)1 << (rnd32() % 33u));
#endif
        }
        for (k = 3; k < 24; k++) ref += sn_mul(d[k], sn_out(l[k], s, &s2));
        got = sn_k_energy24(d, l, s, &s1);
        clamps += (int)s2;
        bad += got != ref || s1 != s2;
    }
    T_CHECK(bad == 0, "cell energy sum (path %s): %d of 4000 cells differ from the reference loop", sn_kernels_name(), bad);
    T_FIGURE("cell energy sums: 4000 cells, shifts -3..61, %d clamped terms", clamps);
}
#endif

#if defined(SN_K_MASS_FF)
/* The M4's mass pass (sn_k_mass_ff) against pass_M_ff's loop written here
 * with sn_mul (exact int64 sums: tolerance 0): random row structures of
 * 1..40 free rows, 0..8 blocks a row, columns past nF (the row stops there)
 * and operands at the bounds (y +-2^28 and INT32_MIN/MAX; |M| <= 2^23, so
 * the <= 330 products of <= 2^54 a sum gets stay below 2^63). */
static void test_mass_ff(void) {
    static unsigned char rp[4 * 41], cols[2 * 400], md[4 * 40], mo[4 * 400];
    static sn_q y[3 * 48];
    static sn_acc a1[3 * 40], a2[3 * 40];
    int t, bad = 0, stops = 0;
    for (t = 0; t < 500; t++) {
        const uint32_t nF = 1u + rnd32() % 40u;
        const int wild = t % 8 == 0;
        uint32_t i, e = 0, k;
#if defined(SN_FLOAT) /* x86-64 AVX2's float pass: values and the blob's float bits */
        (void)wild;
        for (i = 0; i < 3 * 48; i++) y[i] = (float)rnd_in(1 << 20) / (float)(1u << (rnd32() % 20u)) * (rnd32() % 16u ? 1.0f : -0.0f);
#else
        for (i = 0; i < 3 * 48; i++) y[i] = wild ? (rnd32() & 1 ? INT32_MAX : INT32_MIN) : rnd32() & 1 ? rnd_in(SN_LIM) : (rnd32() & 1 ? SN_LIM : -SN_LIM);
#endif
        for (i = 0; i < nF; i++) {
            const uint32_t nb = rnd32() % 9u;
            put32(rp + 4 * i, e);
#if defined(SN_FLOAT)
            put32(md + 4 * i, fbits((float)rnd_in(1 << 23) / 1024.0f));
#else
            put32(md + 4 * i, wild ? 0x007FFFFFu : (uint32_t)rnd_in(1 << 23));
#endif
            for (k = 0; k < nb; k++, e++) {
                const uint32_t j = rnd32() % 12u == 0 ? nF + rnd32() % 8u : rnd32() % nF;
                cols[2 * e] = (unsigned char)j;
                cols[2 * e + 1] = (unsigned char)(j >> 8);
#if defined(SN_FLOAT)
                put32(mo + 4 * e, fbits((float)rnd_in(1 << 23) / 1024.0f * (rnd32() % 16u ? 1.0f : -0.0f)));
#else
                put32(mo + 4 * e, wild ? 0xFF800000u : (uint32_t)rnd_in(1 << 23));
#endif
            }
        }
        put32(rp + 4 * nF, e);
        for (i = 0; i < 3 * nF; i++) a1[i] = a2[i] = 0;
        sn_k_mass_ff(rp, cols, md, mo, y, a1, nF);
        for (i = 0; i < nF; i++) {
            uint32_t b = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
            sn_acc l[3];
            for (k = 0; k < 3; k++) l[k] = (sn_acc)0 + sn_mul(rd_real(md, i), y[3 * i + k]); /* pass_M_ff: l = 0, then += */
            for (; b < end; b++) {
                const uint32_t j = sn_rd_u16(cols + 2 * b);
                const sn_q m = rd_real(mo, b);
                if (j >= nF) { stops++; break; }
                for (k = 0; k < 3; k++) { l[k] += sn_mul(m, y[3 * j + k]); a2[3 * j + k] += sn_mul(m, y[3 * i + k]); }
            }
            for (k = 0; k < 3; k++) a2[3 * i + k] += l[k];
        }
        bad += memcmp(a1, a2, 3 * nF * sizeof a1[0]) != 0; /* float: bit for bit, signed zeros included */
    }
    T_CHECK(bad == 0, "mass pass (path %s): %d of 500 structures differ from the reference loop", sn_kernels_name(), bad);
    T_FIGURE("mass pass: 500 random row structures, %d rows stopped at a column >= nF", stops);
}
#endif

#if defined(SN_K_FREE8)
/* sn_k_free8 (a cell's free corners as bits) against the loop it replaced,
 * indices and nF over the whole u16 range (the signed compare's edge at
 * 2^15 included), nF 0 and indices at nF - 1, nF, nF + 1 */
static void test_free8(void) {
    int t, bad = 0;
    for (t = 0; t < 20000; t++) {
        unsigned char cl[16];
        const uint32_t nF = t % 7 == 0 ? 0u : t % 7 == 1 ? 65535u : t % 7 == 2 ? 32768u + rnd32() % 3u - 1u : rnd32() % 65536u;
        uint32_t k, ref = 0;
        for (k = 0; k < 8; k++) {
            const uint32_t a = rnd32() & 1 ? (nF + rnd32() % 3u - 1u) & 0xFFFFu : rnd32() % 65536u;
            cl[2 * k] = (unsigned char)a;
            cl[2 * k + 1] = (unsigned char)(a >> 8);
            ref |= (uint32_t)(a < nF) << k;
        }
        bad += sn_k_free8(cl, nF) != ref;
    }
    T_CHECK(bad == 0, "sn_k_free8: %d of 20000 records differ from the corner loop", bad);
}
/* sn_k_out_rot_acc2_m (cell_forces' corner row out) against its loop:
 * ls = ld + lu + 0 + 0, sn_out per entry, acc += R t (sn_rot_acc); clamps,
 * NaN and signed zeros included */
static void test_out_rot2(void) {
    int t, k, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 20000; t++) {
        sn_q R[9], ts[3];
        sn_acc ld[3], lu[3], a1[3], a2[3], ls[3];
        sn_k_rotm rm;
        uint32_t s1 = 0, s2 = 0;
        const int extreme = t % 8 == 0;
        for (k = 0; k < 9; k++) R[k] = (float)rnd_in(1 << 20) / 1048576.0f;
        for (k = 0; k < 3; k++) {
            ld[k] = extreme && rnd32() % 4u == 0 ? (rnd32() & 1 ? 5.0e3f : nanf("")) : (float)rnd_in(1 << 20) / 256.0f;
            lu[k] = rnd32() % 8u == 0 ? -0.0f : (float)rnd_in(1 << 20) / 256.0f;
            if (rnd32() % 8u == 0) ld[k] = -0.0f;
            a1[k] = a2[k] = (float)rnd_in(1 << 20);
        }
        sn_k_rotm_ld(&rm, R);
        sn_k_out_rot_acc2_m(a1, &rm, ld, lu, &s1);
        for (k = 0; k < 3; k++) {
            ls[k] = ld[k] + lu[k] + (t < 0 ? 1.0f : 0) + (t < 0 ? 1.0f : 0); /* the solve's sum, its +0 shares */
            ts[k] = sn_out(ls[k], 0, &s2);
        }
        sn_rot_acc(a2, R, ts);
        bad += memcmp(a1, a2, sizeof a1) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "sn_k_out_rot_acc2_m: %d of 20000 rows differ from the reference loop", bad);
    T_FIGURE("cell_forces' row out: 20000 rows, %u clamps and NaN replacements", clamps);
}
#endif

#if defined(SN_K_CELL_STIFF)
/* sn_k_cell_stiff (the mat-vec's cell on x86-64 float) against cell_stiff's
 * loop written here: u = sn_rot_t(R, d_a) per free corner in order,
 * sn_k_cell_mul (the product the other tests check against the reference),
 * acc_a += R sn_out(l_a) by sn_rot_acc; every free-corner count 0..8,
 * repeated vertices, operands and accumulators with clamps */
static void test_cell_stiff(void) {
    static unsigned char K[REC];
    static double S[24][24];
    static sn_q d[3 * 48];
    static sn_acc a1[3 * 48], a2[3 * 48];
    int t, bad = 0, nfs[9] = {0};
    uint32_t clamps = 0;
    for (t = 0; t < 3000; t++) {
        unsigned char cl[16];
        const uint32_t nF = 1u + rnd32() % 40u;
        const int wild = t % 8 == 0;
        sn_q R[9], u[24];
        sn_acc l[24];
        uint8_t fc[8];
        uint32_t vi[8], k, c, nf = 0, s1 = 0, s2 = 0;
        if (t % 50 == 0) make_rec(K, S, t % 100 == 0);
        for (k = 0; k < 9; k++) R[k] = (float)rnd_in(1 << 20) / 1048576.0f;
        for (k = 0; k < 3 * 48; k++) {
            d[k] = wild && rnd32() % 8u == 0 ? (float)rnd_in(1 << 20) : (float)rnd_in(1 << 20) / 1024.0f;
            a1[k] = a2[k] = (float)rnd_in(1 << 20) / 64.0f;
        }
        for (k = 0; k < 8; k++) { /* corners: free (< nF) or not, by a per-record chance; repeats allowed */
            const uint32_t a = rnd32() % 8u < (uint32_t)(t % 9) ? rnd32() % nF : nF + rnd32() % 8u;
            cl[2 * k] = (unsigned char)a;
            cl[2 * k + 1] = (unsigned char)(a >> 8);
        }
        sn_k_cell_stiff(K, cl, nF, R, d, a1, &s1);
        for (k = 0; k < 8; k++) {
            const uint32_t a = sn_rd_u16(cl + 2 * k);
            if (a >= nF) continue;
            sn_rot_t(R, d + 3 * a, u + 3 * nf, &s2);
            fc[nf] = (uint8_t)k;
            vi[nf++] = a;
        }
        nfs[nf]++;
        if (nf) sn_k_cell_mul(K, fc, nf, u, l);
        for (k = 0; k < nf; k++) {
            sn_q o[3];
            for (c = 0; c < 3; c++) o[c] = sn_out(l[3 * k + c], 0, &s2);
            sn_rot_acc(a2 + 3 * vi[k], R, o);
        }
        bad += memcmp(a1, a2, sizeof a1) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "sn_k_cell_stiff: %d of 3000 cells differ from cell_stiff's loop", bad);
    T_FIGURE("mat-vec cells: 3000 (free corners 0..8: %d %d %d %d %d %d %d %d %d), %u clamps", nfs[0], nfs[1], nfs[2], nfs[3],
             nfs[4], nfs[5], nfs[6], nfs[7], nfs[8], clamps);
}
#endif

#if defined(SN_K_FRHS)
/* The float right-hand side's kernels (x86-64 AVX2, sn_kernels.h SN_K_FRHS)
 * against rhs_x0's loops written here with the scalar reference (sn_out,
 * sn_add, sn_mulq, sn_mul; the fold's operands as plain float expressions,
 * each rounded on its own through a volatile): bit for bit (memcmp: signed zeros included) and
 * the same clamp counts. Operands: values inside and beyond +-SN_FLIM, NaN,
 * -0, lengths 0..41 (the 4-lane loop's tails). */
static float frnd(int wild) {
    const uint32_t k = rnd32() % 16u;
    if (wild && k == 0) return nanf("");
    if (wild && k == 1) return rnd32() & 1 ? 3.0e4f : -3.0e4f; /* clamps */
    if (k == 2) return -0.0f;
    return (float)rnd_in(1 << 20) / (float)(1u << (rnd32() % 12u));
}
/* uniform in +-0.6 SN_FLIM: differences and 3-term products of such values
 * clamp now and then, one step at a time */
static float fnear(void) {
    return (float)rnd_in(1 << 20) / 1048576.0f * 0.6f * SN_FLIM;
}
static void test_frhs_flat(void) {
    static sn_q v[48], x[48], u1[48], u2[48];
    static sn_acc a[48];
    int t, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 3000; t++) {
        const uint32_t n = rnd32() % 42u;
        const int wild = t % 4 == 0, op = t % 3;
        const sn_q c = t % 5 == 0 ? 1.75f : (float)rnd_in(1 << 20) / 1048576.0f;
        uint32_t i, s1 = 0, s2 = 0;
        for (i = 0; i < 48; i++) { v[i] = frnd(wild); x[i] = frnd(wild); a[i] = frnd(wild); u1[i] = u2[i] = 7.0f; }
        if (op == 0) {
            sn_k_fold_w(u1, v, x, c, n); /* the fold's operands: plain floats, no clamp (sn_kernels.h) */
            for (i = 0; i < n; i++) { volatile float t = v[i] + x[i]; u2[i] = t * c; }
        } else if (op == 1) {
            sn_k_fold_y(u1, v, x, c, n);
            for (i = 0; i < n; i++) { volatile float t = v[i] + x[i], p = t * c; u2[i] = p + x[i]; }
        } else {
            sn_k_negout(u1, a, n, &s1);
            for (i = 0; i < n; i++) u2[i] = (sn_q)-sn_out(a[i], SN_Q_ROT, &s2);
        }
        bad += memcmp(u1, u2, sizeof u1) != 0 || s1 != s2; /* entries past n untouched too */
        clamps += s2;
    }
    T_CHECK(bad == 0, "fold_w / fold_y / negout (path %s): %d of 3000 cases differ from the reference loops", sn_kernels_name(), bad);
    T_FIGURE("fold_w / fold_y / negout: 3000 cases, %u clamps", clamps);
}
/* sn_k_mass_rhs: random rows of 1..40 free rows over nF + 1..16 vertices,
 * free and skeleton columns in random order, y, v', ds with clamping values */
static void test_mass_rhs(void) {
    static unsigned char rp[4 * 41], cols[2 * 400], md[4 * 40], mo[4 * 400];
    static sn_q y[3 * 40], vel[3 * 56], ds[3 * 16];
    static sn_acc a1[3 * 40], a2[3 * 40];
    int t, bad = 0, sk = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 500; t++) {
        const uint32_t nF = 1u + rnd32() % 40u, nS = 1u + rnd32() % 16u;
        const int wild = t % 4 == 0;
        const sn_q a = (float)rnd_in(1 << 20) / 1048576.0f;
        uint32_t i, e = 0, k, s1 = 0, s2 = 0;
        for (i = 0; i < 3 * nF; i++) { y[i] = frnd(0); a1[i] = a2[i] = frnd(0); }
        for (i = 0; i < 3 * (nF + nS); i++) vel[i] = frnd(wild);
        for (i = 0; i < 3 * nS; i++) ds[i] = frnd(wild);
        for (i = 0; i < nF; i++) {
            const uint32_t nb = rnd32() % 9u;
            put32(rp + 4 * i, e);
            put32(md + 4 * i, fbits((float)rnd_in(1 << 23) / 1024.0f));
            for (k = 0; k < nb; k++, e++) {
                const uint32_t j = rnd32() % 3u == 0 ? nF + rnd32() % nS : rnd32() % nF;
                cols[2 * e] = (unsigned char)j;
                cols[2 * e + 1] = (unsigned char)(j >> 8);
                put32(mo + 4 * e, fbits((float)rnd_in(1 << 23) / 1024.0f * (rnd32() % 16u ? 1.0f : -0.0f)));
            }
        }
        put32(rp + 4 * nF, e);
        sn_k_mass_rhs(rp, cols, md, mo, y, vel, ds, a, a1, nF, &s1);
        for (i = 0; i < nF; i++) { /* rhs_x0's loop with pre */
            uint32_t b = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
            sn_acc l[3];
            for (k = 0; k < 3; k++) l[k] = (sn_acc)0 + sn_mul(rd_real(md, i), y[3 * i + k]);
            for (; b < end; b++) {
                const uint32_t j = sn_rd_u16(cols + 2 * b);
                const sn_q m = rd_real(mo, b);
                for (k = 0; k < 3; k++) {
                    if (j >= nF) l[k] += sn_mul(m, sn_add(sn_mulq(vel[3 * j + k], a, SN_Q_COEF, &s2), ds[3 * (j - nF) + k], &s2));
                    else { l[k] += sn_mul(m, y[3 * j + k]); a2[3 * j + k] += sn_mul(m, y[3 * i + k]); }
                }
                sk += j >= nF;
            }
            for (k = 0; k < 3; k++) a2[3 * i + k] += l[k];
        }
        bad += memcmp(a1, a2, 3 * nF * sizeof a1[0]) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "rhs mass pass (path %s): %d of 500 structures differ from the reference loop", sn_kernels_name(), bad);
    T_FIGURE("rhs mass pass: 500 random row structures, %d skeleton blocks, %u clamps", sk, clamps);
}
/* sn_k_grav_rhs: random frames (any floats: the kernel is the reference's
 * arithmetic, not a rotation's), masses, g, b and acc, modelled or not */
static void test_grav_rhs(void) {
    static sn_q b1[3 * 40], b2[3 * 40], R[9 * 40];
    static sn_acc acc[3 * 40];
    static unsigned char ml[4 * 40];
    int t, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 1000; t++) {
        const uint32_t nF = rnd32() % 41u;
        const int wild = t % 4 == 0, mod = t % 2;
        sn_q g[3];
        uint32_t i, k, s1 = 0, s2 = 0;
        for (k = 0; k < 3; k++) g[k] = frnd(0);
        for (i = 0; i < 3 * 40; i++) { b1[i] = b2[i] = frnd(wild); acc[i] = frnd(wild); }
        for (i = 0; i < 9 * 40; i++) R[i] = wild ? frnd(0) : (float)rnd_in(1 << 20) / 1048576.0f;
        for (i = 0; i < 40; i++) put32(ml + 4 * i, fbits(wild && i % 3 == 0 ? 1.0e4f : (float)rnd_in(1 << 20) / 1024.0f));
        sn_k_grav_rhs(b1, acc, R, ml, g, mod, nF, &s1);
        for (i = 0; i < nF; i++) { /* rhs_x0's loop */
            sn_q mi = rd_real(ml, i), gi[3], gr[3];
            for (k = 0; k < 3; k++) /* sn_rot */
                gr[k] = sn_out(sn_mul(R[9 * i + 3 * k], g[0]) + sn_mul(R[9 * i + 3 * k + 1], g[1]) + sn_mul(R[9 * i + 3 * k + 2], g[2]), 0, &s2);
            for (k = 0; k < 3; k++) gi[k] = mod ? sn_add(g[k], -gr[k], &s2) : g[k];
            for (k = 0; k < 3; k++) {
                sn_q gg = sn_mulq(mi, gi[k], 0, &s2);
                sn_q ma = sn_out(acc[3 * i + k], 0, &s2);
                b2[3 * i + k] = sn_add(sn_add(b2[3 * i + k], gg, &s2), -ma, &s2);
            }
        }
        bad += memcmp(b1, b2, sizeof b1) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "rhs gravity pass (path %s): %d of 1000 cases differ from the reference loop", sn_kernels_name(), bad);
    T_FIGURE("rhs gravity pass: 1000 cases, %u clamps", clamps);
}
/* sn_k_fdot: the CG's float dot, the reference's sum in i order */
static void test_fdot(void) {
    static sn_q a[400], b[400];
    int t, bad = 0, far = 0;
    double worst = 0.0;
    for (t = 0; t < 2000; t++) {
        const uint32_t n = t % 8 == 0 ? 378u : rnd32() % 400u;
        uint32_t i;
        float p[8] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f}, s, r;
        double ex = 0.0, mag = 0.0, bound;
        for (i = 0; i < n; i++) { a[i] = frnd(0); b[i] = frnd(0); }
        for (i = 0; i < n; i++) p[i & 7] += a[i] * b[i]; /* sn_solve.c dot */
        s = ((p[0] + p[1]) + (p[2] + p[3])) + ((p[4] + p[5]) + (p[6] + p[7]));
        r = sn_k_fdot(a, b, n);
        bad += memcmp(&r, &s, sizeof s) != 0;
        /* against the double sum: each product rounds once, a partial sum
         * at most ceil(n / 8) times, the tree 3 times, so |error| <=
         * (n / 8 + 5) u sum |a_i b_i| (u = 2^-24, first order) */
        for (i = 0; i < n; i++) { ex += (double)a[i] * b[i]; mag += fabs((double)a[i] * b[i]); }
        bound = ((double)n / 8.0 + 5.0) * 0x1p-24 * mag;
        if (fabs((double)r - ex) > bound) far++;
        if (mag > 0.0 && fabs((double)r - ex) / mag > worst) worst = fabs((double)r - ex) / mag;
    }
    T_CHECK(bad == 0, "float dot (path %s): %d of 2000 sums differ from the reference order", sn_kernels_name(), bad);
    T_CHECK(far == 0, "float dot: %d of 2000 sums beyond (n/8 + 5) u sum|a b| of the double sum", far);
    T_FIGURE("float dot: worst error %.3g of sum|a b| (2000 sums, n < 400)", worst);
}
#endif

#if defined(SN_K_SKEL)
/* sn_k_skeleton against sn_skeleton's loop written here with the reference
 * helpers (sn_rot, sn_add: the same floats and clamp count, tolerance 0):
 * random bones, rest positions, frames (any floats: the kernel is the
 * reference's arithmetic), translations, positions and velocities; wild
 * cases with values beyond SN_FLIM and NaN, near cases within +-0.6 SN_FLIM
 * so that one sum alone clamps */
static void test_skeleton(void) {
    enum { NV = 40, NJ = 6 };
    static unsigned char fr[4 * NV], rest[4 * 3 * NV];
    static sn_q jR[9 * NJ], jT[3 * NJ], p1[3 * NV], p2[3 * NV], v1[3 * NV], v2[3 * NV], d1[3 * NV], d2[3 * NV];
    int t, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 4000; t++) {
        const int wild = t % 4 == 0, near = t % 4 == 1;
        const uint32_t nV = 1u + rnd32() % NV, nF = rnd32() % nV;
        uint32_t i, k, s1 = 0, s2 = 0;
        for (i = 0; i < NV; i++) {
            fr[4 * i] = (unsigned char)(rnd32() % NJ);
            for (k = 0; k < 3; k++) put32(rest + 4 * (3 * i + k), fbits(near ? fnear() : frnd(wild)));
        }
        for (i = 0; i < 9 * NJ; i++) jR[i] = wild ? frnd(0) : (float)rnd_in(1 << 20) / 1048576.0f;
        for (i = 0; i < 3 * NJ; i++) jT[i] = near ? fnear() : frnd(wild);
        for (i = 0; i < 3 * NV; i++) {
            p1[i] = p2[i] = near ? fnear() : frnd(wild);
            v1[i] = v2[i] = near ? fnear() : frnd(wild);
            d1[i] = d2[i] = 0.0f;
        }
        sn_k_skeleton(jR, jT, fr, rest, nF, nV, p1, v1, d1, &s1);
        for (i = nF; i < nV; i++) { /* sn_skeleton's loop, have_prev */
            const uint32_t b = fr[4 * i];
            sn_q x[3], p[3];
            for (k = 0; k < 3; k++) x[k] = rd_real(rest, 3 * i + k);
            sn_rot(jR + 9 * b, x, p, &s2);
            for (k = 0; k < 3; k++) {
                sn_q pn = sn_add(p[k], jT[3 * b + k], &s2);
                sn_q vn = sn_add(pn, -p2[3 * i + k], &s2);
                d2[3 * (i - nF) + k] = sn_add(vn, -v2[3 * i + k], &s2);
                v2[3 * i + k] = vn;
                p2[3 * i + k] = pn;
            }
        }
        bad += memcmp(p1, p2, sizeof p1) != 0 || memcmp(v1, v2, sizeof v1) != 0 || memcmp(d1, d2, sizeof d1) != 0 ||
               s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "sn_k_skeleton (path %s): %d of 4000 cases differ from the reference loop", sn_kernels_name(), bad);
    T_FIGURE("skeleton vertices: 4000 cases, %u clamps and NaN replacements", clamps);
}
#endif

#if defined(SN_K_RIG)
/* sn_k_rig against sn_rigs' loop written here with the reference helpers
 * (sn_out, sn_rot, sn_add; tolerance 0, the same clamp count): random
 * entries (vertices repeat: a later entry adds to an earlier one's sum),
 * forces, frames (any floats), eta and b; wild cases with values beyond
 * SN_FLIM and NaN, near cases within +-0.6 SN_FLIM */
static void test_rig(void) {
    enum { NE = 60, NVX = 20 };
    static unsigned char F[4 * 3 * NE], vx[2 * NE];
    static sn_q R[9 * NVX], b1[3 * NVX], b2[3 * NVX];
    int t, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 4000; t++) {
        const int wild = t % 4 == 0, near = t % 4 == 1;
        const uint32_t first = rnd32() % NE, cnt = rnd32() % (NE - first + 1u);
        const sn_q eta = near ? fnear() / SN_FLIM : frnd(wild);
        uint32_t e, i, k, s1 = 0, s2 = 0;
        for (e = 0; e < NE; e++) {
            const uint32_t vi = rnd32() % NVX;
            vx[2 * e] = (unsigned char)vi; vx[2 * e + 1] = 0;
            for (k = 0; k < 3; k++) put32(F + 4 * (3 * e + k), fbits(near ? fnear() : frnd(wild)));
        }
        for (i = 0; i < 9 * NVX; i++) R[i] = wild ? frnd(0) : (float)rnd_in(1 << 20) / 1048576.0f;
        for (i = 0; i < 3 * NVX; i++) b1[i] = b2[i] = near ? fnear() : frnd(wild);
        sn_k_rig(eta, F, vx, first, cnt, R, b1, &s1);
        for (e = first; e < first + cnt; e++) { /* sn_rigs' loop */
            const uint32_t vi = sn_rd_u16(vx + 2 * e);
            sn_q tt[3], f[3];
            for (k = 0; k < 3; k++) tt[k] = sn_out(eta * rd_real(F, 3 * e + k), 0, &s2);
            sn_rot(R + 9 * vi, tt, f, &s2);
            for (k = 0; k < 3; k++) b2[3 * vi + k] = sn_add(b2[3 * vi + k], f[k], &s2);
        }
        bad += memcmp(b1, b2, sizeof b1) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "sn_k_rig (path %s): %d of 4000 rigs differ from the reference loop", sn_kernels_name(), bad);
    T_FIGURE("rig entries: 4000 rigs, %u clamps and NaN replacements", clamps);
}
#endif

#if defined(SN_K_CORNER0)
/* sn_k_corner_c0 (cell_forces' corner, corner 0's operands loaded once)
 * against the reference loop of cell_forces: t = sn_add(p_a, -p_0),
 * s = sn_add(w_a, -w_0), uu = sn_rot_t(R, s), d = sn_add(sn_rot_t(R, t),
 * -sn_add(x_a, -x_0)); values with clamps, NaN, signed zeros */
static void test_corner_c0(void) {
    static unsigned char rest[4 * 30];
    int t, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 20000; t++) {
        const int wild = t % 4 == 0;
        const uint32_t ia = 3u * (rnd32() % 10u), ib = 3u * (rnd32() % 10u);
        sn_q R[9], pa[3], p0[3], wa[3], w0[3], d1[3], u1[3], d2[3], u2[3], tt[3], ss[3], l[3], xr[3];
        sn_k_rotm rm;
        sn_k_c0 c0;
        uint32_t k, s1 = 0, s2 = 0;
        for (k = 0; k < 9; k++) R[k] = (float)rnd_in(1 << 20) / 1048576.0f;
        for (k = 0; k < 30; k++) put32(rest + 4 * k, fbits(frnd(wild)));
        for (k = 0; k < 3; k++) { pa[k] = frnd(wild); p0[k] = frnd(wild); wa[k] = frnd(wild); w0[k] = frnd(wild); }
        if (t % 4 == 1) { /* inputs within +-0.6 SN_FLIM: one step alone clamps (the kernel's one test for six) */
            for (k = 0; k < 30; k++) put32(rest + 4 * k, fbits(fnear()));
            for (k = 0; k < 3; k++) { pa[k] = fnear(); p0[k] = fnear(); wa[k] = fnear(); w0[k] = fnear(); }
        }
        sn_k_rotm_ld(&rm, R);
        sn_k_c0_ld(&c0, p0, w0, rest, ib);
        sn_k_corner_c0(&rm, &c0, pa, wa, rest, ia, d1, u1, &s1);
        for (k = 0; k < 3; k++) {
            tt[k] = sn_add(pa[k], -p0[k], &s2);
            ss[k] = sn_add(wa[k], -w0[k], &s2);
        }
        sn_rot_t(R, tt, l, &s2);
        sn_rot_t(R, ss, u2, &s2);
        for (k = 0; k < 3; k++) xr[k] = sn_add(rd_real(rest, ia + k), -rd_real(rest, ib + k), &s2);
        for (k = 0; k < 3; k++) d2[k] = sn_add(l[k], -xr[k], &s2);
        bad += memcmp(d1, d2, sizeof d1) != 0 || memcmp(u1, u2, sizeof u1) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "sn_k_corner_c0: %d of 20000 corners differ from the reference loop", bad);
    T_FIGURE("cell_forces' corners: 20000, %u clamps and NaN replacements", clamps);
}
#endif

#if defined(SN_K_MASS_SK)
/* The M4's right-hand-side mass pass at the skeleton columns (sn_k_mass_sk)
 * against sn_rhs's loop written here with the reference helpers (coef =
 * sn_mulq, sn_add, sn_mul; exact int64 sums and the clamp count: tolerance
 * 0): random ascending rows of 1..40 free rows over nF + 1..16 vertices
 * (free columns first, as the validator's order gives), v' at and inside
 * +-SN_LIM, a1 at and inside +-ONE_COEF (the kernel's contract: sn_rhs's
 * pre), at +-ONE_COEF / 2 (odd v' gives the rounding's ties) and just inside it (the M4's SMMULR form
 * for |a1| < ONE_COEF / 2), ds making y clamp at SN_LIM, starting accumulators random. */
static void test_mass_sk(void) {
    static unsigned char rp[4 * 41], cols[2 * 400], mo[4 * 400];
    static sn_q vel[3 * 56], ds[3 * 16];
    static sn_acc a1[3 * 40], a2[3 * 40];
    int t, bad = 0, blocks = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 500; t++) {
        const uint32_t nF = 1u + rnd32() % 40u, nS = 1u + rnd32() % 16u, nV = nF + nS;
        const int wild = t % 4 == 0;
        const sn_q a = t % 8 == 0 ? ONE_COEF : t % 8 == 1 ? -ONE_COEF : t % 8 == 2 ? ONE_COEF / 2 : t % 8 == 3 ? -ONE_COEF / 2
                     : t % 8 == 4 ? ONE_COEF / 2 - 1 : t % 8 == 5 ? -(ONE_COEF / 2 - 1) : rnd_in(ONE_COEF);
        uint32_t i, e = 0, k, s1 = 0, s2 = 0;
        for (i = 0; i < 3 * nV; i++) vel[i] = wild && rnd32() & 1 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
        for (i = 0; i < 3 * nS; i++) ds[i] = wild ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
        for (i = 0; i < nF; i++) {
            uint32_t j;
            put32(rp + 4 * i, e);
            for (j = i + 1; j < nV && e < 400; j++) /* ascending, > i: about 8 a row */
                if (rnd32() % nV < 8u) {
                    cols[2 * e] = (unsigned char)j;
                    cols[2 * e + 1] = (unsigned char)(j >> 8);
                    put32(mo + 4 * e, wild && rnd32() & 1 ? 0x007FFFFFu : (uint32_t)rnd_in(1 << 23));
                    e++;
                }
        }
        put32(rp + 4 * nF, e);
        for (i = 0; i < 3 * nF; i++) a1[i] = a2[i] = (sn_acc)rnd_in(1 << 30) * 4096;
        sn_k_mass_sk(rp, cols, mo, vel, ds, a, a1, nF, &s1);
        for (i = 0; i < nF; i++) {
            uint32_t b = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
            for (; b < end; b++) {
                const uint32_t j = sn_rd_u16(cols + 2 * b);
                const sn_q m = sn_rd_i32(mo + 4 * b);
                if (j < nF) continue;
                blocks++;
                for (k = 0; k < 3; k++)
                    a2[3 * i + k] += sn_mul(m, sn_add(sn_mulq(vel[3 * j + k], a, SN_Q_COEF, &s2), ds[3 * (j - nF) + k], &s2));
            }
        }
        bad += memcmp(a1, a2, 3 * nF * sizeof a1[0]) != 0 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "rhs mass pass, skeleton columns (path %s): %d of 500 structures differ from the reference loop",
            sn_kernels_name(), bad);
    T_FIGURE("rhs mass pass, skeleton columns: 500 random row structures, %d skeleton blocks, %u clamps", blocks, (unsigned)clamps);
}
#endif

#if defined(SN_K_ENERGY)
/* The M4's energy sum of cell_forces (sn_k_energy) against its loop of
 * sn_mul(d, sn_out(l, s)), tolerance 0 with the clamp count: every shift
 * 0..62, the 24 accumulators from edge_ls' rounding ties and clamp edges
 * (and random), d at +-SN_LIM, 0 and random */
static void test_energy(void) {
    int s, bad = 0, cases = 0;
    for (s = 0; s <= 62; s++) {
        sn_acc l[128], lc[24];
        sn_q d[24];
        const int n = edge_ls(s, l);
        int r;
        for (r = 0; r < 12; r++, cases++) {
            uint32_t k, s1 = 0, s2 = 0;
            sn_acc e2 = 0;
            for (k = 0; k < 24; k++) {
                lc[k] = l[(uint32_t)(r * 24 + (int)k) % (uint32_t)n];
                d[k] = r % 3 == 0 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : r % 3 == 1 ? 0 : rnd_in(SN_LIM);
            }
            for (k = 3; k < 24; k++) e2 += sn_mul(d[k], sn_out(lc[k], s, &s2));
            bad += sn_k_energy(d, lc, s, &s1) != e2 || s1 != s2;
        }
    }
    T_CHECK(bad == 0, "cell energy sum (path %s): %d of %d cases off the reference loop", sn_kernels_name(), bad, cases);
}
#endif

#if defined(SN_K_CORNERS)
/* The M4's cell_forces corners (sn_k_corners, Thumb-2 sn_m4_corners)
 * against cell_forces' loop written here with the reference helpers
 * (sn_add, sn_rot_t, coef = sn_mulq; w_of's skeleton w uncounted),
 * tolerance 0 on d, uu, the free-corner bits and the clamp count: 3000
 * random cells over 24 vertices (nF 0..24), R entries within +-2^30 (at
 * the bounds in every 4th), positions, w, v' and rest values within
 * +-SN_LIM (at the bounds in every 4th: the differences and rotations
 * clamp), b1 at +-1, inside and beyond (the counted coef path). */
static void test_corners(void) {
    static sn_q pos[3 * 24], w[3 * 24], vel[3 * 24];
    static unsigned char rest[4 * 3 * 24], cl[16];
    int t, bad = 0;
    uint32_t clamps = 0;
    for (t = 0; t < 3000; t++) {
        const uint32_t nF = rnd32() % 25u;
        const int wild = t % 4 == 0;
        const sn_q b1 = t % 6 == 0 ? ONE_COEF : t % 6 == 1 ? -ONE_COEF : t % 6 == 2 ? 3 * ONE_COEF + rnd_in(ONE_COEF) : rnd_in(ONE_COEF);
        sn_q R[9], d1[24], u1[24], d2[24], u2[24], w0s[3], ws[3];
        const sn_q *w0, *wa;
        uint32_t i, k, c, a0, s1 = 0, s2 = 0, dummy = 0, f1, f2 = 0;
        for (i = 0; i < 9; i++) R[i] = wild && rnd32() & 1 ? (rnd32() & 1 ? 1 << 30 : -(1 << 30)) : rnd_in(1 << 30);
        for (i = 0; i < 3 * 24; i++) {
            pos[i] = wild && rnd32() & 1 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
            w[i] = wild && rnd32() & 1 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
            vel[i] = wild && rnd32() & 1 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
            put32(rest + 4 * i, (uint32_t)(wild && rnd32() & 1 ? (rnd32() & 1 ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM)));
        }
        for (k = 0; k < 8; k++) {
            const uint32_t a = rnd32() % 24u;
            cl[2 * k] = (unsigned char)a;
            cl[2 * k + 1] = 0;
        }
        for (i = 0; i < 24; i++) d1[i] = u1[i] = d2[i] = u2[i] = 0;
        a0 = cl[0];
        if (a0 < nF) w0 = w + 3 * a0;
        else {
            for (c = 0; c < 3; c++) w0s[c] = sn_mulq(vel[3 * a0 + c], b1, SN_Q_COEF, &dummy);
            w0 = w0s;
        }
        f1 = sn_k_corners(cl, pos, w, vel, nF, b1, rest, R, w0, d1, u1, &s1);
        for (k = 1; k < 8; k++) {
            const uint32_t a = cl[2 * k];
            sn_q tt[3], ss[3], l[3], xr[3];
            if (a < nF) { wa = w + 3 * a; f2 |= 1u << k; }
            else {
                for (c = 0; c < 3; c++) ws[c] = sn_mulq(vel[3 * a + c], b1, SN_Q_COEF, &dummy);
                wa = ws;
            }
            for (c = 0; c < 3; c++) {
                tt[c] = sn_add(pos[3 * a + c], -pos[3 * a0 + c], &s2);
                ss[c] = sn_add(wa[c], -w0[c], &s2);
                xr[c] = sn_add(rd_real(rest, 3 * a + c), -rd_real(rest, 3 * a0 + c), &s2);
            }
            sn_rot_t(R, tt, l, &s2);
            sn_rot_t(R, ss, u2 + 3 * k, &s2);
            for (c = 0; c < 3; c++) d2[3 * k + c] = sn_add(l[c], -xr[c], &s2);
        }
        bad += memcmp(d1, d2, sizeof d1) != 0 || memcmp(u1, u2, sizeof u1) != 0 || f1 != f2 || s1 != s2;
        clamps += s2;
    }
    T_CHECK(bad == 0, "cell_forces corners (path %s): %d of 3000 cells differ from the reference loop", sn_kernels_name(), bad);
    T_FIGURE("cell_forces corners: 3000 random cells (every 4th at the bounds), %u clamps", (unsigned)clamps);
}
#endif

#if !defined(SN_FLOAT)
/* sn_math.c's reduced sine / cosine and CORDIC atan2 (on the M4 image
 * their Cortex-M forms: int32 Horner operands, the CORDIC unrolled, "M4
 * round 4") against their int64 reference written here (the other paths'
 * code), tolerance 0: r over [-pi/4, pi/4] (Q30) in steps of 2^12 plus
 * the ends and 0, every quadrant; atan2 on edges (0, 1, 2^30, 2^31 - 1,
 * 2^40) and random magnitudes of random widths, x or y 0 included. */
static void ref_sincos(int64_t r, int quad, int64_t *s, int64_t *c) {
    static const int64_t ks[6] = {1 << 30, -178956971, 8947849, -213044, 2959, -27};
    static const int64_t kc[7] = {1 << 30, -536870912, 44739243, -1491308, 26630, -296, 2};
    int64_t u = sn_rshr64(r * r, 30), ps = ks[5], pc = kc[6], sv;
    int k;
    for (k = 4; k >= 0; k--) ps = ks[k] + sn_rshr64(ps * u, 30);
    for (k = 5; k >= 0; k--) pc = kc[k] + sn_rshr64(pc * u, 30);
    sv = sn_rshr64(ps * r, 30);
    switch (quad & 3) {
    case 0: *s = sv; *c = pc; break;
    case 1: *s = pc; *c = -sv; break;
    case 2: *s = -sv; *c = -pc; break;
    default: *s = -pc; *c = sv; break;
    }
}
static int64_t ref_atan2(int64_t y, int64_t x) {
    static const int64_t tab[32] = {
        863554413089, 509785937287, 269356888665, 136729762476, 68630207382,
        34348560106, 17178471287, 8589759836, 4294945451, 2147480917,
        1073741483, 536870869, 268435451, 134217727, 67108864, 33554432,
        16777216, 8388608, 4194304, 2097152, 1048576, 524288, 262144, 131072,
        65536, 32768, 16384, 8192, 4096, 2048, 1024, 512};
    int64_t X = x * 256, Y = y * 256, Z = 0;
    int i;
    if (x == 0 && y == 0) return 0;
    for (i = 0; i < 32; i++) {
        int64_t dx = sn_rshr64(Y, i), dy = sn_rshr64(X, i);
        if (Y > 0) { X += dx; Y -= dy; Z += tab[i]; }
        else { X -= dx; Y += dy; Z -= tab[i]; }
    }
    return sn_rshr64(Z, 10);
}
static void test_trig(void) {
    static const int64_t edge[] = {0, 1, 2, 3, 1 << 30, (1 << 30) + 1, INT32_MAX, (int64_t)1 << 32, (int64_t)1 << 40};
    const int64_t lim = 843314857; /* pi/4 2^30 */
    int64_t r;
    int bad = 0, n = 0, quad, t;
    unsigned i, j;
    for (r = -lim; r <= lim; r += r < lim - 4096 ? 4096 : (lim - r > 0 ? lim - r : 1))
        for (quad = 0; quad < 4; quad++) {
            int64_t s1, c1, s2, c2;
            sn_sincos_q30(r, quad, &s1, &c1);
            ref_sincos(r, quad, &s2, &c2);
            bad += s1 != s2 || c1 != c2;
            n++;
        }
    for (i = 0; i < sizeof edge / sizeof edge[0]; i++)
        for (j = 0; j < sizeof edge / sizeof edge[0]; j++, n++) bad += sn_atan2_q30(edge[i], edge[j]) != ref_atan2(edge[i], edge[j]);
    for (t = 0; t < 20000; t++, n++) {
        const int64_t y = t % 7 == 0 ? 0 : (int64_t)(rnd32() >> (rnd32() % 32u)) << (rnd32() % 9u);
        const int64_t x = t % 11 == 0 ? 0 : (int64_t)(rnd32() >> (rnd32() % 32u)) << (rnd32() % 9u);
        bad += sn_atan2_q30(y, x) != ref_atan2(y, x);
    }
    T_CHECK(bad == 0, "sincos / atan2 (path %s): %d of %d results off the int64 reference", sn_kernels_name(), bad, n);
    T_FIGURE("sincos / atan2: %d cases", n);
}
#endif

#if !defined(SN_FLOAT)
/* sn_qslerp_at (this build's route: on the M4 image its int32 clamps, the
 * SMULL / SMLAL blend and sn_slerp_ratio for the division) against the
 * portable algorithm in int64 (ref_qslerp_at: ref_sincos, C's int64
 * division for the ratio, sn_unit's portable form with C's uint64 division),
 * from the library's sn_qslerp_pair: random unit pairs at every angle
 * (tiny, obtuse, opposite: both paths), raw int32 components, t at and
 * beyond its ends; and sn_slerp_ratio against C's int64 division with the
 * clamp at the edges of its cases (N <= 0, the 2^30 + 1 threshold, s at 1
 * and 2^32 - 1, s >= 2^32). Tolerance 0: the same integers. */
static int ref_unit4(const int64_t *c, int32_t *out) {
    uint64_t a[4], m = 0, n2 = 0, N, r;
    int i, b = 0;
    for (i = 0; i < 4; i++) {
        a[i] = c[i] < 0 ? (uint64_t)0 - (uint64_t)c[i] : (uint64_t)c[i];
        if (a[i] > m) m = a[i];
    }
    if (m == 0) return 0;
    while (b < 64 && m >> b) b++;
    for (i = 0; i < 4; i++) {
        a[i] = b > 31 ? a[i] >> (b - 31) : a[i] << (31 - b);
        n2 += a[i] * a[i];
    }
    N = sn_isqrt64(n2); /* exact (test_isqrt) */
    if (n2 - N * N > N) N++;
    if (N <= ((uint64_t)1 << 30)) r = (uint64_t)1 << 32;
    else if (N >= ((uint64_t)1 << 32)) r = (uint64_t)1 << 30;
    else r = (((uint64_t)1 << 62) + (N >> 1)) / N;
    for (i = 0; i < 4; i++) {
        const uint64_t v = (a[i] * r + ((uint64_t)1 << 31)) >> 32;
        out[i] = c[i] < 0 ? -(int32_t)v : (int32_t)v;
    }
    return 1;
}
static int64_t ref_c30s(int64_t v) { return v > (1 << 30) ? (1 << 30) : (v < -(1 << 30) ? -(1 << 30) : v); }
static void ref_qslerp_at(const sn_q a[4], const sn_q b[4], const sn_slerp_pair *p, sn_q t, sn_q out[4]) {
    const int64_t Q = (int64_t)1 << 30, P2 = 1686629713, P4 = 843314857;
    int64_t A[4], o[4], tt, ph, sp, cp, k;
    int i;
    for (i = 0; i < 4; i++) A[i] = ref_c30s(a[i]);
    tt = t < 0 ? 0 : (t > Q ? Q : t);
    if (tt == 0 || tt == Q) {
        for (i = 0; i < 4; i++) out[i] = (int32_t)(tt == 0 ? A[i] : p->flip ? -ref_c30s(b[i]) : ref_c30s(b[i]));
        return;
    }
    ph = sn_rshr64(p->th * tt, 30);
    if (ph > 3 * P4) ref_sincos(ph - 2 * P2, 2, &sp, &cp);
    else if (ph > P4) ref_sincos(ph - P2, 1, &sp, &cp);
    else ref_sincos(ph, 0, &sp, &cp);
    k = p->s == 0 ? tt : (sp * Q + (int64_t)(p->s >> 1)) / (int64_t)p->s;
    k = k < 0 ? 0 : (k > Q ? Q : k);
    for (i = 0; i < 4; i++) o[i] = sn_rshr64(A[i] * cp + (int64_t)p->v[i] * k, 30);
    if (!ref_unit4(o, out))
        for (i = 0; i < 4; i++) out[i] = (int32_t)A[i];
}
static int64_t ref_ratio(int64_t sp, uint64_t s) {
    const int64_t k = (sp * ((int64_t)1 << 30) + (int64_t)(s >> 1)) / (int64_t)s;
    return k < 0 ? 0 : (k > ((int64_t)1 << 30) ? ((int64_t)1 << 30) : k);
}
static void rnd_unitq(sn_q q[4]) {
    double d[4], n = 0;
    int i;
    for (i = 0; i < 4; i++) { d[i] = (double)rnd_in(1 << 30); n += d[i] * d[i]; }
    n = n > 0 ? sqrt(n) : 1;
    for (i = 0; i < 4; i++) q[i] = (sn_q)(d[i] / n * 1073741824.0);
}
static void test_slerp(void) {
    static const uint64_t se[] = {1, 2, 3, 1u << 15, 0x7FFFFFFFu, 0x80000000u, 0xFFFFFFFEu, 0xFFFFFFFFu,
                                  0x100000000ull, 0x3FFFFFFFFull, 0x4000000000000000ull};
    static const int64_t pe[] = {0, 1, -1, 2, (int64_t)1 << 29, ((int64_t)1 << 30) - 1, (int64_t)1 << 30,
                                 ((int64_t)1 << 30) + 1, -((int64_t)1 << 30), (int64_t)1 << 31};
    int bad_k = 0, bad_q = 0, nk = 0, nq = 0, t;
    unsigned i, j;
    for (i = 0; i < sizeof se / sizeof se[0]; i++)
        for (j = 0; j < sizeof pe / sizeof pe[0]; j++, nk++) bad_k += sn_slerp_ratio(pe[j], se[i]) != ref_ratio(pe[j], se[i]);
    for (t = 0; t < 60000; t++, nk++) {
        /* around the 2^30 + 1 threshold (sp 2^30 + s/2 ~ (2^30 + 1) s) and at random */
        const uint64_t s = 1u + (uint64_t)(rnd32() >> (rnd32() % 32u)); /* 1..2^32 */
        const int64_t sp = t % 3 == 0 ? (int64_t)((s * (((uint64_t)1 << 30) + 1) - (s >> 1)) >> 30) + (int64_t)(rnd32() % 5u) - 2
                                      : (int64_t)rnd_in(1 << 30) + (t % 5 == 0 ? ((int64_t)1 << 30) : 0);
        bad_k += sn_slerp_ratio(sp, s) != ref_ratio(sp, s);
    }
    for (t = 0; t < 20000; t++) {
        sn_q a[4], b[4], o1[4], o2[4];
        sn_slerp_pair p;
        const int kind = t % 8, path = t % 2;
        int n;
        rnd_unitq(a);
        if (kind == 0) { for (j = 0; j < 4; j++) { a[j] = (sn_q)rnd32(); b[j] = (sn_q)rnd32(); } } /* raw int32 */
        else if (kind == 1) for (j = 0; j < 4; j++) b[j] = a[j] + rnd_in(64); /* tiny angles */
        else if (kind == 2) for (j = 0; j < 4; j++) b[j] = -a[j] + rnd_in(64); /* opposite */
        else rnd_unitq(b);
        sn_qslerp_pair(a, b, path, &p);
        for (n = 0; n < 6; n++, nq++) {
            static const sn_q te[] = {0, 1, (1 << 30) - 1, 1 << 30, -5, (1 << 30) + 7};
            const sn_q tq = n < 2 && t % 4 == 0 ? te[(t / 4 + n) % 6] : (sn_q)(rnd32() % ((1u << 30) + 1u));
            sn_qslerp_at(a, b, &p, tq, o1);
            ref_qslerp_at(a, b, &p, tq, o2);
            bad_q += memcmp(o1, o2, sizeof o1) != 0;
        }
    }
    T_CHECK(bad_k == 0, "sn_slerp_ratio: %d of %d ratios off C's int64 division", bad_k, nk);
    T_CHECK(bad_q == 0, "sn_qslerp_at (path %s): %d of %d slerps off the portable int64 algorithm", sn_kernels_name(), bad_q, nq);
    T_FIGURE("slerp: %d ratios, %d slerps from %d pairs", nk, nq, 20000);
}
#endif

/* The integer square root of this build (sn_isqrt64: Karatsuba with a
 * hardware 32-bit divide (the M4 image's UDIV, 64-bit hosts); 32-bit hosts
 * the digits) and both methods: the exact floor, checked
 * analytically (r^2 <= x < (r + 1)^2 in uint64, r + 1 = 2^32 excepted),
 * tolerance 0: every method must give the same integer. Inputs: edges,
 * squares and their neighbours at every width, random widths. */
static void test_isqrt(void) {
    static const uint64_t edge[] = {0, 1, 2, 3, 4, 8, 9, 15, 16, 17, 0xFFFFFFFFull, 0x100000000ull,
        0xFFFFFFFE00000000ull, 0xFFFFFFFE00000001ull, 0xFFFFFFFFFFFFFFFFull, 0x3FFFFFFFFFFFFFFFull, 0x4000000000000000ull};
    int i, bad = 0, n = (int)(sizeof edge / sizeof edge[0]) + 30000;
    for (i = 0; i < n; i++) {
        uint64_t x, r;
        uint32_t w = rnd32() % 33u, k = w ? (rnd32() | 1u << 31) >> (32u - w) : 0; /* a root of w bits */
        if (i < (int)(sizeof edge / sizeof edge[0])) x = edge[i];
        else if (i % 2) x = (uint64_t)k * k + (uint64_t)(int64_t)((int)(rnd32() % 5u) - 2) * (k != 0);
        else x = ((uint64_t)rnd32() << 32 | rnd32()) >> (rnd32() % 64u);
        r = sn_isqrt64(x);
        bad += !(r * r <= x && (r == 0xFFFFFFFFull || (r + 1) * (r + 1) > x)) || sn_isqrt64_kara(x) != r ||
               sn_isqrt64_digits(x) != r;
    }
    T_CHECK(bad == 0, "isqrt (this build's, Karatsuba, digits): %d of %d inputs not the exact floor", bad, n);
}

/* sn_udiv64 (64-bit hosts: the divide instruction; 32-bit cores, the M4
 * image: the constant-time restoring loop): floor(n / D) for 0 < D <= 2^62,
 * checked analytically with no division: q D <= n < (q + 1) D, the
 * products in 128 bits from 32-bit limbs. Inputs: edges (D = 1, 2^62,
 * n = 0, 2^64 - 1, n a multiple of D and its neighbours), random widths.
 * Tolerance 0: the quotient is an integer. */
static void mul64x64(uint64_t a, uint64_t b, uint64_t *hi, uint64_t *lo) {
    const uint64_t a0 = (uint32_t)a, a1 = a >> 32, b0 = (uint32_t)b, b1 = b >> 32;
    const uint64_t p00 = a0 * b0, p01 = a0 * b1, p10 = a1 * b0, p11 = a1 * b1;
    const uint64_t mid = (p00 >> 32) + (uint32_t)p01 + (uint32_t)p10;
    *lo = (mid << 32) | (uint32_t)p00;
    *hi = p11 + (p01 >> 32) + (p10 >> 32) + (mid >> 32);
}
static void test_udiv64(void) {
    static const uint64_t ed[][2] = {{0, 1}, {1, 1}, {0xFFFFFFFFFFFFFFFFull, 1}, {0xFFFFFFFFFFFFFFFFull, 0x4000000000000000ull},
        {0x3FFFFFFFFFFFFFFFull, 0x4000000000000000ull}, {0x4000000000000000ull, 0x4000000000000000ull},
        {0xFFFFFFFFFFFFFFFFull, 3}, {0x8000000000000000ull, 0xFFFFFFFFull}, {0x7FFFFFFF80000001ull, 0xFFFFFFFFull}};
    int i, bad = 0, n = (int)(sizeof ed / sizeof ed[0]) + 30000;
    for (i = 0; i < n; i++) {
        uint64_t x, D, q, hi, lo, hi1, lo1;
        if (i < (int)(sizeof ed / sizeof ed[0])) { x = ed[i][0]; D = ed[i][1]; }
        else {
            D = (((uint64_t)rnd32() << 32 | rnd32()) >> (2 + rnd32() % 62u)) | 1u; /* 1 .. 2^62 - 1 */
            x = ((uint64_t)rnd32() << 32 | rnd32()) >> (rnd32() % 64u);
            if (i % 3 == 0) { q = x / (D | 1u); x = q * D + (uint64_t)(int64_t)((int)(rnd32() % 3u) - 1) * (q != 0); }
        }
        q = sn_udiv64(x, D);
        mul64x64(q, D, &hi, &lo);           /* q D <= x */
        mul64x64(q + 1u, D, &hi1, &lo1);    /* (q + 1) D > x; q = 2^64 - 1 only for x = 2^64 - 1, D = 1 */
        if (q == 0xFFFFFFFFFFFFFFFFull) bad += !(D == 1 && x == q);
        else bad += !(hi == 0 && lo <= x) || !(hi1 > 0 || lo1 > x);
    }
    T_CHECK(bad == 0, "udiv64: %d of %d quotients not the exact floor", bad, n);
}

#if !defined(SN_FLOAT)
/* The fixed normals' unit step (sn_kernels_xnorm.c; x86-64: on int64
 * operands, the root by sn_isqrt64 and the rounding step; the cases below
 * were searched for a double root and quotient, corrected exactly, which
 * the fixed library no longer uses: they stay as edge cases of the
 * rounding). sn_k_xrsqrt against its
 * definition, the nearest integer R to sqrt(x): R^2 - R < x <= R^2 + R
 * (checked in exact integers) and against sn_isqrt64 rounded as sn_unit
 * rounds it, on 60,000 x in [16, 3 2^62): random magnitudes, and the
 * rounding edges k^2 + k, k^2 + k + 1, k^2, k^2 - 1 for random k.
 * sn_k_xunit against sn_qnormalize on (x, y, z, 0), the scalar reference,
 * bit for bit: 12,000 sums, random signs and bit lengths 1..32, every 8th
 * with INT32_MIN / INT32_MAX / 0 / +-1 components, the zero sum (0, 0,
 * 2^30), and 36 fixed cases (N = 2^30, b = 32, zero sums beside others) at
 * every position of the AVX2 path's four lanes. Tolerance 0 (the same
 * integers). */
static void test_xnorm(void) {
    enum { NX = 60000, NU = 12000 }; /* NU: 288 KB of static arrays on the M4 image too */
    static sn_vec3 u[NU], v[NU];
    static const int32_t edge[] = {0, 1, -1, INT32_MIN, INT32_MAX, -INT32_MAX, 1 << 30, -(1 << 30)};
    /* N = 2^30 (r = 2^32: v = a), 2^31 magnitudes (b = 32), zero sums beside others, small and equal components */
    static const int32_t fixed_c[][3] = {{1 << 30, 0, 0}, {5, 0, 0}, {0, 0, -1}, {INT32_MIN, 0, 0}, {0, 0, 0},
        {INT32_MIN, INT32_MIN, INT32_MIN}, {INT32_MAX, INT32_MAX, INT32_MAX}, {1, 1, 1}, {1 << 30, 1, 0},
        {0, 0, 0}, {1 << 30, 0, 0}, {5, 0, 0}, {0, 0, -1}, {INT32_MIN, 0, 0}, {-3, 4, 0}, {0, 0, 0}, {7, -7, 7},
        {1 << 30, 0, 0}, {0, 0, 0}, {5, 0, 0}, {0, 0, -1}, {INT32_MIN, 0, 0}, {1, 1 << 20, 0}, {0, 0, 0},
        {1 << 30, 0, 0}, {0, 0, 0}, {5, 0, 0}, {0, 0, -1}, {INT32_MIN, 0, 0}, {0, 0, 0}, {-1, 0, 0}, {2, 2, 1},
        {0, 0, 0}, {1 << 30, 0, 0}, {5, 0, 0}, {0, 0, -1}};
    int i, bad = 0, badu = 0, badd = 0;
    for (i = 0; i < NX; i++) {
        uint64_t x, R, N;
        if (i % 2) {
            const uint64_t k = 4u + (((uint64_t)rnd32() << 32 | rnd32()) % 3719550785u); /* k^2 + k + 1 < 3 2^62 */
            const unsigned w = (unsigned)(i / 2) % 4u;
            x = w == 0 ? k * k + k : w == 1 ? k * k + k + 1 : w == 2 ? k * k : k * k - 1;
        } else {
            x = ((uint64_t)rnd32() << 32 | rnd32()) >> (rnd32() % 60u);
            if (x >= 3 * ((uint64_t)1 << 62)) x -= (uint64_t)1 << 62;
            if (x < 16) x += 16;
        }
        R = sn_k_xrsqrt(x);
        badd += !(R * R - R < x && x <= R * R + R);
        N = sn_isqrt64(x);
        if (x - N * N > N) N++;
        bad += R != N;
    }
    T_CHECK(badd == 0, "xrsqrt: %d of %d roots not the nearest integer", badd, (int)NX);
    T_CHECK(bad == 0, "xrsqrt: %d of %d roots differ from sn_isqrt64 rounded", bad, (int)NX);
    for (i = 0; i < NU; i++) {
        int32_t c[3];
        int k;
        for (k = 0; k < 3; k++) {
            const unsigned b = 1u + rnd32() % 32u;
            const int32_t m = (int32_t)(rnd32() >> (32u - b) >> 1);
            c[k] = (i % 8 == 0 && rnd32() % 2u) ? edge[rnd32() % 8u] : (rnd32() % 2u ? -m : m);
        }
        if (i == 1) c[0] = c[1] = c[2] = 0;
        if (i >= 8 && i < 8 + (int)(sizeof fixed_c / sizeof fixed_c[0])) { /* every lane position of 4 by 9 cases */
            c[0] = fixed_c[i - 8][0]; c[1] = fixed_c[i - 8][1]; c[2] = fixed_c[i - 8][2];
        }
        u[i].x = c[0]; u[i].y = c[1]; u[i].z = c[2];
    }
    {   /* the corrections' cases, searched: (R, s, t) with s^2 + t^2 = R or R + 1 (n2 = R^2 + R or R^2 + R + 1:
         * the root just below / above R + 1/2, where the double root rounds either way), and sums of
         * root N with (2^62 + N/2) mod N within 2^9 of 0 or N (the quotient just above / below an
         * integer, where the double quotient rounds either way) */
        /* odd N in (2^30, 2^31) with N m within 2^9 of 2^63 - 1 or 2^63 (m odd; from the factors of
         * 2^63 - 1 - j and 2^63 + j): (2^62 + (N - 1)/2) mod N below 2^9 (the first 8) or above N - 2^9 */
        static const int32_t qcase[16] = {1531366081, 1532540863, 1225939123, 1504703107, 1264933055, 1484782557,
            1694163963, 1347379551, 1427172271, 1167439457, 1580102845, 1723668343, 1783671063, 1263447831, 1684652439,
            1174172955};
        int found = 0, tries = 0;
        for (i = 64; found < 32 && tries < 4000000; tries++) {
            const uint64_t R = ((uint64_t)1 << 30) + rnd32() % ((uint64_t)1 << 30);
            if (found < 16) {
                const uint64_t w = R + (uint64_t)(found & 1), sq = sn_isqrt64(w), rest = w - sq * sq, t = sn_isqrt64(rest);
                if (t * t != rest) continue;
                u[i].x = (int32_t)R; u[i].y = (int32_t)sq; u[i].z = (int32_t)t;
            } else { /* (a0, a1, a2) of root N, a0 >= 2^30 (no scaling), one a_i r + 2^31 within a_i of a multiple
                      * of 2^32 (so r - 1 or r + 1 changes that output) */
                const uint64_t N = (uint64_t)qcase[found - 16], Q = (((uint64_t)1 << 62) + (N >> 1)) / N;
                const uint64_t a1 = rnd32() % (N / 2), a2 = rnd32() % 4096u, a0 = sn_isqrt64(N * N - a1 * a1 - a2 * a2);
                const uint64_t n2 = a0 * a0 + a1 * a1 + a2 * a2, f0 = sn_isqrt64(n2), Nn = f0 + (n2 - f0 * f0 > f0);
                const uint64_t m0 = (a0 * Q + ((uint64_t)1 << 31)) & 0xFFFFFFFFu, m1 = (a1 * Q + ((uint64_t)1 << 31)) & 0xFFFFFFFFu;
                if (Nn != N || a0 < ((uint64_t)1 << 30) || !(m0 < a0 || m0 >= ((uint64_t)1 << 32) - a0 || m1 < a1 || m1 >= ((uint64_t)1 << 32) - a1))
                    continue;
                u[i].x = (found & 2) ? -(int32_t)a0 : (int32_t)a0; u[i].y = (int32_t)a1; u[i].z = (found & 4) ? -(int32_t)a2 : (int32_t)a2;
            }
            found++; i += 1 + (found % 3); /* across the lanes */
        }
        T_CHECK(found == 32, "xunit: %d of 32 correction cases found", found);
    }
    memcpy(v, u, sizeof u);
    sn_k_xunit(u, NU);
    for (i = 0; i < NU; i++) {
        sn_q q[4];
        q[0] = v[i].x; q[1] = v[i].y; q[2] = v[i].z; q[3] = 0;
        if (q[0] == 0 && q[1] == 0 && q[2] == 0) q[2] = SN_ONE_ROT; /* sn_get_normals' zero sum */
        else sn_qnormalize(q);
        badu += u[i].x != q[0] || u[i].y != q[1] || u[i].z != q[2];
    }
    T_CHECK(badu == 0, "xunit: %d of %d unit normals differ from sn_qnormalize's", badu, (int)NU);
    T_CHECK(u[1].x == 0 && u[1].y == 0 && u[1].z == SN_ONE_ROT, "xunit: the zero sum gives (0, 0, 2^30)");
    T_FIGURE("fixed normals' unit step: %d rounded roots, %d unit vectors bit for bit", (int)NX, (int)NU);
}
#endif

/* sn_k_surf1 (sn_get_surface's vertex: AVX2 the corners in lanes and
 * gathers) against sn_k_surf1_ref: 20,000 vertices, t random in [0, 32768]
 * with the edges 0 and 32768 every 8th, corner ids random in a 64-vertex
 * array (repeats allowed), positions random within the state bound
 * (fixed +-2^28, every 4th vertex at +-2^28 exactly; float +-1e3 and,
 * every 4th, +-2^20 with signed zeros). Tolerance 0: fixed, exact int64
 * sums; float, the same products summed in the same order. */
static void test_surf1(void) {
    static sn_q pos[3 * 64];
    unsigned char cell[16];
    int i, bad = 0;
    for (i = 0; i < 20000; i++) {
        uint32_t t[3];
        sn_acc a[3], r[3];
        int k;
        for (k = 0; k < 3 * 64; k++) {
#if defined(SN_FLOAT)
            pos[k] = i % 4 == 0 ? (float)(rnd32() % 3u) * ((rnd32() & 1) ? 1048576.0f : -1048576.0f) * ((rnd32() % 5u) ? 1.0f : -0.0f)
                                : (float)rnd_in(1 << 20) / 1024.0f;
#else
            pos[k] = i % 4 == 0 ? ((rnd32() & 1) ? SN_LIM : -SN_LIM) : rnd_in(SN_LIM);
#endif
        }
        for (k = 0; k < 8; k++) { const uint32_t v = rnd32() % 64u; cell[2 * k] = (unsigned char)v; cell[2 * k + 1] = 0; }
        for (k = 0; k < 3; k++) t[k] = i % 8 == 0 ? ((rnd32() & 1) ? 32768u : 0u) : rnd32() % 32769u;
        sn_k_surf1(t, cell, pos, a);
        sn_k_surf1_ref(t, cell, pos, r);
        bad += memcmp(a, r, sizeof a) != 0;
    }
    T_CHECK(bad == 0, "surf1: %d of 20000 vertices differ from the reference", bad);
}

/* sn_k_ct8 (the contact rows' point, sn_contact.c: AVX2 the corners in
 * lanes, masked gathers) against sn_k_ct8_ref: 20,000 points, t as in
 * test_surf1, corner ids random below 64 with nF random in 0..64 (free,
 * skeleton and mixed cells), every array random within the state's range
 * (fixed: int32, every 4th entry at +-SN_LIM or the int32 extremes; float:
 * +-1e3 and, every 4th, +-2^20 with signed zeros). Tolerance 0: phi, fw,
 * sp and sv bit for bit (fixed: exact int64 sums; float: the same products
 * summed in the same order, +0 for the skeleton corners' fw terms). */
static void test_ct8(void) {
    static sn_q pos[3 * 64], pst[3 * 64], vel[3 * 64], vpre[3 * 64];
    sn_q *arr[4];
    int i, bad = 0, mixed = 0;
    arr[0] = pos; arr[1] = pst; arr[2] = vel; arr[3] = vpre;
    for (i = 0; i < 20000; i++) {
        uint32_t t[3], nF = rnd32() % 65u, nfree = 0;
        uint16_t vx[8];
        sn_q pa[8], pr[8];
        sn_acc fa, fr, sa[3], sr[3], va[3], vr[3];
        int k, j;
        for (j = 0; j < 4; j++)
            for (k = 0; k < 3 * 64; k++) {
#if defined(SN_FLOAT)
                arr[j][k] = i % 4 == 0 ? (float)(rnd32() % 3u) * ((rnd32() & 1) ? 1048576.0f : -1048576.0f) * ((rnd32() % 5u) ? 1.0f : -0.0f)
                                       : (float)rnd_in(1 << 20) / 1024.0f;
#else
                arr[j][k] = i % 4 == 0 ? ((rnd32() & 1) ? ((rnd32() & 1) ? SN_LIM : INT32_MAX) : ((rnd32() & 1) ? -SN_LIM : INT32_MIN))
                                       : rnd_in(SN_LIM);
#endif
            }
        for (k = 0; k < 8; k++) { vx[k] = (uint16_t)(rnd32() % 64u); nfree += vx[k] < nF; }
        mixed += nfree > 0 && nfree < 8;
        for (k = 0; k < 3; k++) t[k] = i % 8 == 0 ? ((rnd32() & 1) ? 32768u : 0u) : rnd32() % 32769u;
        /* pst is indexed by v - nF < 64 - nF: within the array */
        sn_k_ct8(t, vx, nF, pos, pst, vel, vpre, pa, &fa, sa, va);
        sn_k_ct8_ref(t, vx, nF, pos, pst, vel, vpre, pr, &fr, sr, vr);
        bad += memcmp(pa, pr, sizeof pa) != 0 || memcmp(&fa, &fr, sizeof fa) != 0 || memcmp(sa, sr, sizeof sa) != 0 ||
               memcmp(va, vr, sizeof va) != 0;
    }
    T_CHECK(bad == 0, "ct8: %d of 20000 contact points differ from the reference", bad);
    T_CHECK(mixed > 10000, "ct8: %d of 20000 cells mix free and skeleton corners (want most)", mixed);
}

/* sn_k_cell_mul2 against the independent reference itself (not only
 * against two sn_k_cell_mul calls: on the M4 both are assembly): 2000
 * random records (every 8th at the bounds), corner 0's operands 0 (the
 * contract), the others random, at +-2^28 (the state bound) or, every 4th
 * record, INT32_MIN / INT32_MAX (beyond the contract, still exact: 21
 * products < 2^27 2^31 sum below 2^62.4, and row_ok's halves stay exact);
 * l1 every row, l2 the rows of a random corner set. Fixed: tolerance 0. */
static void test_mul2_ref(void) {
    static unsigned char K[REC];
    double S[24][24];
    int t, bad = 0, rows = 0;
    for (t = 0; t < 2000; t++) {
        sn_q u1[24], u2[24];
        sn_acc l1[24], l2[24];
        uint32_t k, mask = t % 5 == 0 ? 0xFFu : rnd32() & 0xFFu;
        make_rec(K, S, t % 8 == 0);
        for (k = 0; k < 24; k++) {
#if defined(SN_FLOAT)
            u1[k] = (float)rnd_in(1 << 20) / 256.0f;
            u2[k] = (float)rnd_in(1 << 20) / 256.0f;
#else
            if (t % 4 == 1) {
                u1[k] = rnd32() & 1 ? INT32_MAX : INT32_MIN;
                u2[k] = rnd32() & 1 ? INT32_MAX : INT32_MIN;
            } else if (t % 4 == 2) {
                u1[k] = rnd32() & 1 ? (1 << 28) : -(1 << 28);
                u2[k] = rnd32() & 1 ? (1 << 28) : -(1 << 28);
            } else {
                u1[k] = rnd_in(1 << 28);
                u2[k] = rnd_in(1 << 28);
            }
#endif
        }
        u1[0] = u1[1] = u1[2] = u2[0] = u2[1] = u2[2] = 0;
        sn_k_cell_mul2(K, u1, u2, l1, l2, mask);
        for (k = 0; k < 24; k++) {
            bad += !row_ok(S, u1, (int)k, l1[k]);
            rows++;
            if (mask >> (k / 3) & 1u) {
                bad += !row_ok(S, u2, (int)k, l2[k]);
                rows++;
            }
        }
    }
    T_CHECK(bad == 0, "sn_k_cell_mul2 (path %s): %d of %d rows off the reference", sn_kernels_name(), bad, rows);
    T_FIGURE("sn_k_cell_mul2 against the reference: 2000 records, %d rows (operands at +-2^28 and INT32_MIN/MAX)", rows);
}

int main(void) {
    static unsigned char K[REC];
    double S[24][24];
    int t, bad_full = 0, bad_list = 0, bad_two = 0, lists = 0, bad_order = 0;
    printf("cell product kernels (%s flavour, path %s)\n", SN_FLAVOUR ? "float" : "fixed", sn_kernels_name());
    rng = (uint32_t)T_SEED();
    for (t = 0; t < 4000; t++) {
        static const uint8_t all8[8] = {0, 1, 2, 3, 4, 5, 6, 7};
        sn_q u[24], u2[24], uc[24], uz[24];
        sn_acc l[24], l0[24], l2[24], lm1[24], lm2[24], lc[24], lz[24];
        uint8_t fc[8];
        uint32_t nf = 0, k, c, mask = rnd32() & 0xFFu;
        int extreme = t % 16 == 0, r;
        make_rec(K, S, extreme);
        for (k = 0; k < 24; k++) {
#if defined(SN_FLOAT)
            u[k] = (float)rnd_in(1 << 20) / 256.0f;
            u2[k] = (float)rnd_in(1 << 20) / 256.0f;
#else
            u[k] = extreme ? (rnd32() & 1 ? (1 << 28) : -(1 << 28)) : rnd_in(1 << 28);
            u2[k] = rnd_in(1 << 28);
#endif
        }
        sn_k_cell_mul(K, all8, 8, u, l);
        for (r = 0; r < 24; r++) bad_full += !row_ok(S, u, r, l[r]);
#if defined(SN_FLOAT)
        {
            float lo[24];
            order_ref(K, u, lo);
            bad_order += memcmp(lo, l, sizeof lo) != 0;
        }
#endif
        /* two products at once = two calls (corner 0's operands 0, the contract) */
        {
            sn_q u0[24];
            memcpy(u0, u, sizeof u0);
            u0[0] = u0[1] = u0[2] = u2[0] = u2[1] = u2[2] = 0;
            sn_k_cell_mul(K, all8, 8, u0, l0);
            sn_k_cell_mul2(K, u0, u2, lm1, lm2, 0xFFu);
            sn_k_cell_mul(K, all8, 8, u2, l2);
            bad_two += memcmp(lm1, l0, sizeof l0) != 0 || memcmp(lm2, l2, sizeof l2) != 0;
            /* l2 only at the rows of a random corner set (the rhs's free corners) */
            sn_k_cell_mul2(K, u0, u2, lm1, lm2, mask);
            bad_two += memcmp(lm1, l0, sizeof l0) != 0;
            for (k = 0; k < 8; k++)
                if (mask >> k & 1u) bad_two += memcmp(lm2 + 3 * k, l2 + 3 * k, 3 * sizeof l2[0]) != 0;
        }
        /* listed corners = the full product with zero operands at the others */
        for (k = 0; k < 8; k++) {
            if (mask >> k & 1u) {
                fc[nf] = (uint8_t)k;
                for (c = 0; c < 3; c++) uc[3 * nf + c] = uz[3 * k + c] = u[3 * k + c];
                nf++;
            } else
                for (c = 0; c < 3; c++) uz[3 * k + c] = 0;
        }
        if (nf == 0) continue;
        lists++;
        sn_k_cell_mul(K, fc, nf, uc, lc);
        sn_k_cell_mul(K, all8, 8, uz, lz);
        for (k = 0; k < nf; k++)
            for (c = 0; c < 3; c++) bad_list += memcmp(&lc[3 * k + c], &lz[3 * fc[k] + c], sizeof lc[0]) != 0;
    }
    T_CHECK(bad_full == 0, "%d of 96000 rows of the full product off the reference", bad_full);
    T_CHECK(bad_two == 0, "sn_k_cell_mul2 (all rows, then a random row set) differs from two calls in %d of 8000 cases", bad_two);
    T_CHECK(bad_list == 0, "free-corner product differs from the zero-padded full product in %d rows (%d lists)", bad_list, lists);
#if defined(SN_FLOAT)
    T_CHECK(bad_order == 0, "float cell product (path %s): %d of 4000 cells differ from the reference order's floats",
            sn_kernels_name(), bad_order);
#else
    (void)bad_order;
#endif
    T_FIGURE("4000 random cells (every 16th at the bounds), %d free-corner lists", lists);
    test_mul2_ref();
    test_ic();
    test_ic_rows();
#if defined(SN_K_IC_FWD_COL)
    test_ic_fwd();
#endif
#if defined(SN_K_IC_VTX)
    test_ic_vtx();
#endif
#if defined(SN_K_IC_FWD_RUN)
    test_ic_fwd_run();
#endif
#if defined(SN_K_ENERGY24)
    test_energy24();
#endif
#if defined(SN_KERNELS_AVX2) || defined(SN_KERNELS_FAVX2)
    test_ic_fused();
#endif
#if !defined(SN_FLOAT)
    test_out_edges();
    test_vec_edges();
    test_quat_words();
#endif
#if defined(SN_K_MASS_FF)
    test_mass_ff();
#endif
#if defined(SN_K_MASS_SK)
    test_mass_sk();
#endif
#if defined(SN_K_CELL_STIFF)
    test_cell_stiff();
#endif
#if defined(SN_K_CORNER0)
    test_corner_c0();
#endif
#if defined(SN_K_SKEL)
    test_skeleton();
#endif
#if defined(SN_K_RIG)
    test_rig();
#endif
#if defined(SN_K_FREE8)
    test_free8();
    test_out_rot2();
#endif
#if defined(SN_K_FRHS)
    test_frhs_flat();
    test_mass_rhs();
    test_grav_rhs();
    test_fdot();
#endif
#if defined(SN_K_CORNERS)
    test_corners();
#endif
#if defined(SN_K_ENERGY)
    test_energy();
#endif
    test_rot();
    test_axpy();
    test_isqrt();
    test_udiv64();
    test_surf1();
    test_ct8();
#if !defined(SN_FLOAT)
    test_xnorm();
    test_rshr();
    test_trig();
    test_slerp();
    test_dot();
    test_seg_clamps();
    test_seg_move_ops();
    test_seg_move();
    test_seg_star_fixed();
    test_seg_sheet();
    test_mul_out();
#endif
#if defined(SN_FLOAT)
    test_seg_star();
#endif
    test_loops();
    return T_END();
}
