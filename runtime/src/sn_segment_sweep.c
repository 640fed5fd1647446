/* sn_segment_sweep.c -- segment meshes' displacement constraint (seed 004
 * §3.2, Gascuel and Gascuel's method as Palazzi applies it): the moves of one
 * segment end (pair, star, pin, floor), one Gauss-Seidel sweep over a level
 * in a fixed order, the measuring pass. The hot part of the segment step
 * (SEGMENTS.md: Sweep, "Fewer operations in the sweeps").
 * Cost of a sweep: c3 E_l + c4 A + F c5 2 S_l (sn_segment.c's formula).
 * The same moves in SIMD lanes: sn_kernels_seg_avx2.c (fixed, x86-64 AVX2),
 * sn_kernels_seg_fx86.c (float, x86-64); the Cortex-M4 turn here (turn_m4).
 */
#include "sn_segment.h"

/* ---------------- the displacement constraint (seed 004 §3.2) ---------------- */

/* every segment's u of a level to unit length: every write of u leaves
 * |u| in [0.9876, 1] (newton_unit's bound, below), so three Newton steps
 * reach the LSB (|u|^2 - 1: 2.5e-2 -> 4.6e-4 -> 1.6e-7 -> 2e-14, below
 * Q30's 1e-9) without a square root or a division */
void seg_renormalize(const seg_lvl *L) {
    uint32_t i;
    unsigned it, k;
    for (i = 0; i < L->ns; i++) {
        sn_q *u = L->S + SEG_W * i + 3;
        for (it = 0; it < 3; it++) {
            sn_acc x[3];
            for (k = 0; k < 3; k++) x[k] = u[k];
            newton_unit(x, u);
        }
    }
}

/* Move segment i so its endpoint (sign s) closes part of the gap d: the
 * centre by t, and a rotation closing the share rf of the gap's part
 * perpendicular to the segment, seed 004 eq. 3.8 with Palazzi's user factor:
 *   dTheta = rf (r x d) / |r|^2,  r = s half u,  so  dTheta = s rf (u x d) / half,
 * applied as u + dTheta x u = u + e, e = s rf d_perp / half (for a unit u,
 * (u x d) x u = d - (d.u) u = d_perp): no cross products. Each component
 * of the turn e is limited to ROT_MAX (0.25 rad; a designed limiter of the
 * small-angle update, not counted in sat) and e's part along u removed
 * again (the limiter may tilt it), so |u + e|^2 <= |u|^2 + 3/16; then one
 * Newton step towards unit length (newton_unit).
 * Fixed: kf = s rf r / 2^30 (|kf| <= 2^30) with r the half length's
 * reciprocal 2^(29+b)/half, e = d_perp kf >> (b - 1) (Q30). Bounds: see
 * move_seg; d_perp kf <= 2^59.6; e.u <= 2^58.8 in Q60. */
/* the turn factor of segment i's end s: s rf / half (fixed: s rf r >> 30,
 * |.| <= 2^30, with the shift of r in *sh, see seg_move) */
SN_INLINE seg_n seg_kf(const seg_lvl *L, uint32_t i, int s, sn_q rf, int *sh) {
    sn_q r;
    seg_n kf;
    (void)seg_half(L, i, &r, sh);
    kf = NARROW(r30(MUL(rf, r)));
    return s > 0 ? kf : -kf;
}

/* the move on one segment's words S, all in registers (see above). Fixed,
 * |u| <= 1 (+LSBs) kept by every write of u: |d_k| <= 2^28 (clamped to the
 * state range), d.u -> Q22 <= sqrt(3) 2^28, d_perp_k <= 2^29.6, e_k <=
 * 2^28, e.u <= sqrt(3) 2^28, x_k < 1.5 2^30 (u plus e's part across u,
 * |.| <= |e|), f in [0.47, 1.01] 2^30: every factor within int32 (NARROW). */
/* the hot move inlined into its few callers (GCC/Clang would otherwise
 * call it: about 20 instructions of call overhead on a ~130-instruction body) */
#if defined(__GNUC__)
#define SEG_HOT static inline __attribute__((always_inline))
#else
#define SEG_HOT static inline
#endif
SEG_HOT void move_seg_c(sn_q *S, seg_n d0, seg_n d1, seg_n d2, seg_n t0, seg_n t1, seg_n t2, seg_n kf,
                          int sh, sn_acc bias, uint32_t *sat) {
    seg_n u0 = S[3], u1 = S[4], u2 = S[5], du, e0, e1, e2, eu, x0, x1, x2, f;
    d0 = NARROW(d0); d1 = NARROW(d1); d2 = NARROW(d2); /* (32-bit products, see narrow) */
    du = NARROW(r30(MUL(d0, u0) + MUL(d1, u1) + MUL(d2, u2)));
    e0 = NARROW(seg_lim(seg_rsh(MUL(NARROW(d0 - r30s(du, u0)), kf), sh, bias), ROT_MAX));
    e1 = NARROW(seg_lim(seg_rsh(MUL(NARROW(d1 - r30s(du, u1)), kf), sh, bias), ROT_MAX));
    e2 = NARROW(seg_lim(seg_rsh(MUL(NARROW(d2 - r30s(du, u2)), kf), sh, bias), ROT_MAX));
    eu = NARROW(r30(MUL(e0, u0) + MUL(e1, u1) + MUL(e2, u2)));
    x0 = NARROW(u0 + e0 - r30s(eu, u0));
    x1 = NARROW(u1 + e1 - r30s(eu, u1));
    x2 = NARROW(u2 + e2 - r30s(eu, u2));
#if defined(SN_FLOAT)
    f = 1.5f - 0.5f * (x0 * x0 + x1 * x1 + x2 * x2);
#else
    f = NARROW(sn_rshr64(((int64_t)3 << 60) - (MUL(x0, x0) + MUL(x1, x1) + MUL(x2, x2)), SN_Q_ROT + 1));
#endif
    S[3] = (sn_q)r30(MUL(x0, f));
    S[4] = (sn_q)r30(MUL(x1, f));
    S[5] = (sn_q)r30(MUL(x2, f));
    /* |G| <= 2^28, |t| <= 2^29 (a star's last end, else <= 2^28): the sum
     * within int32, no overflow test (sn_add's) needed, same value */
    S[0] = (sn_q)SEG_OUT((seg_n)S[0] + t0, sat);
    S[1] = (sn_q)SEG_OUT((seg_n)S[1] + t1, sat);
    S[2] = (sn_q)SEG_OUT((seg_n)S[2] + t2, sat);
}

