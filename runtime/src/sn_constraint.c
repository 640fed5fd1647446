/* sn_constraint.c -- position constraints (seed 000 §4.4, eq. 19-21) and the
 * machinery every constraint producer shares: the step's rows, the
 * Cholesky-QR factorization of their Gram matrix with deterministic drops,
 * and the projection the CG applies (Baraff-Witkin filtered PCG).
 * runtime/NUMERICS.md "Constraints and contact" derives the formats and
 * bounds quoted here.
 *
 * C is the 3nF x m matrix whose column j is row j's coefficients over the
 * free vertices, c_j[3a+k] = sum_{entries at a} w dir_k. With G = C^T C =
 * L L^T (L = R^T of the QR factorization C = Q R, Q = C R^-1) the projector
 * on the free directions is P = I - Q Q^T = I - C G^-1 C^T: the runtime never
 * forms Q (whose columns are dense), it applies C^T (16 entries a row), two
 * triangular solves with L (m^2) and C (16 entries a row).
 *
 * Fixed formats: coefficients Q30 (|c| <= 1); G Q56 in int64 (|G| <= 2:
 * sum |w| <= 2 a row); L Q28 int32 (|L| <= sqrt 2); 1/L_jj Q24 (L_jj >=
 * 2^-6.5 by the drop rule); C^T y and the solves' vectors Q22 for velocity-
 * like y, Q19 for force-like (clamped to the state range, counted).
 */
#include "sn_constraint.h"
#include "sn_cut.h" /* sn_point_weights: a point's weights under the cut field */

typedef struct sn_con {
    uint16_t vtx[8];  /* lattice vertices of the point (SN_AT_LATTICE: one); cut: cell, t[3] */
    sn_q w[8];        /* their weights, Q30, summing to 1 */
    sn_real target[3];/* world target, public units */
    sn_q dir[3];      /* SN_AXIS_DIR: unit direction, Q30 */
    uint8_t n, axes, cut, pad1; /* cut: a point on the cut level, its <= 15 weights formed per step (sn_point_weights) */
} sn_con;
typedef char sn_con_fits_[sizeof(sn_con) <= SN_CON_BYTES ? 1 : -1];


#if defined(SN_FLOAT)
#define CN_SH(x, s) (x)
#define ONE30 1.0f
#define MUL64(a, b) ((a) * (b))
#else
#define CN_SH(x, s) sn_rshr64((x), (s))
#define ONE30 ((int32_t)1 << 30)
#define MUL64(a, b) ((int64_t)(a) * (int64_t)(b)) /* |a| <= 2^31 (a row's summed coefficients), |b| <= 2^30 */
#endif
/* drop rule: a row is kept when its squared length over the free vertices
 * (its Gram diagonal) is at least 2^-8 (a point almost wholly on skeleton
 * vertices would need huge free velocities), the part of it orthogonal to
 * the kept rows before it has at least 2^-SN_DROP_BITS of that (a nearly
 * dependent row would make G^-1 large: the multipliers of the projection
 * would leave their range), and at least 2^-10 absolutely: L_jj >= 2^-5,
 * so 1/L_jj <= 2^5 (Q24 < 2^31) */
#define SN_DROP_BITS 4
/* crease pair rows (sn_crease.c): relative pivot above 1/6. Neighbouring
 * pairs share cells; kept at 1/16 their G^-1 amplified the solve's
 * rounding and the fold depth followed it (0.26-0.33 mesh units with a
 * 13-15 bit block exponent; 0.215-0.231 at 1/6: NUMERICS.md) */
#define CR_DROP_K 6
#if defined(SN_FLOAT)
#define G_TINY (1.0f / 256.0f)
#define P_TINY (1.0f / 1024.0f)
#define P_REL (1.0f / 16.0f)
#else
#define G_TINY ((int64_t)1 << 48) /* 2^-8 in Q56 */
#define P_TINY ((int64_t)1 << 46) /* 2^-10 in Q56 */
#endif

