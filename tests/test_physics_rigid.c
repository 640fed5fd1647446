/* test_physics_rigid.c -- rigid invariance of the warped force (seed 003 eq. 7):
 * moving the whole skeleton rigidly (random axes, angles up to 180 degrees,
 * translations up to 20 mesh units) must leave the shape undeformed. Uses the
 * cow and limb re-baked without gravity ($(BUILD)/physics/{cow,limb}_nograv blobs), so
 * the exact answer is the rigidly moved rest shape. Two cases per pose:
 *   placed: the pose is the first one (flesh placed rigidly, no transient);
 *   jumped: the skeleton jumps there from another rigid pose and the flesh
 *           settles (damping of the asset) -- checked once settled. */
#include "sn_test.h"
#include "reference/phys_util.h"

static void rigid_pose(unsigned nJ, const double q[4], const double t[3], sn_xform *x) {
    unsigned j;
    for (j = 0; j < nJ; j++) {
#if defined(SN_FLOAT)
        x[j].rot.x = (float)q[0]; x[j].rot.y = (float)q[1]; x[j].rot.z = (float)q[2]; x[j].rot.w = (float)q[3];
#else
        x[j].rot.x = (sn_real)lround(ldexp(q[0], SN_QUAT_FRAC)); x[j].rot.y = (sn_real)lround(ldexp(q[1], SN_QUAT_FRAC));
        x[j].rot.z = (sn_real)lround(ldexp(q[2], SN_QUAT_FRAC)); x[j].rot.w = (sn_real)lround(ldexp(q[3], SN_QUAT_FRAC));
#endif
        x[j].pos.x = pu_rlen(t[0]); x[j].pos.y = pu_rlen(t[1]); x[j].pos.z = pu_rlen(t[2]);
    }
}

static void random_rigid(unsigned long long *st, double maxdeg, double q[4], double t[3]) {
    int k;
    pu_random_quat(st, maxdeg, q);
    for (k = 0; k < 3; k++) t[k] = 40 * pu_rand(st) - 20;
}

/* max |surface - (R x + t)| over the rest surface x (from the reference reader) */
static double deviation(const pu_rt *r, const snref_model *m, const double *rest_surf, const sn_xform *pose) {
    unsigned i, nS = r->info.surface_vertices;
    double *s = malloc(3 * nS * sizeof *s), *e = malloc(3 * nS * sizeof *e), R[9], d;
    snref_xform rp[1];
    pu_rt_surface(r, s);
    pu_pose_to_ref(pose, 1, rp);
    snref_quat_to_mat(rp[0].q, R);
    for (i = 0; i < nS; i++) {
        const double *x = rest_surf + 3 * i;
        unsigned c;
        for (c = 0; c < 3; c++) e[3 * i + c] = R[3 * c] * x[0] + R[3 * c + 1] * x[1] + R[3 * c + 2] * x[2] + rp[0].t[c];
    }
    d = pu_maxdist(s, e, nS);
    (void)m;
    free(s); free(e);
    return d;
}

