/* test_physics_vibration.c -- cantilever free vibration (damping off): first
 * bending frequency vs Euler-Bernoulli f1 = 1.875^2/(2 pi) sqrt(EI/(rho A L^4)),
 * and how backward Euler's numerical damping and period error grow with h.
 * The beam starts undeformed with gravity on, so it swings about its static
 * equilibrium, mostly in the first mode (the gravity load is close to it). */
#include "sn_test.h"
#include "reference/phys_util.h"

#define PI 3.14159265358979323846

/* mean y of the tip face's free vertices, mesh units */
static double tip_y(const snref_model *m, const double *lat) {
    double xmax = -1e300, sum = 0;
    unsigned i, n = 0;
    for (i = 0; i < m->nV; i++) if (m->rest[3 * i] > xmax) xmax = m->rest[3 * i];
    for (i = 0; i < m->nF; i++) if (m->rest[3 * i] > xmax - 1e-9) { sum += lat[3 * i + 1]; n++; }
    return sum / n;
}

typedef struct vib { double period, decay; int ok; } vib;

/* Period (s) from upward zero crossings of e = y - y_static (linear
 * interpolation), and amplitude ratio per period from successive maxima. */
static vib analyse(const double *y, unsigned n, double ystat, double h, int with_start) {
    vib v = { 0, 0, 0 };
    double t0 = -1, t1 = -1, pk[16];
    unsigned k, ncross = 0, npk = 0;
    double cur = -1e300;
    for (k = 1; k < n; k++) {
        double a = y[k - 1] - ystat, b = y[k] - ystat;
        if (b > cur) cur = b;
        if (a < 0 && b >= 0) {
            double t = (k - 1 + a / (a - b)) * h;
            if (ncross == 0) t0 = t;
            t1 = t;
            ncross++;
            cur = -1e300;
        }
        /* max of each positive half-wave; the first one (the start, with higher
         * modes still in it) only if with_start */
        if (a >= 0 && b < 0 && (ncross > 0 || with_start) && npk < 16) { pk[npk++] = cur; cur = -1e300; }
    }
    if (ncross >= 2) { v.period = (t1 - t0) / (ncross - 1); v.ok = 1; }
    if (npk >= 2) v.decay = pow(pk[npk - 1] / pk[0], 1.0 / (npk - 1));
    return v;
}

