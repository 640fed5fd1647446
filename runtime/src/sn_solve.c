/* sn_solve.c -- steps 4-7: the right-hand side with the per-cell warped
 * elastic force (element energy, NUMERICS.md step 4), the mat-vec
 * A d = (1+a1) M^ d + (1+b1) sum_e R_e S^_e R_e^T d, and PCG (preconditioner:
 * sn_precond.c) with a fixed iteration count (seed 000 §4.2).
 *
 * Overflow freedom (fixed): a cell product row sums 8 blocks of 3 products,
 * < 24 * 2^55 = 2^59.6, rounded to an int32 force (clamped) before it is
 * rotated back; a free vertex's accumulator takes at most 8 rotated cell
 * rows (sn_instance_init checks it), each |R t| <= sqrt(3) 2^58, so < 2^61.8.
 * The mass pass is the assembled one of format 1 (<= 53 block products).
 */
#include "sn_constraint.h"
#include "sn_kernels.h" /* sn_k_cell_mul, sn_k_dot: scalar reference or the build's SIMD/DSP path */
#include "sn_blended.h" /* sn_rhs and the CG arithmetic, shared with the blended mode */
#include "sn_kernels_rot.h" /* sn_k_rot_t, sn_k_rot, sn_k_rot_acc: the frame rotations, reference or SIMD */
#include "sn_adapt.h"   /* the active set of level 1 (seed 000 §4.7) */
#include "sn_cut.h"     /* the cut level's extras (sn_cut_terms) */
#include "sn_detail.h"  /* details on the cut level: the seats' rows (sn_detail_step.c, kernels in sn_detail.c) */

SN_INLINE void sca_row(sn_acc l[3], sn_q m, const sn_q e[3]) {
    l[0] += sn_mul(m, e[0]);
    l[1] += sn_mul(m, e[1]);
    l[2] += sn_mul(m, e[2]);
}
/* acc_i += l at the end of row i */
SN_INLINE void row_done(sn_acc *acc, const sn_acc l[3]) {
    acc[0] += l[0];
    acc[1] += l[1];
    acc[2] += l[2];
}

/* acc += m e (scalar block) */
SN_INLINE void sca_mac(sn_acc acc[3], sn_q m, const sn_q e[3]) {
    acc[0] += sn_mul(m, e[0]);
    acc[1] += sn_mul(m, e[1]);
    acc[2] += sn_mul(m, e[2]);
}

static void acc_zero(sn_acc *acc, uint32_t n3) {
#if defined(SN_K_ZERO) /* the M4's and x86-64 AVX2's (sn_kernels.h) */
    sn_k_zero(acc, n3);
#else
    uint32_t i;
    for (i = 0; i < n3; i++) acc[i] = 0;
#endif
}



/* Saturating sum of non-negative energy terms (fixed: at 2^62). */
SN_INLINE sn_acc energy_add(sn_acc e, sn_acc x) {
#if defined(SN_FLOAT)
    return e + (x > 0.0f ? x : 0.0f); /* a term below 0 (a hostile, indefinite Se) counts 0, as in fixed */
#else
    const int64_t lim = (int64_t)1 << 62;
    if (x < 0) x = 0;
    return x > lim - e ? lim : e + x;
#endif
}
/* Q44 energy term -> Q32 (fixed) */
#if defined(SN_FLOAT)
#define E_Q32(x) (x)
#else
#define E_Q32(x) sn_rshr64((x), 12)
#endif

/* w at corner a: stored for free vertices ((1+b1) v), b1 v' for skeleton
 * ones, computed into tmp as rhs would have stored it (the same product;
 * its clamps are counted once in rhs). */
SN_INLINE const sn_q *w_of(const sn_ihdr *h, const sn_q *w, const sn_q *vel, uint32_t a, sn_q tmp[3]) {
    uint32_t counted = 0;
    if (a < h->v.nF) return w + 3 * a;
#if defined(SN_KERNELS_M4)
    if (h->v.b1 <= ONE_COEF && h->v.b1 >= -ONE_COEF) { /* |v'| <= SN_LIM: no clamp, no test (sn_kernels_rot.h) */
        const uint32_t bit = (uint32_t)1 << (SN_Q_COEF - 1);
        tmp[0] = sn_k_coef_nc(vel[3 * a], h->v.b1, bit);
        tmp[1] = sn_k_coef_nc(vel[3 * a + 1], h->v.b1, bit);
        tmp[2] = sn_k_coef_nc(vel[3 * a + 2], h->v.b1, bit);
        return tmp;
    }
#endif
    sn_k_coef3(vel + 3 * a, h->v.b1, tmp, &counted);
    return tmp;
}

/* Cell e's active details (CELLD's compact order): their seats in sj (SN_CUT_NONE:
 * inactive) and, for the active ones, y = R^T ys (ys per seat, world frame). */
static void detail_ops(const sn_view *v, const sn_dstate *dt, uint32_t e, const sn_q *R, const sn_q *ys, uint32_t sj[SN_CUT_MAXX],
                       sn_q yd[SN_CUT_MAXX][3], uint32_t *sat) {
    const unsigned char *cd = sn_sec(v, SN_SEC_CELLD) + (size_t)e * SN_ELEM_CELLD;
    const uint16_t *of = DT(dt, o_of, const uint16_t);
    uint32_t k, j = 0;
    for (k = 0; k < SN_CUT_MAXX; k++) {
        uint32_t d = sn_rd_u16(cd + 2 * k), s;
        if (d == SN_CUT_NONE) continue;
        s = of[d];
        sj[j] = s;
        if (s != SN_CUT_NONE) sn_k_rot_t(R, ys + 3 * s, yd[j], sat);
        else yd[j][0] = yd[j][1] = yd[j][2] = 0;
        j++;
    }
}

/* x clamped to +-lim, each clamp counted (fixed; float: x) */
SN_INLINE sn_acc lim_count(sn_acc x, int lim_log2, uint32_t *sat) {
#if defined(SN_FLOAT)
    (void)lim_log2; (void)sat;
    return x;
#else
    const int64_t lim = (int64_t)1 << lim_log2;
    if (x > lim) { (*sat)++; return lim; }
    if (x < -lim) { (*sat)++; return -lim; }
    return x;
#endif
}
/* acc += t for a seat, the sum saturating at 2^61 (counted): a hostile blob may
 * name one detail in many cells (the validator checks its own cell's entry
 * only); |t| < 2^61, so the sum fits before the clamp. */
SN_INLINE void seat_add(sn_acc acc[3], const sn_acc t[3], uint32_t *sat) {
    uint32_t c;
    for (c = 0; c < 3; c++) acc[c] = lim_count(acc[c] + t[c], 61, sat);
}
/* a corner row's detail mass part, clamped to 2^56 (counted): with <= 8 cells
 * (2^59) and the assembled row's < 2^62.3 (NUMERICS.md "The cut level") the
 * accumulator stays below sn_out's 2^62.5 */
SN_INLINE void corner_add(sn_acc acc[3], const sn_acc t[3], uint32_t *sat) {
    uint32_t c;
    for (c = 0; c < 3; c++) acc[c] += lim_count(t[c], 56, sat);
}

/* The details' rows of cell e (ld, the details' scale Q(frac_S - dshift)) rotated
 * back into their seats' accumulators: R round(l) at Q(19 + k_s), as a free
 * corner's (a detail lies in <= 4 cells: < 2^61 as the corners' 8 x sqrt(3) 2^58). */
