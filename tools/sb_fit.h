/* sb_fit.h -- rig fitting (seed 003 §4.2-4.3) for sinew-rig: point-drag
 * template fitting, pose fitting to feature points, surface rigs from a
 * target mesh. Everything at the static equilibrium of eq. 10 in double
 * precision (the reference model tools/ref/snref.c on a float64 bake), with
 * the factor of A(alpha) kept for the many solves of an optimization, and
 * L-BFGS-B (tools/sb_lbfgsb.h). Definitions of the costs: sb_fit.c and
 * tools/DESCRIPTION.md "Rig fitting (sinew-rig)". */
#ifndef SB_FIT_H
#define SB_FIT_H

#include "sb.h"
#include "sb_lbfgsb.h"
#include "snref.h"

typedef struct sb_fit {
    char desc[1024];
    sb_model o;             /* the bake (float64) */
    sb_blob b;
    sb_mesh mesh;           /* the description's mesh (identity of rig files) */
    sb_desc d;              /* the description (template rigs re-integrated by sb_fit_template) */
    snref_model m;          /* the reference model of the blob */
    snref_state s;
    double off[3];          /* description coordinates = snref positions (mesh units) + off */
    double nscale;          /* newtons -> right-hand-side units: h^2 / (m0 U) */
    struct snref_band *B;   /* factor of A at the current pose (sb_fit_set_pose) */
    double *p0;             /* nV x 3: static equilibrium at the current pose (internal units) */
    double *surf0;          /* nS x 3: its surface, description coordinates */
    int quiet;
    int level;              /* level of detail the bake is (sb_fit_open_level) */
    /* sb_fit_pose: the shape the feature points are read on: 0 the rigidly framed
     * ("skinned") lattice (default), 1 the static equilibrium at the pose with the
     * rigs times pose_rig_scale (one solve per evaluation, sag included) */
    int pose_static;
    double pose_rig_scale;
    /* sb_fit_surface: 0 (default) conjugate gradients on the normal equations
     * (the cost is quadratic, the solve exact), 1 L-BFGS-B (the former method) */
    int surf_lbfgsb;
} sb_fit;

/* bake desc (float64), load the reference model, read the mesh. 0, or -1 with a message on stderr */
int sb_fit_open(sb_fit *F, const char *desc, int quiet);
/* the same on one level of detail: 0 as sb_fit_open, 1 level 1 of a 'levels 2' description alone
 * (sb_bake_level1: its own lattice and rigs; F->d stays the description as written) */
int sb_fit_open_level(sb_fit *F, const char *desc, int level, int quiet);
void sb_fit_close(sb_fit *F);
/* pose the model (transforms per joint), factor A, solve the static equilibrium
 * with every rig at the current controls times rig_scale (0: rigs off) into p0/surf0. 0 or -1 */
int sb_fit_set_pose(sb_fit *F, const snref_xform *pose, double rig_scale);
/* surface of lattice positions lat (nV x 3, internal units) in description coordinates */
void sb_fit_surface_of(const sb_fit *F, const double *lat, double *surf);
/* rigidly framed ("skinned") surface at pose, description coordinates */
void sb_fit_skinned_surface(sb_fit *F, const snref_xform *pose, double *surf);

/* Pose fit (§4.3, C_features): local rotations of the joints listed (rotation
 * vectors, bounds [-pi, pi] per component) minimizing
 *   C_features = (1/N) sum_k |p_k(alpha) - pbar_k|^2 / c^2
 * (p_k: surface vertex feat[k] of the skinned shape at the pose, or of the
 * static equilibrium if F->pose_static; pbar_k its target, c the cell edge).
 * local (nJ x 4, x y z w) in: the start and the joints not fitted; out: the
 * fit. Gradient by central differences (1e-7 rad skinned, 1e-5 static). */
int sb_fit_pose(sb_fit *F, const int *feat, int nfeat, const double *target, const int *joints, int nj, double *local,
                const sb_opt_opts *oo, sb_opt_result *res);

/* Surface rig (§4.3, eq. 13-14) at the current pose (sb_fit_set_pose, p0 without
 * the rig): displacement z of the free lattice vertices minimizing
 *   C = C_surf + omega C_smooth,
 *   C_surf   = (1/N_s) sum_s |Gamma_s(z) - Gammabar_s|^2 / D^2
 *   C_smooth = (1/N_e) sum over the 12 edges (a, b) of every cell |z_a - z_b|^2 / D^2
 * (Gamma(z): surface of p0 + z; D^2 = (1/N_s) sum_s |Gammabar_s - Gamma_s(0)|^2;
 * z = 0 on skeleton vertices), then eta = A z: the generalized force whose
 * equilibrium is exactly p0 + z (eq. 10). eta_rest (o.nf x 3): eta in newtons,
 * each vertex's rest frame (R_i^T), for a rig file. fit (nS x 3, may be NULL):
 * the fitted surface. C is quadratic in z: solved exactly by Jacobi-
 * preconditioned conjugate gradients on the normal equations until
 * |grad C|inf <= oo->pgtol (at most oo->max_iter iterations; progress lines as
 * L-BFGS-B's, oo->verbose), or by L-BFGS-B if F->surf_lbfgsb. res: iterations,
 * f, |grad|inf, status (SB_OPT_PGTOL converged, SB_OPT_MAXITER). */
