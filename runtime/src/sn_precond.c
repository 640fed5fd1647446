/* sn_precond.c -- step 6, the PCG preconditioner z = C r (NUMERICS.md
 * "Preconditioner"). Without an ICHOL section: rotated block Jacobi,
 * z_i = R_i P_i R_i^T r_i (PRECOND = the inverse diagonal blocks of A0).
 * With it: the rest-frame IC(0) of A0 = (1+a1) M^ + (1+b1) sum_e S^_e as a
 * block LDL^T, A0 ~ (I + L^) D (I + L^)^T, rotated per vertex
 * (runtime/SOLVER_STUDY.md §1):
 *   t = R^T r;  y = (I + L^)^-1 t  (forward, by columns);  w = D^-1 y;
 *   z' = (I + L^)^-T w  (backward, by rows);  z = R z'.
 * ICHOL stores U_ji = L^_ij^T (j < i) row-wise in the mass pattern's
 * ROWPTR/COLS order (free columns come first in a row: skeleton ones are
 * skipped), entries m 2^-frac with an int16 mantissa and one frac per block.
 *
 * Fixed point: y_i is a force, Q(19 + k_i); a block's 3-term row
 * (<= 3 (2^15 - 1) 2^28 < 2^44.6) is rounded once into the target vertex's
 * format (shift frac + k_j - k_i in [-15, 62]; below 0 it is scaled up by
 * at most 2^15 and clamped, counted), summed in int64 with the vertex's other
 * rows (the instance's accumulators, scratch here) and clamped once (counted)
 * into y_i. w, z' are Q22 like block Jacobi's z; the backward block rows
 * round by frac into Q22 each, summed in int64, clamped once per vertex.
 * Unmasked applies run the per-vertex passes inside the two sweeps
 * (ic_fused, every path); masked or scaled ones the five passes. */
#include "sn_instance.h"
#include "sn_kernels_rot.h" /* the frame rotations */
#include "sn_kernels_ic.h" /* the block products: portable reference or the build's SIMD path */


/* The fused sweeps' vertex steps (ic_fused): y_j = sn_out(R_j^T r_j -
 * acc_j); z'_j = sn_out(sn_out(D_j^-1 y_j, sh) - l) to zq_j and z_j = R_j
 * z'_j (z_j holds y_j). The M4's in Thumb-2 (sn_kernels_m4_ic.c) where its
 * shift allows, the same values and counts. */
SN_INLINE void ic_y(const sn_q *Rj, const sn_q *rj, const sn_acc *aj, sn_q *yj, uint32_t *sat) {
#if defined(SN_K_IC_VTX)
    sn_m4_icf_y(Rj, rj, aj, yj, sat);
#else
    sn_k_rot_t(Rj, rj, yj, sat);
    sn_k_sub3a(yj, aj, sat);
#endif
}
SN_INLINE void ic_z(const unsigned char *Pj, sn_q *zj, const sn_acc *l, sn_q *zqj, const sn_q *Rj, int sh, uint32_t *sat) {
    sn_q w[3];
#if defined(SN_K_IC_VTX)
    if ((uint32_t)(sh - 1) < 31u) {
        sn_m4_icb_z(Pj, zj, l, zqj, Rj, sh, sat);
        return;
    }
#endif
    sn_k_sym_out(Pj, zj, w, sh, sat);
    sn_k_sub3a(w, l, sat);
    memcpy(zqj, w, sizeof w); /* memcpy: zq may be the accumulators' bytes (ic_fused) */
    sn_k_rot(Rj, w, zj, sat);
}

/* y = (I + L^)^-1 y in place: for j ascending, y_i -= U_ji^T y_j (i > j).
 * The rounded block rows bound for y_i are summed in acc (int64: at most
 * SN_MAX_ROW_BLOCKS of them, each < 2^44.6 or clamped to 2^28: < 2^49.3) and
 * y_i is formed, clamped once, when the sweep reaches i. With R (the fused
 * sweep, ic_fused) y_j enters as t_j = R_j^T r_j, formed there; without, y
 * holds t already. Returns the ICHOL count (the blocks it read). */
