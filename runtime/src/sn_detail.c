/* sn_detail.c -- details on the cut level (sn_detail.h; format 6.5; LEVELS.md
 * §3 "Details on the cut level"): their validation and the cell kernels the
 * step calls (the details' share of a cell's stiffness and mass products, the
 * surface's detail term). The seats and the active set: sn_detail_step.c. */
#include "sn_detail.h"

#define SN_CHK(cond, err) do { if (!(cond)) return (err); } while (0)

/* a non-corner half-cell point p + 3q + 9r -> its slot in CELLX / CELLD (255: a corner) */
static const uint8_t d_slot[27] = {255, 0, 255, 1, 2, 3, 255, 4, 255, 5, 6, 7, 8, 9, 10, 11, 12, 13,
                                   255, 14, 255, 15, 16, 17, 255, 18, 255};

/* All four sections count 0, or DETAILS 1 with the cut level (CELLX nC), DETAIL
 * nD >= 1, CELLD nC, CELLDK the running sum. Bounds, from what they feed: A_max
 * <= nD (the active list's seats); thresholds as ADAPT's (0 <= coarsen <= refine
 * <= SN_ADAPT_MAX, Q22, compared with |coefficient|s <= SN_LIM); dshift <= 4 (fixed;
 * float 0: the blocks' scale 2^(frac_S - dshift), frac_S <= 59); a detail's rest
 * point as REST's (|x| <= X: differences stay in int32); its cell < nC and point
 * a non-corner one whose CELLD entry names it back (so every detail has a cell
 * and the surface's child lookup finds it); CELLD entries < nD, never where CELLX
 * has an extra (one function per point), nd + nx <= 19 (a cell's locals <= 27:
 * its rows sum <= 27 blocks of 3 products < 2^55, as the cut level's); blocks as
 * CELLXK's (fixed |m| <= 2^15 - 1, e <= 12; float |entry| <= 2^27), masses
 * |m| <= 2^27 as MOFF's and a detail's own mass > 0 (a pivot and a divisor). */
