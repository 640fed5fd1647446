/* sn_internal.h -- internal types and arithmetic of the Sinew runtime.
 *
 * One source, two flavours (Opus style): the default fixed flavour uses
 * int32 values in the Q formats of runtime/NUMERICS.md with int64
 * accumulators; -DSN_FLOAT turns the same code into float arithmetic, in which
 * every shift argument is ignored (float blobs store true values).
 * Nothing here allocates, calls libm or recurses.
 */
#ifndef SN_INTERNAL_H
#define SN_INTERNAL_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "sinew.h"
#include "sn_format.h"
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && defined(__ARM_FEATURE_DSP) && !defined(SN_FLOAT)
#include <arm_acle.h> /* __qadd (sn_add); a compiler header, no library */
#endif

#define SN_INLINE static inline
/* a function kept out of its caller: the details' per-cell work, so a step
 * without details does not carry their arrays in its stack frame */
#if defined(__GNUC__)
#define SN_NOINLINE static __attribute__((noinline))
#else
#define SN_NOINLINE static
#endif

/* ---- endian-safe reads of the little-endian blob (aliasing-safe) ---- */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) && \
    __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
#define SN_HOST_LE 1
#else
#define SN_HOST_LE 0
#endif

SN_INLINE uint32_t sn_rd_u32(const unsigned char *p) {
#if SN_HOST_LE
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
#else
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
#endif
}
SN_INLINE uint32_t sn_rd_u16(const unsigned char *p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8);
}
SN_INLINE int32_t sn_rd_i32(const unsigned char *p) {
    uint32_t u = sn_rd_u32(p);
    int32_t v;
    memcpy(&v, &u, 4); /* two's complement reinterpretation, no impl-defined cast */
    return v;
}
SN_INLINE float sn_rd_f32(const unsigned char *p) {
    uint32_t u = sn_rd_u32(p);
    float v;
    memcpy(&v, &u, 4);
    return v;
}

/* ---- scalar types ----
 * sn_q   one internal value (fixed: int32 in a Q format; float: float)
 * sn_acc accumulator of products (fixed: int64; float: float)          */
#if defined(SN_FLOAT)
typedef float sn_q;
typedef float sn_acc;
#define SN_RD_REAL(p) sn_rd_f32(p)
#define SN_REAL_BYTES 4
#else
typedef int32_t sn_q;
typedef int64_t sn_acc;
#define SN_RD_REAL(p) sn_rd_i32(p)
#define SN_REAL_BYTES 4
#endif

/* |d|^2 of a difference of state positions (fixed: |d_k| <= 2^29, so the sum
 * < 2^59.6 in uint64; the health pass and the segment meshes' measure) */
#if defined(SN_FLOAT)
typedef float sn_len2;
#else
typedef uint64_t sn_len2;
#endif
SN_INLINE sn_len2 sn_norm2(const sn_q d[3]) {
#if defined(SN_FLOAT)
    return d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
#else
    return (uint64_t)((int64_t)d[0] * d[0]) + (uint64_t)((int64_t)d[1] * d[1]) + (uint64_t)((int64_t)d[2] * d[2]);
#endif
}

/* Limits (fixed): state values are clamped to +-SN_LIM (Q22: +-64 internal
 * units); SN_ACC_LIM bounds intermediate public-unit sums (NUMERICS.md,
 * overflow freedom). */
#define SN_LIM ((int32_t)1 << 28)
#define SN_ACC_LIM ((int64_t)1 << 62)
#define SN_ENTRY_LIM ((int32_t)1 << 27)

#if defined(SN_FLOAT)
#define SN_ONE_ROT 1.0f
#define SN_FLIM 4096.0f /* float: only a guard against runaway values (no format range to protect) */
#else
#define SN_ONE_ROT ((int32_t)1 << SN_Q_ROT)
#endif

