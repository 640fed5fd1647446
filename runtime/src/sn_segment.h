/* sn_segment.h -- segment meshes (seed 004 ch. 3-4), shared by the step
 * (sn_segment.c: dynamics, velocities, the step's order), the displacement
 * constraint's sweeps (sn_segment_sweep.c), the mesh records, topology and
 * state (sn_segment_mesh.c: levels, ends, reset, teleport, hash) and the
 * multilevel transfers (sn_segment_level.c); the API and validator are
 * sn_segment_api.c.
 *
 * Instance state (h->o_seg), per mesh in blob order: every level's segments
 * (finest first, SEG_W words each), then every level's nodes (NODE_W words).
 *   segment: G[3] centre (Q22), u[3] unit direction start->end (Q30),
 *            v[3] velocity per step (Q22), w[3] angular velocity per step
 *            (Q30 rad); on coarse levels (l > 0) the segment's half
 *            length (Q22), its reciprocal and shift (recip), then 0; on
 *            the finest level 4 words 0. Between the dynamics and the velocity
 *            update v holds the centre and w the direction before the step.
 *   node:    p[3] position (Q22: mean of the endpoints meeting there),
 *            J[3] impulse accumulated for the next step (Q22 per step,
 *            the velocity change of a segment of mass m0).
 */
#ifndef SN_SEGMENT_H
#define SN_SEGMENT_H
#include "sn_instance.h"

#define SEG_W (SN_SEG_SEG_BYTES / 4u)
#define NODE_W (SN_SEG_NODE_BYTES / 4u)
#define SEG_REC SN_ELEM_SEGMESH(SN_REAL_BYTES)
#define ATT_REC SN_ELEM_SEGATTACH(SN_REAL_BYTES)

/* One mesh, decoded from its (validated) record. */
typedef struct seg_mesh {
    unsigned kind, levels, sweeps, coarse_sweeps, relax, flags, side, n_attach;
    uint32_t first_node, first_attach, segs, nodes; /* segs, nodes: all levels */
    sn_q len, gamma, keep, inv_mass, centre, share[SN_SEG_MAX_LEVELS];
    sn_q *S, *N; /* state: segments, nodes of level 0 (coarser levels follow) */
} seg_mesh;

/* One level of a mesh. */
typedef struct seg_lvl {
    sn_q *S, *N;
    uint32_t ns, nn;   /* segments, nodes */
    unsigned kind, side, l;
    sn_q half;         /* half length of a segment (Q22) */
#if defined(SN_FLOAT)
    sn_q bhalf;        /* of a brace: the length of a degenerate coarse brace */
#endif
    sn_q rh;           /* 1/half: fixed Q(29 + bits of half) reciprocal, float 1/x */
    int sh;            /* shift of that reciprocal (fixed) */
} seg_lvl;

void seg_mesh_get(const sn_ihdr *h, uint32_t m, seg_mesh *M);
void seg_level(const seg_mesh *M, unsigned l, seg_lvl *L);
/* nodes of segment i: start a, end b */
void seg_nodes(const seg_lvl *L, uint32_t i, uint32_t *a, uint32_t *b);
/* segment ends meeting at node n: segment index and sign (+1 end, -1 start) */
unsigned seg_node_ends(const seg_lvl *L, uint32_t n, uint32_t seg[5], int sgn[5]);
/* segments of a level rebuilt from its node positions: G = mean, u = unit(b - a);
 * lens (coarse levels): also the segment's half length |b - a|/2 (words 12-14) */
void seg_from_nodes(const seg_lvl *L, int lens, uint32_t *sat);
/* node positions = mean of the endpoints meeting there */
void seg_node_means(const seg_lvl *L, uint32_t *sat);
/* endpoint of segment i (sign s) */
void seg_end(const seg_lvl *L, uint32_t i, int s, sn_q P[3], uint32_t *sat);
/* multilevel (sn_segment_level.c) */
void seg_restrict(const seg_mesh *M, uint32_t *sat);
void seg_prolong(const seg_mesh *M, unsigned l, uint32_t *sat);
/* unit vector of x (any scale) into u; unchanged if x = 0 */
void seg_unit(const sn_q x[3], sn_q u[3]);
/* ---- shared by the sweeps and the step: values, limits, ends (inlined) ---- */

