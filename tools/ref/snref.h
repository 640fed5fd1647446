/* snref.h -- double-precision reference of the Sinew step (runtime/NUMERICS.md,
 * blob format 3.0: per-cell frames, element energy, tracked quaternions, path
 * slerp, limits, health, rig controls and rig forces).
 *
 * Independent of the runtime: its own blob reader (only sn_format.h
 * constants), quaternion/slerp/rotation code, CG and static solver. Reads
 * every blob flavour: fixed (Q formats converted to double), float32, float64
 * (the host tool's unquantized matrices).
 *
 * Units: positions/velocities inside are internal units (U = 2^len_shift mesh
 * units) in world space relative to the root joint's rest position x0 (blob
 * joint rests are model space, REST is relative to x0); the API takes poses and returns positions in mesh
 * units, like the runtime. The state is "world" positions in doubles: no
 * origin shifting is needed at double precision (NUMERICS.md "Origin" only
 * changes representation, not the maths).
 */
#ifndef SNREF_H
#define SNREF_H

#include <stddef.h>
#include <stdint.h>

/* A rigid bone motion x -> R(q) x + t (mesh units), as sn_xform in doubles. */
typedef struct snref_xform { double q[4]; double t[3]; } snref_xform; /* q = x,y,z,w */

typedef struct snref_model {
    int flavour;
    unsigned real_size;
    unsigned nV, nF, nC, nJ, nS, nT, nnz, cg_default, cg_max;
    unsigned flags;       /* SN_FLAG_* */
    unsigned nlimit;      /* 0 (no LIMIT stage) or nF */
    int len_shift;
    unsigned frac_S, frac_M, frac_P;
    int frac_E;           /* fractional bits of ENERGY (fixed flavour) */
    double unit;          /* U in mesh units = 2^len_shift */
    double a1, b1, grav[3], h, m0;
    double energy;        /* joules per internal energy unit (ENERGY) */
    double cell;          /* cell edge, internal units (CELL) */
    double disp_bound;    /* cells (DISP_BOUND) */
    int *jparent;         /* nJ, -1 = root */
    double *jrest;        /* nJ*3 internal units, model space */
    char (*jname)[32];
    double *rest;         /* nV*3 internal units */
    int *fb1, *fb2;       /* nV vertex frame bones */
    double *fw;           /* nV vertex frame weight */
    double *mdiag;        /* nF */
    double *precond;      /* nF*9 full symmetric block: A0_ii^-1, or with ICHOL the IC(0) pivots D_i^-1 */
    unsigned nIC;         /* ICHOL blocks (0: block Jacobi) */
    double *ichol;        /* nIC*9: U_ji = L^_ij^T (free-free upper mass entries, row order), row-major */
    double *mlump;        /* nF */
    unsigned *rowptr;     /* nF+1 (mass pattern) */
    unsigned *cols;       /* nnz */
    double *moff;         /* nnz */
    unsigned *cells;      /* nC*8 */
    int *cb1, *cb2;       /* nC cell frame bones (CFRAMES) */
    double *cw;           /* nC cell frame weight */
    double *cellk;        /* nC*576: S^_e as a full 24x24 row-major matrix, dof 3a+i (corner a) */
    unsigned *cutn, *cutx; /* the cut level (CELLX; NULL without): per cell its extras' count, SN_CUT_MAXX vertex slots */
    double *cutk;         /* per cell, per extra slot: 8 blocks [corner a x extra] of 9, row-major (as cellk) */
    double *limit;        /* nF limits L_i (internal units, 0 = none); NULL when LIMIT is empty */
    unsigned *ecell;      /* nS */
    double *et;           /* nS*3 */
    unsigned *tris;       /* nT*3 */
    /* derived at load */
    /* rigs (format 3.0; all counts may be 0): controls, rigs, tau samples, entries */
    unsigned nK, nR, nRS, nRE;
    char (*kname)[32];    /* nK control names */
    int *kkind;           /* SN_CTL_ABSTRACT / SN_CTL_ANGLE */
    int *kjoint;          /* ANGLE: the joint whose rotation relative to its parent is measured */
    double *kaxis;        /* nK*3 ANGLE: unit axis, rest model axes */
    double *kvalue0;      /* ABSTRACT: value after init/reset (public units) */
    unsigned *rctl, *rns, *rfs, *rfe, *rne; /* per rig: control, samples, first sample, first entry, entries */
    int *rfrac;           /* per rig: fixed-point fraction of its forces (fixed flavour) */
    double *rgamma, *reta;/* nRS tau samples (gamma public units, eta) */
    unsigned *rvert;      /* nRE free vertices */
    double *rforce;       /* nRE*3 Q^a_i at eta = 1, vertex rest frame, right-hand-side units (internal) */
    double *sdiag;        /* nF*9: assembled diagonal block sum_e S^_e,ii */
    unsigned *adjp, *adj; /* free-free neighbours (sharing a cell), CSR over nF */
} snref_model;

