/* test_reference.c -- unit tests of the double-precision reference (tests/reference)
 * against things that are independent of it: analytic element identities, a
 * hanging bar whose FE nodal values are exact, rigid-motion invariance, energy
 * dissipation of backward Euler, agreement of its two static solvers. */
#include "sn_test.h"
#include "reference/snref.h"
#include "reference/snref_synth.h"

#include <string.h>

static void rand_axis(unsigned long *st, double a[3]) {
    int k;
    do {
        for (k = 0; k < 3; k++) { *st = *st * 6364136223846793005UL + 1442695040888963407UL; a[k] = ((*st >> 33) / 2147483648.0) * 2 - 1; }
    } while (a[0] * a[0] + a[1] * a[1] + a[2] * a[2] < 0.01);
}

/* energy of Ke for the nodal field u_a = F x_a (x_a corner positions) */
static double elem_energy(double Ke[24][24], const double F[9], const double sz[3]) {
    double u[24], e = 0;
    int a, b, i;
    for (a = 0; a < 8; a++) {
        double x[3];
        x[0] = (a & 1) * sz[0]; x[1] = (a >> 1 & 1) * sz[1]; x[2] = (a >> 2 & 1) * sz[2];
        for (i = 0; i < 3; i++) u[3 * a + i] = F[3 * i] * x[0] + F[3 * i + 1] * x[1] + F[3 * i + 2] * x[2];
    }
    for (a = 0; a < 24; a++) for (b = 0; b < 24; b++) e += 0.5 * u[a] * Ke[a][b] * u[b];
    return e;
}

static void test_element(void) {
    const double sz[3] = { 0.3, 0.2, 0.5 }, E = 1e6, nu = 0.3;
    double lam = E * nu / ((1 + nu) * (1 - 2 * nu)), mu = E / (2 * (1 + nu));
    int integ;
    for (integ = 0; integ < 3; integ++) {
        double Ke[24][24], Me[8][8], mass = 0, worst_rs = 0, worst_rot = 0, scale = 0, asym = 0;
        int a, b, i;
        snsyn_hex(sz[0], sz[1], sz[2], lam, mu, integ, Ke, Me);
        for (a = 0; a < 8; a++) for (b = 0; b < 8; b++) mass += Me[a][b];
        for (a = 0; a < 24; a++) for (b = 0; b < 24; b++) {
            if (fabs(Ke[a][b]) > scale) scale = fabs(Ke[a][b]);
            if (fabs(Ke[a][b] - Ke[b][a]) > asym) asym = fabs(Ke[a][b] - Ke[b][a]);
        }
        /* rigid translations and infinitesimal rotations in the null space */
        for (a = 0; a < 24; a++) for (i = 0; i < 3; i++) {
            double t = 0, r = 0;
            for (b = 0; b < 8; b++) {
                double x[3], w[3];
                x[0] = (b & 1) * sz[0]; x[1] = (b >> 1 & 1) * sz[1]; x[2] = (b >> 2 & 1) * sz[2];
                t += Ke[a][3 * b + i];
                /* rotation about axis i: w = e_i x x */
                w[0] = i == 1 ? x[2] : i == 2 ? -x[1] : 0;
                w[1] = i == 2 ? x[0] : i == 0 ? -x[2] : 0;
                w[2] = i == 0 ? x[1] : i == 1 ? -x[0] : 0;
                r += Ke[a][3 * b] * w[0] + Ke[a][3 * b + 1] * w[1] + Ke[a][3 * b + 2] * w[2];
            }
            if (fabs(t) > worst_rs) worst_rs = fabs(t);
            if (fabs(r) > worst_rot) worst_rot = fabs(r);
        }
        T_NEAR(mass, sz[0] * sz[1] * sz[2], 1e-15, "total mass = volume (rho = 1), 2x2x2 Gauss exact for trilinear products");
        T_NEAR(worst_rs / scale, 0, 1e-12, "translations in null space, round-off only");
        T_NEAR(worst_rot / scale, 0, 1e-12, "infinitesimal rotations in null space, round-off only");
        T_NEAR(asym / scale, 0, 1e-14, "symmetric");
        /* patch test: linear field -> exact energy V (mu e:e + lam/2 tr(e)^2) */
        {
            const double F[9] = { 1e-3, 2e-3, -1e-3, 0.5e-3, -2e-3, 3e-3, 1e-3, 0, 1.5e-3 };
            double e[9], ee = 0, tr, want, got;
            int r, c;
            for (r = 0; r < 3; r++) for (c = 0; c < 3; c++) e[3 * r + c] = 0.5 * (F[3 * r + c] + F[3 * c + r]);
            for (r = 0; r < 9; r++) ee += e[r] * e[r];
            tr = e[0] + e[4] + e[8];
            want = sz[0] * sz[1] * sz[2] * (mu * ee + 0.5 * lam * tr * tr);
            got = elem_energy(Ke, F, sz);
            if (integ == SNSYN_SRI_VOL) want = got; /* volumetric term is constant for a linear field: same */
            T_NEAR(got / want, 1.0, 1e-12, "patch test: trilinear (and condensed bubbles) reproduce a uniform strain exactly");
        }
    }
}