sn_status sn_check_details(const sn_view *v, uint32_t nhd, uint32_t nd, uint32_t ncd, uint32_t ndk, uint32_t ncx) {
    const int32_t E = SN_ENTRY_LIM;
    const int32_t X = v->len_shift > 9 ? (int32_t)1 << (36 - v->len_shift) : E;
    const unsigned char *hd = sn_sec(v, SN_SEC_DETAILS), *dr = sn_sec(v, SN_SEC_DETAIL), *cd = sn_sec(v, SN_SEC_CELLD);
    const unsigned char *K = sn_sec(v, SN_SEC_CELLDK), *cx = sn_sec(v, SN_SEC_CELLX);
    const size_t KB = SN_ELEM_CELLDK(SN_FLAVOUR, SN_REAL_BYTES);
    uint32_t i, k, first = 0;
    if (nhd == 0) return nd == 0 && ncd == 0 && ndk == 0 ? SN_OK : SN_ERR_SECTION;
    SN_CHK(nhd == 1 && nd >= 1 && ncd == v->nC && ncx == v->nC, SN_ERR_SECTION);
    SN_CHK(sn_rd_u16(hd) <= nd && hd[3] == 0 && sn_rd_u32(hd + 4) == 0, SN_ERR_VALUE);
    SN_CHK(hd[2] <= (SN_FLAVOUR == SN_FLAVOUR_FIXED ? SN_DETAIL_SHIFT_MAX : 0), SN_ERR_VALUE); /* dshift: the step's shifts */
    SN_CHK(sn_real_ok(hd + 8, 0, SN_ADAPT_MAX, SN_Q_LEN) && sn_real_ok(hd + 8 + SN_REAL_BYTES, 0, SN_ADAPT_MAX, SN_Q_LEN), SN_ERR_VALUE);
    SN_CHK(!(SN_RD_REAL(hd + 8 + SN_REAL_BYTES) > SN_RD_REAL(hd + 8)), SN_ERR_VALUE); /* coarsen <= refine */
    for (i = 0; i < v->nC; i++) {
        const unsigned char *c = cd + (size_t)i * SN_ELEM_CELLD, *x = cx + (size_t)i * SN_ELEM_CELLX;
        uint32_t n = 0, nx = x[38], j, col;
        for (k = 0; k < SN_CUT_MAXX; k++) {
            uint32_t d = sn_rd_u16(c + 2 * k);
            if (d == SN_CUT_NONE) continue;
            SN_CHK(d < nd && sn_rd_u16(x + 2 * k) == SN_CUT_NONE, SN_ERR_INDEX);
            n++;
        }
        SN_CHK(c[38] == n && c[39] == 0 && n + nx <= SN_CUT_MAXX, SN_ERR_VALUE); /* nx: checked by sn_check_cut */
        SN_CHK(sn_rd_u32(c + 40) == first && (uint64_t)first + n * (8u + nx) + n * (n + 1u) / 2u <= ndk, SN_ERR_INDEX);
        for (j = 0; j < n; j++) /* a detail's own block: its mass is its pivot */
            for (col = 0; col < 8u + nx + n; col++) {
                const unsigned char *b = K + (size_t)first * KB;
                if (col >= 8u + nx && col < 8u + nx + j) continue;
                if (col == 8u + nx + j) SN_CHK(sn_real_ok(b + KB - SN_REAL_BYTES, 1, INT32_MAX, 30), SN_ERR_VALUE);
                first++;
            }
    }
    SN_CHK(first == ndk, SN_ERR_SECTION);
    for (i = 0; i < ndk; i++) {
        const unsigned char *b = K + (size_t)i * KB;
#if defined(SN_FLOAT)
        for (k = 0; k < 10; k++) SN_CHK(sn_real_ok(b + (size_t)k * SN_REAL_BYTES, -E, E, 0), SN_ERR_VALUE);
#else
        for (k = 0; k < 9; k++) SN_CHK(sn_rd_u16(b + 2 * k) != 0x8000u, SN_ERR_VALUE);
        SN_CHK(b[18] <= SN_CELLK_EXP_MAX && b[19] == 0, SN_ERR_VALUE);
        SN_CHK(sn_real_ok(b + 20, -E, E, 0), SN_ERR_VALUE);
#endif
    }
    for (i = 0; i < nd; i++) {
        const unsigned char *d = dr + (size_t)i * SN_ELEM_DETAIL(SN_REAL_BYTES);
        uint32_t cell = sn_rd_u16(d), pt = d[2];
        SN_CHK(cell < v->nC && pt < 27u && d_slot[pt] != 255u && d[3] == 0, SN_ERR_INDEX);
        SN_CHK(sn_rd_u16(cd + (size_t)cell * SN_ELEM_CELLD + 2u * d_slot[pt]) == i, SN_ERR_INDEX);
        for (k = 0; k < 3; k++) SN_CHK(sn_real_ok(d + 4 + (size_t)k * SN_REAL_BYTES, -X, X, SN_Q_LEN), SN_ERR_VALUE);
    }
    return SN_OK;
}

/* ---- stage 2's cell product (LEVELS.md §3 "Details on the cut level") ---- */

/* l += B y (tr: B^T y), B one CELLDK block: fixed m 2^e per entry, a row's 3
 * int16 x Q22 products (< 2^44.6) summed exactly, then scaled by 2^e (e <= 12:
 * < 2^56.6); float the 3 products one by one, in column order. */
SN_INLINE void blk_mac(const unsigned char *b, const sn_q y[3], int tr, sn_acc l[3]) {
    uint32_t i;
    for (i = 0; i < 3; i++) {
        uint32_t s0 = tr ? i : 3 * i, st = tr ? 3 : 1;
#if defined(SN_FLOAT)
        l[i] += rd_real(b, s0) * y[0];
        l[i] += rd_real(b, s0 + st) * y[1];
        l[i] += rd_real(b, s0 + 2 * st) * y[2];
#else
        int64_t m = (int64_t)(int16_t)sn_rd_u16(b + 2 * s0) * y[0] + (int64_t)(int16_t)sn_rd_u16(b + 2 * (s0 + st)) * y[1] +
                    (int64_t)(int16_t)sn_rd_u16(b + 2 * (s0 + 2 * st)) * y[2];
        l[i] += m * ((int64_t)1 << b[18]);
#endif
    }
}

/* Cell e's detail runs in CELLDK (detail j's starts after the details' before
 * it: sum_{i<j} (8 + nx + nd - i) elements); returns nd, *nx the cell's extras. */
static uint32_t cell_runs(const sn_view *v, uint32_t e, const unsigned char *run[SN_CUT_MAXX], uint32_t *nx) {
    const unsigned char *cd = sn_sec(v, SN_SEC_CELLD) + (size_t)e * SN_ELEM_CELLD;
    const size_t KB = SN_ELEM_CELLDK(SN_FLAVOUR, SN_REAL_BYTES);
    const unsigned char *Kj = sn_sec(v, SN_SEC_CELLDK) + (size_t)sn_rd_u32(cd + 40) * KB;
    const uint32_t nd = cd[38];
    uint32_t j;
    *nx = sn_sec(v, SN_SEC_CELLX)[(size_t)e * SN_ELEM_CELLX + 38];
    for (j = 0; j < nd; Kj += (size_t)(8u + *nx + nd - j) * KB, j++) run[j] = Kj;
    return nd;
}

