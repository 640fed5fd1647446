/* test_rig_runtime.c -- rig controls and forces (issue 10): the runtime
 * against the double-precision reference (tools/ref/snref.c), on the limb
 * (tools/examples/limb) with two controls and two rigs written by the
 * tests' own writer (tests/rig_common.h: a pose control "bend" = the elbow's
 * angle about z driving a muscle-like radial bulge on the upper arm, and an
 * abstract control "breath" driving a push), so the runtime is checked on
 * controlled rigs whatever the tool's templates do. Built fixed and float.
 *
 *  1. stepped to rest with the rigs on (elbow 90 degrees, breath 0.8), the
 *     runtime matches the reference's static solve (seed 003 eq. 10);
 *  2. rig forces turn with the frames: a rigidly moved skeleton gives the
 *     rigidly moved rig shape (no gravity);
 *  3. pose controls: sn_get_control vs the double formula over random
 *     rotations, for a child joint and for the root;
 *  4. 600 steps of a moving limb with both rigs active (breath driven every
 *     step): runtime vs reference on the same blob and on the float64 blob
 *     (the fixed and float builds each against double: fixed vs float
 *     agreement follows), and the state hash with rigs active;
 *  5. biceps: elbow and whole-limb volume at 90 degrees with and without the
 *     bulge rig (and with the limb's own rig when the description has one).
 */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"
#include "reference/snref_synth.h"
#include "sn_format.h"
#include "rig_common.h"

#if defined(SN_FLOAT)
static const double GOAL = 0.001;   /* brief (test_physics_runtime): float runtime within 0.1% of the max displacement */
/* pose control: float atan2/products ~1e-6 of a radian-scale value -> ~1e-4 degrees */
static const double CTL_TOL = 2e-4;
#else
static const double GOAL = 0.01;    /* brief (test_physics_runtime): fixed runtime within 1% */
/* pose control: sn_twist_deg is within ~2 LSB (Q16.16) plus the CORDIC's (1 LSB Q30 rad = 1e-7 deg);
 * the quaternion product and the pose's Q30 rounding add ~1e-7 deg: 4 LSB of Q16.16 */
static const double CTL_TOL = 4.0 / 65536;
#endif

/* runtime instance from blob bytes (copied into an 8-aligned buffer) */
static int rt_open_mem(pu_rt *r, const unsigned char *b, size_t n) {
    sn_status st;
    memset(r, 0, sizeof *r);
    r->bytes = malloc(n + 8);
    memcpy(r->bytes, b, n);
    r->size = n;
    st = sn_blob_validate(r->bytes, n, &r->blob);
    if (st != SN_OK) { printf("  validate: %s\n", sn_status_str(st)); return -1; }
    sn_blob_get_info(r->blob, &r->info);
    r->mem = malloc(sn_instance_size(r->blob) + 8);
    st = sn_instance_init(r->mem, sn_instance_size(r->blob), r->blob, &r->inst);
    if (st != SN_OK) { printf("  init: %s\n", sn_status_str(st)); return -1; }
    return 0;
}

typedef struct asset {
    unsigned char *rt, *d64, *rt0, *d640;   /* rigs / no rigs (runtime flavour, float64) */
    size_t nrt, nd64, nrt0, nd640;
    snref_model m64;                       /* float64 with rigs */
    unsigned nJ, elbow;
    int own_rig;                           /* the description's own rigs (tool) were kept */
} asset;

static unsigned char *load_file(const char *path, size_t *n) { return pu_read(path, n); }