/* ic_forward and ic_backward always inlined: at the five passes' call R is
 * NULL and its branches fold away (as a call, the masked applies of the
 * M4's adaptation runs took +0.6%) */
#if defined(__GNUC__)
#define SN_IC_INLINE __attribute__((always_inline)) SN_INLINE
#else
#define SN_IC_INLINE SN_INLINE
#endif
SN_IC_INLINE uint32_t ic_forward(const sn_view *v, const uint8_t *kk, const sn_q *R, size_t rs, const sn_q *r, sn_q *y, sn_acc *acc,
                           uint32_t *sat) {
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *L = v->sec[SN_SEC_ICHOL];
    uint32_t j, e, n = 0, nF = v->nF;
#if defined(SN_K_IC_FWD_COL)
    struct sn_m4_icc c;
    sn_k_ic_fwd_init(&c, kk, acc, nF);
#endif
#if defined(SN_K_ZERO) /* the M4's and x86-64 AVX2's (sn_kernels.h) */
    sn_k_zero(acc, 3 * nF);
#else
    for (j = 0; j < 3 * nF; j++) acc[j] = 0;
#endif
    for (j = 0; j < nF; j++) {
        uint32_t end = sn_rd_u32(rp + 4 * j + 4);
        sn_q *yj = y + 3 * j;
        const uint32_t n0 = n;
        if (R) ic_y(R + rs * j, r + 3 * j, acc + 3 * j, yj, sat); /* yj = sn_out(t_j - acc_j) */
        else sn_k_sub3a(yj, acc + 3 * j, sat); /* yj = sn_out(yj - acc_j) */
#if defined(SN_K_IC_FWD_COL) /* the M4's loop (sn_kernels_ic.h) */
        e = sn_rd_u32(rp + 4 * j);
        if (e < end)
            n += sn_k_ic_fwd_col(&c, L + (size_t)n * SN_ELEM_ICHOL, cols + 2 * e, cols + 2 * end, yj, kk[j], sat);
#elif defined(SN_K_IC_FWD_RUN) /* x86-64 AVX2's loop (sn_kernels_ic.h) */
        e = sn_rd_u32(rp + 4 * j);
        n += sn_k_ic_fwd_run(L + (size_t)n * SN_ELEM_ICHOL, cols + 2 * e, cols + 2 * end, yj, kk[j], kk, nF, acc, sat);
#else
        for (e = sn_rd_u32(rp + 4 * j); e < end; e++, n++) {
            uint32_t i = sn_rd_u16(cols + 2 * e);
            const unsigned char *blk = L + (size_t)n * SN_ELEM_ICHOL;
            int s;
            if (i >= nF) break; /* skeleton columns: not in ICHOL */
            s = blk[18];
#if !defined(SN_FLOAT)
            s += (int)kk[j] - (int)kk[i]; /* Q(19 + k_j + frac) -> Q(19 + k_i) */
#endif
            sn_k_ic_col(blk, yj, s, acc + 3 * i, sat); /* acc_i += round(U_ji^T y_j) */
        }
#endif
        acc[3 * j] = (sn_acc)(n - n0); /* acc_j is consumed: row j's free column count, for ic_backward */
    }
    (void)kk;
    return n;
}

/* z = (I + L^)^-T z in place: for j descending, z_j -= sum_i U_ji z_i (Q22;
 * each block row rounded by frac, < 2^44.6; their sum < 2^49.3). cnt[3 j]:
 * row j's free column count (ic_forward leaves it in its accumulators).
 * Without R, z holds w = D^-1 y and becomes z'. With R (ic_fused), z holds
 * y: w_j = D^-1 y_j is formed where the sweep reaches j, z'_j kept in zq
 * (the rows above read it there) and z_j = R_j z'_j written. */