static void detail_rows_out(const sn_ihdr *h, const sn_dstate *dt, uint32_t on, const uint32_t sj[SN_CUT_MAXX], const sn_q *R,
                            const sn_acc *ldd, sn_acc *sacc, uint32_t *sat) {
    const uint8_t *dk = DT(dt, o_kk, const uint8_t) + dt->nF;
    const int sh = h->v.frac_S - (SN_FLAVOUR == SN_FLAVOUR_FIXED ? sn_sec(&h->v, SN_SEC_DETAILS)[2] : 0);
    uint32_t j;
    for (j = 0; on >> j; j++)
        if (on >> j & 1u) {
            sn_acc t[3] = {0, 0, 0};
            sn_k_out_rot_acc(t, R, ldd + 3 * j, sh - SN_KREL(dk[sj[j]]), sat);
            seat_add(sacc + 3 * sj[j], t, sat);
        }
}

/* The active details' share of cell e's right-hand side (LEVELS.md §3): y_d =
 * R^T (c_d + w_d), an offset (no corner-0 difference); the corner rows' part in
 * lc, the seats' rows into sacc. */
SN_NOINLINE void detail_cell_rhs(const sn_ihdr *h, const sn_dstate *dt, uint32_t e, uint32_t on, const sn_q *R, const sn_q d[24],
                                 const sn_q uu[24], const sn_q (*yx)[3], sn_acc lc[24], sn_acc *sacc, uint32_t *sat) {
    sn_q yc[24], yd[SN_CUT_MAXX][3];
    sn_acc ldd[3 * SN_CUT_MAXX];
    uint32_t sj[SN_CUT_MAXX], k;
    for (k = 0; k < 24; k++) {
        yc[k] = sn_add(d[k], uu[k], sat); /* the corners' d + u (ld + lu's operand) */
        lc[k] = 0;
    }
    detail_ops(&h->v, dt, e, R, DT(dt, o_q, const sn_q) + 3 * dt->nF, sj, yd, sat);
    sn_detail_cell_mul(&h->v, e, on, yc, yx, (const sn_q(*)[3])yd, lc, ldd, sat);
    detail_rows_out(h, dt, on, sj, R, ldd, sacc, sat);
}

/* Per-cell elastic force plus the implicit stiffness/damping term (step 4-5):
 * acc_a = sum_e R_e S^_e (d_e + R_e^T (w - w_a0))_a over free corners, and twice
 * the elastic energy sum_e d_e . S^_e d_e into *e2 (Q32). u holds w per free vertex. */
static void cell_forces(sn_ihdr *h, const sn_dstate *dt, const sn_q *w, sn_acc *acc, sn_acc *e2, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *cells = v->sec[SN_SEC_CELLS], *K = v->sec[SN_SEC_CELLK];
    const unsigned char *rest = v->sec[SN_SEC_REST];
    const sn_q *cR = CARR(h, o_cR, sn_q), *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t e, k, c, nF = v->nF;
    uint32_t esat = 0; /* clamps of the energy estimate are not state clamps */
    sn_acc *sacc = dt ? DT(dt, o_acc, sn_acc) : NULL;
    acc_zero(acc, 3 * nF);
    if (dt) acc_zero(sacc, 3 * dt->n);
    for (e = 0; e < v->nC; e++, K += SN_K_CELL_BYTES) {
        const unsigned char *cl = cells + (size_t)e * SN_ELEM_CELLS;
        const sn_q *R = cR + 9 * e;
        uint32_t a0 = sn_rd_u16(cl);
        sn_q d[24], uu[24], w0s[3];
        sn_acc ld[24], lu[24], lx[24], lc[24], ec = 0;
        sn_q yx[SN_CUT_MAXX][3];
        uint32_t fr = 0; /* the free corners: lu's rows read below */
        uint32_t on = dt ? DT(dt, o_on, const uint32_t)[e] : 0;
        const sn_q *w0 = w_of(h, w, vel, a0, w0s);
#if defined(SN_K_ROTM) /* x86-64 AVX2: R permuted once for the corners (sn_kernels_rot.h) */
        sn_k_rotm rm;
        sn_k_rotm_ld(&rm, R);
#endif
        /* corner 0 is a0: its t, s and rest difference are 0, so d_0 = uu_0 = 0
         * exactly (no clamp), without its two rotations */
        for (c = 0; c < 3; c++) d[c] = uu[c] = 0;
        fr = (uint32_t)(a0 < nF);
#if defined(SN_K_CORNERS) /* the M4's Thumb-2 (sn_kernels.h) */
        fr |= sn_k_corners(cl, pos, w, vel, nF, v->b1, rest, R, w0, d, uu, sat);
#elif defined(SN_K_CORNER0) /* x86-64 float: corner 0's operands once (sn_kernels_rot.h) */
        {
            sn_k_c0 c0;
            sn_k_c0_ld(&c0, pos + 3 * a0, w0, rest, 3 * a0);
            fr = sn_k_free8(cl, nF);
            for (k = 1; k < 8; k++) {
                const uint32_t a = sn_rd_u16(cl + 2 * k);
                sn_q wa[3];
                sn_k_corner_c0(&rm, &c0, pos + 3 * a, w_of(h, w, vel, a, wa), rest, 3 * a, d + 3 * k, uu + 3 * k, sat);
            }
        }
#else
        for (k = 1; k < 8; k++) {
            uint32_t a = sn_rd_u16(cl + 2 * k);
#if defined(SN_K_CORNER) /* x86-64 AVX2: the steps below in registers (sn_kernels_rot.h) */
            sn_q wa[3];
            fr |= (uint32_t)(a < nF) << k;
            sn_k_corner(&rm, pos + 3 * a, pos + 3 * a0, w_of(h, w, vel, a, wa), w0, rest, 3 * a, 3 * a0, d + 3 * k, uu + 3 * k, sat);
#else
            sn_q t[3], s[3], l[3], wa[3], xr[3];
            fr |= (uint32_t)(a < nF) << k;
            sn_k_sub3(pos + 3 * a, pos + 3 * a0, t, sat); /* sn_add(x, -y) per entry */
            sn_k_sub3(w_of(h, w, vel, a, wa), w0, s, sat);
            sn_k_rot_t(R, t, l, sat);
            sn_k_rot_t(R, s, uu + 3 * k, sat);
            sn_k_sub3r(rest, 3 * a, 3 * a0, xr, sat);
            sn_k_sub3(l, xr, d + 3 * k, sat);
#endif
        }
#endif
        sn_k_cell_mul2(K, d, uu, ld, lu, fr);
        if (v->cut) sn_cut_terms(h, e, R, a0, w0, fr, yx, lx, sat); /* the cut level (sn_cut.c) */
        if (on) detail_cell_rhs(h, dt, e, on, R, d, uu, (const sn_q(*)[3])yx, lc, sacc, sat);
#if defined(SN_K_ENERGY)
        ec = sn_k_energy(d, ld, v->frac_S, &esat); /* the M4's (sn_kernels_rot.h) */
#elif defined(SN_K_ENERGY24) /* x86-64 AVX2 (sn_kernels_rot.h) */
        ec = sn_k_energy24(d, ld, v->frac_S, &esat);
#else
        for (k = 3; k < 24; k++) ec += sn_k_mul_out(d[k], ld[k], v->frac_S, &esat); /* d_0 = 0: no term */
#endif
        *e2 = energy_add(*e2, E_Q32(ec));
#if defined(SN_K_FREE8) /* x86-64 float: the free corners' bits, no cut level or details (sn_kernels_rot.h) */
        if (!v->cut && !on) {
            uint32_t fm;
            for (fm = fr; fm; fm &= fm - 1u) {
                const uint32_t a = sn_rd_u16(cl + 2 * (k = (uint32_t)__builtin_ctz(fm)));
                sn_k_out_rot_acc2_m(acc + 3 * a, &rm, ld + 3 * k, lu + 3 * k, sat);
            }
            continue;
        }
#endif
        for (k = 0; k < 8; k++) {
            uint32_t a = sn_rd_u16(cl + 2 * k);
            sn_acc ls[3];
            if (a >= nF) continue; /* skeleton rows are not unknowns (blob-fixed) */
            for (c = 0; c < 3; c++) ls[c] = ld[3 * k + c] + lu[3 * k + c] + (v->cut ? lx[3 * k + c] : 0) + (on ? lc[3 * k + c] : 0);
#if defined(SN_K_ROTM)
            sn_k_out_rot_acc_m(acc + 3 * a, &rm, ls, v->frac_S - SN_KREL(kk[a]), sat);
#else
            sn_k_out_rot_acc(acc + 3 * a, R, ls, v->frac_S - SN_KREL(kk[a]), sat); /* R round(ld + lu [+ lx]) */
#endif
        }
    }
}

