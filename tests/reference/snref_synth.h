/* snref_synth.h -- test-side writer of synthetic box-lattice blobs (format
 * 2.0, float32 / float64) with textbook trilinear hex elements (one CELLK
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

#endif
