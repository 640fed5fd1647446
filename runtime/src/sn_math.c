/* sn_math.c -- integer (or float) square root, quaternions, sin/cos/atan2.
 *
 * No libm in either flavour: every function below uses a fixed number of
 * iterations / polynomial terms, so its cost does not depend on the data.
 * Fixed flavour: quaternion components and rotation entries are Q30
 * (1.0 = 2^30), angles inside this file are Q30 radians; all rounding is to
 * nearest (sn_rshr64: ties toward +infinity; sn_unit and sn_quat_rotate
 * round magnitudes: ties away from zero); no signed overflow for ANY int32
 * input (inputs that cannot be unit are clamped first, as documented per
 * function). Error figures below are measured against libm in double by
 * tests/test_runtime_math.c.
 */
#include "sn_internal.h"

/* floor(n / D) for 0 < D <= 2^62: on a 32-bit core, restoring division over
 * the 64 bits of n with no data-dependent branch (libgcc's 64-bit divide is
 * neither constant-time nor available everywhere); the remainder stays below
 * D, so shifting it left never overflows. */
uint64_t sn_udiv64(uint64_t n, uint64_t D) {
#if UINTPTR_MAX > 0xFFFFFFFFu /* a 64-bit target divides in one instruction: the same quotient */
    return n / D;
#else
    uint64_t q = 0, r = 0;
    int i;
    for (i = 63; i >= 0; i--) {
        uint64_t ge;
        r = (r << 1) | ((n >> i) & 1u);
        ge = (uint64_t)(r >= D);
        r -= D & (0 - ge);
        q |= ge << i;
    }
    return q;
#endif
}

/* floor(sqrt(x)) for every uint64 x, exact, by two-bit digits (same code
 * in both flavours, 32 fixed steps): after the top 2j bits X of x,
 * y = floor(sqrt(X)) and r = X - y^2 <= 2y, so the remainder and the trial
 * 4y + 1 stay below 2^32 for 30 steps (y < 2^29 before the 30th); only the
 * last two take 64-bit words. A 32-bit core (Cortex-M4): 12 instructions a
 * step against ~16 for a 64-bit bit loop (a 64-bit target takes the
 * Karatsuba root below). */
uint32_t sn_isqrt64_digits(uint64_t x) {
    uint32_t w = (uint32_t)(x >> 32), y = 0, r = 0, t;
    uint64_t r2;
    int i, j;
    for (j = 0; j < 2; j++) {
        for (i = j ? 14 : 16; i > 0; i--) {
            r = (r << 2) | (w >> 30); /* the next two bits of x */
            w <<= 2;
            t = (y << 2) | 1u;
            y <<= 1;
            if (r >= t) { r -= t; y |= 1u; }
        }
        if (!j) w = (uint32_t)x;
    }
    r2 = r;
    for (i = 0; i < 2; i++) {
        uint64_t t2 = ((uint64_t)y << 2) | 1u;
        r2 = (r2 << 2) | (w >> 30);
        w <<= 2;
        y <<= 1;
        if (r2 >= t2) { r2 -= t2; y |= 1u; }
    }
    return y;
}

/* leading zero bits of a nonzero uint32 (one CLZ on ARMv7-M) */
SN_INLINE int lz32(uint32_t w) {
#if defined(__GNUC__)
    return __builtin_clz(w);
#else
    int n = 0, s;
    for (s = 16; s > 0; s >>= 1)
        if (!(w >> (32 - s))) { n += s; w <<= s; }
    return n;
#endif
}

/* floor(sqrt(x)) for every uint64 x, exact, by Zimmermann's Karatsuba
 * square root (P. Zimmermann, "Karatsuba Square Root", INRIA RR-3805, 1999,
 * Algorithm SqrtRem) on a 32-bit core with a 32-bit divider (Cortex-M4
 * UDIV; sn_isqrt64 there: 88 instructions against the digits' 393).
 * x 4^k = N, N's top two bits not both 0, so floor(sqrt(x)) =
 * floor(sqrt(N)) >> k. From (s, r) = root and remainder of N's top w bits
 * (r = P - s^2 <= 2s), the top 2w bits P b^2 + a1 b + a0 (b = 2^(w/2)):
 * q, u = divrem(r b + a1, 2s); s' = s b + q; r' = u b + a0 - q^2, one
 * correction if r' < 0 (r' += 2s' - 1, s' -= 1): the normalization P >=
 * 2^(w-2) (the paper's a3 >= b/4) bounds it to one. Widths 4 (s = 2 or 3),
 * 8, 16, 32 in 32-bit words (r b + a1 < 2^17), the last to 64 with the
 * root and no remainder: r b + a1 < 2^33 is halved before the divide
 * (floor(n / 2s) = floor(floor(n / 2) / s)), and the root may be 2^32
 * before its correction (uint32 arithmetic mod 2^32: the result < 2^32 is
 * right). Fixed steps; the corrections are selects. */
uint32_t sn_isqrt64_kara(uint64_t x) {
    uint32_t hi = (uint32_t)(x >> 32), lo = (uint32_t)x, s, r, a;
    int k;
    if (!(hi | lo)) return 0;
    k = (hi ? lz32(hi) : 32 + lz32(lo)) >> 1;
    if (k >= 16) { hi = lo << (2 * k - 32); lo = 0; }
    else if (k > 0) { hi = hi << 2 * k | lo >> (32 - 2 * k); lo <<= 2 * k; }
    a = hi >> 28; /* >= 4 */
    s = 2u + (a >= 9u);
    r = a - s * s;
    /* root of hi's top 2h bits -> of its top 4h; written out for constant
     * shifts (a loop: ~40 more instructions a call) */
#define SN_KARA_STEP(h) do { \
        const uint32_t A = (hi >> (32 - 4 * (h))) & ((1u << 2 * (h)) - 1u), num = r << (h) | A >> (h); \
        const uint32_t q = num / (2u * s), u = num - q * 2u * s; \
        const int32_t rr = (int32_t)(u << (h) | (A & ((1u << (h)) - 1u))) - (int32_t)(q * q); \
        s = (s << (h)) + q; \
        r = (uint32_t)(rr < 0 ? rr + (int32_t)(2u * s) - 1 : rr); \
        s -= (uint32_t)(rr < 0); \
    } while (0)
    SN_KARA_STEP(2);
    SN_KARA_STEP(4);
    SN_KARA_STEP(8);