/* Product of two values, accumulated exactly (fixed) */
SN_INLINE sn_acc sn_mul(sn_q a, sn_q b) {
#if defined(SN_FLOAT)
    return a * b;
#else
    return (int64_t)a * (int64_t)b;
#endif
}

/* a*b - c*d, exact. Written as a sum with c negated (|c| < 2^31): clang 14
 * for 32-bit MIPS selects a fused multiply-subtract (msub) for the plain
 * difference of two widened int32 products and swaps its operands,
 * returning c*d - a*b (found by tests/scripts/test_determinism.sh; gcc and
 * every other target are right). Use it for every such difference. */
#define sn_mul_sub(a, b, c, d) (sn_mul((a), (b)) + sn_mul(-(c), (d)))

/* Round-to-nearest right shift of an int64 (ties toward +infinity).
 * Right-shifting a negative value is implementation-defined in C99; every
 * supported compiler shifts arithmetically, and the check below refuses to
 * build where that is not so (the result would not be bit-identical).
 * Requires |x| <= 2^62 and s <= 62; s <= 0 returns x unchanged. */
typedef char sn_arithmetic_shift_required_[(((int64_t)-3) >> 1) == -2 ? 1 : -1];

/* Range-checking build (-DSN_RANGE_CHECK; in the spirit of Opus'
 * fixed_debug.h): every rounding shift, accumulator conversion and int64
 * sum whose bound NUMERICS.md derives asserts that bound, calling
 * sn_range_fail, which the test program defines (the runtime has no I/O).
 * Off in every other build: the checks compile to nothing. */
#if defined(SN_RANGE_CHECK) && !defined(SN_FLOAT)
void sn_range_fail(const char *what, const char *file, int line, long long value);
#define SN_RANGE(cond, what, value) \
    do { if (!(cond)) sn_range_fail((what), __FILE__, __LINE__, (long long)(value)); } while (0)
#else
#define SN_RANGE(cond, what, value) do { } while (0)
#endif
/* |x| <= 2^b for an int64 (b < 63) */
#define SN_WITHIN(x, b) ((x) <= ((int64_t)1 << (b)) && (x) >= -((int64_t)1 << (b)))

SN_INLINE int64_t sn_rshr64(int64_t x, int s) {
    if (s <= 0) return x;
    SN_RANGE(s <= 62, "rounding shift beyond 62", s);
    SN_RANGE(x <= INT64_MAX - ((int64_t)1 << (s - 1)), "rounding add overflows int64", x);
    return (x + ((int64_t)1 << (s - 1))) >> s;
}

/* x >> s (floor) for 0 < s < 32 on the two 32-bit words: lo >> s | hi <<
 * (32 - s) and hi >> s, a 32-bit core's cheap form of a variable 64-bit
 * shift (the Cortex-M paths: sn_rshr64_var, the M4 kernels). */
SN_INLINE int64_t sn_shr_words(uint32_t lo, int32_t hi, int s) {
    return (int64_t)(hi >> s) * ((int64_t)1 << 32) + (int64_t)((lo >> s) | ((uint32_t)hi << (32 - s)));
}
SN_INLINE int64_t sn_shr64_w(int64_t x, int s) { return sn_shr_words((uint32_t)x, (int32_t)(x >> 32), s); }

/* sn_rshr64 for a shift known only at run time, on a 32-bit Cortex-M: for
 * 0 < s < 32 the add's carry and the shift on the two words (10
 * instructions instead of GCC's 19 for a variable 64-bit shift and its
 * 64-bit 2^(s-1)); the same value, (hi:lo + 2^(s-1)) >> s, hi + carry kept
 * in range by sn_rshr64's bound. Elsewhere (and for s >= 32) sn_rshr64.
 * Used by sn_out and the segment move, where the M4 profile shows variable
 * shifts; not in sn_rshr64 itself (GCC then inlined the segment sweep
 * differently: +0.1 M a cow step). */
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && !defined(SN_FLOAT)
SN_INLINE int64_t sn_rshr64_var(int64_t x, int s) {
    if (s > 0 && s < 32) {
        const uint32_t bit = (uint32_t)1 << (s - 1), lo = (uint32_t)x + bit;
        const int32_t hi = (int32_t)(x >> 32) + (int32_t)(lo < bit);
        SN_RANGE(x <= INT64_MAX - ((int64_t)1 << (s - 1)), "rounding add overflows int64", x);
        return sn_shr_words(lo, hi, s);
    }
    return sn_rshr64(x, s);
}
#else
#define sn_rshr64_var sn_rshr64
#endif