/* largest rotation per constraint or per step, per component: 0.25 rad
 * (the small-angle update u + theta x u stays within 3% of a true rotation) */
#if defined(SN_FLOAT)
#define ROT_MAX 0.25f
#else
#define ROT_MAX ((int32_t)1 << 28)
/* dynamics() caps angular velocity sums at ROT_MAX where sn_add would clamp
 * at SN_LIM: the same value only while the two are equal */
typedef char sn_rot_max_is_state_lim_[ROT_MAX == SN_LIM ? 1 : -1];
#endif

/* sheet node (r, c) of side s in ring order: left (end), up (end), right
 * (start), down (start); no brace */
SN_INLINE unsigned sheet_ends(uint32_t s, uint32_t r, uint32_t c, uint32_t seg[5], int sgn[5]) {
    uint32_t h = r * (s - 1u) + c, n = r * s + c, nh = s * (s - 1u);
    unsigned k = 0;
    if (c > 0) { seg[k] = h - 1u; sgn[k++] = 1; }
    if (r > 0) { seg[k] = nh + n - s; sgn[k++] = 1; }
    if (c + 1u < s) { seg[k] = h; sgn[k++] = -1; }
    if (r + 1u < s) { seg[k] = nh + n; sgn[k++] = -1; }
    return k;
}

SN_INLINE int is_brace(const seg_lvl *L, uint32_t i) {
    return L->kind == SN_SEG_SHEET && L->side == 2u && i >= 4u;
}

/* half length of segment i with its reciprocal and shift: the level's on
 * the finest level; on a coarser one the segment's own (words 12-14, set by
 * seg_from_nodes from its restricted nodes) */
SN_INLINE sn_q seg_half(const seg_lvl *L, uint32_t i, sn_q *r, int *sh) {
    const sn_q *S = L->S + SEG_W * i;
    if (L->l == 0) { *r = L->rh; *sh = L->sh; return L->half; }
    *r = S[13];
    *sh = (int)S[14];
    return S[12];
}

/* A value the bounds (SEGMENTS.md "Fixed point, bounds") keep within int32 (fixed; float: float), so on
 * a 32-bit target a product of two is one 32x32->64 multiply (SMULL on a
 * Cortex-M4, not a 64x64 one); on a 64-bit target int64 (no sign
 * extensions). The same values either way: the same bits. */
#if defined(SN_FLOAT)
typedef float seg_n;
#define MUL(a, b) ((a) * (b))
#else
#if UINTPTR_MAX > 0xFFFFFFFFu
typedef int64_t seg_n;
typedef uint64_t seg_u;
#else
typedef int32_t seg_n;
typedef uint32_t seg_u;
#endif
#define MUL(a, b) ((int64_t)(a) * (b))
#endif
/* an int64 value into seg_n; the range-checking build asserts the int32 bound
 * on every target (a 64-bit seg_n would hide a value a 32-bit one truncates) */
#if defined(SN_FLOAT)
#define NARROW(x) (x)
#else
#define NARROW(x) narrow(x)
SN_INLINE seg_n narrow(int64_t x) {
    seg_n v;
    SN_RANGE(x >= -INT32_MAX && x <= INT32_MAX, "segment factor beyond int32", x);
    v = (seg_n)x;
#if defined(__GNUC__) && UINTPTR_MAX <= 0xFFFFFFFFu
    /* no code, the same value: GCC would otherwise multiply the 64-bit value
     * v came from (known to fit) as 64 x 64 bits (UMULL and two MLA, seen on
     * the Cortex-M4) instead of one SMULL */
    __asm__("" : "+r"(v));
#endif
    return v;
}
#endif

/* sn_out(v, 0, sat) of a value known to be within int32 (fixed: clamp to
 * +-SN_LIM, counted): the same value, but with seg_n int32 on a 32-bit
 * target two 32-bit compares instead of a 64-bit difference and 64-bit
 * compares (the endpoints' differences below: each endpoint < 2^30) */