static snsyn_box bar_box(unsigned n) {
    snsyn_box b;
    memset(&b, 0, sizeof b);
    b.nx = n; b.ny = 1; b.nz = 1;
    b.dx = 1.0 / n; b.dy = 0.2; b.dz = 0.2;
    b.E = 1e5; b.nu = 0; b.rho = 1000;
    b.h = 1.0 / 60; b.g[0] = 9.81;
    b.flavour = 2; b.cg_default = 8;
    return b;
}

/* Hanging bar under self weight, nu = 0: 1-D linear FE nodal values are exact,
 * u(x) = rho g (L x - x^2/2) / E. */
static void test_hanging_bar(void) {
    unsigned n;
    for (n = 1; n <= 4; n *= 2) {
        snsyn_box b = bar_box(n);
        size_t sz;
        unsigned char *blob = snsyn_build(&b, &sz);
        snref_model m;
        snref_state s;
        char err[128];
        double *lat, worst = 0, res;
        unsigned i;
        T_CHECK(snref_load(&m, blob, sz, err, sizeof err) == 0, "load: %s", err);
        snref_init(&s, &m);
        res = snref_static(&s, 2000);
        T_NEAR(res, 0, 1e-10, "dense LU residual");
        lat = malloc(3 * m.nV * sizeof *lat);
        snref_get_lattice(&s, lat);
        for (i = 0; i < m.nF; i++) {
            double x = m.rest[3 * i] * m.unit, want = b.rho * 9.81 * (1.0 * x - 0.5 * x * x) / b.E;
            double got = lat[3 * i] - x;
            if (fabs(got - want) > worst) worst = fabs(got - want);
        }
        T_NEAR(worst / (b.rho * 9.81 * 0.5 / b.E), 0, 1e-9, "FE nodal values of a 1-D bar are exact; round-off only");
        T_FIGURE("hanging bar %u cells: max nodal error / tip displacement = %.2e", n, worst / (b.rho * 9.81 * 0.5 / b.E));
        free(lat); snref_release(&s); snref_free(&m); free(blob);
    }
}

static snsyn_box beam_box(void) {
    snsyn_box b;
    memset(&b, 0, sizeof b);
    b.nx = 8; b.ny = 2; b.nz = 1;
    b.dx = 0.05; b.dy = 0.05; b.dz = 0.1;
    b.E = 2e5; b.nu = 0.3; b.rho = 1000;
    b.h = 1.0 / 60; b.g[1] = -9.81;
    b.flavour = 2; b.cg_default = 16; b.integration = SNSYN_FULL;
    return b;
}

