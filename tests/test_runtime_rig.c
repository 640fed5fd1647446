/* test_runtime_rig.c -- controls and rig forces in the runtime (seed 003
 * §4, eq. 11-12) on the hand-built test blob (tests/fuzz/sn_tblob.h: an
 * abstract control "puff", a pose control "bend" = the tip's angle about z,
 * three rigs). Built fixed and float.
 *
 *  - API contract: set/get, refusals (pose control, out of range, NaN), reset;
 *    sn_step / sn_get_stats / sn_reset / sn_state_hash / controls on memory
 *    that is not an instance.
 *  - Pose control vs a double swing-twist reference over random rotations.
 *  - tau through the physics: from rest, one step's displacement is
 *    homogeneous of degree 1 in the right-hand side (CG from a zero warm
 *    start scales with b), so with one active rig the displacement at gamma,
 *    divided by the displacement at the last sample, is tau(gamma).
 *  - Rig forces turn with the skeleton: a rigid rotation of the whole pose
 *    rotates the first step's rig displacement with it.
 */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "sn_test.h"
#include "sinew.h"
#include "fuzz/sn_tblob.h"

#define CAP 8192
typedef union { uint64_t align; unsigned char b[CAP]; } tbuf;
static tbuf g_blob;
static union { uint64_t a; unsigned char m[8192]; } g_mem;

#if defined(SN_FLOAT)
#define FLAV "float"
#define R_(f) ((float)(f))
#define UNR(x) ((double)(x))
#else
#define FLAV "fixed"
#define R_(f) ((int32_t)floor((f) * 65536.0 + 0.5))
#define UNR(x) ((double)(x) / 65536.0)
#endif

static double urand(void) { return (double)rand() / RAND_MAX; }

static sn_quat quat_of(const double q[4]) {
    sn_quat r;
#if defined(SN_FLOAT)
    r.x = (float)q[0]; r.y = (float)q[1]; r.z = (float)q[2]; r.w = (float)q[3];
#else
    r.x = (int32_t)floor(q[0] * 1073741824.0 + 0.5); r.y = (int32_t)floor(q[1] * 1073741824.0 + 0.5);
    r.z = (int32_t)floor(q[2] * 1073741824.0 + 0.5); r.w = (int32_t)floor(q[3] * 1073741824.0 + 0.5);
#endif
    return r;
}

/* double reference: twist of q (x,y,z,w) about unit axis a, degrees in (-180, 180] */
static double twist_deg(const double q[4], const double a[3]) {
    double s = q[0] * a[0] + q[1] * a[1] + q[2] * a[2], w = q[3];
    if (w < 0 || (w == 0 && s < 0)) { w = -w; s = -s; }
    return 2.0 * atan2(s, w) * 180.0 / 3.14159265358979323846;
}
static void qmul(const double a[4], const double b[4], double o[4]) {
    o[0] = a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1];
    o[1] = a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0];
    o[2] = a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3];
    o[3] = a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2];
}
static void rand_quat(double q[4]) {
    double n = 0;
    int k;
    do {
        n = 0;
        for (k = 0; k < 4; k++) { q[k] = 2 * urand() - 1; n += q[k] * q[k]; }
    } while (n < 0.01 || n > 1);
    for (k = 0; k < 4; k++) q[k] /= sqrt(n);
}

static sn_instance *fresh(const sn_blob *blob) {
    sn_instance *inst = NULL;
    T_CHECK(sn_instance_init(g_mem.m, sizeof g_mem.m, blob, &inst) == SN_OK, "init");
    return inst;
}

static void test_api(const sn_blob *blob) {
    sn_instance *inst = fresh(blob);
    sn_real v = 0;
    T_CHECK(sn_get_control(inst, 0, &v) == SN_OK && v == R_(0.25), "[%s] puff after init = baked 0.25", FLAV);
    T_CHECK(sn_get_control(inst, 1, &v) == SN_OK && v == 0, "[%s] bend before the first step = 0", FLAV);
    T_CHECK(sn_set_control(inst, 0, R_(-0.75)) == SN_OK, "set puff");
    T_CHECK(sn_get_control(inst, 0, &v) == SN_OK && v == R_(-0.75), "puff reads back");
    T_CHECK(sn_set_control(inst, 1, R_(10)) == SN_ERR_ARG, "a pose control cannot be set");
    T_CHECK(sn_set_control(inst, 2, R_(1)) == SN_ERR_ARG, "control out of range");
    T_CHECK(sn_get_control(inst, 2, &v) == SN_ERR_ARG, "get out of range");
    T_CHECK(sn_set_control(NULL, 0, R_(1)) == SN_ERR_NULL && sn_get_control(inst, 0, NULL) == SN_ERR_NULL, "NULLs");
#if defined(SN_FLOAT)
    T_CHECK(sn_set_control(inst, 0, NAN) == SN_ERR_ARG && sn_set_control(inst, 0, INFINITY) == SN_ERR_ARG,
            "float: NaN and inf refused");
    T_CHECK(sn_set_control(inst, 0, 1e30f) == SN_OK, "float: a huge finite value is clamped by tau, accepted");
#endif
    T_CHECK(sn_get_control(inst, 0, &v) == SN_OK && (v == R_(-0.75) || v == R_(1e30)), "refused sets change nothing");
    sn_reset(inst);
    T_CHECK(sn_get_control(inst, 0, &v) == SN_OK && v == R_(0.25), "reset restores the baked value");
    {   /* memory that is not an instance */
        static union { uint64_t a; unsigned char m[256]; } junk;
        sn_stats st;
        T_CHECK(sn_set_control((sn_instance *)(void *)junk.m, 0, R_(1)) == SN_ERR_INSTANCE &&
                    sn_get_control((sn_instance *)(void *)junk.m, 0, &v) == SN_ERR_INSTANCE, "not an instance");
        T_CHECK(sn_step((sn_instance *)(void *)junk.m) == SN_ERR_INSTANCE && sn_step(NULL) == SN_ERR_NULL,
                "sn_step refuses memory that is not an instance");
        T_CHECK(sn_get_stats((sn_instance *)(void *)junk.m, &st) == SN_ERR_INSTANCE && st.steps == 0,
                "sn_get_stats refuses it too (zeroed)");
        T_CHECK(sn_reset((sn_instance *)(void *)junk.m) == SN_ERR_INSTANCE && sn_reset(NULL) == SN_ERR_NULL &&
                    sn_state_hash((sn_instance *)(void *)junk.m) == 0 && sn_state_hash(NULL) == 0,
                "sn_reset refuses it, sn_state_hash gives 0");
    }
}

