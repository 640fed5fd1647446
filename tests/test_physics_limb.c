/* test_physics_limb.c -- the bent limb (tools/examples/limb): elbow bent 90
 * degrees. The runtime's settled shape against the reference's direct static
 * solve of seed 003 eq. 10 for the format-2.0 energy (per-cell frames; same
 * blob, and the float64 blob), and the volume kept at the elbow by the warped
 * model versus global linear (unwarped) FEM, rigid skinning and the format-1.0
 * per-vertex warped force (reference only): per-cell frames must keep an
 * elastic joint, not turn into skinning. The limb is baked without its biceps
 * rig (tests/physics.mk, limb_norig): this measures the elastic model alone. */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"

/* the limb bent: elbow 90 degrees about z (forearm up), the rest identity */
static void bent_pose(const sn_blob *b, unsigned nJ, sn_xform *out) {
    sn_quat local[16];
    unsigned j;
    for (j = 0; j < nJ; j++) local[j] = pu_qident();
    pu_set_local(b, local, "elbow", pu_axis_angle(0, 0, 1, 90));
    sn_pose_from_local(b, local, NULL, out);
}

/* reference static solve at the pose; surface and lattice out (mesh units) */
static int ref_static(const char *path, const sn_xform *pose, unsigned nJ, int mode, int force, double *surf, double *lat, double *skin, double *skinlat) {
    snref_model m;
    snref_state s;
    snref_xform rp[16];
    unsigned i, c;
    if (pu_ref_open(&m, &s, path) != 0) return -1;
    pu_pose_to_ref(pose, nJ, rp);
    s.mode = mode;
    s.force = force;
    snref_set_pose(&s, rp);
    T_NEAR(snref_static(&s, 0), 0, 1e-8, "static solve converged (relative residual)");
    snref_get_surface(&s, surf);
    if (lat) snref_get_lattice(&s, lat);
    if (skin) {   /* surface of the rigidly framed lattice R_i x_i + c_i (warped frames) */
        double *sk = malloc(3 * m.nV * sizeof *sk);
        s.mode = SNREF_WARPED;
        snref_set_pose(&s, rp);
        for (i = 0; i < m.nV; i++) {
            const double *R = s.R + 9 * i, *x = m.rest + 3 * i;
            for (c = 0; c < 3; c++) sk[3 * i + c] = (R[3 * c] * x[0] + R[3 * c + 1] * x[1] + R[3 * c + 2] * x[2] + s.c[3 * i + c]) * m.unit;
        }
        snref_surface_from_lattice(&m, sk, skin);
        if (skinlat) memcpy(skinlat, sk, 3 * m.nV * sizeof *sk);
        free(sk);
    }
    snref_release(&s); snref_free(&m);
    return 0;
}

