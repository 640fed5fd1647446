/* sn_cut.c -- the cut level (CELLX, CELLXK; format 6.3; LEVELS.md §2
 * "The cut level", NUMERICS.md "The cut level"): its validation, the extras'
 * force terms in the cell product, and the cut field for the surface and the
 * level switch. Level 0's cells are cut at level 1's skeleton; its vertices
 * are extra skeleton vertices (no rows) of the cells they fall in.
 */
#include "sn_cut.h"
#include "sn_kernels_rot.h" /* sn_k_rot_t: the frame rotation, reference or SIMD */

#define SN_CHK(cond, err) do { if (!(cond)) return (err); } while (0)

/* Validation (sn_blob.c calls it with the table's counts): CELLXK only with
 * CELLX; per cell at most SN_CUT_MAXX extras, each a skeleton vertex (nF..nV-1:
 * no row, its value from its bone), nx the entries set, first the running sum
 * of 8 nx, ending at CELLXK's count; blocks as CELLK's off-diagonal ones
 * (fixed |m| <= 2^15 - 1, e <= 12; float |entry| <= 2^27), so a cell row with
 * its extras sums 27 blocks of 3 products < 2^55: < 2^61.4 (sn_solve.c). */
sn_status sn_check_cut(const sn_view *v, uint32_t ncx, uint32_t nxk) {
    const unsigned char *s = sn_sec(v, SN_SEC_CELLX), *K = sn_sec(v, SN_SEC_CELLXK);
    uint32_t i, k, first = 0;
    SN_CHK(ncx != 0 || nxk == 0, SN_ERR_SECTION);
    for (i = 0; i < ncx; i++) {
        const unsigned char *c = s + (size_t)i * SN_ELEM_CELLX;
        uint32_t nx = 0;
        for (k = 0; k < SN_CUT_MAXX; k++) {
            uint32_t x = sn_rd_u16(c + 2 * k);
            if (x == SN_CUT_NONE) continue;
            SN_CHK(x >= v->nF && x < v->nV, SN_ERR_INDEX);
            nx++;
        }
        SN_CHK(c[38] == nx && c[39] == 0, SN_ERR_VALUE);
        SN_CHK(sn_rd_u32(c + 40) == first, SN_ERR_INDEX);
        first += 8u * nx;
    }
    SN_CHK(first == nxk, SN_ERR_SECTION);
    for (i = 0; i < nxk; i++) {
        const unsigned char *b = K + (size_t)i * SN_ELEM_CELLXK(SN_FLAVOUR, SN_REAL_BYTES);
#if defined(SN_FLOAT)
        for (k = 0; k < 9; k++) SN_CHK(sn_real_ok(b + (size_t)k * SN_REAL_BYTES, -SN_ENTRY_LIM, SN_ENTRY_LIM, 0), SN_ERR_VALUE);
#else
        for (k = 0; k < 9; k++) SN_CHK(sn_rd_u16(b + 2 * k) != 0x8000u, SN_ERR_VALUE);
        SN_CHK(b[18] <= SN_CELLK_EXP_MAX && b[19] == 0, SN_ERR_VALUE);
#endif
    }
    return SN_OK;
}

/* Step 4 (sn_solve.c cell_forces): cell e's
 * extra skeleton vertices x enter its free corners' rows through the cut
 * element's blocks [corner x extra]: lx_a = sum_x K_ax (d_x + u_x), d_x and
 * u_x formed as a corner's (relative to corner 0, in the cell's frame). The
 * extras' own rows are the skeleton's (no unknowns), so the energy stat keeps
 * the corner block's d.K d. Bound: 19 x 3 more products < 2^55 per row.
 * Cost (LEVELS.md §2; blob-fixed: no skip on the values): y_x first, then per
 * free corner its 3 rows summed over the extras in registers; each row's additions come in
 * the same order as extra-major loops would give them (x, then c), so float
 * keeps its bits; fixed sums a block row's 3 int16 mantissa products and
 * scales once by 2^e (m y = mant y 2^e, all exact in int64: same integers). */