/* The pose control follows the tip's rotation relative to the root. */
static void test_pose_control(const sn_blob *blob) {
    const double az[3] = {0, 0, 1};
    double worst = 0, worst_deg = 0;
    int n;
    for (n = 0; n < 400; n++) {
        double qr[4], qt[4], rel[4], cr[4], want;
        sn_instance *inst = fresh(blob);
        sn_xform x[TB_NJ];
        sn_real got;
        int k;
        rand_quat(qr);
        if (n < 40) { /* pure rotations about z at chosen angles, incl. the +-180 edge */
            double a = (n < 38 ? -180.0 + 10.0 * n : (n == 38 ? 179.99 : -179.99)) * 3.14159265358979323846 / 360.0;
            qt[0] = 0; qt[1] = 0; qt[2] = sin(a); qt[3] = cos(a);
            qmul(qr, qt, rel);
            memcpy(qt, rel, sizeof qt);
        } else {
            rand_quat(qt);
        }
        x[0].rot = quat_of(qr);
        x[1].rot = quat_of(qt);
        for (k = 0; k < TB_NJ; k++) x[k].pos.x = x[k].pos.y = x[k].pos.z = 0;
        cr[0] = -qr[0]; cr[1] = -qr[1]; cr[2] = -qr[2]; cr[3] = qr[3];
        qmul(cr, qt, rel);
        want = twist_deg(rel, az);
        T_CHECK(sn_set_pose(inst, x, TB_NJ) == SN_OK, "pose");
        sn_step(inst);
        sn_get_control(inst, 1, &got);
        {
            double d = fabs(UNR(got) - want);
            if (d > 180) d = 360 - d; /* +-180 is one angle */
            if (d > worst) { worst = d; worst_deg = want; }
        }
    }
    /* fixed: quaternions are Q30 (2^-30 relative), the CORDIC atan2 ~1 LSB Q30,
     * the conversion to Q16.16 degrees 1 LSB (1.5e-5 deg); near w ~ 0 the
     * angle's sensitivity to q is 2/|q| -> a few 1e-7 deg. 1e-4 deg = ~7 LSB.
     * float: q quantized to 6e-8 relative, the polynomial atan 3e-9: 1e-3 deg. */
    T_FIGURE("[%s] pose control vs double over 400 rotations: worst %.3g deg (at %.2f deg)", FLAV, worst, worst_deg);
    T_CHECK(worst <= (SN_FLAVOUR ? 1e-3 : 1e-4), "[%s] pose control error %.3g deg", FLAV, worst);
}

/* first-step displacement of free vertex v (internal -> double mesh units) */
static void step_disp(const sn_blob *blob, const sn_quat *root, double puff, int v, double out[3]) {
    sn_instance *inst = fresh(blob);
    sn_xform x[TB_NJ];
    sn_vec3 p0, p1;
    int k;
    for (k = 0; k < TB_NJ; k++) {
        x[k].rot = *root;
        x[k].pos.x = x[k].pos.y = x[k].pos.z = 0;
    }
    sn_set_pose(inst, x, TB_NJ);
    sn_set_control(inst, 0, R_(puff));
    sn_step(inst); /* first step: places the skeleton, the state starts at the posed rest */
    sn_get_lattice(inst, &p0, (uint32_t)v, 1);
    sn_step(inst);
    sn_get_lattice(inst, &p1, (uint32_t)v, 1);
    out[0] = UNR(p1.x) - UNR(p0.x);
    out[1] = UNR(p1.y) - UNR(p0.y);
    out[2] = UNR(p1.z) - UNR(p0.z);
}

