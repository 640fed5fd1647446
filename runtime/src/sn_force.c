/* sn_force.c -- external forces and impulses on the flesh, spread over levels
 * (seed 004 ch. 4 applied to the lattice), and the rigid level's share
 * returned to the game as a wrench per joint (runtime/NUMERICS.md
 * "External forces").
 *
 * A force acts on a material point (a cell and trilinear coordinates in
 * it), found when the game applies it. In step 5 its profile's shares go
 *   fine     to the cell's 8 corners with the trilinear weights phi_a (the
 *            embedding: f_a = phi_a F, seed 000 §3.1); corners on the
 *            skeleton pass their part to their bone's wrench;
 *   coarse k to the free vertices within 2^k cells of the point (a
 *            tensor-product hat times the lumped mass), as the force a rigid
 *            body of that region would feel: f_a = w^_a (F + beta x rho_a),
 *            Î beta = rho_p x F, so the total force and the moment about any
 *            point are the applied ones (the region translates and turns as
 *            one piece: seed 004 fig. 4.10's global response);
 *   rigid    to the wrench of the cell's two frame bones (the game reacts).
 * Cost: per applied force, 8 corners plus four passes over the free
 * vertices for each coarse level with a share; no force, no cost. The
 * number of forces is the caller's (at most the blob's MAX_FORCES), known
 * before the step runs.
 */
#include "sn_constraint.h"

#define SHARE_ELEM SN_ELEM_SHARES(SN_REAL_BYTES)
#define NO_PROFILE 0xFFFFu
#if defined(SN_FLOAT)
#define ONE_SHARE 1.0f
#else
#define ONE_SHARE ((int32_t)1 << 30)
#endif

/* a force vector at full width: fixed int64 (a mantissa m 2^-q), float float */
#if defined(SN_FLOAT)
typedef float sn_wide;
#else
typedef int64_t sn_wide;
#endif

typedef struct sn_fslot {
    uint32_t cell;
    uint16_t t[3];          /* trilinear coordinates in the cell, Q15 */
    uint16_t prof;          /* share profile, NO_PROFILE: all on the fine lattice */
    sn_q m[3];              /* fixed: force in right-hand-side units = m 2^-q, |m| < 2^30; float: the value */
    int32_t q;
#if defined(SN_FLOAT)
    float fn[3];            /* newtons (impulses divided by h): the bones' shares */
#else
    int64_t fn[3];          /* newtons, Q16.16 */
#endif
} sn_fslot;
typedef char sn_fslot_fits_[sizeof(sn_fslot) <= SN_FORCE_SLOT_BYTES ? 1 : -1];

typedef struct sn_wrench {
#if defined(SN_FLOAT)
    float f[3], t[3];       /* newtons; newton x mesh units about the joint */
#else
    int64_t f[3];           /* Q16.16 newtons, summed exactly (saturating at 2^62) */
    int64_t t[3];           /* Q32 newton x mesh units: sums of exact products */
#endif
} sn_wrench;
typedef char sn_wrench_fits_[sizeof(sn_wrench) <= SN_WRENCH_BYTES ? 1 : -1];

/* ---- validation ---- */

/* Share profiles: each share in [0, 1], summing to exactly 1 (fixed: 2^30;
 * float: within 2^-20), so a distribution never creates or loses force;
 * vertex profiles index an existing profile. */
sn_status sn_check_forces(const sn_view *v) {
    uint32_t i, k;
    if (v->nVP != 0 && v->nP == 0) return SN_ERR_SECTION;
    for (i = 0; i < v->nP; i++) {
        const unsigned char *p = v->sec[SN_SEC_SHARES] + (size_t)i * SHARE_ELEM;
#if defined(SN_FLOAT)
        float sum = 0.0f;
#else
        int64_t sum = 0;
#endif
        for (k = 0; k < SN_LEVELS; k++) {
            if (!sn_real_ok(p + 4 * k, 0, (int32_t)1 << 30, 30)) return SN_ERR_VALUE; /* [0, 1], finite */
            sum += rd_real(p, k);
        }
#if defined(SN_FLOAT)
        if (!(sum >= 1.0f - 1.0f / 1048576 && sum <= 1.0f + 1.0f / 1048576)) return SN_ERR_VALUE;
#else
        if (sum != (int64_t)1 << 30) return SN_ERR_VALUE;
#endif
    }
    for (i = 0; i < v->nVP; i++)
        if (v->sec[SN_SEC_VSHARE][i] >= v->nP) return SN_ERR_INDEX;
    return SN_OK;
}

/* ---- small helpers ---- */

/* Trilinear weights of the slot's coordinates (the embedding's arithmetic). */
static void corner_weights(const uint16_t t[3], sn_q phi[8]) {
    const uint32_t tt[3] = {t[0], t[1], t[2]};
    sn_trilinear(tt, phi);
}