/* Load a blob of any flavour. Returns 0 on success, else writes a message to
 * err (if non-NULL, size errn) and returns -1. Checks magic, version,
 * endianness, CRC, section bounds and indices (the reference must not crash
 * on a bad blob, but it is not the validator under test). */
int snref_load(snref_model *m, const void *data, size_t size, char *err, size_t errn);
int snref_load_file(snref_model *m, const char *path, char *err, size_t errn);
void snref_free(snref_model *m);

enum { SNREF_WARPED = 0, SNREF_UNWARPED = 1, SNREF_BLENDED = 2 };
/* SNREF_BLENDED: blended local linearization (seed 000 sec. 4.5, eq. 18, 22-24;
 * DESIGN.md). Per step, for each region r (bone b = rbone[r], transform
 * T^r = (R^r, t^r) of the current pose): the region's cells K^r are the cells
 * with a free vertex of positive weight W^r; its unknowns are their free
 * vertices; its elastic energy is linear elasticity of the displacement from
 * the rest state moved by T^r, measured in the bone's frame (floating frame):
 * d_b = R^rT (p_b - T^r(x_b)) over the cells of K^r, i.e. the warped model
 * with every cell frame = R^r (S^_e annihilates translations, so t^r drops
 * out). Stiffness K^r = sum_{e in K^r} R^r S^_e R^rT, mass the global M^
 * restricted to the region's unknowns; the region's step system (NUMERICS
 * step 5-6 with these) is solved by PCG (`iters` iterations, warm start from
 * the previous merged dv; to convergence if `exact`); then
 * dv_a = sum_r W^r_a dv^r_a. Vertex and cell frames stay the warped ones
 * (preconditioner, gravity with REST_MODELLED, limits, health, skinned).
 * snref_static in this mode: the steady state of that step at the fixed
 * pose (v = 0: sum_r W^r (A^r)^-1 r^r(p) = 0, r^r the region's force
 * residual), by dense LU of the affine fixed-point map (small lattices).
 * Not applied in this mode: constraint rows (`rows`), precond_hook; the
 * solve_hook sees b without the elastic terms (they come per region). */
/* Elastic force model. CELL: NUMERICS.md step 4 (per-cell frames, element
 * energy, K~ = sum_e R_e S^_e R_e^T). VERTEX: format 1.0 / seed 003 eq. 7 with
 * per-vertex frames, f_i = -R_i sum_j S_ij (R_i^T (p_j - c_i) - x_j), S
 * assembled from CELLK, step matrix block R_i S_ij R_j^T (kept to show what
 * the per-cell model fixes; it has no energy). */
enum { SNREF_FORCE_CELL = 0, SNREF_FORCE_VERTEX = 1 };