#undef SN_KARA_STEP
    {   /* the low word: s in [2^15, 2^16), r <= 2s */
        const uint32_t nh = r << 15 | lo >> 17, q = nh / s, u = 2u * (nh - q * s) + (lo >> 16 & 1u);
        const uint32_t root = (s << 16) + q - (uint32_t)(((uint64_t)u << 16 | (lo & 0xFFFFu)) < (uint64_t)q * q);
        return root >> k;
    }
}

/* floor(sqrt(x)): Karatsuba where a 32-bit divide is an instruction (a
 * 64-bit target, the M4's UDIV; x86-64 cow_fem: ~90 instructions a root
 * against the 64-bit bit loop's ~245, 21 k a step), else the digits. */
uint32_t sn_isqrt64(uint64_t x) {
#if UINTPTR_MAX > 0xFFFFFFFFu || (defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && defined(__ARM_FEATURE_IDIV))
    return sn_isqrt64_kara(x);
#else
    return sn_isqrt64_digits(x);
#endif
}

/* Messages from the one status list in sinew.h. A switch rather than a
 * pointer table: no relocated data (.data.rel.ro), strings stay in ROM. */
const char *sn_status_str(sn_status s) {
    switch (s) {
#define SN_STATUS_CASE_(name, msg) case name: return msg;
        SN_STATUS_LIST(SN_STATUS_CASE_)
#undef SN_STATUS_CASE_
    default: break;
    }
    return "unknown status code";
}

#if !defined(SN_FLOAT)
/* ======================= fixed flavour ======================= */

#define SN_Q30 ((int64_t)1 << 30)
#define SN_PI_2_Q30 ((int64_t)1686629713) /* pi/2 * 2^30 */
#define SN_PI_4_Q30 ((int64_t)843314857)  /* pi/4 * 2^30 */
#define SN_COS30_Q30 ((int64_t)929887697) /* cos(30 deg) * 2^30 */

/* Round-to-nearest right shift for any int64 except INT64_MIN (magnitude in
 * uint64, so also valid above the 2^62 bound of sn_rshr64). */
static int64_t sn_rshr_any(int64_t x, int s) {
    uint64_t m = x < 0 ? (uint64_t)0 - (uint64_t)x : (uint64_t)x;
    m = (m + ((uint64_t)1 << (s - 1))) >> s;
    return x < 0 ? -(int64_t)m : (int64_t)m;
}

static int64_t sn_clamp64(int64_t x, int64_t lim) {
    return x > lim ? lim : (x < -lim ? -lim : x);
}

/* Saturate to the int32 range (symmetric, +-(2^31-1)). */
static int32_t sn_sat32(int64_t x) {
    return (int32_t)sn_clamp64(x, (int64_t)INT32_MAX);
}

/* Number of significant bits of x (0 for 0); 6 fixed steps (Cortex-M:
 * CLZ on a word). */
static int sn_bitlen64(uint64_t x) {
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && defined(__GNUC__)
    const uint32_t hi = (uint32_t)(x >> 32), lo = (uint32_t)x;
    return hi ? 64 - lz32(hi) : (lo ? 32 - lz32(lo) : 0);
#elif defined(__GNUC__) && UINTPTR_MAX > 0xFFFFFFFFu
    return x ? 64 - __builtin_clzll(x) : 0; /* one LZCNT / BSR / CLZ */
#else
    int n = 0, s;
    for (s = 32; s > 0; s >>= 1)
        if (x >> s) {
            x >>= s;
            n += s;
        }
    return n + (x != 0);
#endif
}

/* out = c/|c| in Q30 for n <= 4 components (any int64 except INT64_MIN).
 * Returns 0 (out untouched) for the zero vector.
 * Scaling: magnitudes are first shifted so the largest lies in [2^30, 2^31)
 * (truncating right shift only when it has more than 31 significant bits),
 * so the sum of squares fits uint64; |c| = isqrt rounded to nearest;
 * one division 2^62/|c|, then a multiply per component.
 * Error: <= 1.5 LSB per component (test: <= 2). |out_i| <= 2^30. */
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
/* Cortex-M: the same arithmetic in 32-bit words where the values fit: the
 * bit length of the OR of the magnitudes (that of their maximum, no 64-bit
 * compares), the scaled magnitudes (< 2^31) as uint32, so the squares are
 * UMULL/UMLAL and a r a UMULL (r = 2^32 exactly gives a itself). The same
 * integers. */
static int sn_unit(const int64_t *c, int n, int32_t *out) {
    uint64_t a64[4], m = 0, n2 = 0, N, r;
    uint32_t a[4];
    int i, b;
    for (i = 0; i < n; i++) {
        a64[i] = c[i] < 0 ? (uint64_t)0 - (uint64_t)c[i] : (uint64_t)c[i];
        m |= a64[i];
    }
    if (m == 0) return 0;
    b = sn_bitlen64(m);
    for (i = 0; i < n; i++) {
        a[i] = b > 31 ? (uint32_t)(a64[i] >> (b - 31)) : (uint32_t)a64[i] << (31 - b); /* < 2^31 */
        n2 += (uint64_t)a[i] * a[i];
    }
    N = sn_isqrt64(n2);
    if (n2 - N * N > N) N++;
    if (N <= ((uint64_t)1 << 30)) {
        for (i = 0; i < n; i++) out[i] = c[i] < 0 ? -(int32_t)a[i] : (int32_t)a[i]; /* r = 2^32 */
        return 1;
    }
    if (N >= ((uint64_t)1 << 32)) r = (uint64_t)1 << 30;
    else {
        int s = N < ((uint64_t)1 << 31) ? 1 : 0;
        r = sn_div64n((((uint64_t)1 << 62) + (N >> 1)) << s, (uint32_t)(N << s));
    }
    for (i = 0; i < n; i++) {
        const uint32_t v = (uint32_t)(((uint64_t)a[i] * (uint32_t)r + ((uint64_t)1 << 31)) >> 32); /* r < 2^32 */
        out[i] = c[i] < 0 ? -(int32_t)v : (int32_t)v;
    }
    return 1;
}
#else
/* inline: each caller's constant n unrolls the loops (x86-64 cow_fem: the
 * fixed normals -13%, the step's 137 slerps -14 k instructions) */
