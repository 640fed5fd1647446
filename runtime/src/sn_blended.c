/* sn_blended.c -- SN_MODE_BLENDED: blended local linearization (seed 000
 * §4.5, eq. 18, 22-24), steps 5-7 of NUMERICS.md "One step" in that mode,
 * for comparison with the warped model as the paper does. It follows the
 * double reference SNREF_BLENDED (tools/ref/snref.c; definitions in
 * tests/reference/NONLINEAR.md):
 *   regions   one per joint r; W^r_a from FRAMES (b1, b2, w): W^b1 += 1 - w,
 *             W^b2 += w (Q15, a partition of unity over bones, exact)
 *   cells     K^r: the cells with a free corner of W^r > 0 (eq. 22)
 *   unknowns  Q^r: every free corner of those cells (the zero-weight border too)
 *   model     every cell of K^r in the bone's frame R^r (eq. 24 with the
 *             bone's motion measured as a floating frame): force
 *             R^r S^_e (R^rT (p - p0) - (x - x0)), stiffness R^r S^_e R^rT
 *   solve     the step system (eq. 18) over Q^r: the common right-hand side
 *             (gravity, mass terms, rigs, forces) plus the region's cell
 *             terms; the same fixed-iteration PCG as sn_solve.c with block
 *             Jacobi R^r P_i R^rT, warm-started from the previous merged dv
 *   merge     dv_a = sum_r W^r_a dv^r_a in one accumulator, rounded once
 * Vertex and cell frames stay the warped ones (gravity of REST_MODELLED,
 * limits, health, the energy). Constraint rows (user, contact, crease) are
 * not applied in this mode, as in the reference.
 *
 * Cost: regions, their cells and unknowns follow from FRAMES and CELLS, so
 * a step's work is fixed by the blob: per region r, nF + 8 nC mask tests,
 * then (1 + iterations) mat-vecs over |K^r| cells and |Q^r| mass rows.
 *
 * Overflow freedom (fixed) is sn_solve.c's: a region's cells are a subset
 * of the lattice's, so a vertex accumulator still takes at most 8 rotated
 * cell rows; the merge sums at most two weights of sum 2^15 times |dv^r| <=
 * 2^28: |sum| <= 2^43. */
#include "sn_blended.h"
#include "sn_kernels.h" /* sn_k_cell_mul: as sn_solve.c */

/* The blended mode's arrays, after the sn_instance_size bytes (the layout's
 * v.instance_bytes, then adaptation's state, ad_bytes; sn_instance_size_mode):
 * mg 3nF x 8 (merge accumulator) | bc, xr, z 3nF x 4 (common rhs, region
 * solution, preconditioned residual) | wr nF x u16 (W^r, Q15) | vm nF x u8
 * (unknowns of the region) | cm nC x u8 (cells of the region). */
typedef struct {
    sn_acc *mg;
    sn_q *bc, *xr, *z;
    uint16_t *wr;
    uint8_t *vm, *cm;
} blend_mem;

uint32_t sn_blended_bytes(uint32_t nF, uint32_t nC) {
    return (3u * nF * 8u + 3u * 3u * nF * 4u + 2u * nF + nF + nC + 7u) & ~7u;
}

size_t sn_instance_size_mode(const sn_blob *blob, sn_mode mode) {
    sn_view v;
    uint32_t nV, nF, nC;
    size_t base = sn_instance_size(blob);
    if (!blob || mode != SN_MODE_BLENDED) return base;
    sn_view_init(&v, blob);
    sn_level_counts(&v, &nV, &nF, &nC); /* the larger level of a 'levels 2' blob: sn_set_lod keeps the mode */
    return base + sn_blended_bytes(nF, nC);
}