SN_IC_INLINE void ic_backward(const sn_view *v, uint32_t n, const sn_acc *cnt, const uint8_t *kk, const sn_q *R, size_t rs, sn_q *zq,
                        sn_q *z, uint32_t *sat) {
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *L = v->sec[SN_SEC_ICHOL], *P = v->sec[SN_SEC_PRECOND];
    uint32_t j = v->nF;
    while (j-- > 0) {
        uint32_t b = sn_rd_u32(rp + 4 * j), f = b + (uint32_t)cnt[3 * j]; /* free columns first */
        sn_acc l[4];
        n -= f - b;
        sn_k_ic_bwd_row(L + (size_t)n * SN_ELEM_ICHOL, cols + 2 * b, f - b, zq, l, sat); /* l = sum_i round(U_ji z'_i) */
        if (R) ic_z(P + (size_t)j * 6 * SN_REAL_BYTES, z + 3 * j, l, zq + 3 * j, R + rs * j, v->frac_P + SN_KREL(kk[j]), sat);
        else sn_k_sub3a(z + 3 * j, l, sat);
    }
}

#if defined(SN_KERNELS_AVX2)
/* x86-64 round 2 (AVX2, fixed; KERNELS.md "x86-64 solve, round 2"): IC(0)
 * without mask or scale, the per-vertex passes fused into the sweeps, the
 * same integers and clamp counts as precond_core's passes: the forward
 * sweep forms t_j = R_j^T r_j where it reaches j (y_j = sn_out(t_j - acc_j)),
 * the backward sweep w_j = D^-1 y_j and z'_j = sn_out(w_j - l_j) where it
 * reaches j, keeps z'_j in acc_j (int64; row j's count, read first, is its
 * last use) for the rows above, and writes z_j = R_j z'_j. One pass over
 * the vertices each way instead of five. */
static void ic_fused(const sn_view *v, const uint8_t *kk, const sn_q *R, size_t rs, const sn_q *r, sn_q *z, sn_acc *acc,
                     uint32_t *sat) {
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *L = v->sec[SN_SEC_ICHOL], *P = v->sec[SN_SEC_PRECOND];
    const uint32_t nF = v->nF;
    uint32_t j, n = 0;
    sn_k_zero(acc, 3 * nF);
    for (j = 0; j < nF; j++) {
        const uint32_t e = sn_rd_u32(rp + 4 * j), end = sn_rd_u32(rp + 4 * j + 4);
        const __m256i y = sn_k_clamp4(_mm256_sub_epi64(sn_k_rot_t4(R + rs * j, r + 3 * j, sat), sn_k_ld3q(acc + 3 * j)), sat);
        uint32_t m;
        sn_k_st3d(z + 3 * j, y);
        m = sn_k_ic_fwd_ops(L + (size_t)n * SN_ELEM_ICHOL, cols + 2 * e, cols + 2 * end, _mm256_permute4x64_epi64(y, 0x00),
                            _mm256_permute4x64_epi64(y, 0x55), _mm256_permute4x64_epi64(y, 0xAA), z + 3 * j, kk[j], kk, nF, acc, sat);
        acc[3 * j] = (sn_acc)m; /* acc_j is consumed: row j's free column count */
        n += m;
    }
    j = nF;
    while (j-- > 0) {
        const uint32_t m = (uint32_t)acc[3 * j], b = sn_rd_u32(rp + 4 * j);
        __m256i w = sn_k_sym_out4(P + (size_t)j * 6 * SN_REAL_BYTES, z + 3 * j, v->frac_P + SN_KREL(kk[j]), sat);
        n -= m;
        w = sn_k_clamp4(_mm256_sub_epi64(w, sn_k_ic_bwd_rowq(L + (size_t)n * SN_ELEM_ICHOL, cols + 2 * b, m, acc)), sat);
        sn_k_st3q(acc + 3 * j, w); /* z'_j, for the rows above */
        sn_k_rot4(R + rs * j, w, z + 3 * j, sat);
    }
}
#elif defined(SN_KERNELS_FAVX2)
/* The float flavour's (AVX2): the same passes fused, each value the
 * reference's floats (sn_kernels_fsimd.h: the operations in its order). */