SN_INLINE int sn_unit(const int64_t *c, int n, int32_t *out) {
    uint64_t a[4], m = 0, n2 = 0, N, r;
    int i, b;
    for (i = 0; i < n; i++) {
        a[i] = c[i] < 0 ? (uint64_t)0 - (uint64_t)c[i] : (uint64_t)c[i];
        if (a[i] > m) m = a[i];
    }
    if (m == 0) return 0;
    b = sn_bitlen64(m);
    for (i = 0; i < n; i++) {
        if (b > 31) a[i] >>= (b - 31);
        else a[i] <<= (31 - b);
        n2 += a[i] * a[i]; /* each < 2^62, n <= 4: < 2^64 */
    }
    N = sn_isqrt64(n2);
    if (n2 - N * N > N) N++;  /* round: sqrt(n2) > N + 1/2 */
    /* r = (2^62 + N/2) / N for N in [2^30, 2^32]: 2^32 at N = 2^30, 2^30 at
     * N = 2^32, else below 2^32: a 64/32 division with N normalized (no
     * library 64-bit divide on a 32-bit core), the same quotient */
    if (N <= ((uint64_t)1 << 30)) r = (uint64_t)1 << 32;
    else if (N >= ((uint64_t)1 << 32)) r = (uint64_t)1 << 30;
    else {
        int s = N < ((uint64_t)1 << 31) ? 1 : 0;
        r = sn_div64n((((uint64_t)1 << 62) + (N >> 1)) << s, (uint32_t)(N << s));
    }
    for (i = 0; i < n; i++) {
        uint64_t v = (a[i] * r + ((uint64_t)1 << 31)) >> 32; /* a*r < 2^63 */
        out[i] = c[i] < 0 ? -(int32_t)v : (int32_t)v;
    }
    return 1;
}
#endif

/* Normalize q in place (Q30). Zero quaternion -> identity (0,0,0,1).
 * Any int32 input; error <= 1.5 LSB per component. */
void sn_qnormalize(sn_q q[4]) {
    int64_t c[4];
    int i;
    for (i = 0; i < 4; i++) c[i] = q[i];
    if (!sn_unit(c, 4, q)) {
        q[0] = q[1] = q[2] = 0;
        q[3] = (int32_t)SN_Q30;
    }
}

/* Row-major rotation matrix of a unit quaternion, Q30 in and out.
 * Components are clamped to +-2^30 (a unit quaternion's range), so every
 * product is <= 2^60 and no sum overflows; entries are rounded from Q60
 * (error <= 0.5 LSB for the given q) and clamped to +-2^30. */
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
/* Cortex-M: the clamp in int32 and the products 32 x 32 -> 64 (one SMULL
 * each; GCC multiplied the clamped int64 as 64 x 64 bits, three
 * multiplies): the same products */
static int32_t sn_clamp30(int32_t v) {
    return v > (int32_t)SN_Q30 ? (int32_t)SN_Q30 : (v < -(int32_t)SN_Q30 ? -(int32_t)SN_Q30 : v);
}
#define SN_QC_(v) sn_clamp30(v)
#define SN_QM_(a, b) sn_mul((a), (b))
typedef int32_t sn_qc_t_;
#else
#define SN_QC_(v) sn_clamp64((v), SN_Q30)
#define SN_QM_(a, b) ((a) * (b))
typedef int64_t sn_qc_t_;
#endif
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
/* clamp(s >> 29, +-2^30) in 32-bit words, s holding the rounding term
 * (|s| < 2^62): the low word of the shifted value and, for the clamp's
 * test, its high word (sn_k_out_w's form) */
SN_INLINE int32_t sn_r29c(int64_t s) {
    const int32_t hi0 = (int32_t)(s >> 32);
    const uint32_t lo = ((uint32_t)s >> 29) | ((uint32_t)hi0 << 3);
    const int32_t hi = hi0 >> 29;
    if (lo + (uint32_t)SN_Q30 <= 2u * (uint32_t)SN_Q30 && hi == (int32_t)lo >> 31) return (int32_t)lo;
    return hi < 0 ? -(int32_t)SN_Q30 : (int32_t)SN_Q30;
}
/* Cortex-M: each entry one SMLAL chain from its rounding term (the
 * diagonal's 2^30 - round(a / 2^29) as -round((a - 2^59) / 2^29): 2^59 is a
 * multiple of 2^29, the clamp symmetric), clamped in words: the same
 * integers as below */
void sn_qtomat(const sn_q q[4], sn_q R[9]) {
    const int32_t x = sn_clamp30(q[0]), y = sn_clamp30(q[1]), z = sn_clamp30(q[2]), w = sn_clamp30(q[3]);
    const int64_t b = (int64_t)1 << 28, bd = b - ((int64_t)1 << 59);
    R[0] = -sn_r29c(bd + sn_mul(y, y) + sn_mul(z, z));
    R[1] = sn_r29c(b + sn_mul(x, y) + sn_mul(-z, w));
    R[2] = sn_r29c(b + sn_mul(x, z) + sn_mul(y, w));
    R[3] = sn_r29c(b + sn_mul(x, y) + sn_mul(z, w));
    R[4] = -sn_r29c(bd + sn_mul(x, x) + sn_mul(z, z));
    R[5] = sn_r29c(b + sn_mul(y, z) + sn_mul(-x, w));
    R[6] = sn_r29c(b + sn_mul(x, z) + sn_mul(-y, w));
    R[7] = sn_r29c(b + sn_mul(y, z) + sn_mul(x, w));
    R[8] = -sn_r29c(bd + sn_mul(x, x) + sn_mul(y, y));
}
#else
void sn_qtomat(const sn_q q[4], sn_q R[9]) {
    sn_qc_t_ x = SN_QC_(q[0]), y = SN_QC_(q[1]);
    sn_qc_t_ z = SN_QC_(q[2]), w = SN_QC_(q[3]);
    int64_t xx = SN_QM_(x, x), yy = SN_QM_(y, y), zz = SN_QM_(z, z), xy = SN_QM_(x, y), xz = SN_QM_(x, z), yz = SN_QM_(y, z);
    int64_t xw = SN_QM_(x, w), yw = SN_QM_(y, w), zw = SN_QM_(z, w);
    int64_t e[9];
    int k;
    e[0] = SN_Q30 - sn_rshr64(yy + zz, 29);
    e[1] = sn_rshr64(xy - zw, 29);
    e[2] = sn_rshr64(xz + yw, 29);
    e[3] = sn_rshr64(xy + zw, 29);
    e[4] = SN_Q30 - sn_rshr64(xx + zz, 29);
    e[5] = sn_rshr64(yz - xw, 29);
    e[6] = sn_rshr64(xz - yw, 29);
    e[7] = sn_rshr64(yz + xw, 29);
    e[8] = SN_Q30 - sn_rshr64(xx + yy, 29);
    for (k = 0; k < 9; k++) R[k] = (int32_t)sn_clamp64(e[k], SN_Q30);
}
#endif

