/* test_bake_retarget.c -- rig retargeting (seed 003 §4.4, eq. 15-16;
 * tools/sb_retarget.c).
 *
 * Character A is a box limb (shoulder -> elbow -> wrist, 9 x 2 x 2 mesh
 * units) with a bump rig on the upper arm; character B is A's mesh and
 * skeleton moved by a known affine map G x + g (scaled and sheared), with its
 * own description (its own, axis-aligned lattice). Checks:
 *  - analytic gradient of C = w_skel C_skel + w_surf C_surf + C_distort
 *    against central differences (relative error <= 1e-5), with vertex
 *    correspondence and with closest points;
 *  - the optimized map's Jacobians J_i (eq. 16) equal G within 1e-6
 *    (relative, Frobenius): an affine copy is matched at zero cost and every
 *    J_i of an affine map is exact;
 *  - the transferred rig (Q_A -> q_A -> J q_A -> Q_B, then B's static
 *    equilibrium under Q_B) moves B's surface as G moves A's rigged
 *    displacement: error at every surface vertex <= 1% of the largest
 *    displacement (measured 0.26%, rms 0.02%); a second rig under the arm
 *    within 1% at every vertex (0.15%); A onto itself
 *    J_i = I and the rig back within 1% (0.12%);
 *  - bad inputs are refused with a message and nothing is written;
 *  - the rig file is the same bytes when written twice.
 * Files go to a temporary directory under /tmp. */
#include "sb.h"
#include "sb_retarget.h"
#include "sn_test.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static const double G[9] = { 1.25, 0.18, -0.07, 0.05, 0.85, 0.2, -0.1, 0.12, 1.1 };
static const double g0[3] = { 3.0, -1.5, 0.75 };

static char dir[256];

static void affine(const double *p, double *o)
{
    int a;
    for (a = 0; a < 3; a++) o[a] = G[3 * a] * p[0] + G[3 * a + 1] * p[1] + G[3 * a + 2] * p[2] + g0[a];
}

/* a box [x0,x1]x[y0,y1]x[z0,z1] split n per unit, counter-clockwise from outside, moved by affine() if mv */
/* Largest |J_i - G| / |G| over A's lattice vertices: how far the map's
 * Jacobians are from the affine map the test built B with. */
static double jacobian_error(const sb_retarget *rt)
{
    double worst = 0, gn = 0;
    int i, k;
    for (k = 0; k < 9; k++) gn += G[k] * G[k];
    gn = sqrt(gn);
    for (i = 0; i < rt->nv; i++) {
        double e = 0;
        for (k = 0; k < 9; k++) e += (rt->J[9 * i + k] - G[k]) * (rt->J[9 * i + k] - G[k]);
        worst = fmax(worst, sqrt(e) / gn);
    }
    return worst;
}

static void write_box(const char *path, int mv)
{
    const double lo[3] = { -0.5, -1, -1 }, hi[3] = { 8.5, 1, 1 };
    const int n[3] = { 18, 4, 4 };
    FILE *f = fopen(path, "w");
    int *id, i, j, k, nv = 0, face;
    size_t sz = (size_t)(n[0] + 1) * (n[1] + 1) * (n[2] + 1);
    id = calloc(sz, sizeof *id);
    /* vertices on the surface */
    for (k = 0; k <= n[2]; k++)
        for (j = 0; j <= n[1]; j++)
            for (i = 0; i <= n[0]; i++) {
                double p[3], q[3];
                if (i && j && k && i < n[0] && j < n[1] && k < n[2]) continue;
                p[0] = lo[0] + (hi[0] - lo[0]) * i / n[0]; p[1] = lo[1] + (hi[1] - lo[1]) * j / n[1]; p[2] = lo[2] + (hi[2] - lo[2]) * k / n[2];
                if (mv) affine(p, q); else memcpy(q, p, sizeof q);
                fprintf(f, "v %.17g %.17g %.17g\n", q[0], q[1], q[2]);
                id[i + (n[0] + 1) * (j + (n[1] + 1) * k)] = ++nv;
            }
#define V(i, j, k) id[(i) + (n[0] + 1) * ((j) + (n[1] + 1) * (k))]
    for (face = 0; face < 6; face++) {
        int ax = face / 2, hiS = face % 2, u = (ax + 1) % 3, v = (ax + 2) % 3, a, b;
        for (a = 0; a < n[u]; a++)
            for (b = 0; b < n[v]; b++) {
                int c[4][3], q;
                for (q = 0; q < 4; q++) {
                    c[q][ax] = hiS ? n[ax] : 0;
                    c[q][u] = a + (q == 1 || q == 2);
                    c[q][v] = b + (q >= 2);
                }
                /* (u, v, ax) right-handed: u x v = ax; outward +ax on the high side */
                if (hiS) fprintf(f, "f %d %d %d %d\n", V(c[0][0], c[0][1], c[0][2]), V(c[1][0], c[1][1], c[1][2]), V(c[2][0], c[2][1], c[2][2]),
                                 V(c[3][0], c[3][1], c[3][2]));
                else fprintf(f, "f %d %d %d %d\n", V(c[0][0], c[0][1], c[0][2]), V(c[3][0], c[3][1], c[3][2]), V(c[2][0], c[2][1], c[2][2]),
                             V(c[1][0], c[1][1], c[1][2]));
            }
    }
#undef V
    fclose(f);
    free(id);
}

