/* phys_util.h -- helpers shared by the physics tests (header-only): blob
 * files, runtime instances of either flavour, sn_real <-> double, poses for
 * runtime and reference alike. Include after sinew.h; build with -DSN_FLOAT
 * for the float runtime. */
#ifndef PHYS_UTIL_H
#define PHYS_UTIL_H

#include "sinew.h"
#include "snref.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(SN_FLOAT)
#define PU_FLAVOUR_NAME "float"
#define PU_BLOB_SUFFIX "_float"
static inline double pu_len(sn_real x) { return (double)x; }
static inline double pu_q(sn_real x) { return (double)x; }
static inline sn_real pu_rlen(double x) { return (sn_real)x; }
static inline sn_real pu_rang(double x) { return (sn_real)x; }
#else
#define PU_FLAVOUR_NAME "fixed"
#define PU_BLOB_SUFFIX ""
static inline double pu_len(sn_real x) { return ldexp((double)x, -SN_LEN_FRAC); }
static inline double pu_q(sn_real x) { return ldexp((double)x, -SN_QUAT_FRAC); }
static inline sn_real pu_rlen(double x) { return (sn_real)lround(ldexp(x, SN_LEN_FRAC)); }
static inline sn_real pu_rang(double x) { return (sn_real)lround(ldexp(x, SN_ANGLE_FRAC)); }
#endif

#ifdef SN_TEST_H
/* keeps sn_test.h's t_seed referenced in tests that draw no random numbers */
static inline unsigned long pu_seed(void) { return T_SEED(); }
#endif

#ifdef SN_TEST_H
/* Every figure of the physics tests is a hard bound (issue 16 item 8):
 *
 * PU_GOAL(ok, fmt, ...)   a goal from the brief that is met today: a pass
 *                         when met, a FAIL when missed.
 * PU_KNOWN_MISS(v, goal, bound, why, fmt, ...)
 *                         a goal missed today (value v > goal, both "smaller
 *                         is better"): an expected failure that fails if it
 *                         changes. Passes while goal < v <= bound (bound: a
 *                         regression bound just above today's figure, `why`:
 *                         the reason it is missed); FAILS when v > bound (a
 *                         regression) and when v <= goal (the goal is met
 *                         now: make it a PU_GOAL). Printed on a
 *                         "figure: KNOWN MISS" line the suite summary shows.
 * Both print the figure on a "figure:" line. */
#define PU_GOAL(ok, ...) do { \
    if (ok) { t_passed_++; printf("  figure: goal met: "); printf(__VA_ARGS__); printf("\n"); } \
    else { t_failed_++; printf("FAIL %s:%d: goal missed: ", __FILE__, __LINE__); printf(__VA_ARGS__); printf("\n"); } \
} while (0)
#define PU_KNOWN_MISS(v, goal, bound, why, ...) do { \
    double v_ = (double)(v), g_ = (double)(goal), b_ = (double)(bound); \
    if (v_ > g_ && v_ <= b_) { t_passed_++; printf("  figure: KNOWN MISS (%.3g; goal %.3g, regression bound %.3g: %s): ", v_, g_, b_, why); } \
    else if (v_ <= g_) { t_failed_++; printf("FAIL %s:%d: known miss now meets its goal (%.3g <= %.3g): make it a PU_GOAL: ", __FILE__, __LINE__, v_, g_); } \
    else { t_failed_++; printf("FAIL %s:%d: known miss regressed past its bound (%.3g > %.3g; goal %.3g): ", __FILE__, __LINE__, v_, b_, g_); } \
    printf(__VA_ARGS__); printf("\n"); \
} while (0)
#endif

static inline const char *pu_build(void) { const char *b = getenv("BUILD"); return b && *b ? b : "build"; }

/* $BUILD/examples/<name>.blob */
static inline void pu_example(char *out, size_t n, const char *name) { snprintf(out, n, "%s/examples/%s.blob", pu_build(), name); }

/* Read a whole file into 8-byte aligned memory (NULL if missing). */
static inline void *pu_read(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    long n;
    double *buf;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END); n = ftell(f); fseek(f, 0, SEEK_SET);
    buf = malloc((size_t)n + 8);
    if (!buf || n <= 0 || fread(buf, 1, (size_t)n, f) != (size_t)n) { fclose(f); free(buf); return NULL; }
    fclose(f);
    *size = (size_t)n;
    return buf;
}

typedef struct pu_rt {
    void *bytes;
    size_t size;
    const sn_blob *blob;
    sn_blob_info info;
    void *mem;
    sn_instance *inst;
} pu_rt;

