/* test_physics_longrun.c -- long runs of random poses: every joint gets a
 * random local rotation (random axis, up to 120 degrees) and the root a random
 * offset (up to 1 mesh unit); targets change every 1..60 steps, reached either
 * smoothly (slerp over the segment) or by a sudden jump (one step, 25%).
 * 100,000 steps on the limb, 5,000 on the cow. Checks: no saturation events
 * (fixed), no NaN/inf (float), energy bounded and stationary, and no lasting
 * damage: after the run, holding the rest pose settles on the same shape as a
 * fresh instance. Energy is evaluated with the reference's formulas from the
 * runtime's positions: kinetic 1/2 v'M^v (v = position change per step) plus
 * warped elastic 1/2 u'S^u (snref_energy). */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"

#define MAXJ 32

static int finite3(const double *p, unsigned n) {
    unsigned i;
    for (i = 0; i < 3 * n; i++) if (!(p[i] == p[i]) || fabs(p[i]) > 1e30) return 0;
    return 1;
}

static void run(const char *name, unsigned steps, unsigned hold, unsigned long long seed) {
    char path[512];
    pu_rt r, fresh;
    snref_model m;
    snref_state s;
    unsigned nJ, nV, k, j, seg_left = 0, seg_len = 1, bad = 0, q4 = steps / 4;
    double cur[MAXJ][4], from[MAXJ][4], to[MAXJ][4], off_from[3] = { 0, 0, 0 }, off_to[3] = { 0, 0, 0 }, off[3] = { 0, 0, 0 };
    double *lat, *prev, emax[4] = { 0, 0, 0, 0 }, esum[4] = { 0, 0, 0, 0 }, size;
    unsigned ecount[4] = { 0, 0, 0, 0 }, jumps = 0;
    unsigned long long st = seed;
    sn_xform pose[MAXJ];
    snref_xform rp[MAXJ];
    sn_stats sts;
    pu_example(path, sizeof path, name);
    if (pu_rt_open(&r, path) != 0 || pu_ref_open(&m, &s, path) != 0) { T_CHECK(0, "missing %s", path); return; }
    nJ = r.info.joints; nV = r.info.vertices;
    if (nJ > MAXJ) { T_CHECK(0, "too many joints"); return; }
    lat = malloc(3 * nV * sizeof *lat); prev = malloc(3 * nV * sizeof *prev);
    {
        double lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 };
        unsigned i, c;
        for (i = 0; i < nV; i++)
            for (c = 0; c < 3; c++) {
                double x = (m.rest[3 * i + c] + m.jrest[c]) * m.unit;
                if (x < lo[c]) lo[c] = x;
                if (x > hi[c]) hi[c] = x;
            }
        size = sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) + (hi[2] - lo[2]) * (hi[2] - lo[2]));
    }
    for (j = 0; j < nJ; j++) { cur[j][0] = cur[j][1] = cur[j][2] = 0; cur[j][3] = 1; memcpy(to[j], cur[j], sizeof cur[j]); }
    snref_get_lattice(&s, prev);
    for (k = 0; k < steps; k++) {
        sn_quat local[MAXJ];
        sn_vec3 o;
        if (seg_left == 0) {     /* new target */
            int jump = pu_rand(&st) < 0.25;
            seg_len = 1 + (unsigned)(60 * pu_rand(&st));
            for (j = 0; j < nJ; j++) { memcpy(from[j], to[j], sizeof to[j]); pu_random_quat(&st, 120, to[j]); }
            memcpy(off_from, off_to, sizeof off_to);
            for (j = 0; j < 3; j++) off_to[j] = 2 * pu_rand(&st) - 1;
            if (jump) { seg_len = 1; jumps++; }
            seg_left = seg_len;
        }
        {
            double u = (double)(seg_len - seg_left + 1) / seg_len;
            for (j = 0; j < nJ; j++) snref_quat_slerp(from[j], to[j], u, cur[j]);
            for (j = 0; j < 3; j++) off[j] = (1 - u) * off_from[j] + u * off_to[j];
            seg_left--;
        }
        for (j = 0; j < nJ; j++) local[j] = pu_quat(cur[j]);
        o.x = pu_rlen(off[0]); o.y = pu_rlen(off[1]); o.z = pu_rlen(off[2]);
        sn_pose_from_local(r.blob, local, &o, pose);
        sn_set_pose(r.inst, pose, nJ);
        sn_step(r.inst);
        if (k % 10 == 0 || k == steps - 1) {
            double ek, ee, e;
            unsigned i, qi = k / q4 < 4 ? k / q4 : 3;
            pu_rt_lattice(&r, lat);
            if (!finite3(lat, nV)) { bad++; break; }
            pu_pose_to_ref(pose, nJ, rp);
            snref_set_pose(&s, rp);                  /* frames of this pose */
            for (i = 0; i < 3 * nV; i++) { s.p[i] = lat[i] / m.unit; s.v[i] = (lat[i] - prev[i]) / m.unit; }
            snref_energy(&s, &ek, &ee);
            e = ek + ee;
            if (e > emax[qi]) emax[qi] = e;
            esum[qi] += e; ecount[qi]++;
        }
        if (k % 10 == 9) pu_rt_lattice(&r, prev);    /* previous-step positions for the next sample */
    }
    sn_get_stats(r.inst, &sts);
    T_CHECK(bad == 0, "%s: non-finite positions at step %u", name, k);
    T_FIGURE("%s %s: %u steps (%u sudden jumps, seed %llu): saturations %u; energy max per quarter %.3g %.3g %.3g %.3g, mean %.3g %.3g %.3g %.3g",
             name, PU_FLAVOUR_NAME, steps, jumps, seed, sts.saturations, emax[0], emax[1], emax[2], emax[3],
             esum[0] / ecount[0], esum[1] / ecount[1], esum[2] / ecount[2], esum[3] / ecount[3]);