#if defined(SEG_M4)
#define SEG_TURN_M4 1
/* Cortex-M4 (Thumb-2, DSP): move_seg's turn (words 3-5) in one asm block,
 * the same integers as move_seg_c with the vectors in registers: r30 as
 * SMLAL onto the rounding bias (2^29, 0) and the two words' shift, r30s
 * as SMMULR of 4x (|du|, |eu| < 2^29, as r30s), the turn's shift on the
 * SMLAL sum p kf + bias with its clamp (seg_rsh, seg_lim: the low word
 * within +-2^28 and the high word its sign), f = (3 2^60 + 2^30 - |x|^2)
 * >> 31 by RSBS/SBC. The translation G + t stays C (move_seg). */
/* one copy, called (inlined at its ten call sites it cost more: 3,489,197
 * instructions per cow step against 3,483,190, and flash) */
__attribute__((noinline)) static void turn_m4(sn_q *S, int32_t d0, int32_t d1, int32_t d2, int32_t kf, int32_t sh, int32_t bias) {
    int32_t u0, u1, u2, a, b, c;
#define SEG_DOTU /* a = 4 r30(d . u) (d0..d2 . u0..u2, from the rounding term 2^29): SMMULR's operand */ \
    "mov %[a], #0x20000000\n\t"                                                           \
    "mov %[b], #0\n\t"                                                                    \
    "smlal %[a], %[b], %[d0], %[u0]\n\t"                                                  \
    "smlal %[a], %[b], %[d1], %[u1]\n\t"                                                  \
    "smlal %[a], %[b], %[d2], %[u2]\n\t"                                                  \
    "lsr %[a], %[a], #30\n\t"                                                             \
    "orr %[a], %[a], %[b], lsl #2\n\t"                                                    \
    "lsl %[a], %[a], #2\n\t"
#define SEG_E(d) /* e = seg_lim(seg_rsh(d kf, sh, bias), 2^28) into d */                  \
    "mov %[a], %[bias]\n\t"                                                                \
    "mov %[b], #0\n\t"                                                                     \
    "smlal %[a], %[b], %[" d "], %[kf]\n\t"                                                \
    "lsr %[a], %[a], %[sh]\n\t"                                                            \
    "rsb %[c], %[sh], #31\n\t"                                                             \
    "lsl %[c], %[b], %[c]\n\t"                                                             \
    "orr %[a], %[a], %[c], lsl #1\n\t"                                                     \
    "asr %[b], %[b], %[sh]\n\t"                                                            \
    "add %[c], %[a], #0x10000000\n\t"                                                      \
    "cmp %[c], #0x20000000\n\t"                                                            \
    "bhi 1f\n\t"                                                                           \
    "cmp %[b], %[a], asr #31\n\t"                                                          \
    "beq 2f\n"                                                                             \
    "1:\n\t"                                                                               \
    "mov %[a], #0x10000000\n\t"                                                            \
    "cmp %[b], #0\n\t"                                                                     \
    "it lt\n\t"                                                                            \
    "rsblt %[a], %[a], #0\n"                                                               \
    "2:\n\t"                                                                               \
    "mov %[" d "], %[a]\n\t"
#define SEG_U(u, off) /* u' = r30(x f), stored */                                          \
    "mov %[b], #0x20000000\n\t"                                                            \
    "mov %[c], #0\n\t"                                                                     \
    "smlal %[b], %[c], %[" u "], %[a]\n\t"                                                 \
    "lsr %[b], %[b], #30\n\t"                                                              \
    "orr %[b], %[b], %[c], lsl #2\n\t"                                                     \
    "str %[b], [%[S], #" off "]\n\t"
    __asm__ volatile(
        "ldr %[u0], [%[S], #12]\n\t"
        "ldr %[u1], [%[S], #16]\n\t"
        "ldr %[u2], [%[S], #20]\n\t"
        /* du = r30(d.u); 4 du; d_perp = d - r30s(du, u) */
        SEG_DOTU
        "smmulr %[b], %[a], %[u0]\n\t"
        "sub %[d0], %[d0], %[b]\n\t"
        "smmulr %[b], %[a], %[u1]\n\t"
        "sub %[d1], %[d1], %[b]\n\t"
        "smmulr %[b], %[a], %[u2]\n\t"
        "sub %[d2], %[d2], %[b]\n\t"
        SEG_E("d0") SEG_E("d1") SEG_E("d2")
        /* eu = r30(e.u); x = u + e - r30s(eu, u) */
        SEG_DOTU
        "smmulr %[b], %[a], %[u0]\n\t"
        "add %[u0], %[u0], %[d0]\n\t"
        "sub %[u0], %[u0], %[b]\n\t"
        "smmulr %[b], %[a], %[u1]\n\t"
        "add %[u1], %[u1], %[d1]\n\t"
        "sub %[u1], %[u1], %[b]\n\t"
        "smmulr %[b], %[a], %[u2]\n\t"
        "add %[u2], %[u2], %[d2]\n\t"
        "sub %[u2], %[u2], %[b]\n\t"
        /* f = (3 2^60 + 2^30 - |x|^2) >> 31 (positive) */
        "smull %[a], %[b], %[u0], %[u0]\n\t"
        "smlal %[a], %[b], %[u1], %[u1]\n\t"
        "smlal %[a], %[b], %[u2], %[u2]\n\t"
        "rsbs %[a], %[a], #0x40000000\n\t"
        "mov %[c], #0x30000000\n\t"
        "sbc %[b], %[c], %[b]\n\t"
        "lsr %[a], %[a], #31\n\t"
        "orr %[a], %[a], %[b], lsl #1\n\t"
        SEG_U("u0", "12") SEG_U("u1", "16") SEG_U("u2", "20")
        : [d0] "+&r"(d0), [d1] "+&r"(d1), [d2] "+&r"(d2), [kf] "+&r"(kf), [sh] "+&r"(sh), [bias] "+&r"(bias),
          [u0] "=&r"(u0), [u1] "=&r"(u1), [u2] "=&r"(u2), [a] "=&r"(a), [b] "=&r"(b), [c] "=&r"(c)
        : [S] "r"(S)
        : "cc", "memory");
#undef SEG_E
#undef SEG_U
#undef SEG_DOTU
}
#endif
/* the move as the sweeps run it: Cortex-M4 the turn in Thumb-2 (turn_m4) */
SEG_HOT void move_seg(sn_q *S, seg_n d0, seg_n d1, seg_n d2, seg_n t0, seg_n t1, seg_n t2, seg_n kf,
                      int sh, sn_acc bias, uint32_t *sat) {
#if defined(SEG_TURN_M4)
    turn_m4(S, d0, d1, d2, kf, sh, (int32_t)bias);
    S[0] = (sn_q)SEG_OUT((seg_n)S[0] + t0, sat);
    S[1] = (sn_q)SEG_OUT((seg_n)S[1] + t1, sat);
    S[2] = (sn_q)SEG_OUT((seg_n)S[2] + t2, sat);
#else
    move_seg_c(S, d0, d1, d2, t0, t1, t2, kf, sh, bias, sat);
#endif
}