/* Hamilton product out = a*b, Q30. Inputs clamped to +-2^30 (sums of four
 * Q60 products <= 2^62), each output rounded (<= 0.5 LSB for the clamped
 * inputs) and saturated to int32. Not renormalized: the product of two unit
 * quaternions is unit within ~2 LSB. */
void sn_qmul(const sn_q a[4], const sn_q b[4], sn_q out[4]) {
    int64_t ax = sn_clamp64(a[0], SN_Q30), ay = sn_clamp64(a[1], SN_Q30);
    int64_t az = sn_clamp64(a[2], SN_Q30), aw = sn_clamp64(a[3], SN_Q30);
    int64_t bx = sn_clamp64(b[0], SN_Q30), by = sn_clamp64(b[1], SN_Q30);
    int64_t bz = sn_clamp64(b[2], SN_Q30), bw = sn_clamp64(b[3], SN_Q30);
    out[0] = sn_sat32(sn_rshr64(aw * bx + ax * bw + ay * bz - az * by, 30));
    out[1] = sn_sat32(sn_rshr64(aw * by - ax * bz + ay * bw + az * bx, 30));
    out[2] = sn_sat32(sn_rshr64(aw * bz + ax * by - ay * bx + az * bw, 30));
    out[3] = sn_sat32(sn_rshr64(aw * bw - ax * bx - ay * by - az * bz, 30));
}

/* sin and cos of (quad*pi/2 + r), r Q30 radians with |r| <= ~pi/4.
 * Taylor polynomials to r^11 / r^12 (truncation < 1e-11), Horner in Q30
 * with rounding: error <= ~1.5 LSB (Q30). */
static void sn_sincos_red(int64_t r, int quad, int64_t *s, int64_t *c) {
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
    /* Cortex-M: the same integers in int32 operands (SMULL, not GCC's
     * 64 x 64 multiply): |r| <= pi/4 2^30 (both callers reduce to it), so
     * u < 2^30 and every Horner value (sin r / r, cos r, partial sums of
     * the alternating series) stays below 2^31 */
    static const int32_t ks[6] = {SN_Q30, -178956971, 8947849, -213044, 2959, -27};
    static const int32_t kc[7] = {SN_Q30, -536870912, 44739243, -1491308, 26630, -296, 2};
    const int32_t r32 = (int32_t)r;
    const int32_t u = (int32_t)sn_rshr64(sn_mul(r32, r32), 30);
    int32_t ps = ks[5], pc = kc[6];
    int64_t sv, cv;
    int k;
    SN_RANGE(r <= 843314857 && r >= -843314857, "sincos argument beyond pi/4", r);
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 6
#endif
    for (k = 4; k >= 0; k--) ps = ks[k] + (int32_t)sn_rshr64(sn_mul(ps, u), 30);
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 6
#endif
    for (k = 5; k >= 0; k--) pc = kc[k] + (int32_t)sn_rshr64(sn_mul(pc, u), 30);
    sv = sn_rshr64(sn_mul(ps, r32), 30);
#else
    static const int64_t ks[6] = {SN_Q30, -178956971, 8947849, -213044, 2959, -27};
    static const int64_t kc[7] = {SN_Q30, -536870912, 44739243, -1491308, 26630, -296, 2};
    int64_t u = sn_rshr64(r * r, 30), ps = ks[5], pc = kc[6], sv, cv;
    int k;
    for (k = 4; k >= 0; k--) ps = ks[k] + sn_rshr64(ps * u, 30);
    for (k = 5; k >= 0; k--) pc = kc[k] + sn_rshr64(pc * u, 30);
    sv = sn_rshr64(ps * r, 30);
#endif
    cv = pc;
    switch (quad & 3) {
    case 0: *s = sv; *c = cv; break;
    case 1: *s = cv; *c = -sv; break;
    case 2: *s = -sv; *c = -cv; break;
    default: *s = -cv; *c = sv; break;
    }
}

/* atan2(y, x) in Q30 radians for x, y >= 0 (any magnitude <= 2^40), result
 * in [0, pi/2]. CORDIC vectoring, 32 fixed iterations, 8 guard bits, angle
 * table atan(2^-i) in Q40: error <= ~1 LSB (Q30). atan2(0, 0) = 0. */
static int64_t sn_atan2_pos(int64_t y, int64_t x) {
    static const int64_t tab[32] = {
        863554413089, 509785937287, 269356888665, 136729762476, 68630207382,
        34348560106, 17178471287, 8589759836, 4294945451, 2147480917,
        1073741483, 536870869, 268435451, 134217727, 67108864, 33554432,
        16777216, 8388608, 4194304, 2097152, 1048576, 524288, 262144, 131072,
        65536, 32768, 16384, 8192, 4096, 2048, 1024, 512};
    int64_t X = x * 256, Y = y * 256, Z = 0;
    int i;
    if (x == 0 && y == 0) return 0;
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && defined(__GNUC__) && !defined(__clang__) && !defined(SN_FLOAT)
    /* Cortex-M: unrolled, each shift a constant (5 instructions on the two
     * words, not sn_rshr64_var's 10 for a variable one); the same values */
#pragma GCC unroll 32
#endif
    for (i = 0; i < 32; i++) {
        int64_t dx = sn_rshr64_var(Y, i), dy = sn_rshr64_var(X, i); /* Cortex-M: the shift on two words */
        if (Y > 0) {
            X += dx;
            Y -= dy;
            Z += tab[i];
        } else {
            X -= dx;
            Y += dy;
            Z -= tab[i];
        }
    }
    return sn_rshr64(Z, 10);
}