/* Accumulator -> value: round-shift by s, clamp to +-SN_LIM and count clamps
 * into *sat. Float: clamp to +-SN_FLIM internal units (s ignored); a NaN
 * becomes 0 (counted), so it never enters the state.
 * Fixed: requires |a| < 2^62.5 so the rounding add cannot overflow; every
 * caller's sum is bounded below that (NUMERICS.md, overflow freedom). */
SN_INLINE sn_q sn_out(sn_acc a, int s, uint32_t *sat) {
#if defined(SN_FLOAT)
    (void)s;
    if (a > SN_FLIM) { (*sat)++; return SN_FLIM; }
    if (a < -SN_FLIM) { (*sat)++; return -SN_FLIM; }
    if (!(a == a)) { (*sat)++; return 0.0f; } /* NaN never enters the state: counted, replaced by 0 */
    return a;
#else
    int64_t v;
    SN_RANGE(a <= (int64_t)6521908912666391106 && a >= -(int64_t)6521908912666391106, /* 2^62.5 */
             "accumulator beyond 2^62.5 reaches sn_out", a);
    v = sn_rshr64_var(a, s);
    if (v > SN_LIM) { (*sat)++; return SN_LIM; }
    if (v < -SN_LIM) { (*sat)++; return -SN_LIM; }
    return (int32_t)v;
#endif
}

/* Saturating add of two state values (fixed clamps to +-SN_LIM). */
SN_INLINE sn_q sn_add(sn_q a, sn_q b, uint32_t *sat) {
#if defined(SN_FLOAT)
    return sn_out(a + b, 0, sat);
#elif defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && defined(__GNUC__) && defined(__ARM_FEATURE_DSP)
    /* Cortex-M4/M7: the sum by QADD (saturated to INT32_MIN/MAX on overflow:
     * beyond SN_LIM with the true sum's sign, clamped and counted as
     * before; the Q flag is never read) and |v| <= SN_LIM as one unsigned
     * compare of v + SN_LIM: 4 instructions instead of a 64-bit sum and
     * 64-bit compares (or ADDS, BVS and two compares) */
    const int32_t v = __qadd(a, b);
    if ((uint32_t)v + (uint32_t)SN_LIM <= 2u * (uint32_t)SN_LIM) return v;
    (*sat)++;
    return v > 0 ? SN_LIM : -SN_LIM;
#elif defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && defined(__GNUC__)
    /* other Cortex-M: one 32-bit ADDS (an overflow means |a + b| >= 2^31
     * with a's sign: beyond SN_LIM, clamped and counted as before) and
     * 32-bit compares */
    int32_t v;
    if (__builtin_add_overflow(a, b, &v)) { (*sat)++; return a < 0 ? -SN_LIM : SN_LIM; }
    if (v > SN_LIM) { (*sat)++; return SN_LIM; }
    if (v < -SN_LIM) { (*sat)++; return -SN_LIM; }
    return v;
#else
    return sn_out((int64_t)a + (int64_t)b, 0, sat);
#endif
}

/* a*b >> s, rounded and clamped (one product). */
SN_INLINE sn_q sn_mulq(sn_q a, sn_q b, int s, uint32_t *sat) {
    return sn_out(sn_mul(a, b), s, sat);
}

