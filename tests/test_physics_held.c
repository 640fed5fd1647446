/* test_physics_held.c -- held-pose acceptance (issue 9 item 1). On the limb,
 * the cow and the beast, one adjacent-bone joint's local rotation is ramped
 * from 0 to an angle over 1 s (smoothstep) about the child bone's own axis
 * (twist) or a perpendicular one (bend), then held. Each case runs with the
 * asset's Rayleigh damping and with Rayleigh 0 0. Checks per case:
 *  (a) energy bounded: max E over (2 s, end] <= max E over [1 s, 2 s] *
 *      (1 + HELD_TOL_REL) + HELD_TOL_ABS (sn_stats.energy);
 *  (b) no saturation;
 *  (c) asset's damping: the final surface is within HELD_STATIC_BOUND of the
 *      maximum elastic displacement of the double-precision static
 *      equilibrium (snref_static on the _double blob) at the held pose.
 * Default: angles 0 90 165 180, one joint per character, holds of 6 s
 * (damping 0) and 14 s (asset's, so the lightly damped cow has settled for
 * (c): it took 12 s to come within 1% on a lattice with thin bones).
 * Argument "soak": angles 0..180 step 15, every listed joint, 60 s holds.
 * Argument "figure DIR": 180 deg twist held 60 s with damping 0 on the limb
 * elbow and the cow and beast necks; per-step CSVs DIR/<asset>_<joint>_twist180.csv. */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/phys_pose.h"

#define MAXJ 64
#define RAMP_S 1.0
/* (a): after the ramp the pose is fixed, so the system is linear and
 * conservative: backward Euler only removes energy. sn_stats.energy leaves
 * out gravity's potential, which trades with it by load.(p - p*), so a later
 * beat of modes could peak a little above the first second's, and fixed
 * point jitters (the settled beast by +-5 mJ of 5.6 J); 5% allows for that
 * (soak, 936 cases per flavour: worst x1.0005 fixed, x1.0000 float), while
 * flutter grows by orders of magnitude. HELD_TOL_ABS: 1e-3 J, ~65 LSB of
 * the fixed runtime's Q16.16 joules, for poses that barely move. */
#define HELD_TOL_REL 0.05
#define HELD_TOL_ABS 1e-3
/* (c) the README's runtime-vs-reference goal for the fixed runtime (1% of
 * the displacement), floored at 0.02 cell (with `rest_shape modelled` the
 * 0 deg pose has no displacement). */
#define HELD_STATIC_BOUND 0.01
#define HELD_STATIC_FLOOR_CELLS 0.02

typedef struct {
    const char *asset;
    const char *joints[4];   /* [0] is the default run's */
} charspec;
static const charspec CHARS[] = {
    { "limb", { "elbow", NULL, NULL, NULL } },
    { "cow", { "neck", "head", "shoulder_l", "hip_l" } },
    { "beast", { "neck", "elbow_l", "knee_l", "spine" } },
};

typedef struct {
    double eA, eB;        /* max energy over [1,2] s and (2 s, end], J */
    unsigned sats, bound_steps, limit_steps;
    double disp_max;      /* cells */
    double err, scale;    /* static error and max elastic displacement, mesh units */
    double spin;          /* least-squares turn of runtime vs static about the twist axis through the joint, deg */
    int have_err;
} result;

typedef struct {
    pu_rt r;
    snref_model m;       /* double blob (asset damping) for the static solve */
    snref_state s;
    int have_ref;
    double cell;          /* mesh units */
} asset_t;

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static void joint_pos(const sn_blob *b, uint32_t j, double o[3]) {
    sn_vec3 v;
    sn_joint_rest(b, j, &v);
    o[0] = pu_len(v.x); o[1] = pu_len(v.y); o[2] = pu_len(v.z);
}

/* Twist axis: joint -> its child continuing the chain (most aligned with the
 * parent bone). Bend axis: the world axis (z, x, y in that order of
 * preference) most perpendicular to it, orthogonalized. 0 on success. */
