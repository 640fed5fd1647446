/* test_physics_cantilever.c -- static cantilever under gravity vs Euler-Bernoulli
 * w L^4 / (8 E I), for the tool's beams with 1, 2, 4 cells through the height
 * (tools/examples/beam, $(BUILD)/examples/beamN*.blob).
 *  - reference static solve (seed 003 eq. 10) on the float64 blob: the model's
 *    own answer, with the incompatible-mode element (tests/reference/snref_synth)
 *    as an independent check of the tool's integration (its default element),
 *    and the textbook trilinear hex to show the locking it removes;
 *  - blob quantization: the same solve on the fixed / float32 blobs;
 *  - the runtime (this build's flavour) settled from rest.
 * The float build runs beam1 only (damped and undamped: the float runtime is
 * within 0.01% of its blob's static tip at every size, the fixed build checks
 * every size); --all (`make cantilever-float`) runs beam2 and beam4 too. */
#include "sn_test.h"
#include "reference/phys_util.h"
#include "reference/snref_synth.h"

typedef struct beam_desc { double unit, E, nu, rho, g; } beam_desc;

/* material / unit / gravity from $(BUILD)/examples/beamN/beam.sinew */
static int read_desc(unsigned n, beam_desc *d) {
    char path[512], line[512];
    FILE *f;
    snprintf(path, sizeof path, "%s/examples/beam%u/beam.sinew", pu_build(), n);
    f = fopen(path, "r");
    if (!f) return -1;
    memset(d, 0, sizeof *d);
    while (fgets(line, sizeof line, f)) {
        char name[64];
        double gx, gy, gz;
        if (sscanf(line, "unit %lf", &d->unit) == 1) continue;
        if (sscanf(line, "material %63s %lf %lf %lf", name, &d->E, &d->nu, &d->rho) == 4) continue;
        if (sscanf(line, "gravity %lf %lf %lf", &gx, &gy, &gz) == 3) d->g = sqrt(gx * gx + gy * gy + gz * gz);
    }
    fclose(f);
    return d->unit > 0 && d->E > 0 && d->rho > 0 ? 0 : -1;
}

/* beam box from the lattice: length along x, height y, width z (mesh units) */
static void extents(const snref_model *m, double lo[3], double hi[3]) {
    unsigned i, k;
    for (k = 0; k < 3; k++) { lo[k] = 1e300; hi[k] = -1e300; }
    for (i = 0; i < m->nV; i++)
        for (k = 0; k < 3; k++) {
            double x = m->rest[3 * i + k] * m->unit;
            if (x < lo[k]) lo[k] = x;
            if (x > hi[k]) hi[k] = x;
        }
}

/* mean y displacement of the free vertices of the tip face x = max, mesh units */
static double tip_dy(const snref_model *m, const double *lat) {
    double lo[3], hi[3], sum = 0, x0y = m->jrest[1] * m->unit;
    unsigned i, n = 0;
    extents(m, lo, hi);
    for (i = 0; i < m->nF; i++)
        if (m->rest[3 * i] * m->unit > hi[0] - 1e-6) { sum += lat[3 * i + 1] - (m->rest[3 * i + 1] * m->unit + x0y); n++; }
    return n ? sum / n : 0;
}

static double ref_static_tip(const char *path, snref_model *keep) {
    snref_model m;
    snref_state s;
    double *lat, tip;
    if (pu_ref_open(&m, &s, path) != 0) return NAN;
    snref_static(&s, 1500);
    lat = malloc(3 * m.nV * sizeof *lat);
    snref_get_lattice(&s, lat);
    tip = tip_dy(&m, lat);
    free(lat);
    snref_release(&s);
    if (keep) *keep = m; else snref_free(&m);
    return tip;
}