void sn_cut_terms(sn_ihdr *h, uint32_t e, const sn_q *R, uint32_t a0, const sn_q w0[3], uint32_t fr,
                  sn_q y[SN_CUT_MAXX][3], sn_acc lx[24], uint32_t *sat) {
    const sn_view *v = &h->v;
    const unsigned char *cx = sn_sec(v, SN_SEC_CELLX) + (size_t)e * SN_ELEM_CELLX, *rest = v->sec[SN_SEC_REST];
    const unsigned char *K0 = sn_sec(v, SN_SEC_CELLXK) + (size_t)sn_rd_u32(cx + 40) * SN_ELEM_CELLXK(SN_FLAVOUR, SN_REAL_BYTES);
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    uint32_t j, a, c, i, n = 0, counted = 0; /* coef's clamps are counted once in rhs */
    for (j = 0; j < SN_CUT_MAXX; j++) {
        uint32_t x = sn_rd_u16(cx + 2 * j);
        sn_q t[3], sw[3], l[3], uu[3];
        if (x == SN_CUT_NONE) continue;
        for (c = 0; c < 3; c++) {
            t[c] = sn_add(pos[3 * x + c], -pos[3 * a0 + c], sat);
            sw[c] = sn_add(coef(vel[3 * x + c], v->b1, &counted), -w0[c], sat); /* w_at of a skeleton vertex (sn_solve.c) */
        }
        sn_k_rot_t(R, t, l, sat);
        sn_k_rot_t(R, sw, uu, sat);
        for (c = 0; c < 3; c++) {
            sn_q xr = sn_add(rd_real(rest, 3 * x + c), -rd_real(rest, 3 * a0 + c), sat);
            y[n][c] = sn_add(sn_add(l[c], -xr, sat), uu[c], sat);
        }
        n++;
    }
    for (a = 0; a < 8; a++) {
        sn_acc s0 = 0, s1 = 0, s2 = 0;
        if (!(fr >> a & 1u)) continue; /* not free: its lx not read (cell_forces) */
        for (j = 0; j < n; j++) {
            const sn_q *yx = y[j]; /* block (extra j, corner a) at 8 j + a */
            const unsigned char *K = K0 + ((size_t)8 * j + a) * SN_ELEM_CELLXK(SN_FLAVOUR, SN_REAL_BYTES);
#if defined(SN_FLOAT)
            s0 += sn_mul(rd_real(K, 0), yx[0]); s0 += sn_mul(rd_real(K, 1), yx[1]); s0 += sn_mul(rd_real(K, 2), yx[2]);
            s1 += sn_mul(rd_real(K, 3), yx[0]); s1 += sn_mul(rd_real(K, 4), yx[1]); s1 += sn_mul(rd_real(K, 5), yx[2]);
            s2 += sn_mul(rd_real(K, 6), yx[0]); s2 += sn_mul(rd_real(K, 7), yx[1]); s2 += sn_mul(rd_real(K, 8), yx[2]);
#else
            int64_t sc = (int64_t)1 << K[18];
#define SN_CUT_M(k) ((int64_t)(int16_t)sn_rd_u16(K + 2 * (k)))
            s0 += (SN_CUT_M(0) * yx[0] + SN_CUT_M(1) * yx[1] + SN_CUT_M(2) * yx[2]) * sc;
            s1 += (SN_CUT_M(3) * yx[0] + SN_CUT_M(4) * yx[1] + SN_CUT_M(5) * yx[2]) * sc;
            s2 += (SN_CUT_M(6) * yx[0] + SN_CUT_M(7) * yx[1] + SN_CUT_M(8) * yx[2]) * sc;
#undef SN_CUT_M
#endif
        }
        lx[3 * a] = s0;
        lx[3 * a + 1] = s1;
        lx[3 * a + 2] = s2;
        for (i = 3 * a; i < 3 * a + 3; i++) SN_RANGE(SN_WITHIN(lx[i], 61), "cut-level row beyond 19 * 3 * 2^55", lx[i]);
    }
}

/* The cut field (surface, sn_embed.c; level switch, sn_level.c): the field in a cell is
 * trilinear in the child (half cell) holding the point, whose corners carry the
 * cell's trilinear field except at an extra skeleton vertex x, which carries
 * its own position: so acc += phi'_k (p_x - P p(x)) for each child corner k at
 * an extra (phi' the child's weights, P p(x) = sum_a (n_a / 8) p_a, n_a the
 * dyadic weights 0, 1, 2, 4, 8 of the cell's corners at that half-cell point).
 * Values: free vertices' in vf, skeleton vertices' (nF..nV-1) in vs. */
static const uint8_t cut_slot[27] = { /* half-cell point -> its CELLX entry (255: a corner) */
    255, 0, 255, 1, 2, 3, 255, 4, 255, 5, 6, 7, 8, 9, 10, 11, 12, 13, 255, 14, 255, 15, 16, 17, 255, 18, 255};