/* limb (or variant) with the rigs of rig_common.h; bend_joint: "elbow" or the root */
static int asset_open(asset *A, const char *base, int root_control) {
    char p[600], p64[600], err[200];
    unsigned char *b, *b64;
    size_t n, n64;
    snref_model m0;
    rc_spec sp;
    int e;
    memset(A, 0, sizeof *A);
    snprintf(p, sizeof p, "%s%s.blob", base, PU_BLOB_SUFFIX);
    snprintf(p64, sizeof p64, "%s_double.blob", base);
    b = load_file(p, &n);
    b64 = load_file(p64, &n64);
    if (!b || !b64) { T_CHECK(0, "missing %s or %s", p, p64); free(b); free(b64); return -1; }
    if (snref_load(&m0, b64, n64, err, sizeof err)) { T_CHECK(0, "%s: %s", p64, err); return -1; }
    A->own_rig = m0.nR > 0;
    e = -1;
    {
        unsigned j;
        for (j = 0; j < m0.nJ; j++) if (!strcmp(m0.jname[j], "elbow")) e = (int)j;
    }
    if (e < 0) { T_CHECK(0, "%s has no elbow", p64); return -1; }
    A->elbow = (unsigned)e;
    A->nJ = m0.nJ;
    memset(&sp, 0, sizeof sp);
    sp.bend_joint = root_control ? 0 : (unsigned)e; sp.bend_axis[2] = 1;
    /* the upper arm (shoulder 0 -> elbow 4 along x, 2 x 2 across): a bulge centred
     * 1.5..3.5 from the shoulder, reaching the surface */
    sp.c0[0] = 1.5; sp.c1[0] = 3.5; sp.rad = 1.6; sp.amp = 600; sp.dir[1] = 1;
    A->rt = rc_add_rigs(b, n, &m0, &sp, &A->nrt);          /* the same forces (float64 masses) in both */
    A->d64 = rc_add_rigs(b64, n64, &m0, &sp, &A->nd64);
    A->rt0 = snsyn_with_rigs(b, n, NULL, 0, NULL, 0, &A->nrt0);   /* rig sections emptied */
    A->d640 = snsyn_with_rigs(b64, n64, NULL, 0, NULL, 0, &A->nd640);
    snref_free(&m0);
    free(b); free(b64);
    if (!A->rt || !A->d64 || !A->rt0 || !A->d640 || snref_load(&A->m64, A->d64, A->nd64, err, sizeof err)) {
        T_CHECK(0, "rigs into %s: %s", base, err);
        return -1;
    }
    return 0;
}
static void asset_close(asset *A) { free(A->rt); free(A->d64); free(A->rt0); free(A->d640); snref_free(&A->m64); }

static void elbow_pose(const sn_blob *b, unsigned nJ, double deg, const sn_quat *root_rot, const sn_vec3 *off, sn_xform *out) {
    sn_quat local[64];
    unsigned j;
    for (j = 0; j < nJ; j++) local[j] = pu_qident();
    pu_set_local(b, local, "elbow", pu_axis_angle(0, 0, 1, deg));
    if (root_rot) local[0] = *root_rot;
    sn_pose_from_local(b, local, off, out);
}

/* reference static surface (mesh units) on blob bytes at pose, breath, rigs on/off */
static double ref_static(const unsigned char *blob, size_t n, const sn_xform *pose, unsigned nJ, double breath, double rig, double *surf, double *skin) {
    snref_model m;
    snref_state s;
    snref_xform rp[64];
    char err[200];
    double res;
    if (snref_load(&m, blob, n, err, sizeof err) || snref_init(&s, &m)) { T_CHECK(0, "ref: %s", err); return 1; }
    pu_pose_to_ref(pose, nJ, rp);
    snref_set_pose(&s, rp);
    if (m.nK) snref_set_control(&s, (unsigned)snref_find_control(&m, "breath"), breath);
    s.rig_scale = rig;
    res = snref_static(&s, 0);
    snref_get_surface(&s, surf);
    if (skin) {
        double *lat = malloc(3 * m.nV * sizeof *lat);
        snref_get_skinned(&s, lat);
        snref_surface_from_lattice(&m, lat, skin);
        free(lat);
    }
    snref_release(&s); snref_free(&m);
    return res;
}

/* runtime settled at pose (steps), surface and lattice out */
static void rt_settle(pu_rt *r, const sn_xform *pose, double breath, unsigned steps, double *surf, double *lat, double *moving) {
    int32_t c = sn_find_control(r->blob, "breath");
    unsigned k, nS = r->info.surface_vertices;
    double *s2 = malloc(3 * nS * sizeof *s2);
    sn_reset(r->inst);
    if (c >= 0) T_CHECK(sn_set_control(r->inst, (uint32_t)c, pu_rlen(breath)) == SN_OK, "set breath");
    sn_set_pose(r->inst, pose, r->info.joints);
    for (k = 0; k < steps; k++) sn_step(r->inst);
    pu_rt_surface(r, surf);
    if (lat) pu_rt_lattice(r, lat);
    for (k = 0; k < 30; k++) sn_step(r->inst);
    pu_rt_surface(r, s2);
    if (moving) *moving = pu_maxdist(surf, s2, nS);
    free(s2);
}