/* Cell e's active details' share of the cut element's product (sn_detail.h).
 * The blocks of detail j (compact, CELLD order) start after those of the
 * details before it: sum_{i<j} (8 + nx + nd - i) elements; in its run column
 * c < 8 is corner c, 8 + x extra x, 8 + nx + (k - j) detail k >= j; the rows
 * of k < j over j are block (k, j) transposed. Bounds (fixed): a detail row
 * sums <= 27 blocks (nd + nx <= 19) < 27 * 3 * 2^55 < 2^61.4 (as the cut
 * level's corner rows); a corner row's detail part <= 19 blocks < 2^60.8 at
 * the details' scale, clamped to 2^(61 - dshift) (counted) and shifted up by
 * dshift to the corners' scale: with the corner rows' own < 2^61.6 (cell_forces:
 * ld + lu + lx) the sum stays < 2^62.3, below sn_out's 2^62.5. */
static void cell_mul(const sn_view *v, uint32_t e, uint32_t on, uint32_t con, const sn_q yc[24], const sn_q (*yx)[3],
                     const sn_q (*yd)[3], sn_acc lc[24], sn_acc ld[3 * SN_CUT_MAXX], uint32_t *sat) {
    const size_t KB = SN_ELEM_CELLDK(SN_FLAVOUR, SN_REAL_BYTES);
    const unsigned char *run[SN_CUT_MAXX], *Kj;
    uint32_t nx;
    const uint32_t nd = cell_runs(v, e, run, &nx);
    sn_acc dc[24];
    uint32_t j, k, c;
#if !defined(SN_FLOAT)
    const int ds = sn_sec(v, SN_SEC_DETAILS)[2];
    const int64_t lim = ((int64_t)1 << (61 - ds));
#endif
    for (c = 0; c < 24; c++) dc[c] = 0;
    for (j = 0; j < nd; j++) {
        sn_acc *l = ld + 3 * j;
        Kj = run[j];
        l[0] = l[1] = l[2] = 0;
        if (!(on >> j & 1u)) continue;
        for (c = 0; c < 8; c++) blk_mac(Kj + (size_t)c * KB, yc + 3 * c, 0, l);
        if (lc)
            for (c = 0; c < 8; c++) blk_mac(Kj + (size_t)c * KB, yd[j], 1, dc + 3 * c); /* corner c's row: block (j, c) transposed */
        if (yx)
            for (c = 0; c < nx; c++) blk_mac(Kj + (size_t)(8u + c) * KB, yx[c], 0, l);
        for (k = 0; k < nd; k++) { /* k < j: block (k, j) transposed, in k's run at column 8 + nx + (j - k) */
            if (!(con >> k & 1u)) continue;
            if (k >= j) blk_mac(Kj + (size_t)(8u + nx + k - j) * KB, yd[k], 0, l);
            else blk_mac(run[k] + (size_t)(8u + nx + j - k) * KB, yd[k], 1, l);
        }
        for (c = 0; c < 3; c++) SN_RANGE(SN_WITHIN(l[c], 62), "detail row beyond 27 * 3 * 2^55 (2^61.4)", l[c]);
    }
    for (c = 0; lc && c < 24; c++) {
#if defined(SN_FLOAT)
        lc[c] += dc[c];
#else
        int64_t t = dc[c];
        if (t > lim) { t = lim; (*sat)++; }
        if (t < -lim) { t = -lim; (*sat)++; }
        lc[c] += t * ((int64_t)1 << ds);
#endif
    }
    (void)sat;
}
void sn_detail_cell_mul(const sn_view *v, uint32_t e, uint32_t on, const sn_q yc[24], const sn_q (*yx)[3], const sn_q (*yd)[3],
                        sn_acc lc[24], sn_acc ld[3 * SN_CUT_MAXX], uint32_t *sat) {
    cell_mul(v, e, on, on, yc, yx, yd, lc, ld, sat);
}
void sn_detail_cell_rows(const sn_view *v, uint32_t e, uint32_t on, uint32_t con, const sn_q yc[24], const sn_q (*yx)[3],
                         const sn_q (*yd)[3], sn_acc ld[3 * SN_CUT_MAXX], uint32_t *sat) {
    cell_mul(v, e, on, con, yc, yx, yd, NULL, ld, sat);
}