int main(void) {
    char path[512], p64[512];
    pu_rt r;
    snref_model m;
    snref_state s0;
    sn_xform pose[16];
    unsigned nJ, nS, nV, k, mode;
    double *surf_ref, *surf_64, *skin, *surf_rt, *lat, *lat_rt, *rest_s, *rest_l, disp, V0, Vc0, Vcskin, elbow[3];
    printf("bent limb (%s runtime)\n", PU_FLAVOUR_NAME);
    /* the limb baked without its biceps rig (tests/physics.mk): the elastic model alone */
    snprintf(path, sizeof path, "%s/physics/limb_norig%s.blob", pu_build(), PU_BLOB_SUFFIX);
    snprintf(p64, sizeof p64, "%s/physics/limb_norig_double.blob", pu_build());
    if (pu_rt_open(&r, path) != 0 || pu_ref_open(&m, &s0, p64) != 0) { T_CHECK(0, "missing %s", path); return T_END(); }
    nJ = r.info.joints; nS = r.info.surface_vertices; nV = r.info.vertices;
    T_CHECK(nJ <= 16 && m.nT > 0, "limb has %u joints, %u triangles", nJ, m.nT);
    bent_pose(r.blob, nJ, pose);
    surf_ref = malloc(3 * nS * sizeof *surf_ref); surf_64 = malloc(3 * nS * sizeof *surf_64);
    skin = malloc(3 * nS * sizeof *skin); surf_rt = malloc(3 * nS * sizeof *surf_rt);
    lat = malloc(3 * nV * sizeof *lat); lat_rt = malloc(3 * nV * sizeof *lat_rt);
    rest_s = malloc(3 * nS * sizeof *rest_s); rest_l = malloc(3 * nV * sizeof *rest_l);
    snref_get_surface(&s0, rest_s);
    snref_get_lattice(&s0, rest_l);
    V0 = snref_surface_volume(&m, rest_s);
    {
        int32_t e = sn_find_joint(r.blob, "elbow");
        for (k = 0; k < 3; k++) elbow[k] = e >= 0 ? m.jrest[3 * e + k] * m.unit : 0;
    }
    Vc0 = snref_cells_volume(&m, rest_l, elbow, 1.5);
    T_CHECK(V0 > 0 && Vc0 > 0, "rest volumes %g %g (outward triangles)", V0, Vc0);
    ref_static(path, pose, nJ, SNREF_WARPED, SNREF_FORCE_CELL, surf_ref, NULL, skin, lat_rt);
    Vcskin = snref_cells_volume(&m, lat_rt, elbow, 1.5);
    ref_static(p64, pose, nJ, SNREF_WARPED, SNREF_FORCE_CELL, surf_64, NULL, NULL, NULL);
    disp = pu_maxdist(surf_64, skin, nS);
    T_FIGURE("limb, elbow 90 deg: max elastic displacement (static surface - rigidly framed surface) %.4f mesh units; blob quantization (static, %s blob vs float64) %.2e of it",
             disp, PU_FLAVOUR_NAME, pu_maxdist(surf_ref, surf_64, nS) / disp);
    for (mode = 0; mode < 2; mode++) {
        double d1, d2, e_ref, e_64, Vrt, Vref, Vc_rt, Vc_ref;
        sn_stats st;
        sn_reset(r.inst);
        sn_set_mode(r.inst, mode ? SN_MODE_UNWARPED : SN_MODE_WARPED);
        sn_set_pose(r.inst, pose, nJ);
        for (k = 0; k < 1200; k++) sn_step(r.inst);
        pu_rt_surface(&r, surf_rt);
        for (k = 0; k < 30; k++) sn_step(r.inst);
        pu_rt_surface(&r, surf_64);      /* reuse as scratch: still moving? */
        d2 = pu_maxdist(surf_rt, surf_64, nS);
        pu_rt_lattice(&r, lat_rt);
        sn_get_stats(r.inst, &st);
        ref_static(path, pose, nJ, mode ? SNREF_UNWARPED : SNREF_WARPED, SNREF_FORCE_CELL, surf_ref, lat, NULL, NULL);
        ref_static(p64, pose, nJ, mode ? SNREF_UNWARPED : SNREF_WARPED, SNREF_FORCE_CELL, surf_64, NULL, NULL, NULL);
        e_ref = pu_maxdist(surf_rt, surf_ref, nS) / disp;
        e_64 = pu_maxdist(surf_rt, surf_64, nS) / disp;
        d1 = d2 / disp;
        Vrt = snref_surface_volume(&m, surf_rt); Vref = snref_surface_volume(&m, surf_ref);
        Vc_rt = snref_cells_volume(&m, lat_rt, elbow, 1.5); Vc_ref = snref_cells_volume(&m, lat, elbow, 1.5);
        T_FIGURE("limb %s, %s runtime settled (1200 steps): vs static solve same blob %.3e, vs float64 blob %.3e of the max displacement; still moving %.1e; saturations %u",
                 mode ? "UNWARPED" : "warped", PU_FLAVOUR_NAME, e_ref, e_64, d1, st.saturations);
        T_FIGURE("limb %s volume change: whole surface runtime %+.2f%% (static %+.2f%%), elbow cells (centre within 1.5 of the elbow) runtime %+.2f%% (static %+.2f%%)",
                 mode ? "UNWARPED" : "warped", 100 * (Vrt / V0 - 1), 100 * (Vref / V0 - 1), 100 * (Vc_rt / Vc0 - 1), 100 * (Vc_ref / Vc0 - 1));
        if (mode == 0) {
            T_CHECK(st.saturations == 0, "saturations %u", st.saturations);
            PU_GOAL(e_ref <= 0.005, "%s runtime settled bent limb = reference static solve (seed 003 eq. 10) within 0.5%% of the displacement (got %.3f%%)",
                    PU_FLAVOUR_NAME, 100 * e_ref);
            T_CHECK(e_ref <= 0.05, "settled shape more than 5%% off the static solve: %g", e_ref);
            T_CHECK(d1 < 1e-3, "settled: motion over 30 steps %.2e of the displacement", d1);
        }
    }
    {
        double Vskin = snref_surface_volume(&m, skin), *s1 = malloc(3 * nS * sizeof *s1), *l1 = malloc(3 * nV * sizeof *l1);
        double *sk = malloc(3 * nV * sizeof *sk), *s2 = malloc(3 * nS * sizeof *s2), *l2 = malloc(3 * nV * sizeof *l2);
        double Vc1, Vc2, e1, e2, cell = m.cell * m.unit;
        T_FIGURE("limb volume change of the rigidly framed (skinned) lattice: surface %+.2f%%, elbow cells %+.2f%%", 100 * (Vskin / V0 - 1), 100 * (Vcskin / Vc0 - 1));
        /* static shapes of both force models on the float64 blob, and their distance from skinning near the elbow */
        ref_static(p64, pose, nJ, SNREF_WARPED, SNREF_FORCE_CELL, s2, l2, s1, sk);   /* s1: scratch for the skinned surface */
        ref_static(p64, pose, nJ, SNREF_WARPED, SNREF_FORCE_VERTEX, s1, l1, NULL, NULL);
        Vc1 = snref_cells_volume(&m, l1, elbow, 1.5); Vc2 = snref_cells_volume(&m, l2, elbow, 1.5);
        e1 = e2 = 0;
        for (k = 0; k < nV; k++) {
            double d1 = 0, d2 = 0, dr = 0;
            unsigned c;
            for (c = 0; c < 3; c++) {
                double x = (m.rest[3 * k + c] + m.jrest[c]) * m.unit;
                d1 += (l1[3 * k + c] - sk[3 * k + c]) * (l1[3 * k + c] - sk[3 * k + c]);
                d2 += (l2[3 * k + c] - sk[3 * k + c]) * (l2[3 * k + c] - sk[3 * k + c]);
                dr += (x - elbow[c]) * (x - elbow[c]);
            }
            if (dr > 2.25 * cell * cell) continue;   /* lattice vertices within 1.5 cells of the elbow */
            if (sqrt(d1) > e1) e1 = sqrt(d1);
            if (sqrt(d2) > e2) e2 = sqrt(d2);
        }
        T_FIGURE("limb elbow 90 deg, elbow cells (centre within 1.5 of the elbow) volume change: rest 0 | per-cell frames (2.0) %+.2f%% | per-vertex warped force (1.0, eq. 7) %+.2f%% | unwarped (global linear) see above | skinned %+.2f%%",
                 100 * (Vc2 / Vc0 - 1), 100 * (Vc1 / Vc0 - 1), 100 * (Vcskin / Vc0 - 1));
        T_FIGURE("limb elbow 90 deg, largest distance of a lattice vertex within 1.5 cells of the elbow from its skinned position: per-cell %.3f cells, per-vertex (1.0) %.3f cells",
                 e2 / cell, e1 / cell);
        T_CHECK(e2 > 0.05 * cell, "per-cell model is not skinning: the elbow flesh sits %.3g cells from its skinned position", e2 / cell);
        free(s1); free(l1); free(sk); free(s2); free(l2);
    }
    free(surf_ref); free(surf_64); free(skin); free(surf_rt); free(lat); free(lat_rt); free(rest_s); free(rest_l);
    snref_release(&s0); snref_free(&m); pu_rt_close(&r);
    return T_END();
}
