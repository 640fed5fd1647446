/* sn_det.c -- determinism workload (see sn_det.h). Integer-only in the fixed
 * flavour; in the float flavour only the final conversions are float. */
#include <string.h>
#include "sn_det.h"

#ifdef SN_FLOAT
static sn_real from_q16(int32_t v) { return (sn_real)v / 65536.0f; }
static const sn_real ONE = 1.0f;
#else
static sn_real from_q16(int32_t v) { return v; }
static const sn_real ONE = (sn_real)1 << SN_QUAT_FRAC;
#endif

static void put(char *err, size_t cap, size_t *len, const char *s) {
    for (; *s; s++) if (*len + 1 < cap) err[(*len)++] = *s;
    if (cap) err[*len] = 0;
}

static int det_init(sn_det *d, const void *blob, size_t blob_size,
                    const char *clip_text, size_t clip_len, sn_clip *clip,
                    void *mem, size_t mem_size, void *ws, size_t ws_size,
                    char *err, size_t errlen) {
    sn_blob_info info;
    sn_status s;
    size_t len = 0;
    if (errlen) err[0] = 0;
    d->clip = NULL;
    d->k = 0;
    d->ws = ws;
    d->ws_size = ws_size;
    d->refused = 0;
    s = sn_blob_validate(blob, blob_size, &d->blob);
    if (s != SN_OK) { put(err, errlen, &len, "blob: "); put(err, errlen, &len, sn_status_str(s)); return 1; }
    sn_blob_get_info(d->blob, &info);
    d->n_joints = info.joints;
    if (info.joints > SN_DET_MAX_JOINTS) { put(err, errlen, &len, "too many joints"); return 1; }
    s = ws ? sn_instance_init_shared(mem, mem_size, d->blob, &d->inst)
           : sn_instance_init(mem, mem_size, d->blob, &d->inst);
    if (s != SN_OK) { put(err, errlen, &len, "instance: "); put(err, errlen, &len, sn_status_str(s)); return 1; }
    if (clip_text) {
        if (sn_clip_parse(clip, clip_text, clip_len, err, errlen)) return 1;
        if (sn_clip_bind(clip, d->blob, err, errlen)) return 1;
        d->clip = clip;
    }
    return 0;
}

int sn_det_init(sn_det *d, const void *blob, size_t blob_size,
                const char *clip_text, size_t clip_len, sn_clip *clip,
                void *mem, size_t mem_size, char *err, size_t errlen) {
    return det_init(d, blob, blob_size, clip_text, clip_len, clip, mem, mem_size, NULL, 0, err, errlen);
}

int sn_det_init_shared(sn_det *d, const void *blob, size_t blob_size,
                       const char *clip_text, size_t clip_len, sn_clip *clip,
                       void *mem, size_t mem_size, void *ws, size_t ws_size,
                       char *err, size_t errlen) {
    size_t len = 0;
    if (!ws) { if (errlen) err[0] = 0; put(err, errlen, &len, "no workspace"); return 1; }
    return det_init(d, blob, blob_size, clip_text, clip_len, clip, mem, mem_size, ws, ws_size, err, errlen);
}

/* Built-in sequence for assets without a clip: every non-root joint swings
 * +-20 degrees (triangle wave, own phase) about a model axis, root bobs. */
static void builtin_pose(sn_det *d) {
    uint32_t j, k = d->k;
    sn_vec3 root;
    for (j = 0; j < d->n_joints; j++) {
        sn_vec3 axis;
        int32_t p = (int32_t)((k * 4u + j * 13u) % 128u);
        int32_t tri = p < 64 ? p : 128 - p;             /* 0..64 */
        if (j == 0) { d->local[j].x = d->local[j].y = d->local[j].z = 0; d->local[j].w = ONE; continue; }
        axis.x = from_q16(j % 3u == 0 ? 65536 : 0);
        axis.y = from_q16(j % 3u == 1 ? 65536 : 0);
        axis.z = from_q16(j % 3u == 2 ? 65536 : 32768);
        d->local[j] = sn_quat_axis_angle(axis, from_q16((tri - 32) * 40960)); /* 20/32 deg per unit */
    }
    root.x = 0;
    root.y = from_q16(((int32_t)(k % 64u) - 32) * 64);     /* +-1/32 mesh unit */
    root.z = 0;
    sn_pose_from_local(d->blob, d->local, &root, d->xf);
}

