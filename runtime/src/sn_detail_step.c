/* sn_detail_step.c -- details on the cut level, stage 2 (LEVELS.md §3
 * "Details on the cut level"): the instance's seats, the active set
 * (sn_details_set), the seats' preconditioner and hash. The step's use of
 * them is in sn_solve.c (cell_forces, the mass pass, the mat-vec, the CG);
 * the kernels in sn_detail.c. */
#include "sn_detail.h"

static uint32_t top_details(const sn_view *top, uint32_t *amax, uint32_t *nd) {
    if (sn_level_sec_count(top, SN_SEC_DETAILS) == 0) return 0;
    *amax = sn_rd_u16(sn_sec(top, SN_SEC_DETAILS));
    *nd = sn_level_sec_count(top, SN_SEC_DETAIL);
    return 1;
}

/* Layout from the region's start (8-aligned pieces first): header | acc 3A x 8 |
 * coef, vel 3A | x, r, d, q 3(nF + A) each | P A | on nC (u32) | seat A,
 * of nD (u16) | kk nF + A (u8) | stage 3, per detail: es, em 3 x 8 | dP, sP,
 * key (4) | dk, sk, fl (u8). Counts are validated (nF, nC, nD, A <= 65535). */
static uint32_t dt_layout(uint32_t amax, uint32_t nd, uint32_t nF, uint32_t nC, sn_dstate *s) {
    uint32_t o = SN_DSTATE_BYTES, n = nF + amax;
    s->o_acc = o; o += 24u * amax;
    s->o_coef = o; o += 12u * amax;
    s->o_vel = o; o += 12u * amax;
    s->o_x = o; o += 12u * n;
    s->o_r = o; o += 12u * n;
    s->o_d = o; o += 12u * n;
    s->o_q = o; o += 12u * n;
    s->o_P = o; o += 4u * amax;
    s->o_on = o; o += 4u * nC;
    s->o_seat = o; o += 2u * amax;
    s->o_of = o; o += 2u * nd;
    s->o_kk = o; o += n;
    o = (o + 7u) & ~7u;
    s->o_es = o; o += 24u * nd; /* stage 3: the estimate's sums (stiffness, mass) */
    s->o_em = o; o += 24u * nd;
    s->o_dP = o; o += 4u * nd;
    s->o_sP = o; o += 4u * nd;
    s->o_key = o; o += 4u * nd;
    s->o_dk = o; o += nd;
    s->o_sk = o; o += nd;
    s->o_fl = o; o += nd;
    return (o + 7u) & ~7u;
}

static void detail_precond(const sn_view *v, const sn_dstate *s, uint32_t det, int stat, sn_q *P, uint8_t *kd);

uint32_t sn_detail_bytes(const sn_view *top) {
    sn_dstate s;
    uint32_t amax, nd;
    if (!top_details(top, &amax, &nd)) return 0;
    return dt_layout(amax, nd, top->nF, top->nC, &s);
}

static sn_dstate *st(const sn_ihdr *h) {
    return (sn_dstate *)(void *)((unsigned char *)(uintptr_t)h + h->v.instance_bytes + h->ad_bytes);
}
/* the blob given to init has DETAILS (its section table: no view needed) */
static int has_details(const sn_ihdr *h) {
    return sn_rd_u32(h->lod_base + SN_H_SECTIONS + (size_t)SN_SEC_DETAILS * SN_SECTION_ENTRY + 8) != 0;
}
sn_dstate *sn_detail_region(const sn_ihdr *h) { return has_details(h) ? st(h) : NULL; }

void sn_detail_init(sn_ihdr *h) {
    sn_view top;
    sn_dstate *s;
    uint32_t amax, nd, i;
    sn_view_init(&top, (const sn_blob *)(const void *)h->lod_base);
    if (!top_details(&top, &amax, &nd)) return;
    s = st(h);
    s->bytes = dt_layout(amax, nd, top.nF, top.nC, s);
    s->amax = amax;
    s->nd = nd;
    s->nF = top.nF;
    s->nC = top.nC;
    s->bmin = 64;
#if !defined(SN_FLOAT)
    for (i = 0; i < top.nF; i++) { /* the k table's smallest trace (sn_k_table): the seats' k follow its rule */
        const unsigned char *P = top.sec[SN_SEC_PRECOND];
        int64_t tr = (int64_t)rd_real(P, 6 * i) + rd_real(P, 6 * i + 1) + rd_real(P, 6 * i + 2);
        uint32_t b = (uint32_t)bitlen64(tr > 0 ? (uint64_t)tr : 0u);
        s->bmin = b < s->bmin ? b : s->bmin;
    }
#else
    (void)i;
#endif
    s->on = 0;
    s->refine = sn_key_of(SN_RD_REAL(sn_sec(&top, SN_SEC_DETAILS) + 8));
    s->coarsen = sn_key_of(SN_RD_REAL(sn_sec(&top, SN_SEC_DETAILS) + 8 + RB));
    for (i = 0; i < nd; i++) { /* per detail, once: a seat's preconditioner and the estimate's denominator */
        detail_precond(&top, s, i, 0, DT(s, o_dP, sn_q) + i, DT(s, o_dk, uint8_t) + i);
        detail_precond(&top, s, i, 1, DT(s, o_sP, sn_q) + i, DT(s, o_sk, uint8_t) + i);
    }
    sn_detail_adapt_init(h);
    sn_detail_reset(h);
}