static void mem_of(sn_ihdr *h, blend_mem *m) {
    unsigned char *p = sn_ws(h) + sn_blend_offset(h); /* scratch: in the instance past adaptation's mask, or the workspace's */
    uint32_t n3 = 3 * h->v.nF;
    m->mg = (sn_acc *)(void *)p;
    p += (size_t)n3 * 8u;
    m->bc = (sn_q *)(void *)p;
    m->xr = m->bc + n3;
    m->z = m->xr + n3;
    p += (size_t)n3 * 12u;
    m->wr = (uint16_t *)(void *)p;
    m->vm = (uint8_t *)(m->wr + h->v.nF);
    m->cm = m->vm + h->v.nF;
}

/* Region r: W^r per free vertex, its cells and unknowns; returns |Q^r|. */
static uint32_t region_setup(const sn_ihdr *h, uint32_t r, blend_mem *m) {
    const sn_view *v = &h->v;
    const unsigned char *fr = v->sec[SN_SEC_FRAMES], *cells = v->sec[SN_SEC_CELLS];
    uint32_t a, e, k, nF = v->nF, nu = 0;
    for (a = 0; a < nF; a++) {
        const unsigned char *f = fr + (size_t)a * SN_ELEM_FRAMES;
        uint32_t w = sn_rd_u16(f + 2), W = 0; /* w <= 32768 (validated) */
        if (f[0] == r) W += 32768u - w;
        if (f[1] == r) W += w;
        m->wr[a] = (uint16_t)W;
        m->vm[a] = 0;
    }
    for (e = 0; e < v->nC; e++) {
        const unsigned char *cl = cells + (size_t)e * SN_ELEM_CELLS;
        uint8_t in = 0;
        for (k = 0; k < 8; k++) {
            a = sn_rd_u16(cl + 2 * k);
            in |= (uint8_t)(a < nF && m->wr[a] != 0);
        }
        m->cm[e] = in;
        if (!in) continue;
        for (k = 0; k < 8; k++) {
            a = sn_rd_u16(cl + 2 * k);
            if (a < nF && !m->vm[a]) { m->vm[a] = 1; nu++; }
        }
    }
    return nu;
}


/* b = bc - sum_{e in K^r} R S^_e (d_e + R^T (w - w_a0)) on Q^r, 0 elsewhere:
 * sn_solve.c's cell_forces with every cell frame R = R^r (eq. 24). w (the
 * rhs's damping velocities: (1+b1) v free, b1 v' skeleton) is formed again
 * from v here, the same values, so this does not depend on where rhs keeps it. */
static void region_rhs(sn_ihdr *h, const sn_q *R, const blend_mem *m, sn_q *b, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *cells = v->sec[SN_SEC_CELLS], *K = v->sec[SN_SEC_CELLK];
    const unsigned char *rest = v->sec[SN_SEC_REST];
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    sn_acc *acc = WARR(h, o_acc, sn_acc);
    uint32_t e, k, c, i, nF = v->nF;
    sn_q ck = (sn_q)(ONE_COEF + v->b1);
    for (i = 0; i < 3 * nF; i++) acc[i] = 0;
    for (e = 0; e < v->nC; e++, K += SN_K_CELL_BYTES) {
        const unsigned char *cl = cells + (size_t)e * SN_ELEM_CELLS;
        uint32_t a0 = sn_rd_u16(cl);
        sn_q w0[3];
        sn_q d[24], uu[24];
        sn_acc ld[24], lu[24];
        uint32_t fr = 0; /* the free corners: the rows read below */
        if (!m->cm[e]) continue;
        for (c = 0; c < 3; c++) w0[c] = coef(vel[3 * a0 + c], a0 < nF ? ck : v->b1, sat);
        for (k = 0; k < 8; k++) {
            uint32_t a = sn_rd_u16(cl + 2 * k);
            sn_q t[3], s[3], l[3];
            fr |= (uint32_t)(a < nF) << k;
            for (c = 0; c < 3; c++) {
                t[c] = sn_add(pos[3 * a + c], -pos[3 * a0 + c], sat);
                s[c] = sn_add(coef(vel[3 * a + c], a < nF ? ck : v->b1, sat), -w0[c], sat);
            }
            sn_rot_t(R, t, l, sat);
            sn_rot_t(R, s, uu + 3 * k, sat);
            for (c = 0; c < 3; c++) {
                sn_q xr = sn_add(rd_real(rest, 3 * a + c), -rd_real(rest, 3 * a0 + c), sat);
                d[3 * k + c] = sn_add(l[c], -xr, sat);
            }
        }
        sn_k_cell_mul2(K, d, uu, ld, lu, fr);
        for (k = 0; k < 8; k++) {
            uint32_t a = sn_rd_u16(cl + 2 * k);
            sn_q t[3];
            int sh;
            if (a >= nF) continue;
            sh = v->frac_S - SN_KREL(kk[a]);
            for (c = 0; c < 3; c++) t[c] = sn_out(ld[3 * k + c] + lu[3 * k + c], sh, sat);
            sn_rot_acc(acc + 3 * a, R, t);
        }
    }
    for (i = 0; i < 3 * nF; i++) {
        SN_RANGE(SN_WITHIN(acc[i], 62), "vertex accumulator beyond 8 rotated cell rows", acc[i]);
        b[i] = m->vm[i / 3] ? sn_add(m->bc[i], -sn_out(acc[i], SN_Q_ROT, sat), sat) : 0;
    }
}