/* Point of the cell at the weights: sum_a phi_a x_a (Q22 in, Q22 out). */
static void cell_point(const sn_q phi[8], const unsigned char *cl, const sn_q *pos, const unsigned char *rest,
                       sn_q out[3]) {
    uint32_t a, k, dummy = 0;
    sn_acc acc[3] = {0, 0, 0};
    for (a = 0; a < 8; a++) {
        uint32_t vx = sn_rd_u16(cl + 2 * a);
        for (k = 0; k < 3; k++) acc[k] += sn_mul(phi[a], pos ? pos[3 * vx + k] : rd_real(rest, 3 * vx + k));
    }
    for (k = 0; k < 3; k++) out[k] = sn_out(acc[k], SN_Q_ROT, &dummy); /* a convex combination: no clamp */
}

/* Public position of an internal point (the outputs' conversion). */
#if defined(SN_FLOAT)
static void pub_point(const sn_ihdr *h, const sn_q p[3], float out[3]) {
    uint32_t k;
    for (k = 0; k < 3; k++) out[k] = h->origin[k] + int_to_pub(h, p[k]);
}
#else
static void pub_point(const sn_ihdr *h, const sn_q p[3], int64_t out[3]) {
    uint32_t k;
    for (k = 0; k < 3; k++) out[k] = (int64_t)h->origin[k] + int_to_pub64(h, p[k]);
}
#endif

/* Joint j's current position (internal): R_j x_j + T_j (sn_pose.c's joint transforms). */
static void joint_pos(const sn_ihdr *h, uint32_t j, sn_q out[3]) {
    const sn_q *jR = CARR(h, o_jR, sn_q), *jT = CARR(h, o_jT, sn_q);
    const unsigned char *jr = h->v.sec[SN_SEC_JOINTS] + (size_t)j * SN_ELEM_JOINTS(SN_REAL_BYTES) + 8;
    sn_q x[3], r[3];
    uint32_t k, dummy = 0;
    for (k = 0; k < 3; k++) x[k] = rd_real(jr, k);
    sn_rot(jR + 9 * j, x, r, &dummy);
    for (k = 0; k < 3; k++) out[k] = sn_add(r[k], jT[3 * j + k], &dummy);
}

#if !defined(SN_FLOAT)
SN_INLINE int64_t clamp64(int64_t x, int64_t lim) { return x > lim ? lim : (x < -lim ? -lim : x); }
SN_INLINE int64_t add_sat62(int64_t a, int64_t b) { /* |a|, |b| <= 2^62 */
    return clamp64(a + b, (int64_t)1 << 62);
}
SN_INLINE int64_t abs64(int64_t x) { return x < 0 ? -x : x; }
/* round(n / D) with sign, |n| < 2^63, 0 < D <= 2^62 */
static int64_t sdiv_round(int64_t n, int64_t D) {
    uint64_t u = (uint64_t)abs64(n), q = sn_udiv64(u + ((uint64_t)D >> 1), (uint64_t)D);
    return n < 0 ? -(int64_t)q : (int64_t)q;
}
#endif

/* Add F (newtons) acting at public point p to joint j's wrench: force, and
 * torque (p - joint) x F about the joint's current position. Fixed: lever
 * and force clamped to +-(2^31 - 1), so each product < 2^62 and the cross
 * product's difference < 2^63: the torque is the exact Q32 product. */
#if defined(SN_FLOAT)
static void wrench_add(sn_ihdr *h, uint32_t j, const float F[3], const float p[3]) {
    sn_wrench *w = ARR(h, o_wr, sn_wrench) + j;
    sn_q jp[3];
    float jpub[3], r[3];
    uint32_t k;
    joint_pos(h, j, jp);
    pub_point(h, jp, jpub);
    for (k = 0; k < 3; k++) { r[k] = p[k] - jpub[k]; w->f[k] += F[k]; }
    w->t[0] += r[1] * F[2] - r[2] * F[1];
    w->t[1] += r[2] * F[0] - r[0] * F[2];
    w->t[2] += r[0] * F[1] - r[1] * F[0];
}
#else
static void wrench_add(sn_ihdr *h, uint32_t j, const int64_t F[3], const int64_t p[3]) {
    sn_wrench *w = ARR(h, o_wr, sn_wrench) + j;
    const int64_t L = INT32_MAX;
    sn_q jp[3];
    int64_t jpub[3], r[3], f[3];
    uint32_t k;
    joint_pos(h, j, jp);
    pub_point(h, jp, jpub);
    for (k = 0; k < 3; k++) {
        r[k] = clamp64(p[k] - jpub[k], L);
        f[k] = clamp64(F[k], L);
        w->f[k] = add_sat62(w->f[k], f[k]);
    }
    w->t[0] = add_sat62(w->t[0], clamp64(r[1] * f[2] - r[2] * f[1], (int64_t)1 << 62));
    w->t[1] = add_sat62(w->t[1], clamp64(r[2] * f[0] - r[0] * f[2], (int64_t)1 << 62));
    w->t[2] = add_sat62(w->t[2], clamp64(r[0] * f[1] - r[1] * f[0], (int64_t)1 << 62));
}
#endif

