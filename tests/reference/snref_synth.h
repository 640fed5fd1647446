/* snref_synth.h -- test-side writer of synthetic box-lattice blobs (format
 * 3.0 without rigs, float32 / float64; snsyn_with_rigs adds rig sections to any blob) with textbook trilinear hex elements (one CELLK
 * matrix per cell), independent of the host tool.
 * Used to unit-test the reference and to measure element locking and its
 * fixes before (and independently of) the tool's own integration. */
#ifndef SNREF_SYNTH_H
#define SNREF_SYNTH_H

#include <stddef.h>

enum {
    SNSYN_FULL = 0,        /* 2x2x2 Gauss, the textbook trilinear hex */
    SNSYN_SRI_VOL = 1,     /* lambda (volumetric) term at 1 point, mu term at 2x2x2 */
    SNSYN_INCOMPATIBLE = 2 /* Wilson-Taylor incompatible modes, condensed (hex11/"Q6" in 3-D) */
};

typedef struct snsyn_box {
    unsigned nx, ny, nz;      /* cells along x (length), y (height), z (width) */
    double dx, dy, dz;        /* cell size, metres (mesh unit = 1 m) */
    double E, nu, rho;        /* Young (Pa), Poisson, density (kg/m^3) */
    double h;                 /* time step, s */
    double g[3];              /* gravity, m/s^2 */
    double alpha, beta;       /* Rayleigh damping */
    int integration;          /* SNSYN_* */
    int flavour;              /* 1 float32, 2 float64 */
    unsigned cg_default;      /* CG iterations */
    /* clamp: every vertex with ix == 0 is a skeleton vertex of joint 0 ("root",
     * resting at the centre of the clamp face). If two_joints, vertices with
     * ix == nx are skeleton vertices of joint 1 (child, resting at the centre of
     * the far face); free vertices blend frames by w = ix/nx. */
    int two_joints;           /* cell frames: root/tip blended at the cell centre, w = (cx + 1/2)/nx */
    int rest_modelled;        /* header flag SN_FLAG_REST_MODELLED */
    double limit;             /* > 0: LIMIT of every free vertex, mesh units; 0: empty LIMIT section */
    double disp_bound;        /* DISP_BOUND in cells (0: 1 cell) */
} snsyn_box;

/* Build the blob; returns malloc'd bytes (8-byte aligned) and its size, NULL on error. */
unsigned char *snsyn_build(const snsyn_box *b, size_t *size);

/* Element matrices of one box cell (exposed for the element tests):
 * Ke 24x24 (dof 3a+i, corner a at (a&1, a>>1&1, a>>2&1)), Me 8x8 scalar. */
void snsyn_hex(double dx, double dy, double dz, double lambda, double mu, int integration,
               double Ke[24][24], double Me[8][8]);

/* ---- rig sections (format 3.0), for any blob of any flavour (fixed included) ----
 * snsyn_with_rigs returns a malloc'd copy of blob (8-aligned allocation,
 * size *out_size) whose rig sections (CONTROLS .. RIG_FORCES) are replaced
 * by the ones given: placed after TRIS, section table, total size,
 * instance_bytes (= SN_INSTANCE_BYTES with nk controls) and CRC updated.
 * Forces are in the right-hand side's units (internal, sn_format.h); fixed
 * blobs store each rig's forces in Q frac, frac = the given one or (0) the
 * largest that keeps |stored| <= 2^27 (snsyn_rig_frac), within
 * SN_RIG_FRAC_MIN..MAX. NULL on a bad argument. Independent of the host tool
 * (the tests' second writer of these sections). */
typedef struct snsyn_control {
    const char *name;         /* <= 31 bytes */
    int kind;                 /* SN_CTL_ABSTRACT / SN_CTL_ANGLE */
    unsigned joint;           /* ANGLE: the joint */
    double axis[3];           /* ANGLE: axis (normalized here) */
    double value0;            /* ABSTRACT: value after init/reset */
} snsyn_control;
typedef struct snsyn_rig {
    unsigned control, n_samples;
    double gamma[16], eta[16];/* tau samples, gamma strictly increasing, |eta| <= 1 */
    unsigned n_entries;
    const unsigned *verts;    /* n_entries free vertices, strictly increasing */
    const double *force;      /* n_entries x 3, vertex rest frame, right-hand-side units */
    int frac;                 /* fixed: forces' fraction bits, 0 = automatic */
} snsyn_rig;
int snsyn_rig_frac(double maxabs);
unsigned char *snsyn_with_rigs(const unsigned char *blob, size_t size, const snsyn_control *ctl, unsigned nk,
                               const snsyn_rig *rig, unsigned nr, size_t *out_size);

#endif