/* ---- the section ---- */
void sn_view_constraints(sn_view *v) {
    const unsigned char *e = v->base + SN_H_SECTIONS + (size_t)SN_SEC_CONSTRAINTS * SN_SECTION_ENTRY;
    uint32_t con = 0, col = 0, ct = 0, rows;
    if (sn_rd_u32(e + 8) == 1u) {
        const unsigned char *r = v->sec[SN_SEC_CONSTRAINTS];
        con = r[0];
        col = r[1];
        ct = sn_rd_u16(r + 2);
    }
    rows = SN_ROWS_CAP(con, ct, v->cr_active); /* the crease record is decoded first (sn_view_sections) */
    if (con > SN_MAX_CONSTRAINTS || col > SN_MAX_COLLIDERS || ct > SN_MAX_CONTACTS || rows > SN_MAX_ROWS)
        con = col = ct = rows = 0; /* refused by sn_check_constraints; decode stays bounded */
    v->nCon = con;
    v->nCol = col;
    v->nCt = ct;
    v->nRows = rows;
    v->conB = rows || col ? SN_CONS_BYTES(con, col, rows) : 0u;
}

sn_status sn_check_constraints(sn_view *v) {
    const unsigned char *e = v->base + SN_H_SECTIONS + (size_t)SN_SEC_CONSTRAINTS * SN_SECTION_ENTRY;
    if (sn_rd_u32(e + 8) == 1u) {
        const unsigned char *r = v->sec[SN_SEC_CONSTRAINTS];
        uint32_t con = r[0], col = r[1], ct = sn_rd_u16(r + 2);
        if (con > SN_MAX_CONSTRAINTS || col > SN_MAX_COLLIDERS || ct > SN_MAX_CONTACTS) return SN_ERR_VALUE;
        if (SN_ROWS_CAP(con, ct, v->cr_active) > SN_MAX_ROWS) return SN_ERR_VALUE;
        if (sn_rd_u32(r + 4) != 0) return SN_ERR_VALUE;
        if (col > 0 && ct == 0) return SN_ERR_VALUE; /* colliders without a contact row */
    }
    sn_view_constraints(v);
    return SN_OK;
}

/* ---- layout and reset ---- */
void sn_cons_layout(sn_ihdr *h, uint32_t off, uint32_t row) {
    const sn_view *v = &h->v;
    h->o_con = off;
    h->o_col = h->o_con + v->nCon * SN_CON_BYTES;
    h->o_row = row; /* scratch (from h->ws): right after the colliders in the instance's own layout */
    h->o_rx = h->o_row + v->nRows * SN_ROW_BYTES;
    h->o_L = h->o_rx + v->nRows * SN_ROWAUX_BYTES;
}

void sn_cons_reset(sn_ihdr *h) {
    h->n_con = h->n_col = h->n_rows = h->rows_kept = h->contacts = 0;
    h->row_drops = h->contact_overflow = h->row_overflow = h->con_refused = h->con_clamps = 0;
}

/* ---- rows ---- */
int sn_rows_push(sn_ihdr *h, const sn_row *r) {
    uint32_t k;
#if defined(SN_FLOAT)
    float sw = 0.0f;
#else
    int64_t sw = 0;
#endif
    if (h->n_rows >= h->v.nRows || r->n == 0 || r->n > SN_ROW_MAX_ENT) {
        h->row_overflow = sn_count(h->row_overflow, 1);
        return 0;
    }
    for (k = 0; k < r->n; k++) {
        if (r->vtx[k] >= h->v.nV) { h->row_overflow = sn_count(h->row_overflow, 1); return 0; }
        sw += r->w[k] < 0 ? -(sn_acc)r->w[k] : (sn_acc)r->w[k];
    }
#if defined(SN_FLOAT)
    if (!(sw <= 2.0f + 1e-5f)) { h->row_overflow = sn_count(h->row_overflow, 1); return 0; }
#else
    if (sw > ((int64_t)2 << 30) + 16) { h->row_overflow = sn_count(h->row_overflow, 1); return 0; }
#endif
    memcpy(sn_rows(h) + h->n_rows, r, sizeof *r);
    h->n_rows++;
    return 1;
}

/* coefficient of entry k of a row along axis c: w dir_c (Q30, |.| <= 1:
 * beyond the state clamp SN_LIM, so rounded without it) */