/* move_seg_c (simd 0) or move_seg (the step's), for test_runtime_kernels (not called by the step) */
void seg_move_test(sn_q *S, const sn_q d[3], const sn_q t[3], sn_q kf, int sh, int simd, uint32_t *sat) {
    if (simd) move_seg(S, d[0], d[1], d[2], t[0], t[1], t[2], kf, sh, seg_bias(sh), sat);
    else move_seg_c(S, d[0], d[1], d[2], t[0], t[1], t[2], kf, sh, seg_bias(sh), sat);
}

static void seg_move(const seg_lvl *L, uint32_t i, int s, const sn_q t[3], const sn_q d[3], sn_q rf,
                     uint32_t *sat) {
    int sh;
    seg_n kf = seg_kf(L, i, s, rf, &sh);
    move_seg(L->S + SEG_W * i, d[0], d[1], d[2], t[0], t[1], t[2], kf, sh, seg_bias(sh), sat);
}

/* The measuring pass keeps the largest |d|^2 and converts it once (seg_gap):
 * the conversion is monotonic, so the same value as the largest converted
 * |d| (fixed), without a square root per pair (sn_norm2, sn_internal.h). */

/* sqrt(n2) in public Q16.16 segment lengths (or float) */
sn_real seg_gap(sn_len2 n2, const seg_lvl *L) {
#if defined(SN_FLOAT)
    return n2 > 0.0f ? n2 * sn_frsqrt(n2) / (2.0f * L->half) : 0.0f;
#else
    int64_t g = ((int64_t)sn_isqrt64(n2) << 16) / (2 * (int64_t)L->half);
    return g > INT32_MAX ? INT32_MAX : (sn_real)g;
#endif
}