/* 1. settled with the rigs on = the static solve */
static void test_settled(asset *A) {
    pu_rt r;
    sn_xform pose[64];
    unsigned nS;
    double *s_rt, *s_ref, *s_64, *s_off, *skin, disp, rigd, e_ref, e_64, moving, breath;
    sn_stats st;
    if (rt_open_mem(&r, A->rt, A->nrt)) { T_CHECK(0, "runtime limb with rigs"); return; }
    nS = r.info.surface_vertices;
    T_CHECK(r.info.controls == 2 && r.info.rigs == 2 && r.info.rig_entries == A->m64.nRE,
            "info: %u controls, %u rigs, %u rig entries (reference %u)", r.info.controls, r.info.rigs, r.info.rig_entries, A->m64.nRE);
    s_rt = malloc(3 * nS * sizeof *s_rt); s_ref = malloc(3 * nS * sizeof *s_ref); s_64 = malloc(3 * nS * sizeof *s_64);
    s_off = malloc(3 * nS * sizeof *s_off); skin = malloc(3 * nS * sizeof *skin);
    elbow_pose(r.blob, A->nJ, 90, NULL, NULL, pose);
    breath = pu_len(pu_rlen(0.8));    /* the runtime's value (fixed: Q16.16) */
    rt_settle(&r, pose, breath, 1200, s_rt, NULL, &moving);
    sn_get_stats(r.inst, &st);
    T_CHECK(ref_static(A->rt, A->nrt, pose, A->nJ, breath, 1, s_ref, skin) < 1e-8, "static solve (same blob) converged");
    T_CHECK(ref_static(A->d64, A->nd64, pose, A->nJ, breath, 1, s_64, NULL) < 1e-8, "static solve (float64) converged");
    ref_static(A->d64, A->nd64, pose, A->nJ, breath, 0, s_off, NULL);
    disp = pu_maxdist(s_64, skin, nS);
    rigd = pu_maxdist(s_64, s_off, nS);
    e_ref = pu_maxdist(s_rt, s_ref, nS);
    e_64 = pu_maxdist(s_rt, s_64, nS);
    T_CHECK(st.saturations == 0, "saturations %u", st.saturations);
    T_CHECK(moving < 1e-3 * disp, "settled: moved %.2e of the displacement over 30 steps", moving / disp);
    T_CHECK(rigd > 0.05 * disp, "the rigs matter: they move the surface %.3g mesh units (elastic displacement %.3g)", rigd, disp);
    T_FIGURE("limb elbow 90 deg, breath 0.8, rigs on, %s runtime settled (1200 steps) vs static solve: same blob %.2e, float64 blob %.2e of the max displacement (%.3f mesh units); %.2e / %.2e of the rigs' own displacement (%.3f)",
             PU_FLAVOUR_NAME, e_ref / disp, e_64 / disp, disp, e_ref / rigd, e_64 / rigd, rigd);
    PU_GOAL(e_64 / disp <= GOAL, "%s runtime with rigs settled on the double static solve within %.1f%% of the displacement (got %.3f%%)",
            PU_FLAVOUR_NAME, 100 * GOAL, 100 * e_64 / disp);
    /* hard regression guard: test_physics_limb's 5% of the displacement */
    T_CHECK(e_64 / disp <= 0.05, "settled shape with rigs %.3g of the displacement off the static solve", e_64 / disp);
    free(s_rt); free(s_ref); free(s_64); free(s_off); free(skin);
    pu_rt_close(&r);
}