static void test_tau(void) {
    /* only rig 0 acts: rig 2's constant sample set to 0 */
    static tbuf b;
    const sn_blob *blob;
    const sn_quat id = quat_of((const double[4]){0, 0, 0, 1});
    static const double g[] = {-3.0, -1.0, -0.6, 0.0, 0.3, 0.5, 1.0, 7.5};
    double ref[3], worst = 0;
    unsigned i;
    memcpy(b.b, g_blob.b, CAP);
    tb_real(b.b + tb_sec(b.b, SN_SEC_RIG_SAMPLES) + 8 * 5 + 4, 0.0, SN_Q_ROT);
    /* and gravity off: the rest-modelled flag cancels it only where R = I */
    tb_real(b.b + SN_H_REALS + SN_R_GRAV_Y * 4, 0.0, SN_Q_LEN);
    tb_fix_crc(b.b);
    if (sn_blob_validate(b.b, CAP, &blob) != SN_OK) { T_CHECK(0, "tau blob"); return; }
    step_disp(blob, &id, 1.0, 1, ref);
    T_CHECK(ref[1] > 0, "[%s] puff = 1 pushes vertex 1 up (+y): %g", FLAV, ref[1]);
    for (i = 0; i < sizeof g / sizeof g[0]; i++) {
        double d[3], want = g[i] < -1 ? -1 : (g[i] > 1 ? 1 : g[i]), got;
        step_disp(blob, &id, g[i], 1, d);
        got = d[1] / ref[1];
        if (fabs(got - want) > worst) worst = fabs(got - want);
        T_CHECK(fabs(got - want) <= 2e-3, "[%s] tau(%g) = %.5f, want %g", FLAV, g[i], got, want);
    }
    /* the displacement (~0.05 mesh units) is read in Q16.16 (fixed): +-1 LSB
     * on each of two positions is ~1e-3 of it at tau = 0.3; the fixed CG is
     * homogeneous in b to far better than that. Bound 2e-3. */
    T_FIGURE("[%s] tau through one step: worst |ratio - tau| = %.2g over %u gammas", FLAV, worst,
             (unsigned)(sizeof g / sizeof g[0]));
}

/* A rigidly rotated skeleton rotates the rig's effect with it. */
static void test_turns(void) {
    static tbuf b;
    const sn_blob *blob;
    double q[4], d0[3], d1[3], rd[3], err = 0, mag = 0;
    int k, v;
    memcpy(b.b, g_blob.b, CAP);
    tb_real(b.b + SN_H_REALS + SN_R_GRAV_Y * 4, 0.0, SN_Q_LEN); /* no gravity: the rig alone */
    tb_fix_crc(b.b);
    if (sn_blob_validate(b.b, CAP, &blob) != SN_OK) { T_CHECK(0, "turn blob"); return; }
    rand_quat(q);
    for (v = 0; v < TB_NF; v++) {
        const sn_quat id = quat_of((const double[4]){0, 0, 0, 1}), qq = quat_of(q);
        double R[9];
        step_disp(blob, &id, 1.0, v, d0);
        step_disp(blob, &qq, 1.0, v, d1);
        R[0] = 1 - 2 * (q[1] * q[1] + q[2] * q[2]); R[1] = 2 * (q[0] * q[1] - q[2] * q[3]); R[2] = 2 * (q[0] * q[2] + q[1] * q[3]);
        R[3] = 2 * (q[0] * q[1] + q[2] * q[3]); R[4] = 1 - 2 * (q[0] * q[0] + q[2] * q[2]); R[5] = 2 * (q[1] * q[2] - q[0] * q[3]);
        R[6] = 2 * (q[0] * q[2] - q[1] * q[3]); R[7] = 2 * (q[1] * q[2] + q[0] * q[3]); R[8] = 1 - 2 * (q[0] * q[0] + q[1] * q[1]);
        for (k = 0; k < 3; k++) rd[k] = R[3 * k] * d0[0] + R[3 * k + 1] * d0[1] + R[3 * k + 2] * d0[2];
        for (k = 0; k < 3; k++) {
            err = fmax(err, fabs(rd[k] - d1[k]));
            mag = fmax(mag, fabs(d0[k]));
        }
    }
    /* same reading resolution as test_tau: Q16.16 outputs, ~1e-3 of the displacement */
    T_FIGURE("[%s] rig displacement under a rigid turn: worst %.2g of the largest %.2g", FLAV, err, mag);
    T_CHECK(mag > 0 && err <= 2e-3 * mag, "[%s] rig forces turn with the skeleton: %.3g > 2e-3 x %.3g", FLAV, err, mag);
}

int main(void) {
    const sn_blob *blob;
    srand((unsigned)T_SEED());
    tb_build(g_blob.b, CAP, 0);
    if (sn_blob_validate(g_blob.b, CAP, &blob) != SN_OK) {
        T_CHECK(0, "test blob rejected");
        return T_END();
    }
    printf("  flavour: %s\n", FLAV);
    test_api(blob);
    test_pose_control(blob);
    test_tau();
    test_turns();
    return T_END();
}