#if defined(SEG_M4)
/* level 0's constants of sn_m4_star (sweep_prep) */
static void seg_m4_prep(seg_ctx *C, const seg_lvl *L) {
    C->m4.S = L->S;
    C->m4.h4 = 4 * L->half; /* r30s's SMMULR operand: half < 2^28 */
    C->m4.kf = C->kf1;
    C->m4.sh = L->sh;
    C->m4.rs = 31 - L->sh;
    C->m4.bias = (int32_t)C->bias0;
    C->m4.g1n = C->g1n;
    C->m4.kf0 = C->kf0;
    C->m4.gh = C->gh;
}
/* star() on level 0, Cortex-M4: sn_m4_star (sn_segment_m4.c), the same integers and counts */
SN_INLINE void star_m4(seg_ctx *C, const uint32_t seg[5], const int sgn[5], unsigned k, uint32_t *sat) {
    C->m4.seg = seg;
    C->m4.sgn = sgn;
    C->m4.k = k;
    C->m4.inv = k == 4u ? (int32_t)1 << 28 : 357913941; /* mean_k's round(2^30/k) */
    C->m4.ls = 0;
    sn_m4_star(&C->m4);
    *sat += C->m4.ls;
}
/* pair() on level 0 (not measuring), Cortex-M4: sn_m4_pair, the same integers and counts */
SN_INLINE void pair_m4(seg_ctx *C, uint32_t a, int sa, uint32_t b, int sb, uint32_t *sat) {
    C->m4.ls = 0;
    sn_m4_pair(&C->m4, a, b, (sa < 0 ? 1u : 0u) | (sb < 0 ? 2u : 0u));
    *sat += C->m4.ls;
}
#endif

/* pair constraint between two endpoints of equal masses: d = P2 - P1,
 * t = gamma d / 2 computed once, +t on segment 1 and -t on segment 2 (linear
 * momentum kept exactly), each rotating to close (1-gamma)/2 of d's
 * perpendicular part */
SEG_HOT void pair_core(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, int measure,
                       uint32_t *sat) {
    sn_q *A = L->S + SEG_W * a, *B = L->S + SEG_W * b, d[3];
    seg_n ha, hb, ka, kb, t[3];
    uint32_t ls = 0; /* local count: no aliasing with the state words */
    int sha, shb;
    sn_acc ba, bb;
    if (L->l == 0) { /* seg_half, seg_kf: the level's half length and turn factor */
        ha = hb = L->half;
        sha = shb = L->sh;
        ba = bb = C->bias0;
        ka = kb = C->kf0;
    } else {
        ha = A[12]; hb = B[12];
        sha = (int)A[14]; shb = (int)B[14];
        ba = seg_bias(sha); bb = seg_bias(shb);
        ka = NARROW(r30(MUL(C->rf2, A[13])));
        kb = NARROW(r30(MUL(C->rf2, B[13])));
    }
    ha = sa > 0 ? ha : -ha;
    hb = sb > 0 ? hb : -hb;
    /* endpoints G +- half u (|.| < 2^30) and their difference, clamped;
     * t = omega gamma d / 2: |.| < 2^28 (components written out) */
    d[0] = (sn_q)SEG_OUT(NARROW(B[0] + r30s(hb, B[3])) - NARROW(A[0] + r30s(ha, A[3])), &ls);
    d[1] = (sn_q)SEG_OUT(NARROW(B[1] + r30s(hb, B[4])) - NARROW(A[1] + r30s(ha, A[4])), &ls);
    d[2] = (sn_q)SEG_OUT(NARROW(B[2] + r30s(hb, B[5])) - NARROW(A[2] + r30s(ha, A[5])), &ls);
    t[0] = r30s(d[0], C->gh);
    t[1] = r30s(d[1], C->gh);
    t[2] = r30s(d[2], C->gh);
    if (measure) {
        sn_len2 g = sn_norm2(d);
        C->gap2 = g > C->gap2 ? g : C->gap2;
    } else {
        ka = sa > 0 ? ka : -ka;
        kb = sb > 0 ? kb : -kb;
        move_seg(A, d[0], d[1], d[2], t[0], t[1], t[2], ka, sha, ba, &ls);
        move_seg(B, -d[0], -d[1], -d[2], -t[0], -t[1], -t[2], kb, shb, bb, &ls);
    }
    *sat += ls;
}

/* the pair as the sweeps run it: its two moves in lanes where built (fixed
 * AVX2 seg_pair_iv, float x86-64 pair_fv) */
SEG_HOT void pair(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, int measure, uint32_t *sat) {
#if defined(SEG_STAR_IV)
    if (!measure) { seg_pair_iv(C, L, a, sa, b, sb, sat); return; }
#elif defined(SEG_STAR_SSE)
    if (!measure) { seg_pair_fx(C, L, a, sa, b, sb, sat); return; }
#elif defined(SEG_M4)
    if (!measure && L->l == 0) { pair_m4(C, a, sa, b, sb, sat); return; }
#endif
    pair_core(C, L, a, sa, b, sb, measure, sat);
}

/* pair_core (simd 0) or the step's pair, for test_runtime_kernels; not called by the step */
void seg_pair_test(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, int simd, uint32_t *sat) {
#if defined(SEG_M4)
    if (simd && L->l == 0) seg_m4_prep(C, L); /* the step's sweep_prep */
#endif
    if (simd) pair(C, L, a, sa, b, sb, 0, sat);
    else pair_core(C, L, a, sa, b, sb, 0, sat);
}

/* The ends meeting at a sheet node (k >= 3) projected together towards
 * their mean m (one Gauss-Seidel step on the node's constraint "all ends
 * coincide", equal masses): end j takes D_j = m - P_j like an attachment
 * to m, t = omega gamma D_j and a turn closing omega (1-gamma) of D_j's
 * perpendicular part. At k = 2 this is pair() (D = d/2). A ring of k pairs
 * costs 2k endpoints and 2k moves; this k and k, and each end reaches the
 * node's mean in one projection instead of exchanging with its two ring
 * neighbours in turn (SEGMENTS.md, Sweep).
 * Linear momentum exact: the last end's t is minus the sum of the others'.
 * Fixed: endpoints |G +- half u| < 2^30, their sum over k <= 5 < 2^32.4,
 * times round(2^30/k) <= 2^28.4 (k >= 3) < 2^61 (mean_k); D clamped to the
 * state range as pair's d; t = D omega gamma (< 2^31) < 2^59 -> Q22 < 2^29. */
