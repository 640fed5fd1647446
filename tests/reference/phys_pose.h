/* phys_pose.h -- deterministic pose sequences for the physics tests, built with
 * the runtime's own helpers (sn_quat_axis_angle, sn_pose_from_local) so the
 * runtime and the reference get exactly the same transforms. Include after
 * phys_util.h. */
#ifndef PHYS_POSE_H
#define PHYS_POSE_H

#define PU_PI 3.14159265358979323846

static inline sn_quat pu_axis_angle(double ax, double ay, double az, double deg) {
    sn_vec3 a;
    a.x = pu_rlen(ax); a.y = pu_rlen(ay); a.z = pu_rlen(az);
    return sn_quat_axis_angle(a, pu_rang(deg));
}

/* A double quaternion (x, y, z, w) in runtime numbers (Q30 rounded / float). */
static inline sn_quat pu_quat(const double q[4]) {
    sn_quat r;
#if defined(SN_FLOAT)
    r.x = (float)q[0]; r.y = (float)q[1]; r.z = (float)q[2]; r.w = (float)q[3];
#else
    r.x = (sn_real)lround(ldexp(q[0], SN_QUAT_FRAC)); r.y = (sn_real)lround(ldexp(q[1], SN_QUAT_FRAC));
    r.z = (sn_real)lround(ldexp(q[2], SN_QUAT_FRAC)); r.w = (sn_real)lround(ldexp(q[3], SN_QUAT_FRAC));
#endif
    return r;
}

/* A whole pose moved rigidly: x -> G x, G = rotation qg about the world
 * origin, then translation tg (mesh units). */
static inline void pu_move_pose(const sn_xform *in, unsigned n, sn_quat qg, const double tg[3], sn_xform *out) {
    unsigned j;
    for (j = 0; j < n; j++) {
        sn_vec3 p = sn_quat_rotate(qg, in[j].pos);
        out[j].rot = sn_quat_mul(qg, in[j].rot);
        out[j].pos.x = pu_rlen(pu_len(p.x) + tg[0]);
        out[j].pos.y = pu_rlen(pu_len(p.y) + tg[1]);
        out[j].pos.z = pu_rlen(pu_len(p.z) + tg[2]);
    }
}

/* The rotation matrix (row-major, doubles) of a runtime quaternion. */
static inline void pu_qmat(sn_quat q, double R[9]) {
    double x = pu_q(q.x), y = pu_q(q.y), z = pu_q(q.z), w = pu_q(q.w);
    R[0] = 1 - 2 * (y * y + z * z); R[1] = 2 * (x * y - z * w); R[2] = 2 * (x * z + y * w);
    R[3] = 2 * (x * y + z * w); R[4] = 1 - 2 * (x * x + z * z); R[5] = 2 * (y * z - x * w);
    R[6] = 2 * (x * z - y * w); R[7] = 2 * (y * z + x * w); R[8] = 1 - 2 * (x * x + y * y);
}

/* Largest |G a - b| over n points (G: x -> R x + t), per component. */
static inline double pu_moved_err(const double *a, const double *b, unsigned n, const double R[9], const double t[3]) {
    double e = 0;
    unsigned i, k;
    for (i = 0; i < n; i++)
        for (k = 0; k < 3; k++) {
            double g = R[3 * k] * a[3 * i] + R[3 * k + 1] * a[3 * i + 1] + R[3 * k + 2] * a[3 * i + 2] + t[k];
            double d = fabs(g - b[3 * i + k]);
            e = d > e ? d : e;
        }
    return e;
}

static inline sn_quat pu_qident(void) {
    sn_quat q;
    memset(&q, 0, sizeof q);
#if defined(SN_FLOAT)
    q.w = 1.0f;
#else
    q.w = (sn_real)1 << SN_QUAT_FRAC;
#endif
    return q;
}

static inline void pu_set_local(const sn_blob *b, sn_quat *local, const char *name, sn_quat q) {
    int32_t j = sn_find_joint(b, name);
    if (j >= 0) local[j] = q;
}

/* Cow (and any asset with these joint names) at step k: head turning, neck
 * nodding, tail swinging, body bouncing and walking forward, a little roll. */