/* The details' share of the mass pass and their gravity (rhs): per cell with
 * active details, sn_detail_cell_mass with y = a1 v (free corners, seats),
 * a1 v' + (v' - v) (skeleton corners, extras) as the assembled pass; the corner
 * rows' detail columns into acc (free corners), the seats' rows into their
 * accumulators. Gravity on a seat is sum over corners and extras of
 * M_E[d][col] g_E (the cut basis sums to one; g_E = g - R_E g with a modelled
 * rest shape, as a vertex's with its frame): folded in as y - g_E at the
 * corners and extras, which only the seats' rows read. bs: the seats' rows of
 * b, -= round(acc) at Q(19 + k_s). ua: a1 v per free vertex (or NULL). */
SN_NOINLINE void detail_mass_rhs(sn_ihdr *h, const sn_dstate *dt, const sn_q *ua, const sn_q *dsk, sn_acc *acc, sn_q *bs, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *cells = v->sec[SN_SEC_CELLS];
    const sn_q *vel = CARR(h, o_vel, sn_q), *cR = CARR(h, o_cR, sn_q);
    const uint32_t *ons = DT(dt, o_on, const uint32_t);
    const uint8_t *dk = DT(dt, o_kk, const uint8_t) + dt->nF;
    sn_acc *sacc = DT(dt, o_acc, sn_acc);
    sn_q *ys = DT(dt, o_d, sn_q) + 3 * dt->nF; /* a1 v per seat (d's seat rows: dead until the PCG) */
    uint32_t e, i, k, c, nF = v->nF, dummy = 0;
    for (i = 0; i < dt->n; i++) sn_k_coef3(DT(dt, o_vel, const sn_q) + 3 * i, v->a1, ys + 3 * i, sat);
    acc_zero(sacc, 3 * dt->n);
    for (e = 0; e < v->nC; e++) {
        const unsigned char *cl = cells + (size_t)e * SN_ELEM_CELLS;
        const unsigned char *cx = sn_sec(v, SN_SEC_CELLX) + (size_t)e * SN_ELEM_CELLX;
        uint32_t on = ons[e], sj[SN_CUT_MAXX], j, nx = 0;
        sn_q yc[24], yx[SN_CUT_MAXX][3], yd[SN_CUT_MAXX][3], g[3], gr[3];
        sn_acc mc[24], md[3 * SN_CUT_MAXX];
        const sn_q I[9] = {SN_ONE_ROT, 0, 0, 0, SN_ONE_ROT, 0, 0, 0, SN_ONE_ROT};
        if (!on) continue;
        sn_k_rot(cR + 9 * e, v->grav, gr, sat);
        for (c = 0; c < 3; c++) g[c] = (v->flags & SN_FLAG_REST_MODELLED) ? sn_add(v->grav[c], -gr[c], sat) : v->grav[c];
        for (k = 0; k < 8; k++) {
            uint32_t a = sn_rd_u16(cl + 2 * k);
            sn_q y[3];
            if (a < nF && ua) { y[0] = ua[3 * a]; y[1] = ua[3 * a + 1]; y[2] = ua[3 * a + 2]; }
            else sn_k_coef3(vel + 3 * a, v->a1, y, &dummy); /* counted by the assembled pass */
            if (a >= nF) sn_k_add3(y, dsk + 3 * (a - nF), y, &dummy);
            for (c = 0; c < 3; c++) yc[3 * k + c] = sn_add(y[c], -g[c], sat);
        }
        for (k = 0; k < SN_CUT_MAXX; k++) {
            uint32_t x = sn_rd_u16(cx + 2 * k);
            sn_q y[3];
            if (x == SN_CUT_NONE) continue;
            sn_k_coef3(vel + 3 * x, v->a1, y, sat);
            sn_k_add3(y, dsk + 3 * (x - nF), y, sat);
            for (c = 0; c < 3; c++) yx[nx][c] = sn_add(y[c], -g[c], sat);
            nx++;
        }
        detail_ops(v, dt, e, I, ys, sj, yd, sat); /* the mass is scalar: the world frame */
        for (k = 0; k < 24; k++) mc[k] = 0;
        sn_detail_cell_mass(v, e, on, yc, (const sn_q(*)[3])yx, (const sn_q(*)[3])yd, mc, md);
        for (k = 0; k < 8; k++) {
            uint32_t a = sn_rd_u16(cl + 2 * k);
            if (a < nF) corner_add(acc + 3 * a, mc + 3 * k, sat);
        }
        for (j = 0; on >> j; j++)
            if (on >> j & 1u) seat_add(sacc + 3 * sj[j], md + 3 * j, sat);
    }
    for (i = 0; i < dt->n; i++)
        for (c = 0; c < 3; c++)
            bs[3 * i + c] = sn_add(bs[3 * i + c], -sn_out(sacc[3 * i + c], v->frac_M - SN_KREL(dk[i]), sat), sat);
}

/* The initial residual folded into the right-hand side (NUMERICS.md "The
 * initial residual folded in"): float only. Its operands v + x0,
 * (1+b1)(v + x0) and a1 (v + x0) + x0 are plain floats, not clamped at
 * SN_FLIM (a torn state's v + x0 can reach 2 SN_FLIM: clamped, the folded
 * residual was not b - A x0 and test_physics_soak_float's cow did not
 * recover). Finite: |v|, |x0| <= SN_FLIM and a1, b1 in [0, 16] (validator)
 * give |w| <= 17 * 2^13 < 2^17.1, |y| < 2^17.1. Fixed: the range of v + x0
 * is not proven: off. */
#if defined(SN_FLOAT)
#define SN_FOLD 1
#else
#define SN_FOLD 0
#endif

/* Right-hand side b (into r), NUMERICS.md step 5:
 * b = f + m^ g^ [- m^ R g^] - a1 M^ v* - K~ w - M^_FS (v'_S - v_S) + f_rig;
 * elastic = 0 leaves out the cell terms (-K~ w and the elastic force: the
 * blended mode adds them per region) but still measures the energy.
 * With x0 (SN_FOLD; the CG's warm start, free rows): b - A x0, the PCG's
 * initial residual, without its mat-vec: A = (1+a1) M^ + (1+b1) K~ and both
 * terms of b are linear in the same operands, so w = (1+b1) (v + x0) and the
 * mass pass's y = a1 (v + x0) + x0 (KERNELS.md "Float step, round 3"). */
