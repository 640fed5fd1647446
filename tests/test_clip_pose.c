/* test_clip_pose.c -- clip binding and sampling through the runtime
 * (ports/common/sn_clip_pose.c) against a double-precision reference:
 * axis-angle quaternions and slerp recomputed in double from the clip text.
 * Built for both flavours; reads the baked cow ($BUILD/examples/cow.blob or
 * cow_float.blob; SN_TEST_BLOB overrides) and uses whatever joints it has. */
#include "sn_test.h"
#include "sn_clip.h"
#include <stdint.h>
#include <string.h>

#ifdef SN_FLOAT
#define BLOB_NAME "cow_float.blob"
static double D(sn_real v) { return v; }
static double DQ(sn_real v) { return v; }
#else
#define BLOB_NAME "cow.blob"
static double D(sn_real v) { return v / 65536.0; }
static double DQ(sn_real v) { return v / 1073741824.0; }
#endif

static sn_clip clip;
static char err[SN_CLIP_ERR_LEN];

typedef struct { double x, y, z, w; } dq;

static dq axis_angle(double ax, double ay, double az, double deg) {
    double l = sqrt(ax * ax + ay * ay + az * az), h = deg * 3.14159265358979323846 / 360.0, s = sin(h) / l;
    dq q = {ax * s, ay * s, az * s, cos(h)};
    return q;
}
static dq slerp(dq a, dq b, double u) {
    double c = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w, th, wa, wb;
    dq r;
    if (c < 0) { c = -c; b.x = -b.x; b.y = -b.y; b.z = -b.z; b.w = -b.w; }
    if (c > 1) c = 1;
    th = acos(c);
    if (th < 1e-9) { wa = 1 - u; wb = u; }
    else { wa = sin((1 - u) * th) / sin(th); wb = sin(u * th) / sin(th); }
    r.x = wa * a.x + wb * b.x; r.y = wa * a.y + wb * b.y; r.z = wa * a.z + wb * b.z; r.w = wa * a.w + wb * b.w;
    return r;
}

/* q and -q are the same rotation: compare up to sign */
static double qdist(dq a, const sn_quat *q) {
    double p = fabs(a.x - DQ(q->x)) + fabs(a.y - DQ(q->y)) + fabs(a.z - DQ(q->z)) + fabs(a.w - DQ(q->w));
    double m = fabs(a.x + DQ(q->x)) + fabs(a.y + DQ(q->y)) + fabs(a.z + DQ(q->z)) + fabs(a.w + DQ(q->w));
    return p < m ? p : m;
}

