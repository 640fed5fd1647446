/* level_util.h -- what the level tests share (test_runtime_level.c,
 * test_runtime_adapt.c, test_runtime_cut.c, test_runtime_details.c,
 * test_runtime_dstep.c): the flavour's real <-> double conversions, a blob
 * loader (with 8 spare bytes, so a short read never overruns), a joint's
 * ramp, the distance between two surfaces in cells, the blob's cell edge and the violent swing. */
#ifndef SN_LEVEL_UTIL_H
#define SN_LEVEL_UTIL_H
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sinew.h"
#include "sn_format.h"
#include "sn_test.h"

#if defined(SN_FLOAT)
#define D(x) ((double)(x))
#define R(x) ((float)(x))
#define FL "float"
#else
#define D(x) ((double)(x) / 65536.0)
#define R(x) ((int32_t)floor((x) * 65536.0 + 0.5))
#define FL "fixed"
#endif

static unsigned char *load(const char *path, size_t *n) { return (unsigned char *)t_read_file(path, n); }

/* the ramps of the cut-level tests: JOINT's local rotation by deg * min(step / 12, 1) about axis, the rest at rest */
static inline void ramp_pose(const sn_blob *blob, uint32_t nj, int32_t joint, int axis, double deg, int step, sn_xform *xf)
{
    sn_quat *local = malloc(sizeof *local * nj);
    uint32_t j;
    double a = deg * (step < 12 ? step / 12.0 : 1.0);
    for (j = 0; j < nj; j++) {
        sn_vec3 ax;
        ax.x = R(axis == 0 ? 1.0 : 0.0); ax.y = R(axis == 1 ? 1.0 : 0.0); ax.z = R(axis == 2 ? 1.0 : 0.0);
        local[j] = sn_quat_axis_angle(ax, R((int32_t)j == joint ? a : 0.0));
    }
    sn_pose_from_local(blob, local, NULL, xf);
    free(local);
}

/* the largest and the rms distance between two surfaces of n points, in cells */
static inline void surf_dist(const sn_vec3 *a, const sn_vec3 *b, uint32_t n, double cell, double *mx, double *rms)
{
    double m = 0, s = 0;
    uint32_t i;
    for (i = 0; i < n; i++) {
        double dx = D(a[i].x) - D(b[i].x), dy = D(a[i].y) - D(b[i].y), dz = D(a[i].z) - D(b[i].z), d2 = dx * dx + dy * dy + dz * dz;
        m = fmax(m, sqrt(d2));
        s += d2;
    }
    *mx = m / cell;
    *rms = sqrt(s / n) / cell;
}

/* the blob's cell edge in mesh units (header real SN_R_CELL: internal Q22, unit 2^len_shift) */
static double cell_of(const unsigned char *b)
{
    int ls = b[SN_H_LEN_SHIFT] < 128 ? b[SN_H_LEN_SHIFT] : b[SN_H_LEN_SHIFT] - 256;
    const unsigned char *r = b + SN_H_REALS + 4 * SN_R_CELL;
    uint32_t u = (uint32_t)r[0] | (uint32_t)r[1] << 8 | (uint32_t)r[2] << 16 | (uint32_t)r[3] << 24;
#if defined(SN_FLOAT)
    float f;
    memcpy(&f, &u, 4);
    return ldexp((double)f, ls);
#else
    return ldexp((double)(int32_t)u, ls - 22);
#endif
}

/* every non-root joint swings about a tilted axis, each with its own phase: motion everywhere */
static void pose_at(const sn_blob *blob, uint32_t nj, int step, sn_xform *xf)
{
    sn_quat *local = malloc(sizeof *local * nj);
    uint32_t j;
    for (j = 0; j < nj; j++) {
        sn_vec3 ax;
        double a = j == 0 ? 0 : 25.0 * sin(2 * 3.14159265358979 * step / 50.0 + 0.7 * j);
        ax.x = R(1.0); ax.y = R(0.3); ax.z = R(0.2 * (j % 3));
        local[j] = sn_quat_axis_angle(ax, R(a));
    }
    sn_pose_from_local(blob, local, NULL, xf);
    free(local);
}

#endif