#if defined(SN_FLOAT)
#define SEG_OUT(v, sat) sn_out((v), 0, (sat))
#else
#define SEG_OUT(v, sat) seg_out((v), (sat))
SN_INLINE seg_n seg_out(seg_n v, uint32_t *sat) {
    SN_RANGE(v >= -INT32_MAX && v <= INT32_MAX, "segment sum beyond int32", v);
    /* |v| <= SN_LIM as one unsigned compare in seg_n's width (exact for
     * every value of that width), the clamp out of the straight path */
    if ((seg_u)v + (seg_u)SN_LIM <= 2u * (seg_u)SN_LIM) return v;
    (*sat)++;
    return v > 0 ? SN_LIM : -SN_LIM;
}
#endif

/* a clamped to +-m (0 < m < 2^31, fixed; float the same compares): the
 * move's turn limiter and the star's last share */
#if !defined(SN_FLOAT) && defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
/* Cortex-M: |a| <= m iff the low word is within +-m (one unsigned compare)
 * and the high word its sign, not two 64-bit compares; the same value */
SN_INLINE sn_acc seg_lim(sn_acc a, sn_acc m) {
    const uint32_t lo = (uint32_t)a, um = (uint32_t)m;
    if (lo + um <= 2u * um && (int32_t)(a >> 32) == (int32_t)lo >> 31) return a;
    return a > 0 ? m : -m;
}
#elif !defined(SN_FLOAT)
/* |a| <= m as one unsigned compare of the 64-bit value (exact for every
 * int64 a and 0 < m < 2^62), the clamp out of the straight path: the same
 * value as the two compares */
SN_INLINE sn_acc seg_lim(sn_acc a, sn_acc m) {
    if ((uint64_t)a + (uint64_t)m <= 2u * (uint64_t)m) return a;
    return a > 0 ? m : -m;
}
#else
SN_INLINE sn_acc seg_lim(sn_acc a, sn_acc m) { return a > m ? m : (a < -m ? -m : a); }
#endif

/* ---- the move's multiplies and shifts (sn_segment_sweep.c; tested bit for bit
 * against a rounded division in test_runtime_kernels, on the Cortex-M4 too) ---- */
SN_INLINE sn_acc r30(sn_acc a) { /* fixed: a Q30 product (sum) back to its operand's Q, rounded */
#if defined(SN_FLOAT)
    return a;
#else
    return sn_rshr64(a, SN_Q_ROT);
#endif
}
/* r30(x b) for a factor |x| < 2^29 (fixed; the bound stated at each use):
 * on a Cortex-M with the DSP extension one SMMULR of 4x and b,
 * (4 x b + 2^31) >> 32 = (x b + 2^29) >> 30 = sn_rshr64(x b, 30) exactly
 * (4x within int32), instead of SMULL or SMLAL on a bias pair and a
 * 64-bit shift (5 instructions); elsewhere that expression */
#if !defined(SN_FLOAT) && defined(__GNUC__) && defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && \
    defined(__ARM_FEATURE_DSP)
#define SEG_SMMULR 1
SN_INLINE seg_n r30s(seg_n x, seg_n b) {
    int32_t r;
    SN_RANGE(x >= -((int32_t)1 << 29) && x < ((int32_t)1 << 29), "segment SMMULR factor beyond 2^29", x);
    __asm__("smmulr %0, %1, %2" : "=r"(r) : "r"(x * 4), "r"(b));
    return r;
}
#else
SN_INLINE seg_n r30s(seg_n x, seg_n b) {
    SN_RANGE(x >= -((int32_t)1 << 29) && x < ((int32_t)1 << 29), "segment SMMULR factor beyond 2^29", x);
    return NARROW(r30(MUL(x, b)));
}
#endif

/* the turn's rounding shift by sh in [0, 29] (recip's b - 1, half < 2^30)
 * with its bias 2^(sh-1) (0 at sh = 0) formed once per level or segment
 * (seg_bias), not per component: sn_rshr64(a, sh)'s value. Cortex-M: on
 * the two words, hi << (32 - sh) as (hi << (31 - sh)) << 1 (0 at sh = 0,
 * every shift < 32) */
