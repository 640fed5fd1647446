/* test_physics_segment.c -- segment meshes on the baked examples (seed 004
 * ch. 3-4; runtime/NUMERICS.md "Segment meshes"), fixed and float:
 *
 *  - zero saturations: the cow (tail chain and 5x5 two-level blanket, whose
 *    rest sheet starts 0.23 mesh units off its surface attachments) over the
 *    trot; the free 9x9 sheet with a corner and a centre impulse and the
 *    tilted sheet dropped on a floor, each with shares fine, equal, coarse
 *    (the demo runs of ports/desktop/demo.sh);
 *  - the gap left after the examples' sweeps (sn_stats seg_gap), reported.
 */
#include "sn_test.h"
#include "snref.h"
#include "phys_util.h"
#include "phys_pose.h"

static const char *fl(void) { return PU_FLAVOUR_NAME; }

/* the cow trotting K steps (phys_pose's trot): saturations and last gap */
static void cow_trot(unsigned K) {
    char path[512];
    pu_rt a;
    sn_xform x[256];
    sn_stats st;
    double h;
    unsigned k;
    pu_example(path, sizeof path, "cow" PU_BLOB_SUFFIX);
    if (pu_rt_open(&a, path)) { T_CHECK(0, "open %s", path); return; }
    h = SN_FLAVOUR ? (double)a.info.timestep : ldexp((double)a.info.timestep, -16);
    for (k = 0; k < K; k++) {
        pu_cow_pose(a.blob, a.info.joints, k, h, x);
        sn_set_pose(a.inst, x, a.info.joints);
        sn_step(a.inst);
    }
    sn_get_stats(a.inst, &st);
    T_FIGURE("[%s] cow (tail + blanket) trot %u steps: saturations %u, gap %.4f%% (max since init %.4f%%) of a segment",
             fl(), K, st.saturations, 100 * pu_len(st.seg_gap) / (SN_FLAVOUR ? 1 : 1), 100 * pu_len(st.seg_gap_max));
    T_CHECK(st.saturations == 0, "[%s] cow trot with segments: %u saturations", fl(), st.saturations);
    pu_rt_close(&a);
}

/* a sheet variant: impulse (node, y newton-seconds) at step 1 or a floor */
static void sheet_run(const char *variant, int node, double jy, int floor_on, double floor_y, unsigned steps) {
    char path[512], name[64];
    pu_rt a;
    sn_stats st;
    unsigned k;
    snprintf(name, sizeof name, "sheet_%s%s", variant, PU_BLOB_SUFFIX);
    pu_example(path, sizeof path, name);
    if (pu_rt_open(&a, path)) { T_CHECK(0, "open %s", path); return; }
    if (floor_on) {
        sn_vec3 up = {0, 0, 0};
        up.y = pu_rlen(1.0);
        T_CHECK(sn_set_segment_floor(a.inst, up, pu_rlen(floor_y)) == SN_OK, "floor");
    }
    for (k = 1; k <= steps; k++) {
        if (k == 1 && !floor_on) {
            sn_vec3 J = {0, 0, 0};
            J.y = pu_rlen(jy);
            T_CHECK(sn_apply_segment_impulse(a.inst, 0, (uint32_t)node, J) == SN_OK, "impulse");
        }
        sn_step(a.inst);
    }
    sn_get_stats(a.inst, &st);
    T_FIGURE("[%s] sheet %-12s %s %u steps: saturations %u, gap max %.4f%%", fl(), variant,
             floor_on ? "floor drop" : (node == 0 ? "corner impulse" : "centre impulse"), steps, st.saturations,
             100 * pu_len(st.seg_gap_max));
    T_CHECK(st.saturations == 0, "[%s] sheet %s: %u saturations", fl(), variant, st.saturations);
    pu_rt_close(&a);
}

int main(void) {
    static const char *v[3] = {"fine", "equal", "coarse"};
    int i;
    char fv[32];
    (void)T_SEED();
    cow_trot(72);
    for (i = 0; i < 3; i++) {
        sheet_run(v[i], 0, 0.08, 0, 0, 60);
        sheet_run(v[i], 40, 0.08, 0, 0, 60);
        snprintf(fv, sizeof fv, "floor_%s", v[i]);
        sheet_run(fv, 0, 0, 1, -0.5, 36);
    }
    return T_END();
}