/* star()'s two loops over its k = 3 or 4 ends unrolled (GCC, Clang): per
 * cow step x86-64 fixed segments 785,010 -> 755,135 instructions, Cortex-M4
 * step 3,821,450 -> 3,757,556 for 4.6 kB of flash */
#if defined(__GNUC__)
#define SEG_UNROLL4 _Pragma("GCC unroll 4")
#else
#define SEG_UNROLL4
#endif
SEG_HOT void star(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k,
                  uint32_t *sat) {
    seg_n P[5][3];
    sn_acc s0 = 0, s1 = 0, s2 = 0, l0 = 0, l1 = 0, l2 = 0;
    sn_q m0, m1, m2;
    uint32_t ls = 0;
    unsigned j;
    const int coarse = L->l != 0;
    SEG_UNROLL4
    for (j = 0; j < k; j++) { /* components written out: compilers kept the loop */
        const sn_q *S = L->S + SEG_W * seg[j];
        seg_n h = coarse ? S[12] : L->half;
        if (sgn[j] < 0) h = -h;
        P[j][0] = NARROW(S[0] + r30s(h, S[3]));
        P[j][1] = NARROW(S[1] + r30s(h, S[4]));
        P[j][2] = NARROW(S[2] + r30s(h, S[5]));
        s0 += P[j][0]; s1 += P[j][1]; s2 += P[j][2];
    }
    m0 = mean_k(s0, k, &ls); m1 = mean_k(s1, k, &ls); m2 = mean_k(s2, k, &ls);
    SEG_UNROLL4
    for (j = 0; j < k; j++) {
        /* the turn factor, shift and bias of the end (seg_kf; a move writes
         * words 0-5 only, so the coarse words 12-14 read here are the
         * first loop's): no arrays of them across the loops */
        sn_q *S = L->S + SEG_W * seg[j];
        seg_n f = C->kf1;
        int sh = L->sh;
        sn_acc bias = C->bias0;
        /* |m| <= 2^28, |P| < 2^30: the difference within int32 */
        seg_n d0 = SEG_OUT((seg_n)m0 - P[j][0], &ls), d1 = SEG_OUT((seg_n)m1 - P[j][1], &ls),
              d2 = SEG_OUT((seg_n)m2 - P[j][2], &ls), t0, t1, t2;
        if (coarse) { sh = (int)S[14]; bias = seg_bias(sh); f = NARROW(r30(MUL(C->rf1, S[13]))); }
        if (sgn[j] < 0) f = -f;
        if (j + 1 < k) {
            t0 = r30s(d0, C->g1n); t1 = r30s(d1, C->g1n); t2 = r30s(d2, C->g1n);
            l0 -= t0; l1 -= t1; l2 -= t2;
        } else { /* the others' sum: |.| <= 2^29 unless a D was clamped */
            t0 = NARROW(seg_lim(l0, (sn_acc)2 * SN_LIM)); t1 = NARROW(seg_lim(l1, (sn_acc)2 * SN_LIM));
            t2 = NARROW(seg_lim(l2, (sn_acc)2 * SN_LIM));
        }
        move_seg(S, d0, d1, d2, t0, t1, t2, f, sh, bias, &ls);
    }
    *sat += ls;
}



/* star() (simd 0) or the step's form of it (star_fv, seg_star_iv where
 * built, sn_m4_star on level 0, else star) as a call: test_runtime_kernels
 * compares the two bit for bit. Not called by the step. */
void seg_star_test(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, int simd,
                   uint32_t *sat) {
#if defined(SEG_STAR_SSE)
    if (simd) { seg_star_fx(C, L, seg, sgn, k, sat); return; }
#elif defined(SEG_STAR_IV)
    if (simd) { seg_star_iv(C, L, seg, sgn, k, sat); return; }
#elif defined(SEG_M4)
    if (simd && L->l == 0) {
        seg_m4_prep(C, L);
        star_m4(C, seg, sgn, k, sat);
        return;
    }
#else
    (void)simd;
#endif
    if (k == 4) star(C, L, seg, sgn, 4u, sat);
    else star(C, L, seg, sgn, 3u, sat);
}

/* an endpoint against a point of infinite mass: the segment takes gamma d
 * and rotates to close (1-gamma) of the perpendicular part */