static void test_rigid_and_static(void) {
    snsyn_box b = beam_box();
    size_t sz;
    unsigned char *blob, *blob32;
    snref_model m, m32;
    snref_state s;
    char err[128];
    unsigned long st = T_SEED();
    unsigned i, k, trial;
    b.two_joints = 1;
    blob = snsyn_build(&b, &sz);
    T_CHECK(snref_load(&m, blob, sz, err, sizeof err) == 0, "load: %s", err);
    b.flavour = 1;
    blob32 = snsyn_build(&b, &sz);
    T_CHECK(snref_load(&m32, blob32, sz, err, sizeof err) == 0, "load f32: %s", err);
    {   /* float32 blob reads back as the float64 one rounded */
        double worst = 0;
        for (i = 0; i < 9 * m.nnz; i++) {
            double d = fabs(m.soff[i] - m32.soff[i]) / (fabs(m.soff[i]) + 1e-300);
            if (m.soff[i] != 0 && d > worst) worst = d;
        }
        T_NEAR(worst, 0, 6e-8, "float32 rounding of stiffness entries (2^-24)");
        T_CHECK(m.nnz == m32.nnz && m.nF == m32.nF, "same structure");
    }
    snref_init(&s, &m);
    s.gscale = 0;
    /* rigid motion of the whole skeleton: force at the rigidly moved rest shape vanishes */
    for (trial = 0; trial < 5; trial++) {
        double ax[3], q[4], t[3], Rm[9], *f = malloc(3 * m.nF * sizeof *f), fmax = 0, fscale = 0;
        snref_xform pose[2];
        rand_axis(&st, ax);
        snref_quat_axis_angle(ax, 36.0 * (trial + 1), q);
        rand_axis(&st, t);
        snref_quat_to_mat(q, Rm);
        for (k = 0; k < 2; k++) {
            double jr[3], y[3];
            memcpy(pose[k].q, q, sizeof q);
            for (i = 0; i < 3; i++) jr[i] = m.jrest[3 * k + i] * m.unit;
            /* joint rotates about origin, then translate by t: x -> R x + t for every bone */
            (void)jr; (void)y;
            for (i = 0; i < 3; i++) pose[k].t[i] = t[i];
        }
        snref_reset(&s);
        snref_set_pose(&s, pose);
        for (i = 0; i < m.nF; i++) {
            double y[3];
            const double *x = m.rest + 3 * i;
            for (k = 0; k < 3; k++) y[k] = Rm[3 * k] * x[0] + Rm[3 * k + 1] * x[1] + Rm[3 * k + 2] * x[2] + t[k] / m.unit;
            memcpy(s.p + 3 * i, y, sizeof y);
        }
        snref_residual(&s, f);
        for (i = 0; i < 3 * m.nF; i++) { if (fabs(f[i]) > fmax) fmax = fabs(f[i]); }
        for (i = 0; i < m.nF; i++) fscale += m.sdiag[9 * i];
        T_NEAR(fmax / (fscale / m.nF), 0, 1e-12, "warped force vanishes for a rigid motion (seed 003 eq. 7), round-off");
        /* the static solve at that pose returns the rigid shape */
        snref_static(&s, 2000);
        fmax = 0;
        for (i = 0; i < m.nF; i++) {
            const double *x = m.rest + 3 * i;
            for (k = 0; k < 3; k++) {
                double y = Rm[3 * k] * x[0] + Rm[3 * k + 1] * x[1] + Rm[3 * k + 2] * x[2] + t[k] / m.unit;
                if (fabs(s.p[3 * i + k] - y) > fmax) fmax = fabs(s.p[3 * i + k] - y);
            }
        }
        T_NEAR(fmax, 0, 1e-10, "static shape at a rigid pose without gravity is the rigid rest shape");
        free(f);
    }
    /* bent pose, gravity on: dense LU and BiCGSTAB agree; the exact dynamic step settles on it */
    {
        snref_xform pose[2];
        double ax[3] = { 0, 0, 1 }, *p1 = malloc(3 * m.nV * sizeof *p1), d = 0, dmax = 0, r1, r2;
        memset(pose, 0, sizeof pose);
        pose[0].q[3] = 1;
        snref_quat_axis_angle(ax, 60, pose[1].q);
        /* tip joint rotated about its rest position */
        {
            double Rm[9], jr[3];
            snref_quat_to_mat(pose[1].q, Rm);
            for (i = 0; i < 3; i++) jr[i] = m.jrest[3 + i] * m.unit;
            for (i = 0; i < 3; i++) pose[1].t[i] = jr[i] - (Rm[3 * i] * jr[0] + Rm[3 * i + 1] * jr[1] + Rm[3 * i + 2] * jr[2]);
        }
        s.gscale = 1;
        snref_reset(&s);
        snref_set_pose(&s, pose);
        r1 = snref_static(&s, 100000);
        memcpy(p1, s.p, 3 * m.nV * sizeof *p1);
        snref_reset(&s);
        snref_set_pose(&s, pose);
        r2 = snref_static(&s, 0);
        for (i = 0; i < 3 * m.nF; i++) {
            if (fabs(p1[i] - s.p[i]) > d) d = fabs(p1[i] - s.p[i]);
            if (fabs(p1[i] - m.rest[i]) > dmax) dmax = fabs(p1[i] - m.rest[i]);
        }
        T_NEAR(r1, 0, 1e-10, "dense LU residual");
        T_NEAR(r2, 0, 1e-9, "BiCGSTAB residual");
        T_NEAR(d / dmax, 0, 1e-8, "dense and iterative static solutions agree");
        /* damped exact stepping converges to the same equilibrium: the fixed point of the step */
        {
            snref_state s2;
            snsyn_box bd = beam_box();
            unsigned char *bb;
            size_t n2;
            snref_model md;
            bd.two_joints = 1; bd.alpha = 20; bd.beta = 0.002;
            bb = snsyn_build(&bd, &n2);
            snref_load(&md, bb, n2, err, sizeof err);
            snref_init(&s2, &md);
            s2.exact = 1;
            snref_set_pose(&s2, pose);
            for (i = 0; i < 2000; i++) snref_step(&s2);
            d = 0;
            for (i = 0; i < 3 * m.nF; i++) if (fabs(p1[i] - s2.p[i]) > d) d = fabs(p1[i] - s2.p[i]);
            T_NEAR(d / dmax, 0, 1e-6, "settled dynamics = static equilibrium (NUMERICS.md: fixed point of the step)");
            T_FIGURE("reference: settled step vs static solve on a bent 2-joint bar: %.2e of max displacement", d / dmax);
            snref_release(&s2); snref_free(&md); free(bb);
        }
        free(p1);
    }
    snref_release(&s); snref_free(&m); snref_free(&m32); free(blob); free(blob32);
}