static void rhs_x0(sn_ihdr *h, sn_q *b, int elastic, const sn_q *x0, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *md = v->sec[SN_SEC_MDIAG], *mo = v->sec[SN_SEC_MOFF];
    const unsigned char *ml = v->sec[SN_SEC_MLUMP];
    const sn_q *R = CARR(h, o_R, sn_q), *vel = CARR(h, o_vel, sn_q);
    const sn_q *ds = CARR(h, o_ds, sn_q); /* in d's storage: d is not live yet */
    sn_q *u = ARR(h, o_q, sn_q); /* w, in q's storage: q and z are live only in the PCG */
    sn_acc *acc = WARR(h, o_acc, sn_acc);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t i, k, nF = v->nF, nV = v->nV, esat = 0;
    int pre;
    sn_q ck = (sn_q)(ONE_COEF + v->b1);
    sn_acc e2 = 0;
    sn_dstate *dt = elastic ? sn_detail_live(h) : NULL; /* the seats' rows follow the free ones in b */

    /* w = (1+b1) v (free), b1 v' (skeleton): stiffness damping + implicit h K v.
     * Stored over free vertices; the skeleton's, computed in cell_forces
     * (w_of), can clamp only when b1 > 1 (|v'| <= SN_LIM): counted here once. */
#if SN_FOLD
    if (x0)
#if defined(SN_K_FRHS) /* x86-64 AVX2 (sn_kernels.h) */
        sn_k_fold_w(u, vel, x0, ck, 3 * nF);
#else
        for (i = 0; i < 3 * nF; i++) u[i] = sn_fold_w1(vel[i], x0[i], ck); /* no clamp (sn_kernels.h) */
#endif
    else
#endif
    for (i = 0; i < nF; i++)
#if defined(SN_KERNELS_M4)
        sn_k_coef3(vel + 3 * i, ck, u + 3 * i, sat); /* coef per entry, in 32-bit words */
#else
        for (k = 0; k < 3; k++) u[3 * i + k] = coef(vel[3 * i + k], ck, sat);
#endif
    if (v->b1 > ONE_COEF)
        for (i = 3 * nF; i < 3 * nV; i++) (void)coef(vel[i], v->b1, sat);
    if (dt) { /* the seats' operands: c + (1+b1) v for the stiffness (in q's seat rows, dead until the PCG) */
        sn_q *ys = DT(dt, o_q, sn_q) + 3 * dt->nF;
        const sn_q *dc = DT(dt, o_coef, const sn_q), *dv = DT(dt, o_vel, const sn_q);
        for (i = 0; i < 3 * dt->n; i++) ys[i] = sn_add(dc[i], coef(dv[i], ck, sat), sat);
    }
    cell_forces(h, dt, u, acc, &e2, sat);
#if defined(SN_K_FRHS)
    if (elastic) sn_k_negout(b, acc, 3 * nF, sat);
    else
#endif
    for (i = 0; i < 3 * nF; i++) {
        SN_RANGE(SN_WITHIN(acc[i], 62), "vertex accumulator beyond 8 rotated cell rows", acc[i]);
#if defined(SN_KERNELS_M4)
        b[i] = elastic ? (sn_q)-sn_k_out_w(acc[i], SN_Q_ROT, (uint32_t)1 << (SN_Q_ROT - 1), sat) : 0; /* sn_out in words */
#else
        b[i] = elastic ? (sn_q)-sn_out(acc[i], SN_Q_ROT, sat) : 0; /* |.| <= SN_LIM */
#endif
    }
    if (dt)
        for (i = 0; i < 3 * dt->n; i++) b[3 * nF + i] = (sn_q)-sn_out(DT(dt, o_acc, sn_acc)[i], SN_Q_ROT, sat);
    /* kinetic energy with the lumped mass: sum m^_i |v_i|^2 (twice the energy) */
    for (i = 0; i < nF; i++) {
        sn_q mi = rd_real(ml, i);
        sn_acc ek = 0;
#if defined(SN_KERNELS_M4)
        if ((uint32_t)(v->frac_M - 1) < 31u) { /* sn_out in 32-bit words: the same values and counts */
            const uint32_t bit = (uint32_t)1 << (v->frac_M - 1);
            for (k = 0; k < 3; k++) {
                int32_t t = sn_k_out_w(sn_mul(mi, vel[3 * i + k]), v->frac_M, bit, &esat);
                __asm__("" : "+r"(t)); /* an int32: SMLAL (SN_K_I32) */
                ek += sn_mul(vel[3 * i + k], t);
            }
        } else
#endif
        for (k = 0; k < 3; k++) ek += sn_mul(vel[3 * i + k], sn_mulq(mi, vel[3 * i + k], v->frac_M, &esat));
        e2 = energy_add(e2, E_Q32(ek));
    }
    sn_set_energy(h, e2);

    /* mass pass: acc_i = M^_ij y_j, y = a1 v (free), a1 v' + (v' - v) (skeleton).
     * With |a1| <= 1 the free y cannot clamp (|a1 v| <= SN_LIM after the
     * rounding): formed once per vertex into q's storage (w is dead after
     * cell_forces) instead of at each of its blocks; the same values and no
     * clamp count lost. Otherwise (and for skeleton y) per block as before. */
    acc_zero(acc, 3 * nF);
    pre = (v->a1 <= ONE_COEF && v->a1 >= -ONE_COEF) || (SN_FOLD && x0);
#if SN_FOLD
    if (x0) /* y = a1 (v + x0) + x0, once per vertex, no clamp */
#if defined(SN_K_FRHS)
        sn_k_fold_y(u, vel, x0, v->a1, 3 * nF);
#else
        for (i = 0; i < 3 * nF; i++) u[i] = sn_fold_y1(vel[i], x0[i], v->a1);
#endif
    else
#endif
    if (pre)
        for (i = 0; i < nF; i++) sn_k_coef3(vel + 3 * i, v->a1, u + 3 * i, sat);
#if defined(SN_K_MASS_FF) && defined(SN_K_MASS_SK)
    /* the M4: the free blocks by the mat-vec's loop, then the skeleton
     * columns (sn_kernels.h); exact int64 sums of the same products, each
     * partial sum within the pass's bound in any order (KERNELS_M4.md "M4
     * round 4") */
    if (pre) {
        sn_k_mass_ff(rp, cols, md, mo, u, acc, nF);
        sn_k_mass_sk(rp, cols, mo, vel, ds, v->a1, acc, nF, sat);
    }
    for (i = pre ? nF : 0; i < nF; i++) {
#elif defined(SN_K_FRHS) /* x86-64 AVX2: the loop below for every row (sn_kernels.h) */
    if (pre) sn_k_mass_rhs(rp, cols, md, mo, u, vel, ds, v->a1, acc, nF, sat);
    for (i = pre ? nF : 0; i < nF; i++) {
#else
    for (i = 0; i < nF; i++) {
#endif
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        sn_q yis[3], yjs[3];
        const sn_q *yi = u + 3 * i;
        sn_acc l[3] = {0, 0, 0};
        if (!pre) {
            sn_k_coef3(vel + 3 * i, v->a1, yis, sat); /* sn_kernels_rot.h: coef per entry */
            yi = yis;
        }
        sca_row(l, rd_real(md, i), yi);
        for (; e < end; e++) {
            uint32_t j = sn_rd_u16(cols + 2 * e);
            sn_q m = rd_real(mo, e);
            const sn_q *yj = u + 3 * j;
            if (j >= nF || !pre) {
                sn_k_coef3(vel + 3 * j, v->a1, yjs, sat);
                if (j >= nF) sn_k_add3(yjs, ds + 3 * (j - nF), yjs, sat);
                yj = yjs;
            }
            sca_row(l, m, yj);
            if (j < nF) sca_mac(acc + 3 * j, m, yi);
        }
        row_done(acc + 3 * i, l);
    }
    if (dt) detail_mass_rhs(h, dt, pre ? u : NULL, ds, acc, b + 3 * nF, sat);
#if defined(SN_K_FRHS) /* x86-64 AVX2: the loop below (sn_kernels.h) */
    sn_k_grav_rhs(b, acc, R, ml, v->grav, (v->flags & SN_FLAG_REST_MODELLED) != 0, nF, sat);
    (void)kk;
#else
    for (i = 0; i < nF; i++) {
        sn_q mi = rd_real(ml, i), gi[3], gr[3];
        /* rest shape = modelled shape: cancel gravity as the vertex frame turns it */
        sn_k_rot(R + 9 * i, v->grav, gr, sat);
        for (k = 0; k < 3; k++)
            gi[k] = (v->flags & SN_FLAG_REST_MODELLED) ? sn_add(v->grav[k], -gr[k], sat) : v->grav[k];
#if defined(SN_KERNELS_M4)
        { /* sn_out for 0 < s < 32 in 32-bit words (sn_k_out_w), the sum by QADD / QSUB (|ma| <= SN_LIM):
           * the same values and counts */
            const int s = v->frac_M - SN_KREL(kk[i]);
            if ((uint32_t)(s - 1) < 31u) {
                const uint32_t bit = (uint32_t)1 << (s - 1);
                for (k = 0; k < 3; k++) {
                    sn_q g = sn_k_out_w(sn_mul(mi, gi[k]), s, bit, sat);
                    sn_q ma = sn_k_out_w(acc[3 * i + k], s, bit, sat);
                    b[3 * i + k] = sn_k_qsub(sn_add(b[3 * i + k], g, sat), ma, sat);
                }
                continue;
            }
        }
#endif
        for (k = 0; k < 3; k++) {
            sn_q g = sn_mulq(mi, gi[k], v->frac_M - SN_KREL(kk[i]), sat);
            sn_q ma = sn_out(acc[3 * i + k], v->frac_M - SN_KREL(kk[i]), sat);
            b[3 * i + k] = sn_add(sn_add(b[3 * i + k], g, sat), -ma, sat);
        }
    }
#endif
    sn_rigs(h, b, sat); /* + R_i sum_a tau_a Q^a_i (seed 003 eq. 12) */
    sn_forces_rhs(h, b, sat); /* + applied forces (seed 004 ch. 4 shares) */
}
void sn_rhs(sn_ihdr *h, sn_q *b, int elastic, uint32_t *sat) { rhs_x0(h, b, elastic, NULL, sat); }


/* Symmetric mass pass over free-free blocks: acc = M^ y (y over free); with
 * mask, over the rows and columns with mask != 0 (y is 0 at the others). */
static void pass_M_ff(const sn_ihdr *h, const sn_q *y, const uint8_t *mask, sn_acc *acc) {
    const sn_view *v = &h->v;
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *md = v->sec[SN_SEC_MDIAG], *mo = v->sec[SN_SEC_MOFF];
    uint32_t i, nF = v->nF;
    acc_zero(acc, 3 * nF);
#if defined(SN_K_MASS_FF)
    if (!mask) { sn_k_mass_ff(rp, cols, md, mo, y, acc, nF); return; } /* the M4's and x86-64 AVX2's loops (sn_kernels.h) */
#endif
    for (i = 0; i < nF; i++) {
        uint32_t e = sn_rd_u32(rp + 4 * i), end = sn_rd_u32(rp + 4 * i + 4);
        sn_acc l[3] = {0, 0, 0};
        if (mask && !mask[i]) continue;
        sca_row(l, rd_real(md, i), y + 3 * i);
        for (; e < end; e++) {
            uint32_t j = sn_rd_u16(cols + 2 * e);
            sn_q m;
            if (j >= nF) break;
            if (mask && !mask[j]) continue;
            m = rd_real(mo, e);
            sca_row(l, m, y + 3 * j);
            sca_mac(acc + 3 * j, m, y + 3 * i);
        }
        row_done(acc + 3 * i, l);
    }
}


/* acc += R S^_e R^T d for one cell over its free corners only (skeleton
 * corners carry no unknown: their terms are exact zeros; with mask, only the
 * corners with mask[a] != 0, the blended mode's region): the free-corner
 * product, 9 f^2 MA (KERNELS.md "SIMD kernels"). */
SN_INLINE void cell_stiff(const sn_ihdr *h, const unsigned char *K, const unsigned char *cl, const sn_q *R, const uint8_t *mask,
                          const sn_q *d, sn_acc *acc, uint32_t *sat) {
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t k, vi[8], nf = 0, nF = h->v.nF;
    sn_q u[24];
    sn_acc l[24];
    uint8_t fc[8];
#if defined(SN_K_ROTM) /* x86-64 AVX2: R permuted once for the corners (sn_kernels_rot.h) */
    sn_k_rotm rm;
    sn_k_rotm_ld(&rm, R);
#define SN_ROT_T(v, o) sn_k_rot_t_m(&rm, (v), (o), sat)
#define SN_OUT_ROT_ACC(x, l, sh) sn_k_out_rot_acc_m((x), &rm, (l), (sh), sat)
#else
#define SN_ROT_T(v, o) sn_k_rot_t(R, (v), (o), sat)
#define SN_OUT_ROT_ACC(x, l, sh) sn_k_out_rot_acc((x), R, (l), (sh), sat)
#endif
#if defined(SN_K_CELL_STIFF) /* x86-64 float: the loops below in one kernel (sn_kernels.h) */
    if (!mask) {
        (void)kk; (void)u; (void)l; (void)fc; (void)vi; (void)nf; (void)k;
        sn_k_cell_stiff(K, cl, nF, R, d, acc, sat);
        return;
    }
#endif
#if defined(SN_K_FREE8) /* x86-64 float: the free corners' bits (sn_kernels_rot.h) */
    if (!mask) {
        uint32_t fm;
        for (fm = sn_k_free8(cl, nF); fm; fm &= fm - 1u) {
            const uint32_t a = sn_rd_u16(cl + 2 * (k = (uint32_t)__builtin_ctz(fm)));
            SN_ROT_T(d + 3 * a, u + 3 * nf);
            fc[nf] = (uint8_t)k;
            vi[nf++] = a;
        }
    } else
#endif
    for (k = 0; k < 8; k++) {
        uint32_t a = sn_rd_u16(cl + 2 * k);
        if (a >= nF || (mask && !mask[a])) continue;
        SN_ROT_T(d + 3 * a, u + 3 * nf);
        fc[nf] = (uint8_t)k;
        vi[nf++] = a;
    }
    if (nf == 0) return;
    sn_k_cell_mul(K, fc, nf, u, l);
    for (k = 0; k < nf; k++) {
        uint32_t a = vi[k];
        SN_OUT_ROT_ACC(acc + 3 * a, l + 3 * k, h->v.frac_S - SN_KREL(kk[a])); /* R round(l) */
    }
#undef SN_ROT_T
#undef SN_OUT_ROT_ACC
}

void sn_cell_stiff_acc(const sn_ihdr *h, const unsigned char *K, const unsigned char *cl, const sn_q *R, const uint8_t *mask,
                       const sn_q *d, sn_acc *acc, uint32_t *sat) {
    cell_stiff(h, K, cl, R, mask, d, acc, sat);
}

/* cell_stiff for a cell with active details (the mat-vec; no mask): the free
 * corners' product plus the details' columns (sn_detail_cell_mul, lc at the
 * corners' scale) before the rounding, and the details' rows into sacc. d's
 * seat rows follow its free rows. */
SN_NOINLINE void cell_stiff_det(const sn_ihdr *h, const sn_dstate *dt, uint32_t e, uint32_t on, const unsigned char *K,
                           const unsigned char *cl, const sn_q *R, const sn_q *d, sn_acc *acc, sn_acc *sacc, uint32_t *sat) {
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t k, c, vi[8], nf = 0, nF = h->v.nF, sj[SN_CUT_MAXX];
    sn_q u[24], uf[24], yd[SN_CUT_MAXX][3];
    sn_acc l[24], lc[24], ldd[3 * SN_CUT_MAXX];
    uint8_t fc[8];
    for (k = 0; k < 24; k++) uf[k] = 0, lc[k] = 0;
    for (k = 0; k < 8; k++) {
        uint32_t a = sn_rd_u16(cl + 2 * k);
        if (a >= nF) continue;
        sn_k_rot_t(R, d + 3 * a, u + 3 * nf, sat);
        for (c = 0; c < 3; c++) uf[3 * k + c] = u[3 * nf + c];
        fc[nf] = (uint8_t)k;
        vi[nf++] = a;
    }
    detail_ops(&h->v, dt, e, R, d + 3 * nF, sj, yd, sat);
    sn_detail_cell_mul(&h->v, e, on, uf, NULL, (const sn_q(*)[3])yd, lc, ldd, sat);
    detail_rows_out(h, dt, on, sj, R, ldd, sacc, sat);
    if (nf == 0) return;
    sn_k_cell_mul(K, fc, nf, u, l);
    for (k = 0; k < nf; k++) {
        uint32_t a = vi[k];
        for (c = 0; c < 3; c++) l[3 * k + c] += lc[3 * fc[k] + c];
        sn_k_out_rot_acc(acc + 3 * a, R, l + 3 * k, h->v.frac_S - SN_KREL(kk[a]), sat);
    }
}

/* The details' share of the mat-vec's mass pass: corner rows' detail columns
 * into acc (free corners), the seats' rows into sacc (zeroed here). */
SN_NOINLINE void detail_mass_mv(const sn_ihdr *h, const sn_dstate *dt, const sn_q *d, sn_acc *acc, sn_acc *sacc, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *cells = v->sec[SN_SEC_CELLS];
    const uint32_t *ons = DT(dt, o_on, const uint32_t);
    const sn_q I[9] = {SN_ONE_ROT, 0, 0, 0, SN_ONE_ROT, 0, 0, 0, SN_ONE_ROT};
    uint32_t e, k, c, j, nF = v->nF;
    acc_zero(sacc, 3 * dt->n);
    for (e = 0; e < v->nC; e++) {
        const unsigned char *cl = cells + (size_t)e * SN_ELEM_CELLS;
        uint32_t on = ons[e], sj[SN_CUT_MAXX];
        sn_q yc[24], yd[SN_CUT_MAXX][3];
        sn_acc mc[24], md[3 * SN_CUT_MAXX];
        if (!on) continue;
        for (k = 0; k < 8; k++) {
            uint32_t a = sn_rd_u16(cl + 2 * k);
            for (c = 0; c < 3; c++) yc[3 * k + c] = a < nF ? d[3 * a + c] : 0;
        }
        for (k = 0; k < 24; k++) mc[k] = 0;
        detail_ops(v, dt, e, I, d + 3 * nF, sj, yd, sat);
        sn_detail_cell_mass(v, e, on, yc, NULL, (const sn_q(*)[3])yd, mc, md);
        for (k = 0; k < 8; k++) {
            uint32_t a = sn_rd_u16(cl + 2 * k);
            if (a < nF) corner_add(acc + 3 * a, mc + 3 * k, sat);
        }
        for (j = 0; on >> j; j++)
            if (on >> j & 1u) seat_add(sacc + 3 * sj[j], md + 3 * j, sat);
    }
}

/* q = A d = (1+a1) M^ d + (1+b1) sum_e R_e S^_e R_e^T d  (free rows).
 * The cell product runs over the cell's free corners only (9 f^2 multiply-adds
 * for f free corners instead of 576): a skeleton corner's operand is zero
 * and its rows are dropped, so the sums are the full product's. The list is
 * read from the blob's corner indices (fixed per blob: constant cost). */
static void matvec(sn_ihdr *h, const sn_dstate *dt, const sn_q *d, sn_q *q, const uint8_t *mask, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *cells = v->sec[SN_SEC_CELLS], *K = v->sec[SN_SEC_CELLK];
    const sn_q *cR = CARR(h, o_cR, sn_q);
    sn_acc *acc = WARR(h, o_acc, sn_acc);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t e, i, nF = v->nF;
    sn_q cm = (sn_q)(ONE_COEF + v->a1), ck = (sn_q)(ONE_COEF + v->b1);
    sn_acc *sacc = dt ? DT(dt, o_acc, sn_acc) : NULL;
    const uint32_t *ons = dt ? DT(dt, o_on, const uint32_t) : NULL;
    acc_zero(acc, 3 * nF);
    if (dt) acc_zero(sacc, 3 * dt->n);
    for (e = 0; e < v->nC; e++, K += SN_K_CELL_BYTES) {
        if (dt && ons[e]) cell_stiff_det(h, dt, e, ons[e], K, cells + (size_t)e * SN_ELEM_CELLS, cR + 9 * e, d, acc, sacc, sat);
#if defined(SN_K_CELL_STIFF) /* x86-64 float: cell_stiff's kernel called here (sn_kernels.h) */
        else if (!mask) sn_k_cell_stiff(K, cells + (size_t)e * SN_ELEM_CELLS, nF, cR + 9 * e, d, acc, sat);
#endif
        else cell_stiff(h, K, cells + (size_t)e * SN_ELEM_CELLS, cR + 9 * e, mask, d, acc, sat);
    }
    for (i = 0; i < 3 * nF; i++)
        SN_RANGE(SN_WITHIN(acc[i], 62), "vertex accumulator beyond 8 rotated cell rows", acc[i]);
    sn_k_outv(q, acc, 3 * nF, SN_Q_ROT, sat); /* sn_kernels_rot.h */
    if (dt) sn_k_outv(q + 3 * nF, sacc, 3 * dt->n, SN_Q_ROT, sat);
    pass_M_ff(h, d, mask, acc);
    if (dt) detail_mass_mv(h, dt, d, acc, sacc, sat);
    sn_k_mix(q, acc, kk, 3 * nF, v->frac_M, ck, cm, sat); /* q = (1+b1) q + (1+a1) M^ d */
    if (dt) sn_k_mix(q + 3 * nF, sacc, DT(dt, o_kk, const uint8_t) + nF, 3 * dt->n, v->frac_M, ck, cm, sat);
}

/* ---- CG scalars ---- */
#if defined(SN_FLOAT)
typedef struct { float m; } sn_dotv;
static sn_dotv dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n) {
    sn_dotv r;
    uint32_t i;
    float s;
    (void)kk;
#if defined(SN_K_FRHS)
    (void)i;
    s = sn_k_fdot(a, b, n); /* the same sum (sn_kernels.h) */
#else
    /* entry i into partial sum i mod 8, then a fixed tree: every path's
     * floats (SIMD lanes: sn_k_fdot), and no chain of n dependent adds (one
     * sum in i order was ~0.3 us a dot on cow_fem: KERNELS.md "Float step,
     * round 4") */
    float p[8] = {0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f};
    for (i = 0; i < n; i++) p[i & 7] += a[i] * b[i];
    s = ((p[0] + p[1]) + (p[2] + p[3])) + ((p[4] + p[5]) + (p[6] + p[7]));
#endif
    r.m = s;
    return r;
}
/* num/den, 0 when den <= 0 or num <= 0 (constant cost, no convergence branch) */
static float ratio(sn_dotv num, sn_dotv den, uint32_t *clamps) {
    (void)clamps;
    return (den.m > 0.0f && num.m > 0.0f) ? num.m / den.m : 0.0f;
}
#define SN_Q_SCAL 0
#else
/* Block floating point dot product: value = m * 2^e. */
typedef struct { int64_t m; int e; } sn_dotv;
#define SN_Q_SCAL 28 /* alpha, beta in Q28 */

/* a force-like (Q(19+k_i) per vertex), b velocity-like (Q22): sum of a.b in
 * Q41, times 2^e (sn_kernels.h sn_k_dot: the scalar reference or the
 * build's SIMD path, the same integers). */
static sn_dotv dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n) {
    sn_dotv r;
    r.m = sn_k_dot(a, b, kk, n, &r.e);
    SN_RANGE(SN_WITHIN(r.m, 62), "block-floating dot product beyond 2^62", r.m);
    return r;
}
/* num/den in Q28, 0 when den <= 0 or num <= 0 (converged: not a clamp);
 * saturates at INT32_MAX (a ratio beyond 8), counted in *clamps. That
 * happens in healthy runs (beta = rz'/rz when rz is at the rounding floor
 * of a converged step), so it is its own statistic, not a saturation. */