typedef struct snref_state {
    const snref_model *m;
    double *p;     /* nV*3 positions, internal units, world */
    double *v;     /* nV*3 velocity per step (h v) */
    double *dv;    /* nF*3 warm start */
    double *R;     /* nV*9 vertex frames */
    double *c;     /* nV*3 frame origins */
    double *Rc;    /* nC*9 cell frames */
    double *jq;    /* nJ*4 current pose quaternions, tracked (NUMERICS step 1) */
    double *jt;    /* nJ*3 current pose translations, internal units */
    double *work;  /* scratch */
    int posed;     /* a pose was set since init/reset */
    int mode;      /* SNREF_WARPED / SNREF_UNWARPED */
    int force;     /* SNREF_FORCE_CELL (default) / SNREF_FORCE_VERTEX */
    int path_slerp;/* 1 (default): tracked quaternions + path slerp (NUMERICS step 1-2); 0: no tracking, shorter arc (format 1.0) */
    unsigned iters;/* CG iterations per step */
    int exact;     /* 1: solve each step to convergence instead of N iterations */
    int warm;      /* 1 (default): warm-start CG from the previous dv */
    int first_pose_moves_free; /* 1 (default, as the runtime): the first pose places free vertices at R_i x_i + c_i */
    double gscale; /* multiplies the baked gravity (1 by default) */
    double hscale; /* step h' = hscale*h: S^,g^ scale by hscale^2, a1 by hscale, b1 by 1/hscale */
    double dscale; /* multiplies a1 and b1 (Rayleigh damping; 1 by default, 0 = undamped) */
    unsigned steps;
    struct snref_band *band; /* cached factor of the step matrix (exact mode) */
    double last_cg_relres; /* |b - A dv| / |b| after the last step's solve */
    /* health of the last step (NUMERICS step 8-9) */
    double e_el, e_kin;      /* internal energy units: E_el of step 4, 1/2 sum m^_i |v_i|^2 of the starting v */
    double energy, energy_max; /* (e_el + e_kin) * ENERGY, joules; max since reset */
    double disp, disp_max;   /* max |p_i - s_i| / CELL after the step over free i with m^_i >= 1/16, cells; max since reset */
    unsigned limit_clamps;   /* vertices pulled back in the last step */
    unsigned limit_steps;    /* steps with a limit clamp since reset */
    unsigned bound_steps;    /* steps with disp > DISP_BOUND since reset (the reference never saturates) */
    /* rigs: current control values (abstract: as set, value0 after init/reset;
     * pose: from the pose at every snref_set_pose, so already before the first
     * step, where the runtime reports 0) and a multiplier of every rig force
     * (1 by default; 0 = rigs off, for with/without comparisons) */
    double *ctl;
    double rig_scale;
    /* blended local linearization (SNREF_BLENDED; seed 000 sec. 4.5): regions.
     * Default after init: one region per joint j (rbone[j] = j) with W^j_a the
     * vertex's frame weights (FRAMES: (1 - w) on bone1, w on bone2; a
     * partition of unity over bones). snref_set_regions replaces them. */
    unsigned nreg;
    int *rbone;    /* nreg: the joint whose transform T^r region r follows */
    double *rw;    /* nreg*nV: W^r_a (row r) */
    int blend_hold;/* 0 (default, the paper): every free vertex of the region's cells is an unknown of its
                    * solve; 1: vertices of the region's cells with W^r_a = 0 are held (dv = 0) in it */
    double blend_fixres; /* snref_static in SNREF_BLENDED: fixed-point residual |G(p)| / max(|G(p_start)|, |G of the load alone|) */
    /* called in snref_step just before the solve of step 6 with the step's
     * right-hand side b and the start x0 (the warm start) of A dv = b, the
     * frames of the step already in R and Rc (NULL: none; tests/precond_study.c) */
    void (*solve_hook)(void *ctx, const struct snref_state *s, const double *b, const double *x0);
    /* replaces the preconditioner z = R_i P_i R_i^T r_i of the N-iteration PCG (NULL: none) */
    void (*precond_hook)(void *ctx, const struct snref_state *s, const double *r, double *z);
    void *hook_ctx;
    /* constraint rows for the next steps (runtime/src/sn_constraint.h in
     * double; NULL: none; the caller owns them): sum_k w_k dir . v_new[vtx_k]
     * = target (per-step velocity units), skeleton vertices' new velocity
     * moved to the right-hand side; the solve is the Baraff-Witkin filtered
     * PCG with an exact projection (rows dropped by the runtime's rule) */
    const struct snref_row *rows;
    unsigned nrows;
    unsigned rows_kept;  /* after the last step's drops */
    const struct snref_rowsys *cg_rows; /* internal: the step's factorized rows while its PCG runs (NULL otherwise) */
} snref_state;

typedef struct snref_row {
    unsigned n;
    unsigned vtx[16];
    double w[16];
    double dir[3];
    double target;
} snref_row;

int snref_init(snref_state *s, const snref_model *m);
void snref_release(snref_state *s);
void snref_reset(snref_state *s);
/* One transform per joint, mesh units (same semantics as sn_set_pose). */
void snref_set_pose(snref_state *s, const snref_xform *pose);
void snref_step(snref_state *s);

/* Positions in mesh units (world). out has count*3 doubles. */
void snref_get_lattice(const snref_state *s, double *out);
void snref_get_surface(const snref_state *s, double *out);
/* Rigidly framed ("skinned") lattice R_i x_i + c_i of the current frames, mesh units, nV*3. */
void snref_get_skinned(const snref_state *s, double *out);
/* Surface from arbitrary lattice positions (mesh units, nV*3). */
void snref_surface_from_lattice(const snref_model *m, const double *lat, double *out);
/* Signed volume enclosed by the surface triangles at positions p (nS*3, mesh
 * units): divergence theorem, mesh units^3. */
double snref_surface_volume(const snref_model *m, const double *p);
/* Volume of the lattice cells (positions lat, nV*3) whose rest centre lies
 * within rad of point e (mesh units, model space + the root's rest): each hex
 * as 6 tetrahedra around its 0-7 diagonal. */
double snref_cells_volume(const snref_model *m, const double *lat, const double e[3], double rad);

/* Static equilibrium (seed 003 eq. 10) at the current pose: skeleton fixed at
 * the pose, frames from the pose, f(p_F) + m^ g^ [- m^ R g^] + f_rig = 0 (the
 * rig force at the current controls, times rig_scale). CELL model:
 * the minimum of E_el - load.p (quadratic in p, one linear solve with K~_FF);
 * VERTEX model: one linear solve with the exact Jacobian of eq. 7. Dense LU
 * when 3 nF <= dense_max, else banded LU in reverse Cuthill-McKee order
 * (BiCGSTAB if the band is too large); Newton refinement passes until the
 * residual stops falling. Writes the solution into the state (velocities
 * zeroed). Returns the relative residual |f + load| / |f + load at the start|. */
