/* nlref.h -- nonlinear (Green strain, St. Venant-Kirchhoff) reference of the
 * Sinew model, in double, for tests (issue 13 items 5-6).
 *
 * Same lattice, cells, skeleton, materials, mass, gravity as the baked blob:
 * nlref_open bakes the description with the host tool's library (sb_build,
 * no rigs), writes the double-flavour blob in memory and loads it with
 * tools/ref/snref.c, so the linear models (warped, global linear = unwarped)
 * and the nonlinear one share one snref_model and one set of units (internal
 * lengths, NUMERICS.md: S^ = h^2 S / m0).
 *
 * Element: the tool's (sb_integrate.c) trilinear hex plus the 9 Wilson
 * incompatible (bubble) modes P_k = 4 t_k (1 - t_k), here kept as per-cell
 * internal unknowns alpha_e (3 bubbles x 3 components) of the nonlinear
 * deformation map phi(X) = sum_a N_a p_a + sum_k P_k alpha_k; the tool
 * condenses the same modes out of its linear element, so the Hessian of this
 * energy at rest, with alpha condensed, IS the baked S^_e (tested to 1e-9).
 * Cells the tool left trilinear (bubble block not positive definite) have no
 * bubbles here either.
 *
 * Energy density (seed 000 eq. 10-12): E = 1/2 (F^T F - I),
 * W = mu E:E + lambda/2 (tr E)^2, Lame parameters of the material at each
 * quadrature point. Quadrature: a wholly inside (or wholly air) cell of one
 * material uses the 3x3x3 Gauss rule (exact to degree 5 per axis; W is of
 * degree <= 4 per axis, so exact); any other cell uses the tool's own points
 * (subdiv^3 sub-boxes x 2x2x2 Gauss, weighted by the inside fraction of the
 * point's box plus air outside, sb_box_fractions), all weights positive. The
 * tool integrates the same points (through its 27-node moment rule, equal
 * for its degree-2 integrands), so at rest the matrices agree to round-off.
 * (With the moment rule itself the first version of this reference diverged
 * on the cow's head turn; an interpolatory rule for a non-uniform weight may
 * have negative weights, harmless for the tool's quadratic form but not for
 * the quartic SVK energy. Not checked directly.)
 *
 * Static: minimise Pi(p_F, alpha) = sum_e psi_e - load . p_F (skeleton fixed at
 * the pose, load = the blob's gravity as snref applies it) by Newton's method
 * with alpha condensed per cell, dense Cholesky (shifted when the Hessian is
 * not positive definite), Armijo backtracking on Pi. Dynamic: the runtime's
 * backward Euler step (Rayleigh alpha on M, beta on the tangent frozen at the
 * step's start) solved fully nonlinearly, by the same Newton on the
 * incremental potential. Deterministic (no threads, fixed order). */
#ifndef NLREF_H
#define NLREF_H
#include "sb.h"
#include "snref.h"

typedef struct nlref {
    sb_desc d;
    sb_mesh mesh;
    sb_model o;
    sb_blob b;
    snref_model m;
    int have_d, have_mesh, have_o, have_b, have_m;
    double L;            /* metres per internal unit */
    double hc;           /* cell edge, internal units */
    unsigned nC, nF, nV;
    unsigned *efirst;    /* nC+1: quadrature points of cell e */
    double *elam, *emu;  /* per point: Lame parameters in internal units (x h^2 L / m0) */
    double *emw;         /* per point: t[3] in the cell, weight (internal units^3) */
    unsigned char *inc;  /* per cell: 1 = bubbles (incompatible modes) */
    unsigned n_trilinear;/* cells without bubbles */
    double *alpha;       /* nC*9 bubble amplitudes of the last solve (internal units) */
    double *lin_dmp;     /* scratch */
    int keep_orientation;/* 1: the line search refuses steps that invert more quadrature points
                          * (weight >= half an inside point, cells with a free corner) than the
                          * current iterate has: stays in the basin of the start. 0 (default): plain */
    /* twist penalty (nlref_set_twist; none by default) */
    unsigned ntw;        /* entries: (cell, bone) pairs with a non-zero T */
    unsigned *tw_cell;
    int *tw_joint;       /* joint whose transform moves the bone */
    double *tw_T;        /* 64 per entry */
    const snref_state *tw_s; /* pose of the bones during a solve */
} nlref;

