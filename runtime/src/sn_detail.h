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

/* ---- stage 2: the step reads the details (sn_detail_step.c; LEVELS.md §3) ----
 * The instance's detail region (after adaptation's, at v.instance_bytes + ad_bytes;
 * 0 without DETAILS): this header, then per seat (A_max) the stiffness
 * / mass accumulator (acc, 3 x 8 B), coefficient and velocity (Q22, world
 * frame: the detail's offset from the coarse field's dyadic value, 0 at rest),
 * the CG's x, r, d, q over nF + A_max rows (the cut level's free rows first,
 * then the seats: one vector for the dot products, the axpys and a
 * preconditioner of the full length), per seat its preconditioner block (6
 * reals, frac_P), per cell its active mask (the kernels' `on`), seat -> detail
 * and detail -> seat (u16, SN_CUT_NONE: none), the force exponents k over the
 * nF + A_max rows. */
typedef struct sn_dstate {
    uint32_t bytes, amax, nd, n, nF, nC, bmin, pad; /* n: seats filled (the active set, <= amax); bmin: the k table's */
    uint32_t o_acc, o_coef, o_vel, o_x, o_r, o_d, o_q, o_P, o_on, o_seat, o_of, o_kk; /* from the region's start */
} sn_dstate;
#define SN_DSTATE_BYTES 80u
typedef char sn_dstate_fits_[sizeof(sn_dstate) == SN_DSTATE_BYTES ? 1 : -1];
#define DT(s, off, T) ((T *)(void *)((unsigned char *)(s) + (s)->off))

/* the region's bytes for a blob (its top view): 0 without DETAILS */
uint32_t sn_detail_bytes(const sn_view *top);
/* the region, NULL when the blob has no details */
sn_dstate *sn_detail_region(const sn_ihdr *h);
/* init: the region (no seat filled) */
void sn_detail_init(sn_ihdr *h);
/* reset: the set emptied */
void sn_detail_reset(sn_ihdr *h);
/* the region if details step this step (a seat filled, the cut level in
 * force, not the blended mode), else NULL */
sn_dstate *sn_detail_live(const sn_ihdr *h);
/* state hash: the seats' details, coefficients, velocities, x (none filled: unchanged) */
uint64_t sn_detail_hash(const sn_ihdr *h, uint64_t hsh);
/* the seats' preconditioner: z_s = P_s r_s (scalar block Jacobi: the seat's
 * own diagonal averaged, no frame), r and z the seat rows */
void sn_detail_precond(const sn_ihdr *h, const sn_dstate *s, const sn_q *r, sn_q *z, uint32_t *sat);
/* CG iterations with a seat filled: at least SN_DETAIL_MIN_ITERATIONS (within
 * the blob's cg_max). With the seats' block Jacobi the cow's ramp
 * (LEVELS.md §3, test_runtime_dstep --study) at the cut level's 4 drifts
 * from the converged run: 1.32 cells with 50 details, 11.8 with every one;
 * at 16: 0.085 and 0.378 (32: 0.0006, 0.034). A floor against the drift,
 * as adaptation's SN_ADAPT_MIN_ITERATIONS; accuracy wants 32 (sn_set_iterations). */
#ifndef SN_DETAIL_MIN_ITERATIONS
#define SN_DETAIL_MIN_ITERATIONS 16u
#endif
uint32_t sn_detail_iterations(const sn_ihdr *h);

#endif /* SN_DETAIL_H */