static void asset(const char *name, unsigned long long seed) {
    char path[512];
    pu_rt r;
    snref_model m;
    snref_state s;
    double *rest_surf, size, lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 };
    double worst_placed = 0, worst_moved = 0, worst_jumped = 0, worst_transient = 0;
    unsigned sat_jumped = 0;
    unsigned i, c, trial, nJ;
    unsigned long long st = seed;
    sn_xform *pose;
    snprintf(path, sizeof path, "%s/physics/%s_nograv%s.blob", pu_build(), name, PU_BLOB_SUFFIX);
    if (pu_rt_open(&r, path) != 0 || pu_ref_open(&m, &s, path) != 0) { T_CHECK(0, "missing %s", path); return; }
    nJ = r.info.joints;
    pose = malloc(nJ * sizeof *pose);
    rest_surf = malloc(3 * m.nS * sizeof *rest_surf);
    snref_get_surface(&s, rest_surf);         /* rest state: model space */
    for (i = 0; i < m.nS; i++)
        for (c = 0; c < 3; c++) {
            if (rest_surf[3 * i + c] < lo[c]) lo[c] = rest_surf[3 * i + c];
            if (rest_surf[3 * i + c] > hi[c]) hi[c] = rest_surf[3 * i + c];
        }
    size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    for (trial = 0; trial < 4; trial++) {
        double q[4], t[3], d;
        unsigned k;
        random_rigid(&st, 180, q, t);
        if (trial == 0) { q[0] = 0; q[1] = 1; q[2] = 0; q[3] = 0; }   /* exactly 180 degrees about y */
        rigid_pose(nJ, q, t, pose);
        /* placed */
        sn_reset(r.inst);
        sn_set_pose(r.inst, pose, nJ);
        for (k = 0; k < 100; k++) sn_step(r.inst);
        d = deviation(&r, &m, rest_surf, pose);
        if (d > worst_placed) worst_placed = d;
        /* moved: from another random rigid pose, a smooth rigid motion to this one
         * over 60 steps (at most 3 degrees per step), then settle;
         * jumped: the same in one step (a teleport) */
        {
            double q2[4], t2[3];
            sn_xform *p2 = malloc(nJ * sizeof *p2);
            sn_stats sts;
            int jump;
            random_rigid(&st, 180, q2, t2);
            for (jump = 0; jump < 2; jump++) {
                unsigned ramp = jump ? 1 : 60;
                sn_reset(r.inst);
                rigid_pose(nJ, q2, t2, p2);
                sn_set_pose(r.inst, p2, nJ);
                for (k = 0; k < 60; k++) sn_step(r.inst);
                for (k = 1; k <= ramp; k++) {
                    double qs[4], ts[3], u = (double)k / ramp;
                    int cc;
                    snref_quat_slerp(q2, q, u, qs);
                    for (cc = 0; cc < 3; cc++) ts[cc] = (1 - u) * t2[cc] + u * t[cc];
                    rigid_pose(nJ, qs, ts, p2);
                    sn_set_pose(r.inst, p2, nJ);
                    sn_step(r.inst);
                }
                sn_set_pose(r.inst, pose, nJ);
                for (k = 0; k < 800; k++) {
                    sn_step(r.inst);
                    if (jump && k == 5) { d = deviation(&r, &m, rest_surf, pose); if (d > worst_transient) worst_transient = d; }
                }
                d = deviation(&r, &m, rest_surf, pose);
                sn_get_stats(r.inst, &sts);
                if (jump) { if (d > worst_jumped) worst_jumped = d; sat_jumped += sts.saturations; }
                else {
                    if (d > worst_moved) worst_moved = d;
                    T_CHECK(sts.saturations == 0, "%s trial %u, smooth rigid motion: %u saturations", name, trial, sts.saturations);
                }
            }
            free(p2);
        }
    }
    T_FIGURE("%s (%s, size %.3g mesh units, seed %llu, 4 poses up to 180 deg): spurious deformation / size: placed %.2e; "
             "moved smoothly (60 steps) and settled (800 steps) %.2e; teleported in one step and settled %.2e (%u saturations; 5 steps after: %.2e)",
             name, PU_FLAVOUR_NAME, size, seed, worst_placed / size, worst_moved / size, worst_jumped / size, sat_jumped, worst_transient / size);
    T_NEAR(worst_placed / size, 0, 1e-4, "rigid invariance of the warped force, brief: 1e-4 of the character size");
    T_NEAR(worst_moved / size, 0, 1e-4, "settled after a rigid motion: brief, 1e-4 of the character size");
    PU_GOAL(worst_jumped / size <= 1e-4 && sat_jumped == 0, "%s %s: settled after a one-step rigid teleport, spurious deformation %.2e <= 1e-4 of the size, %u saturations",
            name, PU_FLAVOUR_NAME, worst_jumped / size, sat_jumped);
    free(pose); free(rest_surf);
    snref_release(&s); snref_free(&m); pu_rt_close(&r);
}

int main(void) {
    unsigned long long seed = pu_seed();
    printf("rigid invariance (%s runtime)\n", PU_FLAVOUR_NAME);
    asset("limb", seed);
    asset("cow", seed + 1);
    return T_END();
}
