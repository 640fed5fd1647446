/* sn_constraint.h -- constraint rows (seed 000 §4.4, Baraff-Witkin filtered
 * PCG; runtime/NUMERICS.md "Constraints and contact").
 *
 * A row is one scalar equation over the lattice velocities of the step
 * (per-step units, h folded in):
 *
 *     sum_k w_k dir . v[vtx_k] = target
 *
 * Producers push rows each step before the solve, in this order: the user's
 * constraints (sn_constraint.c), the colliders' contacts (sn_contact.c), then
 * anything else (crease collision). The step's capacity is the sum of the
 * producers' baked maxima (SN_ROWS_CAP in sn_format.h), so a producer can
 * not take another's rows. sn_rows_factor then drops rows that are (nearly)
 * dependent on earlier ones, and the CG keeps the kept rows satisfied.
 *
 * A one-sided row (contact, >= target) is enforced as an equality while it
 * is pushed: the producer decides, before the solve, whether it is active.
 * Skeleton vertices (vtx >= nF) are not unknowns: their known velocity of
 * the step moves to the right-hand side.
 */
#ifndef SN_CONSTRAINT_H
#define SN_CONSTRAINT_H

#include "sn_instance.h"

#define SN_ROW_MAX_ENT 16
typedef struct sn_row {
    uint16_t vtx[SN_ROW_MAX_ENT]; /* lattice vertices (skeleton ones contribute their known velocity to the target) */
    sn_q w[SN_ROW_MAX_ENT];       /* weights, Q30 (phi_a; negative for the far side of a contact pair) */
    sn_q dir[3];                  /* unit direction, Q30 */
    sn_q target;                  /* required value, per-step velocity units (Q22) */
    uint8_t n;                    /* entries used (<= SN_ROW_MAX_ENT) */
    uint8_t one_sided;            /* 1: contact (>= target), enforced as an equality while active */
    uint16_t source;              /* which producer (user constraint, collider, crease), for stats */
} sn_row;
typedef char sn_row_fits_[sizeof(sn_row) <= SN_ROW_BYTES ? 1 : -1];

/* per-row state of the factorization (instance array parallel to the rows) */
typedef struct sn_rowx {
    sn_q a;     /* required C^T x (Q22) */
    sn_q inv;   /* 1 / L_jj (fixed Q24), 0: row dropped */
    sn_q s;     /* scratch: C^T y, then the triangular solves (Q22 / Q19) */
    sn_q spare; /* producers' scratch while collecting (contact: its score, Q22) */
} sn_rowx;
typedef char sn_rowx_fits_[sizeof(sn_rowx) <= SN_ROWAUX_BYTES ? 1 : -1];

/* source = producer << 8 | item (the item's index within its producer, mod 256) */
#define SN_ROW_SRC(producer, item) ((uint16_t)(((unsigned)(producer) << 8) | ((unsigned)(item) & 0xFFu)))
#define SN_SRC_USER 0u    /* sn_set_constraints: item = constraint index */
#define SN_SRC_CONTACT 1u /* sn_set_colliders: item = collider index */
#define SN_SRC_CREASE 2u  /* reserved: self-collision near creases */
#define SN_ROW_PRODUCER(src) ((unsigned)(src) >> 8)

/* Store a row for the current step: 1 if stored, 0 (counted in
 * sn_stats.row_overflow, nothing written) if the step's row capacity is full,
 * n is 0 or beyond SN_ROW_MAX_ENT, a vertex is out of range or sum |w_k|
 * exceeds 2 (the bound the projection's sums rely on). */
int sn_rows_push(sn_ihdr *h, const sn_row *r);
/* The rows pushed so far this step (valid between collection and the end of the solve). */
SN_INLINE sn_row *sn_rows(sn_ihdr *h) { return WARR(h, o_row, sn_row); }

/* ---- the producers (called by sn_rows_collect, in order) ---- */
void sn_user_rows(sn_ihdr *h, uint32_t *sat);     /* sn_constraint.c */
void sn_contact_rows(sn_ihdr *h, uint32_t *sat);  /* sn_contact.c */
void sn_crease_rows_push(sn_ihdr *h, uint32_t *sat); /* sn_crease.c: the active crease contacts found by sn_crease_step */

/* ---- the solve's hooks (sn_solve.c) ---- */
/* Collect the step's rows, factorize them, and move the warm start x so the
 * rows hold for v + x; xold (or NULL) gets x as it was before the move when
 * rows are kept. Returns the rows kept (0: the solve is unconstrained). */
uint32_t sn_constrain_begin(sn_ihdr *h, sn_q *x, sn_q *xold, uint32_t *sat);
/* y -= C G^-1 C^T y over the kept rows: force_like selects the per-vertex
 * format Q(19 + k_i) (r, q) instead of Q22 (x, z, d). */
void sn_rows_filter(sn_ihdr *h, sn_q *y, int force_like, uint32_t *sat);
/* x += C G^-1 (a - C^T x): the rows hold (again, after the CG's rounding).
 * The multipliers are solved in a block exponent fitted to the residual
 * (a second call after one that fixed large residuals corrects the
 * rounding with 8 more fraction bits). */
void sn_rows_fix(sn_ihdr *h, sn_q *x, uint32_t *sat);

/* c^T y of one row over its free entries, velocity-like y (Q22). */
sn_q sn_row_dot(const sn_ihdr *h, const sn_row *r, const sn_q *y, uint32_t *sat);
/* After the CG (sn_contact.c): the free corners of the contact rows kept
 * within their yield bound; the contact rows' required values follow. */
void sn_contact_yield(sn_ihdr *h, sn_q *x, uint32_t *sat);

/* The material point under a world point (sn_force.c): its cell and
 * trilinear coordinates (Q15). */
void sn_locate(const sn_ihdr *h, const sn_vec3 *P, uint32_t *cell, uint16_t t[3]);

#endif /* SN_CONSTRAINT_H */