/* sn_sincos_red and sn_atan2_pos for the kernel test (their Cortex-M
 * forms against the int64 reference, tests/test_runtime_kernels.c) */
void sn_sincos_q30(int64_t r, int quad, int64_t *s, int64_t *c) { sn_sincos_red(r, quad, s, c); }
int64_t sn_atan2_q30(int64_t y, int64_t x) { return sn_atan2_pos(y, x); }

/* Slerp along the shorter arc, Q30 in and out, t in [0, 2^30] (clamped).
 * Method (stable for tiny angles): d = a.b (b negated if d < 0),
 * v = b - d a (so |v| = sin theta), theta = atan2(|v|, d),
 * out = normalize(a cos(t theta) + v sin(t theta)/|v|).
 * Components clamped to +-2^30 and the ratio sin(t theta)/|v| to [0,1],
 * so no intermediate overflows for any input. Exact shortcuts: t == 0 -> a,
 * t == 1 -> b (sign chosen for the shorter arc); no shortcut on the values
 * (a == b takes the full path, to within 1-2 LSB of a), so the cost of a
 * step does not depend on the pose.
 * Error for unit inputs: <= ~4 LSB per component (test: <= 8). */
/* The part of the slerp that does not depend on t (sn_pose.c's frames reuse
 * it per bone pair): b's sign, v = b - d a, |v| and theta. */
void sn_qslerp_pair(const sn_q a[4], const sn_q b[4], int path, sn_slerp_pair *p) {
    int64_t A[4], B[4], v, d = 0, th;
    uint64_t n2 = 0, s;
    int i, flip;
    for (i = 0; i < 4; i++) {
        A[i] = sn_clamp64(a[i], SN_Q30);
        B[i] = sn_clamp64(b[i], SN_Q30);
        d += A[i] * B[i];
    }
    d = sn_rshr64(d, 30); /* signed cos of the 4-D angle, Q30 */
    if (d > SN_Q30) d = SN_Q30;
    if (d < -SN_Q30) d = -SN_Q30;
    flip = path ? d < -SN_COS30_Q30 : d < 0;
    if (flip) d = -d;
    for (i = 0; i < 4; i++) {
        v = sn_clamp64((flip ? -B[i] : B[i]) - sn_rshr64(A[i] * d, 30), (int64_t)INT32_MAX);
        p->v[i] = (int32_t)v;
        n2 += (uint64_t)(v * v); /* < 2^62 each */
    }
    s = sn_isqrt64(n2);
    if (n2 - s * s > s) s++;
    th = sn_atan2_pos((int64_t)s, d < 0 ? -d : d);
    if (d < 0) th = 2 * SN_PI_2_Q30 - th; /* path: the obtuse side, (pi/2, pi] */
    p->s = s;
    p->th = th;
    p->flip = flip;
}
/* The slerp's ratio k = clamp((sp 2^30 + floor(s/2)) / s, 0, 2^30) (C's
 * truncating int64 division, s > 0) without a 64-bit divide: N = sp 2^30 +
 * floor(s/2) <= 0 gives a quotient <= 0, so 0; N >= (2^30 + 1) s one above
 * 2^30, so 2^30; else the quotient floor(N / s) is in [0, 2^30] and, for s <
 * 2^32 (always: sn_qslerp_pair's s <= isqrt(4 (2^31 - 1)^2) + 1 < 2^32),
 * sn_div64n's: N and s shifted by s's leading zeros z (the same quotient;
 * N 2^z < (2^30 + 1) 2^32 < 2^63, and N 2^z < (s 2^z) 2^32: its 32-bit
 * quotient). s >= 2^32 (no pair makes one): sn_udiv64, the same floor,
 * clamped (s < 2^63: the division's divisor (int64_t)s is s). The
 * same integers as the division (the kernel test checks both against it);
 * 32-bit targets only: a 64-bit one divides natively. */