double snref_static(snref_state *s, unsigned dense_max);

/* x = H^-1 load at the current frames (H = K~_FF for the CELL model, the
 * negated Jacobian for VERTEX): the static solve for an arbitrary load (free
 * rows, internal units). Used for eigen-frequencies. */
void snref_solve_load(snref_state *s, const double *load, double *x);
void snref_mass_mul(const snref_state *s, const double *x, double *y);
/* The same solve for many loads at fixed frames (rig fitting, tools/sb_fit.c):
 * H factored once (banded LU, reverse Cuthill-McKee); NULL if the band is
 * too large (then use snref_solve_load). snref_hess_mul: y = H x (free rows
 * and columns), the matrix the factor inverts. */
struct snref_band *snref_factor(snref_state *s);
void snref_factor_solve(const struct snref_band *B, const double *load, double *x);
void snref_factor_free(struct snref_band *B);
void snref_hess_mul(const snref_state *s, const double *x, double *y);

/* Regions of SNREF_BLENDED: nreg regions, region r follows joint rbone[r],
 * W (nreg*nV) its weights over lattice vertices; every free vertex's weights
 * must be >= 0 and sum to 1 (1e-9). NULL W: the default (one region per
 * joint, weights from the vertex frames). Returns 0, or -1 (nothing changed). */
int snref_set_regions(snref_state *s, unsigned nreg, const int *rbone, const double *W);

/* Net force residual f + m^g^ [- m^ R g^] + f_rig (internal units) at the current positions, free rows. */
void snref_residual(const snref_state *s, double *out);
/* Elastic force of the active model at positions p (nV*3), free rows. */
void snref_force(const snref_state *s, const double *p, double *out);
/* E_el = 1/2 sum_e d_e^T S^_e d_e at positions p (nV*3), current cell frames (NUMERICS step 4). */
double snref_elastic(const snref_state *s, const double *p);
/* y = K x, free rows: the stiffness of the step matrix (CELL: K~ = sum_e R_e S^_e R_e^T;
 * VERTEX: R_i S_ij R_j^T); x has nV*3 entries, skeleton ones used iff with_skel. */
void snref_kmul(const snref_state *s, const double *x, double *y, int with_skel);

/* Energies in baked units (joules: times model energy / hscale^2):
 * kinetic 1/2 v_F^T M^_FF v_F (consistent mass, free rows and columns) and
 * the element energy E_el at the current positions. */
void snref_energy(const snref_state *s, double *kinetic, double *elastic);

/* ---- rig controls and forces (format 3.0; sinew.h "rig controls") ----
 * Index of the control called name, or -1. */
int snref_find_control(const snref_model *m, const char *name);
/* Set abstract control c (kept until set again or reset). -1, and nothing
 * changes, if c is out of range, a pose control, or value is not finite. */
int snref_set_control(snref_state *s, unsigned c, double value);
/* Current value of control c (0 if out of range). */
double snref_get_control(const snref_state *s, unsigned c);
/* Pose control formula: the angle (degrees, [-180, 180]) of rotation q (x,y,z,w;
 * need not be unit) about unit axis A: q's sign chosen so w >= 0 (w == 0:
 * v.A >= 0), 2 atan2(v.A, w). Applied to q_rel = conj(q_parent) q_J (root: q_J). */
double snref_twist_angle(const double q[4], const double axis[3]);
/* tau_a(gamma): piecewise-linear through rig a's samples, clamped at the ends. */
double snref_tau(const snref_model *m, unsigned a, double gamma);
/* out (free rows, internal units) += rig_scale R_i sum_a tau_a(gamma_c(a)) Q^a_i
 * at the current frames and controls: the rig term of the step's right-hand
 * side and of the static equilibrium (both include it already). */
void snref_rig_add(const snref_state *s, double *out);

/* Small quaternion helpers (double), exposed for tests. */
void snref_quat_axis_angle(const double axis[3], double deg, double q[4]);
void snref_quat_mul(const double a[4], const double b[4], double out[4]);
/* Shorter-arc slerp (the generic one). */
void snref_quat_slerp(const double a[4], const double b[4], double t, double out[4]);
/* NUMERICS step 2: slerp along the path from a to b (no sign flip) unless
 * a.b < -cos 30 deg, where the shorter arc is taken. */
void snref_quat_slerp_path(const double a[4], const double b[4], double t, double out[4]);
void snref_quat_to_mat(const double q[4], double R[9]);

/* CRC-32 (zlib polynomial) of n bytes: the blob checksum (runtime/BLOB.md). */
uint32_t snref_crc32(const unsigned char *p, size_t n);

#endif /* SNREF_H */