/* ---- 3-vectors and 3x3 rotations (row-major), rotation entries Q30 ---- */
/* out = R v (v, out in the same Q format) */
SN_INLINE void sn_rot(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    int k;
    for (k = 0; k < 3; k++)
        out[k] = sn_out(sn_mul(R[3 * k], v[0]) + sn_mul(R[3 * k + 1], v[1]) +
                            sn_mul(R[3 * k + 2], v[2]), SN_Q_ROT, sat);
}
/* out = R^T v */
SN_INLINE void sn_rot_t(const sn_q R[9], const sn_q v[3], sn_q out[3], uint32_t *sat) {
    int k;
    for (k = 0; k < 3; k++)
        out[k] = sn_out(sn_mul(R[k], v[0]) + sn_mul(R[3 + k], v[1]) +
                            sn_mul(R[6 + k], v[2]), SN_Q_ROT, sat);
}

/* ---- math (sn_math.c): quaternions x,y,z,w in Q30 (fixed) or float ---- */
/* Normalize q in place (zero quaternion -> identity). */
void sn_qnormalize(sn_q q[4]);
/* Row-major rotation matrix (Q30) of a unit quaternion. */
void sn_qtomat(const sn_q q[4], sn_q R[9]);
/* out = a*b */
void sn_qmul(const sn_q a[4], const sn_q b[4], sn_q out[4]);
/* Slerp along the shorter arc, t in [0,1] (fixed: Q30), result unit. */
void sn_qslerp(const sn_q a[4], const sn_q b[4], sn_q t, sn_q out[4]);
/* Slerp along the path from a to b without the shorter-arc flip (a joint
 * wound past 180 degrees keeps its way), unless a.b < -cos 30 degrees
 * (more than 300 degrees of rotation), where the shorter arc is taken. */
void sn_qslerp_path(const sn_q a[4], const sn_q b[4], sn_q t, sn_q out[4]);
/* sn_qslerp(_path) in two parts: the pair's (b's sign, v = b - (a.b) a,
 * |v|, the angle; independent of t) and the slerp at t from it, the same
 * bits as one call. sn_pose.c keeps one per FPAIRS entry in the step's
 * scratch (SN_FPAIR_BYTES each). */
typedef struct sn_slerp_pair {
#if defined(SN_FLOAT)
    float v[4], s, th;
    int same;
#else
    uint64_t s;  /* |v| rounded, Q30 */
    int64_t th;  /* the angle, Q30 radians */
    int32_t v[4];
#endif
    int flip;
} sn_slerp_pair;
typedef char sn_slerp_pair_fits_[sizeof(sn_slerp_pair) <= SN_FPAIR_BYTES ? 1 : -1];
void sn_qslerp_pair(const sn_q a[4], const sn_q b[4], int path, sn_slerp_pair *p);
void sn_qslerp_at(const sn_q a[4], const sn_q b[4], const sn_slerp_pair *p, sn_q t, sn_q out[4]);
#if !defined(SN_FLOAT)
/* sn_qslerp_at's ratio clamp((sp 2^30 + floor(s/2)) / s, 0, 2^30) for s > 0
 * without a 64-bit divide (its route on 32-bit targets; the kernel test) */
int64_t sn_slerp_ratio(int64_t sp, uint64_t s);
#endif
/* Angle (public degrees: fixed Q16.16) of the rotation q about the unit
 * axis a (Q30 / float): the twist of a swing-twist decomposition,
 * 2 atan2(v.a, w) with q's sign chosen so w >= 0, in (-180, 180]. */
sn_real sn_twist_deg(const sn_q q[4], const sn_q a[3]);
/* floor(n / D), 0 < D <= 2^62, constant time (both flavours link it; fixed uses it). */
uint64_t sn_udiv64(uint64_t n, uint64_t D);
/* sin, cos of (quad pi/2 + r), |r| <= pi/4 (Q30), and atan2(y, x) for x, y
 * >= 0 (Q30 radians): sn_math.c's helpers, exported for the kernel test */