/* b_a += omega v, omega a weight with wbits fractional bits (fixed), v a
 * force in right-hand-side units v 2^-q: into vertex a's force format
 * Q(19 + k_a). |omega v| < 2^62 (callers); a shift <= 0 means the value is
 * beyond the format (clamped, counted), beyond 62 it rounds to 0. */
static void add_force(sn_q *b, uint32_t a, uint8_t ka, sn_q omega, const sn_wide v[3], int q, int wbits,
                      uint32_t *sat) {
    uint32_t c;
#if defined(SN_FLOAT)
    (void)ka; (void)q; (void)wbits;
    for (c = 0; c < 3; c++) b[3 * a + c] = sn_add(b[3 * a + c], sn_out(omega * v[c], 0, sat), sat);
#else
    int s = wbits + q - SN_Q_FORCE - (int)ka;
    for (c = 0; c < 3; c++) {
        int64_t prod = (int64_t)omega * v[c];
        sn_q f;
        SN_RANGE(SN_WITHIN(prod, 62), "force weight x value beyond 2^62", prod);
        if (prod == 0 || s > 62) f = 0;
        else if (s <= 0) { (*sat)++; f = prod > 0 ? SN_LIM : -SN_LIM; }
        else f = sn_out(prod, s, sat);
        b[3 * a + c] = sn_add(b[3 * a + c], f, sat);
    }
#endif
}

/* ---- coarse level k: the region's rigid response ---- */

/* Share s (Q30) of force F (m 2^-q) at the point with rest position x and
 * current position p goes to the free vertices within R = 2^k cells (rest
 * distance per axis), weighted by w_a = m^_a prod_d max(0, 1 - |x_a,d - x_d|/R)
 * and normalised (w^_a = w_a / sum w, Q28, the rounding remainder on the
 * largest so sum w^ = 1 exactly). In units of R about the weighted centre c:
 * rho_a = (p_a - c)/R, Î = sum w^_a (|rho_a|^2 I - rho_a rho_a^T), and
 * f_a = s w^_a (F + beta x rho_a) with Î beta = rho_p x F. Then
 * sum f_a = s F and sum rho_a x f_a = s Î beta = s rho_p x F: the moment
 * about c, hence about any point, is the applied one. Returns 0 (nothing
 * added) when the region is empty or too thin for a reliable Î (det Î <
 * (tr Î)^3 / 2048, or det below 2^-32): the caller moves the share to the
 * fine level. Uses acc (free during step 5's tail) for w^. */
#if defined(SN_FLOAT)
static int coarse(sn_ihdr *h, sn_q *b, int k, sn_q s, const sn_q x[3], const sn_q p[3], const sn_wide F[3],
                  int q, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *pos = CARR(h, o_pos, sn_q);
    const unsigned char *rest = v->sec[SN_SEC_REST], *ml = v->sec[SN_SEC_MLUMP];
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    float *w = (float *)(void *)WARR(h, o_acc, sn_acc);
    float R = v->cell * (float)(1 << k), inv = 1.0f / R, W = 0.0f, c[3] = {0, 0, 0}, I[6] = {0, 0, 0, 0, 0, 0};
    float rp[3], cr[3], A[6], det, tr, beta[3];
    uint32_t a, d;
    for (a = 0; a < v->nF; a++) {
        float hat = 1.0f;
        for (d = 0; d < 3; d++) {
            float u = (rd_real(rest, 3 * a + d) - x[d]) * inv;
            u = u < 0.0f ? -u : u;
            hat *= u < 1.0f ? 1.0f - u : 0.0f;
        }
        w[a] = hat * rd_real(ml, a);
        W += w[a];
    }
    if (!(W > 0.0f)) return 0;
    for (a = 0; a < v->nF; a++) {
        w[a] /= W;
        for (d = 0; d < 3; d++) c[d] += w[a] * pos[3 * a + d];
    }
    for (a = 0; a < v->nF; a++) {
        float r[3], r2;
        for (d = 0; d < 3; d++) r[d] = (pos[3 * a + d] - c[d]) * inv;
        r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        I[0] += w[a] * (r2 - r[0] * r[0]); I[1] += w[a] * (r2 - r[1] * r[1]); I[2] += w[a] * (r2 - r[2] * r[2]);
        I[3] -= w[a] * r[0] * r[1]; I[4] -= w[a] * r[0] * r[2]; I[5] -= w[a] * r[1] * r[2];
    }
    /* adjugate of the symmetric Î (xx yy zz xy xz yz) */
    A[0] = I[1] * I[2] - I[5] * I[5]; A[1] = I[0] * I[2] - I[4] * I[4]; A[2] = I[0] * I[1] - I[3] * I[3];
    A[3] = I[4] * I[5] - I[3] * I[2]; A[4] = I[3] * I[5] - I[4] * I[1]; A[5] = I[3] * I[4] - I[0] * I[5];
    det = I[0] * A[0] + I[3] * A[3] + I[4] * A[4];
    tr = I[0] + I[1] + I[2];
    if (!(det > 1.0f / 4294967296.0f) || det * 2048.0f < tr * tr * tr) return 0;
    for (d = 0; d < 3; d++) rp[d] = (p[d] - c[d]) * inv;
    cr[0] = rp[1] * F[2] - rp[2] * F[1]; cr[1] = rp[2] * F[0] - rp[0] * F[2]; cr[2] = rp[0] * F[1] - rp[1] * F[0];
    beta[0] = (A[0] * cr[0] + A[3] * cr[1] + A[4] * cr[2]) / det;
    beta[1] = (A[3] * cr[0] + A[1] * cr[1] + A[5] * cr[2]) / det;
    beta[2] = (A[4] * cr[0] + A[5] * cr[1] + A[2] * cr[2]) / det;
    for (a = 0; a < v->nF; a++) {
        float r[3], f[3];
        for (d = 0; d < 3; d++) r[d] = (pos[3 * a + d] - c[d]) * inv;
        f[0] = F[0] + beta[1] * r[2] - beta[2] * r[1];
        f[1] = F[1] + beta[2] * r[0] - beta[0] * r[2];
        f[2] = F[2] + beta[0] * r[1] - beta[1] * r[0];
        add_force(b, a, kk[a], s * w[a], f, q, 0, sat);
    }
    return 1;
}
#else
/* Fixed formats (NUMERICS.md "External forces"): hat Q16 per axis, Q30
 * product; w_a = hat m^_a 2^-23 (raw lumped mass) < 2^34, sum < 2^50;
 * w^_a Q28; c Q22 (a convex combination: no overflow); rho Q16 of R for Î
 * (clamped to 8: 2^19), Î summed in Q44 (< 2^54) and scaled to a 19-bit
 * block (relative precision 2^-19); the arms that multiply the force are
 * Q20 (clamped to 8: 2^23); rho_p x F to a 21-bit mantissa; beta = adj
 * (rho_p x F) / det with one rounded division (numerator < 2^61.6), clamped
 * to 2^36 (64 times the largest mantissa); beta x rho_a < 2^60; v_a = m +
 * beta x rho_a clamped to 2^34; w^ s (Q28) x v_a < 2^62. Clamps are counted.
 * The force total's error is |beta| times the weighted mean of the arms'
 * rounding (sum w^ = 1): about |beta| 2^-21. */
