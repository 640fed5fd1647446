/* sn_segment.c -- segment meshes: chains and sheets of rigid segments joined
 * by displacement constraints (seed 004 ch. 3, Gascuel and Gascuel's method
 * as Palazzi applies it to surfaces), with the multilevel force distribution
 * of seed 004 ch. 4 on sheets (transfers in sn_segment_level.c). Model,
 * units and bounds: runtime/NUMERICS.md "Segment meshes (seed 004 ch. 3-4)".
 *
 * Step of one mesh (seed 004 fig. 3.1, fig. 4.3): restriction of positions
 * and impulses to the coarser levels; then from the coarsest level to the
 * finest: dynamics (damping, gravity and impulses by the level's share,
 * Euler-Cromer, seed 004 appendix A), a FIXED number of constraint sweeps
 * (no error-driven exit, unlike seed 004 fig. 3.8: `sweeps` on level 0,
 * `coarse_sweeps` on the coarser ones), velocities from the displacements,
 * prolongation to the next finer level. The sweeps' corrections may be
 * over-relaxed by omega = relax/32 (SOR on Palazzi's projection; omega 1
 * is seed 004 §3.2 as written; NUMERICS.md "Segment meshes").
 *
 * Cost per step, with S_l, N_l, E_l the segments, nodes and rod ends moved
 * at the nodes of level l (a pair 2, a star k), A the attachments, F = 1
 * if a floor is set, W_l the sweeps of level l (sweeps, coarse_sweeps for
 * l >= 1):
 *   sum_l [ c1 S_l + c2 N_l + W_l (c3 E_l + c4 A + F c5 2 S_l) ] + c6 N_0 levels
 * with constants c_i independent of the data: every loop runs over counts
 * fixed by the blob and the settings; no loop exits on a value.
 */
#include "sn_segment.h"

#if defined(SN_FLOAT)
#define THREE 3.0f
#else
#define THREE 3
#endif
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

/* ---------------- mesh records and topology ---------------- */

void seg_mesh_get(const sn_ihdr *h, uint32_t m, seg_mesh *M) {
    const unsigned char *r = h->v.sec[SN_SEC_SEGMESH];
    sn_q *base = (sn_q *)(void *)((unsigned char *)(uintptr_t)h + h->o_seg);
    uint32_t i, k;
    for (i = 0; i <= m; i++, r += SEG_REC) {
        M->kind = r[0]; M->levels = r[1]; M->sweeps = r[2]; M->flags = r[3];
        M->side = sn_rd_u16(r + 4); M->n_attach = sn_rd_u16(r + 6);
        M->first_node = sn_rd_u32(r + 8); M->first_attach = sn_rd_u32(r + 12);
        M->coarse_sweeps = r[16 + 9 * SN_REAL_BYTES]; M->relax = r[17 + 9 * SN_REAL_BYTES];
        sn_seg_counts(M->kind, M->side, M->levels, &M->segs, &M->nodes);
        M->S = base;
        M->N = base + SEG_W * M->segs;
        base = M->N + NODE_W * M->nodes;
        if (i == m) {
            M->len = rd_real(r + 16, 0); M->gamma = rd_real(r + 16, 1); M->keep = rd_real(r + 16, 2);
            M->inv_mass = rd_real(r + 16, 3); M->centre = rd_real(r + 16, 4);
            for (k = 0; k < SN_SEG_MAX_LEVELS; k++) M->share[k] = rd_real(r + 16, 5 + k);
        }
    }
}

/* reciprocal of a half length x: fixed r = 2^(29+b)/x in (2^29, 2^30] with
 * b = bits of x, so y/x (Q30) = y r >> (b - 1); float 1/x */
static void recip(sn_q x, sn_q *r, int *s) {
#if defined(SN_FLOAT)
    *r = 1.0f / x;
    *s = 0;
#else
    /* 2^(29+b)/x = 2^61/(x 2^(32-b)) with the divisor normalized: a 64/32
     * division (no library 64-bit divide on a 32-bit core), same quotient */
    int b = bitlen64((uint64_t)x);
    *r = (sn_q)sn_div64n((uint64_t)1 << 61, (uint32_t)x << (32 - b));
    *s = b - 1;
#endif
}

void seg_level(const seg_mesh *M, unsigned l, seg_lvl *L) {
    unsigned k;
    uint32_t so = 0, no = 0;
    L->kind = M->kind;
    L->l = l;
    for (k = 0; k <= l; k++) {
        uint32_t s = M->kind == SN_SEG_CHAIN ? M->side : ((M->side - 1u) >> k) + 1u;
        uint32_t ns = M->kind == SN_SEG_CHAIN ? s - 1u : 2u * s * (s - 1u) + (s == 2u ? 2u : 0u);
        uint32_t nn = M->kind == SN_SEG_CHAIN ? s : s * s;
        if (k == l) { L->side = s; L->ns = ns; L->nn = nn; }
        else { so += ns; no += nn; }
    }
    L->S = M->S + SEG_W * so;
    L->N = M->N + NODE_W * no;
#if defined(SN_FLOAT)
    L->half = M->len * (float)(1u << l) * 0.5f;
    L->bhalf = L->half * 1.41421356237f;
#else
    /* (side-1) len <= 2^27 (validated) and 2^l <= side-1: no overflow */
    L->half = (sn_q)(((int64_t)M->len << l) >> 1);
    L->half = L->half < 1 ? 1 : L->half;
#endif
    recip(L->half, &L->rh, &L->sh);
}

/* sheet of side s: horizontal (r,c)-(r,c+1) first, r(s-1)+c; vertical
 * (r,c)-(r+1,c) next, s(s-1)+rs+c; at s = 2 the braces (0,0)-(1,1), (0,1)-(1,0) */