/* 2. rig shape turns with the skeleton (no gravity) */
static void test_turns(void) {
    asset A;
    pu_rt r;
    sn_xform pa[64], pb[64];
    snref_xform rp[64];
    sn_quat g = pu_axis_angle(0.3, 1, -0.4, 130);
    sn_vec3 off;
    char base[600];
    unsigned nS, i, k;
    double *sa, *sb, *e, R[9], lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 }, size, worst, mv, moving, rigd;
    snprintf(base, sizeof base, "%s/physics/limb_nograv", pu_build());
    if (asset_open(&A, base, 0)) return;
    if (rt_open_mem(&r, A.rt, A.nrt)) { T_CHECK(0, "runtime nograv limb"); asset_close(&A); return; }
    nS = r.info.surface_vertices;
    sa = malloc(3 * nS * sizeof *sa); sb = malloc(3 * nS * sizeof *sb); e = malloc(3 * nS * sizeof *e);
    off.x = pu_rlen(7); off.y = pu_rlen(-3); off.z = pu_rlen(12);
    elbow_pose(r.blob, A.nJ, 70, NULL, NULL, pa);
    elbow_pose(r.blob, A.nJ, 70, &g, &off, pb);
    rt_settle(&r, pa, 0.8, 1200, sa, NULL, &moving);
    rt_settle(&r, pb, 0.8, 1200, sb, NULL, &mv);
    if (mv > moving) moving = mv;
    pu_pose_to_ref(pb, A.nJ, rp);
    snref_quat_to_mat(rp[0].q, R);
    for (i = 0; i < nS; i++) {
        for (k = 0; k < 3; k++) {
            e[3 * i + k] = R[3 * k] * sa[3 * i] + R[3 * k + 1] * sa[3 * i + 1] + R[3 * k + 2] * sa[3 * i + 2] + rp[0].t[k];
            if (sa[3 * i + k] < lo[k]) lo[k] = sa[3 * i + k];
            if (sa[3 * i + k] > hi[k]) hi[k] = sa[3 * i + k];
        }
    }
    size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    worst = pu_maxdist(sb, e, nS);
    {   /* the rigs' displacement at pose A (reference, float64) */
        double *on = malloc(3 * nS * sizeof *on), *of = malloc(3 * nS * sizeof *of);
        ref_static(A.d64, A.nd64, pa, A.nJ, 0.8, 1, on, NULL);
        ref_static(A.d64, A.nd64, pa, A.nJ, 0.8, 0, of, NULL);
        rigd = pu_maxdist(on, of, nS);
        free(on); free(of);
    }
    T_CHECK(moving < 1e-3 * rigd, "settled (moved %.2e of the rig displacement in 30 steps)", moving / rigd);
    T_NEAR(worst / size, 0, 1e-4, "rig shape turns with the skeleton: test_physics_rigid's rigid-invariance tolerance, 1e-4 of the size");
    T_FIGURE("limb (no gravity), elbow 70 deg, breath 0.8, whole skeleton turned 130 deg and moved: %s runtime shape off the rigidly moved one by %.2e of the size (%.2e of the rigs' displacement %.3f mesh units)",
             PU_FLAVOUR_NAME, worst / size, worst / rigd, rigd);
    free(sa); free(sb); free(e);
    pu_rt_close(&r);
    asset_close(&A);
}

