/* rig_common.h -- rigs for the rig tests (issue 10), written into any blob by
 * the tests' own writer (snsyn_with_rigs), so the runtime and the reference
 * can be checked on controlled rigs independently of the host tool's
 * templates. Header-only; include after snref.h and snref_synth.h.
 *
 * rc_add_rigs(blob) adds to a blob with joints (by name or index):
 *   controls: "breath" (abstract, value0 0.25), "bend" (pose: the angle of
 *             joint `bend_joint` about axis `bend_axis`)
 *   rigs:     0 "bulge": radial push away from the axis through `c0`..`c1`
 *               (a muscle-like bulge), free vertices within radius rad of the
 *               segment, smooth (1 - (r/rad)^2)^2 profile, magnitude amp;
 *               driven by "bend" with samples (0, 0), (45, 0.4), (90, 1), (120, 1)
 *             1 "push": a bump pushing along +dir around c0, driven by
 *               "breath" with samples (-1, -1), (0, 0), (0.5, 0.25), (1, 1)
 * amp is in right-hand-side units per vertex of lumped mass: entry i gets
 * amp * m^_i * profile, so it compares with gravity (|g^| m^_i per vertex).
 */
#ifndef RIG_COMMON_H
#define RIG_COMMON_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct rc_spec {
    unsigned bend_joint;
    double bend_axis[3];
    double c0[3], c1[3];   /* model space, mesh units (relative to the root joint's rest) */
    double rad;            /* mesh units */
    double amp;            /* x m^_i x |g^| of the model: right-hand-side units */
    double dir[3];         /* push direction (rest model axes) */
} rc_spec;

/* distance of p from segment a-b, and the unit radial direction */
static inline double rc_seg(const double p[3], const double a[3], const double b[3], double rdir[3]) {
    double ab[3], ap[3], t = 0, l2 = 0, d[3], n = 0;
    int k;
    for (k = 0; k < 3; k++) { ab[k] = b[k] - a[k]; ap[k] = p[k] - a[k]; l2 += ab[k] * ab[k]; t += ab[k] * ap[k]; }
    t = l2 > 0 ? t / l2 : 0;
    if (t < 0) t = 0;
    if (t > 1) t = 1;
    for (k = 0; k < 3; k++) { d[k] = ap[k] - t * ab[k]; n += d[k] * d[k]; }
    n = sqrt(n);
    for (k = 0; k < 3; k++) rdir[k] = n > 0 ? d[k] / n : 0;
    return n;
}

/* New blob (malloc'd) = blob + the two controls and two rigs above. m is the
 * blob loaded by the reference (rest positions, lumped masses, gravity). */
static inline unsigned char *rc_add_rigs(const unsigned char *blob, size_t size, const snref_model *m, const rc_spec *sp, size_t *out_size) {
    snsyn_control k[2];
    snsyn_rig r[2];
    unsigned *v0 = malloc(m->nF * sizeof *v0 + 4), *v1 = malloc(m->nF * sizeof *v1 + 4), i, n0 = 0, n1 = 0, c;
    double *f0 = malloc(3 * m->nF * sizeof *f0 + 8), *f1 = malloc(3 * m->nF * sizeof *f1 + 8);
    double g = sqrt(m->grav[0] * m->grav[0] + m->grav[1] * m->grav[1] + m->grav[2] * m->grav[2]);
    unsigned char *out;
    if (g == 0) {   /* no gravity in the blob: |g^| of 9.81 m/s^2, U unit = sqrt(ENERGY h^2 / m0) metres */
        double Um = sqrt(m->energy * m->h * m->h / m->m0);
        g = m->h * m->h * 9.81 / Um;
    }
    memset(k, 0, sizeof k); memset(r, 0, sizeof r);
    k[0].name = "breath"; k[0].kind = SN_CTL_ABSTRACT; k[0].value0 = 0.25;
    k[1].name = "bend"; k[1].kind = SN_CTL_ANGLE; k[1].joint = sp->bend_joint;
    memcpy(k[1].axis, sp->bend_axis, sizeof k[1].axis);
    for (i = 0; i < m->nF; i++) {
        double x[3], rd[3], d, w;
        for (c = 0; c < 3; c++) x[c] = m->rest[3 * i + c] * m->unit;
        d = rc_seg(x, sp->c0, sp->c1, rd);
        if (d < sp->rad && d > 1e-9) {
            w = 1 - (d / sp->rad) * (d / sp->rad);
            v0[n0] = i;
            for (c = 0; c < 3; c++) f0[3 * n0 + c] = sp->amp * g * m->mlump[i] * w * w * rd[c];
            n0++;
        }
        d = rc_seg(x, sp->c0, sp->c0, rd);
        if (d < sp->rad) {
            w = 1 - (d / sp->rad) * (d / sp->rad);
            v1[n1] = i;
            for (c = 0; c < 3; c++) f1[3 * n1 + c] = sp->amp * g * m->mlump[i] * w * w * sp->dir[c];
            n1++;
        }
    }
    r[0].control = 1; r[0].n_samples = 4;
    r[0].gamma[0] = 0; r[0].gamma[1] = 45; r[0].gamma[2] = 90; r[0].gamma[3] = 120;
    r[0].eta[0] = 0; r[0].eta[1] = 0.4; r[0].eta[2] = 1; r[0].eta[3] = 1;
    r[0].n_entries = n0; r[0].verts = v0; r[0].force = f0;
    r[1].control = 0; r[1].n_samples = 4;
    r[1].gamma[0] = -1; r[1].gamma[1] = 0; r[1].gamma[2] = 0.5; r[1].gamma[3] = 1;
    r[1].eta[0] = -1; r[1].eta[1] = 0; r[1].eta[2] = 0.25; r[1].eta[3] = 1;
    r[1].n_entries = n1; r[1].verts = v1; r[1].force = f1;
    out = snsyn_with_rigs(blob, size, k, 2, r, 2, out_size);
    free(v0); free(v1); free(f0); free(f1);
    return out;
}

#endif
