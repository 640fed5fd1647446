/* sn_detail_adapt.c -- details on the cut level, stage 3: the active set
 * chosen by the runtime (seed 000 §4.7's adaptation, on the seats;
 * LEVELS.md §3 "Stage 3").
 *
 * After the step, when on: every detail's key. An active detail's is its
 * coefficient, |c|_inf (Q22). An inactive one's is the static coefficient it
 * would take alone, e_d = (M g - S y)_d / (tr sum_E S_dd / 3): the force left
 * on its hat at the current configuration (S y: the detail rows of the cut
 * element's product with y = the corners' and extras' displacement in the
 * cell frame, no velocity term, and the active seats' R^T c; M g: the
 * Galerkin mass against g_E at corners and extras, as the step's gravity)
 * over its own stiffness (the denominator per detail at init). Then the set:
 * an active detail stays while its key >= coarsen, an inactive one joins when
 * >= refine, at most A_max: incumbents first (bit 31), then by key, ties by id
 * (sn_select_threshold, shared with level 1's adaptation), through
 * sn_details_set's path (incumbents keep their state, entrants start at 0,
 * leavers drop theirs).
 *
 * Cost per step, fixed by the blob: the every-detail row product of every
 * cell with details (sn_detail_cell_rows: every row, the active details'
 * columns only; at most A_max of them), its mass rows too only with a modelled rest shape (else M g is
 * constant: summed once at init, sn_detail_adapt_init), 3
 * rotations per cell and detail, the keys, at most 33 nD compares for the
 * selection, and (when the set changes) sn_details_apply (nC masks). The
 * estimate's clamps are not state clamps: counted nowhere (the keys only rank). */
#include "sn_detail.h"
#include "sn_kernels_rot.h" /* the frame rotations, as the step's */

/* cell e's Galerkin mass rows against g at corners and extras (no detail
 * operand: yd zero on entry), summed into em per detail (ids in cell order) */
static void cell_mass(const sn_view *v, uint32_t e, const sn_q g[3], sn_q d[24], sn_q (*yx)[3], sn_q (*yd)[3], sn_acc *l,
                      sn_acc *em) {
    const unsigned char *cd = sn_sec(v, SN_SEC_CELLD) + (size_t)e * SN_ELEM_CELLD;
    const unsigned char *cx = sn_sec(v, SN_SEC_CELLX) + (size_t)e * SN_ELEM_CELLX;
    uint32_t nd = cd[38], on = nd >= 32u ? 0xFFFFFFFFu : (1u << nd) - 1u, k, c, j, nx = 0; /* nd <= 19 (validated) */
    for (k = 0; k < 24; k++) d[k] = (sn_q)-g[k % 3u];
    for (k = 0; k < SN_CUT_MAXX; k++)
        if (sn_rd_u16(cx + 2 * k) != SN_CUT_NONE) {
            for (c = 0; c < 3; c++) yx[nx][c] = (sn_q)-g[c];
            nx++;
        }
    sn_detail_cell_mass(v, e, on, d, (const sn_q(*)[3])yx, (const sn_q(*)[3])yd, NULL, l); /* the rows only */
    for (k = 0, j = 0; k < SN_CUT_MAXX; k++) {
        uint32_t id = sn_rd_u16(cd + 2 * k);
        if (id == SN_CUT_NONE) continue;
        for (c = 0; c < 3; c++) { /* saturating at 2^61 as a seat's accumulator (a hostile blob's repeats) */
#if defined(SN_FLOAT)
            em[3 * id + c] += l[3 * j + c];
#else
            int64_t lim = (int64_t)1 << 61, b = em[3 * id + c] + l[3 * j + c];
            em[3 * id + c] = b > lim ? lim : (b < -lim ? -lim : b);
#endif
        }
        j++;
    }
}

/* M g per detail at init when the rest shape is not modelled: g_E = g in
 * every cell, so the sums are constant (the same calls, the same order: the
 * bits the estimate summed per step before) */
void sn_detail_adapt_init(sn_ihdr *h) {
    const sn_view *v = &h->v;
    sn_dstate *s = sn_detail_region(h);
    sn_acc *em, l[3 * SN_CUT_MAXX];
    sn_q d[24], yx[SN_CUT_MAXX][3], yd[SN_CUT_MAXX][3];
    uint32_t e, i;
    if (!s) return;
    em = DT(s, o_em, sn_acc);
    for (i = 0; i < 3u * s->nd; i++) em[i] = 0;
    for (i = 0; i < SN_CUT_MAXX; i++) yd[i][0] = yd[i][1] = yd[i][2] = 0;
    if (v->flags & SN_FLAG_REST_MODELLED) return; /* per step (estimate) */
    for (e = 0; e < v->nC; e++)
        if (sn_sec(v, SN_SEC_CELLD)[(size_t)e * SN_ELEM_CELLD + 38]) cell_mass(v, e, v->grav, d, yx, yd, l, em);
}