void sn_det_pose(sn_det *d) {
    /* step k+1 ends at time (k+1)h: pose it there, as sinew-play does */
    if (d->clip) sn_clip_pose(d->clip, d->blob, d->k + 1u, d->local, d->xf);
    else builtin_pose(d);
    (void)sn_set_pose(d->inst, d->xf, d->n_joints);
    if (d->clip) (void)sn_clip_controls(d->clip, d->blob, d->k + 1u, d->inst); /* rig control tracks */
    if (d->clip) (void)sn_clip_impulses(d->clip, d->blob, d->k + 1u, d->inst); /* hits on the flesh */
}

void sn_det_step(sn_det *d) {
    if (d->ws) { if (sn_step_with(d->inst, d->ws, d->ws_size) != SN_OK) d->refused++; }
    else sn_step(d->inst);
    d->k++;
}

uint64_t sn_det_run(sn_det *d, uint32_t n) {
    uint32_t i;
    for (i = 0; i < n; i++) { sn_det_pose(d); sn_det_step(d); }
    return sn_state_hash(d->inst);
}

int sn_det_contact(sn_det *d) {
    sn_blob_info bi;
    sn_collider col[2];
    sn_constraint con[4];
    sn_vec3 p;
    sn_real ylow = 0;
    uint32_t s, i;
    sn_blob_get_info(d->blob, &bi);
    if (bi.max_constraints < 4 || bi.max_colliders < 2 || bi.surface_vertices < 4) return 0;
    (void)sn_reset(d->inst);
    d->k = 0;
    for (s = 0; s < bi.surface_vertices; s++) { /* rest positions before the first step */
        (void)sn_get_surface(d->inst, &p, s, 1);
        if (s == 0 || p.y < ylow) ylow = p.y;
    }
    memset(col, 0, sizeof col);
    col[0].kind = SN_COLLIDER_PLANE;
    col[0].a.y = ylow + from_q16(3277);          /* 0.05 */
    col[0].b.y = from_q16(65536);
    col[1].kind = SN_COLLIDER_SPHERE;
    col[1].a.y = ylow - from_q16(45875);         /* 0.7 below the lowest point: 0.3 of it inside the ground's flesh */
    col[1].radius = from_q16(65536);
    col[1].velocity.y = from_q16(19661);         /* 0.3 per second */
    memset(con, 0, sizeof con);
    for (i = 0; i < 4; i++) {
        static const uint32_t pick[4] = {2126u, 2362u, 1732u, 2901u}; /* cow.obj: vertices the flesh carries (not the bones) */
        con[i].at = SN_AT_SURFACE;
        con[i].vertex = pick[i] % bi.surface_vertices;
        (void)sn_get_surface(d->inst, &p, con[i].vertex, 1);
        con[i].target = p;
        con[i].target.y = p.y + from_q16(6554);  /* 0.1 */
        con[i].axes = i == 3 ? SN_AXIS_Y : 0;
    }
    (void)sn_set_colliders(d->inst, col, 2);
    (void)sn_set_constraints(d->inst, con, 4);
    return 1;
}

int sn_det_blended(sn_det *d) {
    if (sn_set_mode(d->inst, SN_MODE_BLENDED) != SN_OK) return 0;
    (void)sn_reset(d->inst);
    d->k = 0;
    return 1;
}

void sn_det_hex64(uint64_t h, char out[17]) {
    int i;
    for (i = 15; i >= 0; i--) { out[i] = "0123456789abcdef"[h & 15u]; h >>= 4; }
    out[16] = 0;
}
