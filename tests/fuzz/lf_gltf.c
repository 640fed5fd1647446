/* lf_gltf.c -- libFuzzer harness: the host tool's glTF 2.0 reader
 * (tools/sb_gltf.c, sb_gltf_data.c, sb_json.c; sb_gltf_load). Built by
 * tests/fuzz/fuzz.mk as fuzz_gltf. The loader takes a path, so each input is
 * written to a temp file first (lf_common.h); .gltf and .glb are told apart
 * by the GLB magic. Checks besides the sanitizers: an error leaves a message
 * and an empty result; an accepted mesh has nv, nt, nj >= 1, triangle and
 * joint indices in range, finite positions and joint positions, weights
 * >= 0 summing to 1 and joint parents inside the skin.
 */
#include "lf_common.h" /* first: it sets _POSIX_C_SOURCE */

#include <math.h>
#include "sb.h"
#include "sb_gltf.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
    sb_gltf g;
    int i, k;
    const char *path = lf_tmp_write(data, size);
    if (sb_gltf_load(&g, path, NULL) != 0) {
        LF_REQUIRE(sb_error() && sb_error()[0], "sb_gltf_load failed without a message");
        LF_REQUIRE(g.nv == 0 && g.pos == NULL && g.joints == NULL && g.tri == NULL, "a failed load left data");
        return 0;
    }
    LF_REQUIRE(g.nv >= 1 && g.nt >= 1 && g.nj >= 1, "nv %d nt %d nj %d", g.nv, g.nt, g.nj);
    for (i = 0; i < 3 * g.nt; i++) LF_REQUIRE(g.tri[i] >= 0 && g.tri[i] < g.nv, "triangle index %d", g.tri[i]);
    for (i = 0; i < 3 * g.nv; i++) LF_REQUIRE(isfinite(g.pos[i]), "position %g", g.pos[i]);
    for (i = 0; i < g.nv; i++) {
        double s = 0;
        for (k = 0; k < 4; k++) {
            LF_REQUIRE(g.joint[4 * i + k] >= 0 && g.joint[4 * i + k] < g.nj, "joint %d", g.joint[4 * i + k]);
            LF_REQUIRE(g.weight[4 * i + k] >= 0, "weight %g", g.weight[4 * i + k]);
            s += g.weight[4 * i + k];
        }
        LF_REQUIRE(fabs(s - 1) < 1e-9, "weights sum to %g", s);
    }
    for (i = 0; i < g.nj; i++) {
        LF_REQUIRE(g.joints[i].parent >= -1 && g.joints[i].parent < g.nj, "parent %d", g.joints[i].parent);
        for (k = 0; k < 3; k++) LF_REQUIRE(isfinite(g.joints[i].pos[k]) && isfinite(g.joints[i].node_pos[k]), "joint position");
    }
    {
        sb_gltf_anim a;
        if (sb_gltf_anim_load(&a, path, &g, NULL, 1.0 / 60, 120) != 0) {   /* 2 s: longer ones are refused, cheaply */
            LF_REQUIRE(sb_error() && sb_error()[0], "sb_gltf_anim_load failed without a message");
            LF_REQUIRE(a.rot == NULL && a.nframes == 0, "a failed animation load left data");
        } else {
            char *clip;
            LF_REQUIRE(a.nframes >= 1 && a.nj == g.nj, "frames %d joints %d", a.nframes, a.nj);
            for (i = 0; i < a.nframes * a.nj; i++) {
                const double *q = a.rot + 4 * i;
                double n = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
                LF_REQUIRE(fabs(n - 1) < 1e-9 && q[3] >= 0, "quaternion %g %g %g %g", q[0], q[1], q[2], q[3]);
            }
            for (i = 0; i < 3 * a.nframes; i++) LF_REQUIRE(isfinite(a.move[i]), "root offset %g", a.move[i]);
            clip = sb_gltf_anim_clip(&a, &g, 1092, 1, "fuzz");
            LF_REQUIRE(clip || (sb_error() && sb_error()[0]), "sb_gltf_anim_clip failed without a message");
            free(clip);
            sb_gltf_anim_free(&a);
        }
    }
    sb_gltf_free(&g);
    return 0;
}