/* q = A^r d = (1+a1) M^ d + (1+b1) sum_{e in K^r} R^r S^_e R^rT d on Q^r, 0
 * elsewhere (d is 0 off Q^r: the reference's region_amul). The rounding is
 * sn_solve.c's matvec. */
static void region_matvec(sn_ihdr *h, const sn_q *R, const blend_mem *m, const sn_q *d, sn_q *q, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *cells = v->sec[SN_SEC_CELLS], *K = v->sec[SN_SEC_CELLK];
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *md = v->sec[SN_SEC_MDIAG], *mo = v->sec[SN_SEC_MOFF];
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    sn_acc *acc = WARR(h, o_acc, sn_acc);
    uint32_t e, i, k, nF = v->nF;
    sn_q cm = (sn_q)(ONE_COEF + v->a1), ck = (sn_q)(ONE_COEF + v->b1);
    for (i = 0; i < 3 * nF; i++) acc[i] = 0;
    for (e = 0; e < v->nC; e++, K += SN_K_CELL_BYTES) {
        /* the corners with an unknown of Q^r: d is 0 at the others */
        if (m->cm[e]) sn_cell_stiff_acc(h, K, cells + (size_t)e * SN_ELEM_CELLS, R, m->vm, d, acc, sat);
    }
    for (i = 0; i < 3 * nF; i++) {
        SN_RANGE(SN_WITHIN(acc[i], 62), "vertex accumulator beyond 8 rotated cell rows", acc[i]);
        q[i] = sn_out(acc[i], SN_Q_ROT, sat);
        acc[i] = 0;
    }
    /* mass over Q^r's rows: a row off Q^r has d_i = 0, so skipping it loses
     * nothing of the symmetric pass (its column terms are M_ij d_i = 0) */
    for (i = 0; i < nF; i++) {
        uint32_t p = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        if (!m->vm[i]) continue;
        for (k = 0; k < 3; k++) acc[3 * i + k] += sn_mul(rd_real(md, i), d[3 * i + k]);
        for (; p < end; p++) {
            uint32_t j = sn_rd_u16(cols + 2 * p);
            sn_q mij;
            if (j >= nF) break;
            mij = rd_real(mo, p);
            for (k = 0; k < 3; k++) {
                acc[3 * i + k] += sn_mul(mij, d[3 * j + k]);
                acc[3 * j + k] += sn_mul(mij, d[3 * i + k]);
            }
        }
    }
    for (i = 0; i < nF; i++)
        for (k = 0; k < 3; k++) {
            sn_q mk;
            sn_acc s;
            if (!m->vm[i]) { q[3 * i + k] = 0; continue; }
            mk = sn_out(acc[3 * i + k], v->frac_M - SN_KREL(kk[i]), sat);
            s = sn_mul(q[3 * i + k], ck) + sn_mul(mk, cm);
            q[3 * i + k] = sn_out(s, SN_Q_COEF, sat);
        }
}

