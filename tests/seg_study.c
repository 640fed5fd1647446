/* seg_study.c -- segment meshes' constraint gap through the cow's trot
 * (phys_pose's pu_cow_pose, as test_physics_segment): for each blob given,
 * the gap (sn_stats seg_gap: the sweeps' measuring pass, the largest |d| of
 * every pair and attachment over every mesh, / segment length) at step 72
 * (test_physics_segment's check), its largest over steps [30, K) and since
 * init. Study tool for issue 15 (make seg-study); one line per blob. */
#include "sn_test.h"
#include "snref.h"
#include "phys_util.h"
#include "phys_pose.h"

#ifdef SEG_PROTO
extern double sn_seg_study_omega;
extern unsigned sn_seg_study_sweeps[4];
#endif
int main(int argc, char **argv) {
    int a;
#ifdef SEG_PROTO
    if (getenv("SEG_OMEGA")) sn_seg_study_omega = atof(getenv("SEG_OMEGA"));
    if (getenv("SEG_L0")) sn_seg_study_sweeps[0] = (unsigned)atoi(getenv("SEG_L0"));
    if (getenv("SEG_L1")) sn_seg_study_sweeps[1] = (unsigned)atoi(getenv("SEG_L1"));
#endif
    unsigned K = 240;
    (void)t_passed_; (void)t_failed_;
    for (a = 1; a < argc; a++) {
        pu_rt r;
        sn_xform x[256];
        sn_stats st;
        double h, g72 = 0, gmax = 0, gsum = 0, ts[3] = {0, 0, 0}, tq[3] = {0, 0, 0}, swing = 0;
        unsigned k, sat, m, nm, tn = 0, c;
        if (!strcmp(argv[a], "-steps") && a + 1 < argc) { K = (unsigned)atoi(argv[++a]); continue; }
        if (pu_rt_open(&r, argv[a])) return 1;
        h = SN_FLAVOUR ? (double)r.info.timestep : ldexp((double)r.info.timestep, -16);
        for (k = 0; k < K; k++) {
            double g;
            pu_cow_pose(r.blob, r.info.joints, k, h, x);
            sn_set_pose(r.inst, x, r.info.joints);
            sn_step(r.inst);
            sn_get_stats(r.inst, &st);
            g = pu_len(st.seg_gap);
            if (k + 1 == 72) g72 = g;
            if (k >= 30) { gmax = g > gmax ? g : gmax; gsum += g; }
            /* swing: the first chain's tip minus root, its rms deviation from its mean over [30, K) */
            nm = sn_segment_mesh_count(r.blob);
            for (m = 0; m < nm && k >= 30; m++) {
                sn_segment_info si;
                sn_vec3 e[2];
                if (sn_segment_mesh_info(r.blob, m, &si) != SN_OK || si.kind != SN_SEGMENT_CHAIN) continue;
                if (sn_get_segment_nodes(r.inst, m, &e[0], 0, 1) != SN_OK || sn_get_segment_nodes(r.inst, m, &e[1], si.nodes - 1, 1) != SN_OK) break;
                for (c = 0; c < 3; c++) {
                    double d = pu_len(c == 0 ? e[1].x : c == 1 ? e[1].y : e[1].z) - pu_len(c == 0 ? e[0].x : c == 1 ? e[0].y : e[0].z);
                    ts[c] += d; tq[c] += d * d;
                }
                tn++;
                break;
            }
        }
        for (c = 0; c < 3 && tn; c++) swing += tq[c] / tn - (ts[c] / tn) * (ts[c] / tn);
        swing = swing > 0 ? sqrt(swing) : 0;
        sat = st.saturations;
        printf("%s %-40s gap%% step72 %.4f  max[30,%u) %.4f  mean %.4f  since-init %.4f  sat %u  chain swing rms %.4f\n",
               SN_FLAVOUR ? "float" : "fixed", argv[a], 100 * g72, K, 100 * gmax, 100 * gsum / (K - 30),
               100 * pu_len(st.seg_gap_max), sat, swing);
        pu_rt_close(&r);
    }
    return 0;
}
