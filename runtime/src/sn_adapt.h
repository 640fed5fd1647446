/* sn_adapt.h -- adaptation on level 1 (seed 000 §4.7; sn_adapt.c,
 * runtime/LEVELS.md §3): which level-1 detail vertices are in the step's
 * solve, and the bookkeeping after it. */
#ifndef SN_ADAPT_H
#define SN_ADAPT_H

#include "sn_instance.h"

/* an ordered 32-bit key of a non-negative length (fixed: the integer; float:
 * its bits, which order as the values do) */
SN_INLINE uint32_t sn_key_of(sn_q x) {
#if defined(SN_FLOAT)
    uint32_t u;
    memcpy(&u, &x, 4);
    return u & 0x7FFFFFFFu; /* |x| */
#else
    return x < 0 ? (uint32_t)(-(int64_t)x) : (uint32_t)x;
#endif
}
/* The selection's threshold (sn_adapt.c): the smallest T with at most max of
 * the wanted entries (bit 1 of m[i]) keyed above T (key NULL: all 0). */
uint32_t sn_select_threshold(const uint8_t *m, const uint32_t *key, uint32_t n, uint32_t max);

/* ADAPT record against the pair (validator): A_max <= nF of level 1, 0 <=
 * coarsen <= refine <= SN_ADAPT_MAX, reserved 0, only in a two-level blob. */
sn_status sn_check_adapt(const sn_view *top, const sn_view *fine);
/* Extra instance bytes the blob needs (the activity mask; 0 without ADAPT). */
uint32_t sn_adapt_bytes(const sn_view *top);
/* At init: the instance fields from the record (adaptation on if present). */
void sn_adapt_init(sn_ihdr *h);
/* After reset, a switch to level 1 or sn_set_adapt: the first selection
 * (zero details: everything joins iff refine is 0, lowest indices first
 * within A_max) and the inactive vertices projected onto the coarse field. */
void sn_adapt_begin(sn_ihdr *h, uint32_t *sat);
/* The mask for the step's solve (1: in it), or NULL when every vertex is
 * (adaptation off, level 0, blended mode, or all detail active). */
const uint8_t *sn_adapt_mask(const sn_ihdr *h);
/* The Galerkin reduction of the step's solve onto the active set (sn_solve.c):
 * an inactive vertex's dv is the coarse field's, P: dv_w = sum_a phi_a dv_c(a)
 * over the level-1 vertices c(a) at its level-0 cell's corners (skeleton
 * ones carry no unknown: 0). expand: v_w = (P v)_w on the inactive rows;
 * restrict: v_c += phi_a v_w (a force: in c's exponent), then v_w = 0 (P^T). */
void sn_adapt_expand(sn_ihdr *h, const uint8_t *mask, sn_q *v, uint32_t *sat);
void sn_adapt_restrict(sn_ihdr *h, const uint8_t *mask, sn_q *v, uint32_t *sat);
/* The refine estimate of the inactive vertices from the step's initial
 * residual r (before restrict): |C_ww r_w| (max-norm), z scratch; kept in x's
 * inactive rows (no unknown there during the PCG) until sn_adapt_keys moves
 * them into acc, before x is expanded. */
void sn_adapt_estimate(sn_ihdr *h, const uint8_t *mask, const sn_q *r, sn_q *z, sn_q *x, uint32_t *sat);
void sn_adapt_keys(sn_ihdr *h, const uint8_t *mask, const sn_q *x);
/* CG iterations of a reduced solve: at least SN_ADAPT_MIN_ITERATIONS (within
 * the blob's cg_max). The preconditioner is the lattice's IC(0) restricted to
 * the active set and scaled per source row (sn_adapt_scales), not the
 * reduced operator's own factor. With the scales no run of
 * tests/test_runtime_adapt.c diverges at 4 or 8, but a held steady state
 * flips vertices every step (the refine estimate rides on the unconverged
 * residual): the cow at 4, the beast at 8; at 16 neither does. */
#ifndef SN_ADAPT_MIN_ITERATIONS
#define SN_ADAPT_MIN_ITERATIONS 16u
#endif
uint32_t sn_adapt_iterations(const sn_ihdr *h);
/* The masked preconditioner's per-vertex scales (Q30, (0, 1]) for the current mask (sn_adapt.c). */
const sn_q *sn_adapt_scales(const sn_ihdr *h);
/* After the step's update and limits: details, selection, projection. */
void sn_adapt_step(sn_ihdr *h, uint32_t *sat);
/* The mask for the state hash (*n bytes, 1: in the solve), NULL without ADAPT:
 * sn_state_hash adds the inactive indices (none: the plain level-1 hash). */
const uint8_t *sn_adapt_mask_bytes(const sn_ihdr *h, uint32_t *n);

#endif /* SN_ADAPT_H */