SN_INLINE sn_q coef30(const sn_row *r, uint32_t k, uint32_t c, uint32_t *sat) {
    (void)sat;
#if defined(SN_FLOAT)
    return r->w[k] * r->dir[c];
#else
    return (int32_t)sn_rshr64((int64_t)r->w[k] * r->dir[c], 30);
#endif
}
#if !defined(SN_FLOAT)
/* int64 -> int32 with the clamp counted (L and 1/L_jj: |L| <= sqrt 2 in Q28
 * and 1/L_jj <= 2^6.5 in Q24 stay below 2^31 by the drop rule) */
SN_INLINE int32_t to32(int64_t x, uint32_t *sat) {
    if (x > INT32_MAX || x < -INT32_MAX) (*sat)++;
    return clamp32(x < -INT32_MAX ? -INT32_MAX : x);
}
#endif

/* c^T y of one row over free vertices: Q22 (velocity-like y) or Q19
 * (force-like y, Q(19+k_i) per vertex). Sum in Q52 / Q49: |.| <= 3.47 * 2^9 * 2^49 < 2^60. */
static sn_acc row_dot_raw(const sn_ihdr *h, const sn_row *r, const sn_q *y, int force_like, uint32_t *sat) {
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t k, nF = h->v.nF;
    sn_acc s = 0;
    (void)kk;
    for (k = 0; k < r->n; k++) {
        uint32_t a = r->vtx[k];
        sn_acc t;
        if (a >= nF) continue;
        t = sn_mul(coef30(r, k, 0, sat), y[3 * a]) + sn_mul(coef30(r, k, 1, sat), y[3 * a + 1]) +
            sn_mul(coef30(r, k, 2, sat), y[3 * a + 2]);
        s += force_like ? CN_SH(t, kk[a]) : t;
    }
    SN_RANGE(SN_WITHIN(s, 61), "constraint row dot beyond 2^61", s);
    return s; /* Q52 (velocity-like) / Q49 (force-like) */
}

sn_q sn_row_dot(const sn_ihdr *h, const sn_row *r, const sn_q *y, uint32_t *sat) {
    return sn_out(row_dot_raw(h, r, y, 0, sat), 30, sat);
}

/* acc += c_j lambda at the row's free entries, exactly (fixed: Q52 for
 * velocity-like y, Q49 for force-like; saturating at 2^62, never reached:
 * an entry takes at most the rows through its 8 cells) */
static void row_acc(const sn_ihdr *h, const sn_row *r, sn_q lam, sn_acc *acc, uint32_t *sat) {
    uint32_t k, c, nF = h->v.nF;
    for (k = 0; k < r->n; k++) {
        uint32_t a = r->vtx[k];
        if (a >= nF) continue;
        for (c = 0; c < 3; c++) {
            sn_acc p = sn_mul(coef30(r, k, c, sat), lam), *t = acc + 3 * a + c;
#if defined(SN_FLOAT)
            *t += p;
#else
            const int64_t lim = (int64_t)1 << 62;
            *t = p > 0 ? (*t > lim - p ? lim : *t + p) : (*t < -lim - p ? -lim : *t + p);
#endif
        }
    }
}
/* acc = 0 at the rows' free entries (the mat-vec leaves its sums there) */
static void rows_zero_acc(const sn_ihdr *h, sn_acc *acc) {
    const sn_row *r = CWARR(h, o_row, sn_row);
    uint32_t j, k, nF = h->v.nF;
    for (j = 0; j < h->n_rows; j++)
        for (k = 0; k < r[j].n; k++)
            if (r[j].vtx[k] < nF) acc[3 * r[j].vtx[k]] = acc[3 * r[j].vtx[k] + 1] = acc[3 * r[j].vtx[k] + 2] = 0;
}
/* y += acc (rounded once per entry to y's format) over the rows' free
 * entries, acc back to 0 there. The multipliers carry the block exponent e
 * (lambda_true = lambda 2^e): the shift is 30 - e (velocity-like) or
 * 30 - k_a - e (force-like), >= 0 for e <= 15. */