/* 3. pose controls over random rotations */
static void test_pose_control(int root) {
    asset A;
    pu_rt r;
    unsigned long long st = 0xC0FFEEULL + (unsigned long long)root;
    unsigned trial, nJ;
    int32_t c;
    double worst = 0, axis[3];
    char base[600];
    sn_xform pose[64];
    snprintf(base, sizeof base, "%s/examples/limb", pu_build());
    if (asset_open(&A, base, root)) return;
    if (rt_open_mem(&r, A.rt, A.nrt)) { T_CHECK(0, "runtime limb"); asset_close(&A); return; }
    nJ = r.info.joints;
    c = sn_find_control(r.blob, "bend");
    T_CHECK(c >= 0 && sn_control_kind_of(r.blob, (uint32_t)c) == SN_CONTROL_ANGLE, "bend is a pose control");
    if (c < 0) { pu_rt_close(&r); asset_close(&A); return; }
    memcpy(axis, A.m64.kaxis + 3 * (unsigned)c, sizeof axis);
    for (trial = 0; trial < 500; trial++) {
        double qp[4], qc[4], cq[4], rel[4], want;
        snref_xform rp[64];
        sn_real got;
        unsigned jj = A.m64.kjoint[c];
        int par = A.m64.jparent[jj];
        pu_random_quat(&st, 180, qp);
        pu_random_quat(&st, trial < 250 ? 180 : 30, qc);
        pu_identity(pose, nJ);
        /* parent rotation qp, child = qp * qc (so the relative rotation is qc up to rounding) */
        {
            double w[4];
            sn_quat a, b;
            snref_quat_mul(qp, qc, w);
#if defined(SN_FLOAT)
            a.x = (float)qp[0]; a.y = (float)qp[1]; a.z = (float)qp[2]; a.w = (float)qp[3];
            b.x = (float)w[0]; b.y = (float)w[1]; b.z = (float)w[2]; b.w = (float)w[3];
#else
            a.x = (sn_real)lround(ldexp(qp[0], 30)); a.y = (sn_real)lround(ldexp(qp[1], 30)); a.z = (sn_real)lround(ldexp(qp[2], 30)); a.w = (sn_real)lround(ldexp(qp[3], 30));
            b.x = (sn_real)lround(ldexp(w[0], 30)); b.y = (sn_real)lround(ldexp(w[1], 30)); b.z = (sn_real)lround(ldexp(w[2], 30)); b.w = (sn_real)lround(ldexp(w[3], 30));
#endif
            if (par >= 0) pose[par].rot = a;
            pose[jj].rot = b;
            if (trial & 1) {   /* either sign of the child's quaternion */
                pose[jj].rot.x = -pose[jj].rot.x; pose[jj].rot.y = -pose[jj].rot.y;
                pose[jj].rot.z = -pose[jj].rot.z; pose[jj].rot.w = -pose[jj].rot.w;
            }
        }
        T_CHECK(sn_set_pose(r.inst, pose, nJ) == SN_OK, "set pose");
        sn_step(r.inst);
        T_CHECK(sn_get_control(r.inst, (uint32_t)c, &got) == SN_OK, "get control");
        pu_pose_to_ref(pose, nJ, rp);
        if (par < 0) memcpy(rel, rp[jj].q, sizeof rel);
        else {
            cq[0] = -rp[par].q[0]; cq[1] = -rp[par].q[1]; cq[2] = -rp[par].q[2]; cq[3] = rp[par].q[3];
            snref_quat_mul(cq, rp[jj].q, rel);
        }
        want = snref_twist_angle(rel, axis);
        /* +-180 is one angle: compare on the circle */
        {
            double d = fabs(pu_len(got) - want);
            if (d > 180) d = 360 - d;
            if (d > worst) worst = d;
        }
    }
    T_NEAR(worst, 0, CTL_TOL, "pose control vs 2 atan2(v.A, w) of conj(q_parent) q_J in double (the runtime's atan2 accuracy)");
    T_FIGURE("pose control (%s joint), %s runtime vs double over 500 random rotations: largest error %.2e deg (%.2f LSB of Q16.16)",
             root ? "root" : "child", PU_FLAVOUR_NAME, worst, worst * 65536);
    pu_rt_close(&r);
    asset_close(&A);
}