void seg_nodes(const seg_lvl *L, uint32_t i, uint32_t *a, uint32_t *b) {
    uint32_t s = L->side, nh = s * (s - 1u);
    if (L->kind == SN_SEG_CHAIN) { *a = i; *b = i + 1u; return; }
    if (i < nh) { *a = (i / (s - 1u)) * s + i % (s - 1u); *b = *a + 1u; }
    else if (i < 2u * nh) { *a = i - nh; *b = *a + s; }
    else if (i == 2u * nh) { *a = 0; *b = 3; }
    else { *a = 1; *b = 2; }
}

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

/* in ring order: left (end), up (end), right (start), down (start), brace */
unsigned seg_node_ends(const seg_lvl *L, uint32_t n, uint32_t seg[5], int sgn[5]) {
    unsigned k = 0;
    uint32_t s = L->side, nh = s * (s - 1u);
    if (L->kind == SN_SEG_CHAIN) {
        if (n > 0) { seg[k] = n - 1u; sgn[k++] = 1; }
        if (n + 1u < s) { seg[k] = n; sgn[k++] = -1; }
        return k;
    }
    k = sheet_ends(s, n / s, n % s, seg, sgn);
    if (s == 2u) { seg[k] = 2u * nh + (n == 0 || n == 3 ? 0u : 1u); sgn[k++] = (n == 0 || n == 1) ? -1 : 1; }
    return k;
}

static int is_brace(const seg_lvl *L, uint32_t i) {
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

/* A value the bounds (NUMERICS.md "Fixed point, bounds") keep within int32 (fixed; float: float), so on
 * a 32-bit target a product of two is one 32x32->64 multiply (SMULL on a
 * Cortex-M4, not a 64x64 one); on a 64-bit target int64 (no sign
 * extensions). The same values either way: the same bits. */
#if defined(SN_FLOAT)
typedef float seg_n;
#define MUL(a, b) ((a) * (b))
#else
#if UINTPTR_MAX > 0xFFFFFFFFu
typedef int64_t seg_n;
#else
typedef int32_t seg_n;
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
    if (v > SN_LIM) { (*sat)++; return SN_LIM; }
    if (v < -SN_LIM) { (*sat)++; return -SN_LIM; }
    return v;
}
#endif

/* P = G +- half u: the offset (|u| <= 1, half <= 2^29: <= 2^29) in int64,
 * one clamp of the sum (fixed); float the same expression */
SN_INLINE void end_of(const seg_lvl *L, uint32_t i, int s, sn_q P[3], uint32_t *sat) {
    const sn_q *S = L->S + SEG_W * i;
    sn_q r;
    int sh;
    sn_q hl = seg_half(L, i, &r, &sh);
    /* components written out: compilers kept the loop (it runs per end per sweep) */
#if defined(SN_FLOAT)
    sn_q o0 = S[3] * hl, o1 = S[4] * hl, o2 = S[5] * hl;
#else
    int64_t o0 = sn_rshr64((int64_t)S[3] * hl, SN_Q_ROT), o1 = sn_rshr64((int64_t)S[4] * hl, SN_Q_ROT),
            o2 = sn_rshr64((int64_t)S[5] * hl, SN_Q_ROT);
#endif
    /* |G| <= 2^28, offset <= 2^29: the end within int32, clamped as one (seg_out) */
    P[0] = (sn_q)SEG_OUT(NARROW(s > 0 ? S[0] + o0 : S[0] - o0), sat);
    P[1] = (sn_q)SEG_OUT(NARROW(s > 0 ? S[1] + o1 : S[1] - o1), sat);
    P[2] = (sn_q)SEG_OUT(NARROW(s > 0 ? S[2] + o2 : S[2] - o2), sat);
}

void seg_end(const seg_lvl *L, uint32_t i, int s, sn_q P[3], uint32_t *sat) { end_of(L, i, s, P, sat); }

void seg_unit(const sn_q x[3], sn_q u[3]) {
    sn_q q[4];
    q[0] = x[0]; q[1] = x[1]; q[2] = x[2]; q[3] = 0;
    sn_qnormalize(q);
    if (q[3] != 0) return; /* zero vector: keep u */
    u[0] = q[0]; u[1] = q[1]; u[2] = q[2];
}

/* mean of k <= 5 values: fixed sum x round(2^30/k) >> 30 (sums of five Q22 values < 2^31.4) */
static sn_q mean_k(sn_acc sum, unsigned k, uint32_t *sat) {
#if defined(SN_FLOAT)
    return sn_out(sum / (float)k, 0, sat);
#else
    static const int32_t inv[6] = {0, 1 << 30, 1 << 29, 357913941, 1 << 28, 214748365};
    return sn_out(sum * inv[k], SN_Q_ROT, sat);
#endif
}

void seg_node_means(const seg_lvl *L, uint32_t *sat) {
    uint32_t n, seg[5];
    int sgn[5];
    unsigned j, k, c;
    for (n = 0; n < L->nn; n++) {
        sn_acc sum[3] = {0, 0, 0};
        k = seg_node_ends(L, n, seg, sgn);
        for (j = 0; j < k; j++) {
            sn_q P[3];
            seg_end(L, seg[j], sgn[j], P, sat);
            for (c = 0; c < 3; c++) sum[c] += P[c];
        }
        for (c = 0; c < 3; c++) L->N[NODE_W * n + c] = mean_k(sum[c], k, sat);
    }
}

void seg_from_nodes(const seg_lvl *L, int lens, uint32_t *sat) {
    uint32_t i, a, b;
    unsigned k;
    for (i = 0; i < L->ns; i++) {
        sn_q *S = L->S + SEG_W * i, d[3];
        seg_nodes(L, i, &a, &b);
        for (k = 0; k < 3; k++) {
            sn_q pa = L->N[NODE_W * a + k], pb = L->N[NODE_W * b + k];
            S[k] = mean_k((sn_acc)pa + pb, 2, sat);
            d[k] = sn_add(pb, -pa, sat);
        }
        seg_unit(d, S + 3);
        if (lens && L->l > 0) { /* a coarse segment's length: its restricted nodes' distance */
            int sh;
#if defined(SN_FLOAT)
            float n2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            S[12] = n2 > 1e-12f ? 0.5f * n2 * sn_frsqrt(n2) : (is_brace(L, i) ? L->bhalf : L->half);
#else
            /* |d_k| <= 2^29 (differences of clamped Q22 values): sum of squares < 2^60 */
            uint64_t n2 = 0;
            for (k = 0; k < 3; k++) n2 += (uint64_t)((int64_t)d[k] * d[k]);
            S[12] = (sn_q)(sn_isqrt64(n2) >> 1); /* <= 2^29 */
            S[12] = S[12] < 1 ? 1 : S[12];
#endif
            recip(S[12], &S[13], &sh);
            S[14] = (sn_q)sh;
        }
    }
}