static void rows_apply_acc(const sn_ihdr *h, sn_acc *acc, sn_q *y, int force_like, int e, uint32_t *sat) {
    const sn_row *r = CWARR(h, o_row, sn_row);
    const sn_rowx *x = CWARR(h, o_rx, sn_rowx);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t j, k, c, nF = h->v.nF;
    for (j = 0; j < h->n_rows; j++) {
        if (x[j].inv == 0) continue;
        for (k = 0; k < r[j].n; k++) {
            uint32_t a = r[j].vtx[k];
            if (a >= nF) continue;
            for (c = 0; c < 3; c++) {
                sn_acc *t = acc + 3 * a + c;
                if (*t == 0) continue;
                y[3 * a + c] = sn_add(y[3 * a + c], sn_out(*t, (force_like ? 30 - kk[a] : 30) - e, sat), sat);
                *t = 0;
            }
        }
    }
}

/* packed lower triangle: entry (j, l), l <= j */
#define LIDX(j, l) ((size_t)(j) * ((j) + 1u) / 2u + (l))

/* One substitution step of gram_solve: s_j loaded into the accumulator
 * (fixed: Q(28 + q), the L entries' 28 fraction bits) ... */
SN_INLINE sn_acc gs_load(sn_q s) {
#if defined(SN_FLOAT)
    return s;
#else
    return (int64_t)s * ((int64_t)1 << 28);
#endif
}
/* ... and, the earlier unknowns subtracted, scaled by 1/L_jj and stored. */
SN_INLINE sn_q gs_store(sn_acc acc, sn_q inv, uint32_t *sat) {
#if defined(SN_FLOAT)
    return sn_out(acc * inv, 0, sat);
#else
    return sn_out((int64_t)clamp32(sn_rshr64(acc, 28)) * inv, 24, sat);
#endif
}

/* Solve G lam = s in place (aux[].s), over the kept rows: L u = s, L^T lam = u. */
static void gram_solve(sn_ihdr *h, uint32_t *sat) {
    const sn_q *L = CWARR(h, o_L, sn_q);
    sn_rowx *x = WARR(h, o_rx, sn_rowx);
    uint32_t j, l, m = h->n_rows;
    for (j = 0; j < m; j++) { /* forward: L u = s */
        sn_acc acc;
        if (x[j].inv == 0) { x[j].s = 0; continue; }
        acc = gs_load(x[j].s);
        for (l = 0; l < j; l++) acc -= sn_mul(L[LIDX(j, l)], x[l].s); /* dropped l: L = 0 */
        SN_RANGE(SN_WITHIN(acc, 62), "forward solve beyond 2^62", acc);
        x[j].s = gs_store(acc, x[j].inv, sat);
    }
    for (j = m; j-- > 0;) { /* back: L^T lam = u */
        sn_acc acc;
        if (x[j].inv == 0) { x[j].s = 0; continue; }
        acc = gs_load(x[j].s);
        for (l = j + 1; l < m; l++) acc -= sn_mul(L[LIDX(l, j)], x[l].s);
        SN_RANGE(SN_WITHIN(acc, 62), "back solve beyond 2^62", acc);
        x[j].s = gs_store(acc, x[j].inv, sat);
    }
}

/* The accumulator array (free between sn_solve's passes) sums the rows'
 * corrections of each entry before the one rounding. */
/* Block exponent of the step's C^T y (NUMERICS.md): the multipliers are
 * solved in units of 2^e LSB, e chosen so the largest |s_j| has 18 bits:
 * 10 bits of headroom below the state clamp (2^28) for G^-1's growth
 * (|G^-1| <= max 1/L_jj^2 <= 2^10 by the drop rule), and a residual of a
 * few LSB gets 8 more fraction bits (e = -8); e in [-8, 15] (the apply
 * shift 30 - k_a - e stays >= 0). Float: e = 0. */
#define SN_BLOCK_BITS 14
static int block_exp(uint64_t o) {
#if defined(SN_FLOAT)
    (void)o;
    return 0;
#else
    int e = bitlen64(o) - 30 - SN_BLOCK_BITS;
    return e < -8 ? -8 : (e > 15 ? 15 : e);
#endif
}
#if defined(SN_FLOAT)
#define ABS64(x) ((x) != (x) ? 1u : 0u) /* unused in float (e = 0) */
#else
#define ABS64(x) ((uint64_t)((x) < 0 ? -(x) : (x)))
#endif