/* sn_out(sn_out(a) - b) (x86-64 round 4): when neither a nor a - b has a lane
 * to clamp, sn_out leaves both and the value is a - b, with no count; one
 * test for the two (otherwise the two fv_out3, the reference's order) */
SN_INLINE sn_fv ic_out_sub(sn_fv a, sn_fv b, uint32_t *sat) {
    const sn_fv d = FV_SUB(a, b);
    if (!(_mm_movemask_ps(_mm_or_ps(FV_BAD(a), FV_BAD(d))) & 7)) return d;
    return fv_out3(FV_SUB(fv_out3(a, sat), b), sat);
}
/* the backward vertex step: z'_j = sn_out(sn_out(w) - l) to zq_j, z_j =
 * sn_out(R z'_j) (c: R's columns); no lane to clamp in w, w - l and R (w - l):
 * one test, their values; otherwise the three fv_out3 in order */
SN_INLINE sn_fv ic_zstep(sn_fv w, sn_fv l, const sn_fv c[3], sn_acc *zqj, sn_q *zj, uint32_t *sat) {
    sn_fv d = FV_SUB(w, l), z = FV_MAC3(c, SN_K_LANE(d, 0), SN_K_LANE(d, 1), SN_K_LANE(d, 2));
    if (_mm_movemask_ps(_mm_or_ps(_mm_or_ps(FV_BAD(w), FV_BAD(d)), FV_BAD(z))) & 7) {
        d = fv_out3(FV_SUB(fv_out3(w, sat), l), sat);
        z = fv_out3(FV_MAC3(c, SN_K_LANE(d, 0), SN_K_LANE(d, 1), SN_K_LANE(d, 2)), sat);
    }
    fv_st3(zqj, d); /* z'_j, for the rows above */
    fv_st3(zj, z);
    return d;
}
static void ic_fused(const sn_view *v, const uint8_t *kk, const sn_q *R, size_t rs, const sn_q *r, sn_q *z, sn_acc *acc,
                     uint32_t *sat) {
    const unsigned char *rp = v->sec[SN_SEC_ROWPTR], *cols = v->sec[SN_SEC_COLS];
    const unsigned char *L = v->sec[SN_SEC_ICHOL], *P = v->sec[SN_SEC_PRECOND];
    const uint32_t nF = v->nF;
    uint32_t j, n = 0;
    sn_fv nx = FV_SET1(0.0f); /* acc_j: column j - 1 read it (and added to it last, if row j is in it) */
    (void)kk;
    for (j = 0; j < 3 * nF; j++) acc[j] = 0;
    for (j = 0; j < nF; j++) {
        const uint32_t e = sn_rd_u32(rp + 4 * j), end = sn_rd_u32(rp + 4 * j + 4);
        const unsigned char *blk = L + (size_t)n * SN_ELEM_ICHOL;
        const sn_q *rj = r + 3 * j;
        sn_fv c[3], y, y0, y1, y2;
        uint32_t m;
        fv_rows(R + rs * j, c); /* t = R^T r_j (sn_k_rot_t), y = sn_out(t - acc_j) */
        y = ic_out_sub(FV_MAC3(c, FV_SET1(rj[0]), FV_SET1(rj[1]), FV_SET1(rj[2])), nx, sat);
        fv_st3(z + 3 * j, y);
        y0 = SN_K_LANE(y, 0); y1 = SN_K_LANE(y, 1); y2 = SN_K_LANE(y, 2);
        /* acc_j+1 is final but for row j + 1 of this column, its first
         * block if there (rows ascend, the validator): the sum goes to the
         * next column in a register, off memory on the sweep's chain (x86-64
         * round 4; the same floats) */
        m = 0;
        if (j + 1 < nF) {
            nx = fv_ld3(acc + 3 * j + 3);
            if (e < end && sn_rd_u16(cols + 2 * e) == j + 1) {
                sn_fv u[3];
                sn_k_ic_rows(blk, u);
                nx = FV_ADD(nx, FV_MAC3(u, y0, y1, y2));
                m = 1;
            }
        }
        m += sn_k_ic_fwd_ops(blk + m * SN_ELEM_ICHOL, cols + 2 * (e + m), cols + 2 * end, y0, y1, y2, nF, acc);
        memcpy(acc + 3 * j, &m, 4); /* acc_j is consumed: row j's free column count (its bits: no conversion) */
        n += m;
    }
    j = nF;
    nx = FV_SET1(0.0f); /* z'_j+1 (the previous vertex's) */
    while (j-- > 0) {
        const uint32_t b = sn_rd_u32(rp + 4 * j);
        const sn_q *yj = z + 3 * j;
        uint32_t m;
        sn_fv c[3], w, l;
        memcpy(&m, acc + 3 * j, 4);
        sn_k_sym_cols(P + (size_t)j * 6 * SN_REAL_BYTES, c); /* w = D^-1 y_j (sn_k_sym_out) */
        w = FV_ADD(FV_SET1(0.0f), FV_MAC3(c, FV_SET1(yj[0]), FV_SET1(yj[1]), FV_SET1(yj[2])));
        n -= m;
        /* column j + 1 first in row j (free columns ascend): z'_j+1 from the register */
        l = sn_k_ic_bwd_rowr(L + (size_t)n * SN_ELEM_ICHOL, cols + 2 * b, m, acc, nx, m && sn_rd_u16(cols + 2 * b) == j + 1);
        fv_cols(R + rs * j, c); /* z_j = R z'_j (sn_k_rot) */
        nx = ic_zstep(w, l, c, acc + 3 * j, z + 3 * j, sat);
    }
}
#else
/* The portable route (scalar, NEON, the M4; fixed and float): the same
 * passes fused as above through ic_forward / ic_backward with R, the same
 * values and clamp counts as precond_core's five passes (each vertex's
 * rotation, D^-1 and rotation back run on the same inputs, only earlier).
 * z'_j goes to zq, the top 12 nF bytes of the accumulators: row j's count
 * acc[3 j] (read before z'_j is written) and the counts below it lie below
 * zq + 3 j (fixed: byte 24 j + 8 <= 12 nF + 12 j for j < nF; float, 4-byte
 * accumulators: zq is acc, z'_j acc_j's own slot), and rows read only
 * columns i > j (the validator: upper triangle), written before. */