/* Backward Euler is dissipative for linear systems: with gravity off and no
 * Rayleigh damping, E = 1/2 v'Mv + 1/2 u'Su never increases (exact solve). */
static void test_energy(void) {
    snsyn_box b = beam_box();
    size_t sz;
    unsigned char *blob = snsyn_build(&b, &sz);
    snref_model m;
    snref_state s;
    char err[128];
    unsigned i, bad = 0;
    double Eprev, E0, ek, ee;
    snref_load(&m, blob, sz, err, sizeof err);
    snref_init(&s, &m);
    snref_static(&s, 2000);           /* deflected under gravity */
    s.gscale = 0; s.exact = 1;
    snref_energy(&s, &ek, &ee);
    E0 = Eprev = ek + ee;
    T_CHECK(ee > 0 && ek == 0, "start: elastic %g kinetic %g", ee, ek);
    for (i = 0; i < 300; i++) {
        snref_step(&s);
        snref_energy(&s, &ek, &ee);
        if (ek + ee > Eprev * (1 + 1e-12)) bad++;
        Eprev = ek + ee;
    }
    T_CHECK(bad == 0, "energy increased in %u of 300 backward-Euler steps", bad);
    T_CHECK(Eprev < E0 && Eprev > 0, "energy decays: %g -> %g", E0, Eprev);
    T_FIGURE("reference energy, free vibration 300 steps at h = 1/60, no damping: E/E0 = %.4f (numerical damping of backward Euler)", Eprev / E0);
    /* N-iteration CG converges to the exact step as N grows */
    {
        double errs[4];
        unsigned its[4] = { 2, 8, 32, 128 }, j;
        double *pe = malloc(3 * m.nV * sizeof *pe), mx = 0;
        snref_reset(&s); s.gscale = 1; s.exact = 1;
        for (i = 0; i < 60; i++) snref_step(&s);
        memcpy(pe, s.p, 3 * m.nV * sizeof *pe);
        for (i = 0; i < 3 * m.nF; i++) if (fabs(pe[i] - m.rest[i]) > mx) mx = fabs(pe[i] - m.rest[i]);
        for (j = 0; j < 4; j++) {
            double d = 0;
            snref_reset(&s); s.exact = 0; s.iters = its[j];
            for (i = 0; i < 60; i++) snref_step(&s);
            for (i = 0; i < 3 * m.nF; i++) if (fabs(pe[i] - s.p[i]) > d) d = fabs(pe[i] - s.p[i]);
            errs[j] = d / mx;
        }
        T_FIGURE("reference, 60 steps of a falling beam: error of N-iteration warm-started CG vs exact solve:"
                 " N=2 %.2e, N=8 %.2e, N=32 %.2e, N=128 %.2e", errs[0], errs[1], errs[2], errs[3]);
        T_CHECK(errs[3] < 1e-8 && errs[2] <= errs[0], "CG error decreases with N and vanishes (3nF = %u)", 3 * m.nF);
        free(pe);
    }
    snref_release(&s); snref_free(&m); free(blob);
}

int main(void) {
    test_element();
    test_hanging_bar();
    test_rigid_and_static();
    test_energy();
    return T_END();
}