void sn_detail_reset(sn_ihdr *h) {
    sn_dstate *s;
    uint32_t i;
    if (!has_details(h)) return;
    s = st(h);
    s->n = 0;
    s->refines = s->coarsens = s->overflow = 0;
    for (i = 0; i < s->nd; i++) DT(s, o_of, uint16_t)[i] = SN_CUT_NONE;
    for (i = 0; i < s->nC; i++) DT(s, o_on, uint32_t)[i] = 0;
    for (i = 0; i < 3u * (s->nF + s->amax); i++) DT(s, o_x, sn_q)[i] = 0;
}

sn_dstate *sn_detail_live(const sn_ihdr *h) {
    if (!has_details(h) || h->lod != 0u || h->mode == SN_MODE_BLENDED || st(h)->n == 0) return NULL;
    return st(h);
}

/* cell e's compact detail j's own block (its run's column 8 + nx) */
static const unsigned char *own_block(const sn_view *v, uint32_t e, uint32_t j) {
    const unsigned char *cd = sn_sec(v, SN_SEC_CELLD) + (size_t)e * SN_ELEM_CELLD;
    const uint32_t nd = cd[38], nx = sn_sec(v, SN_SEC_CELLX)[(size_t)e * SN_ELEM_CELLX + 38];
    const size_t KB = SN_ELEM_CELLDK(SN_FLAVOUR, SN_REAL_BYTES);
    size_t at = sn_rd_u32(cd + 40), i;
    for (i = 0; i < j; i++) at += 8u + nx + nd - i;
    return sn_sec(v, SN_SEC_CELLDK) + (at + 8u + nx) * KB;
}

#if !defined(SN_FLOAT)
/* x * 2^e with |x| reduced below 2^35 (the exponent raised) */
static int64_t norm35(int64_t x, int *e) {
    while (x >= ((int64_t)1 << 35) || x <= -((int64_t)1 << 35)) { x /= 2; (*e)++; }
    return x;
}
#endif

/* The seat's preconditioner and force exponent: the scalar inverse of its
 * diagonal block's mean, a = (1+b1) tr(sum_E S_dd)/3 + (1+a1) sum_E m_dd (the
 * step matrix's, NUMERICS.md step 5-6; a trace is frame-free, so no rotation),
 * P = 1/a at frac_P (0 when a <= 0: a hostile blob's), clamped to 2^27 as
 * PRECOND's entries; k by sn_k_table's rule on 3P. Fixed: the sums are exact
 * int64 (<= 65535 cells x 3 x 2^27.6 stiffness, x 2^27 mass), each term brought
 * below 2^35 before its Q24 coefficient (< 2^61), the two aligned (< 2^62) and
 * brought below 2^31 (relative error < 2^-30), P = (2^63 - 1) / a (>= 32 bits)
 * shifted to frac_P: P within 2^-29 of 1/a, plus its rounding (test_runtime_dstep).
 * stat: the static denominator of stage 3's estimate instead, a = tr(sum_E S_dd)/3
 * (no b1, no mass), at frac_P - x (*kd = x, fixed; float 0): a hat's own
 * stiffness alone may be soft enough that 1/a exceeds 2^27 at frac_P (the
 * cow: 1/a ~ 2^12.2, clamped before x; x < frac_P - 3 keeps the estimate's
 * shift frac_P - x + k - 3 >= 0). Per detail, once at init (nD x nC x
 * 19 reads). */