int main(void) {
    const char *b = getenv("BUILD") ? getenv("BUILD") : "build", *override = getenv("SN_TEST_BLOB");
    char path[1024], text[4096];
    FILE *f;
    long n;
    void *bytes;
    const sn_blob *blob;
    sn_blob_info info;
    sn_quat local[256], local2[256];
    sn_xform xf[256], xf2[256];
    sn_vec3 root;
    int32_t h, t;
    uint32_t j, ja, jb, k;
    double worst = 0, worst_move = 0;
    const char *na, *nb;
    size_t len;
    /* reference keys of the test clip (same numbers as the text below) */
    static const double ka[4][5] = {{0, 0, 1, 0, 0}, {0.5, 0, 1, 0, 40}, {1.25, 0.3, 1, 0.2, -35.5}, {2, 0, 1, 0, 10}};
    static const double kb[3][5] = {{0.2, 1, 0, 0, -20}, {0.9, 1, 0.5, 0, 60}, {1.7, 0, 0, 1, 15}};
    static const double km[3][4] = {{0, 0, 0, 0}, {0.3, 0.1, 0.25, -0.05}, {1.0, -0.2, 0, 0.5}};

    (void)t_seed;   /* no randomness here */
    snprintf(path, sizeof path, "%s/examples/%s", b, BLOB_NAME);
    if (override) snprintf(path, sizeof path, "%s", override);
    f = fopen(path, "rb");
    T_CHECK(f != NULL, "cannot open %s (make $(BUILD)/examples/" BLOB_NAME ")", path);
    if (!f) return T_END();
    fseek(f, 0, SEEK_END); n = ftell(f); fseek(f, 0, SEEK_SET);
    bytes = malloc((size_t)n);
    T_CHECK(bytes && fread(bytes, 1, (size_t)n, f) == (size_t)n, "read %s", path);
    fclose(f);
    T_CHECK(sn_blob_validate(bytes, (size_t)n, &blob) == SN_OK, "validate %s", path);
    sn_blob_get_info(blob, &info);
    T_CHECK(info.joints >= 3 && info.joints <= 256, "blob has %u joints (need 3)", info.joints);
    if (info.joints < 3 || info.joints > 256) return T_END();
    ja = 1; jb = info.joints - 1;
    na = sn_joint_name(blob, ja); nb = sn_joint_name(blob, jb);
    printf("  blob %s, joints '%s' and '%s'\n", path, na, nb);

    len = (size_t)snprintf(text, sizeof text,
        "sinew-clip 1\nduration 2\nloop yes\n"
        "rot %s 0 0 1 0 0\nrot %s 0.5 0 1 0 40\nrot %s 1.25 0.3 1 0.2 -35.5\nrot %s 2 0 1 0 10\n"
        "rot %s 0.2 1 0 0 -20\nrot %s 0.9 1 0.5 0 60\nrot %s 1.7 0 0 1 15\n"
        "move 0 0 0 0\nmove 0.3 0.1 0.25 -0.05\nmove 1.0 -0.2 0 0.5\n", na, na, na, na, nb, nb, nb);
    T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0, "parse: %s", err);
    T_CHECK(sn_clip_bind(&clip, blob, err, sizeof err) == 0 && clip.bound, "bind: %s", err);

    /* time: k*h in integer Q16.16, wrapped at the duration */
    h = sn_clip_timestep_q16(blob);
    T_CHECK(h > 0, "timestep %d", h);
    T_CHECK(sn_clip_time(&clip, h, 0) == 0, "t(0)");
    T_CHECK(sn_clip_time(&clip, h, 7) == 7 * h, "t(7)");
    k = (uint32_t)(clip.duration / h) + 3;
    T_CHECK(sn_clip_time(&clip, h, k) == (int32_t)(((int64_t)k * h) % clip.duration), "t wraps");
    T_CHECK(sn_clip_time(&clip, h, 4000000000u) == (int32_t)((int64_t)4000000000 * h % clip.duration), "t at 4e9 steps (no overflow)");
    clip.loop = 0;
    T_CHECK(sn_clip_time(&clip, h, k) == clip.duration, "t clamps without loop");
    clip.loop = 1;

    /* sampling against the double reference over a fine grid of times */
    for (t = 0; t <= 2 * 65536; t += 331) {
        double ts = t / 65536.0, u;
        dq ra, rb;
        int i;
        sn_clip_sample(&clip, blob, t, local, &root);
        /* channel a */
        if (ts <= ka[0][0]) ra = axis_angle(ka[0][1], ka[0][2], ka[0][3], ka[0][4]);
        else if (ts >= ka[3][0]) ra = axis_angle(ka[3][1], ka[3][2], ka[3][3], ka[3][4]);
        else {
            for (i = 0; ts >= ka[i + 1][0]; i++) {}
            u = (ts - ka[i][0]) / (ka[i + 1][0] - ka[i][0]);
            ra = slerp(axis_angle(ka[i][1], ka[i][2], ka[i][3], ka[i][4]),
                       axis_angle(ka[i + 1][1], ka[i + 1][2], ka[i + 1][3], ka[i + 1][4]), u);
        }
        if (ts <= kb[0][0]) rb = axis_angle(kb[0][1], kb[0][2], kb[0][3], kb[0][4]);
        else if (ts >= kb[2][0]) rb = axis_angle(kb[2][1], kb[2][2], kb[2][3], kb[2][4]);
        else {
            for (i = 0; ts >= kb[i + 1][0]; i++) {}
            u = (ts - kb[i][0]) / (kb[i + 1][0] - kb[i][0]);
            rb = slerp(axis_angle(kb[i][1], kb[i][2], kb[i][3], kb[i][4]),
                       axis_angle(kb[i + 1][1], kb[i + 1][2], kb[i + 1][3], kb[i + 1][4]), u);
        }
        if (qdist(ra, &local[ja]) > worst) worst = qdist(ra, &local[ja]);
        if (qdist(rb, &local[jb]) > worst) worst = qdist(rb, &local[jb]);
        {
            double m[3];
            int c;
            if (ts >= km[2][0]) for (c = 0; c < 3; c++) m[c] = km[2][1 + c];
            else {
                for (i = 0; ts >= km[i + 1][0]; i++) {}
                u = (ts - km[i][0]) / (km[i + 1][0] - km[i][0]);
                for (c = 0; c < 3; c++) m[c] = km[i][1 + c] + u * (km[i + 1][1 + c] - km[i][1 + c]);
            }
            worst_move = fmax(worst_move, fabs(D(root.x) - m[0]));
            worst_move = fmax(worst_move, fabs(D(root.y) - m[1]));
            worst_move = fmax(worst_move, fabs(D(root.z) - m[2]));
        }
        for (j = 0; j < info.joints; j++)
            if (j != ja && j != jb && (local[j].x != 0 || local[j].y != 0 || local[j].z != 0 || DQ(local[j].w) != 1.0)) break;
        if (j != info.joints) { T_CHECK(0, "joint %u without a channel is not exactly identity at t=%g", j, ts); break; }
    }
    /* Key times are rounded to 1/65536 s (0.2 and 0.9 are not exact): up to
       7.6e-6 s on a ramp of at most 114 deg/s is 1.5e-5 rad of rotation,
       7.6e-6 in the quaternion, <= 1.5e-5 summed over 4 components. The
       runtime's integer trig adds ~1e-6 per component. Measured: 9.5e-6. */
    T_NEAR(worst, 0, 3e-5, "slerp vs double, sum of |component| errors, all samples");
    T_FIGURE("clip rotation error vs double: %.2e (sum over components)", worst);
    /* translations: keys exact in Q16.16 up to 1/65536 rounding of the key
       values, one rounding in the interpolation: 2 LSB = 3.1e-5 */
    T_NEAR(worst_move, 0, 2.0 / 65536.0 + 1e-9, "root translation vs double lerp");

    /* pose for step k == sn_pose_from_local of the sample at t(k), bit for bit */
    for (k = 0; k < 300; k += 37) {
        sn_clip_pose(&clip, blob, k, local, xf);
        sn_clip_sample(&clip, blob, sn_clip_time(&clip, h, k), local2, &root);
        sn_pose_from_local(blob, local2, &root, xf2);
        T_CHECK(memcmp(xf, xf2, info.joints * sizeof xf[0]) == 0, "sn_clip_pose step %u", k);
    }

    /* keys 270 degrees apart (warned at parse): the slerp takes the short
       way, so half way is -45 degrees, not +135 */
    len = (size_t)snprintf(text, sizeof text, "sinew-clip 1\nduration 1\nrot %s 0 0 1 0 0\nrot %s 1 0 1 0 270\n", na, na);
    T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0 && clip.n_warnings == 1 &&
            clip.warn[0].taken == 90 * 65536 && sn_clip_bind(&clip, blob, err, sizeof err) == 0, "parse 270: %s", err);
    sn_clip_sample(&clip, blob, 32768, local, &root);
    T_NEAR(qdist(axis_angle(0, 1, 0, -45), &local[ja]), 0, 1e-5, "half way between keys 270 apart is -45 degrees (runtime trig ~1e-6)");

    /* a clip for another skeleton: bind names the missing joint */
    len = (size_t)snprintf(text, sizeof text, "sinew-clip 1\nduration 1\nrot %s 0 0 1 0 5\nrot no_such_joint 0 0 1 0 5\n", na);
    T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0, "parse 2: %s", err);
    T_CHECK(sn_clip_bind(&clip, blob, err, sizeof err) == 1 && strstr(err, "'no_such_joint'") && strstr(err, na) && !clip.bound,
            "bind of an unknown joint: %s", err);

    /* impulse events fire once per pass of their time, across the loop's wrap, at the runtime */
    {
        void *mem = malloc(sn_instance_size(blob) + 8);
        sn_instance *inst;
        sn_stats st;
        uint32_t fired = 0, steps = (uint32_t)(3 * 2 * 65536 / sn_clip_timestep_q16(blob)) + 1;   /* three passes */
        len = (size_t)snprintf(text, sizeof text, "sinew-clip 1\nduration 2\nloop yes\nimpulse 0.5 3 0 10 0\nimpulse 1.95 4 1 0 0 0\n"
                                                  "impulse 2 5 0 0 -1 1\n");
        T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0 && sn_clip_bind(&clip, blob, err, sizeof err) == 0, "impulse clip: %s", err);
        {   /* impulse channels are not pose channels: the pose stays the rest pose (an impulse's profile once
             * posed the joint of that number) */
            int rest = 1;
            for (t = 0; t <= 2 * 65536; t += 4099) {
                sn_clip_sample(&clip, blob, t, local, &root);
                for (j = 0; j < info.joints; j++)
                    rest &= local[j].x == 0 && local[j].y == 0 && local[j].z == 0 && local[j].w == local[0].w;
                rest &= root.x == 0 && root.y == 0 && root.z == 0;
            }
            T_CHECK(rest, "a clip of impulses alone (one with profile 1) samples the rest pose at every time");
        }
        T_CHECK(sn_instance_init(mem, sn_instance_size(blob), blob, &inst) == SN_OK, "instance");
        T_CHECK(sn_clip_impulses(&clip, blob, 0, inst) == 0, "no impulse at step 0");
        for (k = 1; k <= steps; k++) {
            fired += sn_clip_impulses(&clip, blob, k, inst);
            sn_step(inst);
        }
        T_CHECK(fired == 9, "three impulses x three passes of a 2 s loop fired %u times (want 9)", fired);
        sn_get_stats(inst, &st);
        T_CHECK(st.force_drops == 0, "no slot overflow (%u)", st.force_drops);
        len = (size_t)snprintf(text, sizeof text, "sinew-clip 1\nduration 1\nimpulse 0.5 3 0 10 0 200\n");
        T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0 && sn_clip_bind(&clip, blob, err, sizeof err) == 1 && strstr(err, "profile 200"),
                "bind refuses a profile the blob lacks: %s", err);
        len = (size_t)snprintf(text, sizeof text, "sinew-clip 1\nduration 1\nimpulse 0.5 %u 0 10 0\n", info.surface_vertices);
        T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0 && sn_clip_bind(&clip, blob, err, sizeof err) == 1 && strstr(err, "surface vertex"),
                "bind refuses a surface vertex the blob lacks: %s", err);
        free(mem);
    }

    /* colliders and pins: placements at the step's start, targets at its end */
    {
        void *mem = malloc(sn_instance_size(blob) + 8);
        sn_instance *inst;
        sn_collider cl[4];
        sn_constraint cs[4];
        static sn_clip_hold hold[SN_CLIP_MAX_CHANNELS];
        sn_vec3 p3;
        uint32_t nc, seen_ball = 0, seen_lerp = 0, seen_none = 0;
#ifdef SN_FLOAT
#define QD(x) ((double)(x))
#else
#define QD(x) ((double)(x) / 65536.0)
#endif
        h = sn_clip_timestep_q16(blob);
        len = (size_t)snprintf(text, sizeof text, "sinew-clip 1\nduration 2\nloop yes\n"
            "collider g 0 plane 0 -3.39 0 0 1 0 mu 0.5\ncollider b 0.5 sphere 1 -2.5 0 1 vel 0 0.5 0\ncollider b 1 off\n"
            "pin p 0 surface 3 hold axes y\npin p 0.5 surface 3 1 2 3\npin p 1.5 surface 3 2 4 -1\npin p 1.75 off\n");
        T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0 && sn_clip_bind(&clip, blob, err, sizeof err) == 0,
                "collider/pin clip: %s", err);
        T_CHECK(sn_instance_init(mem, sn_instance_size(blob), blob, &inst) == SN_OK, "instance");
        memset(hold, 0, sizeof hold);
        nc = sn_clip_colliders(&clip, blob, 1, cl, 4);
        T_CHECK(nc == 1 && cl[0].kind == SN_COLLIDER_PLANE && fabs(QD(cl[0].a.y) + 3.39) < 1e-5 && QD(cl[0].b.y) == 1 &&
                QD(cl[0].friction) == 0.5 && QD(cl[0].radius) == 0, "step 1: the ground only (%u)", nc);
        T_CHECK(sn_clip_colliders(&clip, blob, 1, cl, 0) == 0, "max 0");
        sn_get_surface(inst, &p3, 3, 1);
        nc = sn_clip_constraints(&clip, blob, 1, inst, hold, cs, 4);
        T_CHECK(nc == 1 && cs[0].at == SN_AT_SURFACE && cs[0].vertex == 3 && cs[0].axes == SN_AXIS_Y &&
                cs[0].target.x == p3.x && cs[0].target.y == p3.y && cs[0].target.z == p3.z, "step 1: pin held where vertex 3 is");
        for (k = 1; k <= (uint32_t)(2 * 65536 / h); k++) {
            int32_t t0 = sn_clip_time(&clip, h, k - 1), t1 = sn_clip_time(&clip, h, k);
            nc = sn_clip_colliders(&clip, blob, k, cl, 4);
            if (t0 >= 32768 && t0 < 65536) {
                /* -2.5 + 0.5 (t0 - 0.5 s), rounded once in Q16.16 */
                double y = (-163840 + floor(32768.0 * (t0 - 32768) / 65536.0 + 0.5)) / 65536.0;
                T_CHECK(nc == 2 && cl[1].kind == SN_COLLIDER_SPHERE && fabs(QD(cl[1].a.y) - y) < 1e-6 && QD(cl[1].a.x) == 1 &&
                        QD(cl[1].velocity.y) == 0.5 && QD(cl[1].radius) == 1, "step %u: sphere at y %.6f, want %.6f", k, QD(cl[1].a.y), y);
                seen_ball++;
            } else T_CHECK(nc == 1, "step %u (t %d): %u colliders, want the ground only", k, t0, nc);
            nc = sn_clip_constraints(&clip, blob, k, inst, hold, cs, 4);
            if (t1 >= 32768 && t1 < 98304) {
                double u = (t1 - 32768) / 65536.0;
                T_CHECK(nc == 1 && cs[0].axes == SN_AXIS_ALL && fabs(QD(cs[0].target.x) - (1 + u)) < 2e-5 &&
                        fabs(QD(cs[0].target.y) - (2 + 2 * u)) < 2e-5 && fabs(QD(cs[0].target.z) - (3 - 4 * u)) < 2e-5,
                        "step %u: target (%.5f %.5f %.5f) interpolated", k, QD(cs[0].target.x), QD(cs[0].target.y), QD(cs[0].target.z));
                seen_lerp++;
            } else if (t1 >= 98304 && t1 < 114688) {
                T_CHECK(nc == 1 && QD(cs[0].target.x) == 2 && QD(cs[0].target.y) == 4 && QD(cs[0].target.z) == -1, "step %u: last target held", k);
            } else if (t1 >= 114688) {
                T_CHECK(nc == 0, "step %u: pin off (%u)", k, nc);
                seen_none++;
            }
        }
        T_CHECK(seen_ball > 10 && seen_lerp > 20 && seen_none > 5, "windows seen: ball %u, lerp %u, off %u", seen_ball, seen_lerp, seen_none);
        len = (size_t)snprintf(text, sizeof text, "sinew-clip 1\nduration 1\npin p 0 lattice %u hold\n", info.free_vertices);
        T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0 && sn_clip_bind(&clip, blob, err, sizeof err) == 1 &&
                strstr(err, "names lattice vertex") && strstr(err, "free lattice vertices"), "bind refuses a lattice vertex the blob lacks: %s", err);
        len = (size_t)snprintf(text, sizeof text, "sinew-clip 1\nduration 1\npin p 0 lattice %u hold\n", info.free_vertices - 1);
        T_CHECK(sn_clip_parse(&clip, text, len, err, sizeof err) == 0 && sn_clip_bind(&clip, blob, err, sizeof err) == 0, "last free lattice vertex: %s", err);
        sn_get_lattice(inst, &p3, info.free_vertices - 1, 1);
        memset(hold, 0, sizeof hold);
        nc = sn_clip_constraints(&clip, blob, 1, inst, hold, cs, 4);
        T_CHECK(nc == 1 && cs[0].at == SN_AT_LATTICE && cs[0].target.x == p3.x && cs[0].target.y == p3.y, "lattice pin held");
        T_CHECK(sn_set_constraints(inst, cs, nc) == SN_OK, "the runtime takes it");
        free(mem);
#undef QD
    }
    free(bytes);
    return T_END();
}