/* vertex a's displacement from a0 in the cell frame, less the rest
 * difference: cell_forces' d (sn_solve.c) without its velocity term */
static void frame_disp(const sn_q *R, const sn_q *pos, const unsigned char *rest, uint32_t a, uint32_t a0, sn_q out[3],
                       uint32_t *sat) {
    sn_q t[3], lr[3], xr[3];
    sn_k_sub3(pos + 3 * a, pos + 3 * a0, t, sat);
    sn_k_rot_t(R, t, lr, sat);
    sn_k_sub3r(rest, 3 * a, 3 * a0, xr, sat);
    sn_k_sub3(lr, xr, out, sat);
}

/* the keys into s->o_key (their sums in o_es, o_em) */
static void estimate(const sn_ihdr *h, sn_dstate *s) {
    const sn_view *v = &h->v;
    const unsigned char *cells = v->sec[SN_SEC_CELLS], *rest = v->sec[SN_SEC_REST];
    const sn_q *cR = CARR(h, o_cR, sn_q), *pos = CARR(h, o_pos, sn_q), *coef = DT(s, o_coef, const sn_q);
    const uint16_t *of = DT(s, o_of, const uint16_t);
    const uint8_t *sk = DT(s, o_dk, const uint8_t), *sx = DT(s, o_sk, const uint8_t); /* the seat's force exponent; the static inverse's scale */
    const sn_q *sP = DT(s, o_sP, const sn_q);
    sn_acc *es = DT(s, o_es, sn_acc), *em = DT(s, o_em, sn_acc);
    uint32_t *key = DT(s, o_key, uint32_t);
    const int sh = v->frac_S - (SN_FLAVOUR == SN_FLAVOUR_FIXED ? sn_sec(v, SN_SEC_DETAILS)[2] : 0);
    uint32_t e, i, k, c, j, lsat = 0;
    for (i = 0; i < 3u * s->nd; i++) es[i] = 0;
    if (v->flags & SN_FLAG_REST_MODELLED)
        for (i = 0; i < 3u * s->nd; i++) em[i] = 0; /* else the constant sums of sn_detail_adapt_init */
    for (e = 0; e < v->nC; e++) {
        const unsigned char *cd = sn_sec(v, SN_SEC_CELLD) + (size_t)e * SN_ELEM_CELLD;
        const unsigned char *cx = sn_sec(v, SN_SEC_CELLX) + (size_t)e * SN_ELEM_CELLX;
        const unsigned char *cl = cells + (size_t)e * SN_ELEM_CELLS;
        const sn_q *R = cR + 9 * e;
        uint32_t a0 = sn_rd_u16(cl), nd = cd[38], on, nx = 0, act, ids[SN_CUT_MAXX];
        sn_q d[24], yx[SN_CUT_MAXX][3], yd[SN_CUT_MAXX][3], g[3], gr[3];
        sn_acc l[3 * SN_CUT_MAXX]; /* the mass rows, then the stiffness rows (one array: the stack, M4) */
        if (nd == 0) continue;
        on = nd >= 32u ? 0xFFFFFFFFu : (1u << nd) - 1u; /* nd <= 19 (validated) */
        for (k = 0, j = 0; k < SN_CUT_MAXX; k++) { /* the cell's details (ids) */
            uint32_t id = sn_rd_u16(cd + 2 * k);
            if (id == SN_CUT_NONE) continue;
            ids[j] = id;
            yd[j][0] = yd[j][1] = yd[j][2] = 0;
            j++;
        }
        if (v->flags & SN_FLAG_REST_MODELLED) { /* M g first: g_E = g - R_E^T g (sn_solve.c detail_mass_rhs) */
            sn_k_rot(R, v->grav, gr, &lsat);
            for (c = 0; c < 3; c++) g[c] = sn_add(v->grav[c], -gr[c], &lsat);
            cell_mass(v, e, g, d, yx, yd, l, em);
        }
        /* then S y: the corners' displacement in the cell frame (cell_forces' d), the extras' (sn_cut_terms' y
         * without its velocity term), the active details' R^T c */
        d[0] = d[1] = d[2] = 0;
        for (k = 1; k < 8; k++) frame_disp(R, pos, rest, sn_rd_u16(cl + 2 * k), a0, d + 3 * k, &lsat);
        for (k = 0, nx = 0; k < SN_CUT_MAXX; k++) {
            uint32_t x = sn_rd_u16(cx + 2 * k);
            if (x != SN_CUT_NONE) frame_disp(R, pos, rest, x, a0, yx[nx++], &lsat);
        }
        for (k = 0, act = 0; k < j; k++)
            if (of[ids[k]] != SN_CUT_NONE) {
                sn_k_rot_t(R, coef + 3 * (uint32_t)of[ids[k]], yd[k], &lsat);
                act |= 1u << k;
            }
        /* the rows only, the active details' columns only (the others' yd are 0: the same sums) */
        sn_detail_cell_rows(v, e, on, act, d, (const sn_q(*)[3])yx, (const sn_q(*)[3])yd, l, &lsat);
        for (k = 0; k < j; k++) {
            sn_acc t[3] = {0, 0, 0};
            uint32_t id = ids[k];
            sn_k_out_rot_acc(t, R, l + 3 * k, sh - SN_KREL(sk[id]), &lsat); /* as a seat's row (detail_rows_out) */
            for (c = 0; c < 3; c++) {
#if defined(SN_FLOAT)
                es[3 * id + c] += t[c];
#else
                int64_t lim = (int64_t)1 << 61, a = es[3 * id + c] + t[c];
                es[3 * id + c] = a > lim ? lim : (a < -lim ? -lim : a);
#endif
            }
        }
    }
    for (i = 0; i < s->nd; i++) {
        uint32_t m = 0;
        if (of[i] != SN_CUT_NONE) { /* active: its coefficient */
            for (c = 0; c < 3; c++) {
                uint32_t u = sn_key_of(coef[3 * (uint32_t)of[i] + c]);
                m = u > m ? u : m;
            }
        } else
            for (c = 0; c < 3; c++) { /* f = M g - S y at Q(19 + k) as a seat's b row, then its static answer P f (Q22) */
                sn_q f = sn_add((sn_q)-sn_out(es[3 * i + c], SN_Q_ROT, &lsat),
                                (sn_q)-sn_out(em[3 * i + c], v->frac_M - SN_KREL(sk[i]), &lsat), &lsat);
                uint32_t u = sn_key_of(sn_out(sn_mul(sP[i], f), v->frac_P - (int)sx[i] + SN_KREL(sk[i]), &lsat));
                m = u > m ? u : m;
            }
        key[i] = m > 0x7FFFFFFFu ? 0x7FFFFFFFu : m; /* bit 31 marks the incumbents (below) */
    }
}

