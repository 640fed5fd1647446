/* test_rigfit.c -- rig fitting (tools/sb_fit.c, issue 11 items 2-3) and rig
 * files (tools/sb_rigfile.c) on the limb and the cow:
 *   - the newton -> right-hand-side scale against the baked rig forces;
 *   - point-drag (§4.2): adjoint gradient vs central differences (relative
 *     error <= 1e-5), recovery of known strengths from dragged points;
 *   - pose fit (§4.3): a known pose recovered within 0.5 degrees per joint
 *     from 10 feature points;
 *   - surface rig (§4.3): a target made by a known rig recovered within 1% of
 *     its displacement, written as a rig file, baked through `rig_file` and
 *     solved again (the same shape), and a rig file refused by another
 *     character. */
#include "sb_fit.h"
#include "sb_static.h"
#include "sn_test.h"
#include <string.h>

#define LIMB "tools/examples/limb/limb.sinew"
#define COW "tools/examples/cow/cow.sinew"

static double qangle(const double a[4], const double b[4])
{   /* angle (degrees) of the rotation conj(a) b, both unit */
    double w = a[3] * b[3] + a[0] * b[0] + a[1] * b[1] + a[2] * b[2], v[3];
    v[0] = a[3] * b[0] - b[3] * a[0] - (a[1] * b[2] - a[2] * b[1]);
    v[1] = a[3] * b[1] - b[3] * a[1] - (a[2] * b[0] - a[0] * b[2]);
    v[2] = a[3] * b[2] - b[3] * a[2] - (a[0] * b[1] - a[1] * b[0]);
    return 2 * atan2(sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), fabs(w)) * 180 / 3.14159265358979323846;
}

static void disp_stats(const double *a, const double *target, const double *base, unsigned n, double *rms_frac, double *max_frac)
{
    double r2 = 0, d2 = 0, rmax = 0, dmax = 0;
    unsigned i, k;
    for (i = 0; i < n; i++) {
        double r = 0, d = 0;
        for (k = 0; k < 3; k++) { r += (a[3 * i + k] - target[3 * i + k]) * (a[3 * i + k] - target[3 * i + k]); d += (target[3 * i + k] - base[3 * i + k]) * (target[3 * i + k] - base[3 * i + k]); }
        r2 += r; d2 += d; rmax = fmax(rmax, sqrt(r)); dmax = fmax(dmax, sqrt(d));
    }
    *rms_frac = sqrt(r2 / d2);
    *max_frac = rmax / dmax;
}

/* scratch files in $BUILD/tests (default build/tests), as the other tool tests */
static const char *tpath(const char *name)
{
    static char buf[4][1100];
    static int k;
    const char *b = getenv("BUILD") ? getenv("BUILD") : "build";
    k = (k + 1) % 4;
    snprintf(buf[k], sizeof buf[k], "%s/tests/%s", b, name);
    return buf[k];
}

static int write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fputs(text, f);
    return fclose(f);
}