void sn_rows_filter(sn_ihdr *h, sn_q *y, int force_like, uint32_t *sat) {
    const sn_row *r = sn_rows(h);
    sn_rowx *x = WARR(h, o_rx, sn_rowx);
    sn_acc *acc = WARR(h, o_acc, sn_acc);
    uint32_t j, m = h->n_rows;
    uint64_t o = 0;
    int e;
    for (j = 0; j < m; j++)
        if (x[j].inv != 0) { sn_acc t = row_dot_raw(h, r + j, y, force_like, sat); o |= ABS64(t); }
    e = block_exp(o);
    for (j = 0; j < m; j++) x[j].s = x[j].inv != 0 ? sn_out(row_dot_raw(h, r + j, y, force_like, sat), 30 + e, sat) : 0;
    gram_solve(h, sat);
    rows_zero_acc(h, acc);
    for (j = 0; j < m; j++)
        if (x[j].inv != 0) row_acc(h, r + j, (sn_q)-x[j].s, acc, sat);
    rows_apply_acc(h, acc, y, force_like, e, sat);
}

void sn_rows_fix(sn_ihdr *h, sn_q *y, uint32_t *sat) {
    const sn_row *r = sn_rows(h);
    sn_rowx *x = WARR(h, o_rx, sn_rowx);
    sn_acc *acc = WARR(h, o_acc, sn_acc);
    uint32_t j, m = h->n_rows;
    uint64_t o = 0;
    int e;
    /* residual a_j - c_j^T y in Q52: |a| 2^30 < 2^58.1, |c^T y| < 2^59.8 */
#if defined(SN_FLOAT)
#define FIX_RES(j) ((sn_acc)x[j].a - row_dot_raw(h, r + (j), y, 0, sat))
#else
#define FIX_RES(j) ((int64_t)x[j].a * ((int64_t)1 << 30) - row_dot_raw(h, r + (j), y, 0, sat))
#endif
    for (j = 0; j < m; j++)
        if (x[j].inv != 0) { sn_acc t = FIX_RES(j); o |= ABS64(t); }
    e = block_exp(o);
    for (j = 0; j < m; j++) x[j].s = x[j].inv != 0 ? sn_out(FIX_RES(j), 30 + e, sat) : 0;
#undef FIX_RES
    gram_solve(h, sat);
    rows_zero_acc(h, acc);
    for (j = 0; j < m; j++)
        if (x[j].inv != 0) row_acc(h, r + j, x[j].s, acc, sat);
    rows_apply_acc(h, acc, y, 0, e, sat);
}

/* Gram matrix and its Cholesky factor, row by row (Cholesky-Crout), with the
 * drop rule; the required values a_j = target_j - c_j . v (every entry:
 * free vertices' velocity at the start of the step, skeleton vertices' new
 * one). Uses the accumulator array as a dense scratch of one row. */