static int32_t ratio(sn_dotv num, sn_dotv den, uint32_t *clamps) {
    int e, bn, bd;
    uint64_t n, d, q;
    if (den.m <= 0 || num.m <= 0) return 0;
    n = (uint64_t)num.m;
    d = (uint64_t)den.m;
    e = SN_Q_SCAL + num.e - den.e;
    /* normalize den to [2^30, 2^31) and num to [2^61, 2^62) */
    bd = bitlen64(d); /* den = d * 2^(bd-31): a larger true den lowers the exponent */
    if (bd > 31) { d >>= (bd - 31); e -= bd - 31; } else { d <<= (31 - bd); e += 31 - bd; }
    bn = bitlen64(n);
    if (bn > 62) { n >>= (bn - 62); e += bn - 62; } else { n <<= (62 - bn); e -= 62 - bn; }
    q = n / d; /* in [2^30, 2^32) */
    if (e > 0) q = (uint64_t)INT32_MAX + 1u;
    else if (e < -40) q = 0;
    else if (e < 0) q = (q + ((uint64_t)1 << (-e - 1))) >> -e;
    if (q > (uint64_t)INT32_MAX) { (*clamps)++; return INT32_MAX; }
    return (int32_t)q;
}
#endif

/* The CG's rounding floor: r.z at or below SN_CG_FLOOR units of Q41 (a
 * Q19 force LSB times a Q22 velocity LSB) per unknown is noise. From there
 * on alpha = rz/dq and beta = rz'/rz are ratios of rounding errors: beta
 * sits at 1, d = z + d grows by the noise every iteration and x drifts
 * along it (cow, 32 iterations: 1.7e-2 off the reference, 16x the error at
 * 8). So a step at the floor takes alpha = beta = 0 for its remaining
 * iterations: x and r stay, and so does the floor. The iterations still
 * run: the cost stays the baked count's. Float: 0 only when r.z <= 0. */
