/* sb_retarget.h -- rig retargeting (seed 003 §4.4, eq. 15-16): map character
 * A's control lattice onto character B, estimate the map's Jacobian at every
 * lattice vertex, and carry a generalized-force rig from A to B through
 * displacements (Q_A -> q_A by eq. 10 on A -> q_B,i = J_i q_A,i -> Q_B by
 * eq. 10 on B). Host side, C99 + libc + libm; allocates.
 *
 * The map h (eq. 15) is the trilinear interpolation of new positions h_i of
 * A's lattice vertices (mesh units of B). Cost, every term dimensionless:
 *
 *   C(h) = w_skel C_skel + w_surf C_surf + C_distort
 *
 *   C_skel    = 1/n_s sum_k |h(p_k) - pbar_k|^2 / L^2 over skeleton samples:
 *               every joint of A at B's joint of the same name, and
 *               `bone_samples` evenly spaced interior points of every bone of
 *               A (parent -> child, both matched) at the same fractions of
 *               B's bone. L = B's bounding-box diagonal.
 *   C_surf    = vertex correspondence (A and B have the same surface vertex
 *               count and `corr` allows it): 1/n sum_k |h(s_k) - sbar_k|^2 / L^2.
 *               Otherwise closest points, symmetric, recomputed once per outer
 *               round and held fixed inside it:
 *               1/2 [ 1/nA sum_{k in A} |h(s_k) - cp_B(h(s_k))|^2
 *                   + 1/nB sum_{m in B} |cp_hA(b_m) - b_m|^2 ] / L^2
 *               where cp_B is the closest point of B's surface and cp_hA the
 *               closest point of A's mapped surface (a fixed triangle and
 *               barycentric weights, so the term is linear in h).
 *   C_distort = 1/n_d sum |D h|^2 / c^2 over the second differences of h on
 *               A's grid: h_a - 2 h_b + h_c for three consecutive lattice
 *               vertices along an axis and h_a - h_b - h_c + h_d for the four
 *               corners of a lattice face (a mixed difference). They measure
 *               how much the deformation of one lattice edge differs from its
 *               neighbour's and vanish exactly for affine maps, so an affine
 *               copy of A is matched at zero cost. c = A's cell times the
 *               size ratio L / L_A (the expected mapped edge).
 *
 * With the closest points held fixed C is quadratic in h; each round solves
 * it by preconditioned conjugate gradients on the analytic gradient (the
 * Hessian-vector product is the gradient with the targets set to zero); the
 * L-BFGS-B of tools/sb_lbfgsb.c on the same cost and gradient is an option
 * (slower on this ill-conditioned quadratic: the distortion term is a
 * biharmonic-like operator).
 *
 * The Jacobian J_i (eq. 16) minimizes sum_j |J_i e_ij - ebar_ij|^2 over the
 * lattice vertices j sharing a cell with i (e_ij = x_j - x_i in A,
 * ebar_ij = h_j - h_i): the linear least-squares (affine Procrustes) solution
 * J_i = (sum ebar e^T)(sum e e^T)^-1, exact for an affine map. */
#ifndef SB_RETARGET_H
#define SB_RETARGET_H

#include "sb.h"

/* a character loaded for retargeting: description, mesh, model with rigs */
typedef struct sb_rt_char {
    sb_desc d;
    sb_mesh m;
    sb_model o;
    int loaded;
} sb_rt_char;
int sb_rt_char_load(const char *desc_path, sb_rt_char *c);   /* 0 or -1 (sb_error) */
/* level 1 of a 'levels 2' description (sb_level_desc / sb_level_model), without its rigs */
int sb_rt_char_load_level1(const char *desc_path, sb_rt_char *c);
void sb_rt_char_free(sb_rt_char *c);

enum { SB_RT_CORR_AUTO = -1, SB_RT_CORR_CLOSEST = 0, SB_RT_CORR_VERTEX = 1 };

typedef struct sb_rt_opts {
    double w_skel, w_surf;  /* eq. 15 weights (C_distort has weight 1) */
    int corr;               /* SB_RT_CORR_*: AUTO = vertex correspondence iff same vertex count */
    int bone_samples;       /* interior samples per bone in C_skel */
    int rounds;             /* closest-point rounds (vertex correspondence: 1) */
    double round_tol;       /* stop when the cost falls by less than this fraction in a round */
    int cg_max;             /* CG iterations per round */
    double cg_tol;          /* CG stops at |grad| <= cg_tol |grad at the round's start| */
    int optimizer;          /* SB_RT_OPT_CG (default) or SB_RT_OPT_LBFGSB (tools/sb_lbfgsb.c, unbounded, same stopping rule) */
    int verbose;            /* progress lines on stdout */
    const char *joint_map;  /* "A_JOINT=B_JOINT,..." : joints of A matched to a B joint of another name (NULL: none) */
    const char *skip;       /* "A_JOINT,..." : joints of A left out of C_skel (NULL: none) */
} sb_rt_opts;
enum { SB_RT_OPT_CG = 0, SB_RT_OPT_LBFGSB = 1 };
void sb_rt_defaults(sb_rt_opts *o);

/* one quadratic term f |sum_k w_k h_{v_k} - t|^2 */
#define SB_RT_TERM_MAX 24
typedef struct sb_rt_term {
    int n;
    int v[SB_RT_TERM_MAX];
    double w[SB_RT_TERM_MAX];
    double t[3];
    double f;
} sb_rt_term;