SEG_HOT void pin(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, const sn_q T[3], int measure, uint32_t *sat) {
    /* the end P, then d = T - P and t = omega gamma d (|d| 2^31 < 2^60),
     * each clamped and counted */
    sn_q *S = L->S + SEG_W * a, P[3], d[3], t0, t1, t2;
    int sh;
    sn_acc bias;
    seg_n kf;
    uint32_t ls = 0;
    end_of(L, a, sa, P, &ls);
    d[0] = sn_add(T[0], -P[0], &ls);
    d[1] = sn_add(T[1], -P[1], &ls);
    d[2] = sn_add(T[2], -P[2], &ls);
    if (measure) {
        sn_len2 g = sn_norm2(d);
        C->gap2 = g > C->gap2 ? g : C->gap2;
        *sat += ls;
        return;
    }
    /* omega gamma < 2^31 as its int32 copy g1n: one 32x32 product (the same
     * product as with the int64 g1) */
    /* |d| <= 2^28 (sn_add's clamp): r30s, then sn_out's clamp and count */
    t0 = (sn_q)SEG_OUT(r30s(d[0], C->g1n), &ls);
    t1 = (sn_q)SEG_OUT(r30s(d[1], C->g1n), &ls);
    t2 = (sn_q)SEG_OUT(r30s(d[2], C->g1n), &ls);
    if (L->l == 0) { /* level 0: the sweep's turn factor (seg_kf of the level's half) */
        kf = sa > 0 ? C->kf1 : -C->kf1;
        sh = L->sh;
        bias = C->bias0;
    } else {
        kf = seg_kf(L, a, sa, C->rf1, &sh);
        bias = seg_bias(sh);
    }
    move_seg(S, d[0], d[1], d[2], t0, t1, t2, kf, sh, bias, &ls);
    *sat += ls;
}

#if defined(SEG_M4)
/* an attachment's pins on level 0, Cortex-M4: sn_m4_pins, every end's gap
 * and translation as pin() forms them, then the moves (its ends belong to
 * distinct segments); the same integers and counts */
SN_INLINE void pins_m4(seg_ctx *C, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3], uint32_t *sat) {
    C->m4.seg = seg;
    C->m4.sgn = sgn;
    C->m4.plast = &C->m4.e[k - 1u];
    C->m4.ls = 0;
    sn_m4_pins(&C->m4, T);
    *sat += C->m4.ls;
}
#endif

/* an attachment's pins on its k ends: 2..4 at once in lanes where built
 * (seg_pins_iv, pins_fv; Cortex-M4 level 0 1..4: pins_m4), else one by one */
SEG_HOT void pins(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3],
                    int measure, uint32_t *sat) {
    unsigned j;
#if defined(SEG_STAR_IV)
    if (!measure && k >= 2u && k <= 4u) { seg_pins_iv(C, L, seg, sgn, k, T, sat); return; }
#elif defined(SEG_STAR_SSE)
    if (!measure && k >= 2u && k <= 4u) { seg_pins_fx(C, L, seg, sgn, k, T, sat); return; }
#elif defined(SEG_M4)
    if (!measure && L->l == 0 && k >= 1u && k <= 4u) { pins_m4(C, seg, sgn, k, T, sat); return; }
#endif
    for (j = 0; j < k; j++) pin(C, L, seg[j], sgn[j], T, measure, sat);
}

/* the scalar pins (simd 0) or the step's (pins), for test_runtime_kernels; not called by the step */
void seg_pins_test(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, const sn_q T[3],
                   int simd, uint32_t *sat) {
    unsigned j;
#if defined(SEG_M4)
    if (simd && L->l == 0) seg_m4_prep(C, L); /* the step's sweep_prep */
#endif
    if (simd) { pins(C, L, seg, sgn, k, T, 0, sat); return; }
    for (j = 0; j < k; j++) pin(C, L, seg[j], sgn[j], T, 0, sat);
}

/* attachment target in the internal frame */
void seg_attach_target(const sn_ihdr *h, const unsigned char *rec, sn_q T[3], uint32_t *sat) {
    uint32_t tgt = sn_rd_u16(rec + 4), k;
    if (rec[2] == SN_SEGATT_JOINT) {
        const sn_q *jR = CARR(h, o_jR, sn_q), *jT = CARR(h, o_jT, sn_q);
        sn_q p0[3];
        for (k = 0; k < 3; k++) p0[k] = rd_real(rec + 8, k);
        sn_rot(jR + 9 * tgt, p0, T, sat);
        for (k = 0; k < 3; k++) T[k] = sn_add(T[k], jT[3 * tgt + k], sat);
    } else { /* surface vertex: trilinear in its cell, as sn_get_surface */
        sn_surface_point(h, tgt, T);
    }
}

/* fine node n of the mesh at level l, or -1 if it is not a node there */
static int64_t level_node(const seg_mesh *M, const seg_lvl *L, uint32_t n) {
    uint32_t r, c, m;
    if (L->l == 0) return n;
    r = n / M->side; c = n % M->side; m = (1u << L->l) - 1u;
    if ((r & m) || (c & m)) return -1;
    return (int64_t)(r >> L->l) * L->side + (c >> L->l);
}

/* One sweep, or (measure) the gaps it would close. Order (NUMERICS.md):
 * attachments first, so the pinned ends propagate through the same sweep;
 * then the nodes: a chain from node 0 up on even sweeps (dir 0) and back
 * down on odd ones (symmetric Gauss-Seidel: a chain held at either end
 * has one sweep in each pass running away from its holder); a sheet
 * row-major, reversed on odd sweeps (symmetric too), each node of 3-4
 * ends by star, a corner by its pair; the brace crossing of a 2x2 level;
 * the floor last. The measuring pass measures at a node with k ends the
 * pairs (e0,e1), ..., (e_k-2, e_k-1) and, for k >= 3, (e_k-1, e0): a ring. */
/* the pairs around one sheet node's ring of k ends: each end with the next,
 * and the last with the first when the ring closes (k >= 3); moves only at
 * k = 2 (one pair), measures any k */