static int joint_axes(const sn_blob *b, unsigned nJ, int32_t jn, double tw[3], double bd[3]) {
    double pj[3], pp[3], pc[3], d0[3], best = -2, n;
    static const double W[3][3] = { { 0, 0, 1 }, { 1, 0, 0 }, { 0, 1, 0 } };
    int32_t p = sn_joint_parent(b, (uint32_t)jn), child = -1;
    unsigned j, k, wb = 0;
    joint_pos(b, (uint32_t)jn, pj);
    joint_pos(b, p >= 0 ? (uint32_t)p : (uint32_t)jn, pp);
    for (k = 0; k < 3; k++) d0[k] = pj[k] - pp[k];
    n = sqrt(dot3(d0, d0));
    for (j = 0; j < nJ; j++) {
        double d[3], c;
        if (sn_joint_parent(b, j) != jn) continue;
        joint_pos(b, j, pc);
        for (k = 0; k < 3; k++) d[k] = pc[k] - pj[k];
        c = n > 0 ? dot3(d, d0) / (n * sqrt(dot3(d, d))) : 0;
        if (c > best) { best = c; child = (int32_t)j; memcpy(tw, d, sizeof d); }
    }
    if (child < 0) return -1;
    n = sqrt(dot3(tw, tw));
    for (k = 0; k < 3; k++) tw[k] /= n;
    for (j = 1; j < 3; j++) if (fabs(dot3(W[j], tw)) < fabs(dot3(W[wb], tw)) - 1e-9) wb = j;
    n = dot3(W[wb], tw);
    for (k = 0; k < 3; k++) bd[k] = W[wb][k] - n * tw[k];
    n = sqrt(dot3(bd, bd));
    for (k = 0; k < 3; k++) bd[k] /= n;
    return 0;
}

static double ramp(unsigned k, double h) {
    double s = k * h / RAMP_S;
    return s >= 1 ? 1 : s * s * (3 - 2 * s);
}

static void held_pose(const sn_blob *b, unsigned nJ, int32_t jn, const double ax[3], double deg, sn_xform *out) {
    sn_quat local[MAXJ];
    unsigned j;
    for (j = 0; j < nJ; j++) local[j] = pu_qident();
    local[jn] = pu_axis_angle(ax[0], ax[1], ax[2], deg);
    sn_pose_from_local(b, local, NULL, out);
}

/* One case on the instance: ramp, hold. csv (may be NULL) gets one row per
 * step, with the energy also by the reference's formulas (snref_energy:
 * consistent-mass kinetic from the position change, element energy; the
 * asset's lattice is the undamped blob's, only Rayleigh differs). */