/* ---------------- the displacement constraint (seed 004 §3.2) ---------------- */

/* A rotation angle from a lever: f c/half, with c (Q22) limited to +-half
 * and f a factor (fixed: f >> fs, |f >> fs| <= 3), the result limited to
 * +-ROT_MAX. Both limits are designed limiters of the small-angle update
 * (a turn of more than 0.25 rad per constraint or per step is not
 * followed), not overflows: not counted in sat. Fixed: |c| r <= 2^(b+30)
 * < 2^57, shift b - 1: the quotient c/half (Q30) <= 2^30; times |f| <= 2^31:
 * < 2^62 (before the shift fs). */
static sn_q lever(sn_q c, sn_q hl, sn_q r, int sh, sn_q f, int fs) {
    sn_q ck = c > hl ? hl : (c < -hl ? -hl : c);
#if defined(SN_FLOAT)
    sn_q t = ck * r * f;
    (void)sh; (void)fs;
#else
    int64_t t = sn_rshr64(sn_rshr64((int64_t)ck * r, sh) * f, fs);
#endif
    return (sn_q)(t > ROT_MAX ? ROT_MAX : (t < -ROT_MAX ? -ROT_MAX : t));
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
 * [0.987, 1] (NUMERICS.md "Fixed point, bounds"); the small turns of the
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

/* every segment's u of a level to unit length: every write of u leaves
 * |u| in [0.9876, 1] (newton_unit's bound, below), so three Newton steps
 * reach the LSB (|u|^2 - 1: 2.5e-2 -> 4.6e-4 -> 1.6e-7 -> 2e-14, below
 * Q30's 1e-9) without a square root or a division */
static void renormalize(const seg_lvl *L) {
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

/* u + theta x u (the dynamics' turn by w, |theta_k| <= ROT_MAX, limited by
 * the caller), brought back towards unit length by newton_unit. */
SN_INLINE void rotate_u(sn_q u[3], const sn_q t[3]) {
    sn_acc x[3];
    /* each term of t x u <= 2^58, a component <= 2^59 -> 2^29 in Q30 (beyond
     * the state clamp 2^28, so not through sn_out): u + t x u < 1.5 2^30 */
    x[0] = u[0] + shr30(sn_mul_sub(t[1], u[2], t[2], u[1]));
    x[1] = u[1] + shr30(sn_mul_sub(t[2], u[0], t[0], u[2]));
    x[2] = u[2] + shr30(sn_mul_sub(t[0], u[1], t[1], u[0]));
    newton_unit(x, u);
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
SN_INLINE sn_acc r30(sn_acc a) { /* fixed: a Q30 product (sum) back to its operand's Q, rounded */
#if defined(SN_FLOAT)
    return a;
#else
    return sn_rshr64(a, SN_Q_ROT);
#endif
}
SN_INLINE sn_acc rsh(sn_acc a, int s) {
#if defined(SN_FLOAT)
    (void)s;
    return a;
#else
    return sn_rshr64_var(a, s);
#endif
}
SN_INLINE sn_acc lim(sn_acc a, sn_acc m) { return a > m ? m : (a < -m ? -m : a); }

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
SEG_HOT void move_seg(sn_q *S, seg_n d0, seg_n d1, seg_n d2, seg_n t0, seg_n t1, seg_n t2, seg_n kf,
                        int sh, uint32_t *sat) {
    seg_n u0 = S[3], u1 = S[4], u2 = S[5], du, e0, e1, e2, eu, x0, x1, x2, f;
    d0 = NARROW(d0); d1 = NARROW(d1); d2 = NARROW(d2); /* (32-bit products, see narrow) */
    du = NARROW(r30(MUL(d0, u0) + MUL(d1, u1) + MUL(d2, u2)));
    e0 = NARROW(lim(rsh(MUL(NARROW(d0 - r30(MUL(du, u0))), kf), sh), ROT_MAX));
    e1 = NARROW(lim(rsh(MUL(NARROW(d1 - r30(MUL(du, u1))), kf), sh), ROT_MAX));
    e2 = NARROW(lim(rsh(MUL(NARROW(d2 - r30(MUL(du, u2))), kf), sh), ROT_MAX));
    eu = NARROW(r30(MUL(e0, u0) + MUL(e1, u1) + MUL(e2, u2)));
    x0 = NARROW(u0 + e0 - r30(MUL(eu, u0)));
    x1 = NARROW(u1 + e1 - r30(MUL(eu, u1)));
    x2 = NARROW(u2 + e2 - r30(MUL(eu, u2)));
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

static void seg_move(const seg_lvl *L, uint32_t i, int s, const sn_q t[3], const sn_q d[3], sn_q rf,
                     uint32_t *sat) {
    int sh;
    seg_n kf = seg_kf(L, i, s, rf, &sh);
    move_seg(L->S + SEG_W * i, d[0], d[1], d[2], t[0], t[1], t[2], kf, sh, sat);
}

/* The measuring pass keeps the largest |d|^2 and converts it once (gap_of):
 * the conversion is monotonic, so the same value as the largest converted
 * |d| (fixed), without a square root per pair (sn_norm2, sn_internal.h). */

/* sqrt(n2) in public Q16.16 segment lengths (or float) */
static sn_real gap_of(sn_len2 n2, const seg_lvl *L) {
#if defined(SN_FLOAT)
    return n2 > 0.0f ? n2 * sn_frsqrt(n2) / (2.0f * L->half) : 0.0f;
#else
    int64_t g = ((int64_t)sn_isqrt64(n2) << 16) / (2 * (int64_t)L->half);
    return g > INT32_MAX ? INT32_MAX : (sn_real)g;
#endif
}

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
} seg_ctx;

/* pair constraint between two endpoints of equal masses: d = P2 - P1,
 * t = gamma d / 2 computed once, +t on segment 1 and -t on segment 2 (linear
 * momentum kept exactly), each rotating to close (1-gamma)/2 of d's
 * perpendicular part */
SEG_HOT void pair(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, uint32_t b, int sb, int measure,
                  uint32_t *sat) {
    sn_q *A = L->S + SEG_W * a, *B = L->S + SEG_W * b, d[3];
    seg_n ha, hb, ka, kb, t[3];
    uint32_t ls = 0; /* local count: no aliasing with the state words */
    int sha, shb;
    if (L->l == 0) { /* seg_half, seg_kf: the level's half length and turn factor */
        ha = hb = L->half;
        sha = shb = L->sh;
        ka = kb = C->kf0;
    } else {
        ha = A[12]; hb = B[12];
        sha = (int)A[14]; shb = (int)B[14];
        ka = NARROW(r30(MUL(C->rf2, A[13])));
        kb = NARROW(r30(MUL(C->rf2, B[13])));
    }
    ha = sa > 0 ? ha : -ha;
    hb = sb > 0 ? hb : -hb;
    /* endpoints G +- half u (|.| < 2^30) and their difference, clamped;
     * t = omega gamma d / 2: |.| < 2^28 (components written out) */
    d[0] = (sn_q)SEG_OUT(NARROW(B[0] + r30(MUL(B[3], hb))) - NARROW(A[0] + r30(MUL(A[3], ha))), &ls);
    d[1] = (sn_q)SEG_OUT(NARROW(B[1] + r30(MUL(B[4], hb))) - NARROW(A[1] + r30(MUL(A[4], ha))), &ls);
    d[2] = (sn_q)SEG_OUT(NARROW(B[2] + r30(MUL(B[5], hb))) - NARROW(A[2] + r30(MUL(A[5], ha))), &ls);
    t[0] = NARROW(r30(MUL(NARROW(d[0]), C->gh)));
    t[1] = NARROW(r30(MUL(NARROW(d[1]), C->gh)));
    t[2] = NARROW(r30(MUL(NARROW(d[2]), C->gh)));
    if (measure) {
        sn_len2 g = sn_norm2(d);
        C->gap2 = g > C->gap2 ? g : C->gap2;
    } else {
        ka = sa > 0 ? ka : -ka;
        kb = sb > 0 ? kb : -kb;
        move_seg(A, d[0], d[1], d[2], t[0], t[1], t[2], ka, sha, &ls);
        move_seg(B, -d[0], -d[1], -d[2], -t[0], -t[1], -t[2], kb, shb, &ls);
    }
    *sat += ls;
}

/* The ends meeting at a sheet node (k >= 3) projected together towards
 * their mean m (one Gauss-Seidel step on the node's constraint "all ends
 * coincide", equal masses): end j takes D_j = m - P_j like an attachment
 * to m, t = omega gamma D_j and a turn closing omega (1-gamma) of D_j's
 * perpendicular part. At k = 2 this is pair() (D = d/2). A ring of k pairs
 * costs 2k endpoints and 2k moves; this k and k, and each end reaches the
 * node's mean in one projection instead of exchanging with its two ring
 * neighbours in turn (NUMERICS.md "Segment meshes", Sweep).
 * Linear momentum exact: the last end's t is minus the sum of the others'.
 * Fixed: endpoints |G +- half u| < 2^30, their sum over k <= 5 < 2^32.4,
 * times round(2^30/k) <= 2^28.4 (k >= 3) < 2^61 (mean_k); D clamped to the
 * state range as pair's d; t = D omega gamma (< 2^31) < 2^59 -> Q22 < 2^29. */
SEG_HOT void star(seg_ctx *C, const seg_lvl *L, const uint32_t seg[5], const int sgn[5], unsigned k,
                  uint32_t *sat) {
    seg_n P[5][3], kf[5], h0 = L->half, k0 = C->kf1;
    int sh[5];
    sn_acc s0 = 0, s1 = 0, s2 = 0, l0 = 0, l1 = 0, l2 = 0;
    sn_q m0, m1, m2;
    uint32_t ls = 0;
    unsigned j;
    for (j = 0; j < k; j++) { /* components written out: compilers kept the loop */
        const sn_q *S = L->S + SEG_W * seg[j];
        seg_n h = h0, f = k0;
        sh[j] = L->sh;
        if (L->l != 0) { h = S[12]; sh[j] = (int)S[14]; f = NARROW(r30(MUL(C->rf1, S[13]))); }
        if (sgn[j] < 0) { h = -h; f = -f; }
        kf[j] = f;
        P[j][0] = NARROW(S[0] + r30(MUL(S[3], h)));
        P[j][1] = NARROW(S[1] + r30(MUL(S[4], h)));
        P[j][2] = NARROW(S[2] + r30(MUL(S[5], h)));
        s0 += P[j][0]; s1 += P[j][1]; s2 += P[j][2];
    }
    m0 = mean_k(s0, k, &ls); m1 = mean_k(s1, k, &ls); m2 = mean_k(s2, k, &ls);
    for (j = 0; j < k; j++) {
        /* |m| <= 2^28, |P| < 2^30: the difference within int32 */
        seg_n d0 = SEG_OUT((seg_n)m0 - P[j][0], &ls), d1 = SEG_OUT((seg_n)m1 - P[j][1], &ls),
              d2 = SEG_OUT((seg_n)m2 - P[j][2], &ls), t0, t1, t2;
        if (j + 1 < k) {
            t0 = NARROW(r30(MUL(d0, C->g1n))); t1 = NARROW(r30(MUL(d1, C->g1n))); t2 = NARROW(r30(MUL(d2, C->g1n)));
            l0 -= t0; l1 -= t1; l2 -= t2;
        } else { /* the others' sum: |.| <= 2^29 unless a D was clamped */
            t0 = NARROW(lim(l0, (sn_acc)2 * SN_LIM)); t1 = NARROW(lim(l1, (sn_acc)2 * SN_LIM));
            t2 = NARROW(lim(l2, (sn_acc)2 * SN_LIM));
        }
        move_seg(L->S + SEG_W * seg[j], d0, d1, d2, t0, t1, t2, kf[j], sh[j], &ls);
    }
    *sat += ls;
}

/* an endpoint against a point of infinite mass: the segment takes gamma d
 * and rotates to close (1-gamma) of the perpendicular part */
SEG_HOT void pin(seg_ctx *C, const seg_lvl *L, uint32_t a, int sa, const sn_q T[3], int measure, uint32_t *sat) {
    /* the end P, then d = T - P and t = omega gamma d (|d| 2^31 < 2^60),
     * each clamped and counted */
    sn_q *S = L->S + SEG_W * a, P[3], d[3], t0, t1, t2;
    int sh;
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
    t0 = sn_out(MUL(d[0], C->g1n), SN_Q_ROT, &ls);
    t1 = sn_out(MUL(d[1], C->g1n), SN_Q_ROT, &ls);
    t2 = sn_out(MUL(d[2], C->g1n), SN_Q_ROT, &ls);
    if (L->l == 0) { /* level 0: the sweep's turn factor (seg_kf of the level's half) */
        kf = sa > 0 ? C->kf1 : -C->kf1;
        sh = L->sh;
    } else {
        kf = seg_kf(L, a, sa, C->rf1, &sh);
    }
    move_seg(S, d[0], d[1], d[2], t0, t1, t2, kf, sh, &ls);
    *sat += ls;
}

/* attachment target in the internal frame */
static void attach_target(const sn_ihdr *h, const unsigned char *rec, sn_q T[3], uint32_t *sat) {
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
    else if (k == 4) star(C, L, seg, sgn, 4u, sat);
    else star(C, L, seg, sgn, 3u, sat);
}

/* What every sweep of level L reads and no sweep changes, once per level:
 * level 0's turn factors and the first SEG_TCACHE attachments' rod ends
 * (none where the attached fine node is not a node of the level) */
static void sweep_prep(seg_ctx *C, const seg_lvl *L) {
    const seg_mesh *M = C->M;
    uint32_t i;
    int sh;
    C->kf0 = seg_kf(L, 0, 1, C->rf2, &sh);
    C->kf1 = seg_kf(L, 0, 1, C->rf1, &sh);
    for (i = 0; i < M->n_attach && i < SEG_TCACHE; i++) {
        const unsigned char *rec = C->h->v.sec[SN_SEC_SEGATTACH] + (size_t)(M->first_attach + i) * ATT_REC;
        int64_t ln = level_node(M, L, sn_rd_u16(rec));
        C->ak[i] = ln < 0 ? 0u : seg_node_ends(L, (uint32_t)ln, C->aseg[i], C->asgn[i]);
    }
}

static void sweep(seg_ctx *C, const seg_lvl *L, int measure, unsigned dir, uint32_t *sat) {
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
            for (j = 0; j < C->ak[i]; j++) pin(C, L, C->aseg[i][j], C->asgn[i][j], C->T[i], measure, sat);
            continue;
        }
        ln = level_node(M, L, sn_rd_u16(rec));
        if (ln < 0) continue; /* a fine node between the level's nodes: not pinned there */
        attach_target(C->h, rec, T, sat);
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
        uint32_t sd = L->side, r, c;
        for (r = 0; r < sd; r++)
            for (c = 0; c < sd; c++) {
                uint32_t rr = dir ? sd - 1u - r : r, cc = dir ? sd - 1u - c : c;
                if (sd == 2u) k = seg_node_ends(L, rr * 2u + cc, seg, sgn); /* with the brace */
                else k = sheet_ends(sd, rr, cc, seg, sgn);
                node_proj(C, L, seg, sgn, k, measure, sat);
            }
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

/* ---------------- dynamics and velocities ---------------- */

/* Level l's dynamics: save G, u (into v, w's words after the velocities are
 * read), damping, gravity and the node impulses (J at the centres' share
 * `centre`, the rest at the endpoints with torque), Euler-Cromer. */
static void dynamics(seg_ctx *C, const seg_lvl *L, sn_q inv_mass, uint32_t *sat) {
    const seg_mesh *M = C->M;
    sn_q g[3];
    uint32_t i, n, seg[5];
    int sgn[5];
    unsigned j, k, ne;
    for (k = 0; k < 3; k++)
        g[k] = (M->flags & SN_SEGF_NO_GRAVITY) ? 0 : sn_mulq(C->h->v.grav[k], M->share[L->l], SN_Q_ROT, sat);
    for (i = 0; i < L->ns; i++) { /* damping and gravity: v = keep v + g; w = keep w */
        sn_q *S = L->S + SEG_W * i;
        for (k = 0; k < 3; k++) {
            S[6 + k] = sn_add(sn_mulq(S[6 + k], M->keep, SN_Q_ROT, sat), g[k], sat);
            S[9 + k] = sn_mulq(S[9 + k], M->keep, SN_Q_ROT, sat);
        }
    }
    /* impulses: node J split evenly over its k ends; dv = J/k inv_mass
     * (an end force translates too); dw = s 6 inv_mass (u x J_end)/L
     * = s 3 (u x f)/half with f = (1 - centre) J/k inv_mass, the thin rod's
     * J = m L^2/12 about the perpendicular axes (seed 004 §3.2.2, app. A) */
    for (n = 0; n < L->nn; n++) {
        const sn_q *J = L->N + NODE_W * n + 3;
        sn_q f[3], fe[3];
        uint32_t ls = 0;
        ne = seg_node_ends(L, n, seg, sgn);
        /* f and fe are the node's, the same at each of its ends: formed once,
         * their clamps counted once per end as when formed per end */
        for (k = 0; k < 3; k++) {
            f[k] = sn_mulq(mean_k(J[k], ne, &ls), inv_mass, 16, &ls);
            fe[k] = sn_add(f[k], -sn_mulq(f[k], M->centre, SN_Q_ROT, &ls), &ls);
        }
        *sat += ls * ne;
        for (j = 0; j < ne; j++) {
            sn_q *S = L->S + SEG_W * seg[j], c[3];
            sn_q rr;
            int rs;
            sn_q hl = seg_half(L, seg[j], &rr, &rs);
            for (k = 0; k < 3; k++) S[6 + k] = sn_add(S[6 + k], f[k], sat);
            c[0] = sn_out(sn_mul_sub(S[4], fe[2], S[5], fe[1]), SN_Q_ROT, sat);
            c[1] = sn_out(sn_mul_sub(S[5], fe[0], S[3], fe[2]), SN_Q_ROT, sat);
            c[2] = sn_out(sn_mul_sub(S[3], fe[1], S[4], fe[0]), SN_Q_ROT, sat);
            for (k = 0; k < 3; k++) { /* 3 (u x f)/half, limited to 0.25 rad/step */
                sn_q dw = lever(c[k], hl, rr, rs, THREE, 0);
#if defined(SN_FLOAT)
                S[9 + k] = sn_add(S[9 + k], sgn[j] > 0 ? dw : -dw, sat);
#else
                /* w is Q30 rad/step and ROT_MAX = SN_LIM: a sum beyond it is
                 * the designed 0.25 rad/step cap (float applies it below), not
                 * an overflow, so it is not counted in sat; same value */
                int64_t w = (int64_t)S[9 + k] + (sgn[j] > 0 ? dw : -dw);
                S[9 + k] = (sn_q)(w > ROT_MAX ? ROT_MAX : (w < -ROT_MAX ? -ROT_MAX : w));
#endif
            }
        }
    }
    for (i = 0; i < L->ns; i++) { /* Euler-Cromer: G += v; u turned by w; save the start */
        sn_q *S = L->S + SEG_W * i, G0[3], u0[3], w[3];
        for (k = 0; k < 3; k++) {
            G0[k] = S[k];
            u0[k] = S[3 + k];
            S[k] = sn_add(S[k], S[6 + k], sat);
            /* |w_k| <= 0.25 rad (fixed: already, the state clamp is 2^28) */
            w[k] = S[9 + k] > ROT_MAX ? ROT_MAX : (S[9 + k] < -ROT_MAX ? -ROT_MAX : S[9 + k]);
        }
        rotate_u(S + 3, w);
        for (k = 0; k < 3; k++) { S[6 + k] = G0[k]; S[9 + k] = u0[k]; }
    }
}

/* A Q60 product sum (|.| <= 2^61) to Q30 limited to +-ROT_MAX: the
 * per-step rotation cap, a designed limiter (not counted in sat). */
static sn_q rot_cap(sn_acc a) {
#if defined(SN_FLOAT)
    sn_q t = a;
#else
    int64_t t = sn_rshr64(a, SN_Q_ROT);
#endif
    return (sn_q)(t > ROT_MAX ? ROT_MAX : (t < -ROT_MAX ? -ROT_MAX : t));
}

/* Velocities from the displacements (seed 004 fig. 3.1 step 4):
 * v = G - G_start (exact: the sum of v changes only by external terms),
 * w = u_start x u (small angle), clamped to 0.25 rad per step. */
static void velocities(const seg_lvl *L, uint32_t *sat) {
    uint32_t i;
    unsigned k;
    for (i = 0; i < L->ns; i++) {
        sn_q *S = L->S + SEG_W * i, w[3];
        const sn_q *u0 = S + 9, *u = S + 3;
        w[0] = rot_cap(sn_mul_sub(u0[1], u[2], u0[2], u[1]));
        w[1] = rot_cap(sn_mul_sub(u0[2], u[0], u0[0], u[2]));
        w[2] = rot_cap(sn_mul_sub(u0[0], u[1], u0[1], u[0]));
        for (k = 0; k < 3; k++) {
            S[6 + k] = sn_add(S[k], -S[6 + k], sat);
            S[9 + k] = w[k];
        }
    }
}

static void ctx_init(seg_ctx *C, sn_ihdr *h, const seg_mesh *M, uint32_t *sat) {
    unsigned k;
    C->h = h;
    C->M = M;
#if defined(SN_FLOAT)
    {
        float om = (float)M->relax / 32.0f;
        C->gb = 0.5f * M->gamma;
        C->rfu = 1.0f - M->gamma;
        C->gh = C->gb * om;
        C->rf1 = C->rfu * om;
        C->rf2 = 0.5f * C->rf1;
        C->g1 = M->gamma * om;
    }
#else
    C->gb = M->gamma >> 1; /* gamma/2 rounded down: the pair's translation is t = d gamma/2 */
    C->rfu = ((int32_t)1 << 30) - M->gamma;
    /* relax <= 63, gamma <= 2^30: gamma relax < 2^36; the validator keeps
     * omega (1 - gamma) <= 1, so rf1 <= 2^30 and the turn factors keep
     * their bounds (seg_kf); omega gamma < 2^31 needs int64 (pin) */
    C->g1 = ((int64_t)M->gamma * M->relax) >> 5;
    C->gh = (sn_q)(((int64_t)M->gamma * M->relax) >> 6);
    C->rf1 = (sn_q)(((int64_t)C->rfu * M->relax) >> 5);
    C->rf2 = C->rf1 >> 1;
#endif
    C->g1n = NARROW(C->g1);
    (void)sat;
    C->floor_on = (int)h->floor_on;
    C->gap2 = 0;
    C->foff = 0;
    for (k = 0; k < 3; k++) C->fn[k] = h->floor_n[k];
    if (h->floor_on) { /* n.(origin + p) >= off  <=>  n.p >= off - n.origin */
#if defined(SN_FLOAT)
        float no = C->fn[0] * h->origin[0] + C->fn[1] * h->origin[1] + C->fn[2] * h->origin[2];
        C->foff = pub_to_int(h, h->floor_off - no);
#else
        int64_t no = sn_rshr64((int64_t)C->fn[0] * h->origin[0] + (int64_t)C->fn[1] * h->origin[1] +
                                   (int64_t)C->fn[2] * h->origin[2], SN_Q_ROT); /* |.| < 2^32.6 */
        C->foff = pub_to_int_sat(h, (int64_t)h->floor_off - no, sat);
#endif
    }
}

/* The mesh's node-impulse accumulators of every level to zero. */
static void clear_impulses(const seg_mesh *M) {
    uint32_t n;
    for (n = 0; n < M->nodes; n++) M->N[NODE_W * n + 3] = M->N[NODE_W * n + 4] = M->N[NODE_W * n + 5] = 0;
}

/* First step after init/reset: the rest mesh (model space) placed by the
 * transform of the joint of its first JOINT attachment (else the root),
 * as the skeleton's rest positions are (p = R_j x + T_j). */
static void place(sn_ihdr *h, const seg_mesh *M, uint32_t *sat) {
    const sn_q *jR = CARR(h, o_jR, sn_q), *jT = CARR(h, o_jT, sn_q);
    uint32_t j = 0, i;
    unsigned k;
    for (i = M->n_attach; i-- > 0;) {
        const unsigned char *rec = h->v.sec[SN_SEC_SEGATTACH] + (size_t)(M->first_attach + i) * ATT_REC;
        if (rec[2] == SN_SEGATT_JOINT) j = sn_rd_u16(rec + 4);
    }
    for (i = 0; i < M->segs; i++) {
        sn_q *S = M->S + SEG_W * i, x[3], y[3];
        memcpy(x, S, sizeof x);
        sn_rot(jR + 9 * j, x, S, sat);
        for (k = 0; k < 3; k++) S[k] = sn_add(S[k], jT[3 * j + k], sat);
        for (k = 0; k < 3; k++) x[k] = S[3 + k] / 4; /* Q28 (sn_rot clamps at 2^28), then unit again */
        sn_rot(jR + 9 * j, x, y, sat);
        seg_unit(y, S + 3);
    }
    for (i = 0; i < M->nodes; i++) {
        sn_q *N = M->N + NODE_W * i, x[3];
        memcpy(x, N, sizeof x);
        sn_rot(jR + 9 * j, x, N, sat);
        for (k = 0; k < 3; k++) N[k] = sn_add(N[k], jT[3 * j + k], sat);
    }
}

void sn_segments_step(sn_ihdr *h, uint32_t *sat) {
    uint32_t m, i, s;
    sn_q shift[3] = {0, 0, 0};
    sn_real gap = 0;
    unsigned k;
    if (h->v.nM == 0) return;
    /* the origin moved with the root since the last step: positions are kept
     * in the world by shifting them, as sn_frames shifts the flesh */
    for (k = 0; k < 3; k++) {
#if defined(SN_FLOAT)
        shift[k] = h->seg_placed ? pub_to_int(h, h->origin[k] - h->seg_origin[k]) : 0;
#else
        shift[k] = h->seg_placed ? pub_to_int_sat(h, (int64_t)h->origin[k] - h->seg_origin[k], sat) : 0;
#endif
        h->seg_origin[k] = h->origin[k];
    }
    for (m = 0; m < h->v.nM; m++) {
        seg_mesh M;
        seg_ctx C;
        seg_lvl L;
        unsigned l;
        seg_mesh_get(h, m, &M);
        if (!h->seg_placed) place(h, &M, sat);
        for (i = 0; i < M.segs; i++)
            for (k = 0; k < 3; k++) M.S[SEG_W * i + k] = sn_add(M.S[SEG_W * i + k], -shift[k], sat);
        for (i = 0; i < M.nodes; i++)
            for (k = 0; k < 3; k++) M.N[NODE_W * i + k] = sn_add(M.N[NODE_W * i + k], -shift[k], sat);
        ctx_init(&C, h, &M, sat);
        for (i = 0; i < M.n_attach && i < SEG_TCACHE; i++) {
            C.Tsat[i] = 0;
            attach_target(h, h->v.sec[SN_SEC_SEGATTACH] + (size_t)(M.first_attach + i) * ATT_REC, C.T[i], &C.Tsat[i]);
        }
        if (M.levels > 1) seg_restrict(&M, sat); /* positions and impulse shares of the coarse levels */
        else {
            seg_level(&M, 0, &L);
            for (i = 0; i < L.nn; i++) /* one level: share[0] is 1 (validated) */
                for (k = 0; k < 3; k++)
                    L.N[NODE_W * i + 3 + k] = sn_mulq(L.N[NODE_W * i + 3 + k], M.share[0], SN_Q_ROT, sat);
        }
        for (l = M.levels; l-- > 0;) {
            sn_q im;
            seg_level(&M, l, &L);
            {   /* equal total mass on every level (seed 004 §4.2.1): m_l = m_0 S_0 / S_l */
                seg_lvl L0;
                seg_level(&M, 0, &L0);
#if defined(SN_FLOAT)
                im = M.inv_mass * (float)L.ns / (float)L0.ns;
#else
                im = (sn_q)(((int64_t)M.inv_mass * L.ns) / L0.ns); /* S_l <= S_0: <= inv_mass */
                im = im < 1 ? 1 : im;
#endif
            }
            dynamics(&C, &L, im, sat);
            /* level 0 takes `sweeps`, the coarser ones `coarse_sweeps`: a
             * coarse level starts each step with its constraints met
             * (restriction), its sweeps only pin it and follow its dynamics */
            sweep_prep(&C, &L);
            for (s = 0; s < (l ? M.coarse_sweeps : M.sweeps); s++) sweep(&C, &L, 0, s & 1u, sat);
            renormalize(&L); /* the Newton steps of the moves leave |u| within 2% of 1 */
            seg_node_means(&L, sat);
            if (l > 0) seg_prolong(&M, l, sat); /* reads this level's start (v, w words) */
            velocities(&L, sat);
        }
        seg_level(&M, 0, &L);
        sweep_prep(&C, &L);
        sweep(&C, &L, 1, 0, sat); /* measure the gaps left (no displacement) */
        {
            sn_real g = gap_of(C.gap2, &L);
            gap = g > gap ? g : gap;
        }
        clear_impulses(&M);
    }
    h->seg_placed = 1;
    h->seg_gap = gap;
    h->seg_gap_max = gap > h->seg_gap_max ? gap : h->seg_gap_max;
}

/* M a (Q30 rotation times a value of any Q) without the state clamp: |M a|
 * <= 1.74 |a|_max (rows of a rotation, rounded), each product <= 2^61 */
static void turn_raw(const sn_q M[9], const sn_q a[3], sn_q out[3]) {
    unsigned k;
    for (k = 0; k < 3; k++) out[k] = shr30(sn_mul(M[3 * k], a[0]) + sn_mul(M[3 * k + 1], a[1]) + sn_mul(M[3 * k + 2], a[2]));
}

void sn_segments_teleport(sn_ihdr *h, const sn_q M[9], const sn_q T0[3], const sn_q T1[3], uint32_t *sat) {
    uint32_t m, i;
    unsigned k;
    if (h->v.nM == 0) return;
    for (k = 0; k < 3; k++) h->seg_origin[k] = h->origin[k];
    if (!h->seg_placed) return; /* the first step places the meshes by their joint */
    for (m = 0; m < h->v.nM; m++) {
        seg_mesh Ms;
        seg_mesh_get(h, m, &Ms);
        for (i = 0; i < Ms.segs; i++) {
            sn_q *S = Ms.S + SEG_W * i, a[3], b[3];
            for (k = 0; k < 3; k++) a[k] = sn_add(S[k], -T0[k], sat);
            sn_rot(M, a, b, sat); /* Q22 positions: within the state range */
            for (k = 0; k < 3; k++) S[k] = sn_add(b[k], T1[k], sat);
            turn_raw(M, S + 3, a); /* Q30 unit: <= 1.74 2^30 */
            seg_unit(a, S + 3);
            memcpy(a, S + 6, sizeof a);
            sn_rot(M, a, S + 6, sat);
            turn_raw(M, S + 9, a); /* w: each |w_k| <= 2^28, limited again */
            for (k = 0; k < 3; k++) S[9 + k] = a[k] > ROT_MAX ? ROT_MAX : (a[k] < -ROT_MAX ? -ROT_MAX : a[k]);
        }
        for (i = 0; i < Ms.nodes; i++) {
            sn_q *N = Ms.N + NODE_W * i, a[3];
            for (k = 0; k < 3; k++) a[k] = sn_add(N[k], -T0[k], sat);
            sn_rot(M, a, N, sat);
            for (k = 0; k < 3; k++) N[k] = sn_add(N[k], T1[k], sat);
            memcpy(a, N + 3, sizeof a);
            sn_rot(M, a, N + 3, sat);
        }
    }
}

/* Rest state: level 0 from the rest nodes, coarser levels restricted; all
 * velocities and impulses zero. */
void sn_segments_reset(sn_ihdr *h) {
    uint32_t m, i, sat = 0;
    unsigned k, l;
    h->seg_placed = 0;
    for (k = 0; k < 3; k++) h->seg_origin[k] = h->origin[k];
    for (m = 0; m < h->v.nM; m++) {
        seg_mesh M;
        seg_lvl L;
        seg_mesh_get(h, m, &M);
        memset(M.S, 0, (size_t)SN_SEG_SEG_BYTES * M.segs + (size_t)SN_SEG_NODE_BYTES * M.nodes);
        seg_level(&M, 0, &L);
        for (i = 0; i < L.nn; i++)
            for (k = 0; k < 3; k++) L.N[NODE_W * i + k] = rd_real(h->v.sec[SN_SEC_SEGNODES], 3 * (M.first_node + i) + k);
        for (i = 0; i < M.segs; i++) M.S[SEG_W * i + 3] = SN_ONE_ROT; /* any unit u before seg_from_nodes */
        seg_from_nodes(&L, 0, &sat);
        for (l = 1; l < M.levels; l++) {
            seg_lvl Lc;
            seg_level(&M, l, &Lc);
            for (i = 0; i < Lc.nn; i++) { /* coarse node (r,c) = finer node (2r, 2c), eq. 4.1-4.2 */
                uint32_t r = i / Lc.side, c = i % Lc.side, f;
                seg_level(&M, l - 1, &L);
                f = 2u * r * L.side + 2u * c;
                for (k = 0; k < 3; k++) Lc.N[NODE_W * i + k] = L.N[NODE_W * f + k];
            }
            seg_from_nodes(&Lc, 1, &sat);
        }
    }
}

/* ---- determinism hash: every word of the segment state, little-endian ---- */
uint64_t sn_segments_hash(const sn_ihdr *h, uint64_t hsh) {
    const unsigned char *p = (const unsigned char *)h + h->o_seg;
    uint32_t i;
    for (i = 0; i < h->v.segB / 4u; i++) {
        sn_q x;
        uint32_t u;
        int b;
        memcpy(&x, p + 4u * i, 4);
        memcpy(&u, &x, 4);
        for (b = 0; b < 4; b++) {
            hsh ^= (u >> (8 * b)) & 0xFFu;
            hsh *= 0x100000001B3ull;
        }
    }
    return hsh;
}
