/* sb_blob_cells.c -- the cells' stiffness blocks as baked: quantized per flavour, null space kept (NUMERICS.md). */
#include "sb_blob_int.h"
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* Cell e's stiffness S^_e = h^2 S_e / m0, quantized for the flavour into
 * out (36 upper blocks a <= b, 9 entries each, block (a,b)[3i+j] =
 * S^_e[3a+i][3b+j]). Fixed flavour (format 6.0 CELLK, sn_format.h): each
 * off-diagonal block is rounded on its own to an int16 mantissa times 2^e,
 * e the smallest exponent (0..12) whose mantissas fit |m| <= 2^15 - 1 (into
 * exps[], by the block's index among the 28); each diagonal block (int32)
 * is set so that the integer block row sums equal the rounded exact ones
 * (zero for the translation null space): rounding every entry alone breaks
 * that null space, which moved a slender beam's static tip by 1.4%
 * (tests/reference/README.md, finding 2); then symmetrized (<= 1 LSB).
 * out holds the integer entries m 2^e / the diagonal's. Returns 0, or -1 if
 * an entry does not fit. */
/* The cut level's blocks [corner a x extra k] of cell ci (sb_cut.h), scaled as
 * cell_blocks' and, fixed, rounded each to int16 mantissas times 2^e (xe[]):
 * out[9 (8 k + a) + 3i + j]. Returns the extras, or -1 if an entry does not fit. */
int sb_blob_cut_blocks(const sb_model *o, int ci, double sc, int flavour, int frac, double *out, int *xe)
{
    const sb_cut *cut = o->cut;
    const int N3 = 3 * SB_CUT_NL;
    const double *KE;
    int nx, k, a, i, j;
    if (!cut) return 0;
    nx = cut->cnx[ci];
    KE = cut->K + (size_t)(N3 * N3) * (size_t)ci;
    for (k = 0; k < nx; k++)
        for (a = 0; a < 8; a++) {
            double *B = out + 9 * (8 * k + a), mx = 0;
            int e = 0;
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++) {
                    double x = sc * KE[(size_t)N3 * (size_t)(3 * a + i) + (size_t)(3 * (8 + k) + j)];
                    B[3 * i + j] = flavour == SB_FIXED ? ldexp(x, frac) : x;
                    mx = fmax(mx, fabs(B[3 * i + j]));
                }
            if (!(mx <= 134217728.0)) return -1; /* 2^27: the runtime's entry bound */
            if (flavour != SB_FIXED) continue;
            while (e < SN_CELLK_EXP_MAX && rnd(ldexp(mx, -e)) > (double)SN_CELLK_M_MAX) e++;
            for (i = 0; i < 9; i++) B[i] = ldexp(fmax(-SN_CELLK_M_MAX, fmin(SN_CELLK_M_MAX, rnd(ldexp(B[i], -e)))), e);
            xe[8 * k + a] = e;
        }
    return nx;
}

int sb_blob_cell_blocks(const sb_model *o, int ci, double h, double m0, int flavour, int frac, double out[36 * 9],
                       int exps[28])
{
    const double *Se = o->Se + (size_t)ci * 576;
    double sc = h * h / m0, xb[8 * SB_CUT_MAXX * 9];
    int a, b, i, j, n = 0, no = 0, nx = 0, xe[8 * SB_CUT_MAXX];
    for (a = 0; a < 8; a++)
        for (b = a; b < 8; b++, n++)
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++) {
                    double x = sc * Se[(size_t)(3 * a + i) * 24 + (size_t)(3 * b + j)];
                    out[9 * n + 3 * i + j] = flavour == SB_FIXED ? ldexp(x, frac) : x;
                }
    if (flavour != SB_FIXED) return 0;
    for (a = 0, n = 0; a < 8; a++)
        for (b = a; b < 8; b++, n++) {
            double mx = 0;
            int k, e = 0;
            if (b == a) continue;
            for (k = 0; k < 9; k++) mx = fmax(mx, fabs(out[9 * n + k]));
            while (e < SN_CELLK_EXP_MAX && rnd(ldexp(mx, -e)) > (double)SN_CELLK_M_MAX) e++;
            if (!(mx <= 134217728.0)) return -1; /* 2^27: the runtime's entry bound */
            for (k = 0; k < 9; k++) /* at e = 12 an entry within 2^11 of 2^27 takes the largest mantissa */
                out[9 * n + k] = ldexp(fmax(-SN_CELLK_M_MAX, fmin(SN_CELLK_M_MAX, rnd(ldexp(out[9 * n + k], -e)))), e);
            exps[no++] = e;
        }
    if (o->cut && (nx = sb_blob_cut_blocks(o, ci, sc, SB_FIXED, frac, xb, xe)) < 0) return -1;
    for (a = 0; a < 8; a++) {
        double exact[9] = {0}, D[9], xsum[9] = {0};
        int k, na = 0;
        for (k = 0; k < a; k++) na += 8 - k; /* index of block (a,a) */
        for (b = 0; b < 8; b++)
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++) exact[3 * i + j] += sc * Se[(size_t)(3 * a + i) * 24 + (size_t)(3 * b + j)];
        if (o->cut) { /* the cut element: its rows' null space runs over the extras too (their rounded blocks) */
            const int N3 = 3 * SB_CUT_NL;
            const double *KE = o->cut->K + (size_t)(N3 * N3) * (size_t)ci;
            for (k = 0; k < nx; k++)
                for (i = 0; i < 3; i++)
                    for (j = 0; j < 3; j++) {
                        exact[3 * i + j] += sc * KE[(size_t)N3 * (size_t)(3 * a + i) + (size_t)(3 * (8 + k) + j)];
                        xsum[3 * i + j] += xb[9 * (8 * k + a) + 3 * i + j];
                    }
        }
        for (k = 0; k < 9; k++) D[k] = rnd(ldexp(exact[k], frac)) - xsum[k];
        for (b = 0; b < 8; b++) {
            int lo = a < b ? a : b, hi = a < b ? b : a, nb = 0;
            if (b == a) continue;
            for (k = 0; k < lo; k++) nb += 8 - k;
            nb += hi - lo;
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++) /* block (a,b) = stored (lo,hi), transposed when a > b */
                    D[3 * i + j] -= a < b ? out[9 * nb + 3 * i + j] : out[9 * nb + 3 * j + i];
        }
        for (i = 0; i < 3; i++)
            for (j = 0; j < 3; j++)
                out[9 * na + 3 * i + j] = i == j ? D[3 * i + j] : rnd(0.5 * (D[3 * i + j] + D[3 * j + i]));
    }
    for (n = 0; n < 36 * 9; n++)
        if (!(fabs(out[n]) <= 134217728.0)) return -1; /* 2^27: the runtime's entry bound */
    return 0;
}