static result run_case(asset_t *A, pu_rt *r, int32_t jn, const double ax[3], const double tw_axis[3], double deg, double hold_s, int static_ref, FILE *csv) {
    result res;
    sn_xform pose[MAXJ];
    sn_stats st;
    unsigned nJ = r->info.joints, nV = r->info.vertices, k;
    double h = pu_len(r->info.timestep);
    unsigned steps = (unsigned)ceil((RAMP_S + hold_s) / h - 1e-9), ramp_steps = (unsigned)ceil(RAMP_S / h - 1e-9);
    double *lat = NULL, *prev = NULL;
    snref_xform rp[MAXJ];
    memset(&res, 0, sizeof res);
    sn_reset(r->inst);
    if (csv && A->have_ref) {
        lat = malloc(3 * nV * sizeof *lat); prev = malloc(3 * nV * sizeof *prev);
        snref_reset(&A->s);
        pu_rt_lattice(r, prev);
        fprintf(csv, "step,t_s,energy_J,disp_cells,saturations,bound_steps,limit_clamps,energy_ref_J\n");
    }
    for (k = 0; k < steps; k++) {
        double t = (k + 1) * h, e;
        held_pose(r->blob, nJ, jn, ax, deg * ramp(k, h), pose);
        sn_set_pose(r->inst, pose, nJ);
        sn_step(r->inst);
        sn_get_stats(r->inst, &st);
        e = pu_len(st.energy);
        if (t >= 1 - 1e-9 && t <= 2 + 1e-9) { if (e > res.eA) res.eA = e; }
        else if (t > 2 && e > res.eB) res.eB = e;
        if (csv) {
            double eref = 0;
            if (lat) {
                double ek, ee;
                unsigned i;
                pu_rt_lattice(r, lat);
                pu_pose_to_ref(pose, nJ, rp);
                snref_set_pose(&A->s, rp);
                for (i = 0; i < 3 * nV; i++) { A->s.p[i] = lat[i] / A->m.unit; A->s.v[i] = (lat[i] - prev[i]) / A->m.unit; }
                snref_energy(&A->s, &ek, &ee);
                eref = (ek + ee) * A->m.energy;
                memcpy(prev, lat, 3 * nV * sizeof *lat);
            }
            fprintf(csv, "%u,%.6f,%.9g,%.6g,%u,%u,%u,%.9g\n", k + 1, t, e, pu_len(st.disp), st.saturations, st.bound_steps, st.limit_clamps, eref);
        }
    }
    res.sats = st.saturations; res.bound_steps = st.bound_steps; res.limit_steps = st.limit_steps;
    res.disp_max = pu_len(st.disp_max);
    free(lat); free(prev);
    if (static_ref && A->have_ref) {   /* same pose sequence into the reference (quaternion tracking), then solve */
        unsigned nS = r->info.surface_vertices, nVr = A->m.nV;
        double *sr = malloc(3 * nS * sizeof *sr), *ss = malloc(3 * nS * sizeof *ss), *sk = malloc(3 * nS * sizeof *sk);
        double *sl = malloc(3 * nVr * sizeof *sl), resid;
        snref_reset(&A->s);
        A->s.mode = SNREF_WARPED;
        for (k = 0; k <= ramp_steps; k++) {
            held_pose(r->blob, nJ, jn, ax, deg * ramp(k, h), pose);
            pu_pose_to_ref(pose, nJ, rp);
            snref_set_pose(&A->s, rp);
        }
        resid = snref_static(&A->s, 0);
        T_CHECK(resid < 1e-6, "static solve converged (relative residual %.2e)", resid);
        snref_get_surface(&A->s, ss);
        snref_get_skinned(&A->s, sl);
        snref_surface_from_lattice(&A->m, sl, sk);
        pu_rt_surface(r, sr);
        res.err = pu_maxdist(sr, ss, nS);
        {   /* diagnosis: a rigid spin about the bone (a free mode) shows as a turn here */
            double o[3], a[3], sc = 0, sn = 0;
            unsigned i, c2;
            joint_pos(r->blob, (uint32_t)jn, o);
            memcpy(a, tw_axis, sizeof a);
            for (i = 0; i < nS; i++) {
                double p0[3], p1[3], d0, d1;
                for (c2 = 0; c2 < 3; c2++) { p0[c2] = ss[3 * i + c2] - o[c2]; p1[c2] = sr[3 * i + c2] - o[c2]; }
                d0 = dot3(p0, a); d1 = dot3(p1, a);
                for (c2 = 0; c2 < 3; c2++) { p0[c2] -= d0 * a[c2]; p1[c2] -= d1 * a[c2]; }
                sn += a[0] * (p0[1] * p1[2] - p0[2] * p1[1]) + a[1] * (p0[2] * p1[0] - p0[0] * p1[2]) + a[2] * (p0[0] * p1[1] - p0[1] * p1[0]);
                sc += dot3(p0, p1);
            }
            res.spin = atan2(sn, sc) * 180 / PU_PI;
        }
        res.scale = pu_maxdist(ss, sk, nS);
        res.have_err = 1;
        free(sr); free(ss); free(sk); free(sl);
    }
    return res;
}

static int open_asset(asset_t *A, const char *name) {
    char p[512], p64[512];
    memset(A, 0, sizeof *A);
    {   /* name + flavour suffix */
        char nm[64];
        snprintf(nm, sizeof nm, "%s%s", name, PU_BLOB_SUFFIX);
        pu_example(p, sizeof p, nm);
        snprintf(nm, sizeof nm, "%s_double", name);
        pu_example(p64, sizeof p64, nm);
    }
    {
        FILE *f = fopen(p, "rb");
        if (!f) return 1;
        fclose(f);
    }
    if (pu_rt_open(&A->r, p) != 0) { T_CHECK(0, "cannot open %s", p); return -1; }
    if (A->r.info.joints > MAXJ) { T_CHECK(0, "%s: %u joints > %d", name, A->r.info.joints, MAXJ); return -1; }
    if (pu_ref_open(&A->m, &A->s, p64) == 0) A->have_ref = 1;
    else T_CHECK(0, "%s: no double-precision blob %s for the static solve", name, p64);
    A->cell = A->have_ref ? A->m.cell * A->m.unit : 0;
    return 0;
}