static int coarse(sn_ihdr *h, sn_q *b, int k, sn_q s, const sn_q x[3], const sn_q p[3], const sn_wide F[3],
                  int q, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *pos = CARR(h, o_pos, sn_q);
    const unsigned char *rest = v->sec[SN_SEC_REST], *ml = v->sec[SN_SEC_MLUMP];
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    int64_t *w = WARR(h, o_acc, sn_acc);
    int64_t R = (int64_t)v->cell << k, INV, W = 0, Ws, inv, sum = 0, c[3], I[6] = {0, 0, 0, 0, 0, 0};
    int64_t Iq[6], A[6], det, tr, rp[3], cr[3], beta[3], accc[3] = {0, 0, 0};
    int S = 14 + bitlen64((uint64_t)R), sh, bl;
    uint32_t a, d, amax = 0;
    /* 2^(S+16) / R in (2^30, 2^31]: rho = diff INV >> S is diff / R in Q16 */
    INV = (int64_t)sn_udiv64(((uint64_t)1 << (S + 16)) + ((uint64_t)R >> 1), (uint64_t)R);
    for (a = 0; a < v->nF; a++) {
        int64_t hat = (int64_t)1 << 30;
        for (d = 0; d < 3; d++) {
            int64_t u = abs64((int64_t)rd_real(rest, 3 * a + d) - x[d]) * INV >> S; /* Q16 of R; diff < 2^29 */
            int64_t hd = u < 65536 ? 65536 - u : 0;
            hat = (hat * hd) >> 16;
        }
        w[a] = (hat * rd_real(ml, a)) >> 23; /* entries < 2^27 (validated): w_a < 2^34, whatever frac_M */
        W += w[a];
    }
    if (W <= 0) return 0;
    /* w^_a = w_a / W in Q28: both scaled so W lies in [2^30, 2^31) */
    bl = bitlen64((uint64_t)W);
    sh = bl - 31;
    Ws = sh >= 0 ? W >> sh : W << -sh;
    inv = (int64_t)sn_udiv64(((uint64_t)1 << 59) + ((uint64_t)Ws >> 1), (uint64_t)Ws); /* (2^28, 2^29] */
    for (a = 0; a < v->nF; a++) {
        int64_t ws = sh >= 0 ? w[a] >> sh : w[a] << -sh;
        w[a] = (ws * inv + ((int64_t)1 << 30)) >> 31;
        sum += w[a];
        amax = w[a] > w[amax] ? a : amax;
    }
    w[amax] += ((int64_t)1 << 28) - sum; /* sum w^ = 1 exactly: the force total is kept */
    for (a = 0; a < v->nF; a++)
        for (d = 0; d < 3; d++) accc[d] += w[a] * pos[3 * a + d];
    for (d = 0; d < 3; d++) c[d] = sn_rshr64(accc[d], 28);
    for (a = 0; a < v->nF; a++) {
        int64_t r[3], r2;
        for (d = 0; d < 3; d++) r[d] = clamp64(((int64_t)pos[3 * a + d] - c[d]) * INV >> S, (int64_t)1 << 19);
        r2 = (r[0] * r[0] + r[1] * r[1] + r[2] * r[2]) >> 16;
        I[0] += w[a] * (r2 - ((r[0] * r[0]) >> 16)); I[1] += w[a] * (r2 - ((r[1] * r[1]) >> 16));
        I[2] += w[a] * (r2 - ((r[2] * r[2]) >> 16));
        I[3] -= w[a] * ((r[0] * r[1]) >> 16); I[4] -= w[a] * ((r[0] * r[2]) >> 16); I[5] -= w[a] * ((r[1] * r[2]) >> 16);
    }
    {   /* Î scaled so its largest entry lies in [2^18, 2^19): Î = Iq 2^(sh-44); adjugate < 2^39, det < 2^59.6 */
        int64_t mx = 0;
        for (d = 0; d < 6; d++) mx |= abs64(I[d]);
        sh = bitlen64((uint64_t)mx) - 19;
        sh = sh < 0 ? 0 : sh;
        for (d = 0; d < 6; d++) Iq[d] = sn_rshr64(I[d], sh);
    }
    A[0] = Iq[1] * Iq[2] - Iq[5] * Iq[5]; A[1] = Iq[0] * Iq[2] - Iq[4] * Iq[4]; A[2] = Iq[0] * Iq[1] - Iq[3] * Iq[3];
    A[3] = Iq[4] * Iq[5] - Iq[3] * Iq[2]; A[4] = Iq[3] * Iq[5] - Iq[4] * Iq[1]; A[5] = Iq[3] * Iq[4] - Iq[0] * Iq[5];
    det = Iq[0] * A[0] + Iq[3] * A[3] + Iq[4] * A[4];
    tr = Iq[0] + Iq[1] + Iq[2]; /* < 2^20.6: tr^3 < 2^61.8 */
    if (det <= 0 || det < ((tr * tr * tr) >> 11)) return 0;
    /* rho_p x F as a 21-bit mantissa cm 2^ecr (Q20 arms: F's scale after >> 20) */
    for (d = 0; d < 3; d++) rp[d] = clamp64(((int64_t)p[d] - c[d]) * INV >> (S - 4), (int64_t)1 << 23);
    cr[0] = sn_rshr64(rp[1] * F[2] - rp[2] * F[1], 20); cr[1] = sn_rshr64(rp[2] * F[0] - rp[0] * F[2], 20);
    cr[2] = sn_rshr64(rp[0] * F[1] - rp[1] * F[0], 20);
    {
        int64_t mx = abs64(cr[0]) | abs64(cr[1]) | abs64(cr[2]), den;
        int ecr = bitlen64((uint64_t)mx) - 21, E;
        ecr = ecr < 0 ? 0 : ecr;
        for (d = 0; d < 3; d++) cr[d] = sn_rshr64(cr[d], ecr);
        /* beta = Î^-1 (rho_p x F) = adj cm / det 2^(44 - sh + ecr); E >= 9 (I < 2^54 so sh <= 35) */
        E = 44 - sh + ecr;
        den = E < 62 ? det >> E : 0;
        if (den < 1) return 0; /* Î too small against the force's arm: thin region */
        beta[0] = sdiv_round(A[0] * cr[0] + A[3] * cr[1] + A[4] * cr[2], den); /* |adj cm| < 3 2^60 */
        beta[1] = sdiv_round(A[3] * cr[0] + A[1] * cr[1] + A[5] * cr[2], den);
        beta[2] = sdiv_round(A[4] * cr[0] + A[5] * cr[1] + A[2] * cr[2], den);
    }
    for (d = 0; d < 3; d++) {
        if (abs64(beta[d]) > ((int64_t)1 << 36)) (*sat)++;
        beta[d] = clamp64(beta[d], (int64_t)1 << 36);
    }
    for (a = 0; a < v->nF; a++) {
        int64_t r[3], f[3];
        sn_q om = (sn_q)(((int64_t)s * w[a] + ((int64_t)1 << 29)) >> 30); /* Q28 */
        for (d = 0; d < 3; d++) r[d] = clamp64(((int64_t)pos[3 * a + d] - c[d]) * INV >> (S - 4), (int64_t)1 << 23); /* Q20 */
        f[0] = F[0] + sn_rshr64(beta[1] * r[2] - beta[2] * r[1], 20);
        f[1] = F[1] + sn_rshr64(beta[2] * r[0] - beta[0] * r[2], 20);
        f[2] = F[2] + sn_rshr64(beta[0] * r[1] - beta[1] * r[0], 20);
        for (d = 0; d < 3; d++) { /* vertices outside the region (weight 0) have arbitrary arms: no clamp to count */
            if (abs64(f[d]) > ((int64_t)1 << 34) && om != 0) (*sat)++;
            f[d] = clamp64(f[d], (int64_t)1 << 34);
        }
        add_force(b, a, kk[a], om, f, q, 28, sat);
    }
    return 1;
}
#endif