/* z = R^r C R^rT r on Q^r, 0 elsewhere: the warped solve's preconditioner
 * (block Jacobi or IC(0), sn_precond.c) with the region's frame */
static void region_precond(sn_ihdr *h, const sn_q *R, const blend_mem *m, const sn_q *r, sn_q *z, uint32_t *sat) {
    sn_precond_region(h, R, m->vm, r, z, sat);
}

void sn_blended_solve(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    const sn_q *jR = CARR(h, o_jR, sn_q);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    sn_q *x = ARR(h, o_x, sn_q), *r = WARR(h, o_r, sn_q), *d = ARR(h, o_d, sn_q), *q = ARR(h, o_q, sn_q);
    sn_q *pos = ARR(h, o_pos, sn_q), *vel = ARR(h, o_vel, sn_q);
    uint32_t reg, i, it, n3 = 3 * v->nF, clamps = 0;
    blend_mem m;
    mem_of(h, &m);
    h->n_rows = h->rows_kept = h->contacts = 0; /* rows are not applied in this mode */
    sn_rhs(h, m.bc, 0, sat);
    for (i = 0; i < n3; i++) m.mg[i] = 0;
    for (reg = 0; reg < v->nJ; reg++) {
        const sn_q *R = jR + 9 * reg;
        sn_cgdot rz;
        if (region_setup(h, reg, &m) == 0) continue; /* a bone without flesh: no region */
        region_rhs(h, R, &m, r, sat);
        for (i = 0; i < n3; i++) m.xr[i] = m.vm[i / 3] ? x[i] : 0; /* warm start: the previous merged dv */
        region_matvec(h, R, &m, m.xr, q, sat);
        for (i = 0; i < n3; i++) r[i] = sn_add(r[i], -q[i], sat);
        region_precond(h, R, &m, r, m.z, sat);
        memcpy(d, m.z, n3 * sizeof(sn_q));
        rz = sn_cg_dot(r, m.z, kk, n3);
        for (it = 0; it < h->iterations; it++) {
            sn_cgdot dq, rz1;
            sn_q alpha, beta;
            int flat = sn_cg_flat(rz, n3); /* at the rounding floor: x and r stay (sn_solve.c) */
            region_matvec(h, R, &m, d, q, sat);
            dq = sn_cg_dot(q, d, kk, n3);
            alpha = flat ? 0 : sn_cg_ratio(rz, dq, &clamps);
            sn_cg_axpy(m.xr, alpha, d, n3, sat);
            if (it + 1 == h->iterations) break; /* the rest is never read (sn_solve.c) */
            sn_cg_axpy(r, (sn_q)-alpha, q, n3, sat);
            region_precond(h, R, &m, r, m.z, sat);
            rz1 = sn_cg_dot(r, m.z, kk, n3);
            beta = flat ? 0 : sn_cg_ratio(rz1, rz, &clamps);
            sn_cg_dir(d, m.z, beta, n3, sat);
            rz = rz1;
        }
        for (i = 0; i < n3; i++) { /* merge: + W^r dv^r (Q15 x Q22) */
#if defined(SN_FLOAT)
            m.mg[i] += (float)m.wr[i / 3] * (1.0f / 32768.0f) * m.xr[i];
#else
            m.mg[i] += sn_mul((sn_q)m.wr[i / 3], m.xr[i]);
#endif
        }
    }
    for (i = 0; i < n3; i++) x[i] = sn_out(m.mg[i], SN_Q_W, sat); /* rounded once */
    /* v += dv, p += h v (as sn_solve) */
    for (i = 0; i < n3; i++) {
        vel[i] = sn_add(vel[i], x[i], sat);
        pos[i] = sn_add(pos[i], vel[i], sat);
    }
    h->cg_clamps = sn_count(h->cg_clamps, clamps);
}
