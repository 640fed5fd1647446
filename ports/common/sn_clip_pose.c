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
static void put_uint(char *err, size_t cap, size_t *len, uint32_t v) {
    char d[12];
    int n = 11;
    d[11] = 0;
    do { d[--n] = (char)('0' + v % 10u); v /= 10u; } while (v);
    put(err, cap, len, d + n);
}

int sn_clip_bind(sn_clip *clip, const sn_blob *blob, char *err, size_t errlen) {
    sn_blob_info info;
    uint32_t c, j;
    size_t len = 0;
    if (errlen) err[0] = 0;
    sn_blob_get_info(blob, &info);
    clip->bound = 0;
    if (sn_clip_timestep_q16(blob) <= 0) {
        put(err, errlen, &len, "the blob's timestep is outside what clip time (Q16.16 seconds) can step: "
                               "a clip needs 2^-17 s <= h < 32768 s");
        return 1;
    }
    for (c = 0; c < clip->n_channels; c++) {
        sn_clip_channel *ch = &clip->chan[c];
        if (ch->kind == SN_CLIP_IMPULSE) {   /* profile and surface vertices must exist */
            uint32_t k;
            int32_t prof = 0;
            const char *q = ch->name;
            sn_blob_get_info(blob, &info);
            if (*q == '-') prof = -1;
            else for (; *q; q++) prof = prof * 10 + (*q - '0');
            if (prof >= 0 && (uint32_t)prof >= info.force_profiles) {
                put(err, errlen, &len, "clip impulse profile ");
                put(err, errlen, &len, ch->name);
                put(err, errlen, &len, " is not in the blob (it has fewer share profiles: sinew-bake lists them)");
                return 1;
            }
            for (k = ch->first; k < (uint32_t)ch->first + ch->count; k++)
                if ((uint32_t)clip->keys[k].v[3] >= info.surface_vertices) {
                    put(err, errlen, &len, "clip impulse on a surface vertex beyond the blob's");
                    return 1;
                }
            if (info.force_slots == 0) {
                put(err, errlen, &len, "the clip has impulses but the blob has no force slots (description: 'forces N')");
                return 1;
            }
            ch->joint = prof;
            continue;
        }
        if (ch->kind == SN_CLIP_COLLIDER) {
            if (clip->n_colliders > info.max_colliders) {
                put(err, errlen, &len, info.max_colliders ? "the clip has more collider channels than the blob's max_colliders (description: 'colliders N CONTACTS'; reuse a name for colliders one after another)"
                                                          : "the clip has colliders but the blob bakes none (description: 'colliders N CONTACTS')");
                return 1;
            }
            continue;
        }
        if (ch->kind == SN_CLIP_PIN) {   /* vertices must exist */
            uint32_t k;
            if (clip->n_pins > info.max_constraints) {
                put(err, errlen, &len, info.max_constraints ? "the clip has more pin channels than the blob's max_constraints (description: 'constraints N'; reuse a name for pins one after another)"
                                                            : "the clip has pins but the blob bakes no constraints (description: 'constraints N')");
                return 1;
            }
            for (k = ch->first; k < (uint32_t)ch->first + ch->count && k < SN_CLIP_MAX_KEYS; k++) {
                int32_t f = clip->keys[k].v[3];
                uint32_t v = (uint32_t)f & SN_CLIP_PIN_VERTEX;
                if (f & SN_CLIP_PIN_OFF) continue;
                if ((f & SN_CLIP_PIN_LATTICE) ? v >= info.free_vertices : v >= info.surface_vertices) {
                    put(err, errlen, &len, "clip pin '");
                    put(err, errlen, &len, ch->name);
                    put(err, errlen, &len, (f & SN_CLIP_PIN_LATTICE) ? "' names lattice vertex " : "' names surface vertex ");
                    put_uint(err, errlen, &len, v);
                    put(err, errlen, &len, ", but the blob has ");
                    put_uint(err, errlen, &len, (f & SN_CLIP_PIN_LATTICE) ? info.free_vertices : info.surface_vertices);
                    put(err, errlen, &len, (f & SN_CLIP_PIN_LATTICE) ? " free lattice vertices (sinew-bake lists the lattice)"
                                                                     : " surface vertices (those of the mesh it was baked from)");
                    return 1;
                }
            }
            continue;
        }
        if (ch->kind == SN_CLIP_CONTROL) {   /* a control the blob lacks: ignored (joint -1) */
            ch->joint = sn_find_control(blob, ch->name);
            if (ch->joint >= 0 && sn_control_kind_of(blob, (uint32_t)ch->joint) != SN_CONTROL_ABSTRACT) {
                put(err, errlen, &len, "clip control '");
                put(err, errlen, &len, ch->name);
                put(err, errlen, &len, "' is a pose control of the blob (read from the pose by sn_step): "
                                       "key its joint instead");
                return 1;
            }
            continue;
        }
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

/* The validator accepts any h > 0 (float: up to 32768 s), but clip time is
 * Q16.16: h below 2^-17 s rounds to 0 (a player dividing by it died with
 * SIGFPE) and h >= 32768 s overflows int32 (the float conversion was UB).
 * Such a timestep gives 0 here, and sn_clip_bind refuses the blob. */
int32_t sn_clip_timestep_q16(const sn_blob *blob) {
    sn_blob_info info;
    sn_blob_get_info(blob, &info);
#ifdef SN_FLOAT
    if (!(info.timestep >= 0.5f / 65536.0f && info.timestep < 32768.0f)) return 0; /* also NaN */
    {
        float q = info.timestep * 65536.0f + 0.5f;   /* in [1, 2^31]: 2^31 when h rounds up to 32768 */
        return q >= 2147483648.0f ? 0 : (int32_t)q;
    }
#else
    return info.timestep > 0 ? info.timestep : 0;
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
        if (!ch->count || ch->kind == SN_CLIP_CONTROL || ch->joint < 0 || (uint32_t)ch->joint >= info.joints) continue;
        if (ch->kind == SN_CLIP_COLLIDER || ch->kind == SN_CLIP_PIN || ch->kind == SN_CLIP_IMPULSE)
            continue;   /* not pose channels (an impulse channel's joint field holds its profile) */
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

/* ---- control tracks ---- */
uint32_t sn_clip_unbound_controls(const sn_clip *clip) {
    uint32_t c, n = 0;
    for (c = 0; c < clip->n_channels; c++)
        if (clip->chan[c].kind == SN_CLIP_CONTROL && clip->chan[c].joint < 0) n++;
    return n;
}

uint32_t sn_clip_controls(const sn_clip *clip, const sn_blob *blob, uint32_t step, sn_instance *inst) {
    sn_blob_info info;
    uint32_t c, n = 0;
    int32_t t = sn_clip_time(clip, sn_clip_timestep_q16(blob), step);
    sn_blob_get_info(blob, &info);
    for (c = 0; c < clip->n_channels; c++) {
        const sn_clip_channel *ch = &clip->chan[c];
        if (ch->kind != SN_CLIP_CONTROL || !ch->count || ch->joint < 0 || (uint32_t)ch->joint >= info.controls) continue;
        if (sn_set_control(inst, (uint32_t)ch->joint, from_q16(sn_clip_control_at(clip, c, t))) == SN_OK) n++;
    }
    return n;
}

/* ---- impulse events ---- */
uint32_t sn_clip_impulses(const sn_clip *clip, const sn_blob *blob, uint32_t step, sn_instance *inst) {
    int32_t h = sn_clip_timestep_q16(blob), t1, t0;
    uint32_t c, k, n = 0;
    if (step == 0 || h <= 0) return 0;
    t1 = sn_clip_time(clip, h, step);
    t0 = sn_clip_time(clip, h, step - 1u);
    for (c = 0; c < clip->n_channels; c++) {
        const sn_clip_channel *ch = &clip->chan[c];
        if (ch->kind != SN_CLIP_IMPULSE) continue;
        for (k = ch->first; k < (uint32_t)ch->first + ch->count && k < SN_CLIP_MAX_KEYS; k++) {
            const sn_clip_key *e = &clip->keys[k];
            /* (t0, t1]; a looping clip that wrapped covers (t0, duration] and [0, t1] */
            int in = t1 >= t0 ? (e->t > t0 && e->t <= t1) : (e->t > t0 || e->t <= t1);
            if (in && t1 != t0) {
                sn_force f;
                memset(&f, 0, sizeof f);
                f.at = SN_AT_SURFACE;
                f.vertex = (uint32_t)e->v[3];
                f.profile = ch->joint;
                f.force.x = from_q16(e->v[0]); f.force.y = from_q16(e->v[1]); f.force.z = from_q16(e->v[2]);
                if (sn_apply_impulse(inst, &f) == SN_OK) n++;
            }
        }
    }
    return n;
}

/* ---- colliders and pins ---- */

/* The channel's last key at or before t (NULL: before its first key). */
static const sn_clip_key *key_at(const sn_clip *clip, const sn_clip_channel *ch, int32_t t, uint32_t *idx) {
    uint32_t k, n = ch->count;
    const sn_clip_key *found = NULL;
    for (k = 0; k < n && (uint32_t)ch->first + k < SN_CLIP_MAX_KEYS && clip->keys[ch->first + k].t <= t; k++) {
        found = &clip->keys[ch->first + k];
        *idx = ch->first + k;
    }
    return found;
}

/* p + v dt, Q16.16 (dt Q16.16 s), rounded half away from zero. */
static int32_t moved(int32_t p, int32_t v, int32_t dt) {
    int64_t d = (int64_t)v * dt;
    d = d >= 0 ? (d + 32768) / 65536 : -((-d + 32768) / 65536);
    d += p;
    return d > INT32_MAX ? INT32_MAX : d < INT32_MIN ? INT32_MIN : (int32_t)d;
}

uint32_t sn_clip_colliders(const sn_clip *clip, const sn_blob *blob, uint32_t step,
                           sn_collider *out, uint32_t max) {
    int32_t h = sn_clip_timestep_q16(blob), t;
    uint32_t c, n = 0, idx = 0;
    if (h <= 0) return 0;
    t = sn_clip_time(clip, h, step ? step - 1u : 0u);
    for (c = 0; c < clip->n_channels && c < SN_CLIP_MAX_CHANNELS && n < max; c++) {
        const sn_clip_channel *ch = &clip->chan[c];
        const sn_clip_key *k;
        const sn_clip_shape *sh;
        sn_collider *o;
        int32_t dt;
        int i;
        if (ch->kind != SN_CLIP_COLLIDER || !(k = key_at(clip, ch, t, &idx))) continue;
        if (k->v[0] < 0 || k->v[0] >= clip->n_shapes || k->v[0] >= SN_CLIP_MAX_SHAPES) continue;
        sh = &clip->shapes[k->v[0]];
        dt = t - k->t;
        o = &out[n++];
        memset(o, 0, sizeof *o);
        o->kind = sh->kind;
        o->a.x = from_q16(moved(sh->a[0], sh->vel[0], dt));
        o->a.y = from_q16(moved(sh->a[1], sh->vel[1], dt));
        o->a.z = from_q16(moved(sh->a[2], sh->vel[2], dt));
        for (i = 0; i < 3; i++) {   /* plane: the normal does not move; capsule: the other end does */
            int32_t b = sh->kind == SN_COLLIDER_CAPSULE ? moved(sh->b[i], sh->vel[i], dt) : sh->b[i];
            if (i == 0) o->b.x = from_q16(b); else if (i == 1) o->b.y = from_q16(b); else o->b.z = from_q16(b);
        }
        o->radius = from_q16(sh->radius);
        o->velocity.x = from_q16(sh->vel[0]); o->velocity.y = from_q16(sh->vel[1]); o->velocity.z = from_q16(sh->vel[2]);
        o->friction = from_q16(sh->mu);
    }
    return n;
}

uint32_t sn_clip_constraints(const sn_clip *clip, const sn_blob *blob, uint32_t step,
                             const sn_instance *inst, sn_clip_hold *hold,
                             sn_constraint *out, uint32_t max) {
    int32_t h = sn_clip_timestep_q16(blob), t;
    uint32_t c, n = 0, idx = 0;
    if (h <= 0) return 0;
    t = sn_clip_time(clip, h, step);
    for (c = 0; c < clip->n_channels && c < SN_CLIP_MAX_CHANNELS && n < max; c++) {
        const sn_clip_channel *ch = &clip->chan[c];
        const sn_clip_key *k;
        sn_constraint *o;
        int32_t f, tx[3];
        uint32_t v;
        if (ch->kind != SN_CLIP_PIN || !(k = key_at(clip, ch, t, &idx))) continue;
        f = k->v[3];
        if (f & SN_CLIP_PIN_OFF) continue;
        v = (uint32_t)f & SN_CLIP_PIN_VERTEX;
        o = &out[n++];
        memset(o, 0, sizeof *o);
        o->at = (f & SN_CLIP_PIN_LATTICE) ? SN_AT_LATTICE : SN_AT_SURFACE;
        o->vertex = v;
        o->axes = ((uint32_t)f >> SN_CLIP_PIN_AXES_SHIFT) & SN_AXIS_ALL;
        if (f & SN_CLIP_PIN_HOLD) {
            if (hold[c].key_plus1 != idx + 1u) {   /* the key came into force: where the point is now */
                hold[c].key_plus1 = idx + 1u;
                if (!inst || (f & SN_CLIP_PIN_LATTICE ? sn_get_lattice(inst, &hold[c].at, v, 1)
                                                      : sn_get_surface(inst, &hold[c].at, v, 1)) != SN_OK)
                    memset(&hold[c].at, 0, sizeof hold[c].at);
            }
            o->target = hold[c].at;
            continue;
        }
        tx[0] = k->v[0]; tx[1] = k->v[1]; tx[2] = k->v[2];
        if (idx + 1u < (uint32_t)ch->first + ch->count && idx + 1u < SN_CLIP_MAX_KEYS) {
            const sn_clip_key *b = &clip->keys[idx + 1u];
            if (!(b->v[3] & (SN_CLIP_PIN_OFF | SN_CLIP_PIN_HOLD)) && b->v[3] == f && b->t > k->t) {
                int32_t u = (int32_t)(((int64_t)(t - k->t) << 30) / ((int64_t)b->t - k->t));
                tx[0] = lerp_q16(k->v[0], b->v[0], u);
                tx[1] = lerp_q16(k->v[1], b->v[1], u);
                tx[2] = lerp_q16(k->v[2], b->v[2], u);
            }
        }
        o->target.x = from_q16(tx[0]); o->target.y = from_q16(tx[1]); o->target.z = from_q16(tx[2]);
    }
    return n;
}