static void close_asset(asset_t *A) {
    if (A->have_ref) { snref_release(&A->s); snref_free(&A->m); }
    pu_rt_close(&A->r);
}

static int open_undamped(pu_rt *r, const char *name) {
    char p[512];
    snprintf(p, sizeof p, "%s/physics/held/%s_undamped%s.blob", pu_build(), name, PU_BLOB_SUFFIX);
    if (pu_rt_open(r, p) != 0) { T_CHECK(0, "cannot open %s (make re-bakes it)", p); return -1; }
    return 0;
}

typedef struct { double worst_growth, worst_err; unsigned sats, cases, bound; } summary;

static void sweep(const charspec *c, int soak, summary *sum) {
    static const double slice_angles[] = { 0, 90, 165, 180 };
    asset_t A;
    pu_rt u;
    unsigned nj = soak ? 4 : 1, ji, na = soak ? 13 : 4, ai, mode, damp;
    double hold[2] = { soak ? 60 : 14, soak ? 60 : 6 };   /* asset's damping, 0 */
    int rc = open_asset(&A, c->asset);
    if (rc > 0) {
        printf("SKIPPED: %s: no %s/examples/%s%s.blob (tools/examples/%s/%s.sinew not there yet?): its held poses were NOT tested\n",
               c->asset, pu_build(), c->asset, PU_BLOB_SUFFIX, c->asset, c->asset);
        return;
    }
    if (rc < 0) return;
    if (open_undamped(&u, c->asset) != 0) { close_asset(&A); return; }
    for (ji = 0; ji < nj && c->joints[ji]; ji++) {
        int32_t jn = sn_find_joint(A.r.blob, c->joints[ji]);
        double ax[2][3];
        if (jn < 0 || joint_axes(A.r.blob, A.r.info.joints, jn, ax[0], ax[1]) != 0) {
            T_CHECK(0, "%s: joint '%s' missing or without a child bone", c->asset, c->joints[ji]);
            continue;
        }
        printf("  %s %s: twist axis (%.3f %.3f %.3f), bend axis (%.3f %.3f %.3f); static solve on %s_double, displacement bound %g cells\n",
               c->asset, c->joints[ji], ax[0][0], ax[0][1], ax[0][2], ax[1][0], ax[1][1], ax[1][2], c->asset, A.have_ref ? A.m.disp_bound : 0.0);
        for (mode = 0; mode < 2; mode++)
            for (ai = 0; ai < na; ai++)
                for (damp = 0; damp < 2; damp++) {
                    double deg = soak ? 15.0 * ai : slice_angles[ai], growth;
                    pu_rt *r = damp ? &u : &A.r;
                    result res = run_case(&A, r, jn, ax[mode], ax[0], deg, hold[damp], !damp, NULL);
                    growth = res.eA > 0 ? res.eB / res.eA : (res.eB > 0 ? HUGE_VAL : 1);
                    printf("  %-5s %-10s %-5s %3.0f %-6s | %10.4g %10.4g %7.4f | %5u %5u %5u %7.3f |",
                           c->asset, c->joints[ji], mode ? "bend" : "twist", deg, damp ? "0 0" : "asset",
                           res.eA, res.eB, growth, res.sats, res.bound_steps, res.limit_steps, res.disp_max);
                    if (res.have_err) printf(" %9.3g %9.3g %8.2e\n", res.err, res.scale, res.err / fmax(res.scale, HELD_STATIC_FLOOR_CELLS * A.cell));
                    else printf(" %9s %9s %8s\n", "-", "-", "-");
                    T_CHECK(res.eB <= res.eA * (1 + HELD_TOL_REL) + HELD_TOL_ABS,
                            "%s %s %s %.0f deg, damping %s, %s: energy grows: max %.6g J over [1,2] s, %.6g J after 2 s (x%.4f)",
                            c->asset, c->joints[ji], mode ? "bend" : "twist", deg, damp ? "0" : "asset", PU_FLAVOUR_NAME, res.eA, res.eB, growth);
                    T_CHECK(res.sats == 0, "%s %s %s %.0f deg, damping %s, %s: %u saturations",
                            c->asset, c->joints[ji], mode ? "bend" : "twist", deg, damp ? "0" : "asset", PU_FLAVOUR_NAME, res.sats);
                    if (res.have_err) {
                        double rel = res.err / fmax(res.scale, HELD_STATIC_FLOOR_CELLS * A.cell);
                        T_CHECK(rel <= HELD_STATIC_BOUND,
                                "%s %s %s %.0f deg, %s: surface %.4g mesh units from the static equilibrium = %.3g of the displacement %.4g (bound %g); "
                                "runtime turned %.3f deg from it about the rest twist axis",
                                c->asset, c->joints[ji], mode ? "bend" : "twist", deg, PU_FLAVOUR_NAME, res.err, rel, res.scale, HELD_STATIC_BOUND, res.spin);
                        if (rel > sum->worst_err) sum->worst_err = rel;
                    }
                    if (growth > sum->worst_growth) sum->worst_growth = growth;
                    sum->sats += res.sats; sum->bound += res.bound_steps; sum->cases++;
                }
    }
    pu_rt_close(&u);
    close_asset(&A);
}

