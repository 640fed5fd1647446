/* sn_cut.h -- the cut level (CELLX, CELLXK; format 6.3; LEVELS.md §2
 * "The cut level"), internal: level 0's cells cut at level 1's skeleton,
 * whose vertices are extra skeleton vertices of the cell (sn_cut.c).
 */
#ifndef SN_CUT_H
#define SN_CUT_H

#include "sn_instance.h"

/* Validator (sn_blob.c): CELLX (ncx entries) and CELLXK (nxk blocks). */
sn_status sn_check_cut(const sn_view *v, uint32_t ncx, uint32_t nxk);

/* Step 4 (sn_solve.c cell_forces): cell e's extras' terms lx (24 rows, the
 * cell product's scale) for its free corners fr (bit a: corner a free);
 * R the cell frame, a0 its corner 0, w0 w at a0. Only free corners' rows
 * are written (cell_forces reads no other). y: the extras' operands
 * d_x + u_x (cell frame, CELLX order compacted), which the details' rows
 * read too. */
void sn_cut_terms(sn_ihdr *h, uint32_t e, const sn_q *R, uint32_t a0, const sn_q w0[3], uint32_t fr,
                  sn_q y[SN_CUT_MAXX][3], sn_acc lx[24], uint32_t *sat);

/* Outputs and the level switch (sn_embed.c, sn_level.c): the correction to
 * the trilinear field in a cell at t (Q15); free vertices' values in vf,
 * skeleton vertices' (nF..nV-1) in vs. */
void sn_cut_interp(const sn_view *v, uint32_t cell, const uint32_t t[3], const sn_q *vf, const sn_q *vs, sn_acc acc[3]);

/* Rows (sn_constraint.c, sn_contact.c, sn_crease.c): the lattice vertices
 * and weights (Q30 / float, >= 0 but for a -1 LSB rounding, summing to one) of the point at t (Q15) in
 * cell under the surface's field: the cell's 8 corners (trilinear on a plain
 * lattice), on the cut level then the extras of the child holding the point
 * (skeleton vertices). Returns the entries: 8 plain, <= 15 cut. */
#define SN_CUT_POINT_MAX 15
uint32_t sn_point_weights(const sn_view *v, uint32_t cell, const uint32_t t[3], uint16_t vtx[SN_CUT_POINT_MAX],
                          sn_q w[SN_CUT_POINT_MAX]);

/* The contacts' prefilter (sn_contact.c): the largest |value at x - the cell's
 * trilinear value at x| (max-norm over the components) over every cell's
 * extras x, free vertices' values in vf, skeleton vertices' (nF..nV-1) in vs;
 * at most SN_LIM (fixed). A point's cut value differs from its trilinear one
 * by at most this (phi' >= 0, sum <= 1). */
sn_q sn_cut_dev(const sn_view *v, const sn_q *vf, const sn_q *vs);

#endif /* SN_CUT_H */