int64_t sn_slerp_ratio(int64_t sp, uint64_t s) {
    const int64_t N = sp * SN_Q30 + (int64_t)(s >> 1);
    int z;
    if (N <= 0) return 0;
    if (s >> 32) { /* (int64_t)s the same value for s < 2^63; sn_udiv64 exact for such divisors */
        const uint64_t q = sn_udiv64((uint64_t)N, s);
        return q > SN_Q30 ? SN_Q30 : (int64_t)q;
    }
    if ((uint64_t)N >= (s << 30) + s) return SN_Q30; /* (2^30 + 1) s < 2^63 */
    z = lz32((uint32_t)s);
    return sn_div64n((uint64_t)N << z, (uint32_t)s << z);
}
/* The slerp at t from its pair part p (of these a and b). */
void sn_qslerp_at(const sn_q a[4], const sn_q b[4], const sn_slerp_pair *p, sn_q t, sn_q out[4]) {
    int64_t A[4], o[4], tt, ph, sp, cp, k;
    uint64_t s = p->s;
    int i;
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
    for (i = 0; i < 4; i++) A[i] = sn_clamp30(a[i]); /* int32 compares; the same values */
#else
    for (i = 0; i < 4; i++) A[i] = sn_clamp64(a[i], SN_Q30);
#endif
    tt = t < 0 ? 0 : (t > SN_Q30 ? SN_Q30 : t);
    if (tt == 0 || tt == SN_Q30) { /* t is the blob's frame weight: not a pose-dependent branch */
        for (i = 0; i < 4; i++) {
            int64_t B = sn_clamp64(b[i], SN_Q30);
            out[i] = (int32_t)(tt == 0 ? A[i] : p->flip ? -B : B);
        }
        return;
    }
    ph = sn_rshr64(p->th * tt, 30); /* [0, pi] */
    if (ph > 3 * SN_PI_4_Q30) sn_sincos_red(ph - 2 * SN_PI_2_Q30, 2, &sp, &cp);
    else if (ph > SN_PI_4_Q30) sn_sincos_red(ph - SN_PI_2_Q30, 1, &sp, &cp);
    else sn_sincos_red(ph, 0, &sp, &cp);
    if (s == 0) k = tt;
#if UINTPTR_MAX > 0xFFFFFFFFu
    else k = (sp * SN_Q30 + (int64_t)(s >> 1)) / (int64_t)s;
#else
    else k = sn_slerp_ratio(sp, s); /* the same integer, no library 64-bit divide */
#endif
    k = k < 0 ? 0 : (k > SN_Q30 ? SN_Q30 : k);
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
    { /* Cortex-M: int32 operands, SMULL / SMLAL (GCC multiplied 64 x 64):
       * |A| <= 2^30, 0 <= k <= 2^30, |cp| < 2^31 (sn_sincos_red's int32
       * Horner value or its rounded product with |r| < 2^30) */
        const int32_t c32 = (int32_t)cp, k32 = (int32_t)k;
        SN_RANGE(cp <= INT32_MAX && cp >= -INT32_MAX, "slerp cosine beyond int32", cp);
        for (i = 0; i < 4; i++) o[i] = sn_rshr64(sn_mul((int32_t)A[i], c32) + sn_mul(p->v[i], k32), 30);
    }
#else
    for (i = 0; i < 4; i++) o[i] = sn_rshr64(A[i] * cp + (int64_t)p->v[i] * k, 30);
#endif
    if (!sn_unit(o, 4, out)) {
        for (i = 0; i < 4; i++) out[i] = (int32_t)A[i];
    }
}
static void sn_qslerp_core(const sn_q a[4], const sn_q b[4], sn_q t, int path, sn_q out[4]) {
    sn_slerp_pair p;
    sn_qslerp_pair(a, b, path, &p);
    sn_qslerp_at(a, b, &p, t, out);
}
void sn_qslerp(const sn_q a[4], const sn_q b[4], sn_q t, sn_q out[4]) {
    sn_qslerp_core(a, b, t, 0, out);
}
void sn_qslerp_path(const sn_q a[4], const sn_q b[4], sn_q t, sn_q out[4]) {
    sn_qslerp_core(a, b, t, 1, out);
}

/* Twist angle of q about unit axis a (Q30 each), public degrees Q16.16:
 * s = v.a, q's sign taken so w >= 0 (w == 0: s >= 0), angle = 2 atan2(s, w).
 * |s|, |w| <= ~2^30.1 for unit inputs (validated axes), inside the CORDIC's
 * range; radians Q30 -> degrees: * 360/pi in Q16 (7509872, relative error
 * 7e-8 < 1 LSB at 180 degrees). Error <= ~2 LSB (Q16.16) plus the CORDIC's. */
sn_real sn_twist_deg(const sn_q q[4], const sn_q a[3]) {
    int64_t s = sn_rshr64((int64_t)q[0] * a[0] + (int64_t)q[1] * a[1] + (int64_t)q[2] * a[2], 30);
    int64_t w = q[3], half;
    int neg;
    if (w < 0 || (w == 0 && s < 0)) { w = -w; s = -s; }
    neg = s < 0;
    half = sn_atan2_pos(neg ? -s : s, w); /* [0, pi/2] Q30 */
    half = sn_rshr64(half * 7509872, 30);  /* degrees of the full angle, Q16.16 */
    return (int32_t)(neg ? -half : half);
}

/* ---- public helpers (fixed) ---- */

/* Axis (Q16.16, any non-zero length; zero -> identity) and angle (Q16.16
 * degrees, any int32) -> unit quaternion Q30. The half angle is reduced
 * exactly modulo 360 degrees in integers, then to |r| <= 45 degrees and
 * converted to radians with a 2^-45-accurate constant; axis normalized by
 * sn_unit. Error vs double: <= ~3 LSB per component (test: <= 4). */
sn_quat sn_quat_axis_angle(sn_vec3 axis, sn_real angle_degrees) {
    /* Q17 degrees of the half angle == angle_degrees as stored (Q16). */
    const int64_t P = (int64_t)360 << 17, Q = (int64_t)90 << 17;
    const int64_t K = 614083138197; /* pi/180 * 2^45 */
    int64_t c[3], rm, rem, r, s, co, o[4];
    int32_t u[3];
    int quad;
    sn_quat q;
    c[0] = axis.x;
    c[1] = axis.y;
    c[2] = axis.z;
    if (!sn_unit(c, 3, u)) {
        q.x = q.y = q.z = 0;
        q.w = (int32_t)SN_Q30;
        return q;
    }
    rm = (int64_t)angle_degrees % P;
    if (rm < 0) rm += P;
    quad = (int)((rm + Q / 2) / Q);
    rem = rm - (int64_t)quad * Q;       /* [-45, 45) degrees, Q17 */
    r = sn_rshr64(rem * K, 32);         /* Q30 radians; |rem*K| < 2^62 */
    sn_sincos_red(r, quad, &s, &co);
    o[0] = (int64_t)u[0] * s;
    o[1] = (int64_t)u[1] * s;
    o[2] = (int64_t)u[2] * s;
    o[3] = co * SN_Q30;
    {
        int32_t qq[4];
        (void)sn_unit(o, 4, qq); /* |o| ~ 2^60, never zero */
        q.x = qq[0];
        q.y = qq[1];
        q.z = qq[2];
        q.w = qq[3];
    }
    return q;
}

/* v (Q16.16) rotated by q (Q30, assumed unit): R(q) v via sn_qtomat; sums of
 * three Q46 products (< 2^63) rounded to Q16.16 and saturated to int32.
 * Error: <= 0.5 LSB + |v| * ~2^-29 (matrix rounding). */