void sn_cut_interp(const sn_view *v, uint32_t cell, const uint32_t t[3], const sn_q *vf, const sn_q *vs, sn_acc acc[3]) {
    const unsigned char *cx = sn_sec(v, SN_SEC_CELLX) + (size_t)cell * SN_ELEM_CELLX;
    const unsigned char *cl = v->sec[SN_SEC_CELLS] + (size_t)cell * SN_ELEM_CELLS;
    uint32_t b[3], tc[3], k, a, c, dummy = 0, nF = v->nF;
    sn_q phi[8];
    for (c = 0; c < 3; c++) {
        b[c] = t[c] >= 16384u; /* the child: t = 1/2 belongs to the upper one (its weight there is the same) */
        tc[c] = 2u * t[c] - 32768u * b[c];
    }
    sn_trilinear(tc, phi);
    for (k = 0; k < 8; k++) {
        uint32_t p0 = b[0] + (k & 1u), p1 = b[1] + (k >> 1 & 1u), p2 = b[2] + (k >> 2 & 1u), slot = cut_slot[p0 + 3 * p1 + 9 * p2], x;
        sn_acc s8[3] = {0, 0, 0};
        if (slot == 255u || (x = sn_rd_u16(cx + 2 * slot)) == SN_CUT_NONE) continue;
        for (a = 0; a < 8; a++) { /* n_a = prod over axes of (a bit ? p : 2 - p), p in 0..2 */
            uint32_t n = ((a & 1u) ? p0 : 2u - p0) * ((a >> 1 & 1u) ? p1 : 2u - p1) * ((a >> 2 & 1u) ? p2 : 2u - p2);
            uint32_t vtx = sn_rd_u16(cl + 2 * a);
            const sn_q *src = vtx < nF ? vf + 3 * vtx : vs + 3 * (vtx - nF);
            for (c = 0; c < 3; c++) s8[c] += (sn_acc)n * src[c];
        }
        for (c = 0; c < 3; c++) {
#if defined(SN_FLOAT)
            sn_q px = s8[c] * 0.125f;
#else
            sn_q px = (sn_q)sn_rshr64(s8[c], 3);
#endif
            acc[c] += sn_mul(phi[k], sn_add(vs[3 * (x - nF) + c], -px, &dummy));
        }
    }
}

/* A point's row weights (sn_cut.h): plain, the trilinear phi_a; cut, the same
 * field sn_cut_interp gives the surface written over the lattice vertices:
 * w_a = sum over the child's corners k not at an extra of phi'_k n_a(k) / 8,
 * = phi_a(t) - sum over the child's corners k at an extra of phi'_k n_a(k) / 8
 * (the trilinear field restricted to the child is the child's trilinear
 * interpolation of its corner values), w_x = phi'_k at an extra x (zero
 * weights left out). A child without extras: the plain weights. Sum one
 * within the Q30 roundings (8 + 7 terms); fixed: sum_k phi'_k n_a(k) <=
 * 8 2^30 before the shift; a w_a whose true value is 0 may round to -1 LSB. */
static const uint8_t cut_na[27][8] = { /* n_a at half-cell point p0 + 3 p1 + 9 p2: prod over axes of (a bit ? p : 2 - p) */
    {8, 0, 0, 0, 0, 0, 0, 0}, {4, 4, 0, 0, 0, 0, 0, 0}, {0, 8, 0, 0, 0, 0, 0, 0}, {4, 0, 4, 0, 0, 0, 0, 0}, {2, 2, 2, 2, 0, 0, 0, 0},
    {0, 4, 0, 4, 0, 0, 0, 0}, {0, 0, 8, 0, 0, 0, 0, 0}, {0, 0, 4, 4, 0, 0, 0, 0}, {0, 0, 0, 8, 0, 0, 0, 0}, {4, 0, 0, 0, 4, 0, 0, 0},
    {2, 2, 0, 0, 2, 2, 0, 0}, {0, 4, 0, 0, 0, 4, 0, 0}, {2, 0, 2, 0, 2, 0, 2, 0}, {1, 1, 1, 1, 1, 1, 1, 1}, {0, 2, 0, 2, 0, 2, 0, 2},
    {0, 0, 4, 0, 0, 0, 4, 0}, {0, 0, 2, 2, 0, 0, 2, 2}, {0, 0, 0, 4, 0, 0, 0, 4}, {0, 0, 0, 0, 8, 0, 0, 0}, {0, 0, 0, 0, 4, 4, 0, 0},
    {0, 0, 0, 0, 0, 8, 0, 0}, {0, 0, 0, 0, 4, 0, 4, 0}, {0, 0, 0, 0, 2, 2, 2, 2}, {0, 0, 0, 0, 0, 4, 0, 4}, {0, 0, 0, 0, 0, 0, 8, 0},
    {0, 0, 0, 0, 0, 0, 4, 4}, {0, 0, 0, 0, 0, 0, 0, 8}};