int main(void)
{
    sb_fit F;
    sb_opt_opts oo;
    sb_opt_result rr;
    char what[256];
    (void)t_seed;
    sb_opt_defaults(&oo);
    /* ---------------- limb: scale, point drag, pose, surface ---------------- */
    if (sb_fit_open(&F, LIMB, 1)) { T_CHECK(0, "open %s", LIMB); return T_END(); }
    {
        const snref_model *m = &F.m;
        snref_xform *pose = malloc(m->nJ * sizeof *pose);
        double *target = malloc(3 * (size_t)m->nS * sizeof *target), *base = malloc(3 * (size_t)m->nS * sizeof *base), *fit = malloc(3 * (size_t)m->nS * sizeof *fit);
        double *eta = malloc(3 * (size_t)F.o.nf * sizeof *eta), t0;
        unsigned e, i;
        double worst = 0;
        /* the scale: baked rig forces (rhs units, eta samples max 1) = newtons * nscale */
        for (e = 0; e < (unsigned)F.o.rig[0].n; e++)
            for (i = 0; i < 3; i++)
                worst = fmax(worst, fabs(m->rforce[3 * e + i] - F.o.rig[0].Q[3 * e + i] * F.nscale) / F.o.rig[0].qmax / F.nscale);
        T_CHECK(m->rvert[0] == (unsigned)F.o.rig[0].vert[0] && worst < 1e-12, "rig forces = newtons * h^2/(m0 U): worst %.3g of the peak", worst);
        T_CHECK(sb_static_pose(&F.s, "elbow:0,0,1,90", pose, NULL, what, sizeof what) == 0, "pose");

        /* point drag: adjoint gradient vs central differences; recovery of a known strength */
        {
            int rigs[1] = {0}, vert[4] = {139, 150, 200, 60}, k;
            double pts[12], g[1], gfd, h = 1e-4, etav[1] = {2.0}, lo[1] = {0}, hi[1] = {10}, want = 1.7, rel;
            T_CHECK(sb_fit_set_pose(&F, pose, want / F.o.rig[0].def.s) == 0, "solve");   /* the shape at strength 1.7 */
            for (k = 0; k < 4; k++) for (i = 0; i < 3; i++) pts[3 * k + i] = F.surf0[3 * vert[k] + i];
            T_CHECK(sb_fit_set_pose(&F, pose, 1.0) == 0, "solve");   /* the description's strength 2.5 */
            sb_fit_points_cost(&F, rigs, 1, vert, pts, 4, 1e-3, etav, g);
            {
                double ep[1] = {etav[0] + h}, em[1] = {etav[0] - h};
                gfd = (sb_fit_points_cost(&F, rigs, 1, vert, pts, 4, 1e-3, ep, NULL) - sb_fit_points_cost(&F, rigs, 1, vert, pts, 4, 1e-3, em, NULL)) / (2 * h);
            }
            rel = fabs(g[0] - gfd) / fabs(gfd);
            printf("  point drag (limb): adjoint dC/deta %.10g, central difference %.10g, relative error %.2e\n", g[0], gfd, rel);
            T_CHECK(rel <= 1e-5, "adjoint gradient vs finite differences: relative error %.3g (want <= 1e-5)", rel);
            oo.pgtol = 1e-12;
            t0 = sb_now();
            sb_fit_points(&F, rigs, 1, vert, pts, 4, 0, lo, hi, etav, &oo, &rr);
            printf("  point drag (limb, 4 points, biceps strength): %.6f (want %.6f), %d iterations, %d evaluations, %.3f s\n",
                   etav[0], want, rr.iterations, rr.evaluations, sb_now() - t0);
            T_NEAR(etav[0], want, 1e-6, "exact targets, lambda 0: the strength that made them");
            /* bounds: an upper bound below the answer is active */
            hi[0] = 1.5; etav[0] = 2.0;
            sb_fit_points(&F, rigs, 1, vert, pts, 4, 0, lo, hi, etav, &oo, &rr);
            T_NEAR(etav[0], 1.5, 0, "bound [0, 1.5] active: eta at its bound");
        }

        /* pose fit: 10 feature points of a known pose's skinned shape */
        {
            double local_true[12], local[12], r[3] = {0.1, 0.25, 0.3}, r2[3] = {0, 0, -0.8}, worstdeg = 0;
            int joints[2] = {0, 1}, feat[10], k;
            int jw = -1;
            for (k = 0; k < 12; k++) local_true[k] = (k % 4 == 3);
            sb_rotvec_quat(r, local_true + 0);        /* shoulder (root) */
            sb_rotvec_quat(r2, local_true + 4);       /* elbow, -45.8 degrees about z */
            {
                double root[3] = {0, 0, 0};
                sb_pose_from_local(m, local_true, root, pose);
            }
            sb_fit_skinned_surface(&F, pose, target);
            for (k = 0; k < 10; k++) feat[k] = (int)((k * 37 + 5) % m->nS);
            for (k = 0; k < 12; k++) local[k] = (k % 4 == 3);
            oo.pgtol = 1e-10;
            t0 = sb_now();
            {
                double tg[30];
                for (k = 0; k < 10; k++) for (i = 0; i < 3; i++) tg[3 * k + i] = target[3 * feat[k] + i];
                sb_fit_pose(&F, feat, 10, tg, joints, 2, local, &oo, &rr);
            }
            for (k = 0; k < 2; k++) { double a = qangle(local + 4 * k, local_true + 4 * k); if (a > worstdeg) { worstdeg = a; jw = k; } }
            printf("  pose fit (limb, 10 feature points, 2 joints): worst joint error %.2e degrees (joint %d), %d iterations, %.3f s\n",
                   worstdeg, jw, rr.iterations, sb_now() - t0);
            T_CHECK(worstdeg <= 0.5, "known pose recovered within 0.5 degrees per joint (worst %.3g)", worstdeg);
            /* the same on the static equilibrium (sag included): the target is the static shape at the pose */
            {
                double root[3] = {0, 0, 0}, tg[30];
                sb_pose_from_local(m, local_true, root, pose);
                T_CHECK(sb_fit_set_pose(&F, pose, 0.0) == 0, "static target");
                for (k = 0; k < 10; k++) for (i = 0; i < 3; i++) tg[3 * k + i] = F.surf0[3 * feat[k] + i];
                for (k = 0; k < 12; k++) local[k] = (k % 4 == 3);
                F.pose_static = 1; F.pose_rig_scale = 0;
                t0 = sb_now();
                sb_fit_pose(&F, feat, 10, tg, joints, 2, local, &oo, &rr);
                F.pose_static = 0;
                worstdeg = 0;
                for (k = 0; k < 2; k++) { double a = qangle(local + 4 * k, local_true + 4 * k); if (a > worstdeg) { worstdeg = a; jw = k; } }
                printf("  pose fit on the static shape (limb, 10 feature points, 2 joints): worst joint error %.2e degrees, %d iterations, %.3f s\n",
                       worstdeg, rr.iterations, sb_now() - t0);
                T_CHECK(worstdeg <= 0.5, "known pose recovered from the static shape within 0.5 degrees per joint (worst %.3g)", worstdeg);
            }
        }

        /* surface rig: the target is the biceps' shape at 90 degrees; fit with the rigs off */
        {
            double rmsf, maxf;
            T_CHECK(sb_static_pose(&F.s, "elbow:0,0,1,90", pose, NULL, what, sizeof what) == 0, "pose");
            T_CHECK(sb_fit_set_pose(&F, pose, 1.0) == 0, "rigs on");
            memcpy(target, F.surf0, 3 * (size_t)m->nS * sizeof *target);
            T_CHECK(sb_fit_set_pose(&F, pose, 0.0) == 0, "rigs off");
            memcpy(base, F.surf0, 3 * (size_t)m->nS * sizeof *base);
            oo.pgtol = 1e-9; oo.max_iter = 5000;
            t0 = sb_now();
            sb_fit_surface(&F, target, 1e-4, &oo, &rr, eta, fit);
            disp_stats(fit, target, base, m->nS, &rmsf, &maxf);
            printf("  surface rig (limb biceps target, omega 1e-4): residual rms %.3g%%, max %.3g%% of the target displacement; %d iterations, %.3f s\n",
                   100 * rmsf, 100 * maxf, rr.iterations, sb_now() - t0);
            T_CHECK(maxf <= 0.01, "target recovered within 1%% of its displacement (max %.3g%%)", 100 * maxf);
            /* through a rig file and a re-bake: the same shape */
            T_CHECK(sb_rigfile_write(tpath("test_rigfit_biceps.rig"), &F.o, &F.mesh, eta, "test_rigfit: limb biceps refit") == 0, "write rig file: %s", sb_error());
            {
                char desc[4096], *p;
                FILE *f = fopen(LIMB, "r");
                size_t n = f ? fread(desc, 1, sizeof desc - 600, f) : 0;
                sb_fit G;
                if (f) fclose(f);
                desc[n] = 0;
                p = strstr(desc, "rig biceps");
                T_CHECK(p != NULL, "limb description has the biceps");
                if (p) {
                    char *eol = strchr(p, '\n');
                    char tail[2048];
                    snprintf(tail, sizeof tail, "%s", eol ? eol : "");
                    sprintf(p, "rig_file biceps test_rigfit_biceps.rig elbow_bend tau 0 0 90 1%s", tail);
                }
                {   /* absolute mesh path */
                    char full[8192], cwd[1024];
                    char *q = strstr(desc, "\nmesh ") + 1;
                    if (!getenv("PWD")) snprintf(cwd, sizeof cwd, "."); else snprintf(cwd, sizeof cwd, "%s", getenv("PWD"));
                    *q = 0;
                    snprintf(full, sizeof full, "%smesh %s/tools/examples/limb/limb.obj%s", desc, cwd, strchr(q + 5, '\n'));
                    write_text(tpath("test_rigfit_limb.sinew"), full);
                }
                if (sb_fit_open(&G, tpath("test_rigfit_limb.sinew"), 1) == 0) {
                    T_CHECK(sb_static_pose(&G.s, "elbow:0,0,1,90", pose, NULL, what, sizeof what) == 0, "pose");
                    T_CHECK(sb_fit_set_pose(&G, pose, 1.0) == 0, "rig_file on");
                    disp_stats(G.surf0, target, base, m->nS, &rmsf, &maxf);
                    printf("  rig file re-baked (rig_file ... tau 0 0 90 1): residual rms %.3g%%, max %.3g%% of the target displacement\n", 100 * rmsf, 100 * maxf);
                    T_CHECK(maxf <= 0.01, "the re-baked rig file reproduces the target within 1%% (max %.3g%%)", 100 * maxf);
                    T_CHECK(G.o.rig[0].def.tpl == SB_TPL_FILE, "rig is a file rig");
                    sb_fit_close(&G);
                } else T_CHECK(0, "bake with rig_file: %s", sb_error());
            }
        }
        free(pose); free(target); free(base); free(fit); free(eta);
    }
    sb_fit_close(&F);

    /* ---------------- point drag with the template's geometry (limb biceps) ---------------- */
    {
        char desc[4096], full[8192], cwd[1024], *p, *q;
        FILE *f = fopen(LIMB, "r");
        size_t n = f ? fread(desc, 1, sizeof desc - 1, f) : 0;
        sb_fit G;
        if (f) fclose(f);
        desc[n] = 0;
        snprintf(cwd, sizeof cwd, "%s", getenv("PWD") ? getenv("PWD") : ".");
        q = strstr(desc, "\nmesh ") + 1;
        *q = 0;
        p = strchr(q + 5, '\n');
        snprintf(full, sizeof full, "%smesh %s/tools/examples/limb/limb.obj%s", desc, cwd, p);
        /* the target: the biceps moved 0.4 along the arm, thicker, weaker */
        p = strstr(full, "rig biceps elbow_bend muscle 2.5   2.0 0.3 0   5.5 0.3 0   1.5 0.2");
        T_CHECK(p != NULL, "the limb's biceps line");
        if (p) memcpy(p, "rig biceps elbow_bend muscle 2.0   2.4 0.3 0   5.9 0.3 0   1.8 0.2", 66);
        write_text(tpath("test_rigfit_limb_geo.sinew"), full);
        if (sb_fit_open(&G, tpath("test_rigfit_limb_geo.sinew"), 1) == 0 && sb_fit_open(&F, LIMB, 1) == 0) {
            const snref_model *m = &F.m;
            snref_xform *pose = malloc(m->nJ * sizeof *pose);
            int rigs[1] = {0}, vert[40], np = 0, k, c, npar = sb_fit_template_npar(&F, 0);
            double pts[120], par[8], par_true[8], g[8], lo[8], hi[8], worst = 0, t0;
            sb_static_pose(&G.s, "elbow:0,0,1,90", pose, NULL, what, sizeof what);
            sb_fit_set_pose(&G, pose, 1.0);
            sb_static_pose(&F.s, "elbow:0,0,1,90", pose, NULL, what, sizeof what);
            T_CHECK(sb_fit_set_pose(&F, pose, 1.0) == 0, "limb solve");
            for (k = 0; k < (int)m->nS && np < 40; k += 8) vert[np++] = k;
            for (k = 0; k < np; k++) for (c = 0; c < 3; c++) pts[3 * k + c] = G.surf0[3 * vert[k] + c];
            sb_fit_template_get(&G, 0, par_true);
            sb_fit_template_get(&F, 0, par);
            T_CHECK(npar == 8, "muscle: strength, two ends, radius (%d)", npar);
            for (k = 0; k < npar; k++) par[k] = 0.5 * (par[k] + par_true[k]);   /* half way: a gradient away from 0 */
            sb_fit_template_cost(&F, rigs, 1, vert, pts, np, 1e-3, par, g);
            for (k = 0; k < npar; k++) {
                double pp[8], pm[8], h = 1e-5 * (k ? 1.5 : 2.5), fd, rel;
                memcpy(pp, par, sizeof pp); memcpy(pm, par, sizeof pm);
                pp[k] += h; pm[k] -= h;
                fd = (sb_fit_template_cost(&F, rigs, 1, vert, pts, np, 1e-3, pp, NULL) - sb_fit_template_cost(&F, rigs, 1, vert, pts, np, 1e-3, pm, NULL)) / (2 * h);
                rel = fabs(g[k] - fd) / fmax(fabs(fd), 1e-12);
                if (fabs(fd) > 1e-9) worst = fmax(worst, rel);
                printf("    d C / d par[%d]: adjoint %.9g, central difference %.9g, relative error %.2e\n", k, g[k], fd, rel);
            }
            printf("  template geometry (limb biceps, 8 parameters): adjoint vs central differences, worst relative error %.2e\n", worst);
            T_CHECK(worst <= 1e-5, "adjoint gradient with the template's geometry: relative error %.3g (want <= 1e-5)", worst);
            sb_fit_template_get(&F, 0, par);
            sb_fit_template_bounds(&F, 0, lo, hi);
            oo.pgtol = 1e-9; oo.max_iter = 200; oo.ftol = 1e-13;
            t0 = sb_now();
            sb_fit_template(&F, rigs, 1, vert, pts, np, 0, lo, hi, par, &oo, &rr);
            printf("  template geometry fit: cost %.3g (mean squared point distance / cell^2), %d iterations, %d evaluations, %.2f s;"
                   " s %.4g (2.0), a.x %.4g (2.4), b.x %.4g (5.9), R %.4g (1.8)\n",
                   rr.f, rr.iterations, rr.evaluations, sb_now() - t0, par[0], par[1], par[4], par[7]);
            T_CHECK(rr.f < 1e-6, "40 dragged points reached: rms distance %.3g cells (want < 1e-3)", sqrt(rr.f));
            free(pose);
            sb_fit_close(&F);
            sb_fit_close(&G);
        } else T_CHECK(0, "open the limbs");
    }

    /* ---------------- the rig file refused by another character ---------------- */
    {
        sb_desc d;
        sb_mesh mm;
        sb_model o;
        sb_rigfile rf;
        int vert[4], n, drop;
        double Q[12];
        memset(&o, 0, sizeof o);
        T_CHECK(sb_desc_load(COW, &d) == 0 && sb_mesh_load_obj(d.mesh_path, &mm) == 0, "cow");
        T_CHECK(sb_rigfile_read(tpath("test_rigfit_biceps.rig"), &rf) == 0, "read back");
        T_CHECK(sb_rigfile_apply(&rf, "biceps.rig", &o, &mm, 0, vert, Q, &n, &drop) == -1 && strstr(sb_error(), "fitted to another character"),
                "wrong character refused: %s", sb_error());
        printf("  wrong character: %s\n", sb_error());
        sb_rigfile_free(&rf);
        write_text(tpath("test_rigfit_bad.rig"), "sinew-rig 1\nmesh 322 0\ncell 1\norigin 0 0 0\nforces 1\nf 0 0 0 nan 0 0\nend\n");
        T_CHECK(sb_rigfile_read(tpath("test_rigfit_bad.rig"), &rf) == -1 && strstr(sb_error(), "finite"), "non-finite force refused: %s", sb_error());
        sb_mesh_free(&mm); sb_desc_free(&d);
    }

    /* ---------------- cow: point drag with two rigs, FD check ---------------- */
    if (sb_fit_open(&F, COW, 1) == 0) {
        const snref_model *m = &F.m;
        snref_xform *pose = malloc(m->nJ * sizeof *pose);
        int rigs[2] = {1, 2}, vert[3] = {2882, 2800, 2850}, k, a;
        double pts[9], eta[2] = {0.9, 1.4}, g[2], worst = 0;
        T_CHECK(sb_static_pose(&F.s, "rest", pose, NULL, what, sizeof what) == 0, "pose");
        snref_set_control(&F.s, (unsigned)snref_find_control(m, "smile"), 1.0);
        T_CHECK(sb_fit_set_pose(&F, pose, 1.0) == 0, "cow solve");
        for (k = 0; k < 3; k++) for (a = 0; a < 3; a++) pts[3 * k + a] = F.surf0[3 * vert[k] + a] + (a == 1 ? 0.05 : 0);
        sb_fit_points_cost(&F, rigs, 2, vert, pts, 3, 1e-2, eta, g);
        for (a = 0; a < 2; a++) {
            double ep[2], em[2], h = 1e-4, fd, rel;
            memcpy(ep, eta, sizeof ep); memcpy(em, eta, sizeof em);
            ep[a] += h; em[a] -= h;
            fd = (sb_fit_points_cost(&F, rigs, 2, vert, pts, 3, 1e-2, ep, NULL) - sb_fit_points_cost(&F, rigs, 2, vert, pts, 3, 1e-2, em, NULL)) / (2 * h);
            rel = fabs(g[a] - fd) / fmax(fabs(fd), 1e-300);
            worst = fmax(worst, rel);
        }
        printf("  point drag (cow smile_l, smile_r): adjoint vs central differences, worst relative error %.2e\n", worst);
        T_CHECK(worst <= 1e-5, "adjoint gradient (2 rigs): relative error %.3g (want <= 1e-5)", worst);
        {   /* the smile (smile = 1) refitted as a surface rig with the smile off: within 1% */
            double *target = malloc(3 * (size_t)m->nS * sizeof *target), *base = malloc(3 * (size_t)m->nS * sizeof *base);
            double *fit = malloc(3 * (size_t)m->nS * sizeof *fit), *etaf = malloc(3 * (size_t)F.o.nf * sizeof *etaf), rmsf, maxf, t0;
            memcpy(target, F.surf0, 3 * (size_t)m->nS * sizeof *target);
            snref_set_control(&F.s, (unsigned)snref_find_control(m, "smile"), 0.0);
            T_CHECK(sb_fit_set_pose(&F, pose, 1.0) == 0, "cow smile off");
            memcpy(base, F.surf0, 3 * (size_t)m->nS * sizeof *base);
            sb_opt_defaults(&oo);
            oo.pgtol = 1e-10; oo.ftol = 1e-15; oo.max_iter = 3000;
            t0 = sb_now();
            sb_fit_surface(&F, target, 1e-5, &oo, &rr, etaf, fit);
            disp_stats(fit, target, base, m->nS, &rmsf, &maxf);
            printf("  surface rig (cow smile target, omega 1e-5): residual rms %.3g%%, max %.3g%% of the target displacement; %d iterations, %.3f s\n",
                   100 * rmsf, 100 * maxf, rr.iterations, sb_now() - t0);
            T_CHECK(maxf <= 0.01, "cow smile recovered within 1%% of its displacement (max %.3g%%)", 100 * maxf);
            {   /* the exact solve (CG) against L-BFGS-B on the same cost; the reach bound below the fit */
                sb_opt_result r2;
                sb_surf_reach reach;
                double f_cg = rr.f;
                F.surf_lbfgsb = 1;
                sb_fit_surface(&F, target, 1e-5, &oo, &r2, etaf, NULL);
                F.surf_lbfgsb = 0;
                printf("  surface rig cost: conjugate gradients %.12g (%d iterations), L-BFGS-B %.12g (%d iterations)\n", f_cg, rr.iterations, r2.f, r2.iterations);
                T_CHECK(rr.status == SB_OPT_PGTOL && f_cg <= r2.f * (1 + 1e-9), "CG converged to the minimum (%.12g vs L-BFGS-B %.12g)", f_cg, r2.f);
                T_CHECK(sb_fit_surface_reach(&F, target, &oo, &reach, NULL) == 0, "reach");
                printf("  reach: best rms %.3g%% (skeleton freed %.3g%%), %.3g%% of sum |d|^2 on half-bone-carried surface\n", 100 * reach.rms, 100 * reach.rms_all, 100 * reach.skel_half);
                T_CHECK(reach.rms <= rmsf + 1e-6 && reach.rms_all <= reach.rms + 1e-6, "best reachable %.3g%% <= fit %.3g%%, freed %.3g%%", 100 * reach.rms, 100 * rmsf, 100 * reach.rms_all);
            }
            free(target); free(base); free(fit); free(etaf);
        }
        free(pose);
        sb_fit_close(&F);
    } else T_CHECK(0, "open cow");
    return T_END();
}