void sn_sincos_q30(int64_t r, int quad, int64_t *s, int64_t *c);
int64_t sn_atan2_q30(int64_t y, int64_t x);
/* Integer square root: floor(sqrt(x)). */
uint32_t sn_isqrt64(uint64_t x);
/* the same by two-bit digits in 32-bit words (sn_isqrt64 on a 32-bit target) */
uint32_t sn_isqrt64_digits(uint64_t x);
/* the same by Karatsuba square root with 32-bit divides (sn_isqrt64 on a Cortex-M with UDIV) */
uint32_t sn_isqrt64_kara(uint64_t x);
/* floor(n / d) for a normalized d in [2^31, 2^32) and n < d 2^32 (the
 * quotient fits 32 bits): two 32/32 divisions on 16-bit digits with at most
 * two corrections each (Knuth D; Warren, Hacker's Delight fig. 9-3 divlu),
 * exact. A core with a 32-bit divider (Cortex-M4 UDIV) needs no library
 * 64-bit divide; a 64-bit target divides natively (sn_div64n). */
SN_INLINE uint32_t sn_div64n_digits(uint64_t n, uint32_t d) {
    uint32_t u1 = (uint32_t)(n >> 32), n1 = (uint32_t)n >> 16, n0 = (uint32_t)n & 0xffffu;
    uint32_t d1 = d >> 16, d0 = d & 0xffffu, q1, q0, r;
    int i;
    SN_RANGE(d >= 0x80000000u && u1 < d, "sn_div64n: divisor not normalized or quotient beyond 32 bits", n);
    q1 = u1 / d1; r = u1 - q1 * d1;
    for (i = 0; i < 2; i++) /* q1 too large by at most 2 */
        if (r <= 0xffffu && (q1 > 0xffffu || q1 * d0 > ((r << 16) | n1))) { q1--; r += d1; }
    u1 = (u1 << 16) + n1 - q1 * d; /* the remainder < d (mod 2^32 exact) */
    q0 = u1 / d1; r = u1 - q0 * d1;
    for (i = 0; i < 2; i++)
        if (r <= 0xffffu && (q0 > 0xffffu || q0 * d0 > ((r << 16) | n0))) { q0--; r += d1; }
    return (q1 << 16) + q0;
}
/* the same quotient: natively on a 64-bit target, by digits on a 32-bit one */
SN_INLINE uint32_t sn_div64n(uint64_t n, uint32_t d) {
#if UINTPTR_MAX > 0xFFFFFFFFu
    SN_RANGE(d >= 0x80000000u && (n >> 32) < d, "sn_div64n: divisor not normalized or quotient beyond 32 bits", n);
    return (uint32_t)(n / d);
#else
    return sn_div64n_digits(n, d);
#endif
}
#if defined(SN_FLOAT)
/* 1/sqrt(x) for x > 0 (no libm). */
float sn_frsqrt(float x);
#endif