#if !defined(SN_FLOAT)
    PU_GOAL(sts.saturations == 0, "%s %s: no saturation events in %u steps of random poses (got %u)", name, PU_FLAVOUR_NAME, steps, sts.saturations);
#endif
    {   /* stationary input, stationary energy: a growing trend means instability */
        double first = emax[0] > emax[1] ? emax[0] : emax[1], last = emax[2] > emax[3] ? emax[2] : emax[3];
        T_CHECK(last <= 3 * first && esum[3] / ecount[3] <= 3 * esum[0] / ecount[0],
                "%s: energy grows: max first half %g, second half %g", name, first, last);
    }
    /* no lasting damage: hold the rest pose, compare with a fresh instance */
    if (pu_rt_open(&fresh, path) == 0) {
        double *l2 = malloc(3 * nV * sizeof *l2), d, dscale;
        sn_quat local[MAXJ];
        for (j = 0; j < nJ; j++) local[j] = pu_qident();
        sn_pose_from_local(r.blob, local, NULL, pose);
        sn_set_pose(fresh.inst, pose, nJ);
        for (k = 0; k < hold; k++) { sn_set_pose(r.inst, pose, nJ); sn_step(r.inst); sn_step(fresh.inst); }
        pu_rt_lattice(&r, lat); pu_rt_lattice(&fresh, l2);
        d = pu_maxdist(lat, l2, nV);
        for (k = 0; k < nV; k++) { unsigned c; for (c = 0; c < 3; c++) prev[3 * k + c] = (m.rest[3 * k + c] + m.jrest[c]) * m.unit; }
        dscale = pu_maxdist(l2, prev, nV);   /* sag under gravity at rest */
        T_FIGURE("%s %s: after the run, %u steps at rest pose: max distance to a fresh instance %.2e mesh units (%.2e of the size; rest sag %.3g)",
                 name, PU_FLAVOUR_NAME, hold, d, d / size, dscale);
        PU_GOAL(d / size <= 1e-4, "%s %s: no lasting damage after the run: settled shape = fresh instance's within 1e-4 of the size (got %.2e)",
                name, PU_FLAVOUR_NAME, d / size);
#if defined(SN_FLOAT)
        T_NEAR(d / size, 0, 1e-4, "float: no lasting damage (1e-4 of the size, as the rigid-invariance goal)");
#endif
        free(l2);
        pu_rt_close(&fresh);
    }
    free(lat); free(prev);
    snref_release(&s); snref_free(&m); pu_rt_close(&r);
}

int main(void) {
    unsigned long long seed = pu_seed();
    printf("long run (%s runtime)\n", PU_FLAVOUR_NAME);
    run("limb" PU_BLOB_SUFFIX, 100000, 1000, seed);
    run("cow" PU_BLOB_SUFFIX, 5000, 2500, seed + 7);   /* the cow is lightly damped: longer hold */
    return T_END();
}