/* ---- step 5: the applied forces into b ---- */

static void shares_of(const sn_ihdr *h, const sn_fslot *f, sn_q sh[SN_LEVELS]) {
    uint32_t k;
    for (k = 0; k < SN_LEVELS; k++) sh[k] = k == 0 ? (sn_q)ONE_SHARE : 0;
    if (f->prof != NO_PROFILE)
        for (k = 0; k < SN_LEVELS; k++)
            sh[k] = rd_real(h->v.sec[SN_SEC_SHARES] + (size_t)f->prof * SHARE_ELEM, k);
}

/* part (Q30 / float) of the slot's force in newtons, for the bones */
static void newtons_part(const sn_fslot *f, sn_q part, sn_wide out[3]) {
    uint32_t c;
    for (c = 0; c < 3; c++) {
#if defined(SN_FLOAT)
        out[c] = f->fn[c] * part;
#else
        /* |fn| < 2^47 (impulse / h, h >= 2^-16): split so the product stays < 2^62 */
        int64_t hi = f->fn[c] / 65536, lo = f->fn[c] - hi * 65536; /* truncation: lo has fn's sign */
        out[c] = hi * part / 16384 + sn_rshr64(lo * part, 30);      /* hi * part < 2^61: exact / 2^14 within 1 */
#endif
    }
}