int main(void) {
    char path[512];
    snref_model m;
    snref_state s;
    double unit = 0.1, E = 0, nu = 0, rho = 0, L, H, W, A, I, f_eb, ystat, omega_model, h0, kin, el;
    unsigned i;
    printf("cantilever free vibration (%s runtime)\n", PU_FLAVOUR_NAME);
    {   /* material from the generated description */
        FILE *f;
        char line[512], nm[64];
        snprintf(path, sizeof path, "%s/examples/beam4/beam.sinew", pu_build());
        f = fopen(path, "r");
        T_CHECK(f != NULL, "missing %s", path);
        if (!f) return T_END();
        while (fgets(line, sizeof line, f)) {
            if (sscanf(line, "unit %lf", &unit) == 1) continue;
            if (sscanf(line, "material %63s %lf %lf %lf", nm, &E, &nu, &rho) == 4) continue;
        }
        fclose(f);
    }
    pu_example(path, sizeof path, "beam4_double");
    if (pu_ref_open(&m, &s, path) != 0) { T_CHECK(0, "%s", path); return T_END(); }
    {
        double lo[3] = { 1e300, 1e300, 1e300 }, hi[3] = { -1e300, -1e300, -1e300 };
        unsigned k;
        for (i = 0; i < m.nV; i++)
            for (k = 0; k < 3; k++) {
                double x = m.rest[3 * i + k] * m.unit;
                if (x < lo[k]) lo[k] = x;
                if (x > hi[k]) hi[k] = x;
            }
        L = (hi[0] - lo[0]) * unit; H = (hi[1] - lo[1]) * unit; W = (hi[2] - lo[2]) * unit;
    }
    A = H * W; I = W * H * H * H / 12;
    f_eb = 1.875104 * 1.875104 / (2 * PI) * sqrt(E * I / (rho * A * L * L * L * L));
    h0 = m.h;
    /* static equilibrium, and the model's own first frequency by inverse
     * iteration from the static shape: x <- S^-1 M x, (omega h)^2 = x'S^x / x'M^x */
    snref_static(&s, 1500);
    {
        double *lat = malloc(3 * m.nV * sizeof *lat), *x = malloc(3 * m.nF * sizeof *x), *y = malloc(3 * m.nF * sizeof *y);
        unsigned it;
        snref_get_lattice(&s, lat);
        ystat = tip_y(&m, lat);
        for (i = 0; i < 3 * m.nF; i++) x[i] = s.p[i] - (m.rest[i] + m.jrest[i % 3]);
        for (it = 0; it < 8; it++) {
            double nx = 0;
            snref_mass_mul(&s, x, y);
            snref_solve_load(&s, y, x);
            for (i = 0; i < 3 * m.nF; i++) nx += x[i] * x[i];
            for (i = 0; i < 3 * m.nF; i++) x[i] /= sqrt(nx);
        }
        for (i = 0; i < 3 * m.nF; i++) s.v[i] = x[i];
        snref_energy(&s, &kin, &el);        /* 1/2 x'M^x and 1/2 u'S^u with u = current shape: recompute below */
        snref_mass_mul(&s, x, y);
        kin = 0;
        for (i = 0; i < 3 * m.nF; i++) kin += x[i] * y[i];
        for (i = 0; i < 3 * m.nF; i++) s.p[i] = x[i] + (m.rest[i] + m.jrest[i % 3]);
        s.gscale = 0;
        snref_residual(&s, y);                /* -S^ x */
        s.gscale = 1;
        el = 0;
        for (i = 0; i < 3 * m.nF; i++) el -= x[i] * y[i];
        omega_model = sqrt(el / kin) / h0;
        memset(s.v, 0, 3 * m.nV * sizeof *s.v);
        free(lat); free(x); free(y);
    }
    (void)ystat;
    T_FIGURE("beam4 (L %.2f m, H %.2f m, E %.3g, rho %.0f): Euler-Bernoulli f1 = %.4f Hz; lattice model (inverse iteration) %.4f Hz (%+.2f%%: discretization)",
             L, H, E, rho, f_eb, omega_model / (2 * PI), 100 * (omega_model / (2 * PI) / f_eb - 1));
#if !defined(SN_FLOAT)
    /* h table: reference, exact solves (the scheme itself), h = h0 / {1, 2, 4, 8} */
    T_FIGURE("  h (s)    | omega h | f measured (Hz) | f / f_EB | period / model period | BE theory (wh/atan wh) | amplitude per period | BE theory (1+(wh)^2)^(-T/2h)");
    {
        static const double div[4] = { 1, 2, 4, 8 };
        unsigned d;
        for (d = 0; d < 4; d++) {
            double h = h0 / div[d], wh = omega_model * h, *y, *lat = malloc(3 * m.nV * sizeof *lat);
            unsigned n = (unsigned)(2.35 * 2 * PI / omega_model / h) + 2, k;
            vib v;
            y = malloc(n * sizeof *y);
            snref_reset(&s);
            s.hscale = 1.0 / div[d]; s.exact = 1;
            for (k = 0; k < n; k++) { snref_step(&s); snref_get_lattice(&s, lat); y[k] = tip_y(&m, lat); }
            v = analyse(y, n, ystat, h, 0);
            {
                double th_period = wh / atan(wh), th_decay = pow(1 + wh * wh, -0.5 * v.period / h);
                T_FIGURE("  %.6f | %7.4f | %15.4f | %8.4f | %21.4f | %22.4f | %20.4f | %.4f", h, wh, 1 / v.period, 1 / v.period / f_eb,
                         v.period * omega_model / (2 * PI), th_period, v.decay, th_decay);
                T_CHECK(v.ok, "h %g: no oscillation found", h);
                T_NEAR(v.period * omega_model / (2 * PI), th_period, 0.002 * th_period,
                       "period elongation follows backward Euler's wh/atan(wh) on the first mode (0.2%: crossing interpolation, higher modes in the signal)");
                T_NEAR(v.decay, th_decay, 0.01, "amplitude decay per period follows (1+(wh)^2)^(-N/2) (1%: peaks sampled at steps, higher modes)");
                if (d == 3) {
                    PU_GOAL(fabs(1 / v.period / f_eb - 1) <= 0.05,
                            "first bending frequency at small h (%.5f s) %.4f Hz vs Euler-Bernoulli %.4f Hz: %+.2f%% (goal 5%%)",
                            h, 1 / v.period, f_eb, 100 * (1 / v.period / f_eb - 1));
                    T_CHECK(fabs(1 / v.period / f_eb - 1) <= 0.10, "frequency off by more than 10%%");
                }
            }
            free(y); free(lat);
        }
        s.hscale = 1; s.exact = 0;
    }
#endif
    /* runtime: the beam re-baked at h = 1/960 s ($(BUILD)/physics/beam4_h960*.blob),
     * 32 CG iterations (converged at this h: the double reference's relative residual is ~1e-6) */
    {
        pu_rt r;
        snref_model mr;
        snref_state sr;
        snprintf(path, sizeof path, "%s/physics/beam4_h960%s.blob", pu_build(), PU_BLOB_SUFFIX);
        if (pu_rt_open(&r, path) == 0 && pu_ref_open(&mr, &sr, path) == 0) {
            double h = mr.h, *lat = malloc(3 * mr.nV * sizeof *lat), ys, *y, *yr;
            unsigned n = (unsigned)(1.9 / f_eb / h) + 2, k;
            sn_xform pose[1];
            sn_stats st;
            vib v, vr;
            char p64[512];
            snref_model m64;
            snref_state s64;
            snprintf(p64, sizeof p64, "%s/physics/beam4_h960_double.blob", pu_build());
            pu_ref_open(&m64, &s64, p64);
            h = m64.h;      /* the exact h (the fixed blob's h is Q16.16) */
            snref_static(&s64, 1500);
            snref_get_lattice(&s64, lat);
            ys = tip_y(&m64, lat);
            y = malloc(n * sizeof *y); yr = malloc(n * sizeof *yr);
            sn_set_iterations(r.inst, 32);
            sr.exact = 1;   /* reference: exact solves (32 iterations are converged here) */
            pu_identity(pose, 1);
            sn_set_pose(r.inst, pose, 1);
            for (k = 0; k < n; k++) {
                sn_step(r.inst); pu_rt_lattice(&r, lat); y[k] = tip_y(&mr, lat);
                snref_step(&sr); snref_get_lattice(&sr, lat); yr[k] = tip_y(&mr, lat);
            }
            sn_get_stats(r.inst, &st);
            v = analyse(y, n, ys, h, 1);   /* 1.9 periods: runtime and reference measured alike */
            vr = analyse(yr, n, ys, h, 1);
            T_FIGURE("beam4 %s runtime, h = %.6f s, 32 CG it.: f = %.4f Hz (f/f_EB %.4f), amplitude per period %.4f; reference on the same blob %.4f Hz, %.4f; saturations %u",
                     PU_FLAVOUR_NAME, h, 1 / v.period, 1 / v.period / f_eb, v.decay, 1 / vr.period, vr.decay, st.saturations);
            T_CHECK(v.ok, "runtime: no oscillation found");
            T_NEAR(v.period / vr.period, 1.0, 0.005, "runtime period = reference period on the same blob (0.5%: one step in 200 per period)");
#if defined(SN_FLOAT)
            PU_GOAL(fabs(v.decay - vr.decay) <= 0.01, "%s runtime amplitude per period %.4f = the scheme's (reference, same blob) %.4f within 0.01 (no energy injected by the arithmetic)",
                    PU_FLAVOUR_NAME, v.decay, vr.decay);
#else
            PU_KNOWN_MISS(fabs(v.decay - vr.decay), 0.01, 0.025,
                          "fixed point only (float matches the scheme to 1e-4): the fixed runtime keeps more amplitude "
                          "(0.9967 per period vs the scheme's 0.9770); cause not isolated, likely backward Euler's small "
                          "numerical damping at h = 1/960 s (~1e-4 of the motion per step) lost in the rounding of the Q22 "
                          "per-step velocity; bound 0.025 over today's 0.0197 (bit-exact runtime)",
                          "%s runtime amplitude per period %.4f = the scheme's (reference, same blob) %.4f within 0.01 (no energy injected by the arithmetic)",
                          PU_FLAVOUR_NAME, v.decay, vr.decay);
            T_CHECK(v.decay < 1.0, "fixed runtime: the amplitude grows (%.4f per period): energy injected", v.decay);
#endif
            PU_GOAL(fabs(1 / v.period / f_eb - 1) <= 0.05, "%s runtime first bending frequency %.4f Hz vs Euler-Bernoulli %.4f Hz: %+.2f%% (goal 5%%)",
                    PU_FLAVOUR_NAME, 1 / v.period, f_eb, 100 * (1 / v.period / f_eb - 1));
            free(lat); free(y); free(yr);
            snref_release(&sr); snref_free(&mr); snref_release(&s64); snref_free(&m64); pu_rt_close(&r);
        } else T_CHECK(0, "missing %s", path);
    }
    snref_release(&s);
    snref_free(&m);
    return T_END();
}