static void ic_fused(const sn_view *v, const uint8_t *kk, const sn_q *R, size_t rs, const sn_q *r, sn_q *z, sn_acc *acc,
                     uint32_t *sat) {
    sn_q *zq = (sn_q *)(void *)((unsigned char *)acc + 3 * (size_t)v->nF * (sizeof(sn_acc) - sizeof(sn_q)));
    ic_backward(v, ic_forward(v, kk, R, rs, r, z, acc, sat), acc, kk, R, rs, zq, z, sat);
}
#endif

/* t = s t, s a Q30 scale in (0, 1] (adaptation's source rows): no clamp */
SN_INLINE void scale3(sn_q t[3], sn_q s, uint32_t *sat) {
    t[0] = sn_out(sn_mul(s, t[0]), SN_Q_ROT, sat);
    t[1] = sn_out(sn_mul(s, t[1]), SN_Q_ROT, sat);
    t[2] = sn_out(sn_mul(s, t[2]), SN_Q_ROT, sat);
}

/* z = C r with the frame of vertex i at R + rs i (rs 9: the vertex frames;
 * rs 0: one frame for all, the blended mode's region) and, if mask, only the
 * vertices with mask[i] != 0 (inv: == 0) (r taken as 0 elsewhere, z set to 0
 * there: the principal block of an SPD C, so still SPD on the region). With
 * sc, z = S C S r, S = diag(sc) per vertex (a scalar: it commutes with the
 * frames): still SPD. */