static void write_desc(const char *path, const char *mesh, int mv, int with_wrist, const char *extra)
{
    FILE *f = fopen(path, "w");
    const char *nm[3] = { "shoulder", "elbow", "wrist" }, *par[3] = { "-", "shoulder", "elbow" };
    int j;
    fprintf(f, "mesh %s\nunit 0.05\ncell %s\nbone_radius 0.6\n", mesh, mv ? "0.45" : "0.5");
    for (j = 0; j < (with_wrist ? 3 : 2); j++) {
        double p[3] = { 4.0 * j, 0, 0 }, q[3];
        if (mv) affine(p, q); else memcpy(q, p, sizeof q);
        fprintf(f, "joint %s %s %.17g %.17g %.17g\n", nm[j], par[j], q[0], q[1], q[2]);
    }
    fprintf(f, "material flesh 3e4 0.3 1000\ngravity 0 0 0\n%s", extra ? extra : "");
    fclose(f);
}

static char *path_in(const char *name)
{
    static char buf[8][512];
    static int k;
    k = (k + 1) % 8;
    snprintf(buf[k], sizeof buf[k], "%s/%s", dir, name);
    return buf[k];
}

/* central-difference check of the gradient at x on ncheck components */
static double grad_check(const sb_retarget *rt, const double *x0, int ncheck, unsigned *seed)
{
    int n = 3 * rt->nv, k;
    double *x = malloc(sizeof(double) * (size_t)n), *g = malloc(sizeof(double) * (size_t)n), worst = 0, gn = 0;
    memcpy(x, x0, sizeof(double) * (size_t)n);
    sb_rt_cost(rt, x, g, NULL);
    for (k = 0; k < n; k++) gn = fmax(gn, fabs(g[k]));
    for (k = 0; k < ncheck; k++) {
        int i;
        double hstep = 1e-4, cp, cm, fd, err;
        *seed = *seed * 1103515245u + 12345u;
        i = (int)((*seed >> 8) % (unsigned)n);
        x[i] = x0[i] + hstep; cp = sb_rt_cost(rt, x, NULL, NULL);
        x[i] = x0[i] - hstep; cm = sb_rt_cost(rt, x, NULL, NULL);
        x[i] = x0[i];
        fd = (cp - cm) / (2 * hstep);
        /* relative to the component, floored at 1e-3 of the largest component (a near-zero component) */
        err = fabs(fd - g[i]) / fmax(fabs(g[i]), 1e-3 * gn);
        worst = fmax(worst, err);
    }
    free(x); free(g);
    return worst;
}

/* rig `name` of A through rt onto B: surface error against G times A's
 * displacement (max, rms) and the largest mapped displacement */