/* CELLS, CFRAMES, CELLK and the cut level's CELLX / CELLXK (sn_format.h); a
 * block beyond its format sets w->err */
void sb_blob_write_cells(const sb_model *o, wr_t *w, const uint32_t *off, const uint32_t *esz, double h, double m0,
                         const sb_blob *b)
{
    static const int sym6[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
    const int flavour = w->flavour, rs = w->rs;
    int i, k;
    for (i = 0; i < o->nc; i++) {
        double blk[36 * 9];
        int exps[28];
        size_t at = off[SN_SEC_CFRAMES] + 4 * (size_t)i;
        for (k = 0; k < 8; k++) put_u16(w, off[SN_SEC_CELLS] + 16 * (size_t)i + 2 * (size_t)k, (unsigned)o->cells[8 * i + k]);
        put_u8(w, at, (unsigned)o->cfb1[i]);
        put_u8(w, at + 1, (unsigned)o->cfb2[i]);
        put_u16(w, at + 2, sb_frame_w(o->cfw[i]));
        if (sb_blob_cell_blocks(o, i, h, m0, flavour, b->frac_S, blk, exps) != 0) w->err = 1;
        if (flavour == SB_FIXED) { /* int32 diagonal (6 symmetric), int16 mantissas, exponents */
            size_t c0 = off[SN_SEC_CELLK] + (size_t)i * SN_CELLK_FIXED_BYTES;
            int a, bb, n = 0, no = 0;
            for (a = 0; a < 8; a++)
                for (bb = a; bb < 8; bb++, n++) {
                    if (bb == a) {
                        for (k = 0; k < 6; k++)
                            put_u32(w, c0 + SN_CELLK_DIAG + 24 * (size_t)a + 4 * (size_t)k,
                                    (uint32_t)(int32_t)blk[9 * n + 3 * sym6[k][0] + sym6[k][1]]);
                    } else {
                        for (k = 0; k < 9; k++)
                            put_u16(w, c0 + SN_CELLK_OFF + 18 * (size_t)no + 2 * (size_t)k,
                                    (unsigned)(uint16_t)(int16_t)ldexp(blk[9 * n + k], -exps[no]));
                        put_u8(w, c0 + SN_CELLK_EXP + (size_t)no, (unsigned)exps[no]);
                        no++;
                    }
                }
        } else
            for (k = 0; k < 36 * 9; k++)
                put_real(w, off[SN_SEC_CELLK] + ((size_t)i * 36 * 9 + (size_t)k) * (size_t)rs, blk[k], 0);
    }
    if (o->cut) { /* the cut level: each cell's extras and their blocks (sb_cut.h) */
        uint32_t first = 0;
        for (i = 0; i < o->nc; i++) {
            size_t at = off[SN_SEC_CELLX] + (size_t)i * SN_ELEM_CELLX;
            double xb[8 * SB_CUT_MAXX * 9];
            int xe[8 * SB_CUT_MAXX], nx, q, m = 0;
            nx = sb_blob_cut_blocks(o, i, h * h / m0, flavour, b->frac_S, xb, xe);
            if (nx < 0) { w->err = 1; continue; }
            for (q = 0; q < 27; q++) {
                int id;
                if (!((q % 3) & 1) && !((q / 3 % 3) & 1) && !((q / 9) & 1)) continue; /* a corner */
                id = o->cut->csub[27 * i + q];
                put_u16(w, at + 2 * (size_t)m++, id < 0 ? SN_CUT_NONE : (unsigned)(o->cut_nv0 + id));
            }
            put_u8(w, at + 38, (unsigned)nx);
            put_u32(w, at + 40, first);
            for (k = 0; k < 8 * nx; k++) {
                size_t bt = off[SN_SEC_CELLXK] + (size_t)(first + (uint32_t)k) * esz[SN_SEC_CELLXK];
                int l;
                if (flavour == SB_FIXED) {
                    for (l = 0; l < 9; l++) put_u16(w, bt + 2 * (size_t)l, (unsigned)(uint16_t)(int16_t)ldexp(xb[9 * k + l], -xe[k]));
                    put_u8(w, bt + 18, (unsigned)xe[k]);
                } else
                    for (l = 0; l < 9; l++) put_real(w, bt + (size_t)l * (size_t)rs, xb[9 * k + l], 0);
            }
            first += 8u * (uint32_t)nx;
        }
    }
}