static void precond_core(sn_ihdr *h, const sn_q *R, size_t rs, const uint8_t *mask, int inv, const sn_q *sc, const sn_q *r,
                         sn_q *z, uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *P = v->sec[SN_SEC_PRECOND];
    const uint8_t *kk = CARR(h, o_k, uint8_t);
    uint32_t i, n;
    if (!v->ic) { /* block Jacobi: z_i = R_i P_i R_i^T r_i */
        for (i = 0; i < v->nF; i++) {
            sn_q t[3], s[3];
            int sh = v->frac_P + SN_KREL(kk[i]); /* r is Q(19+k_i), z is Q22 */
            if (mask && !mask[i] == !inv) { z[3 * i] = z[3 * i + 1] = z[3 * i + 2] = 0; continue; }
            sn_k_rot_t(R + rs * i, r + 3 * i, t, sat);
            if (sc) scale3(t, sc[i], sat);
            sn_k_sym_out(P + (size_t)i * 6 * SN_REAL_BYTES, t, s, sh, sat); /* s = round(P_i t) */
            if (sc) scale3(s, sc[i], sat);
            sn_k_rot(R + rs * i, s, z + 3 * i, sat);
        }
        return;
    }
    if (!mask && !sc) { ic_fused(v, kk, R, rs, r, z, WARR(h, o_acc, sn_acc), sat); return; }
    for (i = 0; i < v->nF; i++) {
        if (mask && !mask[i] == !inv) z[3 * i] = z[3 * i + 1] = z[3 * i + 2] = 0;
        else {
            sn_k_rot_t(R + rs * i, r + 3 * i, z + 3 * i, sat);
            if (sc) scale3(z + 3 * i, sc[i], sat);
        }
    }
    n = ic_forward(v, kk, NULL, 0, NULL, z, WARR(h, o_acc, sn_acc), sat);
    for (i = 0; i < v->nF; i++) { /* w = D^-1 y: Q(19 + k_i) -> Q22 */
        sn_k_sym_out(P + (size_t)i * 6 * SN_REAL_BYTES, z + 3 * i, z + 3 * i, v->frac_P + SN_KREL(kk[i]), sat);
    }
    ic_backward(v, n, WARR(h, o_acc, sn_acc), kk, NULL, 0, z, z, sat);
    for (i = 0; i < v->nF; i++) {
        sn_q t[3] = {z[3 * i], z[3 * i + 1], z[3 * i + 2]};
        if (mask && !mask[i] == !inv) { z[3 * i] = z[3 * i + 1] = z[3 * i + 2] = 0; continue; }
        if (sc) scale3(t, sc[i], sat);
        sn_k_rot(R + rs * i, t, z + 3 * i, sat);
    }
}

void sn_precond(sn_ihdr *h, const sn_q *r, sn_q *z, uint32_t *sat) {
    precond_core(h, CARR(h, o_R, sn_q), 9, NULL, 0, NULL, r, z, sat);
}

void sn_precond_region(sn_ihdr *h, const sn_q *R, const uint8_t *mask, const sn_q *r, sn_q *z, uint32_t *sat) {
    precond_core(h, R, 0, mask, 0, NULL, r, z, sat);
}

void sn_precond_mask(sn_ihdr *h, const uint8_t *mask, int inv, const sn_q *sc, const sn_q *r, sn_q *z, uint32_t *sat) {
    precond_core(h, CARR(h, o_R, sn_q), 9, mask, inv, sc, r, z, sat);
}