static void transfer_error(const sb_retarget *rt, const sb_model *A, const sb_model *B, const char *name, double *emax, double *erms, double *dmax)
{
    double *QA = calloc(3 * (size_t)A->nf, sizeof(double)), *QB = calloc(3 * (size_t)B->nf, sizeof(double));
    double *qA = calloc(3 * (size_t)A->nv, sizeof(double)), *qB = calloc(3 * (size_t)B->nv, sizeof(double));
    double *a0 = malloc(sizeof(double) * 3 * (size_t)A->ns), *a1 = malloc(sizeof(double) * 3 * (size_t)A->ns);
    double *b0 = malloc(sizeof(double) * 3 * (size_t)B->ns), *b1 = malloc(sizeof(double) * 3 * (size_t)B->ns), e2 = 0;
    int k, a;
    *emax = *dmax = 0;
    T_CHECK(sb_rt_rig_force(A, name, QA, NULL) == 0 && sb_rt_transfer(rt, QA, QB, qA, NULL, NULL) == 0, "transfer %s: %s", name, sb_error());
    sb_rt_static(B, QB, qB);
    sb_rt_surface(A, NULL, a0); sb_rt_surface(A, qA, a1);
    sb_rt_surface(B, NULL, b0); sb_rt_surface(B, qB, b1);
    for (k = 0; k < A->ns; k++) {
        double dA[3], dG[3], z[3] = { 0, 0, 0 }, gz[3], e = 0, d = 0;
        for (a = 0; a < 3; a++) dA[a] = a1[3 * k + a] - a0[3 * k + a];
        affine(dA, dG); affine(z, gz);
        for (a = 0; a < 3; a++) {
            double r = (b1[3 * k + a] - b0[3 * k + a]) - (dG[a] - gz[a]);
            e += r * r; d += (dG[a] - gz[a]) * (dG[a] - gz[a]);
        }
        *emax = fmax(*emax, sqrt(e)); *dmax = fmax(*dmax, sqrt(d)); e2 += e;
    }
    *erms = sqrt(e2 / A->ns);
    free(QA); free(QB); free(qA); free(qB); free(a0); free(a1); free(b0); free(b1);
}