typedef struct sb_retarget {
    const sb_model *A, *B;
    const sb_mesh *mA, *mB;
    sb_rt_opts opt;
    int nv;                 /* A's lattice vertices */
    double *h;              /* nv x 3 mapped positions (B mesh units) */
    double L, LA;           /* bounding-box diagonals of B and A (mesh units) */
    double cref;            /* distortion length c (B mesh units) */
    int corr;               /* the correspondence in use (SB_RT_CORR_VERTEX / CLOSEST) */
    int njm;                /* matched joints */
    int *jA, *jB;           /* sorted joint indices of each match */
    /* terms: [0, nsk) skeleton, [nsk, nsk + nsf) surface, the rest distortion */
    int nsk, nsf, nd, nterm;
    sb_rt_term *term;
    int nsa;                /* surface terms A -> B (the rest of the surface terms are B -> A) */
    /* results of the last solve */
    double c_skel, c_surf, c_dist, cost, gnorm;
    double skel_rms, skel_max;      /* |h(p_k) - pbar_k|, B mesh units */
    double surf_rms, surf_max;      /* |surface term residual|, B mesh units */
    int rounds, cg_iters;
    double secs;
    double *J;              /* nv x 9 row-major (sb_rt_jacobians) */
} sb_retarget;

/* Set up A -> B: match joints by name (every joint of A not in opt->skip must
 * exist in B under its own name or the name opt->joint_map gives it, else an
 * error naming the missing ones), sample the skeleton, build the
 * distortion stencils, initial h = the affine least-squares fit of A's
 * skeleton samples to B's. 0 or -1 (sb_error). */
int sb_rt_init(sb_retarget *rt, const sb_model *A, const sb_mesh *mA, const sb_model *B, const sb_mesh *mB, const sb_rt_opts *opt);
void sb_rt_free(sb_retarget *rt);
/* Minimize C (rounds of closest points + CG). 0 or -1 (non-finite cost, no progress). */
int sb_rt_solve(sb_retarget *rt);
/* C at positions x (nv x 3) with the current terms; grad (nv x 3) if non-NULL;
 * parts (skel, surf, distort) if non-NULL. */
double sb_rt_cost(const sb_retarget *rt, const double *x, double *grad, double parts[3]);
/* rebuild the surface terms from the current h (closest points) */
int sb_rt_update_surface(sb_retarget *rt);
/* J_i of every lattice vertex of A (eq. 16) into rt->J. 0 or -1. */
int sb_rt_jacobians(sb_retarget *rt);

/* ---- eq. 10 at rest, skeleton held: S_FF q_F = Q_F ---- */
/* q (nv x 3, mesh units; skeleton rows 0) from Q (nf x 3, newtons); relative residual, or -1 */
double sb_rt_static(const sb_model *o, const double *Q, double *q);
/* Q_F = S_FF q_F (+ S_FS q_S = 0): newtons from q (nv x 3, mesh units; skeleton rows ignored) */
void sb_rt_force_of(const sb_model *o, const double *q, double *Q);
/* surface positions (mesh units, ns x 3) of the rest lattice displaced by q (nv x 3, or NULL) */
void sb_rt_surface(const sb_model *o, const double *q, double *s);
/* sum of the named rigs' generalized forces at eta = 1 (nf x 3, newtons): names
 * comma-separated; 0 or -1 (unknown rig, listed) */
int sb_rt_rig_force(const sb_model *o, const char *names, double *Q, int *control);

/* rig transfer (seed 003 §4.4): Q_A (nf_A x 3, N) -> q_A (eq. 10 on A) ->
 * qbar_i = J_i q_A,i at the mapped vertex h(x_i) -> B's lattice field q_B
 * (free vertices; skeleton vertices 0) fitted by least squares to the
 * transferred field at B's surface vertices (weight 1; the field at the
 * vertex's preimage in A's mapped lattice, or at the closest point of A's
 * mapped surface for a vertex outside it) and at A's mapped lattice vertices
 * and 2x2x2 points per cell inside A's mesh (weight 0.01), with a 1e-6
 * second-difference smoothing (B's lattice is its own grid, not h(K) as in
 * the paper) -> Q_B = S_FF q_B (nf_B x 3, N).
 * An empty overlap (no surface vertex of B in A's mapped lattice) is an error.
 * qA, qB (nv x 3, mesh units of A and B) out if non-NULL. Needs
 * sb_rt_jacobians. 0 or -1. */
typedef struct sb_rt_transfer_stats {
    int inside, outside;    /* B free vertices with / without a sample in one of their cells */
    int surf_inside, surf_outside;  /* B surface vertices inside A's mapped lattice / valued from the closest mapped surface point */
    double qA_max, qB_max;  /* largest |q| (mesh units of A / B) */
    double static_res;      /* relative residual of the static solve on A */
} sb_rt_transfer_stats;
int sb_rt_transfer(const sb_retarget *rt, const double *QA, double *QB, double *qA, double *qB, sb_rt_transfer_stats *st);

/* Write a generalized-force rig of B (Q: nf_B x 3, newtons, at eta = 1) as a
 * rig file (tools/sb_rigfile.c, DESCRIPTION.md "Rig files": keyed by lattice
 * rest positions, with B's mesh identity), which B's description includes
 * with 'rig_file NAME FILE CONTROL'. comment: lines written as '# ...'.
 * Refuses a zero or non-finite force. 0 or -1 (sb_error; nothing written). */
int sb_rt_write_rig(const char *path, const sb_model *B, const sb_mesh *mB, const double *Q, const char *comment);
/* the same with one fit per level of B (nlev 2: B[1], Q[1] its level 1, sb_rt_char_load_level1) */
int sb_rt_write_rig_levels(const char *path, int nlev, const sb_model *const *B, const sb_mesh *mB, const double *const *Q, const char *comment);

#endif /* SB_RETARGET_H */