SN_INLINE void ring(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k, int measure,
                    uint32_t *sat) {
    unsigned j;
    for (j = 0; j + 1 < k; j++) pair(C, L, seg[j], sgn[j], seg[j + 1], sgn[j + 1], measure, sat);
    if (k >= 3) pair(C, L, seg[k - 1], sgn[k - 1], seg[0], sgn[0], measure, sat);
}

/* a sheet node's ends: measured as ring pairs (the gap's definition);
 * projected by star at k = 3 or 4 (a sheet node has 2 to 4 ends, a braced
 * 2x2 level's 3: the constant k lets the compiler unroll), pair at k = 2 */
SN_INLINE void node_proj(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k,
                         int measure, uint32_t *sat) {
    if (measure || k < 3) ring(C, L, seg, sgn, k, measure, sat);
#if defined(SEG_STAR_SSE)
    else seg_star_fx(C, L, seg, sgn, k, sat);
#elif defined(SEG_STAR_IV)
    else seg_star_iv(C, L, seg, sgn, k, sat);
#else
#if defined(SEG_M4)
    else if (L->l == 0) star_m4(C, seg, sgn, k, sat);
#endif
    else if (k == 4) star(C, L, seg, sgn, 4u, sat);
    else star(C, L, seg, sgn, 3u, sat);
#endif
}

/* a sheet's nodes in a sweep: row-major, reversed on odd sweeps */
SN_NOINLINE void sheet_nodes(seg_ctx *C, const seg_lvl *L, int measure, unsigned dir, uint32_t *sat) {
    const uint32_t sd = L->side;
    uint32_t seg[5], r, c;
    int sgn[5];
    unsigned k;
    for (r = 0; r < sd; r++)
        for (c = 0; c < sd; c++) {
            uint32_t rr = dir ? sd - 1u - r : r, cc = dir ? sd - 1u - c : c;
            if (sd == 2u) k = seg_node_ends(L, rr * 2u + cc, seg, sgn); /* with the brace */
            else k = sheet_ends(sd, rr, cc, seg, sgn);
            node_proj(C, L, seg, sgn, k, measure, sat);
        }
}

#if defined(SEG_M4)
/* A level-0 sheet's sweep (side > 2, not measuring), Cortex-M4: the nodes
 * in seg_sweep's order, each row's run of middle nodes (sheet_ends' ends
 * left, up, right, down without the top row's up and the bottom row's
 * down, the indices stepping by one along the row) without sheet_ends,
 * the row's first and last node by it; sn_m4_star / sn_m4_pair called directly
 * with the clamps counted across the sweep. The same projections in the
 * same order as node_proj's. */
static void sheet_m4(seg_ctx *C, const seg_lvl *L, unsigned dir, uint32_t *sat) {
    const uint32_t sd = L->side, nh = sd * (sd - 1u);
    uint32_t seg[5], r, c, j;
    int sgn[5];
    unsigned k;
    C->m4.seg = seg;
    C->m4.sgn = sgn;
    C->m4.ls = 0;
    for (r = 0; r < sd; r++) {
        const uint32_t rr = dir ? sd - 1u - r : r;
        for (c = 0; c < sd; c++) {
            const uint32_t cc = dir ? sd - 1u - c : c;
            if (c == 1u) { /* the row's sd - 2 middle nodes: left, (up,) right, (down) */
                const int top = rr == 0u, bottom = rr + 1u == sd;
                uint32_t h = rr * (sd - 1u) + cc, n = nh + rr * sd + cc;
                sgn[0] = 1;
                sgn[1] = top ? -1 : 1;
                sgn[2] = sgn[3] = -1;
                C->m4.k = top || bottom ? 3u : 4u;
                C->m4.inv = top || bottom ? 357913941 : (int32_t)1 << 28;
                for (j = 0; j < sd - 2u; j++) {
                    seg[0] = h - 1u;
                    if (top) {
                        seg[1] = h;
                        seg[2] = n;
                    } else {
                        seg[1] = n - sd;
                        seg[2] = h;
                        seg[3] = n; /* not read on the bottom row (k = 3) */
                    }
                    sn_m4_star(&C->m4);
                    if (dir) { h--; n--; } else { h++; n++; }
                }
                c = sd - 2u;
                continue;
            }
            k = sheet_ends(sd, rr, cc, seg, sgn);
            if (k == 2u) sn_m4_pair(&C->m4, seg[0], seg[1], (sgn[0] < 0 ? 1u : 0u) | (sgn[1] < 0 ? 2u : 0u));
            else {
                C->m4.k = k;
                C->m4.inv = k == 4u ? (int32_t)1 << 28 : 357913941;
                sn_m4_star(&C->m4);
            }
        }
    }
    *sat += C->m4.ls;
}
#endif

/* a sheet's nodes (side > 2) in one sweep (not measuring): the portable
 * C's (simd 0: pair_core, star) or the step's (sheet_m4 on a Cortex-M4's
 * level 0, else the node loop), for test_runtime_kernels; not called by
 * the step */
void seg_sheet_test(seg_ctx *C, const seg_lvl *L, unsigned dir, int simd, uint32_t *sat) {
    const uint32_t sd = L->side;
    uint32_t seg[5], r, c;
    int sgn[5];
    unsigned k;
    if (simd) {
#if defined(SEG_M4)
        seg_m4_prep(C, L);
        if (L->l == 0) { sheet_m4(C, L, dir, sat); return; }
#endif
        sheet_nodes(C, L, 0, dir, sat);
        return;
    }
    for (r = 0; r < sd; r++)
        for (c = 0; c < sd; c++) {
            k = sheet_ends(sd, dir ? sd - 1u - r : r, dir ? sd - 1u - c : c, seg, sgn);
            if (k == 2u) pair_core(C, L, seg[0], sgn[0], seg[1], sgn[1], 0, sat);
            else if (k == 4u) star(C, L, seg, sgn, 4u, sat);
            else star(C, L, seg, sgn, 3u, sat);
        }
}