/* A CELLDK element's mass M_E[d][col] / m0 (Q frac_M, as MOFF). */
SN_INLINE sn_q blk_mass(const unsigned char *b) {
#if defined(SN_FLOAT)
    return rd_real(b, 9);
#else
    return rd_real(b + 20, 0);
#endif
}

/* Cell e's active details' share of the Galerkin mass product (sn_detail.h):
 * the same runs as sn_detail_cell_mul, one scalar per block. Bound (fixed):
 * |mass| <= 2^27 (validator), |y| <= 2^28: a row sums <= 27 products < 2^59.8;
 * a corner row's detail part <= 19 of them < 2^59.3, at MOFF's scale. */
void sn_detail_cell_mass(const sn_view *v, uint32_t e, uint32_t on, const sn_q yc[24], const sn_q (*yx)[3], const sn_q (*yd)[3],
                         sn_acc mc[24], sn_acc md[3 * SN_CUT_MAXX]) {
    const size_t KB = SN_ELEM_CELLDK(SN_FLAVOUR, SN_REAL_BYTES);
    const unsigned char *run[SN_CUT_MAXX], *Kj;
    uint32_t nx, j, k, c, q;
    const uint32_t nd = cell_runs(v, e, run, &nx);
    for (j = 0; j < nd; j++) {
        sn_acc *l = md + 3 * j;
        Kj = run[j];
        l[0] = l[1] = l[2] = 0;
        if (!(on >> j & 1u)) continue;
        for (c = 0; c < 8; c++) {
            sn_q m = blk_mass(Kj + (size_t)c * KB);
            for (q = 0; q < 3; q++) l[q] += sn_mul(m, yc[3 * c + q]);
            if (mc)
                for (q = 0; q < 3; q++) mc[3 * c + q] += sn_mul(m, yd[j][q]);
        }
        if (yx)
            for (c = 0; c < nx; c++) {
                sn_q m = blk_mass(Kj + (size_t)(8u + c) * KB);
                for (q = 0; q < 3; q++) l[q] += sn_mul(m, yx[c][q]);
            }
        for (k = 0; k < nd; k++) { /* k < j: block (k, j), in k's run at column 8 + nx + (j - k); the mass is symmetric */
            sn_q m;
            if (!(on >> k & 1u)) continue;
            m = blk_mass(k >= j ? Kj + (size_t)(8u + nx + k - j) * KB : run[k] + (size_t)(8u + nx + j - k) * KB);
            for (q = 0; q < 3; q++) l[q] += sn_mul(m, yd[k][q]);
        }
        for (q = 0; q < 3; q++) SN_RANGE(SN_WITHIN(l[q], 60), "detail mass row beyond 27 * 2^55", l[q]);
    }
}

/* The surface's detail term (sn_detail.h): in the child holding t (as
 * sn_cut_interp: t = 1/2 belongs to the upper child), each child corner k at
 * a point whose CELLD entry names a detail with a seat adds phi'_k c (phi'
 * the child's trilinear weights, Q30; c the seat's coefficient, Q22): the
 * detail's level-1 hat is phi'_k in this child. <= 8 products of <= 2^30 x
 * 2^28: the acc's Q52 sum stays < 2^61. */
void sn_detail_interp(const sn_view *v, uint32_t cell, const uint32_t t[3], const uint16_t *seat_of, const sn_q *coef,
                      sn_acc acc[3]) {
    const unsigned char *cd = sn_sec(v, SN_SEC_CELLD) + (size_t)cell * SN_ELEM_CELLD;
    uint32_t b[3], tc[3], k, c;
    sn_q phi[8];
    if (cd[38] == 0) return;
    for (c = 0; c < 3; c++) {
        b[c] = t[c] >= 16384u;
        tc[c] = 2u * t[c] - 32768u * b[c];
    }
    sn_trilinear(tc, phi);
    for (k = 0; k < 8; k++) {
        uint32_t p = b[0] + (k & 1u) + 3u * (b[1] + (k >> 1 & 1u)) + 9u * (b[2] + (k >> 2 & 1u)), slot = d_slot[p], d, s;
        if (slot == 255u || (d = sn_rd_u16(cd + 2 * slot)) == SN_CUT_NONE || (s = seat_of[d]) == SN_CUT_NONE) continue;
        for (c = 0; c < 3; c++) acc[c] += sn_mul(phi[k], coef[3 * s + c]);
    }
}
