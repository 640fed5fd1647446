/* sn_crease.h -- self-collision near creases (seed 003 §3.4), internal.
 *
 * The producer side of the constraint rows: sn_crease_step (sn_crease.c)
 * keeps the collision list C and hands one row per active pair to
 * sn_rows_push, which the constraint projection (branch `cons`,
 * runtime/src/sn_constraint.h) enforces inside the CG.
 *
 * ---- TEMPORARY (until sn_constraint.h lands from branch `cons`) ----
 * sn_row and sn_rows_push below copy that branch's announced interface
 * exactly; sn_rows_push here stores the rows in a small buffer of the crease
 * state (max_active rows, SN_CREASE_ROW_BYTES each) and nothing enforces
 * them yet. At the merge: delete this block, include "sn_constraint.h"
 * instead, and drop the row buffer from SN_CREASE_STATE_BYTES.
 */
#ifndef SN_CREASE_H
#define SN_CREASE_H

#include "sn_instance.h"

#define SN_ROW_MAX_ENT 16
typedef struct sn_row {
    uint16_t vtx[SN_ROW_MAX_ENT]; /* lattice vertices */
    sn_q w[SN_ROW_MAX_ENT];       /* weights, Q30 (phi_a; negative for the far side of a contact pair) */
    sn_q dir[3];                  /* unit direction, Q30 */
    sn_q target;                  /* required value of sum_k w_k dir.v[vtx_k], per-step velocity units (Q22) */
    uint8_t n;                    /* entries used */
    uint8_t one_sided;            /* contact: >= target, enforced as equality while active */
    uint16_t source;              /* producer id, for stats */
} sn_row;
int sn_rows_push(sn_ihdr *h, const sn_row *r); /* 1 stored, 0 capacity full (counted) */
/* ---- end TEMPORARY ---- */

typedef char sn_row_fits_[sizeof(sn_row) <= SN_CREASE_ROW_BYTES ? 1 : -1];

#define SN_ROW_SRC_CREASE 2u /* sn_row.source of crease contact rows */

/* One entry of the collision list C (eq. 8), in instance memory. */
typedef struct sn_crease_pair {
    uint16_t vertex;  /* surface vertex i that penetrated */
    uint16_t tri;     /* triangle it penetrated (b: the projection of r_i on it) */
    uint16_t corner;  /* corner of tri nearest b (largest barycentric): its cell carries b's velocity */
    uint16_t pad;     /* 0 */
} sn_crease_pair;

/* Read access for tests and tools: the list C (cr_n entries) and the rows
 * pushed by the last step (temporary buffer, cr_rows entries). */
const sn_crease_pair *sn_crease_list(const sn_ihdr *h);
const sn_row *sn_crease_rows(const sn_ihdr *h);
/* The surface positions (internal units, 3 per surface vertex) the last
 * step's detection used: lattice after the pose, before the solve. */
const sn_q *sn_crease_surface(const sn_ihdr *h);

#endif /* SN_CREASE_H */