SN_INLINE sn_acc seg_bias(int sh) {
#if defined(SN_FLOAT)
    (void)sh;
    return 0;
#else
    SN_RANGE(sh >= 0 && sh <= 29, "segment turn shift beyond [0, 29]", sh);
    return ((sn_acc)1 << sh) >> 1;
#endif
}
SN_INLINE sn_acc seg_rsh(sn_acc a, int sh, sn_acc bias) {
#if defined(SN_FLOAT)
    (void)sh;
    (void)bias;
    return a;
#else
    SN_RANGE(a <= INT64_MAX - bias, "rounding add overflows int64", a);
#if defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M'
    {   /* a + bias as one 64-bit sum (an SMLAL on the bias when a is a product) */
        const int64_t y = a + bias;
        const uint32_t lo = (uint32_t)y;
        const int32_t hi = (int32_t)(y >> 32);
        return (int64_t)(hi >> sh) * ((int64_t)1 << 32) + (int64_t)((lo >> sh) | (((uint32_t)hi << (31 - sh)) << 1));
    }
#else
    return (a + bias) >> sh;
#endif
#endif
}

/* P = G +- half u: the offset (|u| <= 1, half <= 2^29: <= 2^29) in int64,
 * one clamp of the sum (fixed); float the same expression */
SN_INLINE void end_of(const seg_lvl *L, uint32_t i, int s, sn_q P[3], uint32_t *sat) {
    const sn_q *S = L->S + SEG_W * i;
    sn_q r;
    int sh;
    sn_q hl = seg_half(L, i, &r, &sh);
    /* components written out: compilers kept the loop (it runs per end per
     * sweep); hl < 2^28 (a coarse half is half the clamped nodes' distance,
     * |d_k| <= 2^28: < 2^27.8), so r30s (one SMMULR on the M4) */
#if defined(SN_FLOAT)
    sn_q o0 = S[3] * hl, o1 = S[4] * hl, o2 = S[5] * hl;
#else
    seg_n o0 = r30s(hl, S[3]), o1 = r30s(hl, S[4]), o2 = r30s(hl, S[5]);
#endif
    /* |G| <= 2^28, offset <= 2^29: the end within int32, clamped as one (seg_out) */
    P[0] = (sn_q)SEG_OUT(NARROW(s > 0 ? S[0] + o0 : S[0] - o0), sat);
    P[1] = (sn_q)SEG_OUT(NARROW(s > 0 ? S[1] + o1 : S[1] - o1), sat);
    P[2] = (sn_q)SEG_OUT(NARROW(s > 0 ? S[2] + o2 : S[2] - o2), sat);
}

/* mean of k <= 5 values: fixed sum x round(2^30/k) >> 30 (sums of five Q22 values < 2^31.4) */
SN_INLINE sn_q mean_k(sn_acc sum, unsigned k, uint32_t *sat) {
#if defined(SN_FLOAT)
    return sn_out(sum / (float)k, 0, sat);
#else
    static const int32_t inv[6] = {0, 1 << 30, 1 << 29, 357913941, 1 << 28, 214748365};
    return sn_out(sum * inv[k], SN_Q_ROT, sat);
#endif
}

/* a Q60 product sum known to be within +-2^61 to Q30 (rounded), no clamp */
SN_INLINE sn_q shr30(sn_acc a) {
#if defined(SN_FLOAT)
    return a;
#else
    return (sn_q)sn_rshr64(a, SN_Q_ROT);
#endif
}

/* One multiply-only Newton step towards unit length: u = x (3 - |x|^2)/2
 * (no square root, no division). For |x| = n the result has length
 * n (3 - n^2)/2 <= 1 (equality at n = 1): an error e = n^2 - 1 becomes
 * -3e^2/4 + e^3/4. A turn of u (|u| in [0.987, 1]) by e perpendicular to u
 * with |e_k| <= 0.25 gives n^2 <= 1.1875, so the result stays in
 * [0.987, 1] (SEGMENTS.md "Fixed point, bounds"); the small turns of the
 * later sweeps restore the length to the LSB, and the sweeps' end
 * renormalizes exactly (renormalize, once per segment and step). */