void sn_forces_rhs(sn_ihdr *h, sn_q *b, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *pos = CARR(h, o_pos, sn_q);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    const sn_fslot *slots = CARR(h, o_frc, sn_fslot);
    uint32_t n, a, c;
    memset(ARR(h, o_wr, sn_wrench), 0, (size_t)v->nJ * sizeof(sn_wrench)); /* this step's wrenches */
    for (n = 0; n < h->n_forces; n++) {
        const sn_fslot *f = slots + n;
        const unsigned char *cl = v->sec[SN_SEC_CELLS] + (size_t)f->cell * SN_ELEM_CELLS;
        const unsigned char *cf = v->sec[SN_SEC_CFRAMES] + (size_t)f->cell * SN_ELEM_CFRAMES;
        sn_q phi[8], sh[SN_LEVELS], x[3], p[3], fine;
        sn_wide F[3], Fn[3], Fb[3];
#if defined(SN_FLOAT)
        float ppub[3];
#else
        int64_t ppub[3];
#endif
        int k;
        corner_weights(f->t, phi);
        cell_point(phi, cl, NULL, v->sec[SN_SEC_REST], x);
        cell_point(phi, cl, pos, NULL, p);
        pub_point(h, p, ppub);
        shares_of(h, f, sh);
        for (c = 0; c < 3; c++) F[c] = f->m[c];
        fine = sh[0];
        for (k = 1; k < SN_LEVELS - 1; k++) /* coarse levels; a region too thin hands its share to the fine level */
            if (sh[k] != 0 && !coarse(h, b, k, sh[k], x, p, F, f->q, sat)) fine += sh[k];
        for (a = 0; a < 8; a++) {
            uint32_t vx = sn_rd_u16(cl + 2 * a);
#if defined(SN_FLOAT)
            sn_q om = phi[a] * fine;
#else
            sn_q om = (sn_q)(((int64_t)phi[a] * fine + ((int64_t)1 << 29)) >> 30); /* Q30 */
#endif
            if (vx < v->nF) add_force(b, vx, kk[vx], om, F, f->q, 30, sat);
            else { /* a skeleton corner: that part pushes its bone */
                newtons_part(f, om, Fn);
                wrench_add(h, v->sec[SN_SEC_FRAMES][4 * vx], Fn, ppub);
            }
        }
        if (sh[SN_LEVELS - 1] != 0) { /* rigid level: the cell's two frame bones, by its frame weight */
            uint32_t wq = sn_rd_u16(cf + 2);
            newtons_part(f, sh[SN_LEVELS - 1], Fn);
            for (c = 0; c < 3; c++) {
#if defined(SN_FLOAT)
                Fb[c] = Fn[c] * (float)wq * (1.0f / 32768.0f);
#else
                Fb[c] = sdiv_round(Fn[c] * (int64_t)wq, 32768); /* |Fn| < 2^47: product < 2^62 */
#endif
                Fn[c] -= Fb[c]; /* the two parts sum to the share exactly */
            }
            wrench_add(h, cf[0], Fn, ppub);
            wrench_add(h, cf[1], Fb, ppub);
        }
    }
}

void sn_forces_clear(sn_ihdr *h) { h->n_forces = 0; }

/* ---- public API ---- */