static void detail_precond(const sn_view *v, const sn_dstate *s, uint32_t det, int stat, sn_q *P, uint8_t *kd) {
    const unsigned char *cd = sn_sec(v, SN_SEC_CELLD);
    uint32_t e, k;
#if defined(SN_FLOAT)
    float ssum = 0.0f, msum = 0.0f, a;
#else
    int64_t ssum = 0, msum = 0, t1, t2, A, q;
    int e1 = 0, e2 = 0, ea, sh, x = 0, ds = sn_sec(v, SN_SEC_DETAILS)[2];
#endif
    for (e = 0; e < s->nC; e++) {
        const unsigned char *c = cd + (size_t)e * SN_ELEM_CELLD;
        uint32_t j = 0;
        if (c[38] == 0) continue;
        for (k = 0; k < SN_CUT_MAXX; k++) {
            uint32_t d = sn_rd_u16(c + 2 * k);
            const unsigned char *b;
            if (d == SN_CUT_NONE) continue;
            if (d == det) {
                b = own_block(v, e, j);
#if defined(SN_FLOAT)
                ssum += rd_real(b, 0) + rd_real(b, 4) + rd_real(b, 8);
                msum += rd_real(b, 9);
#else
                ssum += ((int64_t)(int16_t)sn_rd_u16(b) + (int16_t)sn_rd_u16(b + 8) + (int16_t)sn_rd_u16(b + 16)) *
                        ((int64_t)1 << b[18]);
                msum += rd_real(b + 20, 0);
#endif
            }
            j++;
        }
    }
#if defined(SN_FLOAT)
    a = stat ? ssum / 3.0f : (1.0f + v->b1) * ssum / 3.0f + (1.0f + v->a1) * msum;
    *P = a > 1.0f / 134217728.0f ? 1.0f / a : 0.0f;
    *kd = 0;
#else
    /* a = t1 2^(e1 - (frac_S - ds) - 24) + t2 2^(e2 - frac_M - 24) */
    t1 = norm35(ssum, &e1) * (ONE_COEF + (stat ? 0 : (int64_t)v->b1)) / 3;
    t2 = stat ? 0 : norm35(msum, &e2) * (ONE_COEF + (int64_t)v->a1);
    e1 -= v->frac_S - ds;
    e2 -= v->frac_M;
    ea = stat || e1 > e2 ? e1 : e2;
    t1 = ea - e1 > 62 ? 0 : t1 / ((int64_t)1 << (ea - e1));
    t2 = stat || ea - e2 > 62 ? 0 : t2 / ((int64_t)1 << (ea - e2)); /* stat: no mass (and ea may be below e2) */
    A = t1 + t2; /* a = A 2^(ea - 24) */
    q = 0;
    if (A > 0) {
        while (A >= ((int64_t)1 << 31)) { A /= 2; ea++; } /* below 2^31: the quotient keeps >= 32 bits */
        q = INT64_MAX / A; /* ~2^63 / A */
        sh = v->frac_P - (ea - 24) - 63; /* P = q 2^sh */
        if (stat) /* the static inverse at frac_P - x, x the smallest that keeps it <= 2^27 (a soft hat's 1/a exceeds it) */
            while (x < 40 && x < v->frac_P - 3 && (sh - x > 30 || (sh - x >= 0 && q > ((int64_t)1 << 27) >> (sh - x)) ||
                              (sh - x < 0 && -(sh - x) <= 62 && sn_rshr64(q, x - sh) > ((int64_t)1 << 27))))
                x++;
        sh -= x;
        if (sh >= 0) q = (sh > 30 || q > ((int64_t)1 << 27) >> sh) ? (int64_t)1 << 27 : q << sh;
        else q = -sh > 62 ? 0 : sn_rshr64(q, -sh);
        if (q > ((int64_t)1 << 27)) q = (int64_t)1 << 27;
    }
    *P = (sn_q)q;
    if (stat) *kd = (uint8_t)x; /* the static inverse's scale: frac_P - x */
    else {
        int kb = bitlen64((uint64_t)(3 * q)) - (int)s->bmin;
        *kd = (uint8_t)(kb < 0 ? 0 : (kb > SN_KMAX ? SN_KMAX : kb));
    }
#endif
}

void sn_detail_precond(const sn_ihdr *h, const sn_dstate *s, const sn_q *r, sn_q *z, uint32_t *sat) {
    const sn_q *P = DT(s, o_P, const sn_q);
    const uint8_t *kk = DT(s, o_kk, const uint8_t) + s->nF;
    uint32_t i, c;
    for (i = 0; i < s->n; i++) /* r Q(19 + k), P Q(frac_P): P r < 2^27 2^31 */
        for (c = 0; c < 3; c++) z[3 * i + c] = sn_out(sn_mul(P[i], r[3 * i + c]), h->v.frac_P + SN_KREL(kk[i]), sat);
}

uint32_t sn_detail_iterations(const sn_ihdr *h) {
    uint32_t fl = st(h)->n <= SN_DETAIL_FEW ? SN_DETAIL_MIN_ITERATIONS : SN_DETAIL_MIN_ITERATIONS_MANY;
    uint32_t it = h->iterations < fl ? fl : h->iterations;
    return it > h->v.cg_max ? h->v.cg_max : it;
}