uint32_t sn_point_weights(const sn_view *v, uint32_t cell, const uint32_t t[3], uint16_t vtx[SN_CUT_POINT_MAX],
                          sn_q w[SN_CUT_POINT_MAX]) {
    const unsigned char *cl = v->sec[SN_SEC_CELLS] + (size_t)cell * SN_ELEM_CELLS, *cx;
    uint32_t b[3], tc[3], k, a, c, n = 8;
    sn_acc s[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    sn_q phi[8];
    for (a = 0; a < 8; a++) vtx[a] = (uint16_t)sn_rd_u16(cl + 2 * a);
    sn_trilinear(t, w);
    if (!v->cut) return 8;
    cx = sn_sec(v, SN_SEC_CELLX) + (size_t)cell * SN_ELEM_CELLX;
    for (c = 0; c < 3; c++) { /* the child, as sn_cut_interp */
        b[c] = t[c] >= 16384u;
        tc[c] = 2u * t[c] - 32768u * b[c];
    }
    sn_trilinear(tc, phi);
    for (k = 0; k < 8; k++) {
        uint32_t p = b[0] + (k & 1u) + 3u * (b[1] + (k >> 1 & 1u)) + 9u * (b[2] + (k >> 2 & 1u)), slot = cut_slot[p], x;
        if (slot == 255u || (x = sn_rd_u16(cx + 2 * slot)) == SN_CUT_NONE || phi[k] == 0) continue;
        vtx[n] = (uint16_t)x;
        w[n] = phi[k];
        n++;
        for (a = 0; a < 8; a++) s[a] += (sn_acc)cut_na[p][a] * phi[k];
    }
    if (n > 8)
        for (a = 0; a < 8; a++) {
#if defined(SN_FLOAT)
            w[a] -= s[a] * 0.125f;
#else
            w[a] -= (sn_q)sn_rshr64(s[a], 3);
#endif
        }
    return n;
}

/* sn_cut.h: the deviation bound. Per CELLX entry the trilinear value at its
 * half-cell point (the dyadic n_a / 8, one rounding shift) and the
 * difference; fixed |difference| <= 2^29, kept in int64, clamped to SN_LIM.
 * Cost: the cells' extras x 8 corners x 3, once a step. */
static const uint8_t cut_pt[SN_CUT_MAXX] = {1, 3, 4, 5, 7, 9, 10, 11, 12, 13, 14, 15, 16, 17, 19, 21, 22, 23, 25}; /* slot -> point */
sn_q sn_cut_dev(const sn_view *v, const sn_q *vf, const sn_q *vs) {
    const unsigned char *cx = sn_sec(v, SN_SEC_CELLX), *cl = v->sec[SN_SEC_CELLS];
    uint32_t e, j, a, c, nF = v->nF;
#if defined(SN_FLOAT)
    float m = 0.0f;
#else
    int64_t m = 0;
#endif
    for (e = 0; e < v->nC; e++, cx += SN_ELEM_CELLX, cl += SN_ELEM_CELLS) {
        if (cx[38] == 0) continue;
        for (j = 0; j < SN_CUT_MAXX; j++) {
            uint32_t x = sn_rd_u16(cx + 2 * j);
            const uint8_t *na = cut_na[cut_pt[j]];
            sn_acc s8[3] = {0, 0, 0};
            if (x == SN_CUT_NONE) continue;
            for (a = 0; a < 8; a++) {
                uint32_t vtx = sn_rd_u16(cl + 2 * a);
                const sn_q *src = vtx < nF ? vf + 3 * vtx : vs + 3 * (vtx - nF);
                if (na[a]) for (c = 0; c < 3; c++) s8[c] += (sn_acc)na[a] * src[c];
            }
            for (c = 0; c < 3; c++) {
#if defined(SN_FLOAT)
                float d = vs[3 * (x - nF) + c] - s8[c] * 0.125f;
                d = d < 0 ? -d : d;
                m = d > m ? d : m; /* NaN never: the state is finite */
#else
                int64_t d = (int64_t)vs[3 * (x - nF) + c] - sn_rshr64(s8[c], 3);
                d = d < 0 ? -d : d;
                m = d > m ? d : m;
#endif
            }
        }
    }
#if defined(SN_FLOAT)
    return m;
#else
    return (sn_q)(m > SN_LIM ? SN_LIM : m);
#endif
}