SN_INLINE void newton_unit(const sn_acc x[3], sn_q u[3]) {
#if defined(SN_FLOAT)
    float f = 1.5f - 0.5f * (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
    u[0] = x[0] * f; u[1] = x[1] * f; u[2] = x[2] * f;
#else
    /* |x_k| < 1.5 2^30: the sum of squares <= 1.19 2^60 (Q60); f in Q30
     * within [0.9, 1.01] 2^30; x_k f < 2^61 */
    int64_t n2 = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    int64_t f = sn_rshr64(((int64_t)3 << 60) - n2, SN_Q_ROT + 1);
    unsigned k;
    for (k = 0; k < 3; k++) u[k] = (sn_q)sn_rshr64(x[k] * f, SN_Q_ROT);
#endif
}

#if !defined(SN_FLOAT) && defined(__GNUC__) && defined(__ARM_ARCH_PROFILE) && __ARM_ARCH_PROFILE == 'M' && \
    defined(__ARM_FEATURE_DSP) && defined(__thumb2__)
#define SEG_M4 1
/* Cortex-M4 (Thumb-2, DSP): level 0's star() and pair() moves in assembly
 * (sn_segment_m4.c, sn_m4_star, sn_m4_pair), their operands and scratch
 * here; the offsets are the assembly's (checked by a typedef there) */
struct seg_m4_slot {      /* an end's move (8 words) */
    sn_q *S;                /* its segment's words */
    int32_t d[3], f, t[3];  /* the gap (the star's first pass: its end P), turn factor, translation */
};
struct seg_m4_star {
    sn_q *S;              /* 0: the level's segment words */
    int32_t h4, kf, sh;   /* 4: 4 half (r30s's SMMULR operand), kf1, the turn's shift */
    int32_t rs, bias;     /* 16: 31 - sh, the turn's rounding bias (< 2^29) */
    int32_t g1n;          /* 24: omega gamma */
    uint32_t ls;          /* 28: clamps counted */
    int32_t inv;          /* 32: round(2^30 / k) (mean_k) */
    struct seg_m4_slot *plast; /* 36: the last end's slot */
    const uint32_t *seg;  /* 40 */
    const int *sgn;       /* 44 */
    uint32_t k;           /* 48 */
    int32_t *slot;        /* 52: the current slot's t while the turn has the registers */
    int32_t kf0, gh;      /* 56: the pair's turn factor rf2/half and omega gamma/2 */
    struct seg_m4_slot e[4]; /* 64: the ends' moves */
};
void sn_m4_star(struct seg_m4_star *c);
/* pair(a, sa, b, sb) on level 0 (not measuring); sg: bit 0 sa < 0, bit 1 sb < 0 */
void sn_m4_pair(struct seg_m4_star *c, uint32_t a, uint32_t b, uint32_t sg);
/* an attachment's pins on level 0 (seg, sgn, plast = e + k - 1 set), target T */
void sn_m4_pins(struct seg_m4_star *c, const sn_q *T);
#endif

#define SEG_TCACHE 4u /* the cow's blanket has 4 attachments, its tail 1 */
typedef struct seg_ctx {
    sn_ihdr *h;
    const seg_mesh *M;
    /* Palazzi's factors times the over-relaxation omega = relax/32 (1 when
     * relax = 32: then these are exactly the plain factors, same bits) */
    sn_q gh, rf1, rf2;  /* omega gamma/2, omega (1-gamma), omega (1-gamma)/2 */
    sn_acc g1;          /* omega gamma (fixed Q30, < 2^31: int64) */
    sn_q gb, rfu;       /* gamma/2, 1-gamma: braces and floor, not relaxed */
    seg_n kf0, kf1;     /* level 0's turn factors rf2/half, rf1/half (seg_kf), set by sweep */
    seg_n g1n;          /* omega gamma: < 2^31 (relax <= 63), int32 */
    sn_acc bias0;       /* level 0's turn rounding bias 2^(sh-1) (seg_bias), set by sweep_prep */
    sn_q fn[3], foff;   /* floor in the internal frame */
    int floor_on;
    sn_len2 gap2;        /* the measuring pass's largest |d|^2 */
    /* the first SEG_TCACHE attachments' targets and their clamp counts:
     * the joints and the flesh do not move during the segment step, so
     * each target is computed once per step, not once per sweep and level */
    sn_q T[SEG_TCACHE][3];
    uint32_t Tsat[SEG_TCACHE];
    /* their rod ends on the current level (sweep_prep): count (0: the
     * attached node is not a node of the level), segments, signs */
    unsigned ak[SEG_TCACHE];
    uint32_t aseg[SEG_TCACHE][5];
    int asgn[SEG_TCACHE][5];
#if defined(SEG_M4)
    struct seg_m4_star m4; /* level 0's constants set by sweep_prep */
#endif
} seg_ctx;


/* sweeps (sn_segment_sweep.c) */
/* attachment target of record rec in the internal frame */
void seg_attach_target(const sn_ihdr *h, const unsigned char *rec, sn_q T[3], uint32_t *sat);
/* what every sweep of level L reads and none changes: once per level */
void seg_sweep_prep(seg_ctx *C, const seg_lvl *L);
/* one sweep in direction dir (0 up / row-major, 1 back), or (measure) the gaps it would close */
void seg_sweep(seg_ctx *C, const seg_lvl *L, int measure, unsigned dir, uint32_t *sat);
/* a sheet node's star projection (k = 3, 4 ends): the scalar one (simd 0)
 * or the step's (SIMD where built), for the kernel test only */
void seg_star_test(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, int simd,
                   uint32_t *sat);
#if !defined(SN_FLOAT) && !defined(SN_SIMD_SCALAR) && defined(__AVX2__) && defined(__x86_64__)
#define SEG_STAR_IV 1
/* fixed, x86-64 AVX2: star() with its ends in int64 lanes (sn_kernels_seg_avx2.c), the same bits */
void seg_star_iv(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, uint32_t *sat);
/* and pair()'s two moves (not measuring) in two lanes */
void seg_pair_iv(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, uint32_t *sat);
/* and an attachment's pins on its k = 2..4 ends (not measuring) in lanes */
void seg_pins_iv(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3],
                 uint32_t *sat);