#if defined(SN_FLOAT)
static int at_floor(sn_dotv rz, uint32_t n) { (void)n; return rz.m <= 0.0f; }
#else
#ifndef SN_CG_FLOOR
#define SN_CG_FLOOR 1
#endif
static int at_floor(sn_dotv rz, uint32_t n) {
    /* rz = m 2^e with m > 0, e >= 0 (sn_k_dot); SN_CG_FLOOR n fits 64 bits */
    if (rz.m <= 0) return 1;
    if (rz.e >= 40) return 0;
    return (uint64_t)rz.m <= (((uint64_t)SN_CG_FLOOR * n) >> rz.e);
}
#endif

/* y += s * x (s in Q28 fixed) over n values */
static void axpy(sn_q *y, sn_q s, const sn_q *x, uint32_t n, uint32_t *sat) {
    sn_k_axpy(y, y, s, x, n, SN_Q_SCAL, sat); /* sn_kernels.h: reference or SIMD */
}


/* Steps 5-7: right-hand side, PCG warm-started from the previous step's
 * solution with a fixed iteration count, update. */
void sn_solve(sn_ihdr *h, uint32_t *sat) {
    const sn_view *v = &h->v;
    uint32_t it, i, n3 = 3 * v->nF;
    sn_q *x = ARR(h, o_x, sn_q), *r = WARR(h, o_r, sn_q), *d = ARR(h, o_d, sn_q);
    /* z shares q's storage: q is dead from r -= alpha q to the next mat-vec,
     * z from d = z + beta d to the next preconditioner call */
    sn_q *q = ARR(h, o_q, sn_q), *z = q;
    sn_q *pos = ARR(h, o_pos, sn_q), *vel = ARR(h, o_vel, sn_q);
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    sn_dotv rz;
    uint32_t clamps = 0, rows, iters = h->iterations;
    int fold;
    uint32_t cold;
    const uint8_t *mask = sn_adapt_mask(h); /* level 1's inactive detail vertices: their dv is the coarse field's */
    sn_dstate *dt = sn_detail_live(h); /* details on the cut level: the CG over nF + n rows, the seats after the free ones */
    sn_q *xf = x;

    if (dt) {
        r = DT(dt, o_r, sn_q);
        d = DT(dt, o_d, sn_q);
        q = z = DT(dt, o_q, sn_q);
        memcpy(DT(dt, o_kk, uint8_t), kk, v->nF); /* the free rows' k (the level's table), the seats' after */
        kk = DT(dt, o_kk, const uint8_t);
        mask = NULL; /* adaptation is level 1's, details the cut level's */
    }
    /* the initial residual b - A x folded into the right-hand side (rhs_x0)
     * when SN_FOLD (float) and neither level 1's adaptation nor details are on */
    fold = SN_FOLD && !mask && !dt;
    cold = *sat;
    rhs_x0(h, r, 1, fold ? x : NULL, sat);
    cold = fold && *sat != cold; /* a clamp in the folded rhs: its residual is not b - A x0 (below) */
    /* constraint rows: collected, factorized, the warm start moved onto them
     * (sn_constraint.c); folded, the x before the move into d's storage (dead
     * until the PCG) */
    rows = sn_constrain_begin(h, x, fold ? d : NULL, sat);
    if (dt) { /* the warm start: the free rows' x, then the seats' own */
        x = DT(dt, o_x, sn_q);
        memcpy(x, xf, n3 * sizeof(sn_q));
        n3 += 3 * dt->n;
    }
    if (rows) mask = NULL; /* rows may hold an inactive vertex: this step solves them all (sn_adapt.c projects after) */
    if (mask) sn_adapt_expand(h, mask, x, sat); /* the warm start in the reduced space */
    if (mask) iters = sn_adapt_iterations(h); /* the reduced rows' preconditioner is the lattice's: more iterations */
    if (dt) iters = sn_detail_iterations(h); /* the seats' block Jacobi: more iterations (sn_detail.h) */
    /* PCG, warm-started from the previous step's solution, fixed iterations;
     * with rows, residuals and preconditioned residuals are projected onto
     * the free directions (Baraff-Witkin filtered PCG) */
    if (!fold) {
        matvec(h, dt, x, q, NULL, sat);
        for (i = 0; i < n3; i++) r[i] = sn_add(r[i], -q[i], sat);
    } else if (rows) { /* the rows moved x: r -= A (x - x before), the mat-vec the fold saved otherwise */
        for (i = 0; i < n3; i++) d[i] = sn_add(x[i], -d[i], sat);
        matvec(h, NULL, d, q, NULL, sat);
        for (i = 0; i < n3; i++) r[i] = sn_add(r[i], -q[i], sat);
    }
    if (mask) { /* refine estimates from the inactive rows, then r = P^T (b - A P x) */
        sn_adapt_estimate(h, mask, r, q, x, sat);
        sn_adapt_restrict(h, mask, r, sat);
    }
    if (rows) sn_rows_filter(h, r, 1, sat);
    if (mask) sn_precond_mask(h, mask, 0, sn_adapt_scales(h), r, z, sat); /* the active set's block, scaled: z = 0 at inactive rows */
    else sn_precond(h, r, z, sat); /* sn_precond.c */
    if (dt) sn_detail_precond(h, dt, r + 3 * v->nF, z + 3 * v->nF, sat); /* the seats: block Jacobi (sn_detail_step.c) */
    if (rows) sn_rows_filter(h, z, 0, sat);
    memcpy(d, z, n3 * sizeof(sn_q));
    rz = dot(r, z, kk, n3);
    for (it = 0; it < iters; it++) {
        sn_dotv dq, rz1;
        sn_q alpha, beta, nalpha;
        int flat;
        if (mask) { /* q = P^T A P d: d expanded for the product, then 0 again off the active set */
            sn_adapt_expand(h, mask, d, sat);
            matvec(h, NULL, d, q, NULL, sat);
            for (i = 0; i < n3; i++) d[i] = mask[i / 3] ? d[i] : 0;
            sn_adapt_restrict(h, mask, q, sat);
        } else matvec(h, dt, d, q, NULL, sat);
        dq = dot(q, d, kk, n3);
        flat = at_floor(rz, n3);
        alpha = flat ? 0 : ratio(rz, dq, &clamps);
        nalpha = (sn_q)-alpha;
        axpy(x, alpha, d, n3, sat);
        /* the last iteration's r, z, rz and d are never read: x is the
         * answer (a fixed count, not a data-dependent exit) */
        if (it + 1 == iters) break;
        axpy(r, nalpha, q, n3, sat);
        if (rows) sn_rows_filter(h, r, 1, sat);
        if (mask) sn_precond_mask(h, mask, 0, sn_adapt_scales(h), r, z, sat);
        else sn_precond(h, r, z, sat); /* sn_precond.c */
        if (dt) sn_detail_precond(h, dt, r + 3 * v->nF, z + 3 * v->nF, sat);
        if (rows) sn_rows_filter(h, z, 0, sat);
        rz1 = dot(r, z, kk, n3);
        beta = flat ? 0 : ratio(rz1, rz, &clamps);
        sn_k_axpy(d, z, beta, d, n3, SN_Q_SCAL, sat); /* d = z + beta d */
        rz = rz1;
    }
    if (mask) { /* the estimates out of x, then dv = P x: the inactive vertices move with the coarse field */
        sn_adapt_keys(h, mask, x);
        sn_adapt_expand(h, mask, x, sat);
    }
    if (rows) { /* the contacts' corners within their yield bound (sn_contact.c); the CG's rounding off the rows
                 * again; the second pass, in finer units, takes the first's rounding */
        sn_contact_yield(h, x, sat);
        sn_rows_fix(h, x, sat);
        sn_rows_fix(h, x, sat);
    }
    if (dt) { /* the seats as pos / vel: v += dv, c += v; the free rows' x back */
        sn_q *dc = DT(dt, o_coef, sn_q), *dv = DT(dt, o_vel, sn_q);
        n3 = 3 * v->nF;
        for (i = 0; i < 3 * dt->n; i++) {
            dv[i] = sn_add(dv[i], x[n3 + i], sat);
            dc[i] = sn_add(dc[i], dv[i], sat);
        }
        memcpy(xf, x, n3 * sizeof(sn_q));
        x = xf;
    }
    /* v += dv, p += h v  (velocities are per step: h folded in) */
    for (i = 0; i < n3; i++) {
        vel[i] = sn_add(vel[i], x[i], sat);
        pos[i] = sn_add(pos[i], vel[i], sat);
    }
    /* The folded rhs clamped (a torn state: the state range's guard or a
     * cell row beyond it, where b's terms and A x0's are not kept apart): the
     * next step starts cold, x0 = 0, so its folded residual is b itself
     * whatever clamps (NUMERICS.md "The initial residual folded in"). One
     * memset of 12 nF bytes in such a step, like a clamp's branch (an
     * unconditional select cost every step 2-3 k instructions on cow_fem). */
    if (cold) memset(x, 0, n3 * sizeof(sn_q));
    h->cg_clamps = sn_count(h->cg_clamps, clamps);
}