sn_status sn_details_set(sn_instance *inst, const uint16_t *ids, uint32_t n) {
    sn_ihdr *h;
    sn_dstate *s;
    uint8_t *fl;
    uint32_t i;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    if (n > 0 && !ids) return SN_ERR_NULL;
    if (!has_details(h)) return n ? SN_ERR_ARG : SN_OK;
    s = st(h);
    if (n > s->amax) return SN_ERR_ARG;
    for (i = 0; i < n; i++)
        if (ids[i] >= s->nd) return SN_ERR_ARG;
    fl = DT(s, o_fl, uint8_t); /* stage 3's flags: scratch between steps */
    for (i = 0; i < s->nd; i++) fl[i] = 0;
    for (i = 0; i < n; i++) { /* a repeat: refused, nothing changed */
        if (fl[ids[i]]) return SN_ERR_ARG;
        fl[ids[i]] = 1;
    }
    sn_details_apply(h, s, ids, n);
    return SN_OK;
}

void sn_details_apply(sn_ihdr *h, sn_dstate *s, const uint16_t *ids, uint32_t n) {
    uint16_t *of, *seat, *old;
    sn_q *coef, *vel, *x, *tc, *tv, *tx;
    uint32_t i, e, k, n0;
    sn_view top;
    of = DT(s, o_of, uint16_t);
    seat = DT(s, o_seat, uint16_t);
    coef = DT(s, o_coef, sn_q);
    vel = DT(s, o_vel, sn_q);
    x = DT(s, o_x, sn_q) + 3u * s->nF;
    old = (uint16_t *)(void *)DT(s, o_P, sn_q); /* the new seats' old ones (P is rebuilt below) */
    for (i = 0; i < n; i++) { /* mark (distinct: checked by the caller) */
        old[i] = of[ids[i]];
        of[ids[i]] = 0xFFFEu;
    }
    /* the old seats' state aside (d, q, r: dead between steps), then the new seats in ids' order */
    tc = DT(s, o_d, sn_q);
    tv = DT(s, o_q, sn_q);
    tx = DT(s, o_r, sn_q);
    n0 = s->n;
    for (i = 0; i < 3u * n0; i++) { tc[i] = coef[i]; tv[i] = vel[i]; tx[i] = x[i]; }
    for (i = 0; i < n0; i++)
        if (of[seat[i]] != 0xFFFEu) of[seat[i]] = SN_CUT_NONE; /* leaving: its coefficient dropped */
    for (i = 0; i < n; i++) {
        uint32_t o = old[i];
        seat[i] = ids[i];
        of[ids[i]] = (uint16_t)i;
        for (k = 0; k < 3; k++) {
            coef[3 * i + k] = o == SN_CUT_NONE ? 0 : tc[3 * o + k]; /* entering: 0 (the hierarchical basis) */
            vel[3 * i + k] = o == SN_CUT_NONE ? 0 : tv[3 * o + k];
            x[3 * i + k] = o == SN_CUT_NONE ? 0 : tx[3 * o + k];
        }
    }
    s->n = n;
    sn_view_init(&top, (const sn_blob *)(const void *)h->lod_base); /* the cut level's (h->v is level 1's while it is in force) */
    for (e = 0; e < s->nC; e++) { /* the cells' masks */
        const unsigned char *c = sn_sec(&top, SN_SEC_CELLD) + (size_t)e * SN_ELEM_CELLD;
        uint32_t j = 0, on = 0;
        for (k = 0; k < SN_CUT_MAXX; k++) {
            uint32_t d = sn_rd_u16(c + 2 * k);
            if (d == SN_CUT_NONE) continue;
            if (of[d] != SN_CUT_NONE) on |= 1u << j;
            j++;
        }
        DT(s, o_on, uint32_t)[e] = on;
    }
    for (i = 0; i < n; i++) { /* the seats' preconditioners: the details' (init) */
        DT(s, o_P, sn_q)[i] = DT(s, o_dP, const sn_q)[seat[i]];
        DT(s, o_kk, uint8_t)[s->nF + i] = DT(s, o_dk, const uint8_t)[seat[i]];
    }
}

uint64_t sn_detail_hash(const sn_ihdr *h, uint64_t hsh) {
    const sn_dstate *s;
    uint32_t i;
    if (!has_details(h) || st(h)->n == 0) return hsh;
    s = st(h);
    for (i = 0; i < s->n; i++) hsh = sn_fnv_u32(hsh, DT(s, o_seat, const uint16_t)[i]);
    for (i = 0; i < 3u * s->n; i++) {
        uint32_t u[3];
        memcpy(&u[0], DT(s, o_coef, const sn_q) + i, 4);
        memcpy(&u[1], DT(s, o_vel, const sn_q) + i, 4);
        memcpy(&u[2], DT(s, o_x, const sn_q) + 3u * s->nF + i, 4);
        hsh = sn_fnv_u32(sn_fnv_u32(sn_fnv_u32(hsh, u[0]), u[1]), u[2]);
    }
    return hsh;
}