typedef struct nlref_stats {
    unsigned iters;       /* Newton iterations */
    unsigned shifts;      /* iterations that needed a shifted (regularised) Hessian */
    double res0, res;     /* |grad Pi| (free p and alpha) at the start and at the end */
    double relres;        /* res / scale, scale = |load| + |elastic force at the start| */
} nlref_stats;

/* Bake desc (host tool library, no rigs, double flavour) and prepare. 0 or -1 (message in err). */
int nlref_open(nlref *n, const char *desc_path, char *err, size_t errn);
void nlref_close(nlref *n);

/* Cell e: energy psi_e of corner positions P (24, internal units) and bubbles A
 * (9; ignored for a trilinear cell); gradient g (33: 24 corner dofs then 9
 * bubble dofs) and Hessian H (33x33 row-major) when non-NULL. */
double nlref_cell(const nlref *n, unsigned e, const double P[24], const double A[9], double *g, double *H);
/* Cell e's Hessian at rest with the bubbles condensed (24x24), internal units:
 * must equal the blob's S^_e. Returns 0, or -1 if the bubble block is not
 * positive definite (then the trilinear block). */
int nlref_rest_condensed(const nlref *n, unsigned e, double K[576]);

/* Elastic energy and force (free rows, 3 nF) at lattice positions p (3 nV,
 * internal units), bubbles equilibrated (inner Newton per cell) when
 * relax_bubbles, else taken as alpha (NULL: zero). */
double nlref_force(nlref *n, const double *p, const double *alpha, double *f);

/* Static solve: s is an snref state at the pose (skeleton positions and the
 * load come from it, gscale and rig_scale as set; s->p is the initial guess,
 * e.g. after snref_static). On return s->p holds the nonlinear equilibrium,
 * n->alpha its bubbles. tol: on relres. */
int nlref_static(nlref *n, snref_state *s, double tol, unsigned max_iter, nlref_stats *st);

/* One dynamic step of the state s (its pose set for the end of the step with
 * snref_set_pose, as before snref_step): backward Euler with the nonlinear
 * elastic force, solved by Newton to tol. Updates s->p, s->v. */
int nlref_step(nlref *n, snref_state *s, double tol, nlref_stats *st);

/* Twist (seed 000 eq. 25-26), test-side (the tool's term is retired): the
 * 8x8 scalar matrix T_ab = kappa * integral over cell e (rest) of N_a N_b over
 * the points within radius r (mesh units) of bone sel (segments A0[i]-A1[i],
 * mesh units, model space) that have no other of the nseg bones nearer, by
 * nsub^3 sub-boxes with 2x2x2 Gauss points and a 0/1 test per point (volume
 * in internal units^3). */
void nlref_twist_cell(const nlref *n, unsigned e, int nseg, const double *A0, const double *A1, int sel, double r, double kappa,
                      int nsub, double T[64]);

/* Smallest det F over the quadrature points of weight >= wmin (internal
 * units^3; e.g. half a point's inside weight to leave air points out) of the
 * cells with at least one free corner, at
 * positions p and bubbles alpha; *ninv (if non-NULL) = points with det F <= 0. */
double nlref_min_jacobian(const nlref *n, const double *p, const double *alpha, double wmin, unsigned *ninv);

/* Add the twist penalty U = 1/2 kappa int_{within r of a bone, nearest bone} |p - T_bone(x)|^2
 * (seed 000 eq. 25-26; d relative to the rigidly moved bone) to the
 * nonlinear solves: kappa in internal units (energy / internal length^5),
 * r in mesh units, nsub as nlref_twist_cell. kappa <= 0 removes it. 0 or -1. */
int nlref_set_twist(nlref *n, double kappa, double r, int nsub);

#endif
