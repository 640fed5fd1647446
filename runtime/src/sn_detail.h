/* sn_detail.h -- details on the cut level (DETAILS, DETAIL, CELLD, CELLDK;
 * format 6.5; LEVELS.md §3 "Details on the cut level"), internal: level 1's
 * free vertices inside the cut level's cells, each a level-1 hat added to the
 * cut field (the hierarchical basis of seed 000 §3.1), with the cut element's
 * blocks [detail x corner / extra / detail] and their mass (sn_detail.c).
 */
#ifndef SN_DETAIL_H
#define SN_DETAIL_H

#include "sn_instance.h"
#include "sn_adapt.h" /* sn_key_of, sn_select_threshold: stage 3 shares level 1's selection */

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
 * 0 for inactive ones) at the details' scale (fixed Q(frac_S - dshift)).
 * lc NULL: the details' rows only (stage 3's estimate). */
void sn_detail_cell_mul(const sn_view *v, uint32_t e, uint32_t on, const sn_q yc[24], const sn_q (*yx)[3], const sn_q (*yd)[3],
                        sn_acc lc[24], sn_acc ld[3 * SN_CUT_MAXX], uint32_t *sat);
/* The details' rows only (stage 3's estimate): the rows of on, the detail
 * columns of con only (the others' yd zero: skipping them changes no bit in
 * fixed; in float at most a zero's sign) */
void sn_detail_cell_rows(const sn_view *v, uint32_t e, uint32_t on, uint32_t con, const sn_q yc[24], const sn_q (*yx)[3],
                         const sn_q (*yd)[3], sn_acc ld[3 * SN_CUT_MAXX], uint32_t *sat);

/* The same for the Galerkin mass (CELLDK's masses, scalar: no frame): mc +=
 * the corner rows' detail columns, md = the details' rows, both at MOFF's
 * scale (fixed Q(frac_M)); mc NULL: the details' rows only. */
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
    /* per detail (nD): its seat's preconditioner and k (computed once at init, sn_details_set copies them), the
     * static denominator's inverse and k (stage 3's estimate), the estimate's sums, keys and flags */
    uint32_t o_dP, o_dk, o_sP, o_sk, o_es, o_em, o_key, o_fl;
    uint32_t on, refine, coarsen, refines, coarsens, overflow; /* stage 3 (sn_detail_adapt.c): on, thresholds as keys, events */
} sn_dstate;
#define SN_DSTATE_BYTES 136u
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
/* CG iterations with a seat filled: at least SN_DETAIL_MIN_ITERATIONS while
 * at most SN_DETAIL_FEW seats are filled, SN_DETAIL_MIN_ITERATIONS_MANY above
 * (within the blob's cg_max; the cost bound at init is A_max's). With the
 * seats' block Jacobi the ramps of LEVELS.md §3 "The floor, measured" (cow
 * neck, beast elbow and neck, fixed and float, against 64 iterations): 25
 * details are within 0.003 cell over the hold at 8 (4: up to 0.83 cell); 50
 * need 32 (the cow, fixed: 0.051 / 0.055 / 0.10 cell at 8 / 12 / 16, 0.0008
 * at 32; the beast's elbow, fixed: 0.31 at 8, 0.036 at 12); every detail 32
 * (0.01-0.03). A floor against the drift, as adaptation's SN_ADAPT_MIN_ITERATIONS. */
#ifndef SN_DETAIL_MIN_ITERATIONS
#define SN_DETAIL_MIN_ITERATIONS 8u
#endif
#ifndef SN_DETAIL_MIN_ITERATIONS_MANY
#define SN_DETAIL_MIN_ITERATIONS_MANY 32u
#endif
#define SN_DETAIL_FEW 25u
uint32_t sn_detail_iterations(const sn_ihdr *h);
/* the active set replaced by ids[0..n) (validated: distinct, < nD, n <= A_max):
 * sn_details_set's path (incumbents keep their state, entrants start at 0) */
void sn_details_apply(sn_ihdr *h, sn_dstate *s, const uint16_t *ids, uint32_t n);

/* ---- stage 3: adaptation on the seats (sn_detail_adapt.c; LEVELS.md §3) ----
 * After the step, when on (sn_set_detail_adapt) and the cut level steps
 * warped: every detail's key (an active one: |c|_inf; an inactive one: the
 * static coefficient it would take, |(M g - S y)_d| / (tr sum_E S_dd / 3),
 * y the cut field's displacement and the active details), then the set:
 * incumbents while >= coarsen, entrants when >= refine, at most A_max,
 * incumbents first, then by key, ties by id (sn_select_threshold). */
void sn_detail_adapt_step(sn_ihdr *h);
/* init: the estimate's M g per detail, once when the rest shape is not modelled */
void sn_detail_adapt_init(sn_ihdr *h);

#endif /* SN_DETAIL_H */
