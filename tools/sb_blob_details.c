/* sb_blob_details.c -- the cut level's details in the blob (format 6.5:
 * DETAILS, DETAIL, CELLD, CELLDK; sn_format.h, runtime/LEVELS.md §3). */
#include "sb_blob_int.h"

/* the record, the details' rest points, per cell their list and blocks with
 * their mass; -1 (sb_fail) for a refine threshold beyond the format, a block
 * beyond its format sets w->err */
int sb_blob_write_details(const sb_model *o, wr_t *w, const uint32_t *off, const uint32_t *esz, double h, double m0,
                          double U, const double *root, const sb_blob *b)
{
    const int flavour = w->flavour, rs = w->rs;
    int i, k;
    const sb_cut *cut = o->cut;
    const int N3 = 3 * SB_CUT_NL, NL = SB_CUT_NL;
    uint32_t first = 0;
    size_t at = off[SN_SEC_DETAILS];
    int dshift = 0;
    if (flavour == SB_FIXED) { /* a detail's own block can exceed the corners' (a cell-centre hat spans 8 children):
                                * its blocks in Q(frac_S - dshift), the smallest shift keeping |entry| <= 2^27 */
        double mx = 0;
        for (i = 0; i < o->nc; i++) {
            const double *KE = cut->K + (size_t)(N3 * N3) * (size_t)i;
            int r, c2, l;
            for (r = 8 + cut->cnx[i]; r < 8 + cut->cnx[i] + cut->cnd[i]; r++)
                for (c2 = 0; c2 < 8 + cut->cnx[i] + cut->cnd[i]; c2++)
                    for (l = 0; l < 9; l++) mx = fmax(mx, fabs(KE[(size_t)N3 * (size_t)(3 * r + l / 3) + (size_t)(3 * c2 + l % 3)]));
        }
        mx = ldexp(h * h / m0 * mx, b->frac_S);
        while (dshift < SN_DETAIL_SHIFT_MAX && rnd(ldexp(mx, -dshift)) > 134217728.0) dshift++;
    }
    if (o->det_refine / U * 4194304.0 > (double)SN_ADAPT_MAX) return sb_fail("details refine %g mesh units out of range (0..%g)", o->det_refine, U * 256);
    put_u16(w, at, (unsigned)o->det_max);
    put_u8(w, at + 2, (unsigned)dshift);
    put_real(w, at + 8, o->det_refine / U, SN_Q_LEN);
    put_real(w, at + 8 + (size_t)rs, fmin(o->det_coarsen, o->det_refine) / U, SN_Q_LEN);
    for (i = 0; i < cut->nd; i++) {
        size_t dt = off[SN_SEC_DETAIL] + (size_t)i * esz[SN_SEC_DETAIL];
        put_u16(w, dt, (unsigned)cut->dcell[i]);
        put_u8(w, dt + 2, (unsigned)cut->dpoint[i]);
        for (k = 0; k < 3; k++) put_real(w, dt + 4 + (size_t)(k * rs), (cut->dx[3 * i + k] - root[k]) / U, SN_Q_LEN);
    }
    for (i = 0; i < o->nc; i++) {
        const double *KE = cut->K + (size_t)(N3 * N3) * (size_t)i, *ME = cut->M + (size_t)(NL * NL) * (size_t)i;
        size_t ct = off[SN_SEC_CELLD] + (size_t)i * SN_ELEM_CELLD;
        int q, m = 0, nx = cut->cnx[i], nd = cut->cnd[i], j, c;
        for (q = 0; q < 27; q++) {
            int id;
            if (!((q % 3) & 1) && !((q / 3 % 3) & 1) && !((q / 9) & 1)) continue; /* a corner */
            id = cut->dsub[27 * i + q];
            put_u16(w, ct + 2 * (size_t)m++, id < 0 ? SN_CUT_NONE : (unsigned)id);
        }
        put_u8(w, ct + 38, (unsigned)nd);
        put_u32(w, ct + 40, first);
        for (j = 0; j < nd; j++)
            for (c = 0; c < 8 + nx + nd; c++) { /* columns: corners, extras, details from j on (locals 8 + nx + ..) */
                int r = 8 + nx + j, l, e = 0;
                size_t bt = off[SN_SEC_CELLDK] + (size_t)first * esz[SN_SEC_CELLDK];
                double B[9], mx = 0, mass = ME[NL * r + c] / m0;
                if (c >= 8 + nx && c < r) continue;
                for (l = 0; l < 9; l++) {
                    B[l] = h * h / m0 * KE[(size_t)N3 * (size_t)(3 * r + l / 3) + (size_t)(3 * c + l % 3)];
                    if (flavour == SB_FIXED) B[l] = ldexp(B[l], b->frac_S - dshift);
                    mx = fmax(mx, fabs(B[l]));
                }
                if (!(mx <= 134217728.0)) w->err = 1; /* 2^27: the runtime's entry bound */
                if (flavour == SB_FIXED) {
                    while (e < SN_CELLK_EXP_MAX && rnd(ldexp(mx, -e)) > (double)SN_CELLK_M_MAX) e++;
                    for (l = 0; l < 9; l++)
                        put_u16(w, bt + 2 * (size_t)l, (unsigned)(uint16_t)(int16_t)fmax(-SN_CELLK_M_MAX, fmin(SN_CELLK_M_MAX, rnd(ldexp(B[l], -e)))));
                    put_u8(w, bt + 18, (unsigned)e);
                    put_real(w, bt + 20, mass, b->frac_M);
                    if (!(fabs(ldexp(mass, b->frac_M)) <= 134217728.0) || (c == r && !(rnd(ldexp(mass, b->frac_M)) > 0))) w->err = 1;
                } else {
                    for (l = 0; l < 9; l++) put_real(w, bt + (size_t)l * (size_t)rs, B[l], 0);
                    put_real(w, bt + 9 * (size_t)rs, mass, 0);
                    if (!(fabs(mass) <= 134217728.0) || (c == r && !(mass > 0))) w->err = 1;
                }
                first++;
            }
    }
    return 0;
}