static inline void pu_cow_pose(const sn_blob *b, unsigned nJ, unsigned k, double h, sn_xform *out) {
    sn_quat local[256];
    sn_vec3 off;
    double t = k * h;
    unsigned j;
    for (j = 0; j < nJ; j++) local[j] = pu_qident();
    pu_set_local(b, local, "head", pu_axis_angle(0, 1, 0, 35 * sin(2 * PU_PI * 0.5 * t)));
    pu_set_local(b, local, "neck", pu_axis_angle(0, 0, 1, 15 * sin(2 * PU_PI * 0.7 * t)));
    pu_set_local(b, local, "tail_base", pu_axis_angle(0, 1, 0, 30 * sin(2 * PU_PI * 1.3 * t)));
    pu_set_local(b, local, "hips", pu_axis_angle(1, 0, 0, 5 * sin(2 * PU_PI * 0.9 * t)));
    pu_set_local(b, local, "hip_l", pu_axis_angle(0, 0, 1, 20 * sin(2 * PU_PI * 1.5 * t)));
    pu_set_local(b, local, "hip_r", pu_axis_angle(0, 0, 1, -20 * sin(2 * PU_PI * 1.5 * t)));
    pu_set_local(b, local, "shoulder_l", pu_axis_angle(0, 0, 1, -20 * sin(2 * PU_PI * 1.5 * t)));
    pu_set_local(b, local, "shoulder_r", pu_axis_angle(0, 0, 1, 20 * sin(2 * PU_PI * 1.5 * t)));
    off.x = pu_rlen(0.5 * t);                                  /* walk forward */
    off.y = pu_rlen(0.25 * sin(2 * PU_PI * 1.5 * t));           /* bounce */
    off.z = pu_rlen(0);
    sn_pose_from_local(b, local, &off, out);
}

/* Beast (upright humanoid, tools/examples/beast): walking in place along +z,
 * legs and arms swinging, elbows and knees bending, head turning. */
static inline void pu_beast_pose(const sn_blob *b, unsigned nJ, unsigned k, double h, sn_xform *out) {
    sn_quat local[256];
    sn_vec3 off;
    double t = k * h, w = 2 * PU_PI * 0.9 * t;
    unsigned j;
    for (j = 0; j < nJ; j++) local[j] = pu_qident();
    pu_set_local(b, local, "head", pu_axis_angle(0, 1, 0, 35 * sin(2 * PU_PI * 0.5 * t)));
    pu_set_local(b, local, "neck", pu_axis_angle(1, 0, 0, 10 * sin(2 * PU_PI * 0.7 * t)));
    pu_set_local(b, local, "hip_l", pu_axis_angle(1, 0, 0, 25 * sin(w)));
    pu_set_local(b, local, "hip_r", pu_axis_angle(1, 0, 0, -25 * sin(w)));
    pu_set_local(b, local, "knee_l", pu_axis_angle(1, 0, 0, 20 * (1 - cos(w))));
    pu_set_local(b, local, "knee_r", pu_axis_angle(1, 0, 0, 20 * (1 + cos(w))));
    pu_set_local(b, local, "shoulder_l", pu_axis_angle(1, 0, 0, -20 * sin(w)));
    pu_set_local(b, local, "shoulder_r", pu_axis_angle(1, 0, 0, 20 * sin(w)));
    pu_set_local(b, local, "elbow_l", pu_axis_angle(1, 0, 0, -15 * (1 - cos(w))));
    pu_set_local(b, local, "elbow_r", pu_axis_angle(1, 0, 0, -15 * (1 + cos(w))));
    off.x = pu_rlen(0);
    off.y = pu_rlen(3 * sin(2 * w));   /* bounce */
    off.z = pu_rlen(40 * t);           /* walk forward */
    sn_pose_from_local(b, local, &off, out);
}

/* Limb: elbow bending 0..90 degrees and back, shoulder twisting and lifting. */
static inline void pu_limb_pose(const sn_blob *b, unsigned nJ, unsigned k, double h, sn_xform *out) {
    sn_quat local[256];
    double t = k * h;
    unsigned j;
    for (j = 0; j < nJ; j++) local[j] = pu_qident();
    pu_set_local(b, local, "elbow", pu_axis_angle(0, 0, 1, 45 * (1 - cos(2 * PU_PI * 0.4 * t))));
    pu_set_local(b, local, "shoulder", sn_quat_mul(pu_axis_angle(1, 0, 0, 20 * sin(2 * PU_PI * 0.3 * t)),
                                                  pu_axis_angle(0, 0, 1, 15 * sin(2 * PU_PI * 0.6 * t))));
    sn_pose_from_local(b, local, NULL, out);
}

#endif