void sn_detail_adapt_step(sn_ihdr *h) {
    sn_dstate *s = sn_detail_region(h);
    uint8_t *fl;
    uint32_t *key;
    uint16_t *ids;
    uint32_t i, want = 0, T = 0, above = 0, room, n = 0, ev = 0;
    if (!s || !s->on || h->lod != 0u || h->mode == SN_MODE_BLENDED) return;
    estimate(h, s);
    fl = DT(s, o_fl, uint8_t);
    key = DT(s, o_key, uint32_t);
    for (i = 0; i < s->nd; i++) {
        uint32_t was = DT(s, o_of, const uint16_t)[i] != SN_CUT_NONE;
        fl[i] = (uint8_t)(was | (key[i] >= (was ? s->coarsen : s->refine) ? 2u : 0u));
        want += (uint32_t)fl[i] >> 1;
        if (was) key[i] |= 0x80000000u; /* incumbents keep their seats before any entrant (sn_adapt.c's reason) */
    }
    if (want > s->amax) {
        s->overflow = sn_count(s->overflow, want - s->amax);
        T = sn_select_threshold(fl, key, s->nd, s->amax);
    }
    for (i = 0; i < s->nd; i++) above += ((uint32_t)fl[i] >> 1) & (uint32_t)(key[i] > T);
    room = s->amax - (above < s->amax ? above : s->amax);
    ids = (uint16_t *)(void *)DT(s, o_es, sn_acc); /* the estimate's sums are done with: the new set, ascending */
    for (i = 0; i < s->nd; i++) {
        uint32_t take = 0, was = fl[i] & 1u;
        if (fl[i] >> 1) {
            if (want <= s->amax || key[i] > T) take = 1;
            else if (key[i] == T && room) { take = 1; room--; }
        }
        if (take && !was) { s->refines = sn_count(s->refines, 1); ev++; }
        if (!take && was) { s->coarsens = sn_count(s->coarsens, 1); ev++; }
        if (take) ids[n++] = (uint16_t)i;
    }
    if (ev) sn_details_apply(h, s, ids, n); /* n <= A_max, ascending, distinct */
}

sn_status sn_set_detail_adapt(sn_instance *inst, int on) {
    sn_ihdr *h;
    sn_dstate *s;
    SN_CHECK_INST(inst);
    h = hdr_of(inst);
    s = sn_detail_region(h);
    if (!s) return on ? SN_ERR_ARG : SN_OK;
    s->on = on != 0;
    return SN_OK;
}
