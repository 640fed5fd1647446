/* test_physics_cut.c -- the cut level (runtime/LEVELS.md §2 "The cut level")
 * settled at a held pose against the double-precision static equilibrium of
 * the same blob (tools/ref/snref.c reads CELLX/CELLXK: the extras' coupling in
 * its element force), as test_physics_held.c does for the plain lattice.
 *
 * The cow's neck (head turn) and the beast's elbow are ramped to 90 degrees in
 * 1 s and held to 15 s with the asset's damping and gravity; the runtime's
 * lattice (free vertices) must lie within HELD_STATIC_BOUND of the largest
 * elastic displacement of the reference's static solution (snref_static on
 * the float64 blob, fed the same pose sequence), floored at 0.02 cell:
 * test_physics_held.c's bound for the fixed runtime (README's goal), the
 * model for this one. Blobs: $BUILD/level/{cow,beast}_cut{,_float,_double}.blob
 * (tests/level.mk). */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"

#define HELD_STATIC_BOUND 0.01
#define HELD_STATIC_FLOOR_CELLS 0.02

static void check(const char *name, const char *joint, double deg)
{
    char p[512], p64[512];
    pu_rt r;
    snref_model m;
    snref_state s;
    sn_xform *pose;
    snref_xform *rp;
    sn_quat *local;
    double *lat, *ref, *skin, err = 0, scale = 0, cell, resid;
    unsigned k, i, nJ, nF, n = 900, ramp = 60;
    int32_t jn;
    snprintf(p, sizeof p, "%s/level/%s_cut%s.blob", pu_build(), name, PU_BLOB_SUFFIX);
    snprintf(p64, sizeof p64, "%s/level/%s_cut_double.blob", pu_build(), name);
    memset(&m, 0, sizeof m); memset(&s, 0, sizeof s);
    if (pu_rt_open(&r, p) != 0 || pu_ref_open(&m, &s, p64) != 0) { T_CHECK(0, "%s: cannot open %s / %s (tests/level.mk)", name, p, p64); return; }
    nJ = r.info.joints; nF = r.info.free_vertices;
    T_CHECK(m.nV == r.info.vertices && m.nF == nF && m.cutn != NULL, "%s: the reference reads the cut level (%u vertices, %u free)", name, m.nV, m.nF);
    jn = sn_find_joint(r.blob, joint);
    pose = malloc(sizeof *pose * nJ); rp = malloc(sizeof *rp * nJ); local = malloc(sizeof *local * nJ);
    lat = malloc(sizeof *lat * 3 * r.info.vertices); ref = malloc(sizeof *ref * 3 * m.nV); skin = malloc(sizeof *skin * 3 * m.nV);
    snref_reset(&s);
    s.mode = SNREF_WARPED;
    for (k = 0; k <= n; k++) {
        double t = k < ramp ? (double)k / ramp : 1.0;
        unsigned j;
        for (j = 0; j < nJ; j++) local[j] = pu_qident();
        local[jn] = pu_axis_angle(0, 1, 0, deg * t * t * (3 - 2 * t));
        sn_pose_from_local(r.blob, local, NULL, pose);
        if (k <= ramp) { pu_pose_to_ref(pose, nJ, rp); snref_set_pose(&s, rp); }   /* quaternion tracking, as the runtime */
        sn_set_pose(r.inst, pose, nJ);
        sn_step(r.inst);
    }
    resid = snref_static(&s, 0);
    T_CHECK(resid < 1e-6, "%s: static solve converged (relative residual %.2e)", name, resid);
    snref_get_lattice(&s, ref);
    snref_get_skinned(&s, skin);
    pu_rt_lattice(&r, lat);
    cell = m.cell * m.unit;
    for (i = 0; i < nF; i++) {
        double d = 0, e = 0;
        for (k = 0; k < 3; k++) {
            d += (lat[3 * i + k] - ref[3 * i + k]) * (lat[3 * i + k] - ref[3 * i + k]);
            e += (ref[3 * i + k] - skin[3 * i + k]) * (ref[3 * i + k] - skin[3 * i + k]);
        }
        err = fmax(err, sqrt(d)); scale = fmax(scale, sqrt(e));
    }
    T_FIGURE("%s [%s]: cut level, %s %.0f deg held 15 s: lattice vs the reference's static %.4g mesh units (%.3g cells), "
             "largest elastic displacement %.4g: %.3g%%", name, PU_FLAVOUR_NAME, joint, deg, err, err / cell, scale, 100 * err / scale);
    T_CHECK(err <= fmax(HELD_STATIC_BOUND * scale, HELD_STATIC_FLOOR_CELLS * cell),
            "%s: the settled cut level is %.4g from the static reference (bound %.4g)", name, err,
            fmax(HELD_STATIC_BOUND * scale, HELD_STATIC_FLOOR_CELLS * cell));
    free(pose); free(rp); free(local); free(lat); free(ref); free(skin);
    snref_release(&s); snref_free(&m); pu_rt_close(&r);
}

int main(void)
{
    check("cow", "neck", 90);
    check("beast", "elbow_l", 90);
    return T_END();
}
