/* sn_detail.h -- details on the cut level (DETAILS, DETAIL, CELLD, CELLDK;
 * format 6.5; LEVELS.md §3 "Details on the cut level"), internal: level 1's
 * free vertices inside the cut level's cells, each a level-1 hat added to the
 * cut field (the hierarchical basis of seed 000 §3.1), with the cut element's
 * blocks [detail x corner / extra / detail] and their mass (sn_detail.c).
 */
#ifndef SN_DETAIL_H
#define SN_DETAIL_H

#include "sn_instance.h"

/* Validator (sn_blob.c): the table's counts of DETAILS, DETAIL, CELLD,
 * CELLDK and CELLX (the details live on the cut level only). */
sn_status sn_check_details(const sn_view *v, uint32_t nhd, uint32_t nd, uint32_t ncd, uint32_t ndk, uint32_t ncx);

/* Stage 2 (not yet called by the step): cell e's active details' share of
 * the cut element's product in the cell frame. on: bit j = the cell's j-th
 * detail (CELLD order, compact) active; yc the corners' operand (24, Q22, as
 * cell_forces' d), yx the extras' (CELLX order; NULL: the mat-vec, extras have
 * no unknown), yd the details' (CELLD order). lc += the corner rows' detail
 * columns at the corners' scale (fixed: Q(frac_S), shifted up by dshift, the
 * part clamped first, counted in *sat); ld = the details' rows (3 per detail,
 * 0 for inactive ones) at the details' scale (fixed Q(frac_S - dshift)). */
void sn_detail_cell_mul(const sn_view *v, uint32_t e, uint32_t on, const sn_q yc[24], const sn_q (*yx)[3], const sn_q (*yd)[3],
                        sn_acc lc[24], sn_acc ld[3 * SN_CUT_MAXX], uint32_t *sat);

/* The same for the Galerkin mass (CELLDK's masses, scalar: no frame): mc +=
 * the corner rows' detail columns, md = the details' rows, both at MOFF's
 * scale (fixed Q(frac_M)). */
void sn_detail_cell_mass(const sn_view *v, uint32_t e, uint32_t on, const sn_q yc[24], const sn_q (*yx)[3], const sn_q (*yd)[3],
                         sn_acc mc[24], sn_acc md[3 * SN_CUT_MAXX]);

/* The surface (stage 2, for sn_embed.c): acc (the cut field's, Q52 fixed) +=
 * the active details' term at t (Q15) in cell: seat_of[d] the seat of detail d
 * (SN_CUT_NONE: inactive), coef[3 s] the seat's coefficient (Q22). */
void sn_detail_interp(const sn_view *v, uint32_t cell, const uint32_t t[3], const uint16_t *seat_of, const sn_q *coef,
                      sn_acc acc[3]);

#endif /* SN_DETAIL_H */