/* The material point at world point P (public units): the nearest free
 * lattice vertex i by current position carries P back to rest space through
 * its frame, x = x_i + R_i^T (P - p_i); the cell whose rest box holds x (or
 * is nearest to it) and x's trilinear coordinates in it, clamped to the box.
 * O(nF + nC), in the call, not in the step. */
void sn_locate(const sn_ihdr *h, const sn_vec3 *P, uint32_t *cell, uint16_t t[3]) {
    const sn_view *v = &h->v;
    const sn_q *pos = CARR(h, o_pos, sn_q), *R = CARR(h, o_R, sn_q);
    const unsigned char *rest = v->sec[SN_SEC_REST], *cells = v->sec[SN_SEC_CELLS];
    sn_q p[3], d[3], x[3];
    uint32_t i, e, k, best = 0, dummy = 0;
    const sn_real pp[3] = {P->x, P->y, P->z};
#if defined(SN_FLOAT)
    float bd = 3.4e38f, be = 3.4e38f;
    for (k = 0; k < 3; k++) p[k] = pub_to_int(h, pp[k] - h->origin[k]);
#else
    int64_t bd = INT64_MAX, be = INT64_MAX;
    for (k = 0; k < 3; k++) p[k] = pub_to_int_sat(h, (int64_t)pp[k] - h->origin[k], &dummy);
#endif
    for (i = 0; i < v->nF; i++) {
        sn_acc d2 = 0;
        for (k = 0; k < 3; k++) {
            sn_q dk = sn_add(p[k], -pos[3 * i + k], &dummy);
            d2 += sn_mul(dk, dk); /* < 3 2^58 */
        }
        if (d2 < bd) { bd = d2; best = i; }
    }
    for (k = 0; k < 3; k++) d[k] = sn_add(p[k], -pos[3 * best + k], &dummy);
    sn_rot_t(R + 9 * best, d, x, &dummy);
    for (k = 0; k < 3; k++) x[k] = sn_add(x[k], rd_real(rest, 3 * best + k), &dummy);
    *cell = 0;
    for (e = 0; e < v->nC; e++) { /* squared distance from x to the cell's rest box (corner 0 to corner 7) */
        const unsigned char *cl = cells + (size_t)e * SN_ELEM_CELLS;
        sn_acc d2 = 0;
        for (k = 0; k < 3; k++) {
            sn_q lo = rd_real(rest, 3 * sn_rd_u16(cl) + k), hi = rd_real(rest, 3 * sn_rd_u16(cl + 14) + k);
            sn_q o = x[k] < lo ? sn_add(lo, -x[k], &dummy) : (x[k] > hi ? sn_add(x[k], -hi, &dummy) : 0);
            d2 += sn_mul(o, o);
        }
        if (d2 < be) { be = d2; *cell = e; }
    }
    {
        const unsigned char *cl = cells + (size_t)*cell * SN_ELEM_CELLS;
        for (k = 0; k < 3; k++) {
            sn_q lo = rd_real(rest, 3 * sn_rd_u16(cl) + k), hi = rd_real(rest, 3 * sn_rd_u16(cl + 14) + k);
            sn_q o = x[k] < lo ? lo : (x[k] > hi ? hi : x[k]);
#if defined(SN_FLOAT)
            float u = hi > lo ? (o - lo) / (hi - lo) : 0.0f;
            t[k] = (uint16_t)(u * 32768.0f + 0.5f);
#else
            int64_t D = (int64_t)hi - lo;
            t[k] = D > 0 ? (uint16_t)sn_udiv64(((uint64_t)((int64_t)o - lo) << 15) + ((uint64_t)D >> 1), (uint64_t)D) : 0;
#endif
        }
    }
}

