/* sn_wiggle.h -- the pose sequence the integration consumers step the cow
 * with: the built-in sequence of ports/cross/sn_det.c (every non-root joint
 * swings +-20 degrees about a model axis, triangle wave with its own phase;
 * the root bobs), written against the public API only, so the hash after N
 * steps equals `det_main BLOB --steps N` (no clip) of the determinism suite.
 * tests/scripts/test_integration.sh checks that they agree.
 * `phase` shifts the sequence (0: exactly sn_det's), so instances of the
 * thread test follow different motions. Header only, C99 and C++98..C++17. */
#ifndef SN_WIGGLE_H
#define SN_WIGGLE_H

#include <stdint.h>
#include "sinew.h"

#ifdef SN_FLOAT
static inline sn_real sn_wiggle_q16(int32_t v) { return (sn_real)v / 65536.0f; }
#define SN_WIGGLE_ONE 1.0f
#else
static inline sn_real sn_wiggle_q16(int32_t v) { return v; }
#define SN_WIGGLE_ONE ((sn_real)1 << SN_QUAT_FRAC)
#endif

/* Local rotations for step k (k = 0, 1, ...) into local[n_joints], then the
 * model-space pose into xf[n_joints]; set it with sn_set_pose before sn_step. */
static inline void sn_wiggle_pose(const sn_blob *blob, uint32_t n_joints, uint32_t k, uint32_t phase,
                                  sn_quat *local, sn_xform *xf) {
    uint32_t j;
    sn_vec3 root;
    k += phase;
    for (j = 0; j < n_joints; j++) {
        sn_vec3 axis;
        int32_t p = (int32_t)((k * 4u + j * 13u) % 128u);
        int32_t tri = p < 64 ? p : 128 - p;             /* 0..64 */
        if (j == 0) { local[j].x = local[j].y = local[j].z = 0; local[j].w = SN_WIGGLE_ONE; continue; }
        axis.x = sn_wiggle_q16(j % 3u == 0 ? 65536 : 0);
        axis.y = sn_wiggle_q16(j % 3u == 1 ? 65536 : 0);
        axis.z = sn_wiggle_q16(j % 3u == 2 ? 65536 : 32768);
        local[j] = sn_quat_axis_angle(axis, sn_wiggle_q16((tri - 32) * 40960));
    }
    root.x = 0;
    root.y = sn_wiggle_q16(((int32_t)(k % 64u) - 32) * 64);
    root.z = 0;
    sn_pose_from_local(blob, local, &root, xf);
}

/* 16 lowercase hex digits of h plus NUL. */
static inline void sn_wiggle_hex(uint64_t h, char out[17]) {
    int i;
    for (i = 15; i >= 0; i--) { out[i] = "0123456789abcdef"[h & 15u]; h >>= 4; }
    out[16] = 0;
}

#endif /* SN_WIGGLE_H */
