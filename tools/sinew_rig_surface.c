/* sinew_rig_surface.c -- sinew-rig fit-surface: a surface rig from target meshes (seed 003 §4.3), on level 1 too. */
#include "sinew_rig_int.h"
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int cmp_gamma(const void *a, const void *b)
{
    double x = ((const double *)a)[0], y = ((const double *)b)[0];
    return (x > y) - (x < y);
}

/* fit-surface on level 1 of 'levels 2' (F1 opened by sb_fit_open_level): the same target,
 * pose (--pose re-read on level 1's model, else the fitted or rest rotations local), controls
 * and omega on level 1's own lattice; eta1 (F1->o.nf x 3) the fit, a summary in sum. 0, 1, 2 */
static int fit_level1(sb_fit *F1, const opts_t *o, const double *target, const double *local, sb_opt_opts oo, double *eta1, char *sum, size_t sumn)
{
    const snref_model *m = &F1->m;
    snref_xform *pose = malloc(m->nJ * sizeof *pose);
    double *base = malloc(3 * (size_t)m->nS * sizeof *base), *fit = malloc(3 * (size_t)m->nS * sizeof *fit), *best = malloc(3 * (size_t)m->nS * sizeof *best);
    double root[3] = {0, 0, 0}, rms, mx, rrms, rmx, t0 = sb_now();
    char what[4096];
    sb_opt_result rr;
    sb_surf_reach reach;
    int rc = 2;
    if (o->controls && sr_set_controls(&F1->s, o->controls)) goto done;
    if (o->pose) { if (sb_static_pose(&F1->s, o->pose, pose, NULL, what, sizeof what)) goto done; }
    else sb_pose_from_local(m, local, root, pose);
    rc = 1;
    if (sb_fit_set_pose(F1, pose, o->rigs_off ? 0 : 1)) goto done;
    memcpy(base, F1->surf0, 3 * (size_t)m->nS * sizeof *base);
    oo.label = "fit-surface level 1";
    if (sb_fit_surface(F1, target, o->omega, &oo, &rr, eta1, fit)) goto done;
    sr_residual(fit, target, base, m->nS, &rms, &mx, NULL);
    if (sb_fit_surface_reach(F1, target, &oo, &reach, best)) goto done;
    sr_residual(fit, best, base, m->nS, &rrms, &rmx, NULL);
    snprintf(sum, sumn, "level 1 (cell %g, %u free lattice vertices): residual rms %.3g%%, max %.3g%% of the target's displacement; "
             "best reachable rms %.3g%%, max %.3g%%; the fit against it rms %.3g%%, max %.3g%%; %d iterations",
             m->cell * m->unit, m->nF, 100 * rms, 100 * mx, 100 * reach.rms, 100 * reach.max, 100 * rrms, 100 * rmx, rr.iterations);
    if (!o->quiet) printf("fit-surface: %s (%s), %.2f s\n", sum, rr.status <= 1 ? "converged" : rr.status == 2 ? "max-iter" : "line search failed", sb_now() - t0);
    rc = 0;
done:
    free(pose); free(base); free(fit); free(best);
    return rc;
}