static sn_status apply(sn_instance *inst, const sn_force *f, int impulse) {
    sn_ihdr *h;
    const sn_view *v;
    sn_fslot *s;
    uint32_t c;
    SN_CHECK_INST(inst);
    if (!f) return SN_ERR_NULL;
    h = hdr_of(inst);
    v = &h->v;
    if (f->at > SN_AT_POINT || (f->at == SN_AT_SURFACE && f->vertex >= v->nS) ||
        f->profile < -1 || (f->profile >= 0 && (uint32_t)f->profile >= v->nP))
        return SN_ERR_ARG;
#if defined(SN_FLOAT)
    {   /* finite, and within the range the arithmetic keeps finite */
        const float x[6] = {f->force.x, f->force.y, f->force.z, f->point.x, f->point.y, f->point.z};
        for (c = 0; c < 6; c++)
            if (!(x[c] >= -1.0e9f && x[c] <= 1.0e9f)) return SN_ERR_ARG;
    }
#endif
    if (h->n_forces >= v->nFrc) {
        h->force_drops = sn_count(h->force_drops, 1);
        return SN_ERR_FULL;
    }
    s = ARR(h, o_frc, sn_fslot) + h->n_forces;
    if (f->at == SN_AT_SURFACE) {
        const unsigned char *e = v->sec[SN_SEC_EMBED] + (size_t)f->vertex * SN_ELEM_EMBED;
        s->cell = sn_rd_u16(e);
        for (c = 0; c < 3; c++) s->t[c] = (uint16_t)sn_rd_u16(e + 2 + 2 * c);
    } else {
        sn_locate(h, &f->point, &s->cell, s->t);
    }
    /* profile: the caller's, or that of the cell's free corner with the largest weight */
    if (v->nP == 0) s->prof = NO_PROFILE;
    else if (f->profile >= 0) s->prof = (uint16_t)f->profile;
    else {
        const unsigned char *cl = v->sec[SN_SEC_CELLS] + (size_t)s->cell * SN_ELEM_CELLS;
        sn_q phi[8], bw = -1;
        uint32_t a, pick = 0;
        corner_weights(s->t, phi);
        for (a = 0; a < 8; a++) {
            uint32_t vx = sn_rd_u16(cl + 2 * a);
            if (vx < v->nF && phi[a] > bw) { bw = phi[a]; pick = vx; }
        }
        s->prof = v->nVP ? v->sec[SN_SEC_VSHARE][pick] : 0;
    }
    {
        const sn_real F[3] = {f->force.x, f->force.y, f->force.z};
#if defined(SN_FLOAT)
        float scale = impulse ? v->force / v->timestep : v->force, m[3], fn[3];
        for (c = 0; c < 3; c++) { /* a valid blob's tiny h can make J/h overflow: refused, nothing stored */
            m[c] = F[c] * scale;
            fn[c] = impulse ? F[c] / v->timestep : F[c];
            if (!(m[c] >= -1.0e30f && m[c] <= 1.0e30f && fn[c] >= -1.0e30f && fn[c] <= 1.0e30f)) return SN_ERR_ARG;
        }
        for (c = 0; c < 3; c++) { s->m[c] = m[c]; s->fn[c] = fn[c]; }
        s->q = 0;
#else
        /* value = F FORCE in Q(16 + frac_F) (< 2^62); an impulse is the force
         * J/h for one step: value 2^lead / h, J 2^16 / h for the bones */
        int64_t P[3], mx = 0;
        int q = 16 + v->frac_F, b;
        for (c = 0; c < 3; c++) {
            P[c] = (int64_t)F[c] * v->force;
            mx |= abs64(P[c]);
        }
        if (impulse) {
            int lead = 62 - bitlen64((uint64_t)mx);
            mx = 0;
            for (c = 0; c < 3; c++) {
                P[c] = sdiv_round(P[c] * ((int64_t)1 << lead), v->timestep); /* < 2^62 / h */
                mx |= abs64(P[c]);
            }
            q += lead - 16;
        }
        b = bitlen64((uint64_t)mx) - 30; /* mantissas below 2^30 */
        b = b < 0 ? 0 : b;
        for (c = 0; c < 3; c++) {
            s->m[c] = (int32_t)sn_rshr64(P[c], b);
            s->fn[c] = impulse ? sdiv_round((int64_t)F[c] * 65536, v->timestep) : (int64_t)F[c];
        }
        s->q = q - b;
#endif
    }
    h->n_forces++;
    return SN_OK;
}

sn_status sn_apply_force(sn_instance *inst, const sn_force *f) { return apply(inst, f, 0); }

sn_status sn_apply_impulse(sn_instance *inst, const sn_force *f) { return apply(inst, f, 1); }

sn_status sn_get_joint_wrench(const sn_instance *inst, uint32_t joint, sn_vec3 *force, sn_vec3 *torque,
                              sn_vec3 *about) {
    const sn_ihdr *h;
    const sn_wrench *w;
    sn_q jp[3];
    SN_CHECK_INST(inst);
    if (!force || !torque) return SN_ERR_NULL;
    h = chdr_of(inst);
    if (joint >= h->v.nJ) return SN_ERR_ARG;
    if (h->v.nFrc == 0) { /* no force slots: no wrench memory, always zero */
        force->x = force->y = force->z = torque->x = torque->y = torque->z = 0;
    } else {
        w = CARR(h, o_wr, sn_wrench) + joint;
#if defined(SN_FLOAT)
        force->x = w->f[0]; force->y = w->f[1]; force->z = w->f[2];
        torque->x = w->t[0]; torque->y = w->t[1]; torque->z = w->t[2];
#else
        force->x = clamp32(w->f[0]); force->y = clamp32(w->f[1]); force->z = clamp32(w->f[2]);
        torque->x = clamp32(sn_rshr64(w->t[0], 16)); torque->y = clamp32(sn_rshr64(w->t[1], 16));
        torque->z = clamp32(sn_rshr64(w->t[2], 16));
#endif
    }
    if (about) {
        joint_pos(h, joint, jp);
#if defined(SN_FLOAT)
        {
            float o[3];
            pub_point(h, jp, o);
            about->x = o[0]; about->y = o[1]; about->z = o[2];
        }
#else
        {
            int64_t o[3];
            pub_point(h, jp, o);
            about->x = clamp32(o[0]); about->y = clamp32(o[1]); about->z = clamp32(o[2]);
        }
#endif
    }
    return SN_OK;
}