int main(int argc, char **argv) {
    static const unsigned cells[3] = { 1, 2, 4 };
    unsigned c, sizes = 3;
    char path[512];
    printf("cantilever static (%s runtime)\n", PU_FLAVOUR_NAME);
#if defined(SN_FLOAT)
    if (!(argc > 1 && strcmp(argv[1], "--all") == 0)) {
        sizes = 1;
        printf("  beam1 only; beam2 and beam4: --all (make cantilever-float)\n");
    }
#else
    (void)argc; (void)argv;
#endif
#if !defined(SN_FLOAT)
    T_FIGURE("cantilever static: tip deflection / Euler-Bernoulli w L^4/(8EI) (reference static solve of seed 003 eq. 10)");
    T_FIGURE("  cells/H | tool f64 blob | textbook hex | incompatible modes | fixed blob | float32 blob | Timoshenko/EB");
#endif
    for (c = 0; c < sizes; c++) {
        unsigned n = cells[c];
        beam_desc d;
        snref_model m;
        double lo[3], hi[3], L, H, W, A, I, w, eb, tim, tip64;
        char name[64];
        snprintf(name, sizeof name, "beam%u_double", n);
        pu_example(path, sizeof path, name);
        if (read_desc(n, &d) != 0) { T_CHECK(0, "beam%u description missing", n); continue; }
        tip64 = ref_static_tip(path, &m);
        if (tip64 != tip64) { T_CHECK(0, "%s missing", path); continue; }
        extents(&m, lo, hi);
        L = (hi[0] - lo[0]) * d.unit; H = (hi[1] - lo[1]) * d.unit; W = (hi[2] - lo[2]) * d.unit;
        A = H * W; I = W * H * H * H / 12; w = d.rho * d.g * A;
        eb = w * L * L * L * L / (8 * d.E * I);                     /* Euler-Bernoulli tip deflection, m */
        tim = eb + w * L * L / (2 * (10 * (1 + d.nu) / (12 + 11 * d.nu)) * d.E / (2 * (1 + d.nu)) * A); /* + shear (Cowper kappa) */
        T_CHECK(L / H >= 8, "slender: L/H = %.1f", L / H);
        (void)tim;
#if !defined(SN_FLOAT)
        {
            double r64 = -tip64 * d.unit / eb, rtext, rinc, rfix, rf32;
            /* independent textbook beam with the same geometry, full and incompatible-mode elements */
            snsyn_box b;
            size_t sz;
            unsigned char *bl;
            snref_model ms;
            snref_state ss;
            int integ;
            double rr[2];
            char err[128];
            for (integ = 0; integ < 2; integ++) {
                double *lat;
                memset(&b, 0, sizeof b);
                b.nx = (unsigned)lround((hi[0] - lo[0]) * n / (hi[1] - lo[1])); b.ny = n; b.nz = n;
                b.dx = L / b.nx; b.dy = H / n; b.dz = W / n;
                b.E = d.E; b.nu = d.nu; b.rho = d.rho; b.h = m.h; b.g[1] = -d.g;
                b.flavour = 2; b.cg_default = 32;
                b.integration = integ ? SNSYN_INCOMPATIBLE : SNSYN_FULL;
                bl = snsyn_build(&b, &sz);
                if (!bl || snref_load(&ms, bl, sz, err, sizeof err) != 0) {
                    T_CHECK(0, "synthetic beam: %s", bl ? err : "snsyn_build failed");
                    free(bl);
                    return T_END();
                }
                snref_init(&ss, &ms);
                snref_static(&ss, 1500);
                lat = malloc(3 * ms.nV * sizeof *lat);
                snref_get_lattice(&ss, lat);
                rr[integ] = -tip_dy(&ms, lat) / eb;   /* synthetic blobs are in metres */
                free(lat); snref_release(&ss); snref_free(&ms); free(bl);
            }
            rtext = rr[0]; rinc = rr[1];
            snprintf(name, sizeof name, "beam%u", n); pu_example(path, sizeof path, name);
            rfix = -ref_static_tip(path, NULL) * d.unit / eb;
            snprintf(name, sizeof name, "beam%u_float", n); pu_example(path, sizeof path, name);
            rf32 = -ref_static_tip(path, NULL) * d.unit / eb;
            T_FIGURE("  %7u | %13.4f | %12.4f | %18.4f | %10.4f | %12.4f | %.4f", n, r64, rtext, rinc, rfix, rf32, tim / eb);
            /* the tool's default element condenses Wilson-Taylor incompatible modes (tools/sb_integrate.c) */
            T_NEAR(r64 / rinc, 1.0, 1e-6, "tool integration (subdivided Gauss) = 2x2x2 incompatible-mode hex for full cells; round-off only");
            if (n == 4) T_NEAR(r64, 1.0, 0.05, "goal: within 5% of Euler-Bernoulli at the finest lattice (brief)");
            if (n == 2) {   /* the scheme itself (double reference), undamped, the runtime's CG count: warm vs cold start */
                unsigned its[3] = { 32, 64, 128 }, q, k;
                int warm;
                snprintf(name, sizeof name, "beam%u_double", n); pu_example(path, sizeof path, name);
                for (q = 0; q < 3; q++)
                    for (warm = 1; warm >= 0; warm--) {
                        snref_model mw;
                        snref_state sw;
                        double *l2, t;
                        if (pu_ref_open(&mw, &sw, path) != 0) break;
                        l2 = malloc(3 * mw.nV * sizeof *l2);
                        sw.iters = its[q]; sw.warm = warm;
                        for (k = 0; k < 600; k++) snref_step(&sw);
                        snref_get_lattice(&sw, l2);
                        t = tip_dy(&mw, l2);
                        T_FIGURE("beam2 undamped, double reference, %u CG it., %s start, 600 steps: tip %.5g (static %.5f)%s", its[q],
                                 warm ? "warm" : "cold", t, tip64, fabs(t / tip64 - 1) > 0.5 ? "  DIVERGED" : "");
                        free(l2); snref_release(&sw); snref_free(&mw);
                    }
            }
            T_NEAR(rinc, tim / eb, 0.03 * tim / eb, "incompatible modes remove the locking at every resolution (3%: clamp/3-D effects)");
            PU_GOAL(fabs(rfix / r64 - 1) <= 0.01, "beam%u fixed blob quantization changes the static tip by %+.3f%% (budget 1%%, as the runtime goal)", n, 100 * (rfix / r64 - 1));
            PU_GOAL(fabs(rf32 / r64 - 1) <= 0.01, "beam%u float32 blob quantization changes the static tip by %+.3f%% (budget 1%%)", n, 100 * (rf32 / r64 - 1));
            T_CHECK(fabs(rfix / r64 - 1) < 0.05 && fabs(rf32 / r64 - 1) < 0.05, "blob quantization error above 5%%: fixed %g float32 %g", rfix / r64, rf32 / r64);
        }
#endif
        /* runtime: settle from rest on the mass-damped re-bake ($(BUILD)/physics/beamN_damped*.blob,
         * rayleigh 20 0: the equilibrium does not depend on damping), and undamped on beam1 */
        {
            int pass;
            for (pass = 0; pass < 2; pass++) {
                pu_rt r;
                unsigned k, steps = pass == 0 ? 200 : 700;
                if (pass == 1 && n != 1) break;
                if (pass == 0) snprintf(path, sizeof path, "%s/physics/beam%u_damped%s.blob", pu_build(), n, PU_BLOB_SUFFIX);
                else { snprintf(name, sizeof name, "beam%u%s", n, PU_BLOB_SUFFIX); pu_example(path, sizeof path, name); }
                if (pu_rt_open(&r, path) == 0) {
                    snref_model mq;
                    double tipq = ref_static_tip(path, &mq), *lat = malloc(3 * r.info.vertices * sizeof *lat), tipr, tipr2;
                    sn_xform pose[1];
                    sn_stats st;
                    pu_identity(pose, 1);
                    sn_set_pose(r.inst, pose, 1);
                    for (k = 0; k < steps; k++) sn_step(r.inst);
                    pu_rt_lattice(&r, lat); tipr = tip_dy(&mq, lat);
                    for (k = 0; k < 37; k++) sn_step(r.inst);   /* ~ one period later: still moving? */
                    pu_rt_lattice(&r, lat); tipr2 = tip_dy(&mq, lat);
                    sn_get_stats(r.inst, &st);
                    T_FIGURE("beam%u %s runtime, %s, %u steps, %u CG it.: tip %.5f, reference static on the same blob %.5f (%+.3f%%), "
                             "on the float64 blob %.5f (%+.3f%%), E-B %.5f; residual motion %.1e; saturations %u",
                             n, PU_FLAVOUR_NAME, pass ? "undamped" : "damped", steps, r.info.cg_iters_default, tipr, tipq,
                             100 * (tipr / tipq - 1), tip64, 100 * (tipr / tip64 - 1), -eb / d.unit, fabs(tipr2 - tipr) / fabs(tipq),
                             st.saturations);
                    /* beam1 undamped, fixed, was a known miss (1.89%, bound 2%) until the IC(0) preconditioner */
                    PU_GOAL(fabs(tipr / tipq - 1) <= 0.01,
                            "beam%u %s runtime (%s) settles on the static equilibrium of its blob within 1%% (runtime goal; got %+.3g%%)",
                            n, PU_FLAVOUR_NAME, pass ? "undamped" : "damped", 100 * (tipr / tipq - 1));
                    PU_GOAL(fabs(tipr2 - tipr) <= 0.01 * fabs(tipq),
                            "beam%u %s runtime (%s) at rest: residual motion over 37 steps %.2g of the static tip <= 1%%",
                            n, PU_FLAVOUR_NAME, pass ? "undamped" : "damped", fabs(tipr2 - tipr) / fabs(tipq));
                    T_CHECK(tipr == tipr && fabs(tipr) < 10 * fabs(tipq), "beam%u runtime blew up: tip %g", n, tipr);
                    free(lat); snref_free(&mq); pu_rt_close(&r);
                } else T_CHECK(0, "runtime blob %s", path);
            }
        }
        snref_free(&m);
    }
    return T_END();
}