#define SN_SEC_VIEWED SN_SEC_CELLX
/* ---- validated blob, decoded once (pointers into the read-only blob) ---- */
typedef struct sn_view {
    const unsigned char *base;
    const unsigned char *sec[SN_SEC_VIEWED]; /* sections before the cut level's (sn_sec for those: the header stays 832 B) */
    uint32_t nV, nF, nC, nJ, nS, nT, nnz, nL; /* nL: LIMIT entries, 0 or nF */
    uint32_t nK, nR, nRS, nRE; /* controls, rigs, rig samples, rig entries (section counts) */
    uint32_t nP, nVP, nFrc;    /* share profiles, vertex profile entries (0 or nF), force slots */
    uint32_t nM, nSN, nSA, segB; /* segment meshes, nodes, attachments; segment state bytes */
    uint32_t nD, crB;          /* crease: seed pairs, state bytes (SN_CREASE_STATE_BYTES, 0 without) */
    uint16_t nCR, cr_list, cr_active, cr_nv, cr_nt, cr_nq; /* crease: CREASE count (0 or 1), max list, max active,
                                                              VNBR / TNBR row widths, neighbourhood rows (0 without) */
    uint16_t ic, cut;          /* 1 with an ICHOL section; 1 with CELLX (the cut level; 16-bit: the view sits in the instance header) */
    sn_q cr_depth, cr_push;    /* crease: deepest detected penetration, push-out cap per step (Q22) */
    uint32_t nCon, nCol, nCt, nRows, conB; /* max constraints, colliders, contacts; rows per step; constraint state bytes */
    uint32_t cg_default, cg_max, instance_bytes, total, flags;
    int len_shift, frac_S, frac_M, frac_P, frac_E, frac_F;
    sn_q a1, b1, grav[3], timestep;
    sn_q energy, cell, disp_bound; /* health scalars (NUMERICS.md) */
    sn_q force;                    /* right-hand-side units per newton (Q frac_F) */
} sn_view;
/* a section's first byte from the blob's table (the cut level's two, not kept in the view) */
SN_INLINE const unsigned char *sn_sec(const sn_view *v, int k) {
    return v->base + sn_rd_u32(v->base + SN_H_SECTIONS + (size_t)k * SN_SECTION_ENTRY);
}

/* Instance bytes for these counts: the runtime's layout (sn_instance.c), the
 * one source of the size (SN_INSTANCE_BYTES in sn_format.h is tested equal). */
uint32_t sn_instance_bytes(uint32_t nV, uint32_t nF, uint32_t nJ, uint32_t nC, uint32_t nK,
                           uint32_t nFrc, uint32_t segB, uint32_t crB, uint32_t conB, uint32_t nFP);
/* Frame references (sn_pose.c, format 6.4): FPAIRS and FREFS valid against
 * FRAMES and CFRAMES (counts already checked by the table). */
sn_status sn_check_frefs(const sn_view *v, uint32_t nfp, uint32_t nfr);

/* One stored real in range (validator helper, sn_blob.c): fixed, the stored
 * integer in [lo, hi]; float, finite and in [lo, hi] / 2^q (q <= 30). */
int sn_real_ok(const unsigned char *p, int32_t lo, int32_t hi, int q);

/* Segment sections (sn_segment_api.c): contents valid, and *segB = the state
 * bytes they need. Called by the validator once the table is checked. */
sn_status sn_check_segments(const sn_view *v, uint32_t *segB);
/* Crease sections (sn_crease.c): contents valid (table counts already
 * checked against the parameters). */
sn_status sn_check_crease(const sn_view *v);
/* Force sections (sn_force.c): profiles and vertex profiles valid. */
sn_status sn_check_forces(const sn_view *v);

/* Constraint section (sn_constraint.c): the record's maxima within their
 * bounds (SN_MAX_*, rows <= SN_MAX_ROWS), reserved bytes 0; fills the view's
 * nCon, nCol, nCt, nRows, conB (sn_view_constraints). */
sn_status sn_check_constraints(sn_view *v);
void sn_view_constraints(sn_view *v); /* decode only (validated blob) */

/* Levels of detail (sn_level.c, format 6.0): a section's count from the
 * blob's table; the finer level against the coarse one (both already
 * validated alone); the layout's counts, the largest over the levels (the
 * free and the skeleton vertices each at their largest). */
uint32_t sn_level_sec_count(const sn_view *v, int sec);
sn_status sn_check_levels(const sn_view *coarse, const sn_view *fine);
void sn_level_counts(const sn_view *v, uint32_t *nV, uint32_t *nF, uint32_t *nC);
uint32_t sn_level_fpairs(const sn_view *v); /* FPAIRS entries, the largest over the levels (the step's pair scratch) */

/* Decode the header of a blob that sn_blob_validate() accepted (no checks). */
void sn_view_init(sn_view *v, const sn_blob *blob);

#endif /* SN_INTERNAL_H */