int main(void)
{
    sb_rt_char ca, cb, cm;
    sb_rt_opts opt;
    sb_retarget rt;
    unsigned seed = (unsigned)T_SEED();
    int i, k, a, ctl = -1;
    char cmd[600];
    const char *rig = "control c\nrig bump c bump 0.6   5.0 0.9 0.2   0.9   0 1 0.3\n"
                      "rig under c bump 0.8   2.5 -0.6 -0.5   1.2   0.2 -1 -0.4\n";

    snprintf(dir, sizeof dir, "/tmp/sn_test_retarget_%ld", (long)getpid());
    snprintf(cmd, sizeof cmd, "mkdir -p %s", dir);
    if (system(cmd)) { printf("cannot create %s\n", dir); return 1; }
    write_box(path_in("a.obj"), 0);
    write_box(path_in("b.obj"), 1);
    write_desc(path_in("a.sinew"), "a.obj", 0, 1, rig);
    write_desc(path_in("b.sinew"), "b.obj", 1, 1, NULL);
    write_desc(path_in("m.sinew"), "b.obj", 1, 0, NULL);   /* B without the wrist */

    T_CHECK(sb_rt_char_load(path_in("a.sinew"), &ca) == 0, "load A: %s", sb_error());
    T_CHECK(sb_rt_char_load(path_in("b.sinew"), &cb) == 0, "load B: %s", sb_error());
    T_CHECK(sb_rt_char_load(path_in("m.sinew"), &cm) == 0, "load B without wrist: %s", sb_error());
    if (!ca.loaded || !cb.loaded || !cm.loaded) return T_END();
    for (i = 0; i < cb.o.nv; i++) if ((i < cb.o.nf) != (cb.o.vseg[i] == -1)) break;
    T_CHECK(i == cb.o.nv, "free vertices come first in the model (vertex %d)", i);
    T_FIGURE("A: lattice %d vertices (%d free), %d cells; B: %d vertices (%d free), %d cells", ca.o.nv, ca.o.nf, ca.o.nc, cb.o.nv, cb.o.nf,
             cb.o.nc);

    sb_rt_defaults(&opt);
    /* ---- gradients ---- */
    {
        int mode;
        for (mode = 0; mode < 2; mode++) {
            double *x, worst;
            opt.corr = mode ? SB_RT_CORR_CLOSEST : SB_RT_CORR_VERTEX;
            T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cb.o, &cb.m, &opt) == 0, "init: %s", sb_error());
            x = malloc(sizeof(double) * 3 * (size_t)rt.nv);
            for (i = 0; i < 3 * rt.nv; i++) {
                seed = seed * 1103515245u + 12345u;
                x[i] = rt.h[i] + 0.2 * (((seed >> 8) & 0xffff) / 65535.0 - 0.5);
            }
            worst = grad_check(&rt, x, 300, &seed);
            T_FIGURE("gradient check (%s): worst relative error %.2e over 300 components", mode ? "closest points" : "vertex correspondence", worst);
            T_CHECK(worst <= 1e-5, "analytic gradient vs central differences: relative error %.3g > 1e-5", worst);
            free(x);
            sb_rt_free(&rt);
        }
    }

    /* ---- affine copy: J_i = G ---- */
    opt.corr = SB_RT_CORR_AUTO;
    opt.cg_tol = 1e-13;
    T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cb.o, &cb.m, &opt) == 0, "init: %s", sb_error());
    T_CHECK(rt.corr == SB_RT_CORR_VERTEX, "same vertex count: vertex correspondence");
    T_CHECK(sb_rt_solve(&rt) == 0, "solve: %s", sb_error());
    T_CHECK(sb_rt_jacobians(&rt) == 0, "jacobians: %s", sb_error());
    {
        double worst = jacobian_error(&rt), hx = 0;
        for (i = 0; i < rt.nv; i++) {
            double q[3];
            affine(ca.o.x + 3 * i, q);
            for (a = 0; a < 3; a++) hx = fmax(hx, fabs(rt.h[3 * i + a] - q[a]));
        }
        T_FIGURE("affine copy: cost %.3e (skel %.2e surf %.2e distort %.2e), %d CG iterations, %.3f s; max |h(x_i) - (G x_i + g)| %.2e mesh units",
                 rt.cost, rt.c_skel, rt.c_surf, rt.c_dist, rt.cg_iters, rt.secs, hx);
        T_FIGURE("affine copy: largest |J_i - G| / |G| = %.3e over %d lattice vertices", worst, rt.nv);
        T_CHECK(worst <= 1e-6, "J_i = G within 1e-6 (got %.3g)", worst);
    }

    /* ---- rig transfer ---- */
    {
        double *QA = calloc(3 * (size_t)ca.o.nf, sizeof(double)), *QB = calloc(3 * (size_t)cb.o.nf, sizeof(double));
        double *qA = calloc(3 * (size_t)ca.o.nv, sizeof(double)), *qB = calloc(3 * (size_t)cb.o.nv, sizeof(double));
        double *sA0 = malloc(sizeof(double) * 3 * (size_t)ca.o.ns), *sA1 = malloc(sizeof(double) * 3 * (size_t)ca.o.ns);
        double *sB0 = malloc(sizeof(double) * 3 * (size_t)cb.o.ns), *sB1 = malloc(sizeof(double) * 3 * (size_t)cb.o.ns);
        double emax = 0, dmax = 0, e2 = 0, res;
        sb_rt_transfer_stats st;
        T_CHECK(sb_rt_rig_force(&ca.o, "bump", QA, &ctl) == 0, "rig force: %s", sb_error());
        T_CHECK(sb_rt_transfer(&rt, QA, QB, qA, NULL, &st) == 0, "transfer: %s", sb_error());
        T_FIGURE("transfer: %d of B's free vertices with a sample of the mapped field in a cell, %d without one (smoothed); static residual on A %.1e",
                 st.inside, st.outside, st.static_res);
        /* B's static equilibrium under Q_B vs G times A's displacement */
        res = sb_rt_static(&cb.o, QB, qB);
        T_CHECK(res >= 0 && res < 1e-9, "static solve on B: relative residual %.3g", res);
        sb_rt_surface(&ca.o, NULL, sA0); sb_rt_surface(&ca.o, qA, sA1);
        sb_rt_surface(&cb.o, NULL, sB0); sb_rt_surface(&cb.o, qB, sB1);
        for (k = 0; k < ca.o.ns; k++) {
            double dA[3], dG[3], e[3], z[3] = { 0, 0, 0 }, gz[3];
            for (a = 0; a < 3; a++) dA[a] = sA1[3 * k + a] - sA0[3 * k + a];
            affine(dA, dG); affine(z, gz);
            for (a = 0; a < 3; a++) { dG[a] -= gz[a]; e[a] = (sB1[3 * k + a] - sB0[3 * k + a]) - dG[a]; }
            dmax = fmax(dmax, sqrt(dG[0] * dG[0] + dG[1] * dG[1] + dG[2] * dG[2]));
            emax = fmax(emax, sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]));
            e2 += e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
        }
        T_FIGURE("transfer: largest mapped displacement %.4g mesh units; transferred - mapped: max %.3e (%.3f%%), rms %.3e (%.3f%%)", dmax, emax,
                 100 * emax / dmax, sqrt(e2 / ca.o.ns), 100 * sqrt(e2 / ca.o.ns) / dmax);
        T_CHECK(dmax > 0.05, "the rig moves the surface (%.3g mesh units)", dmax);
        /* the 1%, at every surface vertex (measured 0.26%; rms 0.02%) */
        T_CHECK(emax <= 0.01 * dmax, "transferred shape = mapped shape within 1%% at every vertex (max error %.3g%%)", 100 * emax / dmax);
        T_CHECK(sqrt(e2 / ca.o.ns) <= 0.01 * dmax, "transferred shape = mapped shape within 1%% rms (%.3g%%)", 100 * sqrt(e2 / ca.o.ns) / dmax);
        {   /* a second rig, under the arm across the bone's side: max 0.15%, rms 0.02% */
            double em2, er2, dm2;
            transfer_error(&rt, &ca.o, &cb.o, "under", &em2, &er2, &dm2);
            T_FIGURE("transfer of rig 'under': largest mapped displacement %.4g; max error %.3e (%.3f%%), rms %.3e (%.3f%%)", dm2, em2, 100 * em2 / dm2,
                     er2, 100 * er2 / dm2);
            T_CHECK(em2 <= 0.01 * dm2, "rig 'under': within 1%% at every vertex (%.3g%%)", 100 * em2 / dm2);
        }

        /* rig file: deterministic, refused when zero */
        {
            FILE *f1, *f2;
            int same = 1, c1, c2;
            T_CHECK(sb_rt_write_rig(path_in("r1.rig"), &cb.o, &cb.m, QB, "test") == 0, "write rig: %s", sb_error());
            T_CHECK(sb_rt_write_rig(path_in("r2.rig"), &cb.o, &cb.m, QB, "test") == 0, "write rig: %s", sb_error());
            f1 = fopen(path_in("r1.rig"), "rb"); f2 = fopen(path_in("r2.rig"), "rb");
            if (f1 && f2) {
                do { c1 = fgetc(f1); c2 = fgetc(f2); if (c1 != c2) same = 0; } while (c1 != EOF && c2 != EOF);
            } else same = 0;
            if (f1) fclose(f1);
            if (f2) fclose(f2);
            T_CHECK(same, "the rig file is the same bytes twice");
            {   /* B's description including the file (rig_file): the baked rig gives the same shape */
                sb_rt_char cr;
                double *Qr = calloc(3 * (size_t)cb.o.nf, sizeof(double)), *qr = calloc(3 * (size_t)cb.o.nv, sizeof(double));
                double *sr = malloc(sizeof(double) * 3 * (size_t)cb.o.ns), e = 0;
                write_desc(path_in("br.sinew"), "b.obj", 1, 1, "control c\nrig_file bump r1.rig c\n");
                T_CHECK(sb_rt_char_load(path_in("br.sinew"), &cr) == 0, "B with rig_file: %s", sb_error());
                if (cr.loaded) {
                    T_CHECK(cr.o.nrig == 1 && cr.o.nf == cb.o.nf, "one rig baked, same lattice");
                    if (cr.o.nrig == 1 && cr.o.nf == cb.o.nf) {
                        for (k = 0; k < cr.o.rig[0].n; k++)
                            for (a = 0; a < 3; a++) Qr[3 * cr.o.rig[0].vert[k] + a] = cr.o.rig[0].Q[3 * k + a];
                        sb_rt_static(&cr.o, Qr, qr);
                        sb_rt_surface(&cr.o, qr, sr);
                        for (k = 0; k < cb.o.ns; k++)
                            for (a = 0; a < 3; a++) e = fmax(e, fabs(sr[3 * k + a] - sB1[3 * k + a]));
                        T_FIGURE("rig_file round trip: baked rig moves B's surface within %.2e of the transferred shape (%.2e of its largest displacement)", e, e / dmax);
                        T_CHECK(e <= 1e-6 * dmax, "rig_file round trip within 1e-6 of the displacement (%.3g)", e / dmax);
                    }
                    sb_rt_char_free(&cr);
                }
                free(Qr); free(qr); free(sr);
            }
            memset(QB, 0, sizeof(double) * 3 * (size_t)cb.o.nf);
            T_CHECK(sb_rt_write_rig(path_in("r0.rig"), &cb.o, &cb.m, QB, NULL) != 0, "a zero rig is refused");
            T_CHECK(access(path_in("r0.rig"), F_OK) != 0, "nothing written for a zero rig");
            printf("  message: %s\n", sb_error());
        }
        /* non-finite source force */
        QA[0] = NAN;
        T_CHECK(sb_rt_transfer(&rt, QA, QB, NULL, NULL, NULL) != 0 && strstr(sb_error(), "not finite"), "non-finite force refused: %s", sb_error());
        printf("  message: %s\n", sb_error());
        free(QA); free(QB); free(qA); free(qB); free(sA0); free(sA1); free(sB0); free(sB1);
    }
    sb_rt_free(&rt);

    /* ---- A onto itself: J_i = I, the rig comes back ---- */
    {
        double *QA = calloc(3 * (size_t)ca.o.nf, sizeof(double)), *QB = calloc(3 * (size_t)ca.o.nf, sizeof(double));
        double *qA = calloc(3 * (size_t)ca.o.nv, sizeof(double)), *qB = calloc(3 * (size_t)ca.o.nv, sizeof(double));
        double *s0 = malloc(sizeof(double) * 3 * (size_t)ca.o.ns), *s1 = malloc(sizeof(double) * 3 * (size_t)ca.o.ns);
        double *s2 = malloc(sizeof(double) * 3 * (size_t)ca.o.ns), jerr = 0, e = 0, dm = 0;
        T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &ca.o, &ca.m, &opt) == 0, "init A -> A: %s", sb_error());
        T_CHECK(sb_rt_solve(&rt) == 0 && sb_rt_jacobians(&rt) == 0, "solve A -> A: %s", sb_error());
        for (i = 0; i < rt.nv; i++)
            for (k = 0; k < 9; k++) jerr = fmax(jerr, fabs(rt.J[9 * i + k] - (k % 4 == 0)));
        T_CHECK(jerr <= 1e-9, "A -> A: J_i = I within 1e-9 (%.3g)", jerr);
        sb_rt_rig_force(&ca.o, "bump", QA, NULL);
        T_CHECK(sb_rt_transfer(&rt, QA, QB, qA, NULL, NULL) == 0, "transfer A -> A: %s", sb_error());
        sb_rt_static(&ca.o, QB, qB);
        sb_rt_surface(&ca.o, NULL, s0); sb_rt_surface(&ca.o, qA, s1); sb_rt_surface(&ca.o, qB, s2);
        for (k = 0; k < 3 * ca.o.ns; k++) { e = fmax(e, fabs(s2[k] - s1[k])); dm = fmax(dm, fabs(s1[k] - s0[k])); }
        T_FIGURE("A onto itself: largest |J_i - I| %.2e; the rig's surface displacement comes back within %.2e (%.3f%% of its largest component)", jerr, e,
                 100 * e / dm);
        T_CHECK(e <= 0.01 * dm, "A -> A: the rig comes back within 1%% (%.3g%%)", 100 * e / dm);
        sb_rt_free(&rt);
        free(QA); free(QB); free(qA); free(qB); free(s0); free(s1); free(s2);
    }

    /* ---- the same with L-BFGS-B (tools/sb_lbfgsb.c) as the inner optimizer ---- */
    {
        double worst;
        opt.optimizer = SB_RT_OPT_LBFGSB;
        opt.cg_tol = 1e-12;
        opt.cg_max = 50000;
        T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cb.o, &cb.m, &opt) == 0, "init: %s", sb_error());
        T_CHECK(sb_rt_solve(&rt) == 0, "solve (L-BFGS-B): %s", sb_error());
        T_CHECK(sb_rt_jacobians(&rt) == 0, "jacobians: %s", sb_error());
        worst = jacobian_error(&rt);
        T_FIGURE("affine copy by L-BFGS-B: %d iterations, %.2f s, cost %.3e; largest |J_i - G| / |G| = %.3e", rt.cg_iters, rt.secs, rt.cost, worst);
        T_CHECK(worst <= 1e-6, "L-BFGS-B: J_i = G within 1e-6 (got %.3g)", worst);
        sb_rt_free(&rt);
        sb_rt_defaults(&opt);
    }

    /* ---- closest points on the same pair (no correspondence used) ---- */
    {
        double worst;
        opt.corr = SB_RT_CORR_CLOSEST;
        opt.cg_tol = 1e-10;
        T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cb.o, &cb.m, &opt) == 0, "init: %s", sb_error());
        T_CHECK(sb_rt_solve(&rt) == 0, "solve: %s", sb_error());
        T_CHECK(sb_rt_jacobians(&rt) == 0, "jacobians: %s", sb_error());
        worst = jacobian_error(&rt);
        T_FIGURE("closest points: %d rounds, %d CG iterations, %.2f s; surface rms %.2e max %.2e, skeleton rms %.2e (mesh units); largest |J_i - G|/|G| %.2e",
                 rt.rounds, rt.cg_iters, rt.secs, rt.surf_rms, rt.surf_max, rt.skel_rms, worst);
        T_CHECK(rt.surf_max < 1e-2 * rt.L, "closest points: the affine copy is matched within 1%% of its size (surface max %.3g)", rt.surf_max);
        sb_rt_free(&rt);
    }

    /* ---- bad inputs ---- */
    opt.corr = SB_RT_CORR_AUTO;
    T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cm.o, &cm.m, &opt) != 0 && strstr(sb_error(), "wrist"), "a joint missing in B is named: %s", sb_error());
    printf("  message: %s\n", sb_error());
    {
        double *Q = calloc(3 * (size_t)ca.o.nf, sizeof(double));
        T_CHECK(sb_rt_rig_force(&ca.o, "nope", Q, NULL) != 0 && strstr(sb_error(), "nope"), "an unknown rig is named: %s", sb_error());
        free(Q);
    }
    printf("  message: %s\n", sb_error());
    opt.skip = "wrist";
    T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cm.o, &cm.m, &opt) == 0, "the missing joint skipped: %s", sb_error());
    if (rt.h) { T_CHECK(rt.njm == 2, "two joints matched (%d)", rt.njm); sb_rt_free(&rt); }
    opt.skip = NULL;
    opt.joint_map = "wrist=elbow,elbow=shoulder";   /* a map onto other names (here a wrong one, but legal) */
    T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cb.o, &cb.m, &opt) == 0, "joint map: %s", sb_error());
    if (rt.h) {
        T_CHECK(rt.njm == 3 && !strcmp(cb.o.joints[rt.jB[2]].name, "elbow") && !strcmp(cb.o.joints[rt.jB[1]].name, "shoulder"),
                "wrist -> elbow, elbow -> shoulder");
        sb_rt_free(&rt);
    }
    opt.joint_map = "wrist=hand";
    T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cb.o, &cb.m, &opt) != 0 && strstr(sb_error(), "hand"), "a map to a joint B lacks is named: %s", sb_error());
    printf("  message: %s\n", sb_error());
    opt.joint_map = NULL;
    opt.w_skel = NAN;
    T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cb.o, &cb.m, &opt) != 0, "a non-finite weight is refused");
    printf("  message: %s\n", sb_error());
    sb_rt_defaults(&opt);
    {   /* empty overlap: B moved far away from where the map puts A (h forced off B) */
        double *QA = calloc(3 * (size_t)ca.o.nf, sizeof(double)), *QB = calloc(3 * (size_t)cb.o.nf, sizeof(double));
        T_CHECK(sb_rt_init(&rt, &ca.o, &ca.m, &cb.o, &cb.m, &opt) == 0, "init: %s", sb_error());
        T_CHECK(sb_rt_jacobians(&rt) == 0, "jacobians");
        for (i = 0; i < rt.nv; i++) rt.h[3 * i] += 1000;   /* the mapped lattice nowhere near B */
        sb_rt_rig_force(&ca.o, "bump", QA, NULL);
        T_CHECK(sb_rt_transfer(&rt, QA, QB, NULL, NULL, NULL) != 0 && strstr(sb_error(), "overlap"), "empty overlap refused: %s", sb_error());
        printf("  message: %s\n", sb_error());
        sb_rt_free(&rt);
        free(QA); free(QB);
    }

    sb_rt_char_free(&ca); sb_rt_char_free(&cb); sb_rt_char_free(&cm);
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd)) printf("  (could not remove %s)\n", dir);
    return T_END();
}
