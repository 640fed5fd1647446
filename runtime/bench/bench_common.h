/* bench_common.h -- what the benchmarks (bench.c, herd.c) share: the
 * flavour's unit macros, the blob loader and the pose sequence (every joint
 * swings about its own axis with its own period and phase, the root walks
 * and bobs, all fed through sn_pose_from_local, as a game would every frame). */
#ifndef SN_BENCH_COMMON_H
#define SN_BENCH_COMMON_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "sinew.h"

#if defined(SN_FLOAT)
#define FLAV "float"
#define LEN(x) ((float)(x))
#define DEG(x) ((float)(x))
#else
#define FLAV "fixed"
#define LEN(x) ((int32_t)floor((x) * 65536.0 + 0.5))
#define DEG(x) ((int32_t)floor((x) * 65536.0 + 0.5))
#endif

/* the whole file, malloc'd (16-byte aligned: the blob needs 8) */
static unsigned char *bench_load(const char *path, size_t *size) {
    FILE *f = fopen(path, "rb");
    unsigned char *p;
    long n;
    if (!f) return NULL;
    fseek(f, 0, SEEK_END);
    n = ftell(f);
    fseek(f, 0, SEEK_SET);
    p = (unsigned char *)malloc((size_t)n + 8);
    if (p && fread(p, 1, (size_t)n, f) != (size_t)n) { free(p); p = NULL; }
    fclose(f);
    *size = (size_t)n;
    return p;
}

static int bench_cmp_d(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* The pose at time t (seconds): per joint a swing of up to 25 degrees. */
static void bench_pose(const sn_blob *blob, uint32_t nJ, double t, sn_quat *local, sn_xform *out) {
    uint32_t j;
    sn_vec3 root;
    for (j = 0; j < nJ; j++) {
        sn_vec3 ax;
        double ph = 0.7 * j, per = 0.8 + 0.13 * (j % 5);
        ax.x = LEN(cos(1.3 * j));
        ax.y = LEN(0.5);
        ax.z = LEN(sin(1.3 * j));
        local[j] = sn_quat_axis_angle(ax, DEG((j == 0 ? 8.0 : 25.0) * sin(2 * 3.14159265358979 * t / per + ph)));
    }
    root.x = LEN(0.4 * t);
    root.y = LEN(0.05 * sin(2 * 3.14159265358979 * t * 2));
    root.z = LEN(0.0);
    sn_pose_from_local(blob, local, &root, out);
}

#endif /* SN_BENCH_COMMON_H */