sn_vec3 sn_quat_rotate(sn_quat q, sn_vec3 v) {
    sn_q qq[4], R[9];
    int64_t o[3];
    int k;
    sn_vec3 r;
    qq[0] = q.x; qq[1] = q.y; qq[2] = q.z; qq[3] = q.w;
    sn_qtomat(qq, R);
    for (k = 0; k < 3; k++)
        o[k] = sn_sat32(sn_rshr_any((int64_t)R[3 * k] * v.x + (int64_t)R[3 * k + 1] * v.y +
                                        (int64_t)R[3 * k + 2] * v.z, 30));
    r.x = (int32_t)o[0];
    r.y = (int32_t)o[1];
    r.z = (int32_t)o[2];
    return r;
}

#else
/* ======================= float flavour ======================= */
/* Same algorithms in float. Accuracy: a few float ulps (<~ 3e-7 absolute for
 * unit quantities). Inputs must be finite; NaN/inf propagate. */

#define SN_FPI_2 1.57079632679489662f
#define SN_FPI_4 0.78539816339744831f
#define SN_FPI_6 0.52359877559829887f

/* 1/sqrt(x) for x > 0: bit-level first guess, 3 Newton steps (error after
 * 3 steps ~3e-11 before float rounding, i.e. ~1 ulp). x <= 0 -> 0. */
float sn_frsqrt(float x) {
    uint32_t i;
    float y;
    int k;
    if (!(x > 1e-37f)) return 0.0f;
    memcpy(&i, &x, 4);
    i = 0x5f3759dfu - (i >> 1);
    memcpy(&y, &i, 4);
    for (k = 0; k < 3; k++) y = y * (1.5f - 0.5f * x * y * y);
    return y;
}

static float sn_fabs(float x) { return x < 0.0f ? -x : x; }

/* Scale c[0..n) to unit length; returns 0 if |c| is ~0 (or NaN). */
static int sn_funit(const float *c, int n, float *out) {
    float m = 0.0f, n2 = 0.0f, r;
    int i;
    for (i = 0; i < n; i++)
        if (sn_fabs(c[i]) > m) m = sn_fabs(c[i]);
    if (!(m > 1e-30f)) return 0;
    for (i = 0; i < n; i++) n2 += (c[i] / m) * (c[i] / m); /* scaled: no overflow */
    r = sn_frsqrt(n2) / m;
    for (i = 0; i < n; i++) out[i] = c[i] * r;
    return 1;
}

void sn_qnormalize(sn_q q[4]) {
    float c[4];
    memcpy(c, q, sizeof c);
    if (!sn_funit(c, 4, q)) {
        q[0] = q[1] = q[2] = 0.0f;
        q[3] = 1.0f;
    }
}

void sn_qtomat(const sn_q q[4], sn_q R[9]) {
    float x = q[0], y = q[1], z = q[2], w = q[3];
    R[0] = 1.0f - 2.0f * (y * y + z * z);
    R[1] = 2.0f * (x * y - z * w);
    R[2] = 2.0f * (x * z + y * w);
    R[3] = 2.0f * (x * y + z * w);
    R[4] = 1.0f - 2.0f * (x * x + z * z);
    R[5] = 2.0f * (y * z - x * w);
    R[6] = 2.0f * (x * z - y * w);
    R[7] = 2.0f * (y * z + x * w);
    R[8] = 1.0f - 2.0f * (x * x + y * y);
}

/* GCC 12 with FMA (-mavx512f, -mfma) SLP-vectorizes these four sums into
 * one VFMSUBADD, a fused rounding even under -std=c99 / -ffp-contract=off:
 * the float AVX-512 hash moved. No SLP here under GCC (the reference's
 * roundings on every target; four sums, nothing to gain). */
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("no-tree-slp-vectorize")))
#endif
void sn_qmul(const sn_q a[4], const sn_q b[4], sn_q out[4]) {
    float o0 = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    float o1 = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    float o2 = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    float o3 = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
    out[0] = o0; out[1] = o1; out[2] = o2; out[3] = o3;
}

/* sin, cos of quad*pi/2 + r, |r| <= ~pi/4: Taylor to r^11 / r^12. */
static void sn_fsincos_red(float r, int quad, float *s, float *c) {
    float u = r * r;
    float sv = r * (1.0f + u * (-1.0f / 6 + u * (1.0f / 120 + u * (-1.0f / 5040 +
                    u * (1.0f / 362880 - u * (1.0f / 39916800))))));
    float cv = 1.0f + u * (-0.5f + u * (1.0f / 24 + u * (-1.0f / 720 + u * (1.0f / 40320 +
                    u * (-1.0f / 3628800 + u * (1.0f / 479001600))))));
    switch (quad & 3) {
    case 0: *s = sv; *c = cv; break;
    case 1: *s = cv; *c = -sv; break;
    case 2: *s = -sv; *c = -cv; break;
    default: *s = -cv; *c = sv; break;
    }
}

/* atan2(y, x) for x, y >= 0, in [0, pi/2]: reduce to z in [0,1], then to
 * |w| <= tan(15 deg) via atan z = pi/6 + atan((z sqrt3 - 1)/(sqrt3 + z)),
 * Taylor to w^11 (truncation < 3e-9). */
static float sn_fatan2_pos(float y, float x) {
    const float r3 = 1.73205080756887729f;
    float z, w, u, a;
    int swap = y > x, big;
    if (!(x > 0.0f) && !(y > 0.0f)) return 0.0f;
    z = swap ? x / y : y / x;
    big = z > 0.26794919243112270f;
    w = big ? (z * r3 - 1.0f) / (r3 + z) : z;
    u = w * w;
    a = w * (1.0f + u * (-1.0f / 3 + u * (1.0f / 5 + u * (-1.0f / 7 + u * (1.0f / 9 - u * (1.0f / 11))))));
    if (big) a += SN_FPI_6;
    return swap ? SN_FPI_2 - a : a;
}