/* What every sweep of level L reads and no sweep changes, once per level:
 * level 0's turn factors and the first SEG_TCACHE attachments' rod ends
 * (none where the attached fine node is not a node of the level) */
void seg_sweep_prep(seg_ctx *C, const seg_lvl *L) {
    const seg_mesh *M = C->M;
    uint32_t i;
    int sh;
    C->kf0 = seg_kf(L, 0, 1, C->rf2, &sh);
    C->kf1 = seg_kf(L, 0, 1, C->rf1, &sh);
    C->bias0 = seg_bias(L->sh);
#if defined(SEG_M4)
    if (L->l == 0) seg_m4_prep(C, L);
#endif
    for (i = 0; i < M->n_attach && i < SEG_TCACHE; i++) {
        const unsigned char *rec = C->h->v.sec[SN_SEC_SEGATTACH] + (size_t)(M->first_attach + i) * ATT_REC;
        int64_t ln = level_node(M, L, sn_rd_u16(rec));
        C->ak[i] = ln < 0 ? 0u : seg_node_ends(L, (uint32_t)ln, C->aseg[i], C->asgn[i]);
    }
}

void seg_sweep(seg_ctx *C, const seg_lvl *L, int measure, unsigned dir, uint32_t *sat) {
    const seg_mesh *M = C->M;
    uint32_t n, seg[5], i, q;
    int sgn[5];
    unsigned j, k;
    for (i = 0; i < M->n_attach; i++) {
        const unsigned char *rec = C->h->v.sec[SN_SEC_SEGATTACH] + (size_t)(M->first_attach + i) * ATT_REC;
        int64_t ln;
        sn_q T[3];
        if (i < SEG_TCACHE) { /* the same target, clamp count and ends as computed per sweep */
            if (C->ak[i] == 0) continue;
            *sat += C->Tsat[i];
            pins(C, L, C->aseg[i], C->asgn[i], C->ak[i], C->T[i], measure, sat);
            continue;
        }
        ln = level_node(M, L, sn_rd_u16(rec));
        if (ln < 0) continue; /* a fine node between the level's nodes: not pinned there */
        seg_attach_target(C->h, rec, T, sat);
        k = seg_node_ends(L, (uint32_t)ln, seg, sgn);
        for (j = 0; j < k; j++) pin(C, L, seg[j], sgn[j], T, measure, sat);
    }
    if (L->kind == SN_SEG_CHAIN) {
        /* interior node n joins segment n-1's end and segment n's start (one
         * pair; the chain's two end nodes have one end each, none) */
        for (q = 1; q + 1u < L->nn; q++) {
            n = dir ? L->nn - 1u - q : q;
            pair(C, L, n - 1u, 1, n, -1, measure, sat);
        }
    } else { /* sheet: row-major, reversed on odd sweeps (symmetric Gauss-Seidel) */
#if defined(SEG_M4)
        if (L->l == 0 && !measure && L->side > 2u) sheet_m4(C, L, dir, sat);
        else
#endif
        sheet_nodes(C, L, measure, dir, sat);
    }
    if (is_brace(L, 4) && !measure) {
        /* the braces keep the offset of their centres at the step's start
         * (node words: the restricted nodes until seg_node_means): a flat
         * cell stays flat, so the braced 2x2 level is rigid (fig. 4.4) and
         * not a mechanism folding about a diagonal */
        sn_q *B4 = L->S + SEG_W * 4, *B5 = L->S + SEG_W * 5, t;
        const sn_q *N = L->N;
        for (k = 0; k < 3; k++) {
            sn_q d0 = sn_add(mean_k((sn_acc)N[NODE_W + k] + N[2 * NODE_W + k], 2, sat),
                             -mean_k((sn_acc)N[k] + N[3 * NODE_W + k], 2, sat), sat);
            t = sn_mulq(sn_add(sn_add(B5[k], -B4[k], sat), -d0, sat), C->gb, SN_Q_ROT, sat);
            B4[k] = sn_add(B4[k], t, sat);
            B5[k] = sn_add(B5[k], -t, sat);
        }
    }
    if (C->floor_on && !measure)
        for (i = 0; i < L->ns; i++)
            for (j = 0; j < 2; j++) {
                int s = j ? 1 : -1;
                sn_q P[3], d[3], t[3], pen;
                seg_end(L, i, s, P, sat);
                pen = sn_add(C->foff, -sn_out(sn_mul(C->fn[0], P[0]) + sn_mul(C->fn[1], P[1]) +
                                                  sn_mul(C->fn[2], P[2]), SN_Q_ROT, sat), sat);
                pen = pen > 0 ? pen : 0; /* one-sided: only a penetration is pushed out */
                for (k = 0; k < 3; k++) {
                    d[k] = sn_mulq(C->fn[k], pen, SN_Q_ROT, sat);
                    t[k] = sn_mulq(d[k], M->gamma, SN_Q_ROT, sat);
                }
                seg_move(L, i, s, t, d, C->rfu, sat);
            }
}

