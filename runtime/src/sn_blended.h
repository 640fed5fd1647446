/* sn_blended.h -- what the blended mode (sn_blended.c, SN_MODE_BLENDED:
 * seed 000 §4.5) shares with the warped solve (sn_solve.c): the common
 * right-hand side and the CG arithmetic, so both modes round alike. */
#ifndef SN_BLENDED_H
#define SN_BLENDED_H

#include "sn_instance.h"

/* Step 5's right-hand side into b (free rows); elastic = 0 leaves out the
 * cell terms (elastic force, -K~ w) but still sets the energy (sn_solve.c). */
void sn_rhs(sn_ihdr *h, sn_q *b, int elastic, uint32_t *sat);
/* acc += R S^_e R^T d for one cell (CELLK record K, CELLS record cl) over its free corners with mask[a] != 0 (sn_solve.c) */
void sn_cell_stiff_acc(const sn_ihdr *h, const unsigned char *K, const unsigned char *cl, const sn_q *R, const uint8_t *mask,
                       const sn_q *d, sn_acc *acc, uint32_t *sat);

/* A CG dot product: fixed, m * 2^e in Q41 units (block floating point);
 * float, m (e = 0). */
typedef struct { sn_acc m; int e; } sn_cgdot;
sn_cgdot sn_cg_dot(const sn_q *a, const sn_q *b, const uint8_t *kk, uint32_t n);
/* num/den as a CG step (fixed Q28), 0 when either is <= 0; clamps counted. */
sn_q sn_cg_ratio(sn_cgdot num, sn_cgdot den, uint32_t *clamps);
/* 1 when r.z is at the CG's rounding floor (sn_solve.c at_floor): that
 * iteration takes alpha = beta = 0 */
int sn_cg_flat(sn_cgdot rz, uint32_t n);
/* y += s x;  d = z + beta d  (s, beta from sn_cg_ratio) */
void sn_cg_axpy(sn_q *y, sn_q s, const sn_q *x, uint32_t n, uint32_t *sat);
void sn_cg_dir(sn_q *d, const sn_q *z, sn_q beta, uint32_t n, uint32_t *sat);

/* Steps 5-7 in SN_MODE_BLENDED (sn_blended.c): per region the step system
 * in the region bone's frame, PCG, the merge dv = sum_r W^r dv^r, update. */
void sn_blended_solve(sn_ihdr *h, uint32_t *sat);

/* Instance-side bit of sn_view.flags (the blob's flags are one byte): set
 * by sn_instance_init when the memory also holds the blended mode's arrays,
 * which follow the layout at v.instance_bytes. */
#define SN_VIEW_BLENDED 0x80000000u

/* Bytes the blended mode needs beyond sn_instance_size (sn_blended.c). */
uint32_t sn_blended_bytes(uint32_t nF, uint32_t nC);

#endif /* SN_BLENDED_H */