static uint32_t rows_factor(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_row *r = sn_rows(h);
    sn_rowx *x = WARR(h, o_rx, sn_rowx);
    sn_q *L = WARR(h, o_L, sn_q);
    sn_acc *sc = WARR(h, o_acc, sn_acc);
    const sn_q *vel = CARR(h, o_vel, sn_q);
    uint32_t j, l, k, kept = 0, m = h->n_rows, nF = v->nF;
    uint32_t c;
    for (k = 0; k < 3 * nF; k++) sc[k] = 0;
    for (j = 0; j < m; j++) {
        const sn_row *rj = r + j;
        sn_acc gjj = 0, piv, sv = 0;
        /* a_j */
        for (k = 0; k < rj->n; k++) {
            uint32_t a = rj->vtx[k];
            for (c = 0; c < 3; c++) sv += sn_mul(coef30(rj, k, c, sat), vel[3 * a + c]);
        }
        x[j].a = sn_add(rj->target, -sn_out(sv, 30, sat), sat);
        /* scatter c_j */
        for (k = 0; k < rj->n; k++) {
            uint32_t a = rj->vtx[k];
            if (a >= nF) continue;
            for (c = 0; c < 3; c++) sc[3 * a + c] += coef30(rj, k, c, sat);
        }
        /* G_jl = c_j . c_l (l <= j), Q56; then L_jl = (G_jl - sum_p L_jp L_lp) / L_ll */
        for (l = 0; l <= j; l++) {
            const sn_row *rl = r + l;
            sn_acc g = 0, s;
            uint32_t p;
            for (k = 0; k < rl->n; k++) {
                uint32_t a = rl->vtx[k];
                if (a >= nF) continue;
                for (c = 0; c < 3; c++) g += CN_SH(MUL64(sc[3 * a + c], coef30(rl, k, c, sat)), 4);
            }
            if (l == j) { gjj = g; break; }
            if (x[l].inv == 0) { L[LIDX(j, l)] = 0; continue; }
            s = g;
            for (p = 0; p < l; p++) s -= sn_mul(L[LIDX(j, p)], L[LIDX(l, p)]);
#if defined(SN_FLOAT)
            L[LIDX(j, l)] = sn_out(s * x[l].inv, 0, sat);
#else
            L[LIDX(j, l)] = to32(sn_rshr64((int64_t)clamp32(sn_rshr64(s, 28)) * x[l].inv, 24), sat);
#endif
        }
        /* unscatter */
        for (k = 0; k < rj->n; k++) {
            uint32_t a = rj->vtx[k];
            if (a >= nF) continue;
            for (c = 0; c < 3; c++) sc[3 * a + c] = 0;
        }
        piv = gjj;
        for (l = 0; l < j; l++) piv -= sn_mul(L[LIDX(j, l)], L[LIDX(j, l)]);
#if defined(SN_FLOAT)
        if (!(gjj >= G_TINY) || !(piv * (SN_ROW_PRODUCER(rj->source) == SN_SRC_CREASE ? (float)CR_DROP_K : 1.0f / P_REL) > gjj) || !(piv >= P_TINY)) {
#else
        if (gjj < G_TINY || piv * (SN_ROW_PRODUCER(rj->source) == SN_SRC_CREASE ? CR_DROP_K : (1 << SN_DROP_BITS)) <= gjj || piv < P_TINY) {
#endif
            x[j].inv = 0;
            for (l = 0; l <= j; l++) L[LIDX(j, l)] = 0;
            continue;
        }
#if defined(SN_FLOAT)
        x[j].inv = sn_frsqrt(piv);
        L[LIDX(j, j)] = piv * x[j].inv;
#else
        {
            uint32_t ljj = sn_isqrt64((uint64_t)piv); /* Q28, >= 2^21.5 */
            L[LIDX(j, j)] = (int32_t)ljj;
            x[j].inv = (int32_t)sn_udiv64((uint64_t)1 << 52, ljj);
        }
#endif
        kept++;
    }
    return kept;
}

/* ---- user constraints -> rows ---- */
/* position of the point at the start of the step: free vertices where they
 * are, skeleton vertices where they were (pos - vel: sn_skeleton moved them) */
static void con_point(const sn_ihdr *h, const uint16_t *vtx, const sn_q *w, uint32_t n, sn_q out[3], uint32_t *sat) {
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    uint32_t k;
    uint32_t c;
    sn_acc s[3] = {0, 0, 0};
    for (k = 0; k < n; k++) {
        uint32_t a = vtx[k];
        for (c = 0; c < 3; c++) {
            sn_q p = a < h->v.nF ? pos[3 * a + c] : sn_add(pos[3 * a + c], -vel[3 * a + c], sat);
            s[c] += sn_mul(w[k], p);
        }
    }
    for (c = 0; c < 3; c++) out[c] = sn_out(s[c], 30, sat);
}

/* one lattice cell per step at most */
static sn_q cap_cell(sn_ihdr *h, sn_q t) {
    sn_q cell = h->v.cell;
    if (t > cell) { h->con_clamps = sn_count(h->con_clamps, 1); return cell; }
    if (t < -cell) { h->con_clamps = sn_count(h->con_clamps, 1); return (sn_q)-cell; }
    return t;
}

void sn_user_rows(sn_ihdr *h, uint32_t *sat) {
    const sn_con *cs = CARR(h, o_con, sn_con);
    uint32_t i, k;
    uint32_t c;
    for (i = 0; i < h->n_con; i++) {
        const sn_con *cn = cs + i;
        sn_q p[3], t[3];
        sn_row r;
        memset(&r, 0, sizeof r);
        if (cn->cut) {
            const uint32_t tc[3] = {cn->vtx[1], cn->vtx[2], cn->vtx[3]};
            r.n = (uint8_t)sn_point_weights(&h->v, cn->vtx[0], tc, r.vtx, r.w);
        } else {
            r.n = cn->n;
            for (k = 0; k < cn->n; k++) { r.vtx[k] = cn->vtx[k]; r.w[k] = cn->w[k]; }
        }
        r.source = SN_ROW_SRC(SN_SRC_USER, i);
        con_point(h, r.vtx, r.w, r.n, p, sat);
        for (c = 0; c < 3; c++) {
#if defined(SN_FLOAT)
            t[c] = sn_add(pub_to_int(h, cn->target[c] - h->origin[c]), -p[c], sat);
#else
            t[c] = sn_add(pub_to_int_sat(h, (int64_t)cn->target[c] - h->origin[c], sat), -p[c], sat);
#endif
        }
        if (cn->axes & SN_AXIS_DIR) {
            for (c = 0; c < 3; c++) r.dir[c] = cn->dir[c];
            r.target = cap_cell(h, sn_out(sn_mul(cn->dir[0], t[0]) + sn_mul(cn->dir[1], t[1]) + sn_mul(cn->dir[2], t[2]),
                                          30, sat));
            (void)sn_rows_push(h, &r);
        } else {
            for (c = 0; c < 3; c++) {
                if (!(cn->axes & (1u << c))) continue;
                r.dir[0] = r.dir[1] = r.dir[2] = 0;
                r.dir[c] = ONE30;
                r.target = cap_cell(h, t[c]);
                (void)sn_rows_push(h, &r);
            }
        }
    }
}

/* ---- the solve's hook ---- */
uint32_t sn_constrain_begin(sn_ihdr *h, sn_q *x, sn_q *xold, uint32_t *sat) {
    uint32_t kept, m;
    h->n_rows = 0;
    h->rows_kept = 0;
    h->contacts = 0;
    if (h->v.nRows == 0) return 0;
    sn_user_rows(h, sat);
    sn_contact_rows(h, sat);
    sn_crease_rows_push(h, sat); /* self-collision near creases (sn_crease.c) */
    m = h->n_rows;
    if (m == 0) return 0;
    kept = rows_factor(h, sat);
    h->row_drops = sn_count(h->row_drops, m - kept);
    h->rows_kept = kept;
    if (kept == 0) { h->n_rows = 0; return 0; }
    if (xold) memcpy(xold, x, 3 * (size_t)h->v.nF * sizeof(sn_q)); /* after the collection: it uses d's storage */
    sn_rows_fix(h, x, sat);
    return kept;
}

/* ---- public API ---- */
#if defined(SN_FLOAT)
static int cn_fin(float x) { return x >= -1.0e9f && x <= 1.0e9f; }
#endif

sn_status sn_set_constraints(sn_instance *inst, const sn_constraint *list, uint32_t count) {
    sn_ihdr *h;
    sn_con *cs;
    uint32_t i, n, k;
    uint32_t c;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (count && !list) return SN_ERR_NULL;
    n = count < h->v.nCon ? count : h->v.nCon;
    for (i = 0; i < n; i++) { /* everything checked before anything changes */
        const sn_constraint *q = list + i;
        if (q->at > SN_AT_LATTICE) return SN_ERR_ARG;
        if (q->at == SN_AT_SURFACE && q->vertex >= h->v.nS) return SN_ERR_ARG;
        if (q->at == SN_AT_LATTICE && q->vertex >= h->v.nF) return SN_ERR_ARG;
        if (q->axes != SN_AXIS_DIR && (q->axes & ~SN_AXIS_ALL) != 0) return SN_ERR_ARG;
        if (q->axes == SN_AXIS_DIR && q->dir.x == 0 && q->dir.y == 0 && q->dir.z == 0) return SN_ERR_ARG;
#if defined(SN_FLOAT)
        if (!cn_fin(q->target.x) || !cn_fin(q->target.y) || !cn_fin(q->target.z) || !cn_fin(q->point.x) || !cn_fin(q->point.y) ||
            !cn_fin(q->point.z) || !cn_fin(q->dir.x) || !cn_fin(q->dir.y) || !cn_fin(q->dir.z))
            return SN_ERR_ARG;
#endif
    }
    cs = ARR(h, o_con, sn_con);
    for (i = 0; i < n; i++) {
        const sn_constraint *q = list + i;
        sn_con *cn = cs + i;
        memset(cn, 0, sizeof *cn);
        if (q->at == SN_AT_LATTICE) {
            cn->n = 1;
            cn->vtx[0] = (uint16_t)q->vertex;
            cn->w[0] = ONE30;
        } else {
            uint32_t cell, t[3];
            uint16_t t16[3];
            const unsigned char *cl;
            if (q->at == SN_AT_SURFACE) {
                const unsigned char *e = h->v.sec[SN_SEC_EMBED] + (size_t)q->vertex * SN_ELEM_EMBED;
                cell = sn_rd_u16(e);
                for (k = 0; k < 3; k++) t[k] = sn_rd_u16(e + 2 + 2 * k);
            } else {
                sn_locate(h, &q->point, &cell, t16);
                for (k = 0; k < 3; k++) t[k] = t16[k];
            }
            cl = h->v.sec[SN_SEC_CELLS] + (size_t)cell * SN_ELEM_CELLS;
            cn->n = 8;
            sn_trilinear(t, cn->w);
            for (k = 0; k < 8; k++) cn->vtx[k] = (uint16_t)sn_rd_u16(cl + 2 * k);
            if (h->v.cut) { /* the cut field: up to 15 weights, formed each step (sn_user_rows) */
                cn->cut = 1;
                cn->vtx[0] = (uint16_t)cell;
                for (k = 0; k < 3; k++) cn->vtx[1 + k] = (uint16_t)t[k];
            }
        }
        cn->target[0] = q->target.x;
        cn->target[1] = q->target.y;
        cn->target[2] = q->target.z;
        cn->axes = (uint8_t)(q->axes == 0 ? SN_AXIS_ALL : q->axes);
        if (q->axes == SN_AXIS_DIR) {
            const sn_real d[3] = {q->dir.x, q->dir.y, q->dir.z};
#if defined(SN_FLOAT)
            float l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2], il = l2 > 0.0f ? sn_frsqrt(l2) : 0.0f;
            for (c = 0; c < 3; c++) cn->dir[c] = d[c] * il;
            if (!(l2 > 0.0f) || !(l2 < 3.0e38f)) { cn->dir[0] = 1.0f; cn->dir[1] = cn->dir[2] = 0.0f; }
#else
            /* Q16.16 components: |d|^2 < 2^63; the unit vector in Q30 */
            int64_t l2 = 0;
            uint64_t len;
            for (c = 0; c < 3; c++) l2 += (int64_t)(d[c] >> 2) * (d[c] >> 2); /* Q14, < 3 2^58 */
            len = sn_isqrt64((uint64_t)l2);                                  /* Q14 */
            if (len == 0) { cn->dir[0] = ONE30; }
            else
                for (c = 0; c < 3; c++) {
                    int64_t num = (int64_t)(d[c] >> 2) * ((int64_t)1 << 30);
                    uint64_t qq = sn_udiv64((uint64_t)(num < 0 ? -num : num) + (len >> 1), len);
                    cn->dir[c] = (int32_t)(num < 0 ? -(int64_t)qq : (int64_t)qq);
                }
#endif
        }
    }
    h->n_con = n;
    if (count > n) {
        h->con_refused = sn_count(h->con_refused, count - n);
        return SN_ERR_FULL;
    }
    return SN_OK;
}
