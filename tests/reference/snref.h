/* snref.h -- double-precision reference of the Sinew step (runtime/NUMERICS.md).
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
    int len_shift;
    unsigned frac_S, frac_M, frac_P;
    double unit;          /* U in mesh units = 2^len_shift */
    double a1, b1, grav[3], h, m0;
    int *jparent;         /* nJ, -1 = root */
    double *jrest;        /* nJ*3 internal units, model space */
    char (*jname)[32];
    double *rest;         /* nV*3 internal units */
    int *fb1, *fb2;       /* nV frame bones */
    double *fw;           /* nV frame weight */
    double *mdiag;        /* nF */
    double *sdiag;        /* nF*9 full symmetric block */
    double *precond;      /* nF*9 full symmetric block */
    double *mlump;        /* nF */
    unsigned *rowptr;     /* nF+1 */
    unsigned *cols;       /* nnz */
    double *moff;         /* nnz */
    double *soff;         /* nnz*9 row-major */
    unsigned *cells;      /* nC*8 */
    unsigned *ecell;      /* nS */
    double *et;           /* nS*3 */
    unsigned *tris;       /* nT*3 */
} snref_model;

/* Load a blob of any flavour. Returns 0 on success, else writes a message to
 * err (if non-NULL, size errn) and returns -1. Checks magic, version,
 * endianness, CRC, section bounds and indices (the reference must not crash
 * on a bad blob, but it is not the validator under test). */
int snref_load(snref_model *m, const void *data, size_t size, char *err, size_t errn);
int snref_load_file(snref_model *m, const char *path, char *err, size_t errn);
void snref_free(snref_model *m);

enum { SNREF_WARPED = 0, SNREF_UNWARPED = 1 };

typedef struct snref_state {
    const snref_model *m;
    double *p;     /* nV*3 positions, internal units, world */
    double *v;     /* nV*3 velocity per step (h v) */
    double *dv;    /* nF*3 warm start */
    double *R;     /* nV*9 vertex frames */
    double *c;     /* nV*3 frame origins */
    double *jq;    /* nJ*4 current pose quaternions */
    double *jt;    /* nJ*3 current pose translations, internal units */
    double *work;  /* scratch */
    int posed;     /* a pose was set since init/reset */
    int mode;      /* SNREF_WARPED / SNREF_UNWARPED */
    unsigned iters;/* CG iterations per step */
    int exact;     /* 1: solve each step to convergence instead of N iterations */
    int warm;      /* 1 (default): warm-start CG from the previous dv */
    int first_pose_moves_free; /* 1 (default, as the runtime): the first pose places free vertices at R_i x_i + c_i */
    double gscale; /* multiplies the baked gravity (1 by default) */
    double hscale; /* step h' = hscale*h: S^,g^ scale by hscale^2, a1 by hscale, b1 by 1/hscale */
    unsigned steps;
    struct snref_band *band; /* cached factor of the step matrix (exact mode) */
    double last_cg_relres; /* |b - A dv| / |b| after the last step's solve */
} snref_state;

int snref_init(snref_state *s, const snref_model *m);
void snref_release(snref_state *s);
void snref_reset(snref_state *s);
/* One transform per joint, mesh units (same semantics as sn_set_pose). */
void snref_set_pose(snref_state *s, const snref_xform *pose);
void snref_step(snref_state *s);

/* Positions in mesh units (world). out has count*3 doubles. */
void snref_get_lattice(const snref_state *s, double *out);
void snref_get_surface(const snref_state *s, double *out);
/* Surface from arbitrary lattice positions (mesh units, nV*3). */
void snref_surface_from_lattice(const snref_model *m, const double *lat, double *out);

/* Static equilibrium of seed 003 eq. 10 at the current pose (skeleton fixed at
 * the pose, frames from the pose): f(p_F) + m^ g^ = 0, solved as one linear
 * system with the exact (non-symmetric) Jacobian -R_i S^_ij R_i^T. Dense LU
 * when 3 nF <= dense_max, else BiCGSTAB to a relative residual of 1e-12.
 * Otherwise banded LU in reverse Cuthill-McKee order (BiCGSTAB if the band
 * is too large). Writes the solution into the state's free positions (velocities zeroed).
 * Returns the final relative residual |f + m g| / |m g| (or / |f(p0)|). */
double snref_static(snref_state *s, unsigned dense_max);

/* x = (-J)^-1 load at the current frames (free rows; the stiffness solve of
 * eq. 10 for an arbitrary load), and y = M^_FF x. Used for eigen-frequencies. */
void snref_solve_load(snref_state *s, const double *load, double *x);
void snref_mass_mul(const snref_state *s, const double *x, double *y);

/* Net force residual f + m^g^ (internal units) at the current positions, free rows. */
void snref_residual(const snref_state *s, double *out);

/* Energies in baked units (m0 * U^2 / h^2 ... only ratios matter):
 * kinetic 1/2 v^T M^ v over free rows (full consistent mass incl. coupling to
 * skeleton velocities) and warped elastic 1/2 sum u_i^T S^_ij u_j with
 * u_j = R_j^T (p_j - c_j) - x_j. */
void snref_energy(const snref_state *s, double *kinetic, double *elastic);

/* Small quaternion helpers (double), exposed for tests. */
void snref_quat_axis_angle(const double axis[3], double deg, double q[4]);
void snref_quat_mul(const double a[4], const double b[4], double out[4]);
void snref_quat_slerp(const double a[4], const double b[4], double t, double out[4]);
void snref_quat_to_mat(const double q[4], double R[9]);

/* CRC-32 (zlib polynomial) of n bytes: the blob checksum (runtime/BLOB.md). */
uint32_t snref_crc32(const unsigned char *p, size_t n);

#endif /* SNREF_H */