int sb_fit_surface(sb_fit *F, const double *target, double omega, const sb_opt_opts *oo, sb_opt_result *res,
                   double *eta_rest, double *fit);

/* What a surface rig can reach of a target (at the current pose): skel_half /
 * skel_all, the shares of the target's sum |d|^2 (d = target - surf0) on surface
 * vertices with at least half / all of their embedding weight on skeleton
 * vertices (carried rigidly by the bones: z = 0 there); rms / max, the residual
 * of the best fit of the target by the free lattice vertices' displacements
 * alone (C_surf minimized with omega = 0: a lower bound for any rig at this
 * pose, whatever the optimizer), as fractions of the target's displacement
 * (rms: sqrt(sum r^2 / sum d^2), max: max |r| / max |d|); rms_all / max_all:
 * the same with every lattice vertex free (as if no bone carried any: what is
 * left is the trilinear lattice's resolution). best (nS x 3, may be NULL): the
 * free vertices' best surface. */
typedef struct sb_surf_reach {
    double skel_half, skel_all, rms, max, rms_all, max_all;
    int iterations, status;
} sb_surf_reach;
int sb_fit_surface_reach(sb_fit *F, const double *target, const sb_opt_opts *oo, sb_surf_reach *out, double *best);

/* Point-drag template fit (§4.2) at the current pose (p0 with every rig on):
 * strengths eta_a of the template rigs rigs[0..nr) minimizing
 *   C = C_points + C_params,
 *   C_points = (1/N) sum_k |p_k(eta) - pbar_k|^2 / c^2   (p_k: surface vertex vert[k])
 *   C_params = lambda sum_a ((eta_a - s_a) / s_a)^2      (s_a: the description's strength)
 * within [lo_a, hi_a]; q(eta) by eq. 10 (rig a's force is eta_a / s_a times its
 * baked force at its control's current value); the gradient by the adjoint:
 * one solve with A per evaluation. eta: in the start, out the fit. */
int sb_fit_points(sb_fit *F, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda,
                  const double *lo, const double *hi, double *eta, const sb_opt_opts *oo, sb_opt_result *res);
/* the point-drag cost and gradient at eta (for checks against finite differences) */
double sb_fit_points_cost(sb_fit *F, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda,
                          const double *eta, double *grad);

/* Point-drag with the templates' geometry (§4.2: "one integration over the
 * character for each element of eta"): per rig a, its parameters
 *   bump: s, centre (3), radius; ring: s, centre (3), radius, width;
 *   muscle: s, end a (3), end b (3), radius; uniform: s
 * (directions, axes and SHORTEN stay), packed rig after rig. The rig's force
 * is re-integrated by the bake's own quadrature (sb_rig_build) at every
 * evaluation, dQ/dp by central differences of that integration (step 1e-4 of
 * the template's size; Q is linear in s). Same C_points; C_params =
 * lambda sum_k ((par_k - par0_k) / scale_k)^2, scale = |s| for strengths, the
 * template's size for geometry. npar: parameters of rig a. */
int sb_fit_template_npar(const sb_fit *F, int rig);
void sb_fit_template_get(const sb_fit *F, int rig, double *par);
/* bounds that make sense: strength within +-1e6, centres within 2 sizes of the
 * description's, sizes within [1/4, 4] of it */
void sb_fit_template_bounds(const sb_fit *F, int rig, double *lo, double *hi);
double sb_fit_template_cost(sb_fit *F, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda,
                            const double *par, double *grad);
int sb_fit_template(sb_fit *F, const int *rigs, int nr, const int *vert, const double *target, int np, double lambda,
                    const double *lo, const double *hi, double *par, const sb_opt_opts *oo, sb_opt_result *res);
/* rig a's template parameters par written into a rigdef copy */
void sb_fit_template_apply(const sb_fit *F, int rig, const double *par, sb_rigdef *out);

/* rotation vector <-> quaternion (x y z w) */
void sb_rotvec_quat(const double r[3], double q[4]);
void sb_quat_rotvec(const double q[4], double r[3]);

#endif
