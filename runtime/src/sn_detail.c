/* sn_detail.c -- details on the cut level (sn_detail.h; format 6.4; LEVELS.md
 * §3 "Details on the cut level"): their validation. */
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