void sn_qslerp_pair(const sn_q a[4], const sn_q b[4], int path, sn_slerp_pair *p) {
    float d = 0.0f, n2 = 0.0f;
    int i, same = 1, flip;
    for (i = 0; i < 4; i++) {
        d += a[i] * b[i];
        same &= a[i] == b[i];
    }
    if (!(d <= 1.0f)) d = d > 1.0f ? 1.0f : 0.0f; /* also NaN -> 0 */
    if (d < -1.0f) d = -1.0f;
    flip = path ? d < -0.86602540378443865f : d < 0.0f;
    if (flip) d = -d;
    for (i = 0; i < 4; i++) {
        p->v[i] = (flip ? -b[i] : b[i]) - a[i] * d;
        n2 += p->v[i] * p->v[i];
    }
    p->s = n2 * sn_frsqrt(n2);
    p->th = sn_fatan2_pos(p->s, sn_fabs(d));
    if (d < 0.0f) p->th = 2.0f * SN_FPI_2 - p->th; /* path: the obtuse side */
    p->flip = flip;
    p->same = same;
}
void sn_qslerp_at(const sn_q a[4], const sn_q b[4], const sn_slerp_pair *p, sn_q t, sn_q out[4]) {
    float o[4], ph, sp, cp, k;
    int i;
    if (!(t > 0.0f)) t = 0.0f; /* also NaN -> 0 */
    if (t > 1.0f) t = 1.0f;
    if (p->same || t == 0.0f || t == 1.0f) {
        for (i = 0; i < 4; i++) out[i] = t == 1.0f && !p->same ? (p->flip ? -b[i] : b[i]) : a[i];
        return;
    }
    ph = p->th * t;
    if (ph > 3.0f * SN_FPI_4) sn_fsincos_red(ph - 2.0f * SN_FPI_2, 2, &sp, &cp);
    else if (ph > SN_FPI_4) sn_fsincos_red(ph - SN_FPI_2, 1, &sp, &cp);
    else sn_fsincos_red(ph, 0, &sp, &cp);
    k = p->s > 1e-20f ? sp / p->s : t;
    k = k < 0.0f ? 0.0f : (k > 1.0f ? 1.0f : k);
    for (i = 0; i < 4; i++) o[i] = a[i] * cp + p->v[i] * k;
    if (!sn_funit(o, 4, out)) memcpy(out, a, 4 * sizeof(float));
}
static void sn_qslerp_core(const sn_q a[4], const sn_q b[4], sn_q t, int path, sn_q out[4]) {
    sn_slerp_pair p;
    sn_qslerp_pair(a, b, path, &p);
    sn_qslerp_at(a, b, &p, t, out);
}
void sn_qslerp(const sn_q a[4], const sn_q b[4], sn_q t, sn_q out[4]) {
    sn_qslerp_core(a, b, t, 0, out);
}
void sn_qslerp_path(const sn_q a[4], const sn_q b[4], sn_q t, sn_q out[4]) {
    sn_qslerp_core(a, b, t, 1, out);
}

/* Axis (any non-zero length; zero -> identity), angle in degrees. The half
 * angle is reduced to |r| <= 45 degrees (exactly, for |angle| < 2e7; larger
 * or non-finite angles are treated as 0). */
/* Twist angle of q about unit axis a in degrees (float twin of the fixed one). */
sn_real sn_twist_deg(const sn_q q[4], const sn_q a[3]) {
    float sv = q[0] * a[0] + q[1] * a[1] + q[2] * a[2], w = q[3], half;
    int neg;
    if (w < 0.0f || (w == 0.0f && sv < 0.0f)) { w = -w; sv = -sv; }
    neg = sv < 0.0f;
    half = sn_fatan2_pos(neg ? -sv : sv, w);
    half *= 114.591559026164646f; /* 2 * 180 / pi */
    return neg ? -half : half;
}

sn_quat sn_quat_axis_angle(sn_vec3 axis, sn_real angle_degrees) {
    float c[3], u[3], half = 0.5f * angle_degrees, s, co, qv[4];
    long n;
    sn_quat q;
    c[0] = axis.x;
    c[1] = axis.y;
    c[2] = axis.z;
    if (!sn_funit(c, 3, u)) {
        q.x = q.y = q.z = 0.0f;
        q.w = 1.0f;
        return q;
    }
    if (!(sn_fabs(half) < 1e7f)) half = 0.0f;
    {
        float qf = half / 90.0f;
        n = (long)(qf + (qf >= 0.0f ? 0.5f : -0.5f));
    }
    sn_fsincos_red((half - (float)n * 90.0f) * (SN_FPI_2 / 90.0f), (int)(((n % 4) + 4) % 4), &s, &co);
    qv[0] = u[0] * s;
    qv[1] = u[1] * s;
    qv[2] = u[2] * s;
    qv[3] = co;
    sn_qnormalize(qv);
    q.x = qv[0];
    q.y = qv[1];
    q.z = qv[2];
    q.w = qv[3];
    return q;
}

sn_vec3 sn_quat_rotate(sn_quat q, sn_vec3 v) {
    sn_q qq[4], R[9];
    sn_vec3 r;
    qq[0] = q.x; qq[1] = q.y; qq[2] = q.z; qq[3] = q.w;
    sn_qtomat(qq, R);
    r.x = R[0] * v.x + R[1] * v.y + R[2] * v.z;
    r.y = R[3] * v.x + R[4] * v.y + R[5] * v.z;
    r.z = R[6] * v.x + R[7] * v.y + R[8] * v.z;
    return r;
}
#endif

/* ---- flavour-independent public wrappers ---- */

sn_quat sn_quat_mul(sn_quat a, sn_quat b) {
    sn_q qa[4], qb[4], o[4];
    sn_quat r;
    qa[0] = a.x; qa[1] = a.y; qa[2] = a.z; qa[3] = a.w;
    qb[0] = b.x; qb[1] = b.y; qb[2] = b.z; qb[3] = b.w;
    sn_qmul(qa, qb, o);
    r.x = o[0]; r.y = o[1]; r.z = o[2]; r.w = o[3];
    return r;
}

/* Public slerp: inputs are normalized first (any int32 input is fine). */
sn_quat sn_quat_slerp(sn_quat a, sn_quat b, sn_real t) {
    sn_q qa[4], qb[4], o[4];
    sn_quat r;
    qa[0] = a.x; qa[1] = a.y; qa[2] = a.z; qa[3] = a.w;
    qb[0] = b.x; qb[1] = b.y; qb[2] = b.z; qb[3] = b.w;
    sn_qnormalize(qa);
    sn_qnormalize(qb);
    sn_qslerp(qa, qb, t, o);
    r.x = o[0]; r.y = o[1]; r.z = o[2]; r.w = o[3];
    return r;
}

