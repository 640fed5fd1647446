/* sn_clip_pose.c -- bind a parsed clip to a blob and sample poses through the
 * runtime's own quaternion helpers. Times and interpolation weights are
 * integers in both flavours; the float flavour converts only at the end. */
#include "sn_clip.h"
#include <string.h>

#ifdef SN_FLOAT
static sn_real from_q16(int32_t v) { return (sn_real)v / 65536.0f; }
static sn_real from_q30(int32_t v) { return (sn_real)v / 1073741824.0f; }
static const sn_real ONE = 1.0f;
#else
static sn_real from_q16(int32_t v) { return v; }
static sn_real from_q30(int32_t v) { return v; }
static const sn_real ONE = (sn_real)1 << SN_QUAT_FRAC;
#endif

static void put(char *err, size_t cap, size_t *len, const char *s) {
    for (; *s; s++) if (*len + 1 < cap) err[(*len)++] = *s;
    if (cap) err[*len] = 0;
}

int sn_clip_bind(sn_clip *clip, const sn_blob *blob, char *err, size_t errlen) {
    sn_blob_info info;
    uint32_t c, j;
    size_t len = 0;
    if (errlen) err[0] = 0;
    sn_blob_get_info(blob, &info);
    clip->bound = 0;
    for (c = 0; c < clip->n_channels; c++) {
        sn_clip_channel *ch = &clip->chan[c];
        ch->joint = ch->kind == SN_CLIP_MOVE ? 0 : sn_find_joint(blob, ch->name);
        if (ch->joint < 0) {
            put(err, errlen, &len, "clip joint '");
            put(err, errlen, &len, ch->name);
            put(err, errlen, &len, "' is not in the blob's skeleton (joints:");
            for (j = 0; j < info.joints; j++) {
                const char *n = sn_joint_name(blob, j);
                put(err, errlen, &len, " ");
                put(err, errlen, &len, n ? n : "?");
            }
            put(err, errlen, &len, ")");
            return 1;
        }
    }
    clip->bound = 1;
    return 0;
}

int32_t sn_clip_timestep_q16(const sn_blob *blob) {
    sn_blob_info info;
    sn_blob_get_info(blob, &info);
#ifdef SN_FLOAT
    return (int32_t)(info.timestep * 65536.0f + 0.5f);
#else
    return info.timestep;
#endif
}

int32_t sn_clip_time(const sn_clip *clip, int32_t h_q16, uint32_t step) {
    int64_t t = (int64_t)step * h_q16;
    if (clip->loop) return (int32_t)(t % clip->duration);
    return t > clip->duration ? clip->duration : (int32_t)t;
}

/* Keys a, b around t and the weight of b in Q30 (0 when t is outside the keys). */
static void segment(const sn_clip *clip, const sn_clip_channel *ch, int32_t t,
                    const sn_clip_key **a, const sn_clip_key **b, int32_t *u) {
    const sn_clip_key *k = &clip->keys[ch->first];
    uint32_t i, n = ch->count;
    *u = 0;
    if (t <= k[0].t) { *a = *b = &k[0]; return; }
    if (t >= k[n - 1].t) { *a = *b = &k[n - 1]; return; }
    for (i = 0; i + 2 < n && k[i + 1].t <= t; i++) {}
    *a = &k[i]; *b = &k[i + 1];
    *u = (int32_t)(((int64_t)(t - k[i].t) << 30) / (k[i + 1].t - k[i].t));
}

static sn_quat key_quat(const sn_clip_key *k) {
    sn_vec3 axis;
    axis.x = from_q16(k->v[0]); axis.y = from_q16(k->v[1]); axis.z = from_q16(k->v[2]);
    return sn_quat_axis_angle(axis, from_q16(k->v[3]));
}

static int32_t lerp_q16(int32_t a, int32_t b, int32_t u) {
    int64_t d = (int64_t)b - a, p = d * u;
    /* round half away from zero without shifting a negative value */
    p = p >= 0 ? (p + (1 << 29)) / (1 << 30) : -((-p + (1 << 29)) / (1 << 30));
    return (int32_t)(a + p);
}

void sn_clip_sample(const sn_clip *clip, const sn_blob *blob, int32_t t,
                    sn_quat *local, sn_vec3 *root) {
    sn_blob_info info;
    uint32_t j, c;
    sn_blob_get_info(blob, &info);
    for (j = 0; j < info.joints; j++) {
        local[j].x = local[j].y = local[j].z = 0;
        local[j].w = ONE;
    }
    root->x = root->y = root->z = 0;
    for (c = 0; c < clip->n_channels; c++) {
        const sn_clip_channel *ch = &clip->chan[c];
        const sn_clip_key *a, *b;
        int32_t u;
        if (!ch->count || ch->joint < 0 || (uint32_t)ch->joint >= info.joints) continue;
        segment(clip, ch, t, &a, &b, &u);
        if (ch->kind == SN_CLIP_MOVE) {
            root->x = from_q16(lerp_q16(a->v[0], b->v[0], u));
            root->y = from_q16(lerp_q16(a->v[1], b->v[1], u));
            root->z = from_q16(lerp_q16(a->v[2], b->v[2], u));
        } else if (a == b || u == 0) {
            local[ch->joint] = key_quat(a);
        } else {
            local[ch->joint] = sn_quat_slerp(key_quat(a), key_quat(b), from_q30(u));
        }
    }
}

void sn_clip_pose(const sn_clip *clip, const sn_blob *blob, uint32_t step,
                  sn_quat *local, sn_xform *out) {
    sn_vec3 root;
    int32_t t = sn_clip_time(clip, sn_clip_timestep_q16(blob), step);
    sn_clip_sample(clip, blob, t, local, &root);
    sn_pose_from_local(blob, local, &root, out);
}
