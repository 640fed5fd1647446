/* sn_crease.h -- self-collision near creases (seed 003 §3.4), internal.
 *
 * sn_crease_step (sn_crease.c, stage 3b of the step) keeps the collision list
 * C and finds its active prefix n_a; sn_crease_rows_push, a producer of the
 * constraint rows (sn_constraint.h), hands one contact row per active pair
 * to the projection, which enforces it inside the CG.
 */
#ifndef SN_CREASE_H
#define SN_CREASE_H

#include "sn_constraint.h"


/* One entry of the collision list C (eq. 8), in instance memory. */
typedef struct sn_crease_pair {
    uint16_t vertex;  /* surface vertex i that penetrated */
    uint16_t tri;     /* triangle it penetrated (b: the projection of r_i on it) */
    uint16_t corner;  /* corner of tri nearest b (largest barycentric): its cell carries b's velocity */
    uint16_t pad;     /* 0 */
} sn_crease_pair;

/* Read access for tests and tools: the list C (cr_n entries). The rows the
 * last step pushed are sn_rows(h)[0, n_rows) with SN_ROW_PRODUCER(source)
 * == SN_SRC_CREASE (cr_rows of them). */
const sn_crease_pair *sn_crease_list(const sn_ihdr *h);
/* The surface positions (internal units, 3 per surface vertex) the last
 * step's detection used: lattice after the pose, before the solve. */
const sn_q *sn_crease_surface(const sn_ihdr *h);

#endif /* SN_CREASE_H */