#if SN_FOLD
void sn_fold_rhs(sn_ihdr *h, sn_q *r, const sn_q *x0, uint32_t *sat) { rhs_x0(h, r, 1, x0, sat); }
void sn_fold_matvec(sn_ihdr *h, const sn_q *d, sn_q *q, uint32_t *sat) { matvec(h, NULL, d, q, NULL, sat); }
#endif

/* ---- the CG arithmetic of the blended mode (sn_blended.h): the same functions ---- */
sn_cgdot sn_cg_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n) {
    sn_dotv d = dot(a, b, kk, n);
    sn_cgdot o;
    o.m = d.m;
#if defined(SN_FLOAT)
    o.e = 0;
#else
    o.e = d.e;
#endif
    return o;
}
static sn_dotv dotv_of(sn_cgdot d) { /* the blended mode's dot product as this file's */
    sn_dotv o;
    o.m = d.m;
#if !defined(SN_FLOAT)
    o.e = d.e;
#endif
    return o;
}
sn_q sn_cg_ratio(sn_cgdot num, sn_cgdot den, uint32_t *clamps) { return ratio(dotv_of(num), dotv_of(den), clamps); }
int sn_cg_flat(sn_cgdot rz, uint32_t n) { return at_floor(dotv_of(rz), n); }
void sn_cg_axpy(sn_q *y, sn_q s, const sn_q *x, uint32_t n, uint32_t *sat) { axpy(y, s, x, n, sat); }
void sn_cg_dir(sn_q *d, const sn_q *z, sn_q beta, uint32_t n, uint32_t *sat) {
    sn_k_axpy(d, z, beta, d, n, SN_Q_SCAL, sat);
}