#endif
/* an attachment's pins on k ends (not measuring): the scalar pins (simd 0)
 * or the step's form, for the kernel test only */
void seg_pins_test(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3],
                   int simd, uint32_t *sat);
#if defined(SN_FLOAT) && !defined(SN_SIMD_SCALAR) && (defined(__AVX2__) || (defined(__x86_64__) && defined(__SSE2__)))
#define SEG_STAR_SSE 1
/* float, x86-64: star(), pair() (not measuring) and an attachment's pins on
 * its 2-4 ends in SIMD lanes, the same floats (sn_kernels_seg_fx86.c) */
void seg_star_fx(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, uint32_t *sat);
void seg_pair_fx(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, uint32_t *sat);
void seg_pins_fx(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3],
                 uint32_t *sat);
#endif
/* a segment's move (d, t, turn factor, shift): the portable C (simd 0) or the step's form, for the kernel test only */
void seg_move_test(sn_q *S, const sn_q d[3], const sn_q t[3], sn_q kf, int sh, int simd, uint32_t *sat);
/* a pair's projection (not measuring): the scalar one (simd 0) or the step's, for the kernel test only */
void seg_pair_test(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, int simd, uint32_t *sat);
/* a sheet's nodes in one sweep of direction dir (not measuring): the node loop (simd 0) or the step's, for the kernel test only */
void seg_sheet_test(seg_ctx *C, const seg_lvl *L, unsigned dir, int simd, uint32_t *sat);
/* every segment's u of level L to unit length (three Newton steps) */
void seg_renormalize(const seg_lvl *L);
/* the measuring pass's largest |d|^2 as a length in public Q16.16 segment lengths (or float) */
sn_real seg_gap(sn_len2 n2, const seg_lvl *L);
#endif