/* 4. a moving limb with both rigs active: runtime vs reference */
#define STEPS 600
static void test_moving(asset *A) {
    pu_rt r;
    snref_model m1, m2;
    snref_state s1, s2;
    sn_xform pose[64];
    snref_xform rp[64];
    char err[200];
    unsigned k, nS, nJ;
    int32_t cb;
    double h, *a, *b1, *b2, *sk, ea = 0, et = 0, disp = 0, bmin = 1e9, bmax = -1e9;
    if (rt_open_mem(&r, A->rt, A->nrt)) { T_CHECK(0, "runtime limb"); return; }
    if (snref_load(&m1, A->rt, A->nrt, err, sizeof err) || snref_init(&s1, &m1) ||
        snref_load(&m2, A->d64, A->nd64, err, sizeof err) || snref_init(&s2, &m2)) { T_CHECK(0, "ref: %s", err); return; }
    nS = r.info.surface_vertices; nJ = r.info.joints;
    h = pu_len(r.info.timestep);
    cb = sn_find_control(r.blob, "breath");
    a = malloc(3 * nS * sizeof *a); b1 = malloc(3 * nS * sizeof *b1); b2 = malloc(3 * nS * sizeof *b2);
    sk = malloc(3 * (m2.nV > nS ? m2.nV : nS) * sizeof *sk);
    for (k = 0; k < STEPS; k++) {
        sn_real bv = pu_rlen(0.9 * sin(2 * PU_PI * 0.5 * k * h));
        double b = pu_len(bv);
        pu_limb_pose(r.blob, nJ, k, h, pose);
        sn_set_control(r.inst, (uint32_t)cb, bv);
        sn_set_pose(r.inst, pose, nJ);
        sn_step(r.inst);
        pu_pose_to_ref(pose, nJ, rp);
        snref_set_control(&s1, (unsigned)snref_find_control(&m1, "breath"), b);
        snref_set_control(&s2, (unsigned)snref_find_control(&m2, "breath"), b);
        snref_set_pose(&s1, rp); snref_set_pose(&s2, rp);
        snref_step(&s1); snref_step(&s2);
        pu_rt_surface(&r, a);
        snref_get_surface(&s1, b1);
        snref_get_surface(&s2, b2);
        {
            double *lat = malloc(3 * m2.nV * sizeof *lat), d;
            snref_get_skinned(&s2, lat);
            snref_surface_from_lattice(&m2, lat, sk);
            free(lat);
            d = pu_maxdist(b2, sk, nS);
            if (d > disp) disp = d;
        }
        if (pu_maxdist(a, b1, nS) > ea) ea = pu_maxdist(a, b1, nS);
        if (pu_maxdist(a, b2, nS) > et) et = pu_maxdist(a, b2, nS);
        {
            sn_real g;
            sn_get_control(r.inst, (uint32_t)sn_find_control(r.blob, "bend"), &g);
            if (pu_len(g) < bmin) bmin = pu_len(g);
            if (pu_len(g) > bmax) bmax = pu_len(g);
        }
    }
    {
        sn_stats st;
        sn_get_stats(r.inst, &st);
        T_CHECK(st.saturations == 0, "600 steps with rigs: %u saturations", st.saturations);
    }
    T_CHECK(bmin < 5 && bmax > 80, "the elbow sweeps the bulge's tau: bend %.1f..%.1f deg", bmin, bmax);
    T_FIGURE("limb, 600 steps, elbow 0..90 deg and breath +-0.9 driving both rigs: %s runtime vs reference, same blob %.3g%%, float64 blob %.3g%% of the max displacement (%.3f mesh units)",
             PU_FLAVOUR_NAME, 100 * ea / disp, 100 * et / disp, disp);
    PU_GOAL(ea / disp <= GOAL, "%s runtime arithmetic with rigs active within %.1f%% (got %.3g%%)", PU_FLAVOUR_NAME, 100 * GOAL, 100 * ea / disp);
    PU_GOAL(et / disp <= GOAL, "%s runtime total error with rigs active (incl. blob quantization) within %.1f%% (got %.3g%%)", PU_FLAVOUR_NAME, 100 * GOAL, 100 * et / disp);
    T_CHECK(et / disp <= 5 * GOAL, "regression guard: runtime with rigs %.3g of the displacement off double (5 x the goal)", et / disp);
    T_FIGURE("state hash after 600 limb steps with rigs active (%s): %016llx", PU_FLAVOUR_NAME, (unsigned long long)sn_state_hash(r.inst));
    free(a); free(b1); free(b2); free(sk);
    snref_release(&s1); snref_release(&s2); snref_free(&m1); snref_free(&m2);
    pu_rt_close(&r);
}

/* 5. biceps: volume at a 90-degree elbow with and without the bulge
 * (snref_cells_volume: test_physics_limb's elbow-cell measure) */
typedef struct vols { double surf, cells; } vols;

/* static (reference, float64 blob) and settled runtime volumes at elbow 90 */
static void biceps_case(const char *what, const unsigned char *rt_blob, size_t nrt, const unsigned char *d64, size_t n64,
                        double rig, const double elbow[3], const vols *v0, vols *vs, vols *vr) {
    snref_model m;
    snref_state s;
    snref_xform rp[64];
    sn_xform pose[64];
    pu_rt r;
    char err[200];
    double *lat, *surf;
    if (snref_load(&m, d64, n64, err, sizeof err) || snref_init(&s, &m) || rt_open_mem(&r, rt_blob, nrt)) { T_CHECK(0, "biceps %s: %s", what, err); return; }
    lat = malloc(3 * m.nV * sizeof *lat); surf = malloc(3 * m.nS * sizeof *surf);
    elbow_pose(r.blob, r.info.joints, 90, NULL, NULL, pose);
    pu_pose_to_ref(pose, r.info.joints, rp);
    snref_set_pose(&s, rp);
    if (m.nK && snref_find_control(&m, "breath") >= 0) snref_set_control(&s, (unsigned)snref_find_control(&m, "breath"), 0);
    s.rig_scale = rig;
    snref_static(&s, 0);
    snref_get_lattice(&s, lat); snref_get_surface(&s, surf);
    vs->surf = snref_surface_volume(&m, surf) / v0->surf - 1; vs->cells = snref_cells_volume(&m, lat, elbow, 1.5) / v0->cells - 1;
    rt_settle(&r, pose, 0, 1200, surf, lat, NULL);   /* breath 0: its push off (tau(0) = 0), the bulge alone */
    vr->surf = snref_surface_volume(&m, surf) / v0->surf - 1; vr->cells = snref_cells_volume(&m, lat, elbow, 1.5) / v0->cells - 1;
    T_FIGURE("biceps, limb elbow 90 deg, %s: elbow cells %+.2f%% (static %+.2f%%), whole limb %+.2f%% (static %+.2f%%) [%s runtime settled]",
             what, 100 * vr->cells, 100 * vs->cells, 100 * vr->surf, 100 * vs->surf, PU_FLAVOUR_NAME);
    free(lat); free(surf);
    snref_release(&s); snref_free(&m); pu_rt_close(&r);
}

