/* cost_probe.c -- steps the fixed cow under one of three pose regimes, for
 * tests/scripts/test_cost.sh to count sn_step's instructions with callgrind
 * (issue 16 item 4: the cost of a step is a function of the blob, not of the
 * pose or the state).
 *   cost_probe BLOB MODE STEPS [NCON]    MODE 0 rest, 1 trot-like swings, 2 adversarial
 * (uniformly random rotations every step, every joint; controls at extremes).
 * NCON > 0 (issue 12): that many position constraints (surface vertices
 * spread over the mesh pinned where they rest, all three axes), to count the
 * step's instructions with 3 NCON rows; the rows kept go to stderr. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "sinew.h"

static unsigned long long g_st = 88172645463325252ull;
static double urand(void) {
    g_st ^= g_st << 13; g_st ^= g_st >> 7; g_st ^= g_st << 17;
    return (double)(g_st >> 11) / 9007199254740992.0;
}

int main(int argc, char **argv) {
    FILE *f;
    long n;
    unsigned char *bytes;
    void *mem;
    const sn_blob *blob;
    sn_instance *inst;
    sn_blob_info info;
    sn_quat loc[256];
    sn_xform x[256];
    int mode, steps, s;
    unsigned j, k;
    int ncon = argc == 5 ? atoi(argv[4]) : 0;
    if (argc != 4 && argc != 5) { fprintf(stderr, "usage: cost_probe BLOB MODE STEPS [NCON]\n"); return 2; }
    mode = atoi(argv[2]);
    steps = atoi(argv[3]);
    f = fopen(argv[1], "rb");
    if (!f) { perror(argv[1]); return 2; }
    fseek(f, 0, SEEK_END); n = ftell(f); fseek(f, 0, SEEK_SET);
    bytes = malloc((size_t)n + 8);
    if (!bytes || fread(bytes, 1, (size_t)n, f) != (size_t)n) return 2;
    fclose(f);
    if (sn_blob_validate(bytes, (size_t)n, &blob) != SN_OK) { fprintf(stderr, "invalid blob\n"); return 2; }
    sn_blob_get_info(blob, &info);
    mem = malloc(sn_instance_size(blob) + 8);
    if (!mem || sn_instance_init(mem, sn_instance_size(blob), blob, &inst) != SN_OK) return 2;
    if (ncon > 0) {   /* pins that stay active: a candidate is taken when a trial step (on a copy) keeps all its rows */
        sn_constraint c[64];
        void *trial = malloc(sn_instance_size(blob) + 8);
        sn_instance *ti;
        int i = 0;
        unsigned cand;
        memset(c, 0, sizeof c);
        if (!trial) return 2;
        for (cand = 0; cand < info.surface_vertices && i < ncon && i < 64; cand++) {
            sn_stats st;
            c[i].at = SN_AT_SURFACE;
            c[i].vertex = (cand * 997u + 13u) % info.surface_vertices;
            sn_get_surface(inst, &c[i].target, c[i].vertex, 1);
            memcpy(trial, mem, sn_instance_size(blob));
            ti = (sn_instance *)trial;
            if (sn_set_constraints(ti, c, (uint32_t)i + 1u) != SN_OK) break;
            sn_step(ti);
            sn_get_stats(ti, &st);
            if (st.constraint_rows == 3u * ((uint32_t)i + 1u)) i++;
        }
        free(trial);
        ncon = i;
        if (sn_set_constraints(inst, c, (uint32_t)ncon) != SN_OK) { fprintf(stderr, "constraints refused\n"); return 2; }
    }
    for (j = 0; j < info.controls; j++)
        sn_set_control(inst, j, mode == 2 ? ((j & 1) ? INT32_MAX : -INT32_MAX) : 0);
    for (s = 0; s < steps; s++) {
        for (j = 0; j < info.joints; j++) {
            if (mode == 0) {
                memset(&loc[j], 0, sizeof loc[j]);
                loc[j].w = 1 << 30;
            } else if (mode == 1) {
                sn_vec3 ax = {0, 0, 65536};
                loc[j] = sn_quat_axis_angle(ax, (sn_real)(30 * 65536 * sin(s * 0.2 + j)));
            } else {
                double q[4], nn = 0;
                for (k = 0; k < 4; k++) { q[k] = 2 * urand() - 1; nn += q[k] * q[k]; }
                nn = sqrt(nn) + 1e-9;
                loc[j].x = (sn_real)(q[0] / nn * 1073741823.0); loc[j].y = (sn_real)(q[1] / nn * 1073741823.0);
                loc[j].z = (sn_real)(q[2] / nn * 1073741823.0); loc[j].w = (sn_real)(q[3] / nn * 1073741823.0);
            }
        }
        sn_pose_from_local(blob, loc, NULL, x);
        sn_set_pose(inst, x, info.joints);
        sn_step(inst);
    }
    if (ncon > 0) {
        sn_stats st;
        sn_get_stats(inst, &st);
        fprintf(stderr, "constraints %d: rows kept %u, drops %u, saturations %u\n", ncon, st.constraint_rows, st.constraint_drops, st.saturations);
    }
    free(mem);
    free(bytes);
    return 0;
}