/* figure mode: 180 deg twist, damping 0, 60 s hold, per-step CSV */
static void figure(const char *dir) {
    static const char *const which[][2] = { { "limb", "elbow" }, { "cow", "neck" }, { "beast", "neck" } };
    unsigned i;
    for (i = 0; i < 3; i++) {
        asset_t A;
        pu_rt u;
        int32_t jn;
        double ax[2][3];
        char path[600];
        FILE *f;
        result res;
        if (open_asset(&A, which[i][0]) != 0) { printf("SKIPPED: %s not baked\n", which[i][0]); continue; }
        if (open_undamped(&u, which[i][0]) != 0) { close_asset(&A); continue; }
        jn = sn_find_joint(A.r.blob, which[i][1]);
        snprintf(path, sizeof path, "%s/%s_%s_twist180%s.csv", dir, which[i][0], which[i][1], PU_BLOB_SUFFIX);
        f = jn >= 0 && joint_axes(A.r.blob, A.r.info.joints, jn, ax[0], ax[1]) == 0 ? fopen(path, "w") : NULL;
        if (!f) { T_CHECK(0, "%s: no joint %s, or cannot write %s", which[i][0], which[i][1], path); pu_rt_close(&u); close_asset(&A); continue; }
        res = run_case(&A, &u, jn, ax[0], ax[0], 180, 60, 0, f);
        fclose(f);
        T_FIGURE("%s %s twist 180 held 60 s, damping 0, %s: max energy %.4g J over [1,2] s, %.4g J after (x%.4f); saturations %u; wrote %s",
                 which[i][0], which[i][1], PU_FLAVOUR_NAME, res.eA, res.eB, res.eA > 0 ? res.eB / res.eA : 0, res.sats, path);
        pu_rt_close(&u);
        close_asset(&A);
    }
}

int main(int argc, char **argv) {
    int soak = argc > 1 && !strcmp(argv[1], "soak");
    unsigned i;
    (void)pu_seed;
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (argc > 2 && !strcmp(argv[1], "figure")) { figure(argv[2]); return T_END(); }
    printf("held poses (%s runtime, %s): ramp 1 s, hold %s; energy growth = max E after 2 s / max E over [1,2] s\n",
           PU_FLAVOUR_NAME, soak ? "soak" : "default slice", soak ? "60 s" : "14 s (asset's damping), 6 s (damping 0)");
    printf("  %-5s %-10s %-5s %3s %-6s | %10s %10s %7s | %5s %5s %5s %7s | %9s %9s %8s\n", "asset", "joint", "mode", "deg", "damp",
           "E[1,2]s J", "E>2s J", "growth", "sat", "bound", "limit", "disp", "static", "displ", "rel");
    for (i = 0; i < sizeof CHARS / sizeof CHARS[0]; i++) {
        summary s;
        memset(&s, 0, sizeof s);
        sweep(&CHARS[i], soak, &s);
        if (s.cases)
            T_FIGURE("held %s %s: %u cases, worst energy growth x%.4f, saturations %u, bound steps %u, worst static error %.2e of the displacement",
                     CHARS[i].asset, PU_FLAVOUR_NAME, s.cases, s.worst_growth, s.sats, s.bound, s.worst_err);
    }
    return T_END();
}