static void test_biceps(asset *A) {
    snref_model *m = &A->m64;
    snref_state s;
    double *lat = malloc(3 * m->nV * sizeof *lat), *surf = malloc(3 * m->nS * sizeof *surf), elbow[3];
    vols v0, off_s, off_r, on_s, on_r;
    unsigned k;
    snref_init(&s, m);
    snref_get_lattice(&s, lat); snref_get_surface(&s, surf);
    for (k = 0; k < 3; k++) elbow[k] = m->jrest[3 * A->elbow + k] * m->unit;
    v0.surf = snref_surface_volume(m, surf); v0.cells = snref_cells_volume(m, lat, elbow, 1.5);
    snref_release(&s);
    free(lat); free(surf);
    biceps_case("no rig", A->rt0, A->nrt0, A->d640, A->nd640, 0, elbow, &v0, &off_s, &off_r);
    biceps_case("bulge rig of the test (bend 90 -> eta 1)", A->rt, A->nrt, A->d64, A->nd64, 1, elbow, &v0, &on_s, &on_r);
    T_CHECK(on_s.cells > off_s.cells && on_r.cells > off_r.cells, "the bulge reduces the elbow-cell volume loss: %+.2f%% -> %+.2f%% (static)",
            100 * off_s.cells, 100 * on_s.cells);
    T_CHECK(on_s.surf > off_s.surf && on_r.surf > off_r.surf, "the bulge reduces the whole-limb volume loss: %+.2f%% -> %+.2f%% (static)",
            100 * off_s.surf, 100 * on_s.surf);
    if (A->own_rig) {
        /* the description's own rigs (the tool's biceps): blobs as baked */
        char p[600], p64[600];
        size_t n, n64;
        unsigned char *b, *b64;
        vols own_s, own_r;
        snprintf(p, sizeof p, "%s/examples/limb%s.blob", pu_build(), PU_BLOB_SUFFIX);
        snprintf(p64, sizeof p64, "%s/examples/limb_double.blob", pu_build());
        b = pu_read(p, &n); b64 = pu_read(p64, &n64);
        if (b && b64) {
            biceps_case("the limb's own rig (tools/examples/limb)", b, n, b64, n64, 1, elbow, &v0, &own_s, &own_r);
            PU_GOAL(own_s.cells > off_s.cells && own_r.cells > off_r.cells && own_s.surf > off_s.surf,
                    "the limb's own biceps rig reduces the volume loss at 90 deg: elbow cells %+.2f%% -> %+.2f%%, whole limb %+.2f%% -> %+.2f%% (%s runtime)",
                    100 * off_r.cells, 100 * own_r.cells, 100 * off_r.surf, 100 * own_r.surf, PU_FLAVOUR_NAME);
        }
        free(b); free(b64);
    } else T_FIGURE("the limb's description has no rig yet: only the test's bulge is measured");
}

int main(void) {
    asset A;
    char base[600];
    printf("rigs: %s runtime vs the double-precision reference\n", PU_FLAVOUR_NAME);
    (void)pu_seed();
    snprintf(base, sizeof base, "%s/examples/limb", pu_build());
    if (asset_open(&A, base, 0)) return T_END();
    test_settled(&A);
    test_moving(&A);
    test_biceps(&A);
    asset_close(&A);
    test_turns();
    test_pose_control(0);
    test_pose_control(1);
    return T_END();
}