/* Runtime instance from a blob file of this build's flavour. 0 on success. */
static inline int pu_rt_open(pu_rt *r, const char *path) {
    sn_status st;
    memset(r, 0, sizeof *r);
    r->bytes = pu_read(path, &r->size);
    if (!r->bytes) { printf("  cannot read %s\n", path); return -1; }
    st = sn_blob_validate(r->bytes, r->size, &r->blob);
    if (st != SN_OK) { printf("  %s: %s\n", path, sn_status_str(st)); return -1; }
    sn_blob_get_info(r->blob, &r->info);
    r->mem = malloc(sn_instance_size(r->blob) + 8);
    st = sn_instance_init(r->mem, sn_instance_size(r->blob), r->blob, &r->inst);
    if (st != SN_OK) { printf("  init: %s\n", sn_status_str(st)); return -1; }
    return 0;
}
static inline void pu_rt_close(pu_rt *r) { free(r->mem); free(r->bytes); memset(r, 0, sizeof *r); }

/* Reference model + state from a blob file (any flavour). */
static inline int pu_ref_open(snref_model *m, snref_state *s, const char *path) {
    char err[200];
    if (snref_load_file(m, path, err, sizeof err) != 0) { printf("  reference: %s: %s\n", path, err); return -1; }
    return snref_init(s, m);
}

/* Runtime pose -> reference pose (exactly the same numbers, in double). */
static inline void pu_pose_to_ref(const sn_xform *x, unsigned n, snref_xform *out) {
    unsigned j;
    for (j = 0; j < n; j++) {
        out[j].q[0] = pu_q(x[j].rot.x); out[j].q[1] = pu_q(x[j].rot.y);
        out[j].q[2] = pu_q(x[j].rot.z); out[j].q[3] = pu_q(x[j].rot.w);
        out[j].t[0] = pu_len(x[j].pos.x); out[j].t[1] = pu_len(x[j].pos.y); out[j].t[2] = pu_len(x[j].pos.z);
    }
}

/* Runtime lattice / surface as doubles (mesh units), out has 3*count doubles. */
static inline void pu_rt_lattice(const pu_rt *r, double *out) {
    uint32_t i, n = r->info.vertices;
    sn_vec3 *v = malloc(n * sizeof *v);
    sn_get_lattice(r->inst, v, 0, n);
    for (i = 0; i < n; i++) { out[3 * i] = pu_len(v[i].x); out[3 * i + 1] = pu_len(v[i].y); out[3 * i + 2] = pu_len(v[i].z); }
    free(v);
}
static inline void pu_rt_surface(const pu_rt *r, double *out) {
    uint32_t i, n = r->info.surface_vertices;
    sn_vec3 *v = malloc(n * sizeof *v);
    sn_get_surface(r->inst, v, 0, n);
    for (i = 0; i < n; i++) { out[3 * i] = pu_len(v[i].x); out[3 * i + 1] = pu_len(v[i].y); out[3 * i + 2] = pu_len(v[i].z); }
    free(v);
}

/* Identity pose in runtime numbers. */
static inline void pu_identity(sn_xform *x, unsigned n) {
    unsigned j;
    memset(x, 0, n * sizeof *x);
#if defined(SN_FLOAT)
    for (j = 0; j < n; j++) x[j].rot.w = 1.0f;
#else
    for (j = 0; j < n; j++) x[j].rot.w = (sn_real)1 << SN_QUAT_FRAC;
#endif
}

/* Deterministic PRNG (64-bit LCG), uniform in [0,1). */
static inline double pu_rand(unsigned long long *st) {
    *st = *st * 6364136223846793005ULL + 1442695040888963407ULL;
    return (double)(*st >> 11) / 9007199254740992.0;
}

/* Random unit quaternion q (x,y,z,w): axis uniform in the unit ball (shell
 * 0.1..1 rejected for a well-defined direction), angle uniform in [0, maxdeg]. */