int sr_cmd_fit_surface(const opts_t *o)
{
    sb_fit F, F1;
    const snref_model *m;
    double *tg[SB_TAU_MAX], gam[SB_TAU_MAX], *local = NULL, *eta = NULL, *eta1 = NULL, *fit = NULL, *base = NULL, *rest = NULL, *best = NULL, secs_pose, t0, rms, mx, dmax;
    double rrms = 0, rmx = 0;
    sb_surf_reach reach;
    double samples[2 * SB_TAU_MAX];
    snref_xform *pose = NULL;
    char what[4096], tau[512], *comment = NULL, sum1[512] = "";
    int i, k, rc = 2, ctl, primary = 0, it_pose, ns = 0, have_g[SB_TAU_MAX];
    sb_opt_opts oo;
    sb_opt_result rr;
    size_t cl;
    memset(tg, 0, sizeof tg);
    memset(&F1, 0, sizeof F1);
    if (!o->ntarget || !o->control || !o->out) { fprintf(stderr, PROG ": fit-surface DESC --target T.obj --control NAME -o OUT.rig (--help)\n"); return 2; }
    if (o->pose && o->features && 0) return 2;
    for (i = 0; i < o->ntarget; i++) {   /* TARGET[@GAMMA] */
        const char *at = strrchr(o->target[i], '@');
        have_g[i] = 0; gam[i] = 0;
        if (at && !strchr(at, '/')) {
            char *e;
            gam[i] = strtod(at + 1, &e);
            if (*e || e == at + 1 || !isfinite(gam[i]) || fabs(gam[i]) > 16384) { fprintf(stderr, PROG ": --target %s: the value after @ is not a control value\n", o->target[i]); return 2; }
            have_g[i] = 1;
        }
    }
    if (sb_fit_open(&F, o->desc, 1)) return 1;
    m = &F.m;
    rc = 2;
    if ((ctl = snref_find_control(m, o->control)) < 0) {
        unsigned c;
        fprintf(stderr, PROG ": --control: the description has no control '%s' (declare it: 'control %s' or 'control %s angle JOINT AX AY AZ'); controls:",
                o->control, o->control, o->control);
        for (c = 0; c < m->nK; c++) fprintf(stderr, " %s", m->kname[c]);
        fprintf(stderr, "\n");
        goto done;
    }
    for (i = 0; i < o->ntarget; i++) {
        char path[1024];
        const char *at = strrchr(o->target[i], '@');
        size_t l = have_g[i] ? (size_t)(at - o->target[i]) : strlen(o->target[i]);
        snprintf(path, sizeof path, "%.*s", (int)l, o->target[i]);
        if (!(tg[i] = sr_read_obj_vertices(path, F.mesh.nv))) goto done;
    }
    if ((unsigned)F.mesh.nv != m->nS) { fprintf(stderr, PROG ": the baked surface has %u vertices, the mesh %d\n", m->nS, F.mesh.nv); rc = 1; goto done; }
    if (o->controls && sr_set_controls(&F.s, o->controls)) goto done;
    /* the primary target: the largest |gamma| (the first if none given) */
    for (i = 1; i < o->ntarget; i++) if (have_g[i] && (!have_g[primary] || fabs(gam[i]) > fabs(gam[primary]))) primary = i;
    local = malloc(4 * (size_t)m->nJ * sizeof *local);
    pose = malloc(m->nJ * sizeof *pose);
    eta = calloc(3 * (size_t)F.o.nf + 3, sizeof *eta);
    fit = malloc(3 * (size_t)m->nS * sizeof *fit);
    base = malloc(3 * (size_t)m->nS * sizeof *base);
    rest = malloc(3 * (size_t)m->nS * sizeof *rest);
    best = malloc(3 * (size_t)m->nS * sizeof *best);
    if ((rc = sr_get_pose(&F, o, tg[primary], local, pose, what, sizeof what, &secs_pose, &it_pose))) goto done;
    rc = 1;
    {   /* the rest shape for the picture */
        snref_xform *id = malloc(m->nJ * sizeof *id);
        double root[3] = {0, 0, 0}, *l0 = malloc(4 * (size_t)m->nJ * sizeof *l0);
        unsigned j;
        for (j = 0; j < 4 * m->nJ; j++) l0[j] = (j % 4 == 3);
        sb_pose_from_local(m, l0, root, id);
        if (sb_fit_set_pose(&F, id, o->rigs_off ? 0 : 1)) { free(id); free(l0); goto done; }
        memcpy(rest, F.surf0, 3 * (size_t)m->nS * sizeof *rest);
        free(id); free(l0);
    }
    if (sb_fit_set_pose(&F, pose, o->rigs_off ? 0 : 1)) goto done;
    memcpy(base, F.surf0, 3 * (size_t)m->nS * sizeof *base);
    if (!have_g[primary]) gam[primary] = m->kkind[ctl] == SN_CTL_ABSTRACT ? 1.0 : snref_get_control(&F.s, (unsigned)ctl);
    if (!(fabs(gam[primary]) > 1e-9)) {
        fprintf(stderr, PROG ": the target's control value is 0 (the rig Q(gamma) = tau(gamma) eta would be off there): give TARGET@GAMMA%s\n",
                m->kkind[ctl] == SN_CTL_ABSTRACT ? "" : " or pose the joint");
        rc = 2;
        goto done;
    }
    if (!o->quiet) printf("fit-surface: %s: pose %s; control %s = %g at the target; %u free lattice vertices (%u unknowns), omega %g\n",
                          o->desc, what, o->control, gam[primary], m->nF, 3 * m->nF, o->omega);
    sb_opt_defaults(&oo);
    oo.pgtol = 1e-10; oo.ftol = 1e-15; oo.max_iter = o->max_iter; oo.verbose = o->quiet ? 0 : o->progress; oo.label = "fit-surface";
    oo.max_iter = o->lbfgsb ? o->max_iter : 100000;   /* the CG solve is exact: the cap only guards against a broken system */
    F.surf_lbfgsb = o->lbfgsb;
    t0 = sb_now();
    if (sb_fit_surface(&F, tg[primary], o->omega, &oo, &rr, eta, fit)) goto done;
    sr_residual(fit, tg[primary], base, m->nS, &rms, &mx, &dmax);
    if (!o->quiet) printf("fit-surface: %d iterations (%s, %s), %.2f s: residual rms %.3g%%, max %.3g%% of the target's displacement (largest %.4g mesh units); "
                          "worst at mesh vertex %u (%.4g, %.4g, %.4g)\n",
                          rr.iterations, o->lbfgsb ? "L-BFGS-B" : "conjugate gradients",
                          rr.status == 0 ? "converged" : rr.status == 1 ? "converged (ftol)" : rr.status == 2 ? "max-iter" : "line search failed",
                          sb_now() - t0, 100 * rms, 100 * mx, dmax, sr_worst_at, tg[primary][3 * sr_worst_at], tg[primary][3 * sr_worst_at + 1], tg[primary][3 * sr_worst_at + 2]);
    /* what any rig at this pose can reach: the target's share on bone-carried surface, the best fit by the free vertices alone */
    if (sb_fit_surface_reach(&F, tg[primary], &oo, &reach, best)) goto done;
    sr_residual(fit, best, base, m->nS, &rrms, &rmx, NULL);
    if (!o->quiet) {
        printf("fit-surface: target on bone-carried surface: %.2g%% of its sum |d|^2 on vertices with at least half their embedding weight on skeleton vertices (%.2g%% all)\n",
               100 * reach.skel_half, 100 * reach.skel_all);
        printf("fit-surface: best reachable (free lattice vertices alone, omega 0; a lower bound): residual rms %.3g%%, max %.3g%% of the target's displacement\n",
               100 * reach.rms, 100 * reach.max);
        printf("fit-surface: the fit against that best (the reachable part): rms %.3g%%, max %.3g%% of its displacement\n", 100 * rrms, 100 * rmx);
        printf("fit-surface: with the skeleton vertices free too (as if no bone carried any; the lattice's resolution): best rms %.3g%%, max %.3g%%\n",
               100 * reach.rms_all, 100 * reach.max_all);
    }
    if (F.d.levels > 1) {   /* 'levels 2': level 1's own fit on its own lattice (its rigs are not level 0's spread: runtime/LEVELS.md §2) */
        if (sb_fit_open_level(&F1, o->desc, 1, 1)) goto done;
        eta1 = calloc(3 * (size_t)F1.o.nf + 3, sizeof *eta1);
        if ((rc = fit_level1(&F1, o, tg[primary], local, oo, eta1, sum1, sizeof sum1))) goto done;
        rc = 1;
    }
    /* tau samples: (0, 0), the primary at 1, the others by least squares on the rig's shape (level 0's) */
    samples[ns * 2] = gam[primary]; samples[ns * 2 + 1] = 1; ns++;
    for (i = 0; i < o->ntarget; i++) {
        double num = 0, den = 0;
        unsigned s;
        if (i == primary) continue;
        if (!have_g[i]) { fprintf(stderr, PROG ": with several targets each needs its control value: TARGET@GAMMA\n"); rc = 2; goto done; }
        for (s = 0; s < 3 * m->nS; s++) { double u = fit[s] - base[s]; num += u * (tg[i][s] - base[s]); den += u * u; }
        samples[ns * 2] = gam[i]; samples[ns * 2 + 1] = den > 0 ? num / den : 0; ns++;
        if (!o->quiet) printf("fit-surface: target %s at %s = %g: tau %.6g (least squares on the fitted shape)\n", o->target[i], o->control, gam[i], samples[ns * 2 - 1]);
    }
    {   int has0 = 0; for (i = 0; i < ns; i++) has0 |= samples[2 * i] == 0; if (!has0) { samples[2 * ns] = 0; samples[2 * ns + 1] = 0; ns++; } }
    qsort(samples, (size_t)ns, 2 * sizeof(double), cmp_gamma);
    for (i = 1; i < ns; i++) if (samples[2 * i] == samples[2 * i - 2]) { fprintf(stderr, PROG ": two targets at %s = %g\n", o->control, samples[2 * i]); rc = 2; goto done; }
    for (i = 0, k = 0; i < ns; i++) k += snprintf(tau + k, sizeof tau - (size_t)k, "%s%.9g %.9g", i ? "  " : "", samples[2 * i], samples[2 * i + 1]);
    /* outputs: picture first (so a failed picture leaves no rig file), then the rig file */
    if (o->png) {
        const double *S[4], *R[4];
        double sc[4];
        const char *l1[4] = {"rest", "unrigged", "rigged (fit)", "target"}, *l2[4];
        char s2[160], s3[160], s4[160];
        S[0] = rest; S[1] = base; S[2] = fit; S[3] = tg[primary];
        R[0] = NULL; R[1] = tg[primary]; R[2] = tg[primary]; R[3] = base;
        sc[0] = 0; sc[1] = sc[2] = sc[3] = dmax;
        snprintf(s2, sizeof s2, "red: distance to the target (%.3g = full red)", dmax);
        snprintf(s3, sizeof s3, "residual rms %.2g%%, max %.2g%%", 100 * rms, 100 * mx);
        snprintf(s4, sizeof s4, "red: displacement from unrigged");
        l2[0] = NULL; l2[1] = s2; l2[2] = s3; l2[3] = s4;
        if (sr_picture(o->png, m, 4, S, R, sc, l1, l2, o->az, o->el)) goto done;
    }
    cl = strlen(o->desc) + strlen(what) + sizeof sum1 + 2048;
    comment = malloc(cl);
    {
        size_t n = 0;
        n += (size_t)snprintf(comment + n, cl - n, "surface rig fitted by sinew-rig fit-surface (seed 003 eq. 13-14) from %s\n", o->desc);
        for (i = 0; i < o->ntarget && n < cl; i++) n += (size_t)snprintf(comment + n, cl - n, "target %s\n", o->target[i]);
        n += (size_t)snprintf(comment + n, cl - n, "pose %s\ncontrol %s, omega %g%s\n", what, o->control, o->omega, o->rigs_off ? ", description rigs off" : "");
        n += (size_t)snprintf(comment + n, cl - n, "residual rms %.3g%%, max %.3g%% of the target displacement; %d iterations\n", 100 * rms, 100 * mx, rr.iterations);
        n += (size_t)snprintf(comment + n, cl - n, "best reachable (free lattice vertices alone): rms %.3g%%, max %.3g%%; the fit against it: rms %.3g%%, max %.3g%%\n"
                              "best with the skeleton vertices free too: rms %.3g%%, max %.3g%%\n",
                              100 * reach.rms, 100 * reach.max, 100 * rrms, 100 * rmx, 100 * reach.rms_all, 100 * reach.max_all);
        if (sum1[0]) n += (size_t)snprintf(comment + n, cl - n, "levels 2: a fit on each level's lattice (level 0 above, then level 1); %s\n", sum1);
        {   /* the file's own name (not its directory): the bytes depend on the inputs only */
            const char *b = strrchr(o->out, '/');
            snprintf(comment + n, cl - n, "use: rig_file %s %s %s tau %s", o->name ? o->name : o->control, b ? b + 1 : o->out, o->control, tau);
        }
    }
    {
        const sb_model *om[2];
        const double *Qs[2];
        om[0] = &F.o; om[1] = &F1.o; Qs[0] = eta; Qs[1] = eta1;
        if (sb_rigfile_write_fits(o->out, eta1 ? 2 : 1, om, &F.mesh, Qs, comment)) { fprintf(stderr, PROG ": %s\n", sb_error()); if (o->png) remove(o->png); goto done; }
    }
    rc = 0;
    if (!o->quiet) {
        printf("fit-surface: wrote %s%s%s\n", o->out, o->png ? " and " : "", o->png ? o->png : "");
        printf("rig_file %s %s %s tau %s\n", o->name ? o->name : o->control, o->out, o->control, tau);
    }
done:
    for (i = 0; i < o->ntarget; i++) free(tg[i]);
    free(local); free(pose); free(eta); free(eta1); free(fit); free(base); free(rest); free(best); free(comment);
    sb_fit_close(&F);
    if (F1.m.nV || F1.o.nv) sb_fit_close(&F1);
    return rc;
}