static inline void pu_random_quat(unsigned long long *st, double maxdeg, double q[4]) {
    double ax[3], n, a;
    int k;
    do {
        for (k = 0; k < 3; k++) ax[k] = 2 * pu_rand(st) - 1;
        n = sqrt(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    } while (n < 0.1 || n > 1);
    a = maxdeg * pu_rand(st) * 3.14159265358979323846 / 180;
    for (k = 0; k < 3; k++) q[k] = ax[k] / n * sin(a / 2);
    q[3] = cos(a / 2);
}

/* max_i |a_i - b_i| over n points (3 doubles each) */
static inline double pu_maxdist(const double *a, const double *b, unsigned n) {
    double mx = 0;
    unsigned i;
    for (i = 0; i < n; i++) {
        double dx = a[3 * i] - b[3 * i], dy = a[3 * i + 1] - b[3 * i + 1], dz = a[3 * i + 2] - b[3 * i + 2];
        double d = sqrt(dx * dx + dy * dy + dz * dz);
        if (d > mx) mx = d;
    }
    return mx;
}

/* White-box helpers for tests that read the instance's internals (built with
 * -Iruntime/src; define PU_WHITE_BOX before including this header):
 * pu_h, the instance header; pu_qd, an internal length (Q22 in fixed,
 * SN_Q_LEN) in internal units; pu_qr, a Q30 weight or coefficient;
 * pu_unit, one internal unit in mesh units (2^len_shift, from the blob);
 * pu_finite_state, pu_row_residual: the constraint tests' state and row checks. */
#ifdef PU_WHITE_BOX
#include "sn_instance.h"
#include "sn_constraint.h" /* pu_row_residual: the rows */
static inline sn_ihdr *pu_h(const pu_rt *r) { return (sn_ihdr *)(void *)r->inst; }
static inline double pu_qd(sn_q x) {
#if defined(SN_FLOAT)
    return x;
#else
    return ldexp((double)x, -SN_Q_LEN);
#endif
}
static inline double pu_qr(sn_q x) {
#if defined(SN_FLOAT)
    return x;
#else
    return ldexp((double)x, -30);
#endif
}
static inline double pu_unit(const pu_rt *r) {
    const unsigned char *b = (const unsigned char *)r->bytes;
    int ls = b[SN_H_LEN_SHIFT] < 128 ? b[SN_H_LEN_SHIFT] : b[SN_H_LEN_SHIFT] - 256;
    return ldexp(1.0, ls);
}
/* the state finite and within the state range (fixed: +-64 internal units; float: the guard) */
static inline int pu_finite_state(const pu_rt *r) {
    sn_ihdr *h = pu_h(r);
    const sn_q *pos = CARR(h, o_pos, sn_q), *vel = CARR(h, o_vel, sn_q);
    uint32_t i;
    for (i = 0; i < 3 * h->v.nV; i++)
        if (!(fabs(pu_qd(pos[i])) <= 4096.0) || !(fabs(pu_qd(vel[i])) <= 4096.0)) return 0;
    return 1;
}
/* Largest |C^T x - a| over the kept rows of one producer (SN_SRC_*, or
 * PU_ANY_PRODUCER), in LSB of Q22 (fixed) or relative to the row's scale
 * sum |c||x| + |a| (float). Coefficients as the runtime forms them (w dir
 * rounded to Q30). */
#define PU_ANY_PRODUCER (~0u)
static inline double pu_row_residual(const pu_rt *r, unsigned producer, uint32_t *kept) {
    sn_ihdr *h = pu_h(r);
    const sn_row *rows = sn_rows(h);
    const sn_rowx *rx = CARR(h, o_rx, sn_rowx);
    const sn_q *x = CARR(h, o_x, sn_q);
    uint32_t j, k, c, nF = h->v.nF;
    double worst = 0;
    *kept = 0;
    for (j = 0; j < h->n_rows; j++) {
        double s = 0, scale = 0, res;
        if (rx[j].inv == 0 || (producer != PU_ANY_PRODUCER && SN_ROW_PRODUCER(rows[j].source) != producer)) continue;
        (*kept)++;
        for (k = 0; k < rows[j].n; k++) {
            uint32_t a = rows[j].vtx[k];
            if (a >= nF) continue;
            for (c = 0; c < 3; c++) {
#if defined(SN_FLOAT)
                double e = (double)(rows[j].w[k] * rows[j].dir[c]);
#else
                double e = (double)(((int64_t)rows[j].w[k] * rows[j].dir[c] + ((int64_t)1 << 29)) >> 30);
#endif
                s += e * x[3 * a + c];
                scale += fabs(e * x[3 * a + c]);
            }
        }
#if defined(SN_FLOAT)
        res = fabs(s - rx[j].a) / (scale + fabs(rx[j].a) + 1e-30);
#else
        (void)scale;
        res = fabs(ldexp(s, -30) - rx[j].a);
#endif
        if (res > worst) worst = res;
    }
    return worst;
}
#endif /* PU_WHITE_BOX */

#endif
